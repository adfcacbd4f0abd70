//! The AXI4-Lite and APB hosts on our wrappers (`can_axi4lite`,
//! `can_apb`), on the golden model through their bridges, and against
//! slaves that stop answering; the wrappers' Verilator lint and Yosys
//! synthesis (no latch, no combinational loop).

use std::process::Command;

use bfm::{ApbConfig, Axi4LiteConfig, BfmError};
use cosim::{DutChoice, HostBfm, TbConfig, TbError, Testbench};

fn cfg(dut: DutChoice, host: HostBfm) -> TbConfig {
    TbConfig { scenario: "axi-apb".into(), dut, host, ..TbConfig::default() }
}

fn hosts() -> [HostBfm; 3] {
    [
        HostBfm::Axi4Lite(Axi4LiteConfig { aw_delay: 2, ready_delay: 1, ..Default::default() }),
        HostBfm::Apb(ApbConfig::default()),
        HostBfm::Apb(ApbConfig { apb4: false, idle_cycles: 2, ..Default::default() }),
    ]
}

#[test]
fn both_hosts_write_and_read_back_on_the_wrappers_and_the_model() {
    for host in hosts() {
        for dut in [DutChoice::Rtl, DutChoice::Model] {
            let mut tb = Testbench::new(cfg(dut.clone(), host)).unwrap();
            if matches!(dut, DutChoice::Rtl) {
                let top = if matches!(host, HostBfm::Axi4Lite(_)) { "can_axi4lite" } else { "can_apb" };
                assert!(tb.dut_name().contains(top), "{}", tb.dut_name());
            }
            // ACR..AMR (BasicCAN, reset mode) and the TEST register.
            for (a, d) in [(4u8, 0x5A), (5, 0xA5), (9, 0x3C)] {
                tb.write(a, d).unwrap();
                assert_eq!(tb.read(a).unwrap(), d, "{host:?} {dut:?} register {a}");
            }
            assert!(tb.violations().is_empty(), "{:?}", tb.violations());
        }
    }
}

fn stopped(host: HostBfm, top: &str, write: bool) -> String {
    let mut tb = Testbench::new(TbConfig { op_timeout_cycles: 1_000, monitor_ack_timeout: 500, ..cfg(DutChoice::Bundled(top.into()), host) }).unwrap();
    let r = if write { tb.write(4, 1).map(|_| ()) } else { tb.read(4).map(|_| ()) };
    match r {
        Err(e @ TbError::Host { error: BfmError::Stopped { .. }, .. }) => e.to_string(),
        other => panic!("{top}: expected a stopped transfer, got {other:?}"),
    }
}

#[test]
fn an_axi_slave_that_never_raises_bvalid_is_diagnosed_after_its_data_phase() {
    let host = HostBfm::Axi4Lite(Axi4LiteConfig { period_ps: 20_000, ..Default::default() });
    let e = stopped(host, "cosim_axi_nob", true);
    assert!(e.contains("timed out after 1000 host cycles: AW accepted at "), "{e}");
    assert!(e.contains(", BVALID never raised"), "{e}");
    assert!(e.contains(" us") || e.contains(" ns"), "a time, not a cycle: {e}");
}

#[test]
fn an_apb_slave_holding_pready_low_is_diagnosed_in_its_access_phase() {
    let host = HostBfm::Apb(ApbConfig { period_ps: 20_000, ..Default::default() });
    let e = stopped(host, "cosim_apb_stuck", false);
    assert!(e.contains("APB access phase (from "), "{e}");
    assert!(e.contains("PREADY low for 999 host clocks"), "{e}");
    assert!(e.contains("APB access phase: PREADY low for 500 host clocks"), "the monitor's sentence: {e}");
}

fn rtl_files() -> (std::path::PathBuf, Vec<String>) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../rtl");
    let mut v: Vec<String> = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).filter(|n| n.ends_with(".v")).collect();
    v.sort();
    (dir, v)
}

const WRAPPERS: [&str; 2] = ["can_axi4lite", "can_apb"];

#[test]
fn the_bus_wrappers_pass_verilator_lint_with_every_warning_on() {
    let (dir, files) = rtl_files();
    for top in WRAPPERS {
        let o = Command::new("verilator").current_dir(&dir).args(["--lint-only", "-Wall", "--top-module", top, "-I."]).args(&files).output().expect("verilator runs");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success() && !err.contains("%Warning"), "{top}:\n{err}");
    }
}

/// Yosys: synthesis to generic cells, `check -assert` (no combinational
/// loop, no undriven or multiply driven net) and no latch left.
fn yosys_synth(dir: &std::path::Path, files: &[String], top: &str) -> std::process::Output {
    let script = format!(
        "read_verilog -I. {}; synth -top {top} -run begin:fine; check -assert; select -assert-none t:$dlatch* t:$_DLATCH*",
        files.join(" ")
    );
    Command::new("yosys").current_dir(dir).args(["-q", "-p", &script]).output().expect("yosys runs")
}

#[test]
fn the_bus_wrappers_synthesise_without_latches_or_combinational_loops() {
    let (dir, files) = rtl_files();
    for top in WRAPPERS {
        let o = yosys_synth(&dir, &files, top);
        assert!(o.status.success(), "{top}: {}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    }
    // The same check refuses a latch and a loop.
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("l.v"), "module l(input e, input d, output reg q, output y);\n always @* if (e) q = d;\n wire a = ~y & d; assign y = a;\nendmodule\n").unwrap();
    for bad in ["l"] {
        let o = yosys_synth(tmp.path(), &["l.v".into()], bad);
        assert!(!o.status.success(), "a latch and a loop pass the check");
    }
}
