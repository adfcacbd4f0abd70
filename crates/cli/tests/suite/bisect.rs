//! `cancosim regress` under `git bisect run`: its exit
//! codes (0 passed, 1 failed, 2 the user's input, 125 the core does not
//! build, for plain and `git:` cores), and a real bisection over a small
//! git repository made here from our `rtl/`, with a bug at a known commit
//! and an unbuildable commit that bisect must skip.
//!
//! The bisection builds two distinct cores (the build cache is keyed by the
//! sources and their path, so the repository is made at the same path every
//! time and a warm cache makes the test take seconds).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

fn cancosim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cancosim")).args(args).current_dir(root()).output().expect("cancosim runs")
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// `git` in `repo`, isolated from the user's configuration, with fixed
/// names and dates (the same commits every run); panics on failure.
fn git(repo: &Path, args: &[&str]) -> String {
    let o = git_output(repo, args);
    assert!(o.status.success(), "git {args:?}: {}", text(&o));
    String::from_utf8_lossy(&o.stdout).trim().to_string()
}

fn git_output(repo: &Path, args: &[&str]) -> Output {
    Command::new("git")
        .args(args)
        .current_dir(repo)
        .env("GIT_CONFIG_GLOBAL", "/dev/null")
        .env("GIT_CONFIG_NOSYSTEM", "1")
        .env("GIT_AUTHOR_NAME", "bisect test")
        .env("GIT_AUTHOR_EMAIL", "bisect@test")
        .env("GIT_COMMITTER_NAME", "bisect test")
        .env("GIT_COMMITTER_EMAIL", "bisect@test")
        .env("GIT_AUTHOR_DATE", "2026-01-01T00:00:00Z")
        .env("GIT_COMMITTER_DATE", "2026-01-01T00:00:00Z")
        .output()
        .expect("git runs")
}

/// A fresh directory at a fixed path under the target directory.
fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Copies our `rtl/*.v` and `*.vh` into `dir`.
fn copy_rtl(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    for e in std::fs::read_dir(root().join("rtl")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "v" || x == "vh") {
            std::fs::copy(&p, dir.join(p.file_name().unwrap())).unwrap();
        }
    }
}

/// Replaces `old` (exactly once) by `new` in `file`.
fn edit(file: &Path, old: &str, new: &str) {
    let s = std::fs::read_to_string(file).unwrap();
    assert_eq!(s.matches(old).count(), 1, "{old:?} once in {}", file.display());
    std::fs::write(file, s.replacen(old, new, 1)).unwrap();
}

fn commit(repo: &Path, message: &str) -> String {
    git(repo, &["add", "-A"]);
    git(repo, &["commit", "-q", "-m", message]);
    git(repo, &["rev-parse", "HEAD"])
}

/// A core that declares `module can_top` but is not Verilog.
const SYNTAX_ERROR: &str = "module can_top(input clk_i;\n  this is not verilog\nendmodule\n";

#[test]
fn regress_exit_codes_are_0_passed_1_failed_2_bad_input_125_unbuildable() {
    // 0: every scenario passed (the golden model as DUT: no build).
    let o = cancosim(&["regress", "tb/de2-pelican-selftest.toml", "--dut", "model"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    // 1: a scenario failed (cut short, the thesis scenario does not finish).
    let o = cancosim(&["regress", "tb/de2-thesis.toml", "--dut", "model", "--max-bits", "10"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));

    // 2: the user's input. A scenario file that does not load (the others
    // still run), an unreadable list, a revision that does not exist.
    let dir = scratch("bisect-exit-codes");
    let good = std::fs::read_to_string(root().join("tb/de2-pelican-selftest.toml")).unwrap();
    std::fs::write(dir.join("good.toml"), &good).unwrap();
    std::fs::write(dir.join("typo.toml"), good.replace("[clocks]", "[clocks]\nhost_mzh = 1.0")).unwrap();
    std::fs::write(dir.join("list"), "good.toml\ntypo.toml\n").unwrap();
    let o = cancosim(&["regress", dir.join("list").to_str().unwrap(), "--dut", "model"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("host_mzh"), "{}", text(&o));
    let o = cancosim(&["regress", dir.join("no-such.list").to_str().unwrap(), "--dut", "model"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));

    // 125: the core does not build. A Verilog syntax error, given as a
    // directory and as a git revision; a revision without the SUBDIR; a
    // directory that holds no core.
    let broken = dir.join("broken");
    std::fs::create_dir_all(&broken).unwrap();
    std::fs::write(broken.join("can_top.v"), SYNTAX_ERROR).unwrap();
    let repo = dir.join("repo");
    std::fs::create_dir_all(repo.join("rtl")).unwrap();
    std::fs::write(repo.join("rtl/can_top.v"), SYNTAX_ERROR).unwrap();
    git(&repo, &["init", "-q"]);
    commit(&repo, "a core that does not parse");
    let r = repo.to_str().unwrap();
    for (core, why) in [
        (format!("core={}", broken.display()), "Verilator could not build"),
        (format!("core=git:{r}@HEAD:rtl"), "Verilator could not build"),
        (format!("core=git:{r}@HEAD:nope"), "nope is not a directory of HEAD"),
        (format!("core={}", dir.join("nowhere").display()), "cannot be read"),
    ] {
        let o = cancosim(&["regress", "tb/de2-pelican-selftest.toml", "--external", &core, "--profile", "rtl"]);
        let all = text(&o);
        assert_eq!(o.status.code(), Some(125), "{core}: {all}");
        assert!(all.contains("the core does not build (exit 125)") && all.contains(why), "{core}: {all}");
        assert!(!all.contains("de2-pelican-selftest"), "{core}: no scenario ran: {all}");
    }
    let o = cancosim(&["regress", "tb/de2-pelican-selftest.toml", "--external", &format!("core=git:{r}@no-such-rev:rtl"), "--profile", "rtl"]);
    assert_eq!(o.status.code(), Some(2), "a revision that does not exist is the user's input: {}", text(&o));
}

#[test]
fn git_bisect_run_finds_the_commit_that_broke_the_core_and_skips_the_unbuildable_one() {
    let t = Instant::now();
    let repo = scratch("bisect-repo");
    let rtl = repo.join("rtl");
    copy_rtl(&rtl);
    git(&repo, &["init", "-q"]);
    let good = commit(&repo, "import the core");
    // A harmless change to the sources (a rebuild, same behaviour) and one
    // outside them.
    edit(&rtl.join("can_top.v"), "module can_top", "// top of the core\nmodule can_top");
    commit(&repo, "comment the top");
    std::fs::write(repo.join("NOTES.md"), "notes\n").unwrap();
    let harmless = commit(&repo, "notes");
    // Unbuildable, at the revision bisect tests first (the middle of six),
    // before the bug: were it counted bad (exit 1 or 2), bisect would name
    // it as the first bad commit. Fixed in the next commit.
    let bsp = std::fs::read_to_string(rtl.join("can_bsp.v")).unwrap();
    std::fs::write(rtl.join("can_bsp.v"), bsp.replacen("endmodule", "endmodule oops", 1)).unwrap();
    let unbuildable = commit(&repo, "half-done edit");
    std::fs::write(rtl.join("can_bsp.v"), &bsp).unwrap();
    let fixed = commit(&repo, "finish the edit");
    // The bug: the CRC-15 polynomial with its last bit flipped; every frame
    // the core sends has a wrong CRC, which the lockstep comparison sees.
    edit(&rtl.join("can_bsp.v"), "15'h4599 : 15'h0000", "15'h4598 : 15'h0000");
    let bug = commit(&repo, "tidy the CRC step");
    std::fs::write(repo.join("NOTES.md"), "more notes\n").unwrap();
    commit(&repo, "more notes");

    git(&repo, &["bisect", "start", "HEAD", &good]);
    let scenario = root().join("tb/de2-pelican-selftest.toml");
    let core = format!("core={}", rtl.display());
    let o = git_output(
        &repo,
        &["bisect", "run", env!("CARGO_BIN_EXE_cancosim"), "regress", scenario.to_str().unwrap(), "--external", &core, "--profile", "rtl", "--host", "wishbone"],
    );
    let log = git(&repo, &["bisect", "log"]);
    git(&repo, &["bisect", "reset"]);
    let all = text(&o);
    assert!(o.status.success(), "git bisect run: {all}");
    let first_bad = all.lines().find_map(|l| l.strip_suffix(" is the first bad commit")).unwrap_or_else(|| panic!("no first bad commit: {all}"));
    assert_eq!(first_bad, bug, "the bug commit ({bug}), not the unbuildable one ({unbuildable}) nor a harmless one ({harmless}):\n{all}\n{log}");
    assert!(log.contains(&format!("git bisect skip {unbuildable}")), "the unbuildable commit was tested and skipped (exit 125):\n{log}");
    assert!(log.contains(&format!("git bisect good {fixed}")), "the commit before the bug passed (exit 0):\n{log}");
    eprintln!("git bisect run over 7 commits: {:.1} s\n{log}", t.elapsed().as_secs_f64());
}
