//! The register scenarios (`tb/registers.list`, datasheet reset values and
//! access rules) cannot rot: every scenario passes on the golden model and
//! on our RTL (Verilated, in lockstep, zero divergences), each cites the
//! datasheet, and a wrong expected value fails.

use scenario::{DutSpec, RunOptions, Scenario, load_list, run};

use crate::common;
use common::root;

fn suite() -> Vec<Scenario> {
    load_list(root().join("tb/registers.list")).expect("tb/registers.list loads")
}

/// The whole list on the model and on our RTL (no bus traffic: about a second).
#[test]
fn register_list_passes_on_model_and_rtl_without_divergence() {
    let s = suite();
    assert!(s.len() >= 4, "the register list shrank to {} scenarios", s.len());
    common::assert_passes_on_model_and_rtl_without_divergence(&s);
}

/// Every scenario states what it verifies and cites the datasheet.
#[test]
fn every_register_scenario_cites_the_datasheet() {
    for sc in suite() {
        assert!(sc.purpose.contains("SJA1000 datasheet"), "{}: purpose does not cite the datasheet", sc.name);
        assert!(!sc.verifies.is_empty(), "{}: no `verifies`", sc.name);
    }
}

/// A wrong expected value fails on the model and on the RTL: the checks
/// are live (TXERR written in reset mode reads back; 0x2A expected as 0x2B).
#[test]
fn a_wrong_register_expectation_fails() {
    let path = root().join("tb/registers/peli-reset-values-and-access.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let from = "{ write = \"TXERR\", value = 0x2A }, { read = \"TXERR\", expect = 0x2A },";
    assert!(text.contains(from), "the mutation point moved");
    let bad = text.replacen(from, "{ write = \"TXERR\", value = 0x2A }, { read = \"TXERR\", expect = 0x2B },", 1);
    let s = Scenario::parse(&bad, &path).unwrap();
    for dut in [DutSpec::model(), DutSpec::rtl()] {
        let o = run(&s, &RunOptions { dut: Some(dut), ..Default::default() });
        assert!(!o.passed, "a wrong TXERR expectation passed");
    }
}

/// peli-txerr-write-ends-bus-off checks what the datasheet states (6.4.12):
/// the 0..254 write clears SR.BS at once (BS = 1 expected fails), ES waits
/// for leaving reset mode (ES = 0 expected in reset mode fails), and a
/// write of 255 instead (which changes nothing while bus-off) fails.
#[test]
fn a_txerr_write_during_bus_off_is_checked_where_the_datasheet_says() {
    let path = root().join("tb/registers/peli-txerr-write-ends-bus-off.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let model = || RunOptions { dut: Some(DutSpec::model()), ..Default::default() };
    assert!(run(&Scenario::parse(&text, &path).unwrap(), &model()).passed, "as shipped");
    for (from, to) in [
        ("{ read = \"SR\", expect = 0x40, mask = 0xC0, note = \"BS = 0 at once", "{ read = \"SR\", expect = 0xC0, mask = 0xC0, note = \"BS = 0 at once"),
        ("{ read = \"SR\", expect = 0x40, mask = 0xC0, note = \"BS = 0 at once", "{ read = \"SR\", expect = 0x00, mask = 0xC0, note = \"BS = 0 at once"),
        ("{ write = \"TXERR\", value = 10, note", "{ write = \"TXERR\", value = 255, note"),
    ] {
        assert!(text.contains(from), "the mutation point moved: {from}");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        assert!(!run(&s, &model()).passed, "{to}: passed");
    }
}

/// The two register checks are live on the model and on our
/// RTL: PeliCAN ACR3 bit 7 after a BasicCAN ACR write (mutant 119 reads
/// 7FH) and the BasicCAN AMR read in operating mode (mutant 125 reads F7H),
/// each expected as the mutant reads it, fail.
#[test]
fn acr3_kept_and_amr_ffh_in_operating_mode_are_checked() {
    for (file, from, to) in [
        (
            "peli-acr-amr-kept-across-basic-writes.toml",
            "{ read = \"ACR3\", expect = 0xFF, note = \"bit 7 kept",
            "{ read = \"ACR3\", expect = 0x7F, note = \"bit 7 kept",
        ),
        (
            "basic-acr-amr-read-ffh-in-operating-mode.toml",
            "{ read = \"AMR\", expect = 0xFF, note = \"Table 2: FFH in operating mode (mutant 125",
            "{ read = \"AMR\", expect = 0xF7, note = \"Table 2: FFH in operating mode (mutant 125",
        ),
    ] {
        let path = root().join("tb/registers").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(from), "{file}: the check moved");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        for dut in [DutSpec::model(), DutSpec::rtl()] {
            let o = run(&s, &RunOptions { dut: Some(dut), ..Default::default() });
            assert!(!o.passed, "{file}: {to} passed");
        }
    }
}
