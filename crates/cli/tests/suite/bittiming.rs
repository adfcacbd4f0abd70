//! `cancosim bittiming` end to end: registers alone give
//! the bit rate they make (the seed-002 parking network's 117.6 kbit/s),
//! `--rate` searches, or with registers reports their deviation.

use std::process::Command;

/// (exit code, stdout, stderr) of `cancosim bittiming args`.
fn bittiming(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_cancosim")).arg("bittiming").args(args).output().expect("cancosim runs");
    (
        o.status.code().expect("exited"),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn registers_without_rate_print_the_rate_they_give_and_exit_0() {
    let (code, out, err) = bittiming(&["--clock", "16MHz", "--btr0", "0x03", "--btr1", "0xBB"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("117.6 kbit/s"), "{out}");
    assert!(out.contains("sample point 76.5%"), "the usual analysis: {out}");
    assert!(out.contains("not a standard rate") && out.contains("125 kbit/s") && out.contains("-5.88%"), "{out}");
    assert!(!out.contains("problem:"), "{out}");
}

#[test]
fn registers_of_a_standard_rate_are_named_as_such() {
    // 24 MHz, BRP 2 (4 clocks per tq), 1 + 8 + 3 = 12 tq: 500 kbit/s.
    let (code, out, _) = bittiming(&["--clock", "24MHz", "--btr0", "0x01", "--btr1", "0x27"]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("500.0 kbit/s") && out.contains("standard 500 kbit/s (+0 ppm)"), "{out}");
    assert!(out.contains("ok: a sound setting"), "{out}");
}

#[test]
fn registers_with_rate_report_the_deviation_and_fail_when_off() {
    let (code, out, _) = bittiming(&["--clock", "16MHz", "--rate", "125k", "--btr0", "0x03", "--btr1", "0xBB"]);
    assert_eq!(code, 1, "5.9% off is a problem: {out}");
    assert!(out.contains("deviation from 125 kbit/s: -58824 ppm"), "{out}");
    assert!(out.contains("problem:"), "{out}");
    let (code, out, _) = bittiming(&["--clock", "24MHz", "--rate", "500k", "--btr0", "0x01", "--btr1", "0x27"]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("deviation from 500 kbit/s: +0 ppm") && out.contains("ok: valid"), "{out}");
}

#[test]
fn rate_alone_still_searches_and_nothing_at_all_is_a_usage_error() {
    let (code, out, _) = bittiming(&["--clock", "24MHz", "--rate", "500k"]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("BTR0") && out.lines().count() > 2, "a table of candidates: {out}");
    let (code, out, err) = bittiming(&["--clock", "24MHz"]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("--rate"), "{err}");
}
