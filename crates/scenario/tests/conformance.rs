//! The ISO 16845-1 conformance suite (`tb/conformance/list`, see
//! docs/conformance.md) cannot rot: every scenario passes on the golden
//! model and on our RTL (Verilated, in lockstep, zero divergences), each
//! names its ISO class and item, and the suite fails when an expectation or
//! the clock-tolerance set-up is wrong.

use scenario::regress::Status;
use scenario::{DutSpec, RegressOptions, RunOptions, Scenario, load_list, regress, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn suite() -> Vec<Scenario> {
    load_list(root().join("tb/conformance/list")).expect("tb/conformance/list loads")
}

fn load(file: &str) -> Scenario {
    Scenario::load(root().join("tb/conformance").join(file)).unwrap()
}

/// The whole list on the model and on our RTL (about 2 s on 2 cores).
#[test]
fn conformance_list_passes_on_model_and_rtl_without_divergence() {
    let s = suite();
    assert!(s.len() >= 45, "the suite shrank to {} scenarios", s.len());
    let opts = RegressOptions { jobs: 2, collect: waivers::CollectMode::Collect, ..Default::default() };
    let rep = regress(&s, &[DutSpec::model(), DutSpec::rtl()], &opts);
    assert_eq!(rep.cells.len(), 2 * s.len());
    for c in &rep.cells {
        assert_eq!(c.status, Status::Pass, "{} on {}: {}", c.scenario, c.dut, c.report);
        assert!(c.waived.is_empty(), "{} on {}: waived divergences {:?}", c.scenario, c.dut, c.waived);
    }
    assert!(rep.passed());
}

/// Names start with the ISO 16845-1 item (7.x receiver, 8.x transmitter),
/// purposes cite the standard, every class 7.1-7.7 and 8.1-8.7 is covered.
#[test]
fn every_scenario_names_its_iso_class_and_item() {
    let s = suite();
    for sc in &s {
        let first = sc.name.split_whitespace().next().unwrap_or("");
        assert!(
            (first.starts_with("7.") || first.starts_with("8.")) && first[2..].chars().next().is_some_and(|c| c.is_ascii_digit()),
            "`{}` does not start with its ISO 16845-1 item",
            sc.name
        );
        assert!(sc.purpose.contains("ISO 16845-1"), "{}: purpose does not cite ISO 16845-1", sc.name);
        assert!(!sc.verifies.is_empty(), "{}: no `verifies`", sc.name);
    }
    for class in ["7.1", "7.2", "7.3", "7.4", "7.5", "7.6", "7.7", "8.1", "8.2", "8.3", "8.4", "8.5", "8.6", "8.7"] {
        assert!(s.iter().any(|sc| sc.name.contains(&format!("{class}."))), "no scenario for class {class}");
    }
}

/// A wrong expected value (the REC after a stuff error off by one) fails
/// the scenario on the model: the checks are live.
#[test]
fn a_wrong_expectation_fails() {
    let path = root().join("tb/conformance/rx-7.2.2-stuff-errors.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let from = "read = \"RXERR\", expect = 9,";
    assert!(text.contains(from), "the mutation point moved");
    let s = Scenario::parse(&text.replacen(from, "read = \"RXERR\", expect = 10,", 1), &path).unwrap();
    let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
    assert!(!o.passed, "a wrong RXERR expectation passed");
}

/// The clock tolerance scenarios really run the other node on its own
/// oscillator: 1.5 % off passes, the same scenario with the node 5 % off
/// fails (with the node on the bench clock it would pass).
#[test]
fn clock_tolerance_scenarios_depend_on_the_drifting_oscillator() {
    let s = load("rx-7.7.5-fast-sender.toml");
    assert!((s.nodes[0].can_hz - 24.36e6).abs() < 1.0);
    assert!(run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() }).passed);
    let mut far = s.clone();
    far.nodes[0].can_hz = 25.2e6;
    let o = run(&far, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
    assert!(!o.passed);
    // Not only the diagnosis's bit-rate check: the DUT's own reads see the
    // frames fail (on the bench clock every read would still pass).
    assert!(o.record.expectations.iter().any(|e| !e.passed), "5 % off: every register read passed: the node clock is not applied");
}

/// A scenario that expects `BitTimingMismatch` (7.7.4) still has its reads
/// judged: a wrong expectation there fails although the category matches.
#[test]
fn reads_are_judged_behind_an_expected_bit_timing_mismatch() {
    let path = root().join("tb/conformance/rx-7.7.4-beyond-sjw.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let from = "read = \"RMC\", expect = 0,";
    assert!(text.contains(from), "the mutation point moved");
    let good = run(&Scenario::parse(&text, &path).unwrap(), &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
    assert!(good.passed, "{:?}", good.mismatches);
    let s = Scenario::parse(&text.replacen(from, "read = \"RMC\", expect = 1,", 1), &path).unwrap();
    let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
    assert_eq!(o.diagnosis.category, diagnose::Category::BitTimingMismatch);
    assert!(!o.passed, "a wrong RMC expectation hid behind the expected BitTimingMismatch");
}
