//! Functional coverage collected by the regression on the golden model's
//! side, merged over scenarios, in the JUnit output.

use scenario::regress::{RegressOptions, regress};
use scenario::{DutSpec, Scenario};

fn load(name: &str) -> Scenario {
    Scenario::load(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tb").join(format!("{name}.toml"))).unwrap()
}

#[test]
fn a_scenario_with_an_eff_remote_frame_marks_that_bin_and_the_junit_carries_the_figures() {
    let s = load("pelican-frame-kinds");
    let report = regress(&[s], &[DutSpec::model()], &RegressOptions { jobs: 1, ..Default::default() });
    assert!(report.passed(), "{}", report.to_table());
    let c = report.funcov("model");
    assert!(c.hits("frame kinds", "EFF remote DLC 0").unwrap() > 0, "{}", c.to_table());
    // What the scenario never sends stays a hole.
    assert_eq!(c.hits("frame kinds", "EFF remote DLC 5"), Some(0));
    assert!(c.holes().any(|b| b.name == "EFF remote DLC 5"));
    let junit = report.to_junit();
    let t = c.totals();
    assert!(junit.contains(&format!("name=\"funcov\" value=\"{}/{}", t.hit, t.total)), "{junit}");
    assert!(junit.contains("name=\"funcov holes frame kinds\""), "{junit}");
}

#[test]
fn coverage_merges_over_scenarios() {
    let a = load("pelican-frame-kinds");
    let b = load("pelican-arbitration");
    let one = regress(&[a.clone()], &[DutSpec::model()], &RegressOptions { jobs: 1, ..Default::default() }).funcov("model");
    let both = regress(&[a, b], &[DutSpec::model()], &RegressOptions { jobs: 1, ..Default::default() }).funcov("model");
    assert!(both.totals().hit > one.totals().hit, "arbitration adds bins: {} vs {}", both.totals().hit, one.totals().hit);
    assert!(both.summary().iter().any(|g| g.group == "arbitration loss" && g.hit > 0), "{}", both.to_table());
}
