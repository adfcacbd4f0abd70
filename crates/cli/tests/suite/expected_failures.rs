//! Strict expected failures (`[[expected-failure]]`), end to end through the
//! built `cancosim regress` on our RTL, with two fixture scenarios
//! (tests/data/xfail): one our RTL fails on purpose (a wrong expectation),
//! its passing twin. The signature is recorded with
//! `--record-expected-failures`, then: the exact signature is an expected
//! failure (exit 0, in the table, JUnit, JSON and HTML); a changed one is a
//! failure printing the lines that differ; an entry on the passing twin is
//! an unexpected pass (exit 1); malformed entries are one clear error
//! (exit 2). Divergence lines and the collect mode are covered with injected
//! outcomes in crates/scenario/tests/suite/xfail.rs.

use std::path::{Path, PathBuf};
use std::process::Command;

const FAILS: &str = "crates/cli/tests/data/xfail/fails-on-purpose.toml";
const PASSES: &str = "crates/cli/tests/data/xfail/passes.toml";
/// What the failing fixture shows on a correct DUT (step 6 expects 0x55, the register holds 0x54).
const SIGNATURE: [&str; 2] = [
    "expectation step 6: ACR0 & 0xFF expected 0x55 (mask 0xFF), seen 0x54",
    "verdict category: expected Pass, diagnosed ExpectationFailed",
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-xfail").join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `cancosim regress ARGS` from the repository root: (exit code, stdout + stderr).
fn regress(args: &[&str]) -> (i32, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_cancosim")).arg("regress").args(args).current_dir(root()).output().unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(!text.contains("panicked"), "{text}");
    (o.status.code().expect("exit code"), text)
}

/// An entry for `scenario` on our RTL with these signature lines.
fn entry(id: &str, scenario: &str, lines: &[&str]) -> String {
    let sig: Vec<String> = lines.iter().map(|l| format!("    {l:?},")).collect();
    format!(
        "[[expected-failure]]\nid = \"{id}\"\nscenario = \"{scenario}\"\ndut = [\"rtl\"]\nhost = \"wishbone\"\ndeviation = \"T1\"\n\
         clause = \"none: a fixture\"\nreason = \"step 6 expects 0x55 on purpose\"\nsignature = [\n{}\n]\n",
        sig.join("\n")
    )
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn the_recorded_exact_signature_is_an_expected_failure_and_exits_0() {
    let d = scratch("exact");
    // Recording: collect mode, one entry per run that did not pass, texts
    // left empty (so it cannot be pasted unexplained), never a waiver file.
    let rec = d.join("recorded.toml");
    let (code, text) = regress(&[FAILS, PASSES, "--record-expected-failures", rec.to_str().unwrap()]);
    assert_eq!(code, 1, "without an entry the fixture fails\n{text}");
    assert!(text.contains("expected-failure entries: 1 written"), "{text}");
    let recorded = std::fs::read_to_string(&rec).unwrap();
    assert_eq!(recorded.lines().filter(|l| *l == "[[expected-failure]]").count(), 1, "{recorded}");
    for l in SIGNATURE {
        assert!(recorded.contains(&format!("{l:?}")), "recorded signature lacks {l}\n{recorded}");
    }
    let (code, text) = regress(&[FAILS, "--waivers", rec.to_str().unwrap()]);
    assert_eq!(code, 2, "an unfilled recorded entry must not load\n{text}");
    assert!(text.contains("recorded.toml:") && text.contains(": deviation: empty"), "{text}");

    // The recorded entry with its texts filled in: an expected failure.
    let filled = recorded.replacen("deviation = \"\"", "deviation = \"T1\"", 1).replacen("clause = \"\"", "clause = \"none: a fixture\"", 1).replacen(
        "reason = \"\"",
        "reason = \"step 6 expects 0x55 on purpose\"",
        1,
    );
    let w = write(&d, "filled.toml", &filled);
    let (junit, json, html) = (d.join("j.xml"), d.join("r.json"), d.join("html"));
    let (code, text) = regress(&[
        FAILS,
        PASSES,
        "--waivers",
        &w,
        "--junit",
        junit.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        "--html",
        html.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "exact signature: exit 0\n{text}");
    assert!(text.contains("xfail (T1: xfail-fixture-fails-wishbone)"), "{text}");
    assert!(text.contains("2 run, 1 passed, 1 expected failure(s), 0 not passed"), "{text}");
    assert!(text.contains("failed with exactly its 2 signature line(s)"), "{text}");
    let j = std::fs::read_to_string(&junit).unwrap();
    assert!(j.contains("<skipped message=\"expected failure xfail-fixture-fails-wishbone (T1): step 6 expects 0x55 on purpose\" type=\"xfail\""), "{j}");
    assert!(!j.contains("<failure"), "{j}");
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!((v["passed"].as_u64(), v["expected_failures"].as_u64(), v["not_passed"].as_u64(), v["ok"].as_bool()), (Some(1), Some(1), Some(0), Some(true)), "{v:#}");
    let cell = v["cells"].as_array().unwrap().iter().find(|c| c["scenario"] == "xfail-fixture-fails").unwrap();
    assert_eq!(cell["status"], "expected-failure", "{cell:#}");
    assert_eq!(cell["expected_failure"]["id"], "xfail-fixture-fails-wishbone", "{cell:#}");
    assert_eq!(cell["expected_failure"]["verdict"], "exact", "{cell:#}");
    let page = std::fs::read_to_string(html.join("index.html")).unwrap();
    assert!(page.contains("id=\"expected-failures\"") && page.contains("expected failure (T1: xfail-fixture-fails-wishbone)"), "HTML lacks the expected failure");
    assert!(page.contains("<b>PASS</b>"), "HTML verdict");
}

#[test]
fn a_changed_signature_fails_with_the_lines_that_differ() {
    let d = scratch("changed");
    // The entry recorded another value than the run shows, and a line the run does not show.
    let changed = [
        "expectation step 6: ACR0 & 0xFF expected 0x55 (mask 0xFF), seen 0x53",
        SIGNATURE[1],
        "divergence register-read SR at bit 12 (BusIdle): model 0x3C, DUT 0x1C",
    ];
    let w = write(&d, "w.toml", &entry("fx", "xfail-fixture-fails", &changed));
    let json = d.join("r.json");
    let (code, text) = regress(&[FAILS, "--waivers", &w, "--json", json.to_str().unwrap()]);
    assert_eq!(code, 1, "a different failure fails the run\n{text}");
    assert!(text.contains("FAIL (not as fx: -2 +1)"), "{text}");
    assert!(text.contains("not the failure expected-failure `fx`"), "{text}");
    assert!(text.contains(&format!("- {}", changed[0])) && text.contains(&format!("- {}", changed[2])), "missing lines not shown\n{text}");
    assert!(text.contains(&format!("+ {}", SIGNATURE[0])), "extra line not shown\n{text}");
    assert!(!text.contains(&format!("- {}", SIGNATURE[1])), "a matching line is not a difference\n{text}");
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let x = &v["cells"][0]["expected_failure"];
    assert_eq!((x["verdict"].as_str(), x["missing"].as_array().map(Vec::len), x["extra"].as_array().map(Vec::len)), (Some("different"), Some(2), Some(1)), "{v:#}");
    // A subset of the run's lines is not enough either (strict: the exact set).
    let w = write(&d, "subset.toml", &entry("fx", "xfail-fixture-fails", &SIGNATURE[1..]));
    let (code, text) = regress(&[FAILS, "--waivers", &w]);
    assert_eq!(code, 1, "{text}");
    assert!(text.contains(&format!("+ {}", SIGNATURE[0])), "{text}");
}

#[test]
fn a_scenario_that_passes_against_its_entry_is_an_unexpected_pass() {
    let d = scratch("xpass");
    let w = write(&d, "w.toml", &entry("stale", "xfail-fixture-passes", &SIGNATURE));
    let junit = d.join("j.xml");
    let (code, text) = regress(&[PASSES, "--waivers", &w, "--junit", junit.to_str().unwrap()]);
    assert_eq!(code, 1, "an unexpected pass fails the run\n{text}");
    assert!(text.contains("UNEXPECTED PASS (stale)"), "{text}");
    assert!(text.contains("the entry is stale"), "{text}");
    let j = std::fs::read_to_string(&junit).unwrap();
    assert!(j.contains("<failure message=\"unexpected pass: expected-failure stale is stale\""), "{j}");
    // The entry is bound to its host: through Avalon it does not apply, the scenario passes.
    let (code, text) = regress(&[PASSES, "--waivers", &w, "--host", "avalon"]);
    assert_eq!(code, 0, "an entry for wishbone does not judge an Avalon run\n{text}");
}

#[test]
fn malformed_entries_are_one_clear_error() {
    let d = scratch("bad");
    let good = entry("fx", "xfail-fixture-fails", &SIGNATURE);
    let cases: Vec<(String, &str)> = vec![
        (good.replace("    \"verdict category", "    \"category"), ":11: signature: line `category: expected Pass, diagnosed ExpectationFailed` must start with one of: divergence, expectation, verdict"),
        (good.replace("host = \"wishbone\"", "host = \"vme\""), ":5: host: unknown host `vme`"),
        (good.replace("reason = \"step 6 expects 0x55 on purpose\"", "reason = \" \""), ":8: reason: empty"),
        (good.replace("scenario = ", "scenarios = "), ":3: scenarios: unknown field `scenarios`"),
        (format!("{good}\n{good}"), ": id: duplicate expected-failure id `fx`"),
        (good.replace(&format!("    {:?},", SIGNATURE[0]), &format!("    {:?},\n    {:?},", SIGNATURE[1], SIGNATURE[1])), ": signature: line `verdict category: expected Pass, diagnosed ExpectationFailed` given twice"),
    ];
    for (i, (text, want)) in cases.iter().enumerate() {
        let w = write(&d, &format!("bad{i}.toml"), text);
        let (code, out) = regress(&[FAILS, "--waivers", &w]);
        assert_eq!(code, 2, "case {i}: a malformed entry is an error before any run\n{out}");
        assert!(out.contains(&format!("bad{i}.toml")) && out.contains(want), "case {i}: want `{want}` in\n{out}");
        assert_eq!(out.trim().lines().count(), 1, "case {i}: one line\n{out}");
    }
}
