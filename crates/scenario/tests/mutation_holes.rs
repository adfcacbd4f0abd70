//! The scenarios that close protocol-side mutation-testing holes
//! (`tb/mutation-holes.list`, docs/mutation-holes-protocol.md) cannot rot:
//! every one passes on the golden model and on our RTL (lockstep, zero
//! divergences), and their key counter checks are live.

use scenario::{DutSpec, RunOptions, Scenario, load_list, run};

mod common;
use common::root;

/// The whole list on the model and on our RTL (well under a second).
#[test]
fn mutation_holes_list_passes_on_model_and_rtl_without_divergence() {
    let s = load_list(root().join("tb/mutation-holes.list")).expect("tb/mutation-holes.list loads");
    assert!(s.len() >= 6, "the list shrank to {} scenarios", s.len());
    common::assert_passes_on_model_and_rtl_without_divergence(&s);
}

/// An off-by-one expectation fails on the model: the checks that killed the
/// counter mutants (TEC after +8/-1, REC from an odd value, FIFO exact fit)
/// are live, not vacuous.
#[test]
fn off_by_one_counter_expectations_fail() {
    for (file, from, to) in [
        ("tec-write-and-count.toml", "read = \"TXERR\", expect = 70,", "read = \"TXERR\", expect = 71,"),
        ("rec-count-from-odd.toml", "read = \"RXERR\", expect = 9,", "read = \"RXERR\", expect = 10,"),
        ("fifo-exact-fit-dual-ext.toml", "read = \"RMC\", expect = 5, note = \"64", "read = \"RMC\", expect = 4, note = \"64"),
    ] {
        let path = root().join("tb/mutation-holes").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(from), "{file}: the mutation point moved");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
        assert!(!o.passed, "{file}: a wrong expectation passed");
    }
}

/// The glitches placed in time quanta (`offset_tq`, `width_tq`) sit where
/// the scenarios say: on the model, a pulse two quanta wide on two of the
/// three SAM samples is a bus error (the one-quantum pulses are not), and
/// the dominant pulse late in PHASE_SEG2 (2 quanta before the bit's end,
/// shortening the bit by 2 tq only) no longer breaks reception.
#[test]
fn quantum_placed_glitches_hit_what_they_aim_at() {
    for (file, from, to) in [
        (
            "sam-glitch-one-sample.toml",
            "bit_in_frame = 4\noffset_tq = 5\nwidth_tq = 1",
            "bit_in_frame = 4\noffset_tq = 5\nwidth_tq = 2",
        ),
        (
            "resync-after-sample-point.toml",
            "bit_in_frame = 5\noffset_tq = 4",
            "bit_in_frame = 5\noffset_tq = 10",
        ),
    ] {
        let path = root().join("tb/mutation-holes").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(from), "{file}: the glitch moved");
        let s = Scenario::parse(&text, &path).unwrap();
        assert!(run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() }).passed, "{file} as shipped");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
        assert!(!o.passed, "{file}: the moved glitch changed nothing");
    }
}

/// The session-7 holes of today's rtl/ sample (`rtl-*.toml`): a wrong value
/// where each scenario reads what its mutant changes fails on the model.
#[test]
fn rtl_sample_hole_expectations_are_live() {
    for (file, from, to) in [
        ("rtl-late-edge-beyond-sjw4.toml", "read = \"RXB+2\", expect = 0x11,", "read = \"RXB+2\", expect = 0x12,"),
        ("rtl-late-edge-at-tseg1-end.toml", "read = \"RXFI\", expect = 0x01,", "read = \"RXFI\", expect = 0x11,"),
        ("rtl-free-ram-bit5-kept.toml", "read = 109, expect = 0xFF, note = \"bit 5 kept", "read = 109, expect = 0xDF, note = \"bit 5 kept"),
    ] {
        let path = root().join("tb/mutation-holes").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(from), "{file}: the checked read moved");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
        assert!(!o.passed, "{file}: a wrong expectation passed");
    }
}
