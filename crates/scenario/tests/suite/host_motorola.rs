//! `--host motorola`: the main list on our RTL (through `can_top_mcu`, MODE
//! low) and on the golden model (through `bfm::MotorolaBridge`), with zero
//! divergences and nothing waived.

use diagnose::HostBus;
use scenario::regress::Status;
use scenario::{DutSpec, HostBfm, RegressOptions, RunOptions, load_list, regress, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn the_host_name_parses() {
    assert_eq!(HostBfm::from_name("motorola"), Some(HostBfm::Motorola));
    assert_eq!(HostBfm::Motorola.name(), "motorola");
}

#[test]
fn main_list_on_rtl_and_model_through_the_motorola_bus() {
    let s = load_list(root().join("tb/regression.list")).unwrap();
    assert!(s.len() >= 20, "the shipped list shrank: {}", s.len());
    let duts = [DutSpec::rtl(), DutSpec::model()];
    let host = HostBfm::Motorola;
    let rep = regress(&s, &duts, &RegressOptions { jobs: 2, host: Some(host), collect: waivers::CollectMode::Collect, ..Default::default() });
    let table = rep.to_table();
    assert!(rep.passed(), "{table}");
    assert!(rep.cells.iter().all(|c| c.waived.is_empty()), "nothing waived: {table}");
    let ran = rep.cells.iter().filter(|c| !matches!(c.status, Status::Skipped(_))).count();
    assert!(ran >= 2 * (s.len() - 1), "{table}");
    let sc = s.iter().find(|s| s.host_fixed.is_none()).unwrap();
    let o = run(sc, &RunOptions { dut: Some(DutSpec::rtl()), host: Some(host), ..Default::default() });
    assert_eq!(o.record.host_bus, HostBus::Motorola);
    assert!(o.record.divergence.is_none() && o.record.violations.is_empty(), "{:?}", o.record.violations);
    assert!(o.record.host_ops.iter().all(|op| op.error.is_none() && op.cycles > 20), "every access a full multiplexed cycle");
}
