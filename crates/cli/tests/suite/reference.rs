//! The committed reference (`docs/reference`: man pages, completions, the
//! command line and file formats in Markdown) is what the code generates.

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn check(dir: &Path) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cancosim")).args(["gen", "reference", "--check", "--out"]).arg(dir).output().unwrap();
    (out.status.success(), String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr))
}

#[test]
fn the_committed_reference_matches_the_code() {
    let (ok, text) = check(&repo().join("docs/reference"));
    assert!(
        ok,
        "docs/reference differs from what the code generates:\n{text}\nRegenerate it (from the repository root) with:\n  cargo run --release -p cancosim -- gen reference --out docs/reference"
    );
}

#[test]
fn a_changed_missing_or_extra_file_is_caught_and_named() {
    let d = tempfile::tempdir().unwrap();
    let ref_dir = d.path().join("reference");
    let w = Command::new(env!("CARGO_BIN_EXE_cancosim")).args(["gen", "reference", "--out"]).arg(&ref_dir).output().unwrap();
    assert!(w.status.success(), "{}", String::from_utf8_lossy(&w.stderr));
    assert!(check(&ref_dir).0, "a fresh copy matches");
    for f in ["cli.md", "man/cancosim-run.1", "man/cancosim-gen-reference.1", "completions/_cancosim", "scenario-format.md", "profile-format.md", "waiver-format.md"] {
        assert!(ref_dir.join(f).is_file(), "{f} is generated");
    }
    std::fs::write(ref_dir.join("profile-format.md"), "stale\n").unwrap();
    std::fs::remove_file(ref_dir.join("completions/cancosim.fish")).unwrap();
    std::fs::write(ref_dir.join("man/cancosim-old.1"), "gone\n").unwrap();
    let (ok, text) = check(&ref_dir);
    assert!(!ok, "{text}");
    for want in ["profile-format.md differs", "completions/cancosim.fish is missing", "man/cancosim-old.1 is no longer generated", "gen reference --out docs/reference"] {
        assert!(text.contains(want), "{want}: {text}");
    }
    // Writing again repairs it, removing what is no longer generated.
    assert!(Command::new(env!("CARGO_BIN_EXE_cancosim")).args(["gen", "reference", "--out"]).arg(&ref_dir).status().unwrap().success());
    assert!(check(&ref_dir).0 && !ref_dir.join("man/cancosim-old.1").exists());
}
