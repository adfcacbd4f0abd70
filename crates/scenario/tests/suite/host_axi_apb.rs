//! `--host axi4-lite` and `--host apb`: the main list on our RTL (through
//! `can_axi4lite` / `can_apb`) and on the golden model (through the bus's
//! bridge), with zero divergences and nothing waived. One test per host;
//! the other lists are measured by hand (`cancosim regress tb/<list>
//! --dut rtl --dut model --host <h>`), see the host-bus page of the guide.

use diagnose::HostBus;
use scenario::regress::Status;
use scenario::{DutSpec, HostBfm, RegressOptions, RunOptions, load_list, regress, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn host_names_parse() {
    for (n, h) in [("axi4-lite", HostBfm::Axi4Lite), ("apb", HostBfm::Apb), ("apb4", HostBfm::Apb), ("apb3", HostBfm::Apb3)] {
        assert_eq!(HostBfm::from_name(n), Some(h));
    }
    assert_eq!(HostBfm::Axi4Lite.name(), "axi4-lite");
    assert_eq!(HostBfm::Apb3.name(), "apb3");
}

fn main_list_clean(host: HostBfm, bus: HostBus) {
    let s = load_list(root().join("tb/regression.list")).unwrap();
    assert!(s.len() >= 20, "the shipped list shrank: {}", s.len());
    let duts = [DutSpec::rtl(), DutSpec::model()];
    let rep = regress(&s, &duts, &RegressOptions { jobs: 2, host: Some(host), collect: waivers::CollectMode::Collect, ..Default::default() });
    let table = rep.to_table();
    assert!(rep.passed(), "{table}");
    assert!(rep.cells.iter().all(|c| c.waived.is_empty()), "nothing waived: {table}");
    let ran = rep.cells.iter().filter(|c| !matches!(c.status, Status::Skipped(_))).count();
    assert!(ran >= 2 * (s.len() - 1), "{table}");
    // The record names the bus, and one scenario shows the accesses went through it.
    let sc = s.iter().find(|s| s.host_fixed.is_none()).unwrap();
    let o = run(sc, &RunOptions { dut: Some(DutSpec::rtl()), host: Some(host), ..Default::default() });
    assert_eq!(o.record.host_bus, bus);
    assert!(o.record.divergence.is_none() && o.record.violations.is_empty(), "{:?}", o.record.violations);
    assert!(o.record.host_ops.iter().all(|op| op.error.is_none() && op.cycles > 2), "every access a full bus transfer");
}

#[test]
fn main_list_on_rtl_and_model_through_axi4_lite() {
    main_list_clean(HostBfm::Axi4Lite, HostBus::Axi4Lite);
}

#[test]
fn main_list_on_rtl_and_model_through_apb() {
    main_list_clean(HostBfm::Apb, HostBus::Apb);
}
