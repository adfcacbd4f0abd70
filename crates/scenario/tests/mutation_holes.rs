//! The scenarios that close protocol-side mutation-testing holes
//! (`tb/mutation-holes.list`, docs/mutation-holes-protocol.md) cannot rot:
//! every one passes on the golden model and on our RTL (lockstep, zero
//! divergences), and their key counter checks are live.

use scenario::regress::Status;
use scenario::{DutSpec, RegressOptions, RunOptions, Scenario, load_list, regress, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The whole list on the model and on our RTL (well under a second).
#[test]
fn mutation_holes_list_passes_on_model_and_rtl_without_divergence() {
    let s = load_list(root().join("tb/mutation-holes.list")).expect("tb/mutation-holes.list loads");
    assert!(s.len() >= 6, "the list shrank to {} scenarios", s.len());
    let opts = RegressOptions { jobs: 2, collect: waivers::CollectMode::Collect, ..Default::default() };
    let rep = regress(&s, &[DutSpec::model(), DutSpec::rtl()], &opts);
    assert_eq!(rep.cells.len(), 2 * s.len());
    for c in &rep.cells {
        assert_eq!(c.status, Status::Pass, "{} on {}: {}", c.scenario, c.dut, c.report);
        assert!(c.waived.is_empty(), "{} on {}: waived divergences {:?}", c.scenario, c.dut, c.waived);
    }
    assert!(rep.passed());
}

/// An off-by-one expectation fails on the model: the checks that killed the
/// counter mutants (TEC after +8/-1, REC from an odd value, FIFO exact fit)
/// are live, not vacuous.
#[test]
fn off_by_one_counter_expectations_fail() {
    for (file, from, to) in [
        ("tec-write-and-count.toml", "read = \"TXERR\", expect = 70,", "read = \"TXERR\", expect = 71,"),
        ("rec-count-from-odd.toml", "read = \"RXERR\", expect = 9,", "read = \"RXERR\", expect = 10,"),
        ("fifo-exact-fit-dual-ext.toml", "read = \"RMC\", expect = 5, note = \"64", "read = \"RMC\", expect = 4, note = \"64"),
    ] {
        let path = root().join("tb/mutation-holes").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(from), "{file}: the mutation point moved");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
        assert!(!o.passed, "{file}: a wrong expectation passed");
    }
}
