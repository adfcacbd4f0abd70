//! The opencores core as its default build has it (no `CAN_WISHBONE_IF`:
//! the 8051 bus with an `inout` port) runs the whole regression list with
//! `--host i8051` through `cosim::i8051_inout_shell`, with the same waiver
//! file as its Wishbone build. Needs the core: `CAN_UPSTREAM_DIR` = its
//! `rtl/verilog` directory (never part of this repository).

use scenario::regress::Status;
use scenario::{DutSpec, HostBfm, RegressOptions, load_list, regress};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
#[ignore = "needs the opencores core: CAN_UPSTREAM_DIR=<its rtl/verilog>"]
fn upstream_8051_build_runs_the_suite_with_its_waivers() {
    let src = PathBuf::from(std::env::var("CAN_UPSTREAM_DIR").expect("set CAN_UPSTREAM_DIR"));
    // A private copy of the core's sources plus the shell (the directory
    // name keeps the waivers' `*opencores*` DUT glob matching).
    let dir = std::env::temp_dir().join(format!("opencores-8051-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for e in std::fs::read_dir(&src).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "v") {
            std::fs::copy(&p, dir.join(p.file_name().unwrap())).unwrap();
        }
    }
    std::fs::write(
        dir.join("cosim_i8051_shell.v"),
        cosim::i8051_inout_shell("can_top", "cs_can_i & rd_i"),
    )
    .unwrap();
    let s = load_list(root().join("tb/regression.list")).unwrap();
    let rep = regress(
        &s,
        &[DutSpec::external("upstream-8051", &dir, cosim::I8051_SHELL_TOP)],
        &RegressOptions {
            jobs: 2,
            host: Some(HostBfm::I8051),
            waivers: vec![root().join("tb/waivers/opencores-upstream.toml")],
            collect: waivers::CollectMode::Collect,
            ..Default::default()
        },
    );
    let table = rep.to_table();
    eprintln!("{table}");
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(rep.cells.len(), s.len());
    assert!(rep.passed(), "{table}");
    let skipped = rep.cells.iter().filter(|c| matches!(c.status, Status::Skipped(_))).count();
    assert_eq!(skipped, s.iter().filter(|s| s.host_fixed.is_some()).count());
}
