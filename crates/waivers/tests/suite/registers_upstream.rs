//! The opencores core on tb/registers.list and tb/mutation-holes.list
//! (docs/opencores-deviations.md D8c and D22), read from the
//! shipped waiver file: `rmc-counts-lost-message` takes one more message
//! only (it used to take any RMC pair, and hid RMC 0 for 1, a frame the
//! core never stored), two more is its own waiver, and D22's waivers take
//! the self-received retransmission the core does not store, in self-test
//! mode only.

use diagnose::{Divergence, DivergenceKind};
use waivers::{DutInfo, Observed, Verdict, WaiverSet};

fn shipped() -> WaiverSet {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tb/waivers/opencores-upstream.toml");
    WaiverSet::load(path).unwrap()
}

fn read(reg: &str, model: u32, seen: u32) -> Divergence {
    Divergence { kind: DivergenceKind::RegisterRead, bit: Some(235), register: Some(reg.into()), expected: model, seen, ..Divergence::default() }
}

/// The id of the waiver that takes `d` with the model's MOD `model_mod`, or None if it fails;
/// the model lost two messages to overruns (D8c's `after`; tests/after_overrun.rs takes fewer).
fn by(set: &mut WaiverSet, d: &Divergence, model_mod: Option<u8>) -> Option<String> {
    let obs = Observed { model_mod, model_lost_messages: Some(2), ..Observed::default() };
    match set.check_observed(d, &DutInfo::new("opencores-can (/cores/can)"), &obs) {
        Verdict::Waived { waiver_id, .. } => Some(waiver_id),
        _ => None,
    }
}

const OPERATING: Option<u8> = Some(0x00);
const SELF_TEST: Option<u8> = Some(0x04);

#[test]
fn rmc_d8c_waives_one_or_two_more_messages_never_fewer() {
    let mut set = shipped();
    assert_eq!(by(&mut set, &read("RMC", 5, 6), OPERATING).as_deref(), Some("rmc-counts-lost-message"));
    assert_eq!(by(&mut set, &read("RMC", 5, 7), OPERATING).as_deref(), Some("rmc-counts-two-lost-messages"));
    assert_eq!(by(&mut set, &read("RMC", 0, 2), OPERATING).as_deref(), Some("rmc-counts-two-lost-messages"));
    // Still caught: the core one message short (what the unbounded waiver
    // hid in tec-write-and-count, passive-retransmit-after-suspend and
    // ecc-segment-id13), three more, and the two-more bound.
    let mut set = shipped();
    assert_eq!(by(&mut set, &read("RMC", 1, 0), OPERATING), None);
    assert_eq!(by(&mut set, &read("RMC", 5, 8), OPERATING), None);
    for _ in 0..2 {
        assert_eq!(by(&mut set, &read("RMC", 5, 7), OPERATING).as_deref(), Some("rmc-counts-two-lost-messages"));
    }
    assert_eq!(by(&mut set, &read("RMC", 5, 7), OPERATING), None);
}

#[test]
fn self_reception_d22_only_rbs_and_one_rmc_message_in_self_test_mode() {
    let mut set = shipped();
    assert_eq!(by(&mut set, &read("SR", 0x0D, 0x0C), SELF_TEST).as_deref(), Some("self-reception-dropped-on-retransmission-rbs"));
    assert_eq!(by(&mut set, &read("RMC", 1, 0), SELF_TEST).as_deref(), Some("self-reception-dropped-on-retransmission-rmc"));
    let mut set = shipped();
    // Still caught: outside self-test mode, the opposite way, another SR bit
    // with it, two messages short, another register.
    // (TS = RS = 1 here: `rbs-for-lost-message-entry`, D8's RBS at bus idle, does not apply.)
    assert_eq!(by(&mut set, &read("SR", 0x3D, 0x3C), OPERATING), None);
    assert_eq!(by(&mut set, &read("SR", 0x3C, 0x3D), SELF_TEST), None);
    assert_eq!(by(&mut set, &read("SR", 0x0D, 0x08), SELF_TEST), None);
    assert_eq!(by(&mut set, &read("RMC", 2, 0), SELF_TEST), None);
    assert_eq!(by(&mut set, &read("ECC", 1, 0), SELF_TEST), None);
    // Bounded: RBS twice, RMC once.
    for _ in 0..2 {
        assert!(by(&mut set, &read("SR", 0x0D, 0x0C), SELF_TEST).is_some());
    }
    assert_eq!(by(&mut set, &read("SR", 0x0D, 0x0C), SELF_TEST), None);
    assert!(by(&mut set, &read("RMC", 1, 0), SELF_TEST).is_some());
    assert_eq!(by(&mut set, &read("RMC", 1, 0), SELF_TEST), None);
}

/// The shipped file's tx-bit waivers in bus idle: D6's GTS start
/// of frame only in BasicCAN, D28's late release only with the model bus-off
/// (reset mode), once.
#[test]
fn tx_bits_in_bus_idle_d6_basiccan_only_d28_bus_off_bit_once() {
    let sof = Divergence { kind: DivergenceKind::TxBit, bit: Some(267), field: Some(can_proto::Field::BusIdle), expected: 1, seen: 0, ..Divergence::default() };
    let dut = DutInfo::new("opencores-can (/cores/can)");
    let check = |set: &mut WaiverSet, basic: bool, model_mod: Option<u8>| {
        let obs = Observed { model_mod, model_basic: Some(basic), ..Observed::default() };
        match set.check_observed(&sof, &dut, &obs) {
            Verdict::Waived { waiver_id, .. } => Some(waiver_id),
            _ => None,
        }
    };
    let mut set = shipped();
    assert_eq!(check(&mut set, true, None).as_deref(), Some("basic-gts-starts-transmission"));
    let mut set = shipped();
    assert_eq!(check(&mut set, false, Some(0x01)).as_deref(), Some("tx-released-later-in-the-bus-off-bit"));
    // Still caught: a second such bit (the DUT dominant at the next sample
    // point too), and a dominant bit in PeliCAN bus idle in operating mode
    // (what D6's waiver took for tx-8.5.10 before it was bound to BasicCAN).
    assert_eq!(check(&mut set, false, Some(0x01)), None);
    let mut set = shipped();
    assert_eq!(check(&mut set, false, Some(0x00)), None);
}
