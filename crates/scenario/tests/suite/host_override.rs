//! Host override (`cancosim run/regress --host`): every shipped scenario
//! played on our RTL through its Avalon-MM wrapper (`rtl/can_avalon.v`)
//! with the Avalon BFM, in lockstep with the golden model, with zero
//! divergences; scenarios whose point is their host wiring are skipped.

use diagnose::HostBus;
use scenario::regress::Status;
use scenario::run::with_host;
use scenario::{DutKind, DutSpec, HostBfm, RegressOptions, RunOptions, RunOutcome, Scenario, load_list, regress, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn shipped() -> Vec<Scenario> {
    load_list(root().join("tb/regression.list")).unwrap()
}

fn load(name: &str) -> Scenario {
    Scenario::load(root().join("tb").join(format!("{name}.toml"))).unwrap()
}

/// Runs `s` on our RTL with `host`, collecting every divergence.
fn on_rtl(s: &Scenario, host: HostBfm) -> RunOutcome {
    let o = run(
        s,
        &RunOptions { dut: Some(DutSpec::rtl()), host: Some(host), collect: waivers::CollectMode::Collect, ..Default::default() },
    );
    eprintln!("{} via {host}: {}\n{:?}", s.name, o.diagnosis.to_text(), o.mismatches);
    o
}

fn divergences(o: &RunOutcome) -> usize {
    o.waivers.as_ref().map(|r| r.failures.len() + r.waived.len()).unwrap_or(0)
}

#[test]
fn host_names_and_dut_mapping() {
    assert_eq!(HostBfm::from_name("avalon"), Some(HostBfm::Avalon { begintransfer_cyc: false }));
    assert_eq!(HostBfm::from_name("Wishbone"), Some(HostBfm::Wishbone));
    assert_eq!(HostBfm::from_name("pio"), Some(HostBfm::Pio));
    assert_eq!(HostBfm::from_name("ahb"), None);
    let s = load("pelican-single-shot");
    assert_eq!(s.dut, DutKind::Rtl);
    let a = with_host(&s, HostBfm::Avalon { begintransfer_cyc: false });
    assert_eq!(a.dut, DutKind::AvalonWrapper, "Avalon on our RTL means the can_avalon wrapper");
    assert_eq!(a.host, HostBfm::Avalon { begintransfer_cyc: false });
    let w = with_host(&load("de2-avalon-wrapper"), HostBfm::Wishbone);
    assert_eq!(w.dut, DutKind::Rtl, "a wrapper scenario on Wishbone runs plain can_top");
    assert!(load("de2-avalon-begintransfer").host_fixed.is_some());
    assert!(s.host_fixed.is_none());
}

/// A few scenarios of different kinds through the wrapper: the record shows
/// Avalon cycles, the outcome is the expected one, no divergence at all.
#[test]
fn rtl_through_avalon_wrapper_runs_in_lockstep() {
    for n in ["pelican-error-kinds", "pelican-sleep-wakeup", "pelican-fifo-overrun", "de2-thesis"] {
        let o = on_rtl(&load(n), HostBfm::Avalon { begintransfer_cyc: false });
        assert!(o.skipped.is_none());
        assert_eq!(o.record.host_bus, HostBus::Avalon, "{n}");
        assert!(o.passed, "{n}: {:?}", o.mismatches);
        assert_eq!(divergences(&o), 0, "{n}: {:?}", o.waivers);
        assert!(o.record.host_ops.iter().all(|op| op.error.is_none()), "{n}: a host access failed");
    }
}

#[test]
fn fixed_host_wiring_is_skipped_with_its_reason() {
    let o = on_rtl(&load("de2-avalon-begintransfer"), HostBfm::Avalon { begintransfer_cyc: false });
    let why = o.skipped.expect("skipped");
    assert!(why.contains("begintransfer"), "{why}");
    assert!(o.passed);
    // Without an override it runs as shipped.
    let o = run(&load("de2-avalon-begintransfer"), &RunOptions { dut: Some(DutSpec::rtl()), ..Default::default() });
    assert!(o.skipped.is_none() && o.passed, "{:?}", o.mismatches);
}

#[test]
fn other_host_overrides() {
    let o = on_rtl(&load("de2-avalon-wrapper"), HostBfm::Wishbone);
    assert_eq!(o.record.host_bus, HostBus::Wishbone);
    assert!(o.passed, "{:?}", o.mismatches);
    let o = on_rtl(&load("pelican-listen-only"), HostBfm::Pio);
    assert_eq!(o.record.host_bus, HostBus::Pio);
    assert!(o.passed, "{:?}", o.mismatches);
    assert_eq!(divergences(&o), 0);
}

/// The whole regression list on our RTL through the Avalon wrapper: every
/// scenario passes (or is skipped because its host wiring is its point),
/// and the table and JUnit say so. About a second in release.
#[test]
fn whole_regression_list_on_rtl_through_avalon() {
    let s = shipped();
    assert!(s.len() >= 20, "the shipped list shrank: {}", s.len());
    let rep = regress(
        &s,
        &[DutSpec::rtl()],
        &RegressOptions { jobs: 2, host: Some(HostBfm::Avalon { begintransfer_cyc: false }), collect: waivers::CollectMode::Collect, ..Default::default() },
    );
    let table = rep.to_table();
    eprintln!("{table}");
    assert_eq!(rep.cells.len(), s.len());
    assert!(rep.passed(), "{table}");
    let skipped: Vec<&str> = rep.cells.iter().filter(|c| matches!(c.status, Status::Skipped(_))).map(|c| c.scenario.as_str()).collect();
    let fixed: Vec<&str> = s.iter().filter(|s| s.host_fixed.is_some()).map(|s| s.name.as_str()).collect();
    assert_eq!(skipped, fixed, "exactly the scenarios with a fixed host wiring are skipped");
    assert!(rep.cells.iter().all(|c| c.waived.is_empty()), "nothing waived: {table}");
    assert!(table.contains(", 1 skipped"), "{table}");
    let junit = rep.to_junit();
    assert!(junit.contains("<skipped message=\"host wiring fixed"), "{junit}");
    // Zero divergences, counted in collect mode, scenario by scenario.
    for sc in s.iter().filter(|s| s.host_fixed.is_none()) {
        let o = on_rtl(sc, HostBfm::Avalon { begintransfer_cyc: false });
        assert_eq!(o.record.host_bus, HostBus::Avalon, "{}", sc.name);
        assert!(o.record.divergence.is_none() && divergences(&o) == 0, "{}: {:?}", sc.name, o.waivers);
    }
}

/// The whole list on our RTL with each scenario's own host, and on the
/// golden model: every scenario passes, no divergence waived.
#[test]
fn whole_regression_list_on_rtl_and_model_as_shipped() {
    let s = shipped();
    let rep = regress(&s, &[DutSpec::rtl(), DutSpec::model()], &RegressOptions { jobs: 2, collect: waivers::CollectMode::Collect, ..Default::default() });
    let table = rep.to_table();
    eprintln!("{table}");
    assert_eq!(rep.cells.len(), s.len() * 2);
    assert!(rep.passed(), "{table}");
    assert!(rep.cells.iter().all(|c| c.status == Status::Pass && c.waived.is_empty()), "{table}");
    // Zero divergences on the RTL with each scenario's own host, except where
    // the scenario's point is a host-bus violation that makes the DUT diverge.
    for sc in s.iter().filter(|s| s.host_fixed.is_none()) {
        let o = run(sc, &RunOptions { dut: Some(DutSpec::rtl()), collect: waivers::CollectMode::Collect, ..Default::default() });
        assert!(o.record.divergence.is_none() && divergences(&o) == 0, "{}: {:?}", sc.name, o.waivers);
    }
}

/// The whole list through a GPIO-polled (PIO) host, on our RTL (its
/// `can_top_pio` level-ack top) and on the golden model (level ack too):
/// every scenario passes in lockstep, nothing waived. The reference takes
/// each access when the DUT's CAN side does, for PIO as for Wishbone.
#[test]
fn whole_regression_list_through_pio_on_rtl_and_model() {
    let s = shipped();
    let rep = regress(
        &s,
        &[DutSpec::rtl(), DutSpec::model()],
        &RegressOptions { jobs: 2, host: Some(HostBfm::Pio), collect: waivers::CollectMode::Collect, ..Default::default() },
    );
    let table = rep.to_table();
    eprintln!("{table}");
    assert_eq!(rep.cells.len(), s.len() * 2);
    assert!(rep.passed(), "{table}");
    assert!(rep.cells.iter().all(|c| c.waived.is_empty()), "nothing waived: {table}");
}
