//! The journal a run resumes from belongs to one suite: a survivor's verdict
//! reached with some scenarios must not be reused when scenarios or waivers
//! are added (a survivor would stay one without running the new scenario).

use std::path::Path;

use mutate::journal_name;
use scenario::{RunOptions, Scenario};

fn load(rel: &str) -> Scenario {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    Scenario::load(root.join(rel)).unwrap()
}

#[test]
fn another_suite_or_waiver_file_gets_another_journal() {
    let a = load("tb/mutation-holes/sam-glitch-one-sample.toml");
    let b = load("tb/mutation-holes/resync-after-sample-point.toml");
    let run = RunOptions::default();
    let one = journal_name("mutants-x", std::slice::from_ref(&a), &run);
    assert_eq!(one, journal_name("mutants-x", std::slice::from_ref(&a), &run), "same suite, same journal");
    assert!(one.starts_with("journal-mutants-x-") && one.ends_with(".jsonl"), "{one}");
    assert_ne!(one, journal_name("mutants-y", std::slice::from_ref(&a), &run), "another build");
    assert_ne!(one, journal_name("mutants-x", &[a.clone(), b.clone()], &run), "a scenario added");
    assert_ne!(one, journal_name("mutants-x", std::slice::from_ref(&b), &run), "another scenario");
    // A waiver file's text is part of the suite, not only its name.
    let dir = tempfile::tempdir().unwrap();
    let w = dir.path().join("w.toml");
    std::fs::write(&w, "# one\n").unwrap();
    let with = RunOptions { waivers: vec![w.clone()], ..RunOptions::default() };
    let first = journal_name("mutants-x", std::slice::from_ref(&a), &with);
    assert_ne!(one, first, "a waiver file added");
    std::fs::write(&w, "# two\n").unwrap();
    assert_ne!(first, journal_name("mutants-x", std::slice::from_ref(&a), &with), "the waiver file edited");
}
