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

/// doi-alone-drives-irq (the opencores mutant 8, DOI left off the irq
/// output) checks the pin, not only IR: with DOIE cleared the model's INT
/// is high once the messages are released and the `wait_irq` fails; an IR
/// expectation with RI still set fails too.
#[test]
fn doi_alone_holds_the_interrupt_output_only_with_doie() {
    let path = root().join("tb/mutation-holes/doi-alone-drives-irq.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let model = || RunOptions { dut: Some(DutSpec::model()), ..Default::default() };
    assert!(run(&Scenario::parse(&text, &path).unwrap(), &model()).passed, "as shipped");
    for (from, to) in [
        ("{ write = \"IER\", value = 0x09,", "{ write = \"IER\", value = 0x01,"),
        ("{ read = \"IR\", expect = 0x08,", "{ read = \"IR\", expect = 0x09,"),
    ] {
        assert!(text.contains(from), "the mutation point moved: {from}");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        let o = run(&s, &model());
        assert!(!o.passed, "{to}: passed");
    }
}
