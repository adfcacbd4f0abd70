//! The generated C headers, the C driver, the `_hw.tcl` and the Verilog
//! include, checked with the real tools (gcc, tclsh, iverilog) against the
//! register map. Each tool missing is a failure with a clear message: these
//! tests are the proof that the generated files work.

use regmap::generate::{self, GenOptions, HeaderOptions, Spacing, TclOptions};
use regmap::{registers, Mode};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

const CFLAGS: &[&str] = &["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"];

fn c_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("c")
}

fn generate_into(dir: &Path, spacing: Spacing) {
    let opts = GenOptions { header: HeaderOptions { spacing, ..Default::default() }, ..Default::default() };
    generate::write_all(dir, &opts).expect("write generated files");
}

/// Runs a command; panics with its output if it fails or cannot start.
fn run(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap_or_else(|e| panic!("cannot run {cmd:?}: {e} (is the tool installed?)"));
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{cmd:?} failed ({}):\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

fn gcc(dir: &Path, extra: &[&str]) -> Command {
    let mut c = Command::new("gcc");
    c.args(CFLAGS).arg("-I").arg(c_dir()).arg("-I").arg(dir).args(extra);
    c
}

/// `#define NAME value` lines with a plain number, `(number)` or `(0xNN)`.
fn parse_defines(text: &str) -> BTreeMap<String, i64> {
    let mut m = BTreeMap::new();
    for line in text.lines() {
        let Some(rest) = line.strip_prefix("#define ") else { continue };
        let mut it = rest.splitn(2, ' ');
        let name = it.next().unwrap();
        if name.contains('(') {
            continue; // function-like
        }
        let val = it.next().unwrap_or("").split("/*").next().unwrap().trim();
        let val = val.trim_start_matches('(').trim_end_matches(')');
        let parsed = if let Some(h) = val.strip_prefix("0x") {
            i64::from_str_radix(h, 16).ok()
        } else {
            val.trim_end_matches("UL").parse().ok()
        };
        if let Some(v) = parsed {
            m.insert(name.to_string(), v);
        }
    }
    m
}

/// What the table says every numeric macro of the header must be.
fn expected_macros() -> BTreeMap<String, i64> {
    let mut m = BTreeMap::new();
    for mode in Mode::ALL {
        for r in registers(mode) {
            let root = format!("CAN_SJA_{}_{}", mode.tag(), r.name);
            m.insert(format!("{root}_REG"), r.addr as i64);
            if r.len > 1 {
                m.insert(format!("{root}_LEN"), r.len as i64);
            }
            for f in r.fields {
                m.insert(format!("{root}_{}_MSK", f.name), f.mask() as i64);
                m.insert(format!("{root}_{}_OFST", f.name), f.lsb as i64);
            }
        }
    }
    use regmap::frame;
    for (n, v) in [
        ("FI", frame::peli::FI),
        ("ID1", frame::peli::ID1),
        ("ID2", frame::peli::ID2),
        ("SFF_DATA", frame::peli::SFF_DATA),
        ("EFF_ID3", frame::peli::EFF_ID3),
        ("EFF_ID4", frame::peli::EFF_ID4),
        ("EFF_DATA", frame::peli::EFF_DATA),
    ] {
        m.insert(format!("CAN_SJA_PELI_FRAME_{n}_OFST"), v as i64);
    }
    m.insert("CAN_SJA_PELI_FRAME_SFF_ID2_RTR_MSK".into(), frame::peli::SFF_ID2_RTR as i64);
    m.insert("CAN_SJA_PELI_FRAME_EFF_ID4_RTR_MSK".into(), frame::peli::EFF_ID4_RTR as i64);
    for (n, v) in [("ID1", frame::basic::ID1), ("ID2", frame::basic::ID2), ("DATA", frame::basic::DATA)] {
        m.insert(format!("CAN_SJA_BASIC_FRAME_{n}_OFST"), v as i64);
    }
    m
}

#[test]
fn header_macros_equal_the_table_as_text_and_as_c_evaluates_them() {
    let tmp = tempfile::tempdir().unwrap();
    generate_into(tmp.path(), Spacing::Byte);
    let text = std::fs::read_to_string(tmp.path().join("can_sja_regs.h")).unwrap();
    let mut parsed = parse_defines(&text);
    assert_eq!(parsed.remove("CAN_SJA_SPACING"), Some(1));
    let expected = expected_macros();
    assert_eq!(parsed, expected, "header numeric macros differ from the register map");

    // The compiler's view: print every macro from C and compare again.
    let mut prog = String::from("#include <stdio.h>\n#include \"can_sja_regs.h\"\nint main(void)\n{\n");
    for name in expected.keys() {
        prog.push_str(&format!("    printf(\"{name} %ld\\n\", (long)({name}));\n"));
    }
    prog.push_str("    return 0;\n}\n");
    let src = tmp.path().join("dump.c");
    std::fs::write(&src, prog).unwrap();
    let exe = tmp.path().join("dump");
    run(gcc(tmp.path(), &[]).arg(&src).arg(c_dir().join("host_io_mem.c")).arg("-o").arg(&exe));
    let out = run(&mut Command::new(&exe));
    let from_c: BTreeMap<String, i64> = out
        .lines()
        .map(|l| {
            let (n, v) = l.split_once(' ').unwrap();
            (n.to_string(), v.parse().unwrap())
        })
        .collect();
    assert_eq!(from_c, expected, "C evaluates the macros differently from the register map");
}

#[test]
fn header_compiles_strictly_and_accesses_the_right_bytes_at_every_stride_and_lane() {
    for (spacing, lane) in [(Spacing::Byte, 0), (Spacing::Half, 0), (Spacing::Half, 1), (Spacing::Word, 0), (Spacing::Word, 2), (Spacing::Word, 3)] {
        let tmp = tempfile::tempdir().unwrap();
        let header = HeaderOptions::new("CAN_SJA", spacing).unwrap().with_lane(lane).unwrap();
        generate::write_all(tmp.path(), &GenOptions { header, ..Default::default() }).expect("write generated files");
        let hdr = tmp.path().join("can_sja_regs.h");
        run(gcc(tmp.path(), &["-fsyntax-only", "-x", "c"]).arg(&hdr));
        let exe = tmp.path().join("test_regs");
        run(gcc(tmp.path(), &[]).arg(c_dir().join("test_regs.c")).arg(c_dir().join("host_io_mem.c")).arg("-o").arg(&exe));
        let out = run(&mut Command::new(&exe));
        assert!(out.contains("all checks passed"), "{spacing:?} lane {lane}: {out}");
        let offset = spacing.stride() as u32 + lane;
        assert!(out.contains(&format!("offset of register 1: {offset})")), "{spacing:?} lane {lane}: {out}");
    }
}

#[test]
fn pio_header_compiles_and_times_out_without_ack() {
    let tmp = tempfile::tempdir().unwrap();
    generate_into(tmp.path(), Spacing::Byte);
    let exe = tmp.path().join("test_pio");
    run(gcc(tmp.path(), &[]).arg(c_dir().join("test_pio.c")).arg(c_dir().join("host_io_mem.c")).arg("-o").arg(&exe));
    let out = run(&mut Command::new(&exe));
    assert!(out.contains("all checks passed"), "{out}");
    // The edge-capture variant compiles too.
    let exe2 = tmp.path().join("test_pio_edge");
    run(gcc(tmp.path(), &["-DCAN_SJA_PIO_ACK_EDGE_CAPTURE", "-c"])
        .arg(c_dir().join("test_pio.c"))
        .arg("-o")
        .arg(&exe2));
}

#[test]
fn c_driver_compiles_strictly_and_drives_the_registers_as_the_data_sheet_says() {
    for spacing in [Spacing::Byte, Spacing::Word] {
        let tmp = tempfile::tempdir().unwrap();
        generate_into(tmp.path(), spacing);
        let exe = tmp.path().join("test_driver");
        run(gcc(tmp.path(), &[])
            .arg(c_dir().join("can_driver.c"))
            .arg(c_dir().join("test_driver.c"))
            .arg(c_dir().join("host_io_mem.c"))
            .arg("-o")
            .arg(&exe));
        if spacing == Spacing::Byte {
            // The test's expected bytes assume byte spacing (M(n) = base + n).
            let out = run(&mut Command::new(&exe));
            assert!(out.contains("all checks passed"), "{out}");
        }
    }
}

#[test]
fn hw_tcl_declares_the_wrapper_ports_and_interfaces() {
    let tmp = tempfile::tempdir().unwrap();
    let opts = TclOptions::default();
    std::fs::write(tmp.path().join("can_avalon_hw.tcl"), generate::hw_tcl(&opts)).unwrap();
    // Stub the Platform Designer commands: record every call, then print.
    let stub = r#"
set calls {}
proc package {args} {}
foreach cmd {set_module_property add_fileset set_fileset_property add_fileset_file add_interface
             set_interface_property set_interface_assignment add_interface_port} {
    proc $cmd {args} "lappend ::calls \[list $cmd \$args\]"
}
source [lindex $argv 0]
foreach c $::calls { puts [join [concat [lindex $c 0] [lindex $c 1]] " "] }
"#;
    let stub_path = tmp.path().join("stub.tcl");
    std::fs::write(&stub_path, stub).unwrap();
    let out = run(Command::new("tclsh").arg(&stub_path).arg(tmp.path().join("can_avalon_hw.tcl")));
    let lines: Vec<&str> = out.lines().collect();
    let has = |l: &str| lines.contains(&l);
    let ports: Vec<&str> = lines.iter().filter_map(|l| l.strip_prefix("add_interface_port ")).collect();
    let expect_ports = [
        "clock clk clk Input 1",
        "reset reset reset Input 1",
        "avalon_slave address address Input 8",
        "avalon_slave chipselect chipselect Input 1",
        "avalon_slave read read Input 1",
        "avalon_slave write write Input 1",
        "avalon_slave writedata writedata Input 8",
        "avalon_slave readdata readdata Output 8",
        "avalon_slave waitrequest waitrequest Output 1",
        "irq irq irq Output 1",
        "can can_clk can_clk Input 1",
        "can rx rx Input 1",
        "can tx tx Output 1",
        "can bus_off_on bus_off_on Output 1",
        "can clkout clkout Output 1",
    ];
    assert_eq!(ports, expect_ports);
    for l in [
        "set_module_property NAME can_avalon",
        "set_fileset_property QUARTUS_SYNTH TOP_LEVEL can_avalon",
        "add_interface avalon_slave avalon end",
        "set_interface_property avalon_slave addressUnits WORDS",
        "set_interface_property avalon_slave readWaitTime 0",
        "set_interface_property avalon_slave readLatency 0",
        "set_interface_property avalon_slave associatedClock clock",
        "set_interface_property avalon_slave associatedReset reset",
        "set_interface_property avalon_slave explicitAddressSpan 256",
        "add_interface irq interrupt end",
        "set_interface_property irq associatedAddressablePoint avalon_slave",
        "add_interface can conduit end",
        "set_interface_property reset associatedClock clock",
    ] {
        assert!(has(l), "missing `{l}` in:\n{out}");
    }
}

#[test]
fn verilog_include_elaborates_and_its_values_equal_the_table() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("sja1000_regs.vh"), generate::verilog_include()).unwrap();
    let mut names = Vec::new();
    for mode in Mode::ALL {
        let vp = if mode == Mode::PeliCan { "PC_" } else { "BC_" };
        for r in registers(mode) {
            names.push((format!("{vp}{}", r.name), r.addr as i64));
            if r.len > 1 {
                names.push((format!("{vp}{}_LEN", r.name), r.len as i64));
            }
            for f in r.fields {
                names.push((format!("{vp}{}_{}", r.name, f.name), f.mask() as i64));
                names.push((format!("{vp}{}_{}_BIT", r.name, f.name), f.lsb as i64));
            }
        }
    }
    // Two modules include it: the file must not rely on an include guard.
    let mut tb = String::from("module other;\n`include \"sja1000_regs.vh\"\nendmodule\nmodule tb;\n`include \"sja1000_regs.vh\"\ninitial begin\n");
    for (n, _) in &names {
        tb.push_str(&format!("  $display(\"{n} %0d\", {n});\n"));
    }
    tb.push_str("end\nendmodule\n");
    std::fs::write(tmp.path().join("tb.v"), tb).unwrap();
    let vvp = tmp.path().join("tb.vvp");
    run(Command::new("iverilog")
        .args(["-g2005", "-Wall", "-s", "tb", "-I"])
        .arg(tmp.path())
        .arg("-o")
        .arg(&vvp)
        .arg(tmp.path().join("tb.v")));
    let out = run(Command::new("vvp").arg("-n").arg(&vvp));
    let got: BTreeMap<String, i64> = out
        .lines()
        .filter_map(|l| l.split_once(' '))
        .filter_map(|(n, v)| Some((n.to_string(), v.trim().parse().ok()?)))
        .collect();
    let want: BTreeMap<String, i64> = names.into_iter().collect();
    assert_eq!(got, want);
    // Verilator (used by cosim) must accept it too.
    let lint = tmp.path().join("lint.v");
    std::fs::write(&lint, "module lint;\n`include \"sja1000_regs.vh\"\nendmodule\n").unwrap();
    run(Command::new("verilator")
        .args(["--lint-only", "-Wall", "-Wno-UNUSEDPARAM"])
        .arg(format!("-I{}", tmp.path().display()))
        .arg(&lint));
}
