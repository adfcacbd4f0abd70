//! The SystemVerilog examples under Verilator: `sv/examples/tb_can_top.sv`
//! (Wishbone), `sv/examples/tb_can_apb.sv` (the scoreboard fed from the
//! APB pins of rtl/can_apb), `sv/examples/tb_can_regport.sv` (fed from
//! the register-port pins of rtl/can_regport) and `sv/examples/tb_can_mcu.sv`
//! (fed from the Motorola-mode pins of rtl/can_top_mcu). Our rtl/ passes
//! with the golden model as scoreboard; the DE2 thesis wiring (rx tied
//! recessive) and a one-line mutant of rtl/ fail with the diagnosis.
//! Builds eight Verilator binaries (about half a minute each).

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

/// The directory of the libsja1000_model.so built with this test: cargo
/// builds the library's cdylib next to the test binary (target/<profile>/deps).
fn lib_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let dir = exe.parent().unwrap().to_path_buf();
    assert!(
        dir.join("libsja1000_model.so").is_file(),
        "libsja1000_model.so not next to the test binary in {}",
        dir.display()
    );
    dir
}

/// Verilates the example bench `top` (`sv/examples/<top>.sv`) over the
/// Verilog files of `rtl`, returns the binary.
fn build(top: &str, rtl: &Path, work: &Path) -> PathBuf {
    let sv = root().join("crates/model-ffi/sv");
    let lib = lib_dir();
    std::fs::create_dir_all(work).unwrap();
    let mut cmd = Command::new("verilator");
    cmd.args([
        "--binary",
        "--timing",
        "-Wno-fatal",
        "-Wno-lint",
        "-Wno-style",
        "--top-module",
        top,
        "-j",
        "2",
    ])
    .arg(format!("-I{}", rtl.display()))
    .arg(sv.join("sja1000_model_pkg.sv"))
    .arg(sv.join(format!("examples/{top}.sv")));
    for e in std::fs::read_dir(rtl).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_str().unwrap().to_string();
        if name.starts_with("can_") && name.ends_with(".v") {
            cmd.arg(p);
        }
    }
    cmd.arg("-LDFLAGS")
        .arg(format!(
            "-L{0} -lsja1000_model -Wl,-rpath,{0}",
            lib.display()
        ))
        .arg("--Mdir")
        .arg(work.join("obj"));
    let out = cmd.output().expect("verilator runs");
    assert!(
        out.status.success(),
        "verilator failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    work.join(format!("obj/V{top}"))
}

/// A one-line mutant of rtl/ in `work`: a completed transmission no longer
/// sets SR.TCS.
fn mutant_rtl(work: &Path) -> PathBuf {
    let mutant = work.join("mutant-rtl");
    std::fs::create_dir(&mutant).unwrap();
    for e in std::fs::read_dir(root().join("rtl")).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, mutant.join(p.file_name().unwrap())).unwrap();
    }
    let regs = mutant.join("can_regs.v");
    let src = std::fs::read_to_string(&regs).unwrap();
    let line = "if (tx_done) begin tbs <= 1'b1; tcs <= 1'b1; end";
    assert_eq!(
        src.matches(line).count(),
        1,
        "the line to mutate is in rtl/can_regs.v once"
    );
    std::fs::write(
        &regs,
        src.replace(line, "if (tx_done) begin tbs <= 1'b1; end"),
    )
    .unwrap();
    mutant
}

fn run(bin: &Path, args: &[&str]) -> (bool, String) {
    // cargo's LD_LIBRARY_PATH may name an older copy of the library
    // (target/<profile>), which would win over the binary's rpath.
    let out = Command::new(bin)
        .args(args)
        .env("LD_LIBRARY_PATH", lib_dir())
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.success(), text)
}

#[test]
fn the_sv_scoreboard_passes_our_rtl_and_diagnoses_the_thesis_wiring_and_a_mutant() {
    let work = tempfile::tempdir().unwrap();
    let bin = build("tb_can_top", &root().join("rtl"), &work.path().join("rtl"));
    let (ok, text) = run(&bin, &[]);
    assert!(ok && text.contains("SCOREBOARD PASS"), "{text}");
    let (ok, text) = run(&bin, &["+tied_rx"]);
    assert!(!ok, "{text}");
    assert!(
        text.contains("SCOREBOARD FAIL") && text.contains("RxNotFollowingTx"),
        "{text}"
    );
    assert!(text.contains("rx_i is tied to 1"), "{text}");

    let mutant = mutant_rtl(work.path());
    let bin = build("tb_can_top", &mutant, &work.path().join("mutant"));
    let (ok, text) = run(&bin, &[]);
    assert!(!ok, "{text}");
    assert!(
        text.contains("SCOREBOARD FAIL") && text.contains("DutDeviatesFromModel"),
        "{text}"
    );
    assert!(
        text.contains("register SR") && text.contains("TCS"),
        "{text}"
    );
}

/// `top` passes on rtl/ and fails on the one-line mutant with the diagnosis.
fn passes_rtl_and_diagnoses_the_mutant(top: &str) {
    let work = tempfile::tempdir().unwrap();
    let bin = build(top, &root().join("rtl"), &work.path().join("rtl"));
    let (ok, text) = run(&bin, &[]);
    assert!(ok && text.contains("SCOREBOARD PASS"), "{text}");
    let mutant = mutant_rtl(work.path());
    let bin = build(top, &mutant, &work.path().join("mutant"));
    let (ok, text) = run(&bin, &[]);
    assert!(!ok, "{text}");
    assert!(
        text.contains("SCOREBOARD FAIL")
            && text.contains("DutDeviatesFromModel")
            && text.contains("register SR")
            && text.contains("TCS"),
        "{text}"
    );
}

#[test]
fn the_sv_scoreboard_fed_from_apb_pins_passes_can_apb_and_diagnoses_a_mutant() {
    passes_rtl_and_diagnoses_the_mutant("tb_can_apb");
}

#[test]
#[ignore = "two Verilator builds (about 25 s); the APB bench covers the same package in the default suite; run with: cargo test --release -p model-ffi --test suite sv_bench -- --ignored"]
fn the_sv_scoreboard_fed_from_register_port_pins_passes_can_regport_and_diagnoses_a_mutant() {
    passes_rtl_and_diagnoses_the_mutant("tb_can_regport");
}

#[test]
#[ignore = "two Verilator builds (about 25 s); the APB bench covers the same package in the default suite; run with: cargo test --release -p model-ffi --test suite sv_bench -- --ignored"]
fn the_sv_scoreboard_fed_from_motorola_pins_passes_can_top_mcu_and_diagnoses_a_mutant() {
    passes_rtl_and_diagnoses_the_mutant("tb_can_mcu");
}
