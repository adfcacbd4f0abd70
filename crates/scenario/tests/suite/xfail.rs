//! Strict expected failures in the regression runner, with injected run
//! outcomes (no Verilator): divergence lines in the signature, collect mode
//! for a named run, the user's mode for a run no entry is for, one entry per
//! run, the host restriction, waived expectations left out of the signature.
//! The end-to-end runs on our RTL are crates/cli/tests/suite/expected_failures.rs.

use std::sync::Mutex;
use std::time::Duration;

use diagnose::{Divergence, DivergenceKind, Expectation, RunRecord};
use scenario::regress::{RegressOptions, Status, regress_with};
use scenario::run::{DutSpec, RunOptions, RunOutcome};
use scenario::Scenario;
use waivers::{CollectMode, WaivedExpectation, WaiverReport};

const SCENARIO: &str = "name = \"xf\"\npurpose = \"fixture\"\nstep = [{ read = \"SR\", expect = 0x0C }]\n[clocks]\nhost_mhz = 50.0\ncan_mhz = 24.0\n[host]\nbfm = \"wishbone\"\n[dut]\nkind = \"rtl\"\n[run]\nmax_bits = 40\n";
const CORE: &str = "fixture core (/x)";

fn sr(bit: u64, model: u32, dut: u32) -> Divergence {
    Divergence { kind: DivergenceKind::RegisterRead, register: Some("SR".into()), bit: Some(bit), expected: model, seen: dut, context: "varies".into(), time_ps: bit * 7, ..Default::default() }
}

/// A failed run on CORE with these unwaived divergences.
fn failed(divs: Vec<Divergence>) -> RunOutcome {
    let record = RunRecord::new("xf", CORE);
    RunOutcome {
        diagnosis: diagnose::diagnose(&record),
        record,
        passed: false,
        mismatches: vec![format!("{} unwaived divergence(s) from the golden model", divs.len())],
        received: Vec::new(),
        // The regression's column; the waivers know the DUT by its full name.
        dut: "rtl".into(),
        wall: Duration::ZERO,
        waivers: Some(WaiverReport { dut: CORE.into(), failures: divs, ..Default::default() }),
        warnings: Vec::new(),
        skipped: None,
        bus_log: Vec::new(),
        delivered: Vec::new(),
        steps: Vec::new(),
    }
}

const TWO: [&str; 3] = [
    "divergence register-read SR at bit 10: model 0x0C, DUT 0x0F",
    "divergence register-read SR at bit 20: model 0x1C, DUT 0x1F",
    "verdict 2 unwaived divergence(s) from the golden model",
];

fn entry(id: &str, dut: &str, host: &str, lines: &[&str]) -> String {
    let sig: Vec<String> = lines.iter().map(|l| format!("{l:?}")).collect();
    format!(
        "[[expected-failure]]\nid = \"{id}\"\nscenario = \"xf\"\ndut = [\"{dut}\"]\n{host}deviation = \"D0\"\nclause = \"c\"\nreason = \"r\"\nsignature = [{}]\n",
        sig.join(", ")
    )
}

/// Regress the scenario on one DUT with `waivers` text, the runner giving
/// `outcome`; returns the cell and the modes the runner was called with.
fn judge(waivers: &str, mode: CollectMode, outcome: impl Fn() -> RunOutcome + Sync) -> (scenario::regress::Cell, Vec<CollectMode>, String) {
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("xfail-{}-{}", std::process::id(), N.fetch_add(1, std::sync::atomic::Ordering::SeqCst)));
    std::fs::create_dir_all(&dir).unwrap();
    let w = dir.join("w.toml");
    std::fs::write(&w, waivers).unwrap();
    let s = Scenario::parse(SCENARIO, "xf.toml").unwrap();
    let modes = Mutex::new(Vec::new());
    let opts = RegressOptions { jobs: 1, waivers: vec![w], collect: mode, ..Default::default() };
    let rep = regress_with(&[s], &[DutSpec::rtl()], &opts, |_: &Scenario, o: &RunOptions| {
        modes.lock().unwrap().push(o.collect);
        outcome()
    });
    let table = rep.to_table();
    (rep.cells[0].clone(), modes.into_inner().unwrap(), table)
}

#[test]
fn the_exact_set_of_divergences_is_an_expected_failure_judged_in_collect_mode() {
    let w = entry("x", "fixture core (*)", "", &TWO);
    // The order of the lines does not matter: it is a set.
    let (c, modes, table) = judge(&w, CollectMode::StopAtFirst, || failed(vec![sr(20, 0x1C, 0x1F), sr(10, 0x0C, 0x0F)]));
    assert_eq!(modes, [CollectMode::Collect], "a named run is judged whole");
    assert_eq!(c.status, Status::ExpectedFailure { id: "x".into(), deviation: "D0".into() }, "{}", c.report);
    assert!(c.status.ok());
    assert!(table.contains("xfail (D0: x)") && table.contains("1 run, 0 passed, 1 expected failure(s), 0 not passed"), "{table}");
}

#[test]
fn another_divergence_fails_with_the_extra_and_missing_lines() {
    let w = entry("x", "fixture core (*)", "", &TWO);
    let (c, _, table) = judge(&w, CollectMode::StopAtFirst, || failed(vec![sr(10, 0x0C, 0x0F), sr(20, 0x1C, 0x3F)]));
    let Status::WrongFailure { id, diff } = &c.status else { panic!("{:?}", c.status) };
    assert_eq!(id, "x");
    assert_eq!(diff.missing, vec![TWO[1].to_string()]);
    assert_eq!(diff.extra, vec!["divergence register-read SR at bit 20: model 0x1C, DUT 0x3F".to_string()]);
    assert!(!c.status.ok());
    assert!(table.contains(&format!("  - {}", TWO[1])) && table.contains("  + divergence register-read SR at bit 20: model 0x1C, DUT 0x3F"), "{table}");
    // The same divergence one bit later is another line: the bit time is part of the signature.
    let (c, _, _) = judge(&w, CollectMode::Collect, || failed(vec![sr(10, 0x0C, 0x0F), sr(21, 0x1C, 0x1F)]));
    assert!(matches!(c.status, Status::WrongFailure { .. }), "{:?}", c.status);
}

#[test]
fn a_pass_is_an_unexpected_pass() {
    let w = entry("x", "fixture core (*)", "", &TWO);
    let (c, _, _) = judge(&w, CollectMode::StopAtFirst, || {
        let mut o = failed(Vec::new());
        o.passed = true;
        o.mismatches.clear();
        o
    });
    assert_eq!(c.status, Status::UnexpectedPass { id: "x".into() });
    assert!(!c.status.ok());
}

#[test]
fn an_entry_for_another_dut_or_host_leaves_the_run_as_asked() {
    // Another DUT: known only after the run, so the run is made again in the user's mode.
    let w = entry("x", "other core*", "", &TWO);
    let (c, modes, _) = judge(&w, CollectMode::StopAtFirst, || failed(vec![sr(10, 0x0C, 0x0F), sr(20, 0x1C, 0x1F)]));
    assert_eq!(modes, [CollectMode::Collect, CollectMode::StopAtFirst]);
    assert!(c.xfail.is_none() && !c.status.ok(), "{:?}", c.status);
    // Another host: not a candidate at all.
    let w = entry("x", "fixture core (*)", "host = \"avalon\"\n", &TWO);
    let (c, modes, _) = judge(&w, CollectMode::StopAtFirst, || failed(vec![sr(10, 0x0C, 0x0F), sr(20, 0x1C, 0x1F)]));
    assert_eq!(modes, [CollectMode::StopAtFirst]);
    assert!(c.xfail.is_none() && !c.status.ok(), "{:?}", c.status);
    // The scenario's own host named: judged.
    let w = entry("x", "fixture core (*)", "host = [\"avalon\", \"wishbone\"]\n", &TWO);
    let (c, _, _) = judge(&w, CollectMode::StopAtFirst, || failed(vec![sr(10, 0x0C, 0x0F), sr(20, 0x1C, 0x1F)]));
    assert!(matches!(c.status, Status::ExpectedFailure { .. }), "{:?}", c.status);
}

#[test]
fn two_entries_for_one_run_are_an_error() {
    let w = format!("{}\n{}", entry("a", "fixture core (*)", "", &TWO), entry("b", "fixture*", "", &TWO));
    let (c, _, _) = judge(&w, CollectMode::StopAtFirst, || failed(vec![sr(10, 0x0C, 0x0F), sr(20, 0x1C, 0x1F)]));
    let Status::Error(e) = &c.status else { panic!("{:?}", c.status) };
    assert!(e.contains("`a`") && e.contains("`b`") && e.contains("keep one"), "{e}");
}

#[test]
fn the_signature_has_failed_expectations_but_not_waived_ones() {
    // A divergence given twice is one line.
    let mut o = failed(vec![sr(10, 0x0C, 0x0F), sr(10, 0x0C, 0x0F)]);
    o.mismatches = vec!["1 unwaived divergence(s) from the golden model".into()];
    let exp = |step, passed| Expectation { step, what: "SR & 0xFF".into(), expected: "0x0C (mask 0xFF)".into(), seen: "0x0F".into(), passed };
    o.record.expectations = vec![exp(1, true), exp(3, false), exp(4, false)];
    o.waivers.as_mut().unwrap().waived_expectations.push(WaivedExpectation {
        step: 3,
        what: "SR & 0xFF".into(),
        expected: "0x0C".into(),
        seen: 0x0F,
        model: 0x0C,
        waiver_id: "w".into(),
        consequence: false,
    });
    assert_eq!(
        scenario::xfail::signature(&o),
        vec![
            "divergence register-read SR at bit 10: model 0x0C, DUT 0x0F".to_string(),
            "expectation step 4: SR & 0xFF expected 0x0C (mask 0xFF), seen 0x0F".to_string(),
            "verdict 1 unwaived divergence(s) from the golden model".to_string(),
        ]
    );
}

/// `place = "step"`: the same failure through a slower host (every
/// divergence later in bits, in the same steps) is the same expected
/// failure; a divergence in another step, or another value, is not. A read
/// that ends the instant the next step starts belongs to its own step.
#[test]
fn an_entry_placed_by_step_holds_for_any_host_speed_and_still_catches_a_move_to_another_step() {
    let placed = |scale: u64, second_step_end: u64, value: u32| {
        move || {
            let mut o = failed(vec![sr(10 * scale, 0x0C, 0x0F), sr(second_step_end * scale, 0x1C, value)]);
            // Step 1 from 0, step 2 from bit 15, step 3 from bit 30 (x7 ps a bit, as `sr` stamps).
            o.steps = vec![(1, 0), (2, 15 * 7 * scale), (3, 30 * 7 * scale), (0, 45 * 7 * scale)];
            o
        }
    };
    let lines = [
        "divergence register-read SR in step 1: model 0x0C, DUT 0x0F",
        "divergence register-read SR in step 2: model 0x1C, DUT 0x1F",
        "verdict 2 unwaived divergence(s) from the golden model",
    ];
    let w = entry("x", "fixture core (*)", "", &lines).replace("signature = [", "place = \"step\"\nsignature = [");
    // The fast host and one three times slower: bits differ, steps do not;
    // the second read ends exactly when step 3 starts.
    for scale in [1, 3] {
        let (cell, _, table) = judge(&w, CollectMode::StopAtFirst, placed(scale, 30, 0x1F));
        assert!(matches!(cell.status, Status::ExpectedFailure { .. }), "scale {scale}: {:?}\n{table}", cell.status);
    }
    // Still caught: the second divergence in step 3, or with another DUT value.
    let (cell, _, _) = judge(&w, CollectMode::StopAtFirst, placed(1, 31, 0x1F));
    assert!(matches!(cell.status, Status::WrongFailure { .. }), "{:?}", cell.status);
    let (cell, _, _) = judge(&w, CollectMode::StopAtFirst, placed(1, 30, 0x1E));
    assert!(matches!(cell.status, Status::WrongFailure { .. }), "{:?}", cell.status);
    // The bit-placed form of the same entry holds only at the recorded bits.
    let bits = entry("x", "fixture core (*)", "", &TWO);
    let (cell, _, _) = judge(&bits, CollectMode::StopAtFirst, placed(3, 20, 0x1F));
    assert!(matches!(cell.status, Status::WrongFailure { .. }), "{:?}", cell.status);
}
