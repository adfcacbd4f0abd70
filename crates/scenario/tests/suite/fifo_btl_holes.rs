//! The scenarios for our rtl/'s mutants 8, 105 (RX FIFO) and 133
//! (bit timing prescaler) check what they claim: on the golden model the
//! deciding stimulus moved by one byte, or the overrun cleared or not, turns
//! the run into a failure, and the large-BRP frames take the time the
//! programmed quantum gives (so the frames really ran at BRP 4..63).

use diagnose::record::Access;
use scenario::{DutSpec, RunOptions, Scenario, run};

#[allow(dead_code)] // only root() of the shared helpers is used here
use crate::common;
use common::root;

fn model() -> RunOptions {
    RunOptions { dut: Some(DutSpec::model()), ..Default::default() }
}

/// `file` passes on the model as shipped, and fails with each `(from, to)`
/// applied alone.
fn live(file: &str, changes: &[(&str, &str)]) {
    let path = root().join("tb/mutation-holes").join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(run(&Scenario::parse(&text, &path).unwrap(), &model()).passed, "{file} as shipped");
    for (from, to) in changes {
        assert!(text.contains(from), "{file}: the deciding point moved: {from}");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        assert!(!run(&s, &model()).passed, "{file}: `{to}` passed as well");
    }
}

/// Refill of a full FIFO: one byte more in either refilling message no
/// longer fits (the exact-fit boundary is what is checked).
#[test]
fn fifo_refill_exact_fit_fails_one_byte_over() {
    live(
        "fifo-full-release-refill.toml",
        &[
            ("data = [0x19, 0x29, 0x39, 0x49, 0x59], at_bit", "data = [0x19, 0x29, 0x39, 0x49, 0x59, 0x69], at_bit"),
            ("data = [0xC1, 0xC2, 0xC3], at_bit", "data = [0xC1, 0xC2, 0xC3, 0xC4], at_bit"),
        ],
    );
}

/// The DOI checks follow DOS's 0 -> 1 transition: without the CDO the loss
/// after it raises no DOI (the "DOI again" check fails), a DOI expected at
/// the loss while DOS = 1 fails, and frame 6 one byte shorter is stored.
#[test]
fn doi_only_on_dos_rising_checks_are_live() {
    live(
        "fifo-overrun-doi-on-dos-rising.toml",
        &[
            ("{ write = \"CMR\", value = 0x08, note = \"CDO: clear data overrun\" }", "{ read = \"RMC\", expect = 6 }"),
            ("{ read = \"IR\", expect = 0x00, note = \"no DOI: DOI", "{ read = \"IR\", expect = 0x08, note = \"no DOI: DOI"),
            ("{ id = 0x206, data = [0x61], at_bit", "{ id = 0x206, data = [], at_bit"),
        ],
    );
}

/// The BasicCAN twin: without the release from full the 10-byte refill is
/// lost; without the CDO the last loss raises no DOI; a DOI expected at the
/// loss while DOS = 1 fails.
#[test]
fn basic_refill_and_doi_checks_are_live() {
    live(
        "basic-fifo-refill-doi-on-dos-rising.toml",
        &[
            ("{ write = \"CMR\", value = 0x04, note = \"release message 1 from the full FIFO", "{ read = \"SR\", note = \"release message 1 from the full FIFO"),
            ("{ write = \"CMR\", value = 0x08, note = \"CDO\" }", "{ read = \"SR\" }"),
            ("{ read = \"IR\", expect = 0xE0, note = \"no DOI: DOS was already 1\" }", "{ read = \"IR\", expect = 0xE8 }"),
        ],
    );
}

/// fifo-rbsa-write-sets-store-address reads the RAM where the RBSA written
/// says the message goes: RBSA written one higher (and the window's RBSA
/// check with it), the RAM reads at 60.. fail.
#[test]
fn rbsa_store_address_checks_are_live() {
    let path = root().join("tb/mutation-holes/fifo-rbsa-write-sets-store-address.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(run(&Scenario::parse(&text, &path).unwrap(), &model()).passed, "as shipped");
    let from = ["{ write = \"RBSA\", value = 0x3C", "{ read = \"RBSA\", expect = 0x3C },", "{ read = \"RBSA\", expect = 0x3C },", "{ read = \"RBSA\", expect = 0x03"];
    let to = ["{ write = \"RBSA\", value = 0x3D", "{ read = \"RBSA\", expect = 0x3D },", "{ read = \"RBSA\", expect = 0x3D },", "{ read = \"RBSA\", expect = 0x04"];
    let mut moved = text.clone();
    for (f, t) in from.iter().zip(to) {
        assert!(moved.contains(f), "the RBSA steps moved: {f}");
        moved = moved.replacen(f, t, 1);
    }
    let o = run(&Scenario::parse(&moved, &path).unwrap(), &model());
    assert!(!o.passed, "RBSA 0x3D passed as well");
    let failed: Vec<&str> = o.record.expectations.iter().filter(|e| !e.passed).map(|e| e.what.as_str()).collect();
    assert!(!failed.is_empty() && failed.iter().all(|w| w.starts_with("RXFIFO")), "not (only) through the RAM reads: {failed:?}");
}

/// Each self-test frame of btl-large-brp-self-test takes 44..100 bit times
/// of its own setting (nq = 10 quanta of 2 (BRP + 1) clocks at 24 MHz),
/// from CMR = SRR to the IR read after its interrupt: the frames ran at BRP
/// 4, 15, 33 and 63, and every BRP bit is 1 in some setting (SJW 1..3).
#[test]
fn large_brp_frames_take_their_quanta() {
    let path = root().join("tb/mutation-holes/btl-large-brp-self-test.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let o = run(&Scenario::parse(&text, &path).unwrap(), &model());
    assert!(o.passed, "as shipped: {:?}", o.mismatches);
    let ops = &o.record.host_ops;
    let btr0: Vec<u8> = ops.iter().filter(|h| h.access == Access::Write && h.addr == 6).map(|h| h.data).collect();
    assert_eq!(btr0, [0x44, 0x8F, 0xE1, 0xFF]);
    assert_eq!(btr0.iter().fold(0, |a, b| a | (b & 0x3F)), 0x3F, "every BRP bit used");
    assert_eq!(btr0.iter().map(|b| b >> 6).collect::<Vec<_>>(), [1, 2, 3, 3], "SJW");
    let starts: Vec<u64> = ops.iter().filter(|h| h.access == Access::Write && h.addr == 1 && h.data == 0x10).map(|h| h.time_ps).collect();
    assert_eq!(starts.len(), 4);
    for (i, (&t0, b)) in starts.iter().zip(&btr0).enumerate() {
        let t1 = ops.iter().find(|h| h.access == Access::Read && h.addr == 3 && h.time_ps > t0).expect("IR read").time_ps;
        let bit_ps = 10.0 * 2.0 * f64::from((b & 0x3F) + 1) * 1e6 / 24.0;
        let bits = (t1 - t0) as f64 / bit_ps;
        assert!((44.0..100.0).contains(&bits), "frame {} at BTR0 0x{b:02X}: {bits:.1} bit times", i + 1);
    }
}

/// btl-large-brp-receive-resync needs its resynchronisation: with SJW = 0
/// (BTR0 0x3F on the DUT and both senders, the rest unchanged) the 1.5 %
/// senders' frames are not received on the model.
#[test]
fn large_brp_receive_needs_sjw() {
    let path = root().join("tb/mutation-holes/btl-large-brp-receive-resync.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(run(&Scenario::parse(&text, &path).unwrap(), &model()).passed, "as shipped");
    assert_eq!(text.matches("btr0 = 0xFF\n").count(), 2, "the senders' BTR0 moved");
    let sjw0 = text.replacen("write = \"BTR0\", value = 0xFF", "write = \"BTR0\", value = 0x3F", 1).replace("btr0 = 0xFF\n", "btr0 = 0x3F\n");
    assert!(!run(&Scenario::parse(&sjw0, &path).unwrap(), &model()).passed, "SJW = 0 passed as well");
}
