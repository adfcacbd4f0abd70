//! `--host i8051`: every shipped scenario played on our RTL through its
//! 8051-bus wrapper (`rtl/can_top_8051.v`) with the 8051 BFM, in lockstep
//! with the golden model, with zero divergences; scenarios whose point is
//! their host wiring are skipped.

use diagnose::HostBus;
use scenario::regress::Status;
use scenario::{DutSpec, HostBfm, RegressOptions, RunOptions, Scenario, load_list, regress, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn host_name_parses() {
    assert_eq!(HostBfm::from_name("i8051"), Some(HostBfm::I8051));
    assert_eq!(HostBfm::from_name("8051"), Some(HostBfm::I8051));
    assert_eq!(HostBfm::I8051.name(), "i8051");
}

#[test]
fn whole_regression_list_on_rtl_through_the_8051_wrapper() {
    let s = load_list(root().join("tb/regression.list")).unwrap();
    assert!(s.len() >= 20, "the shipped list shrank: {}", s.len());
    let rep = regress(
        &s,
        &[DutSpec::rtl()],
        &RegressOptions {
            jobs: 2,
            host: Some(HostBfm::I8051),
            collect: waivers::CollectMode::Collect,
            ..Default::default()
        },
    );
    let table = rep.to_table();
    eprintln!("{table}");
    assert_eq!(rep.cells.len(), s.len());
    assert!(rep.passed(), "{table}");
    let skipped: Vec<&str> = rep
        .cells
        .iter()
        .filter(|c| matches!(c.status, Status::Skipped(_)))
        .map(|c| c.scenario.as_str())
        .collect();
    let fixed: Vec<&str> = s
        .iter()
        .filter(|s| s.host_fixed.is_some())
        .map(|s| s.name.as_str())
        .collect();
    assert_eq!(
        skipped, fixed,
        "exactly the scenarios with a fixed host wiring are skipped"
    );
    assert!(
        rep.cells.iter().all(|c| c.waived.is_empty()),
        "nothing waived: {table}"
    );
    // Zero divergences and 8051 cycles in the record, scenario by scenario.
    for sc in s.iter().filter(|s| s.host_fixed.is_none()) {
        let o = run(
            sc,
            &RunOptions {
                dut: Some(DutSpec::rtl()),
                host: Some(HostBfm::I8051),
                collect: waivers::CollectMode::Collect,
                ..Default::default()
            },
        );
        assert!(o.passed, "{}: {:?}", sc.name, o.mismatches);
        assert_eq!(o.record.host_bus, HostBus::I8051, "{}", sc.name);
        assert!(
            o.record.divergence.is_none(),
            "{}: {:?}",
            sc.name,
            o.record.divergence
        );
        let n = o
            .waivers
            .as_ref()
            .map(|r| r.failures.len() + r.waived.len())
            .unwrap_or(0);
        assert_eq!(n, 0, "{}: {:?}", sc.name, o.waivers);
        assert!(
            o.record.violations.is_empty(),
            "{}: {:?}",
            sc.name,
            o.record.violations
        );
        assert!(
            o.record.host_ops.iter().all(|op| op.error.is_none()),
            "{}: a host access failed",
            sc.name
        );
    }
}

/// The scenario format takes `bfm = "i8051"`.
#[test]
fn scenario_file_can_ask_for_the_8051_host() {
    let text = std::fs::read_to_string(root().join("tb/pelican-single-shot.toml")).unwrap();
    assert!(
        text.contains("bfm = \"wishbone\""),
        "the scenario names its host"
    );
    let text = text.replacen("bfm = \"wishbone\"", "bfm = \"i8051\"", 1);
    let s = Scenario::parse(&text, "inline.toml");
    match s {
        Ok(s) => assert_eq!(s.host, HostBfm::I8051),
        Err(e) => panic!("{e}"),
    }
    // A misspelt host names the choices.
    let bad = Scenario::parse(
        &text.replacen("bfm = \"i8051\"", "bfm = \"i8052\"", 1),
        "inline.toml",
    )
    .unwrap_err();
    assert!(bad.to_string().contains("\"i8051\""), "{bad}");
}
