//! `cancosim regress --baseline OLD=... --external NEW=...` on two
//! revisions of our RTL: a directory copy of rtl/ and a git commit of the
//! same files with tx_o stuck recessive (through the Wishbone host: an
//! external can_top has the one-cycle ack, not the PIO level ack). Old -> new breaks the scenario
//! (exit 1, "BROKEN"); new -> old fixes it (exit 0, "fixed").

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn git(repo: &Path, args: &[&str]) {
    let st = Command::new("git").arg("-C").arg(repo).args(["-c", "user.name=t", "-c", "user.email=t@t"]).args(args).status().unwrap();
    assert!(st.success(), "git {args:?}");
}

fn regress(baseline: &str, new: &str, cache: &Path) -> (i32, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_cancosim"))
        .args(["regress", "tb/de2-pelican-selftest.toml", "--host", "wishbone", "--profile", "rtl", "--baseline", baseline, "--external", new])
        .current_dir(root())
        .env("COSIM_CACHE_DIR", cache)
        .output()
        .unwrap();
    (o.status.code().unwrap(), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

#[test]
fn a_revision_that_breaks_a_scenario_is_named_and_fails_the_command() {
    let t = tempfile::tempdir().unwrap();
    let (good, repo, cache) = (t.path().join("good"), t.path().join("repo"), t.path().join("cache"));
    std::fs::create_dir_all(&good).unwrap();
    std::fs::create_dir_all(repo.join("hdl")).unwrap();
    for e in std::fs::read_dir(root().join("rtl")).unwrap() {
        let p = e.unwrap().path();
        if matches!(p.extension().and_then(|x| x.to_str()), Some("v" | "vh")) {
            std::fs::copy(&p, good.join(p.file_name().unwrap())).unwrap();
            std::fs::copy(&p, repo.join("hdl").join(p.file_name().unwrap())).unwrap();
        }
    }
    git(&repo, &["init", "-q"]);
    git(&repo, &["add", "."]);
    git(&repo, &["commit", "-qm", "good"]);
    // The bug: the bit stream processor's tx never reaches the pin.
    let top = repo.join("hdl/can_top.v");
    let text = std::fs::read_to_string(&top).unwrap();
    let broken = text.replace(".tx_o(tx_o)", ".tx_o(tx_int)");
    assert_ne!(broken, text, "the bug was introduced");
    let broken = broken.replacen(");\n", ");\n    wire tx_int;\n    assign tx_o = 1'b1;\n", 1);
    std::fs::write(&top, broken).unwrap();
    git(&repo, &["commit", "-qam", "bug"]);
    let new = format!("new=git:{}@HEAD:hdl", repo.display());
    let (code, out) = regress(&format!("old={}", good.display()), &new, &cache);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("de2-pelican-selftest  BROKEN"), "{out}");
    assert!(out.contains("0 fixed, 1 broken"), "{out}");
    // The other way round (the commit before the bug as the new one).
    let (code, out) = regress(&new.replace("new=", "old="), &format!("new=git:{}@HEAD~1:hdl", repo.display()), &cache);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("de2-pelican-selftest  fixed"), "{out}");
    // A revision that is no commit is one clear line, exit 2.
    let (code, out) = regress(&format!("old=git:{}@nosuchrev:hdl", repo.display()), &new, &cache);
    assert_eq!(code, 2, "{out}");
    assert!(out.contains("nosuchrev is not a commit"), "{out}");
}
