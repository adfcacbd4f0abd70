//! Issue 8 item 2: the scenario parser never panics or hangs, whatever the
//! input: random text, and shipped files with lines dropped, duplicated or
//! bytes changed. Every rejection is a `ScenarioError::At` with a line
//! inside the file.

use proptest::prelude::*;
use scenario::{Scenario, ScenarioError};
use std::path::PathBuf;

fn shipped_texts() -> Vec<String> {
    let tb = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tb");
    let mut v: Vec<String> = std::fs::read_dir(&tb)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    v.sort();
    v
}

fn check(text: &str) {
    match Scenario::parse(text, "fuzz.toml") {
        Ok(_) => {}
        Err(ScenarioError::At { line, key, message, .. }) => {
            let lines = text.lines().count().max(1) + 1;
            assert!(line >= 1 && line <= lines, "line {line} outside 1..={lines}: {key}: {message}");
            assert!(!message.is_empty());
        }
        Err(e) => panic!("unexpected error kind: {e}"),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn random_text_never_panics(s in "\\PC{0,200}") {
        check(&s);
    }

    #[test]
    fn mutated_shipped_files_never_panic(file in 0usize..7, ops in proptest::collection::vec((0u8..4, any::<u16>(), any::<char>()), 1..6)) {
        let texts = shipped_texts();
        let mut lines: Vec<String> = texts[file % texts.len()].lines().map(str::to_string).collect();
        for (op, pos, c) in ops {
            if lines.is_empty() { break; }
            let i = pos as usize % lines.len();
            match op {
                0 => { lines.remove(i); }
                1 => { let l = lines[i].clone(); lines.insert(i, l); }
                2 => {
                    let mut chars: Vec<char> = lines[i].chars().collect();
                    let j = pos as usize % (chars.len() + 1);
                    chars.insert(j, c);
                    lines[i] = chars.into_iter().collect();
                }
                _ => {
                    // change a number: the classic out-of-range edit
                    lines[i] = lines[i].replace("0x", "0x1FF");
                }
            }
        }
        check(&lines.join("\n"));
    }
}
