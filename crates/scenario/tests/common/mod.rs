//! Helpers shared by the list tests (conformance, registers, mutation holes).

use scenario::regress::Status;
use scenario::{DutSpec, RegressOptions, Scenario, regress};
use std::path::PathBuf;

/// The project's root (where `tb/` is).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every scenario of a list passes on the golden model and on our RTL, in
/// lockstep, with nothing waived (collect mode, so every divergence shows).
pub fn assert_passes_on_model_and_rtl_without_divergence(s: &[Scenario]) {
    let opts = RegressOptions { jobs: 2, collect: waivers::CollectMode::Collect, ..Default::default() };
    let rep = regress(s, &[DutSpec::model(), DutSpec::rtl()], &opts);
    assert_eq!(rep.cells.len(), 2 * s.len());
    for c in &rep.cells {
        assert_eq!(c.status, Status::Pass, "{} on {}: {}", c.scenario, c.dut, c.report);
        assert!(c.waived.is_empty(), "{} on {}: waived divergences {:?}", c.scenario, c.dut, c.waived);
    }
    assert!(rep.passed());
}
