//! End to end: the built `cancosim` binary, given bad
//! input, exits non-zero with a one-line message that names the file and
//! the key (or the argument), and never panics or prints a backtrace.
//! Inputs: malformed and unknown keys, DLC > 8, IDs out of range, register
//! addresses out of range, clocks with no valid bit timing (scenario and
//! `bittiming`), a missing file, non-bits to `decode`, HDL that does not
//! compile, HDL that lacks a port, and a DUT that never acks.

use std::path::PathBuf;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A per-test, per-process scratch directory (tests run in parallel, and
/// two `cargo test` runs may share a target directory).
fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-bad-input").join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs `cancosim args` from the repository root, with a time bound (a
/// hang fails the test instead of blocking CI).
fn cancosim(args: &[&str], bound: Duration) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_cancosim"))
        .args(args)
        .current_dir(root())
        .env("RUST_BACKTRACE", "1")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("cancosim runs");
    let t = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if t.elapsed() > bound {
            let _ = child.kill();
            let out = child.wait_with_output().unwrap();
            panic!(
                "cancosim {args:?} still running after {bound:?} (a hang)\nstdout: {}\nstderr: {}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Asserts a clean failure: non-zero exit, no panic, no backtrace; returns
/// (stdout, stderr).
fn fails_cleanly(args: &[&str], bound: Duration) -> (String, String) {
    let out = cancosim(args, bound);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_ne!(out.status.code(), Some(0), "cancosim {args:?} succeeded\n{stdout}\n{stderr}");
    assert!(out.status.code().is_some(), "cancosim {args:?} killed by a signal\n{stderr}");
    for bad in ["panicked", "stack backtrace", "RUST_BACKTRACE", "thread 'main'"] {
        assert!(!stderr.contains(bad) && !stdout.contains(bad), "cancosim {args:?}: {bad}\n{stdout}\n{stderr}");
    }
    (stdout, stderr)
}

/// A scenario rejected by the parser: exit 2 and exactly one line on
/// stderr, `cancosim: FILE:LINE:COL: key `KEY`: ...`.
fn rejected(text: &str, name: &str) -> String {
    let dir = scratch(name);
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, text).unwrap();
    let f = file.to_str().unwrap();
    let (stdout, stderr) = fails_cleanly(&["run", f, "--dut", "model"], Duration::from_secs(20));
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "one line on stderr: {stderr}\nstdout: {stdout}");
    assert!(lines[0].starts_with(&format!("cancosim: {f}:")), "names the file: {}", lines[0]);
    assert!(stdout.trim().is_empty(), "nothing ran: {stdout}");
    lines[0].to_string()
}

const GOOD: &str = "purpose = \"t\"\nverifies = [\"x\"]\n[clocks]\nhost_mhz = 50.0\ncan_mhz = 24.0\n[host]\nbfm = \"wishbone\"\n[[step]]\nwrite = \"CR\"\nvalue = 1\n";

/// Line and key of a `cancosim: FILE:LINE:COL: key `KEY`: ...` message.
fn line_and_key(msg: &str, file_tail: &str) -> (usize, String) {
    let rest = &msg[msg.find(file_tail).unwrap() + file_tail.len()..];
    let line: usize = rest.trim_start_matches(':').split(':').next().unwrap().parse().unwrap();
    let key = msg.split('`').nth(1).unwrap().to_string();
    (line, key)
}

#[test]
fn good_scenario_runs_on_the_model() {
    // the baseline the bad inputs below are variations of
    let dir = scratch("good");
    let file = dir.join("good.toml");
    std::fs::write(&file, GOOD).unwrap();
    let out = cancosim(&["run", file.to_str().unwrap(), "--dut", "model"], Duration::from_secs(20));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("DUT: model"), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn unknown_key_names_file_line_and_key() {
    let msg = rejected(&GOOD.replace("can_mhz = 24.0", "can_mhz = 24.0\ncan_mzh = 12.0"), "unknown_key");
    assert_eq!(line_and_key(&msg, "unknown_key.toml"), (6, "can_mzh".into()), "{msg}");
    assert!(msg.contains("unknown key"), "{msg}");
}

#[test]
fn malformed_toml_names_the_line() {
    let msg = rejected(&GOOD.replace("value = 1", "value = = 1"), "malformed");
    assert_eq!(line_and_key(&msg, "malformed.toml").0, 10, "{msg}");
    let msg = rejected(&GOOD.replace("can_mhz = 24.0", "can_mhz = \"fast\""), "wrong_type");
    assert_eq!(line_and_key(&msg, "wrong_type.toml").0, 5, "{msg}");
}

#[test]
fn dlc_over_8_in_load_tx_and_node_traffic() {
    let msg = rejected(&format!("{GOOD}[[step]]\nload_tx = {{ id = 0x123, data = [1,2,3,4,5,6,7,8], dlc = 9 }}\n"), "dlc_step");
    assert!(msg.contains("DLC 9 > 8") && msg.contains("dlc"), "{msg}");
    let node = "[[node]]\nname = \"n\"\nbtr0 = 0x41\nbtr1 = 0x25\nsend = [ { id = 0x10, data = [1,2,3,4,5,6,7,8,9] } ]\n";
    let msg = rejected(&format!("{GOOD}{node}"), "dlc_node");
    assert!(msg.contains("at most 8"), "{msg}");
    assert!(line_and_key(&msg, "dlc_node.toml").1.starts_with("node"), "{msg}");
}

#[test]
fn ids_out_of_range() {
    let msg = rejected(&format!("{GOOD}[[step]]\nload_tx = {{ id = 0x800 }}\n"), "id11");
    assert!(msg.contains("0x800") && msg.contains("standard"), "{msg}");
    let msg = rejected(&format!("{GOOD}[[step]]\nload_tx = {{ id = 0x20000000, extended = true }}\n"), "id29");
    assert!(msg.contains("extended"), "{msg}");
    let msg = rejected(&format!("{GOOD}[[step]]\nload_tx = {{ id = -1 }}\n"), "idneg");
    assert!(line_and_key(&msg, "idneg.toml").1.ends_with("id"), "{msg}");
}

#[test]
fn register_addresses_out_of_range() {
    let msg = rejected(&format!("{GOOD}[[step]]\nwrite = 40\nvalue = 0\n"), "addr40");
    assert!(msg.contains("address 40 is out of range"), "{msg}");
    let msg = rejected(&format!("{GOOD}[[step]]\nread = 300\n"), "addr300");
    assert_eq!(line_and_key(&msg, "addr300.toml"), (12, "step[2].read".into()), "{msg}");
    let msg = rejected(&format!("{GOOD}[[step]]\nwrite = \"CR\"\nvalue = 256\n"), "value256");
    assert!(line_and_key(&msg, "value256.toml").1.ends_with("value"), "{msg}");
}

#[test]
fn clocks_without_valid_bit_timing() {
    let msg = rejected(&GOOD.replace("can_mhz = 24.0", "can_mhz = 24.0\nbit_rate = 2000000"), "rate");
    assert_eq!(line_and_key(&msg, "rate.toml"), (6, "clocks.bit_rate".into()), "{msg}");
    assert!(msg.contains("no valid bit timing"), "{msg}");
    let msg = rejected(&GOOD.replace("can_mhz = 24.0", "can_mhz = 0.0"), "zero_clock");
    assert_eq!(line_and_key(&msg, "zero_clock.toml").1, "clocks.can_mhz", "{msg}");
    let msg = rejected(&format!("{GOOD}[[step]]\nwrite = \"BTR0\"\nvalue = 0\n[[step]]\nwrite = \"BTR1\"\nvalue = 0x12\n"), "btr");
    assert!(msg.contains("no valid bit timing"), "{msg}");
}

#[test]
fn missing_scenario_file_is_named() {
    let (_, stderr) = fails_cleanly(&["run", "tb/does-not-exist.toml"], Duration::from_secs(20));
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("tb/does-not-exist.toml") && stderr.contains("cannot read"), "{stderr}");
}

#[test]
fn bittiming_with_no_valid_setting() {
    // 1 MHz cannot make 1 Mbit/s (at least 8 time quanta per bit)
    let (stdout, _) = fails_cleanly(&["bittiming", "--clock", "1MHz", "--rate", "1M"], Duration::from_secs(20));
    assert!(!stdout.trim().is_empty() && stdout.trim().lines().count() == 1, "one sentence: {stdout}");
    // above 1 Mbit/s
    fails_cleanly(&["bittiming", "--clock", "24MHz", "--rate", "2M"], Duration::from_secs(20));
    // a given setting that is wrong for the clock: each problem on its line
    let (stdout, _) = fails_cleanly(
        &["bittiming", "--clock", "16MHz", "--rate", "125k", "--btr0", "0x03", "--btr1", "0xBB"],
        Duration::from_secs(20),
    );
    assert!(stdout.contains("problem:") && stdout.contains("117.6"), "{stdout}");
    // nonsense values are argument errors naming the argument
    for args in [
        ["bittiming", "--clock", "0", "--rate", "500k"],
        ["bittiming", "--clock", "24MHz", "--rate", "fast"],
        ["bittiming", "--clock", "24MHz", "--rate", "-5"],
    ] {
        let (_, stderr) = fails_cleanly(&args, Duration::from_secs(20));
        assert!(stderr.contains("--clock") || stderr.contains("--rate"), "{args:?}: {stderr}");
    }
    let (_, stderr) = fails_cleanly(
        &["bittiming", "--clock", "24MHz", "--rate", "500k", "--btr0", "0x141", "--btr1", "0"],
        Duration::from_secs(20),
    );
    assert!(stderr.contains("--btr0") && stderr.contains("not a byte"), "{stderr}");
}

#[test]
fn decode_rejects_what_is_not_a_bit() {
    let (_, stderr) = fails_cleanly(&["decode", "--bits", "0101x01"], Duration::from_secs(20));
    assert!(stderr.contains("'x'") && stderr.contains("not a bit"), "{stderr}");
    let (_, stderr) = fails_cleanly(&["decode", "no/such/file.vcd"], Duration::from_secs(20));
    assert!(stderr.contains("no/such/file.vcd"), "{stderr}");
    // a stream with a stuck-dominant bus: reported as errors, exit 1, no hang
    let bits = format!("{}{}", "1".repeat(11), "0".repeat(100_000));
    let out = cancosim(&["decode", "--bits", &bits], Duration::from_secs(20));
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
}

/// An external core in a scratch directory.
/// A core's directory at a fixed path (the run-time build cache is keyed
/// on the sources' paths too, so only the first run verilates it), written
/// aside and renamed into place: another test process may be reading it.
fn external_core(name: &str, verilog: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-bad-input/cores").join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{name}.v"));
    if std::fs::read_to_string(&file).ok().as_deref() != Some(verilog) {
        let aside = dir.join(format!(".{name}.v.{}", std::process::id()));
        std::fs::write(&aside, verilog).unwrap();
        std::fs::rename(&aside, &file).unwrap();
    }
    dir
}

#[test]
fn external_hdl_that_does_not_compile() {
    let dir = external_core("broken_core", "module can_top(input wb_clk_i, output tx_o);\n  assign tx_o = wb_clk_i +;\nendmodule\n");
    let (stdout, stderr) = fails_cleanly(
        &["run", "tb/de2-with-ack-node.toml", "--external", dir.to_str().unwrap(), "--profile", "rtl"],
        Duration::from_secs(60),
    );
    let all = format!("{stdout}{stderr}");
    assert!(all.contains("broken_core.v") && all.contains("syntax error"), "carries Verilator's message: {all}");
}

/// An external core without `--profile` is refused before anything is
/// built, with what to declare, the shipped profiles and, for a directory
/// that looks like the opencores core, the hint `--profile opencores-can`;
/// `regress` the same per external core; a misspelt profile lists the
/// shipped ones.
#[test]
fn external_core_without_a_profile_says_what_to_declare() {
    // A directory of its own: the opencores-like file names added below
    // must not leak into a later run's first case.
    let dir = scratch("some_core");
    std::fs::write(dir.join("some_core.v"), "module can_top(input wb_clk_i, output tx_o);\nendmodule\n").unwrap();
    let d = dir.to_str().unwrap();
    let (_, stderr) = fails_cleanly(&["run", "tb/de2-with-ack-node.toml", "--external", d], Duration::from_secs(20));
    for needle in ["has no profile", "phase-origin", "[access.wishbone]", "takes-effect", "[tolerances]", "[ports]", "opencores-can", "rtl"] {
        assert!(stderr.contains(needle), "names {needle}: {stderr}");
    }
    assert!(!stderr.contains("try --profile opencores-can"), "no opencores hint for another core: {stderr}");
    // Looks like the opencores core (its file names only, empty files).
    for f in ["can_bsp.v", "can_btl.v", "can_registers.v"] {
        std::fs::write(dir.join(f), "").unwrap();
    }
    let (_, stderr) = fails_cleanly(&["regress", "tb/de2-thesis.toml", "--external", &format!("oc={d}")], Duration::from_secs(20));
    assert!(stderr.contains("try --profile opencores-can") && stderr.contains(&format!("oc={d}")), "{stderr}");
    let (_, stderr) = fails_cleanly(&["run", "tb/de2-thesis.toml", "--external", d, "--profile", "opencore"], Duration::from_secs(20));
    assert!(stderr.contains("no profile named `opencore`") && stderr.contains("opencores-can, rtl"), "{stderr}");
    let (_, stderr) = fails_cleanly(&["regress", "tb/de2-thesis.toml", "--external", &format!("oc={d}@nope.toml")], Duration::from_secs(20));
    assert!(stderr.contains("nope.toml"), "{stderr}");
}

/// `can_top` port list, but `wb_ack_o` left out; or, for the no-ack
/// fixture, every port with `wb_ack_o` tied low.
fn can_top_ports(ack: Option<&str>) -> String {
    let mut ports = vec![
        "input wb_clk_i", "input wb_rst_i", "input [7:0] wb_dat_i", "output [7:0] wb_dat_o", "input wb_cyc_i",
        "input wb_stb_i", "input wb_we_i", "input [7:0] wb_adr_i", "input clk_i", "input rx_i", "output tx_o",
        "output bus_off_on", "output irq_on", "output clkout_o",
    ];
    if ack.is_some() {
        ports.push("output wb_ack_o");
    }
    format!(
        "module can_top({});\n  assign wb_dat_o = 8'h00;\n  assign tx_o = 1'b1;\n  assign bus_off_on = 1'b1;\n  assign irq_on = 1'b1;\n  assign clkout_o = clk_i;\n{}endmodule\n",
        ports.join(", "),
        ack.map(|a| format!("  assign wb_ack_o = {a};\n")).unwrap_or_default()
    )
}

#[test]
#[ignore = "builds an external core with Verilator and a C++ compiler (about a minute the first time, cached after); run with cargo test -p cancosim --test suite bad_input:: -- --ignored"]
fn external_hdl_that_lacks_a_port() {
    let dir = external_core("core_without_ack", &can_top_ports(None));
    let (stdout, stderr) = fails_cleanly(
        &["run", "tb/de2-with-ack-node.toml", "--external", dir.to_str().unwrap(), "--profile", "rtl"],
        Duration::from_secs(300),
    );
    let all = format!("{stdout}{stderr}");
    assert!(all.contains("wb_ack_o"), "names the missing port: {all}");
}

#[test]
#[ignore = "builds an external core with Verilator and a C++ compiler (about a minute the first time, cached after); run with cargo test -p cancosim --test suite bad_input:: -- --ignored"]
fn a_dut_that_never_acks_times_out_with_a_diagnosis() {
    let dir = external_core("core_never_acks", &can_top_ports(Some("1'b0")));
    let t = Instant::now();
    let (stdout, stderr) = fails_cleanly(
        &["run", "tb/de2-with-ack-node.toml", "--external", dir.to_str().unwrap(), "--profile", "rtl"],
        Duration::from_secs(300),
    );
    let all = format!("{stdout}{stderr}");
    assert!(all.to_lowercase().contains("ack"), "the diagnosis names the missing ack: {all}");
    assert!(all.contains("scenario: FAIL"), "{all}");
    eprintln!("never-acking DUT: failed cleanly in {:.1} s", t.elapsed().as_secs_f64());
}

#[test]
fn a_bad_scenario_in_a_regression_list_does_not_stop_the_others() {
    // Loses nothing: the good scenario still runs and is reported; the bad
    // one is an error row naming file, line and key; the exit code says so.
    let dir = scratch("regress-list");
    let good = std::fs::read_to_string(root().join("tb/de2-pelican-selftest.toml")).unwrap();
    std::fs::write(dir.join("good.toml"), &good).unwrap();
    std::fs::write(dir.join("typo.toml"), good.replace("[clocks]", "[clocks]\nhost_mzh = 1.0")).unwrap();
    std::fs::write(dir.join("list"), "good.toml\ntypo.toml\n").unwrap();
    let list = dir.join("list");
    let (stdout, _stderr) = fails_cleanly(&["regress", list.to_str().unwrap(), "--dut", "model"], Duration::from_secs(60));
    let row = |name: &str| stdout.lines().find(|l| l.contains(name)).unwrap_or_else(|| panic!("no row for {name}:\n{stdout}")).to_owned();
    assert!(row("good").to_lowercase().contains("pass"), "{stdout}");
    let bad = row("typo");
    assert!(!bad.to_lowercase().contains("pass"), "{stdout}");
    assert!(stdout.contains("host_mzh"), "the error names the key:\n{stdout}");
}

/// `regress --external NAME=DIR` with a DIR that cannot hold the core: one
/// line on stderr naming the problem, before any scenario runs (it used to
/// print the same error once per scenario). Exit 125 from `regress` (the
/// core cannot be tested: `git bisect run` skips the revision), 2 (bad
/// input) from `run`.
fn external_rejected(args: &[&str]) -> String {
    let out = cancosim(args, Duration::from_secs(60));
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    let want = if args[0] == "regress" { 125 } else { 2 };
    assert_eq!(out.status.code(), Some(want), "{args:?}: {stdout}{stderr}");
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "one line: {stderr}");
    assert!(stdout.trim().is_empty(), "no scenario ran: {stdout}");
    lines[0].to_string()
}

#[test]
fn regress_with_a_bad_external_directory_fails_once_before_any_scenario() {
    let line = external_rejected(&["regress", "--external", "x=/nonexistent"]);
    assert!(line.contains("--external x=/nonexistent") && line.contains("cannot be read"), "{line}");

    let empty = scratch("external-empty");
    std::fs::write(empty.join("README"), "no HDL here").unwrap();
    let arg = format!("up={}", empty.display());
    let line = external_rejected(&["regress", "--external", &arg]);
    assert!(line.contains("holds no *.v or *.sv files"), "{line}");

    let other = scratch("external-other-top");
    std::fs::write(other.join("core.v"), "module can_top_pio(input a);\nendmodule\n").unwrap();
    let arg = format!("up={}", other.display());
    let line = external_rejected(&["regress", "--external", &arg]);
    assert!(line.contains("no `module can_top`") && line.contains("--top"), "{line}");

    let line = external_rejected(&["run", "tb/de2-thesis.toml", "--external", "/nonexistent"]);
    assert!(line.contains("/nonexistent") && line.contains("cannot be read"), "{line}");
}

#[test]
fn a_failed_scenario_is_exit_1_and_bad_input_exit_2() {
    let out = cancosim(&["run", "tb/de2-thesis.toml", "--dut", "model", "--max-bits", "10"], Duration::from_secs(60));
    let code = out.status.code();
    let all = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(all.contains("scenario: FAIL"), "cut short, the thesis scenario fails: {all}");
    assert_eq!(code, Some(1), "{all}");
    let out = cancosim(&["run", "tb/no-such-scenario.toml"], Duration::from_secs(20));
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn mutate_rejects_a_time_budget_that_is_not_above_zero() {
    for bad in ["0", "-1", "NaN"] {
        let arg = format!("--budget-factor={bad}");
        let (_, stderr) = fails_cleanly(&["mutate", &arg, "--count", "1", "--no-formal"], Duration::from_secs(20));
        assert!(stderr.contains("--budget-factor") && stderr.contains("above 0"), "{bad}: {stderr}");
    }
}

/// `gen` with a stride and byte lane from a profile: the header follows
/// them; a stride or lane the layout or Linux's driver cannot have, or a
/// profile without the bus's table, is one clear sentence.
#[test]
fn gen_reads_stride_and_lane_from_a_profile_and_rejects_impossible_ones() {
    let d = scratch("gen-layout");
    let prof = d.join("core.toml");
    std::fs::write(&prof, "[access.axi4-lite]\nstride = 4\nbyte-lane = 1\n[access.apb]\nstride = 3\n").unwrap();
    let (p, out) = (prof.to_str().unwrap(), d.join("gen"));
    let ok = cancosim(&["gen", "--out", out.to_str().unwrap(), "--profile", p, "--host", "axi4-lite"], Duration::from_secs(30));
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let h = std::fs::read_to_string(out.join("can_sja_regs.h")).unwrap();
    assert!(h.contains("#define CAN_SJA_SPACING (4)") && h.contains("#define CAN_SJA_LANE (1)"), "{h}");
    let node = cancosim(&["gen", "devicetree", "--profile", p, "--host", "axi4-lite", "--byte-lane", "0", "--cdr", "0x81"], Duration::from_secs(30));
    let node = String::from_utf8_lossy(&node.stdout).into_owned();
    assert!(node.contains("reg-io-width = <4>;") && node.contains("nxp,clock-out-frequency = <6000000>;"), "{node}");
    let (_, e) = fails_cleanly(&["gen", "devicetree", "--profile", p, "--host", "axi4-lite"], Duration::from_secs(30));
    assert!(e.contains("byte lane 1 at a 4-byte stride") && e.contains("keeps bits 7..0"), "{e}");
    let (_, e) = fails_cleanly(&["gen", "--out", out.to_str().unwrap(), "--profile", p, "--host", "apb"], Duration::from_secs(30));
    assert!(e.contains("register stride 3 is not 1, 2 or 4 bytes"), "{e}");
    let (_, e) = fails_cleanly(&["gen", "devicetree", "--profile", p, "--host", "wishbone"], Duration::from_secs(30));
    assert!(e.contains("has no [access.wishbone] table"), "{e}");
    let (_, e) = fails_cleanly(&["gen", "--out", out.to_str().unwrap(), "--stride", "2", "--byte-lane", "2"], Duration::from_secs(30));
    assert!(e.contains("byte lane 2 is outside a register of 2 byte(s)"), "{e}");
}
