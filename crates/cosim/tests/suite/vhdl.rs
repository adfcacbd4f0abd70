//! VHDL cores through GHDL, on the VHDL twin of the echo
//! fixture (`tb/fixtures/vhdl/`: a package and the entity, VHDL-2008):
//! analysed in dependency order, `ghdl --synth --out=verilog`, verilated
//! and run in lockstep with the echo fixture's Rust twin; a one-line
//! mutant of it diverges; GHDL's errors name file and line; the GHDL step
//! is cached; a Verilog top instantiating the VHDL entity builds too.
//! GHDL is installed by scripts/setup.sh: without it these tests fail and
//! say so.

use std::path::{Path, PathBuf};

use cosim::vhdl::{VhdlOptions, VhdlStandard};
use cosim::{CompareConfig, DutChoice, ExternalCore, HostBfm, ReferenceChoice, TbConfig, TbError, Testbench};
use diagnose::DivergenceKind;

fn fixture_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tb/fixtures/vhdl")
}

fn require_ghdl() {
    let ok = std::process::Command::new("ghdl").arg("--version").output().is_ok_and(|o| o.status.success());
    assert!(ok, "`ghdl` was not found: these tests need GHDL; run scripts/setup.sh (it installs Debian's ghdl)");
}

fn vhdl08() -> VhdlOptions {
    VhdlOptions { standard: VhdlStandard::V08, ..VhdlOptions::default() }
}

/// A copy of the fixture's sources in `to`, `edit` applied to the
/// entity's text (the build caches are keyed on paths and contents: each
/// copy is a build of its own).
fn copy_fixture(to: &Path, edit: impl Fn(&str) -> String) {
    std::fs::create_dir_all(to).unwrap();
    for f in ["cosim_echo_pkg.vhd", "cosim_echo_vhd.vhd"] {
        let text = std::fs::read_to_string(fixture_dir().join(f)).unwrap();
        let text = if f == "cosim_echo_vhd.vhd" { edit(&text) } else { text };
        std::fs::write(to.join(f), text).unwrap();
    }
}

fn lockstep_on(core: ExternalCore) -> Testbench {
    Testbench::new(TbConfig {
        scenario: "vhdl-echo".into(),
        dut: DutChoice::External(core),
        host: HostBfm::Wishbone,
        lockstep: Some((ReferenceChoice::Echo, CompareConfig { tx_edge_tolerance: 2, ..CompareConfig::default() })),
        ..TbConfig::default()
    })
    .unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn vhdl_echo_twin_runs_in_lockstep_with_the_echo_model() {
    require_ghdl();
    let core = ExternalCore { dir: fixture_dir(), top: "cosim_echo_vhd".into(), vhdl: vhdl08(), ..Default::default() };
    core.check().unwrap();
    let mut tb = lockstep_on(core);
    for k in 0..8u8 {
        tb.write(k + 2, 0xF0 | k).unwrap();
        assert_eq!(tb.read(k + 2).unwrap(), 0xF0 | k);
    }
    tb.write(0, 0x00).unwrap();
    tb.run_bits(5).unwrap();
    tb.write(0, 0x01).unwrap();
    tb.run_bits(5).unwrap();
    // Echo mode: tx follows rx (the bus, tx looped) through one flop.
    tb.write(0, 0x02).unwrap();
    tb.run_bits(2).unwrap();
    tb.write(1, 0x01).unwrap();
    tb.run_bits(2).unwrap();
    assert!(!tb.pins().irq_n, "irq_on low with register 1 bit 0 set");
    assert_eq!(tb.read(31).unwrap(), 1, "address 31 reads rx_i");
    let c = tb.comparator().unwrap();
    assert!(c.divergence().is_none(), "{:?}", c.divergence());
    assert!(c.compared_bits >= 10, "{}", c.compared_bits);
    assert_eq!(c.compared_reads, 9);
    assert!(tb.violations().is_empty(), "{:?}", tb.violations());
    let rec = tb.record();
    assert!(rec.bus_bits.iter().any(|b| !b.bus) && rec.bus_bits.iter().any(|b| b.bus), "tx reached the bus both ways");
}

/// What the lockstep still catches through GHDL: bit 7 of every register
/// stuck at 0 in the VHDL is a register-read divergence 0xFF vs 0x7F.
#[test]
fn a_mutated_vhdl_echo_diverges_at_the_read() {
    require_ghdl();
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().join("mutant");
    copy_fixture(&dir, |t| {
        let m = t.replace("mem(a) <= wb_dat_i;", "mem(a) <= '0' & wb_dat_i(6 downto 0);");
        assert_ne!(m, t, "the mutation applies");
        m
    });
    let core = ExternalCore { dir, top: "cosim_echo_vhd".into(), vhdl: vhdl08(), ..Default::default() };
    let mut tb = lockstep_on(core);
    tb.write(4, 0xFF).unwrap();
    let e = tb.read(4).unwrap_err();
    assert!(matches!(e, TbError::Diverged(_)), "{e}");
    let d = tb.record().divergence.unwrap();
    assert_eq!((d.kind, d.expected, d.seen), (DivergenceKind::RegisterRead, 0xFF, 0x7F));
}

/// GHDL's first error, with file and line, in one paragraph; the
/// standard is the profile's: the fixture's VHDL-2008 condition fails as
/// VHDL-93 at its line.
#[test]
fn ghdl_errors_name_file_and_line_and_the_standard_is_selectable() {
    require_ghdl();
    let scratch = tempfile::tempdir().unwrap();
    let cache = scratch.path().join("cache");
    let as93 = ExternalCore {
        dir: fixture_dir(),
        top: "cosim_echo_vhd".into(),
        vhdl: VhdlOptions { standard: VhdlStandard::V93, ..VhdlOptions::default() },
        ..Default::default()
    };
    let e = cosim::vhdl::lower(&as93, &cache).unwrap_err().to_string();
    let line = std::fs::read_to_string(fixture_dir().join("cosim_echo_vhd.vhd"))
        .unwrap()
        .lines()
        .position(|l| l.contains("when mem(0)(1)"))
        .unwrap()
        + 1;
    assert!(e.contains(&format!("cosim_echo_vhd.vhd:{line}:")) && e.contains("VHDL-93"), "{e}");
    assert!(!e.contains('\n'), "one paragraph: {e}");
    // The same sources as VHDL-2008 go through.
    let as08 = ExternalCore { vhdl: vhdl08(), ..as93.clone() };
    let lowered = cosim::vhdl::lower(&as08, &cache).unwrap().expect("VHDL found");
    let v = std::fs::read_to_string(lowered.files.last().unwrap()).unwrap();
    assert!(v.contains("module cosim_echo_vhd"), "GHDL's Verilog: {}", &v[..v.len().min(400)]);
    // An undeclared name: GHDL's own words at file:line:column.
    let bad = scratch.path().join("bad");
    std::fs::create_dir_all(&bad).unwrap();
    std::fs::write(
        bad.join("bad.vhd"),
        "library ieee; use ieee.std_logic_1164.all;\nentity bad is port (a : in std_logic; b : out std_logic); end;\narchitecture rtl of bad is begin\n  b <= a and c;\nend;\n",
    )
    .unwrap();
    let core = ExternalCore { dir: bad.clone(), top: "bad".into(), ..Default::default() };
    core.check().unwrap();
    let e = core.build_in(&cache).unwrap_err().to_string();
    assert!(e.contains("bad.vhd:4:14:") && e.contains("\"c\""), "{e}");
    // A top that is neither a VHDL entity nor a Verilog module.
    let e = ExternalCore { top: "nope".into(), ..core }.check().unwrap_err().to_string();
    assert!(e.contains("no `entity nope` (VHDL) or `module nope`"), "{e}");
}

/// The GHDL step is a cache entry like the Verilator build: a second
/// lowering reuses the first's Verilog (same file, not rewritten); a
/// changed source is a new entry.
#[test]
fn the_ghdl_step_is_cached_on_the_sources() {
    require_ghdl();
    let scratch = tempfile::tempdir().unwrap();
    let cache = scratch.path().join("cache");
    let src = scratch.path().join("src");
    copy_fixture(&src, |t| t.to_string());
    let core = ExternalCore { dir: src.clone(), top: "cosim_echo_vhd".into(), vhdl: vhdl08(), ..Default::default() };
    let first = cosim::vhdl::lower(&core, &cache).unwrap().unwrap();
    let product = first.files.last().unwrap().clone();
    let stamp = std::fs::metadata(&product).unwrap().modified().unwrap();
    std::thread::sleep(std::time::Duration::from_millis(20));
    let again = cosim::vhdl::lower(&core, &cache).unwrap().unwrap();
    assert_eq!(again.files, first.files);
    assert_eq!(std::fs::metadata(&product).unwrap().modified().unwrap(), stamp, "not rewritten");
    copy_fixture(&src, |t| t.replace("clkdiv <= not clkdiv;", "clkdiv <= not clkdiv; -- changed"));
    let changed = cosim::vhdl::lower(&core, &cache).unwrap().unwrap();
    assert_ne!(changed.files.last(), first.files.last(), "a changed source is a new entry");
    let entries = std::fs::read_dir(&cache).unwrap().filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().starts_with("ghdl-")).count();
    assert_eq!(entries, 2);
}

/// Mixed sources: a Verilog top instantiating the VHDL entity; GHDL
/// synthesises the entity the Verilog names, Verilator takes both.
#[test]
fn a_verilog_top_over_a_vhdl_entity_builds_and_runs() {
    require_ghdl();
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path().join("mixed");
    copy_fixture(&dir, |t| t.to_string());
    let ports = ["wb_clk_i", "wb_rst_i", "wb_dat_i", "wb_dat_o", "wb_cyc_i", "wb_stb_i", "wb_we_i", "wb_adr_i", "wb_ack_o", "clk_i", "rx_i", "tx_o", "bus_off_on", "irq_on", "clkout_o"];
    let conns: Vec<String> = ports.iter().map(|p| format!(".{p}({p})")).collect();
    std::fs::write(
        dir.join("echo_wrap.v"),
        format!(
            "// A Verilog top over the VHDL echo.\nmodule echo_wrap(input wb_clk_i, input wb_rst_i, input [7:0] wb_dat_i, output [7:0] wb_dat_o,\n  input wb_cyc_i, input wb_stb_i, input wb_we_i, input [7:0] wb_adr_i, output wb_ack_o,\n  input clk_i, input rx_i, output tx_o, output bus_off_on, output irq_on, output clkout_o);\n  cosim_echo_vhd u_echo ({});\nendmodule\n",
            conns.join(", ")
        ),
    )
    .unwrap();
    let core = ExternalCore { dir, top: "echo_wrap".into(), vhdl: vhdl08(), ..Default::default() };
    core.check().unwrap();
    let mut tb = lockstep_on(core);
    tb.write(7, 0x3C).unwrap();
    assert_eq!(tb.read(7).unwrap(), 0x3C);
    tb.write(0, 0x00).unwrap();
    tb.run_bits(3).unwrap();
    assert!(tb.comparator().unwrap().divergence().is_none());
}
