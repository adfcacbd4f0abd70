//! The functional-coverage scenarios (`tb/coverage.list`) cannot rot: every
//! one passes on the golden model and on our RTL (lockstep, zero
//! divergences, nothing waived), they still hit the bins they were written
//! for, and their checks are live (a changed expected value fails).

use scenario::regress::{RegressOptions, regress};
use scenario::{DutSpec, RunOptions, Scenario, load_list, run};

use crate::common;
use common::root;

fn suite() -> Vec<Scenario> {
    load_list(root().join("tb/coverage.list")).expect("tb/coverage.list loads")
}

/// The whole list on the model and on our RTL (about two seconds).
#[test]
fn coverage_list_passes_on_model_and_rtl_without_divergence() {
    let s = suite();
    assert!(s.len() >= 13, "the coverage list shrank to {} scenarios", s.len());
    common::assert_passes_on_model_and_rtl_without_divergence(&s);
}

/// The bins each scenario was written to close are hit by the list alone.
#[test]
fn the_list_hits_the_bins_it_was_written_for() {
    let rep = regress(&suite(), &[DutSpec::model()], &RegressOptions { jobs: 2, ..Default::default() });
    assert!(rep.passed(), "{}", rep.to_table());
    let c = rep.funcov("model");
    let group = |g: &str| c.summary().into_iter().find(|s| s.group == g).unwrap_or_else(|| panic!("no group {g}"));
    let frames = group("frame kinds");
    assert_eq!(frames.hit, frames.total, "frame kinds: {}", c.holes_in("frame kinds").join(", "));
    for (g, bin) in [
        ("error kinds x field", "stuff error in SRR/RTR bit"),
        ("error kinds x field", "stuff error in IDE bit"),
        ("error kinds x field", "stuff error in RTR bit"),
        ("error kinds x field", "stuff error in reserved bit r1"),
        ("error kinds x field", "bit error in SRR/RTR bit"),
        ("error kinds x field", "bit error in IDE bit"),
        ("arbitration loss", "first extended ID bit (ID.17, ALC 13)"),
        ("interrupts BasicCAN", "RI raised"),
        ("interrupts BasicCAN", "RI cleared"),
        ("interrupts BasicCAN", "TI cleared"),
        ("interrupts BasicCAN", "EI raised"),
        ("interrupts BasicCAN", "EI cleared"),
        ("registers PeliCAN operating write", "IER bit 7=1"),
        ("registers PeliCAN operating read", "BTR0 bit 7=1"),
        ("registers BasicCAN reset read", "CR bit 4=1"),
        ("registers BasicCAN reset read", "RXID1 bit 7=1"),
        ("registers BasicCAN operating read", "SR bit 7=1"),
        ("registers PeliCAN operating read", "RMC bit 4=1"),
        ("registers PeliCAN reset read", "ALC bit 4=1"),
        ("error kinds x field", "form error in overload delimiter"),
        ("acceptance filter", "BasicCAN EFF rejected"),
    ] {
        assert!(c.hits(g, bin).is_some_and(|h| h > 0), "{g}: {bin} not hit\n{}", c.to_table());
    }
}

/// A changed expected value fails on the model: the checks are live.
#[test]
fn a_changed_expectation_fails() {
    for (file, from, to) in [
        ("rx-stuff-errors-arbitration-control.toml", "expect = 0xA4,", "expect = 0xA5,"),
        ("tx-bit-errors-rtr-ide.toml", "read = \"ECC\", expect = 0x05,", "read = \"ECC\", expect = 0x04,"),
        ("arbitration-loss-id17.toml", "read = \"ALC\", expect = 0x0D,", "read = \"ALC\", expect = 0x0E,"),
        ("basic-interrupts.toml", "read = \"IR\", expect = 0x04,", "read = \"IR\", expect = 0x00,"),
        ("frame-kinds-all.toml", "read = \"RXFI\", expect = 0xCA,", "read = \"RXFI\", expect = 0xC8,"),
        ("frame-kinds-all.toml", "received = { peer = 0, rx0 = 5,", "received = { peer = 0, rx0 = 4,"),
        ("peli-register-bits.toml", "read = \"IER\", expect = 0xAA", "read = \"IER\", expect = 0xAB"),
        ("basic-register-bits.toml", "read = \"CR\", expect = 0x7F,", "read = \"CR\", expect = 0x5F,"),
        ("basic-bus-off-status.toml", "read = \"SR\", expect = 0x80, mask = 0x80,", "read = \"SR\", expect = 0x00, mask = 0x80,"),
        ("basic-rx-buffer-read-in-reset-mode.toml", "{ read = \"RXID1\", expect = 0x55, note", "{ read = \"RXID1\", expect = 0x54, note"),
        ("rx-form-error-overload-delimiter.toml", "read = \"ECC\", expect = 0x77,", "read = \"ECC\", expect = 0x57,"),
        ("rx-fifo-sixteen-messages.toml", "read = \"RMC\", expect = 16,", "read = \"RMC\", expect = 15,"),
        ("peli-captures-read-in-reset-mode.toml", "read = \"ALC\", expect = 0x1F,", "read = \"ALC\", expect = 0x1E,"),
        ("basic-extended-frame-passive.toml", "{ read = \"SR\", expect = 0x00, mask = 0xC1,", "{ read = \"SR\", expect = 0x01, mask = 0xC1,"),
    ] {
        let path = root().join("tb/coverage").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(from), "{file}: the mutation point moved ({from})");
        let s = Scenario::parse(&text, &path).unwrap();
        assert!(run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() }).passed, "{file} as shipped");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        assert!(!run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() }).passed, "{file}: {from} -> {to} still passed");
    }
}
