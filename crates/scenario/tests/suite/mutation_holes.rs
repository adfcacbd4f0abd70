//! The scenarios that close protocol-side mutation-testing holes
//! (`tb/mutation-holes.list`, docs/guide/results/mutation-scores.md) cannot rot:
//! every one passes on the golden model and on our RTL (lockstep, zero
//! divergences), and their key counter checks are live.

use scenario::{DutSpec, RunOptions, Scenario, load_list, run};

use crate::common;
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

/// The opencores seed-1 holes closed (`up-` scenarios) are
/// live: with the deciding frame or register moved each fails on the model,
/// through the filter's or the counter's outcome (none of these values is
/// read back). The DLC-0 frame given a mismatching byte (153), byte 2 bit 7
/// matching (172), ACR2.4 = 1 (167), ID.25 not flipped (125), data byte 1
/// bit 0 matching (140), EWLR 9 to 8 (148); for 110 and 148 the first check
/// expected as the mutant reads it (message 18's RXFI 0xD1, ES = 1 at REC 4).
#[test]
fn up_scenarios_fail_with_their_deciding_stimulus_moved() {
    for (file, from, to) in [
        ("up-filter-single-std-absent-bytes.toml", "{ id = 0x3B5, at_bit = 150 }", "{ id = 0x3B5, data = [0x5A], at_bit = 150 }"),
        ("up-filter-single-std-absent-bytes.toml", "data = [0xA5, 0x43], at_bit = 590", "data = [0xA5, 0xC3], at_bit = 590"),
        ("up-filter-single-ext-id25-id9-compared.toml", "write = \"ACR2\", value = 0x6D", "write = \"ACR2\", value = 0x7D"),
        ("up-filter-single-ext-id25-id9-compared.toml", "id = 0x078BCDAF", "id = 0x058BCDAF"),
        ("up-filter-dual-std-data-byte1-low.toml", "data = [0x97], at_bit = 150", "data = [0x96], at_bit = 150"),
        ("up-rx-info-past-16-releases.toml", "read = \"RXFI\", expect = 0x01, note = \"message 18", "read = \"RXFI\", expect = 0xD1, note = \"message 18"),
        ("up-ewlr-odd-rec.toml", "write = \"EWLR\", value = 9 }", "write = \"EWLR\", value = 8 }"),
        ("up-ewlr-odd-rec.toml", "expect = 0x00, mask = 0xC0, note = \"REC 4", "expect = 0x40, mask = 0xC0, note = \"REC 4"),
    ] {
        let path = root().join("tb/mutation-holes").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(from), "{file}: the deciding stimulus moved");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
        assert!(!o.passed, "{file}: `{to}` passed as well");
    }
}

/// The `up-` scenarios (opencores seed-1 survivors) check what
/// they claim: on the model, the bit error moved from ID.11 to ID.13 gives
/// another ECC segment, DOIE set makes the overrun raise DOI, the ID.20 or
/// ID.12 term made don't care lets the frame between the two accepted ones
/// in, and a read-back or message-order expectation changed fails.
#[test]
fn up_scenarios_fail_with_their_fault_moved_or_value_changed() {
    for (file, from, to) in [
        ("up-ecc-segment-id11.toml", "bit_in_frame = 20", "bit_in_frame = 18"),
        ("up-overrun-doie-off.toml", "write = \"IER\", value = 0x00, note = \"no interrupt", "write = \"IER\", value = 0x08, note = \"no interrupt"),
        ("up-filter-single-ext-id20-id12.toml", "write = \"AMR1\", value = 0x00", "write = \"AMR1\", value = 0x80"),
        ("up-filter-single-ext-id20-id12.toml", "write = \"AMR2\", value = 0x00", "write = \"AMR2\", value = 0x80"),
        ("up-basic-readback-bit-pairs.toml", "read = 14, expect = 0x21", "read = 14, expect = 0x61"),
        ("up-fifo-65-messages-no-release.toml", "read = \"RXB+2\", expect = 0x22", "read = \"RXB+2\", expect = 0x11"),
    ] {
        let path = root().join("tb/mutation-holes").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(from), "{file}: the mutation point moved");
        let s = Scenario::parse(&text, &path).unwrap();
        assert!(run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() }).passed, "{file} as shipped");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
        assert!(!o.passed, "{file}: `{to}` still passed");
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

/// The holes of today's rtl/ sample (`rtl-*.toml`): a wrong value
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

/// ecc-stuff-after-crc-rx / -tx (rtl/ mutant 20: the ECC segment of an error
/// in the stuff bit after the CRC's last bit) are live, on the model and on
/// our RTL. Receiver: the flip moved one bit earlier (the last CRC bit: the
/// stuff bit is then taken for the delimiter, a form error at the ACK
/// delimiter, ECC 0x7B) or one bit later (the CRC delimiter: form error,
/// 0x78) fails, and so does ECC expected as the mutant reads it (0xB8).
/// Transmitter: one bit later (its CRC delimiter read back dominant: form
/// error, 0x58) and the mutant's ECC (0x18) fail; one bit earlier is a bit
/// error in the last CRC bit, whose ECC is the same 0x08 by the datasheet
/// (segment CRC sequence either way), so that one passes: there the RX
/// scenario is the one that tells the stuff bit apart.
#[test]
fn stuff_after_crc_scenarios_fail_with_the_flip_moved_or_the_ecc_changed() {
    for (file, ecc_from, ecc_to, earlier_passes) in [
        ("ecc-stuff-after-crc-rx.toml", "read = \"ECC\", expect = 0xA8,", "read = \"ECC\", expect = 0xB8,", false),
        ("ecc-stuff-after-crc-tx.toml", "read = \"ECC\", expect = 0x08,", "read = \"ECC\", expect = 0x18,", true),
    ] {
        let path = root().join("tb/mutation-holes").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        for dut in [DutSpec::model(), DutSpec::rtl()] {
            let opts = || RunOptions { dut: Some(dut.clone()), ..Default::default() };
            assert!(run(&Scenario::parse(&text, &path).unwrap(), &opts()).passed, "{file} as shipped on {}", dut.name);
            for (from, to, passes) in [
                ("bit_in_frame = 43", "bit_in_frame = 42", earlier_passes),
                ("bit_in_frame = 43", "bit_in_frame = 44", false),
                (ecc_from, ecc_to, false),
            ] {
                assert!(text.contains(from), "{file}: the mutation point moved: {from}");
                let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
                let o = run(&s, &opts());
                assert_eq!(o.passed, passes, "{file} on {} with `{to}`", dut.name);
            }
        }
    }
}
