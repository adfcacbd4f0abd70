//! The Motorola host on our MODE-selectable top (`can_top_mcu`, MODE low)
//! and on the golden model through its bridge, a slave that never answers
//! a read, and the top's Verilator lint and Yosys synthesis (no latch, no
//! combinational loop).

use std::process::Command;

use bfm::I8051Timing;
use cosim::{DutChoice, HostBfm, TbConfig, Testbench, i8051_timing_for_rtl};

fn cfg(dut: DutChoice, host: HostBfm) -> TbConfig {
    TbConfig { scenario: "motorola".into(), dut, host, ..TbConfig::default() }
}

fn host() -> HostBfm {
    let c = TbConfig::default();
    HostBfm::Motorola(i8051_timing_for_rtl(c.host_hz, c.can_hz))
}

#[test]
fn the_motorola_host_writes_and_reads_back_on_can_top_mcu_and_the_model() {
    for dut in [DutChoice::Rtl, DutChoice::Model] {
        let mut tb = Testbench::new(cfg(dut.clone(), host())).unwrap();
        if matches!(dut, DutChoice::Rtl) {
            assert!(tb.dut_name().contains("can_top_mcu"), "{}", tb.dut_name());
        }
        for (a, d) in [(4u8, 0x5A), (5, 0xA5), (9, 0x3C)] {
            tb.write(a, d).unwrap();
            assert_eq!(tb.read(a).unwrap(), d, "{dut:?} register {a}");
        }
        assert!(tb.violations().is_empty(), "{:?}", tb.violations());
    }
}

#[test]
fn a_slave_that_never_answers_a_read_is_named_by_the_monitor() {
    let t = I8051Timing::default();
    let mut tb = Testbench::new(cfg(DutChoice::Bundled("cosim_mcu_mute".into()), HostBfm::Motorola(t))).unwrap();
    // No acknowledge on this bus: the access ends on time with the pull-ups.
    assert_eq!(tb.read(4).unwrap(), 0xFF);
    let v = tb.violations();
    let want = format!("read of register 0x04: E high for {} host cycles and the slave never drove AD (the master read the pull-ups, 0xFF)", t.rd);
    assert!(v.iter().any(|x| x.rule == "motorola.no_read_data" && x.message == want), "{v:?}");
}

/// The MODE strap is bound when the top has it (a Motorola-only top has
/// none); an 8051-only top is refused on the first Motorola pin it lacks.
#[test]
fn an_8051_top_is_refused_naming_the_motorola_pin_it_lacks() {
    let e = Testbench::new(cfg(DutChoice::Bundled("can_top_8051".into()), host())).err().unwrap();
    assert!(e.to_string().contains("has no port `ale_as_i`"), "{e}");
}

fn rtl_files() -> (std::path::PathBuf, Vec<String>) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../rtl");
    let mut v: Vec<String> = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).filter(|n| n.ends_with(".v")).collect();
    v.sort();
    (dir, v)
}

#[test]
fn can_top_mcu_passes_verilator_lint_with_every_warning_on() {
    let (dir, files) = rtl_files();
    let o = Command::new("verilator").current_dir(&dir).args(["--lint-only", "-Wall", "--top-module", "can_top_mcu", "-I."]).args(&files).output().expect("verilator runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && !err.contains("%Warning"), "{err}");
}

#[test]
fn can_top_mcu_synthesises_without_latches_or_combinational_loops() {
    let (dir, files) = rtl_files();
    let script = format!(
        "read_verilog -I. {}; synth -top can_top_mcu -run begin:fine; check -assert; select -assert-none t:$dlatch* t:$_DLATCH*",
        files.join(" ")
    );
    let o = Command::new("yosys").current_dir(&dir).args(["-q", "-p", &script]).output().expect("yosys runs");
    assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
}
