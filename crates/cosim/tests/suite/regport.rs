//! The register-port host on our `can_regport` (on the CAN clock) and on
//! the golden model through its bridge; a port whose read data comes later
//! than the host's latency; the wrapper's Verilator lint and Yosys
//! synthesis (no latch, no combinational loop).

use std::process::Command;

use bfm::RegportConfig;
use cosim::{DutChoice, HostBfm, TbConfig, Testbench};

fn cfg(dut: DutChoice, rc: RegportConfig) -> TbConfig {
    TbConfig { scenario: "regport".into(), dut, host: HostBfm::Regport(rc), ..TbConfig::default() }
}

#[test]
fn the_register_port_writes_and_reads_back_on_can_regport_and_the_model() {
    for dut in [DutChoice::Rtl, DutChoice::Model] {
        for rc in [RegportConfig::default(), RegportConfig { strobe: 3, separate_addr: false, ..Default::default() }] {
            let mut tb = Testbench::new(cfg(dut.clone(), rc)).unwrap();
            if matches!(dut, DutChoice::Rtl) {
                assert!(tb.dut_name().contains("can_regport"), "{}", tb.dut_name());
            }
            for (a, d) in [(4u8, 0x5A), (5, 0xA5), (9, 0x3C)] {
                tb.write(a, d).unwrap();
                assert_eq!(tb.read(a).unwrap(), d, "{dut:?} {rc:?} register {a}");
            }
            assert!(tb.violations().is_empty(), "{:?}", tb.violations());
        }
    }
}

#[test]
fn a_host_that_reads_before_the_data_is_there_is_told_when_it_came() {
    let rc = RegportConfig { read_latency: 2, ..Default::default() };
    let mut tb = Testbench::new(cfg(DutChoice::Rtl, rc)).unwrap();
    tb.write(4, 0x5A).unwrap();
    assert_ne!(tb.read(4).unwrap(), 0x5A, "sampled too early");
    // The monitor watches the port until the next strobe.
    tb.write(5, 0).unwrap();
    let v = tb.violations();
    let want = "read data of register 0x04 changed from 0x00 to 0x5A 10 clocks after the strobe, later than its read latency of 2";
    assert!(v.iter().any(|x| x.rule == "regport.changed_while_valid" && x.message == want), "{v:?}");
}

fn rtl_files() -> (std::path::PathBuf, Vec<String>) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../rtl");
    let mut v: Vec<String> = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).filter(|n| n.ends_with(".v")).collect();
    v.sort();
    (dir, v)
}

#[test]
fn can_regport_passes_verilator_lint_with_every_warning_on() {
    let (dir, files) = rtl_files();
    let o = Command::new("verilator").current_dir(&dir).args(["--lint-only", "-Wall", "--top-module", "can_regport", "-I."]).args(&files).output().expect("verilator runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && !err.contains("%Warning"), "{err}");
}

#[test]
fn can_regport_synthesises_without_latches_or_combinational_loops() {
    let (dir, files) = rtl_files();
    let script = format!(
        "read_verilog -I. {}; synth -top can_regport -run begin:fine; check -assert; select -assert-none t:$dlatch* t:$_DLATCH*",
        files.join(" ")
    );
    let o = Command::new("yosys").current_dir(&dir).args(["-q", "-p", &script]).output().expect("yosys runs");
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
}
