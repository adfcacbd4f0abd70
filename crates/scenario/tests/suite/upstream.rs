//! The real opencores `can` core, through the built `cancosim`:
//! the regression passes with the core's profile and its waiver file, on the
//! scenarios' own hosts and through Wishbone: every scenario passes but
//! basic-sleep-wakeup (D6) and basic-overrun-abort (D8c/D8d in BasicCAN),
//! which fail exactly as their `[[expected-failure]]` entries record; the thesis wiring through the
//! PIO host reproduces the thesis's symptom; and copies of the core with one
//! deliberate bug each still fail, so the waivers hide no fault.
//!
//! The core is third-party (LGPL) and never shipped: these tests take its
//! directory (its `rtl/verilog` files plus `timescale.v`) from
//! `CAN_UPSTREAM_DIR` and are ignored otherwise. The mutations are made at
//! test time in a temporary copy; no mutated file is kept.
//!
//! ```sh
//! cargo build --release -p cancosim
//! CAN_UPSTREAM_DIR=/path/to/can cargo test --release -p scenario --test suite upstream:: -- --ignored --nocapture
//! ```

use std::collections::BTreeSet;
use crate::upstream_common;
use upstream_common::{cancosim, root, upstream_dir};
use std::process::{Command, Output};

const PROFILE: &str = "opencores-can";
const WAIVERS: &str = "tb/waivers/opencores-upstream.toml";




fn run(args: &[&str]) -> (bool, String) {
    let Output { status, stdout, stderr } = Command::new(cancosim()).current_dir(root()).args(args).output().unwrap();
    let text = format!("{}\n{}", String::from_utf8_lossy(&stdout), String::from_utf8_lossy(&stderr));
    (status.success(), text)
}

/// Waiver ids named in a JUnit file ("waived by ID").
fn waivers_hit(junit: &str) -> BTreeSet<String> {
    junit
        .split("waived by ")
        .skip(1)
        .filter_map(|t| t.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.')).next())
        .filter(|id| !id.is_empty())
        .map(str::to_string)
        .collect()
}

/// The regress table's list of waivers hit: (id, line) from
/// "known deviations waived on ..." ("  ID xN in M scenario(s): words").
fn listed_waivers(text: &str) -> Vec<(String, String)> {
    text.lines()
        .skip_while(|l| !l.starts_with("known deviations waived on "))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .map(|l| (l.trim().split(' ').next().unwrap_or("").to_string(), l.trim().to_string()))
        .collect()
}

fn shipped_ids() -> BTreeSet<String> {
    waivers::WaiverSet::load(root().join(WAIVERS)).unwrap().waivers().iter().map(|w| w.id.clone()).collect()
}

/// `cancosim regress` on the core with the profile and the waivers; returns
/// (passed, table text, waivers hit according to the JUnit file, the JSON report).
fn regress(host: Option<&str>) -> (bool, String, BTreeSet<String>, serde_json::Value) {
    let dir = upstream_dir("can_top.v");
    let junit = std::env::temp_dir().join(format!("upstream-{}-{}.xml", host.unwrap_or("own"), std::process::id()));
    let json = junit.with_extension("json");
    let ext = format!("upstream={}", dir.display());
    let mut args = vec![
        "regress",
        "tb/regression.list",
        "--external",
        &ext,
        "--profile",
        PROFILE,
        "--waivers",
        WAIVERS,
        "--junit",
        junit.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ];
    if let Some(h) = host {
        args.extend(["--host", h]);
    }
    let (ok, text) = run(&args);
    let hit = waivers_hit(&std::fs::read_to_string(&junit).unwrap_or_default());
    let report = serde_json::from_str(&std::fs::read_to_string(&json).unwrap_or_else(|_| "null".into())).unwrap_or(serde_json::Value::Null);
    let _ = std::fs::remove_file(&junit);
    let _ = std::fs::remove_file(&json);
    (ok, text, hit, report)
}

/// (run, passed, expected failures, not passed, skipped) from the summary
/// line "N run, M passed, [X expected failure(s), ]K not passed[, S skipped]".
fn summary(text: &str) -> (usize, usize, usize, usize, usize) {
    let line = text.lines().find(|l| l.contains(" run, ") && l.contains(" passed")).unwrap_or_else(|| panic!("no summary in\n{text}"));
    let count = |what: &str| {
        line.split(", ").find_map(|part| part.strip_suffix(what).and_then(|n| n.trim().parse::<usize>().ok())).unwrap_or(0)
    };
    (count(" run"), count(" passed"), count(" expected failure(s)"), count(" not passed"), count(" skipped"))
}

/// The expected failures of a run, (scenario, entry id, deviation), from its JSON report.
fn expected_failures(report: &serde_json::Value) -> BTreeSet<(String, String, String)> {
    report["cells"]
        .as_array()
        .into_iter()
        .flatten()
        .filter(|c| c["status"] == "expected-failure")
        .map(|c| {
            let e = &c["expected_failure"];
            let s = |v: &serde_json::Value| v.as_str().unwrap_or("").to_string();
            (s(&c["scenario"]), s(&e["id"]), s(&e["deviation"]))
        })
        .collect()
}

/// The two scenarios that fail on this core for deviations the golden
/// model does not imitate, each exactly as its [[expected-failure]] entry
/// in the waiver file records (docs/opencores-deviations.md, "Expected failures").
fn expected_xfails() -> BTreeSet<(String, String, String)> {
    [
        ("basic-sleep-wakeup", "basic-sleep-wakeup-gts-transmits", "D6"),
        ("basic-overrun-abort", "basic-overrun-abort-lost-message-keeps-entry", "D8c/D8d"),
    ]
    .iter()
    .map(|(a, b, c)| (a.to_string(), b.to_string(), c.to_string()))
    .collect()
}

/// The table without the per-scenario pass rows: what did not pass, the
/// summary, the waivers hit and the warnings.
fn digest(text: &str) -> String {
    text.lines().filter(|l| !(l.contains(" | pass") || l.contains(" | skipped"))).collect::<Vec<_>>().join("\n")
}

#[test]
#[ignore = "needs the upstream core (CAN_UPSTREAM_DIR) and a built cancosim; about 5 s with a warm build (a minute to verilate the core once)"]
fn the_regression_passes_on_the_upstream_core_with_its_profile_and_waivers() {
    let ids = shipped_ids();
    let lines = tb_list_len();
    let mut failed = Vec::new();
    for host in [None, Some("wishbone")] {
        let t0 = std::time::Instant::now();
        let (ok, text, hit, report) = regress(host);
        let (run, passed, xfails, not_passed, skipped) = summary(&text);
        let label = host.unwrap_or("(own)");
        let listed = listed_waivers(&text);
        eprintln!(
            "--host {label}: {run} run, {passed} passed, {xfails} expected failure(s), {not_passed} not passed, {skipped} skipped ({:.0} s)",
            t0.elapsed().as_secs_f64()
        );
        eprintln!("{}", digest(&text));
        // Every waiver hit is a shipped one, named in the JUnit file and
        // listed in the table with the deviation in words.
        assert!(!hit.is_empty(), "the upstream core deviates: some waiver must be hit\n{text}");
        for id in &hit {
            assert!(ids.contains(id), "waiver {id} hit but not in {WAIVERS}");
            assert!(listed.iter().any(|(l, _)| l == id), "waiver {id} hit but not listed in the table\n{text}");
        }
        assert_eq!(listed.len(), hit.len(), "{listed:?} vs {hit:?}");
        // Exactly: every scenario on its own host; through Wishbone every
        // scenario but the one whose point is its host wiring. All pass but
        // two, which fail exactly as their [[expected-failure]] entries
        // record (a pass or another failure would make `ok` false).
        let want = match host {
            None => (lines, lines - 2, 2, 0, 0),
            Some(_) => (lines - 1, lines - 3, 2, 0, 1),
        };
        let got = (run, passed, xfails, not_passed, skipped);
        if !(ok && got == want) {
            failed.push(format!("--host {label}: want {want:?} (run, passed, expected failures, not passed, skipped), got {got:?}"));
        }
        let xf = expected_failures(&report);
        if xf != expected_xfails() {
            failed.push(format!("--host {label}: expected failures {xf:?}, want exactly {:?}", expected_xfails()));
        }
        if report["ok"] != serde_json::Value::Bool(true) || report["expected_failures"] != 2 {
            failed.push(format!("--host {label}: JSON report says ok = {}, expected_failures = {}", report["ok"], report["expected_failures"]));
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

fn tb_list_len() -> usize {
    std::fs::read_to_string(root().join("tb/regression.list"))
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .count()
}

#[test]
#[ignore = "needs the upstream core (CAN_UPSTREAM_DIR) and a built cancosim; about 1 s with a warm build"]
fn the_thesis_wiring_reproduces_the_thesis_symptom_on_the_upstream_core() {
    let dir = upstream_dir("can_top.v");
    let d = dir.to_str().unwrap();
    let mut failed = Vec::new();
    // The scenario's own host (the thesis's Wishbone wiring) and the PIO host.
    for host in [None, Some("pio")] {
        let label = host.unwrap_or("(own)");
        let mut base = vec!["run", "tb/de2-thesis.toml", "--external", d, "--define", "CAN_WISHBONE_IF", "--include", d, "--profile", PROFILE, "--waivers", WAIVERS];
        if let Some(h) = host {
            base.extend(["--host", h]);
        }
        let (ok, text) = run(&base);
        let hit: BTreeSet<&str> = text.lines().filter_map(|l| l.strip_prefix("WAIVED [")?.split(']').next()).collect();
        let fails: Vec<&str> = text.lines().filter(|l| l.starts_with("FAIL ")).collect();
        eprintln!("de2-thesis --host {label}: {}; waivers hit: {hit:?}; unwaived divergences: {fails:#?}", if ok { "exit 0" } else { "exit 1" });
        for l in text.lines().filter(|l| l.starts_with("Waived: ") || l.starts_with("Figures: ")) {
            eprintln!("  {l}");
        }
        assert!(ok && text.contains("scenario: PASS"), "de2-thesis --host {label} on the upstream core\n{text}");
        let mut json = base.clone();
        json.push("--json");
        let (_, out) = run(&json);
        let start = out.find('{').unwrap_or_else(|| panic!("no JSON in\n{out}"));
        let v: serde_json::Value = serde_json::Deserializer::from_str(&out[start..]).into_iter().next().unwrap().unwrap();
        assert_eq!(v["category"], "RxNotFollowingTx", "{v:#}");
        let f = &v["figures"];
        // The thesis's symptom: rx tied recessive, every attempt a bit error,
        // TEC 136 after the first, bus-off during the 16th, tx recessive after.
        assert_eq!(f["first_attempt_tec"], 136, "{v:#}");
        assert_eq!(f["bus_off_attempt"], 16, "{v:#}");
        assert_eq!(f["attempts"], 16, "{v:#}");
        // The core itself reached bus-off: its own SR read at the end shows BS.
        assert!(f["sr"].as_u64().is_some_and(|sr| sr & 0x80 != 0), "the DUT's final SR has no BS: {v:#}");
        // Each waived deviation is named in words, and nothing else diverged
        // on the way to the bus-off the scenario is about.
        for id in &hit {
            assert!(text.contains(&format!("({id}")), "waiver {id} hit but not named by the diagnosis\n{text}");
        }
        if !fails.is_empty() {
            failed.push(format!("--host {label}: {} unwaived divergence(s): {}", fails.len(), fails.join(" | ")));
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// (name, file, text to find, replacement, scenario that must then fail):
/// each turns one waived deviation into a larger one, or adds a fault next
/// to it, so a waiver that were too wide would let it pass.
const MUTATIONS: &[(&str, &str, &str, &str, &str)] = &[
    // D2 widened: RS stays set while the receiver acknowledges (TS and RS).
    ("rs-while-acking", "can_bsp.v", "(!rx_idle) && (!transmitting)", "(!rx_idle)", "pelican-error-passive"),
    // D7 the other way: the RTR bit of the EFF ID4 byte always set.
    ("eff-rtr-always-set", "can_bsp.v", "{id[4:0], 3'h0}", "{id[4:0], 3'h4}", "pelican-frame-kinds"),
    // D1 later still: the interrupt pin waits for a sample point.
    ("irq-at-sample-point", "can_registers.v", "else if (irq)", "else if (irq & sample_point)", "parking-10-nodes"),
    // A fault beside the waived SR deviations: TBS never released.
    ("tbs-never-released", "can_registers.v", "else if (reset_mode || !need_to_tx)", "else if (reset_mode)", "de2-with-ack-node"),
    // D12 widened: the TX buffer is never locked, so TBS reads 1 through
    // every transmission, not only the one after an abort in an error frame.
    ("tbs-never-locked", "can_registers.v", "transmit_buffer_status <=#Tp 1'b0;", "transmit_buffer_status <=#Tp 1'b1;", "pelican-self-test-abort"),
];

#[test]
#[ignore = "needs the upstream core (CAN_UPSTREAM_DIR) and a built cancosim; verilates five mutated copies (about 4 minutes)"]
fn waivers_hide_no_fault_mutated_upstream_cores_still_fail() {
    let dir = upstream_dir("can_top.v");
    for (name, file, from, to, scen) in MUTATIONS {
        let tb = format!("tb/{scen}.toml");
        let d = dir.to_str().unwrap();
        let args = |core: &str| -> Vec<String> {
            [&tb, "--external", core, "--define", "CAN_WISHBONE_IF", "--include", core, "--profile", PROFILE, "--waivers", WAIVERS]
                .iter()
                .map(|s| s.to_string())
                .collect()
        };
        let with = |core: &str| {
            let mut a = vec!["run".to_string()];
            a.extend(args(core));
            a
        };
        let a = with(d);
        let (ok, text) = run(&a.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(ok, "{scen} must pass on the unmutated core for {name} to mean anything\n{text}");
        let m = std::env::temp_dir().join(format!("upstream-mut-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&m).unwrap();
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "v") {
                let mut text = std::fs::read_to_string(&p).unwrap();
                if p.file_name().unwrap() == *file {
                    assert!(text.contains(from), "{name}: the mutation point is not in {file} (another revision?)");
                    text = text.replacen(from, to, 1);
                }
                std::fs::write(m.join(p.file_name().unwrap()), text).unwrap();
            }
        }
        let a = with(m.to_str().unwrap());
        let (ok, text) = run(&a.iter().map(String::as_str).collect::<Vec<_>>());
        let _ = std::fs::remove_dir_all(&m);
        assert!(!ok && text.contains("scenario: FAIL"), "mutant {name} passed {scen} with the waivers: a waiver hides it\n{text}");
        // It fails for what the mutation did, not because it did not build.
        assert!(!text.contains(": RunError"), "mutant {name} did not run\n{text}");
        let why = text.lines().find(|l| l.starts_with("FAIL ") || l.starts_with("  - ")).unwrap_or("");
        eprintln!("mutant {name}: {scen} fails, as it must ({})", why.trim());
    }
}
