//! A fork's core on AXI4-Lite, APB, the register port and the Motorola bus,
//! bound by its profile alone (tb/fixtures/fork: our wrappers under other
//! port names and polarities). The register-port fork's read data comes 8
//! clocks later than can_regport's: its profile's `read-latency` is what
//! makes it pass, and the same core with can_regport's latency fails with
//! the monitor's sentence, not a divergence somebody could waive.

use scenario::regress::Status;
use scenario::{DutSpec, HostBfm, RegressOptions, RunOptions, Scenario, regress, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn fork(top: &str, profile: &str) -> DutSpec {
    let dir = root().join("tb/fixtures/fork");
    let p = cosim::Profile::load(dir.join(format!("{profile}.toml"))).unwrap_or_else(|e| panic!("{e}"));
    DutSpec::external("fork", dir, top).with_profile(p)
}

fn scenario(name: &str) -> Scenario {
    Scenario::load(root().join("tb").join(name)).unwrap()
}

#[test]
fn the_register_port_fork_passes_a_main_list_subset_with_its_profile() {
    // From the main list: frames both ways, the receive buffer and its
    // overrun, error counters, sleep.
    let list = std::fs::read_to_string(root().join("tb/regression.list")).unwrap();
    let pick = ["basic-filter-frames.toml", "de2-pelican-selftest.toml", "pelican-fifo-overrun.toml", "pelican-error-kinds.toml", "pelican-sleep-wakeup.toml"];
    assert!(pick.iter().all(|p| list.lines().any(|l| l.trim() == *p)), "the main list lost one of {pick:?}");
    let s: Vec<Scenario> = pick.iter().map(|p| scenario(p)).collect();
    let dut = fork("fork_regport", "regport");
    let rep = regress(&s, std::slice::from_ref(&dut), &RegressOptions { jobs: 2, host: Some(HostBfm::Regport), collect: waivers::CollectMode::Collect, ..Default::default() });
    let table = rep.to_table();
    assert!(rep.passed(), "{table}");
    assert!(rep.cells.iter().all(|c| c.waived.is_empty() && !matches!(c.status, Status::Skipped(_))), "{table}");
}

#[test]
fn the_register_port_fork_with_can_regports_latency_fails_on_the_monitor() {
    let s = scenario("basic-filter-frames.toml");
    let o = run(&s, &RunOptions { dut: Some(fork("fork_regport", "regport-wrong-latency")), host: Some(HostBfm::Regport), ..Default::default() });
    assert!(!o.passed, "a read latency of 14 on a port that answers at 18 to 22 must fail");
    let v = o.record.violations.first().unwrap_or_else(|| panic!("no violation: {:?}", o.mismatches));
    assert_eq!(v.rule, "regport.changed_while_valid");
    assert!(v.message.contains("later than its read latency of 14"), "{}", v.message);
}

#[test]
fn apb3_axi4_lite_and_motorola_forks_bind_by_their_profiles() {
    let s = scenario("basic-filter-frames.toml");
    for (top, profile, host) in [("fork_apb", "apb", HostBfm::Apb3), ("fork_axi", "axi4-lite", HostBfm::Axi4Lite), ("fork_mcu", "motorola", HostBfm::Motorola)] {
        let o = run(&s, &RunOptions { dut: Some(fork(top, profile)), host: Some(host), ..Default::default() });
        assert!(o.passed && o.record.violations.is_empty(), "{top} on {host:?}: {:?} {:?}", o.mismatches, o.record.violations);
        // Without the profile's names the top does not bind.
        let bare = DutSpec::external("fork", root().join("tb/fixtures/fork"), top).with_profile(cosim::Profile::rtl());
        let o = run(&s, &RunOptions { dut: Some(bare), host: Some(host), ..Default::default() });
        assert!(!o.passed && o.mismatches.iter().chain(o.warnings.iter()).any(|m| m.contains("has no port")) || format!("{:?}", o.diagnosis).contains("has no port"), "{top}: {:?}", o.mismatches);
    }
}
