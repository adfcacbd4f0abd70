//! The waivers added for tb/conformance on the opencores core
//! (docs/opencores-deviations.md D13-D15 and D18, the freedoms D16/D17/D19, D11 on IR, D3 and D10f
//! variants), read from the shipped file: each waives the divergence that
//! was measured and still catches its near neighbours.

use diagnose::{Divergence, DivergenceKind};
use waivers::{DutInfo, Observed, Verdict, WaiverSet};

fn shipped() -> WaiverSet {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tb/waivers/opencores-upstream.toml");
    WaiverSet::load(path).unwrap()
}

fn dut() -> DutInfo {
    DutInfo::new("opencores-can (/cores/can)")
}

fn read(reg: &str, model: u32, seen: u32) -> Divergence {
    Divergence {
        kind: DivergenceKind::RegisterRead,
        bit: Some(89),
        register: Some(reg.into()),
        expected: model,
        seen,
        ..Divergence::default()
    }
}

/// The id of the waiver that takes `d`, or None if it fails.
fn by(set: &mut WaiverSet, d: &Divergence) -> Option<String> {
    by_observed(set, d, &Observed::default())
}

fn by_observed(set: &mut WaiverSet, d: &Divergence, obs: &Observed) -> Option<String> {
    match set.check_observed(d, &dut(), obs) {
        Verdict::Waived { waiver_id, .. } => Some(waiver_id),
        _ => None,
    }
}

#[test]
fn ecc_direction_d13_only_bit_5_and_only_the_measured_codes() {
    const ID: &str = "ecc-tx-direction-for-receiver-after-own-dominant-bit";
    let mut set = shipped();
    // Measured: ACK slot bit error, ACK delimiter and EOF form errors (RX on the model).
    for (model, seen) in [(0x39, 0x19), (0x7B, 0x5B), (0x7A, 0x5A)] {
        assert_eq!(by(&mut set, &read("ECC", model, seen)).as_deref(), Some(ID), "{model:#x}/{seen:#x}");
    }
    let mut set = shipped();
    // Still caught: another bit differs too (bit error for form error).
    assert_eq!(by(&mut set, &read("ECC", 0x7B, 0x1B)), None);
    // Still caught: a code outside the receiver-after-its-own-dominant-bit list
    // (stuff error in the data field, RX).
    assert_eq!(by(&mut set, &read("ECC", 0xAA, 0x8A)), None);
    // Still caught: the opposite direction swap (model TX, core RX).
    assert_eq!(by(&mut set, &read("ECC", 0x19, 0x39)), None);
    // Still caught: another register with the same values.
    assert_eq!(by(&mut set, &read("ALC", 0x39, 0x19)), None);
    // Bounded: three hits, the fourth fails.
    for _ in 0..3 {
        assert_eq!(by(&mut set, &read("ECC", 0x39, 0x19)).as_deref(), Some(ID));
    }
    assert_eq!(by(&mut set, &read("ECC", 0x39, 0x19)), None);
}

#[test]
fn ecc_bit_for_form_error_freedom_only_for_a_transmitter_at_fixed_form_fields() {
    const ID: &str = "ecc-bit-error-for-transmitter-fixed-form-bit";
    let mut set = shipped();
    for (model, seen) in [(0x58, 0x18), (0x5B, 0x1B), (0x5A, 0x1A)] {
        assert_eq!(by(&mut set, &read("ECC", model, seen)).as_deref(), Some(ID), "{model:#x}/{seen:#x}");
    }
    let mut set = shipped();
    // Still caught: the same swap with another segment (form error in the
    // error delimiter is not a transmitter's CRC/ACK delimiter or EOF bit).
    assert_eq!(by(&mut set, &read("ECC", 0x57, 0x17)), None);
    // Still caught: the swap the other way (core form error, model bit error).
    assert_eq!(by(&mut set, &read("ECC", 0x18, 0x58)), None);
    // Still caught: a stuff error reported instead (type 10).
    assert_eq!(by(&mut set, &read("ECC", 0x58, 0x98)), None);
}

#[test]
fn ecc_overload_delimiter_freedom_takes_only_the_two_measured_pairs_once() {
    const ID: &str = "ecc-overload-delimiter-error-coded-as-overload-flag-bit-error";
    let mut set = shipped();
    assert_eq!(by(&mut set, &read("ECC", 0x57, 0x1C)).as_deref(), Some(ID));
    let mut set = shipped();
    assert_eq!(by(&mut set, &read("ECC", 0x77, 0x1C)).as_deref(), Some(ID));
    // Bounded: once per scenario.
    assert_eq!(by(&mut set, &read("ECC", 0x77, 0x1C)), None);
    let mut set = shipped();
    // Still caught: a different core code (overload flag, RX; or the error flag).
    assert_eq!(by(&mut set, &read("ECC", 0x77, 0x3D)), None);
    assert_eq!(by(&mut set, &read("ECC", 0x57, 0x11)), None);
}

#[test]
fn tec_decrement_at_bus_integration_is_exactly_one_below_on_txerr_twice() {
    const ID: &str = "txerr-decremented-by-bus-integration";
    let mut set = shipped();
    assert_eq!(by(&mut set, &read("TXERR", 9, 8)).as_deref(), Some(ID));
    assert_eq!(by(&mut set, &read("TXERR", 0xC8, 0xC7)).as_deref(), Some(ID));
    // Bounded: a third off-by-one read fails.
    assert_eq!(by(&mut set, &read("TXERR", 0xD0, 0xCF)), None);
    let mut set = shipped();
    // Still caught: two below, one above (that is D10a's +1, bus-off only
    // in meaning, but its own entry), and the same on RXERR.
    assert_eq!(by(&mut set, &read("TXERR", 9, 7)), None);
    assert_ne!(by(&mut set, &read("TXERR", 9, 10)).as_deref(), Some(ID));
    assert_eq!(by(&mut set, &read("RXERR", 9, 8)), None);
}

#[test]
fn rec_stops_at_128_only_dut_128_with_the_model_above() {
    const ID: &str = "rec-stops-at-128";
    let mut set = shipped();
    assert_eq!(by(&mut set, &read("RXERR", 0x88, 0x80)).as_deref(), Some(ID));
    assert_eq!(by(&mut set, &read("RXERR", 0x89, 0x80)).as_deref(), Some(ID));
    let mut set = shipped();
    // rx-7.5.5: one RXERR read after each of its four error frames (model
    // 129, 131, 132, 134); a fifth read fails.
    for model in [0x81, 0x83, 0x84, 0x86] {
        assert_eq!(by(&mut set, &read("RXERR", model, 0x80)).as_deref(), Some(ID), "{model:#x}");
    }
    assert_eq!(by(&mut set, &read("RXERR", 0x87, 0x80)), None, "bounded: four per scenario");
    let mut set = shipped();
    // Still caught: a DUT REC other than 128, a model at or below 128, far
    // above (more than 15 lost increments), and TXERR.
    assert_eq!(by(&mut set, &read("RXERR", 0x88, 0x81)), None);
    assert_eq!(by(&mut set, &read("RXERR", 0x7F, 0x80)), None);
    assert_eq!(by(&mut set, &read("RXERR", 0x96, 0x80)), None);
    assert_eq!(by(&mut set, &read("TXERR", 0x88, 0x80)), None);
}

#[test]
fn late_epi_on_ir_and_epi_at_bus_off_are_told_apart() {
    let mut set = shipped();
    // D11: BEI + EPI on the model, BEI alone on the core, no EI.
    assert_eq!(by(&mut set, &read("IR", 0xA0, 0x80)).as_deref(), Some("epi-late-not-yet-in-ir-at-the-error"));
    // D10b: at bus-off, EI in the same read.
    assert_eq!(by(&mut set, &read("IR", 0x24, 0x04)).as_deref(), Some("epi-cleared-by-bus-off"));
    // The late EPI read after the error frame, once.
    assert_eq!(by(&mut set, &read("IR", 0x00, 0x20)).as_deref(), Some("epi-late-read-after-the-error-frame"));
    assert_eq!(by(&mut set, &read("IR", 0x00, 0x20)), None);
    let mut set = shipped();
    // Still caught: BEI missing as well, EPI with another flag on the core.
    assert_eq!(by(&mut set, &read("IR", 0xA0, 0x00)), None);
    assert_eq!(by(&mut set, &read("IR", 0x00, 0x21)), None);
    // Still caught: EPI alone on the model without EI (not a bus-off read,
    // not the measured D11 pair).
    assert_eq!(by(&mut set, &read("IR", 0x20, 0x00)), None);
}

#[test]
fn ts_in_suspend_is_the_profiles_so_no_waiver_takes_suspend_sr_pairs() {
    // SR.TS in suspend transmission is declared in the core's profile
    // (`ts-in-suspend = "clear"`): the reads it explained are no longer
    // waived, so a TS that differs anywhere else is still caught.
    let mut set = shipped();
    for (model, dut) in [(0x64, 0x4C), (0x50, 0x40), (0x64, 0x44), (0x10, 0x00), (0x60, 0x48)] {
        assert_eq!(by(&mut set, &read("SR", model, dut)), None, "SR model {model:#04x}, DUT {dut:#04x}");
    }
}

#[test]
fn the_single_frame_bus_off_pin_waiver_is_bound_to_frame_1_in_operating_mode() {
    const ID: &str = "ei-irq-when-es-clears-during-bus-off-recovery-single-frame";
    let pin = |frame: u32, field: can_proto::Field| Divergence {
        kind: DivergenceKind::Irq,
        bit: Some(429),
        frame: Some(frame),
        field: Some(field),
        expected: 1,
        seen: 0,
        ..Divergence::default()
    };
    let operating = Observed { model_mod: Some(0x00), ..Default::default() };
    let reset = Observed { model_mod: Some(0x01), ..Default::default() };
    let mut set = shipped();
    assert_eq!(by_observed(&mut set, &pin(1, can_proto::Field::BusIdle), &operating).as_deref(), Some(ID));
    // Still caught: another frame (pelican-bus-off-recovery's 16 has its own
    // entry; frame 2..15 none), a field other than bus idle, reset mode.
    let v = by_observed(&mut set, &pin(5, can_proto::Field::BusIdle), &operating);
    assert_eq!(v, None);
    assert_eq!(by_observed(&mut set, &pin(1, can_proto::Field::Data), &operating), None);
    assert_eq!(by_observed(&mut set, &pin(1, can_proto::Field::BusIdle), &reset), None);
}

#[test]
fn ecc_in_the_error_delimiter_d18_takes_only_the_measured_pair_twice() {
    const ID: &str = "ecc-error-in-error-delimiter-coded-as-flag-bit-error-tx";
    let mut set = shipped();
    assert_eq!(by(&mut set, &read("ECC", 0x77, 0x16)).as_deref(), Some(ID));
    assert_eq!(by(&mut set, &read("ECC", 0x77, 0x16)).as_deref(), Some(ID));
    // Bounded: one read per form error in an error delimiter, rx-7.5.5's
    // two; a third fails.
    assert_eq!(by(&mut set, &read("ECC", 0x77, 0x16)), None);
    let mut set = shipped();
    // Still caught: the active flag's code for the same delimiter error (an
    // error-active receiver, not measured), a form error coded in the flag
    // with only the type differing (0x56), RX with the flag's code (0x36).
    assert_eq!(by(&mut set, &read("ECC", 0x77, 0x11)), None);
    assert_eq!(by(&mut set, &read("ECC", 0x77, 0x56)), None);
    assert_eq!(by(&mut set, &read("ECC", 0x77, 0x36)), None);
    // Still caught: 0x16 for another model code (an error in the passive
    // flag itself would be the model's 0x36, not waived here).
    assert_eq!(by(&mut set, &read("ECC", 0x36, 0x16)), None);
    assert_eq!(by(&mut set, &read("ALC", 0x77, 0x16)), None);
}

#[test]
fn ecc_cleared_by_a_read_d19_is_a_profile_freedom_not_a_waiver() {
    // The profile declares it (`ecc-after-read = "cleared"`): no waiver
    // takes an ECC read of 0 any more, whatever the model holds.
    let mut set = shipped();
    for model in [0xAA, 0xAB, 0x77] {
        assert_eq!(by(&mut set, &read("ECC", model, 0x00)), None);
    }
}

#[test]
fn ecc_in_the_error_delimiter_d18_for_a_transmitter_takes_only_0x57_for_0x16_three_times() {
    const ID: &str = "ecc-error-in-error-delimiter-coded-as-flag-bit-error-transmitter";
    let mut set = shipped();
    // tx-8.5.13: three form errors in the error delimiter, one ECC read each.
    for _ in 0..3 {
        assert_eq!(by(&mut set, &read("ECC", 0x57, 0x16)).as_deref(), Some(ID));
    }
    assert_eq!(by(&mut set, &read("ECC", 0x57, 0x16)), None, "bounded: three per scenario");
    let mut set = shipped();
    // Still caught: the active flag's code (an error-active transmitter, not
    // measured), the delimiter error coded RX by the core (0x36), the right
    // segment with only the type differing (0x17: D16 is not waived for the
    // error delimiter), and the overload flag's code that D17 takes only as
    // 0x1C (0x1C for 0x57 goes to D17's own waiver, not this one).
    assert_eq!(by(&mut set, &read("ECC", 0x57, 0x11)), None);
    assert_eq!(by(&mut set, &read("ECC", 0x57, 0x36)), None);
    assert_eq!(by(&mut set, &read("ECC", 0x57, 0x17)), None);
    assert_ne!(by(&mut set, &read("ECC", 0x57, 0x1C)).as_deref(), Some(ID));
    // Still caught: 0x16 for other model codes (a bit error in the passive
    // flag itself as transmitter, 0x16 on both, is no divergence; a form
    // error in the CRC delimiter 0x58 is not an error-frame error).
    assert_eq!(by(&mut set, &read("ECC", 0x58, 0x16)), None);
    assert_eq!(by(&mut set, &read("ECC", 0x56, 0x16)), None);
    // Still caught: another register with the same values.
    assert_eq!(by(&mut set, &read("ALC", 0x57, 0x16)), None);
}
