//! The opencores core as its default build has it (no `CAN_WISHBONE_IF`:
//! the 8051 bus with an `inout` port) runs the whole regression list with
//! `--host i8051`, as `cancosim regress --external upstream=DIR --profile
//! opencores-can --waivers tb/waivers/opencores-upstream.toml --host i8051`
//! does: the profile's `[access.i8051]` (`inout-drive`) has the kit wrap the
//! core in the split-port shell (`cosim::i8051_shell`), next to the
//! Wishbone build with `--host wishbone`. Needs the core:
//! `CAN_UPSTREAM_DIR` = its `rtl/verilog` directory (never part of this
//! repository).
//!
//! Asserted: the 8051 build passes exactly the scenarios the Wishbone
//! build passes (measured 2026-11-26: 25 of 27 on both, one skipped: host
//! wiring fixed) and fails the other two exactly as their
//! `[[expected-failure]]` entries for its host record (D6 and D8c/D8d, the
//! same deviations as through Wishbone), every scenario builds, binds and
//! runs to a verdict, every host access completes and the 8051 monitor sees
//! no violation. The pin waivers that a slower host's later IR read used to
//! overrun are bounded by that read (`until-read = "IR"`), not by a count.
//!
//! The second test runs the other lists on both builds: the Wishbone
//! build's verdicts as docs/opencores-deviations.md records them, and on
//! the 8051 build a clean verdict (pass, skip or the exact expected failure)
//! on every scenario.

use scenario::regress::Status;
use scenario::{DutKind, DutSpec, HostBfm, RegressOptions, RunOptions, load_list, regress, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
#[ignore = "needs the opencores core: CAN_UPSTREAM_DIR=<its rtl/verilog>"]
fn upstream_8051_build_runs_the_suite_next_to_its_wishbone_build() {
    let src = PathBuf::from(std::env::var("CAN_UPSTREAM_DIR").expect("set CAN_UPSTREAM_DIR"));
    let waivers = vec![root().join("tb/waivers/opencores-upstream.toml")];
    let s = load_list(root().join("tb/regression.list")).unwrap();
    let profile = cosim::Profile::load(root().join("tb/profiles/opencores-can.toml")).unwrap();
    assert!(profile.i8051_inout_drive.is_some(), "the profile declares the 8051 build's inout port");
    // As `regress --external` builds them: the 8051 build without the
    // define, the Wishbone build with it.
    let external = |defines: Vec<String>| DutSpec {
        name: "upstream".into(),
        kind: DutKind::External { path: src.clone(), top: "can_top".into(), defines, includes: vec![src.clone()] },
        profile: None,
    }
    .with_profile(profile.clone());
    let i8051 = external(Vec::new());
    let wishbone = external(vec!["CAN_WISHBONE_IF".into()]);
    let opts = |host| RegressOptions {
        jobs: 2,
        host,
        waivers: waivers.clone(),
        collect: waivers::CollectMode::StopAtFirst,
        ..Default::default()
    };
    let on_8051 = regress(
        &s,
        std::slice::from_ref(&i8051),
        &opts(Some(HostBfm::I8051)),
    );
    let on_wb = regress(&s, &[wishbone], &opts(Some(HostBfm::Wishbone)));
    eprintln!("{}\n{}", on_wb.to_table(), on_8051.to_table());
    assert_eq!(on_8051.cells.len(), s.len());
    let passed = |r: &scenario::regress::RegressReport| -> Vec<String> {
        r.cells.iter().filter(|c| matches!(c.status, Status::Pass)).map(|c| c.scenario.clone()).collect()
    };
    // (scenario, deviation) of each expected failure; the entry ids differ
    // by host (their signatures are exact, bits included).
    let xfails = |r: &scenario::regress::RegressReport| -> Vec<(String, String)> {
        r.cells
            .iter()
            .filter_map(|c| match &c.status {
                Status::ExpectedFailure { deviation, .. } => Some((c.scenario.clone(), deviation.clone())),
                _ => None,
            })
            .collect()
    };
    let two = vec![
        ("basic-sleep-wakeup".to_string(), "D6".to_string()),
        ("basic-overrun-abort".to_string(), "D8c/D8d".to_string()),
    ];
    assert_eq!(passed(&on_wb).len(), 25, "the Wishbone build's verdicts moved: {:?}", passed(&on_wb));
    assert_eq!(xfails(&on_wb), two, "the Wishbone build's expected failures");
    assert_eq!(passed(&on_8051), passed(&on_wb), "the 8051 build passes what the Wishbone build passes");
    assert_eq!(xfails(&on_8051), two, "the 8051 build fails the same two, as recorded for its host");
    for c in &on_8051.cells {
        if let Status::ExpectedFailure { id, .. } = &c.status {
            assert!(id.ends_with("-i8051"), "{}: the entry recorded through the 8051 bus, not {id}", c.scenario);
        }
    }
    for c in &on_8051.cells {
        assert!(
            !matches!(c.status, Status::Error(_)),
            "{}: {:?}",
            c.scenario,
            c.status
        );
    }
    for sc in s.iter().filter(|s| s.host_fixed.is_none()) {
        let o = run(
            sc,
            &RunOptions {
                dut: Some(i8051.clone()),
                host: Some(HostBfm::I8051),
                waivers: waivers.clone(),
                collect: waivers::CollectMode::Collect,
                ..Default::default()
            },
        );
        assert!(
            o.record.host_ops.iter().all(|op| op.error.is_none()),
            "{}: a host access failed",
            sc.name
        );
        assert!(
            o.record
                .violations
                .iter()
                .all(|v| !v.rule.starts_with("i8051.")),
            "{}: {:?}",
            sc.name,
            o.record.violations
        );
        assert!(
            !o.record.host_ops.is_empty(),
            "{}: no host access made",
            sc.name
        );
    }
}

/// Passed and expected failures per list on the Wishbone build, as
/// docs/opencores-deviations.md records them.
const WISHBONE: &[(&str, usize, usize)] = &[
    ("tb/registers.list", 3, 6),
    ("tb/coverage.list", 9, 4),
    ("tb/mutation-holes.list", 36, 9),
    ("tb/conformance/list", 114, 6),
];

#[test]
#[ignore = "needs the opencores core: CAN_UPSTREAM_DIR=<its rtl/verilog>; runs four lists on two builds (minutes)"]
fn upstream_8051_build_gives_a_clean_verdict_on_every_list() {
    let src = PathBuf::from(std::env::var("CAN_UPSTREAM_DIR").expect("set CAN_UPSTREAM_DIR"));
    let waivers = vec![root().join("tb/waivers/opencores-upstream.toml")];
    let profile = cosim::Profile::load(root().join("tb/profiles/opencores-can.toml")).unwrap();
    let external = |defines: Vec<String>| DutSpec {
        name: "upstream".into(),
        kind: DutKind::External { path: src.clone(), top: "can_top".into(), defines, includes: vec![src.clone()] },
        profile: None,
    }
    .with_profile(profile.clone());
    let opts = |host| RegressOptions { jobs: 2, host: Some(host), waivers: waivers.clone(), collect: waivers::CollectMode::StopAtFirst, ..Default::default() };
    let mut open_seen = Vec::new();
    for (list, passed, xfails) in WISHBONE {
        let s = load_list(root().join(list)).unwrap();
        let wb = regress(&s, &[external(vec!["CAN_WISHBONE_IF".into()])], &opts(HostBfm::Wishbone));
        let count = |r: &scenario::regress::RegressReport, f: fn(&Status) -> bool| r.cells.iter().filter(|c| f(&c.status)).count();
        assert_eq!(
            (count(&wb, |s| matches!(s, Status::Pass)), count(&wb, |s| matches!(s, Status::ExpectedFailure { .. }))),
            (*passed, *xfails),
            "{list}: the Wishbone build's verdicts moved\n{}",
            wb.to_table()
        );
        assert!(wb.cells.iter().all(|c| c.status.ok()), "{list} on the Wishbone build\n{}", wb.to_table());
        let on = regress(&s, &[external(Vec::new())], &opts(HostBfm::I8051));
        assert_eq!(on.cells.len(), s.len(), "{list}: every scenario ran on the 8051 build");
        for c in &on.cells {
            assert!(!matches!(c.status, Status::Error(_)), "{list}: {}: {:?}", c.scenario, c.status);
            if !c.status.ok() {
                open_seen.push(c.scenario.clone());
            }
            if let Status::ExpectedFailure { id, .. } = &c.status {
                // Held through the 8051 bus: an entry for every host (placed by step) or its own.
                let e = on.cells.iter().find(|x| x.scenario == c.scenario).and_then(|x| x.xfail.as_ref()).map(|r| r.entry.clone()).unwrap();
                assert!(e.hosts.iter().any(|h| h == "i8051"), "{}: `{id}` names the 8051 bus", c.scenario);
            }
        }
    }
    assert!(open_seen.is_empty(), "scenarios without a clean verdict on the 8051 build: {open_seen:?}");
}
