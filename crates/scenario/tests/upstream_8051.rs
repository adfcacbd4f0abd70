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
//! build passes (measured 2026-11-25: 22 of 26 on both, one skipped: host
//! wiring fixed), every scenario builds, binds and runs to a verdict,
//! every host access completes and the 8051 monitor sees no violation.

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
    assert!(passed(&on_wb).len() >= 22, "the Wishbone build's verdicts moved: {:?}", passed(&on_wb));
    assert_eq!(passed(&on_8051), passed(&on_wb), "the 8051 build passes what the Wishbone build passes");
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
