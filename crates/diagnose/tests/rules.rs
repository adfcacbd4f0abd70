//! One test per rule, from hand-built run records shaped like the runs the
//! issue describes (seed 000 thesis wiring, upstream opencores counts).

use can_engine::{ErrorKind, FaultState};
use can_proto::Field;
use diagnose::rules;
use diagnose::*;

/// The thesis wiring: rx tied recessive, no other node, PIO access.
fn thesis_wiring() -> Wiring {
    Wiring { rx: RxWiring::TiedRecessive, tx_on_bus: false, ..Default::default() }
}

/// TEC per attempt as the upstream opencores core counts it with rx tied
/// recessive (measured): 136 after attempt 1, +8 per attempt,
/// bus-off during attempt 16.
fn upstream_tied_trace(side: Side) -> Vec<TecStep> {
    (1..=16u32)
        .map(|a| {
            let tec = 136 + 8 * (a as u16 - 1);
            TecStep { node: side, attempt: a, bit: 25 * a as u64, tec, bus_off: tec > 255 }
        })
        .collect()
}

fn strict_trace(side: Side) -> Vec<TecStep> {
    rules::strict_tied_recessive_trace()
        .into_iter()
        .enumerate()
        .map(|(i, tec)| TecStep { node: side, attempt: i as u32 + 1, bit: 25 * (i as u64 + 1), tec, bus_off: tec > 255 })
        .collect()
}

fn thesis_record() -> RunRecord {
    let mut r = RunRecord::new("de2-thesis", "upstream")
        .with_wiring(thesis_wiring())
        .op(HostOp::write(0, 0x01).reg("CR").mode(CanMode::BasicCan, false))
        .op(HostOp::write(1, 0x01).reg("CMR").mode(CanMode::BasicCan, false))
        .event(
            EngineEvent::new(412, Side::Dut, EventKind::BusError { kind: ErrorKind::Bit, ecc: 0x03, field: Field::Sof })
                .tec(8),
        )
        .event(
            EngineEvent::new(412, Side::Model, EventKind::BusError { kind: ErrorKind::Bit, ecc: 0x03, field: Field::Sof })
                .tec(8),
        );
    r.tec_trace = upstream_tied_trace(Side::Dut);
    r.tec_trace.extend(strict_trace(Side::Model));
    r.final_dut = Some(FinalRegs { sr: 0xD4, ir: 0xE0, tec: 256, rec: 0, ..FinalRegs::default() });
    r.push_bit(BusBit { bit: 412, bus: true, dut_tx: false, model_tx: false, dut_rx: true, field: Some(Field::Sof), frame: Some(1) }, 64);
    r
}

#[test]
fn strict_trace_is_136_then_8_per_attempt_busoff_in_16th() {
    let t = rules::strict_tied_recessive_trace();
    assert_eq!(t[0], 136);
    assert_eq!(t[1], 144);
    assert_eq!(t.len(), 16);
    assert!(t[15] > 255 && t[14] <= 255);
}

#[test]
fn rx_tied_recessive_is_diagnosed_with_sof_bit_error() {
    let d = diagnose(&thesis_record());
    assert_eq!(d.category, Category::RxNotFollowingTx, "{}", d.to_text());
    assert_eq!(d.figures.field, Some(Field::Sof));
    assert_eq!(d.figures.bit, Some(412));
    assert_eq!(d.figures.expected.as_deref(), Some("dominant (0)"));
    assert_eq!(d.figures.seen.as_deref(), Some("recessive (1)"));
    assert_eq!(d.figures.first_attempt_tec, Some(136));
    assert_eq!(d.figures.bus_off_attempt, Some(16));
    assert_eq!(d.figures.sr, Some(0xD4));
    assert!(d.root_cause.contains("tied to 1"));
    assert!(d.fix.contains("transceiver"));
    // the 136 is explained by the CAN 2.0B rule that makes it
    assert!(d.what_happened.contains("128 + 8 = 136"), "{}", d.what_happened);
    assert!(d.what_happened.contains("during attempt 16"), "{}", d.what_happened);
    // upstream counts equal the CAN 2.0B counts: no difference to explain
    assert_eq!(d.counts_note, None);
}

/// A DUT that switches to a passive flag as soon as TEC reaches 128.
fn early_passive_trace(side: Side) -> Vec<TecStep> {
    (1..=17u32)
        .map(|a| {
            let tec = 128 + 8 * (a as u16 - 1);
            TecStep { node: side, attempt: a, bit: 25 * a as u64, tec, bus_off: tec > 255 }
        })
        .collect()
}

#[test]
fn counts_note_names_the_rule_when_dut_goes_passive_early() {
    let mut r = thesis_record();
    r.tec_trace = early_passive_trace(Side::Dut);
    r.tec_trace.extend(strict_trace(Side::Model));
    let n = diagnose(&r).counts_note.expect("counts differ from CAN 2.0B");
    assert!(n.contains("attempt 1: DUT TEC 128, model (CAN 2.0B) TEC 136"), "{n}");
    assert!(n.contains("causes the node to send an active error flag"), "{n}");
    assert!(n.contains("attempt 17 on the DUT, in attempt 16"), "{n}");
}

#[test]
fn counts_note_names_extra_active_flags() {
    let mut r = thesis_record();
    r.tec_trace = (1..=15u32)
        .map(|a| TecStep { node: Side::Dut, attempt: a, bit: 0, tec: 144 + 8 * (a as u16 - 1), bus_off: 144 + 8 * (a as u16 - 1) > 255 })
        .collect();
    r.tec_trace.extend(strict_trace(Side::Model));
    let n = rules::counts_note(&r).unwrap();
    assert!(n.contains("1 more bit error"), "{n}");
    assert!(n.contains("while error passive"), "{n}");
}

#[test]
fn counts_note_uses_analytic_counts_without_model_trace() {
    let mut r = thesis_record();
    r.tec_trace = early_passive_trace(Side::Dut);
    let n = rules::counts_note(&r).expect("analytic CAN 2.0B counts");
    assert!(n.contains("model (CAN 2.0B) TEC 136"), "{n}");
}

#[test]
fn no_counts_note_when_dut_matches_model() {
    let mut r = thesis_record();
    r.tec_trace = upstream_tied_trace(Side::Dut);
    r.tec_trace.extend(upstream_tied_trace(Side::Model));
    assert_eq!(rules::counts_note(&r), None);
}

#[test]
fn ecc_segment_gives_the_field_of_detection() {
    assert_eq!(field_from_ecc(0x03), Some(Field::Sof));
    assert_eq!(field_from_ecc(0xD9), Some(Field::AckSlot));
    assert_eq!(field_from_ecc(0x11), Some(Field::ActiveErrorFlag));
    assert_eq!(field_from_ecc(0x00), None);
    // the recorded field (drained late) is overridden by the ECC segment
    let r = RunRecord::new("x", "y").event(EngineEvent::new(
        14,
        Side::Model,
        EventKind::BusError { kind: ErrorKind::Bit, ecc: 0x03, field: Field::ActiveErrorFlag },
    ));
    assert_eq!(r.first_bus_error(Side::Model).unwrap().2, Field::Sof);
}

fn loopback_no_ack() -> RunRecord {
    let mut r = RunRecord::new("de2-loopback-no-ack", "upstream").event(EngineEvent::new(
        440,
        Side::Dut,
        EventKind::BusError { kind: ErrorKind::Ack, ecc: 0xD9, field: Field::AckSlot },
    ));
    r.tec_trace = (1..=40)
        .map(|a| TecStep { node: Side::Dut, attempt: a, bit: 0, tec: (8 * a as u16).min(128), bus_off: false })
        .collect();
    r.stuck = Some(StuckTransfer { requested_ps: 0, requested_bit: 400, waited_bits: 5000, sr: 0x60, attempts: 40 });
    r.final_dut = Some(FinalRegs { sr: 0x60, tec: 128, ..Default::default() });
    r
}

#[test]
fn loopback_without_ack_node_is_no_acknowledge_with_sr_0x60() {
    let d = diagnose(&loopback_no_ack());
    assert_eq!(d.category, Category::NoAcknowledge, "{}", d.to_text());
    assert_eq!(d.figures.tec, Some(128));
    assert_eq!(d.figures.sr, Some(0x60));
    assert_eq!(d.figures.field, Some(Field::AckSlot));
    assert!(d.what_happened.contains("TBS = 0"));
    assert!(d.what_happened.contains("TS = 1"));
    assert!(d.root_cause.contains("exception 1"));
    // StuckTransfer is explained by the ACK rule, listed as secondary.
    assert!(d.also.iter().any(|f| f.category == Category::StuckTransfer));
}

#[test]
fn aborted_request_without_ack_is_not_called_forever() {
    // tb/pelican-self-test-abort: two ACK errors, then CMR.AT; SR ends with
    // TBS = 1, TS = 0. The text must say the request ended, not "forever".
    let mut r = loopback_no_ack();
    r.stuck = None;
    r.tec_trace.truncate(2);
    r.final_dut = Some(FinalRegs { sr: 0x04, tec: 16, ..Default::default() });
    r = r.op(HostOp::write(1, 0x02).reg("CMR"));
    let d = diagnose(&r);
    assert_eq!(d.category, Category::NoAcknowledge, "{}", d.to_text());
    assert!(!d.what_happened.contains("forever"), "{}", d.what_happened);
    assert!(d.what_happened.contains("TBS = 1"), "{}", d.what_happened);
    assert!(d.what_happened.contains("CMR.AT"), "{}", d.what_happened);
    // Without the abort write, a released buffer is put down to single shot.
    let mut r = loopback_no_ack();
    r.stuck = None;
    r.final_dut = Some(FinalRegs { sr: 0x04, tec: 8, ..Default::default() });
    let d = diagnose(&r);
    assert!(d.what_happened.contains("single shot"), "{}", d.what_happened);
}

#[test]
fn self_test_or_ack_node_silences_no_acknowledge() {
    let mut r = loopback_no_ack();
    r.wiring.self_test = true;
    assert!(rules::no_acknowledge(&r).is_none());
    let mut r = loopback_no_ack();
    r.wiring.nodes.push(BusNode { name: "ack".into(), timing: Timing::default(), acknowledges: true });
    assert!(rules::no_acknowledge(&r).is_none());
}

#[test]
fn bit_rate_mismatch_names_both_rates_and_a_fix() {
    let mut r = RunRecord::new("mismatch", "rtl");
    r.wiring.nodes.push(BusNode {
        name: "node2".into(),
        timing: Timing { can_clock_hz: 16e6, host_clock_hz: 0.0, btr0: 0x03, btr1: 0xBB },
        acknowledges: true,
    });
    let d = diagnose(&r);
    assert_eq!(d.category, Category::BitTimingMismatch, "{}", d.to_text());
    assert!(d.what_happened.contains("600000 bit/s"), "{}", d.what_happened);
    assert!(d.what_happened.contains("117647 bit/s"), "{}", d.what_happened);
    // 117647 bit/s is not reachable exactly from 24 MHz (24e6/117647 is not an integer)
    assert!(d.fix.contains("No BTR setting") || d.fix.contains("BTR0 = 0x"));
}

#[test]
fn suggest_btr_hits_the_rate() {
    let (b0, b1) = rules::suggest_btr(24e6, 500_000.0, 0.75).expect("500k from 24 MHz");
    let t = can_proto::timing::BusTiming::from_btr(b0, b1);
    assert_eq!(t.bit_rate(24e6), 500_000.0);
    assert!((t.sample_point() - 0.75).abs() < 0.05);
}

#[test]
fn same_rate_nodes_are_not_a_mismatch() {
    let mut r = RunRecord::new("ok", "rtl");
    r.wiring.nodes.push(BusNode { name: "n".into(), timing: Timing::default(), acknowledges: true });
    assert!(rules::bit_timing_mismatch(&r).is_none());
    assert_eq!(diagnose(&r).category, Category::Pass);
}

#[test]
fn config_write_in_operating_mode_is_reported() {
    let r = RunRecord::new("cfg", "model")
        .op(HostOp::write(6, 0x41).reg("BTR0").mode(CanMode::BasicCan, false).outcome(WriteOutcome::IgnoredNotInResetMode))
        .op(HostOp::write(7, 0x25).reg("BTR1").mode(CanMode::BasicCan, false).outcome(WriteOutcome::IgnoredNotInResetMode));
    let d = diagnose(&r);
    assert_eq!(d.category, Category::ConfigWriteOutsideReset);
    assert!(d.what_happened.starts_with("2 configuration write(s)"));
    assert!(d.what_happened.contains("BTR0=0x41"));
    assert_eq!(d.figures.register.as_deref(), Some("BTR0"));
}

#[test]
fn config_write_without_model_verdict_uses_reset_flag() {
    let r = RunRecord::new("cfg", "rtl").op(HostOp::write(4, 0xFF).reg("ACR").mode(CanMode::BasicCan, false));
    assert_eq!(diagnose(&r).category, Category::ConfigWriteOutsideReset);
    let r = RunRecord::new("cfg", "rtl").op(HostOp::write(4, 0xFF).reg("ACR").mode(CanMode::BasicCan, true));
    assert!(rules::config_write_outside_reset(&r).is_none());
}

#[test]
fn tx_buffer_locked_write_is_reported() {
    let r = RunRecord::new("lock", "model")
        .op(HostOp::write(10, 0xA5).reg("TXB1").outcome(WriteOutcome::IgnoredTxBufferLocked));
    let d = diagnose(&r);
    assert_eq!(d.category, Category::TxBufferWriteWhileLocked);
    assert_eq!(d.figures.addr, Some(10));
    assert!(d.fix.contains("TBS = 1"));
}

#[test]
fn ier_at_address_4_in_basiccan_is_address_confusion() {
    let r = RunRecord::new("confusion", "model").op(
        HostOp::write(4, 0x00)
            .reg("ACR")
            .intended("IER")
            .mode(CanMode::BasicCan, false)
            .outcome(WriteOutcome::IgnoredNotInResetMode),
    );
    let d = diagnose(&r);
    assert_eq!(d.category, Category::AddressModeConfusion, "{}", d.to_text());
    assert_eq!(d.figures.expected.as_deref(), Some("IER"));
    assert_eq!(d.figures.seen.as_deref(), Some("ACR"));
    assert!(d.what_happened.contains("address 4"));
    // the ignored write is also reported, after the confusion
    assert_eq!(d.also[0].category, Category::ConfigWriteOutsideReset);
}

#[test]
fn reading_rx_info_at_16_in_reset_mode_is_confusion() {
    let r = RunRecord::new("annexe4", "model")
        .op(HostOp::read(16, 0xFF).reg("ACR0").intended("RXFI").mode(CanMode::PeliCan, true));
    let d = diagnose(&r);
    assert_eq!(d.category, Category::AddressModeConfusion);
    assert!(d.what_happened.contains("read RXFI at address 16"), "{}", d.what_happened);
}

#[test]
fn begintransfer_as_cyc_is_a_host_bus_violation() {
    let mut r = RunRecord::new("de2-avalon-begintransfer", "rtl");
    r.host_bus = HostBus::Avalon;
    r.violations.push(Violation {
        cycle: 3,
        rule: "avalon.cyc_from_begintransfer".into(),
        message: "wb_stb_i high while wb_cyc_i low".into(),
    });
    let d = diagnose(&r);
    assert_eq!(d.category, Category::HostBusViolation);
    assert!(d.root_cause.contains("begintransfer"));
    assert!(d.fix.contains("waitrequest"));
    assert!(d.what_happened.contains("host cycle 3"));
}

#[test]
fn never_acked_access_is_a_timeout() {
    let r = RunRecord::new("dead", "rtl").op(HostOp::read(2, 0).reg("SR").error("no wb_ack_o within 1000 cycles"));
    let d = diagnose(&r);
    assert_eq!(d.category, Category::HostBusTimeout);
    assert!(d.what_happened.contains("no wb_ack_o"));
    assert!(d.root_cause.contains("not clocked"));
    // through PIO, when the DUT did answer, the cause is a pulse ack missed
    // by the polling loop
    let mut op = HostOp::read(2, 0).reg("SR").error("timed out");
    op.bfm = HostBus::Pio;
    op.acks_seen = 2;
    let d = diagnose(&RunRecord::new("pio", "rtl").op(op));
    assert!(d.root_cause.contains("one-cycle wb_ack_o pulse"), "{}", d.root_cause);
    assert!(d.fix.contains("level acknowledge"));
}

fn broken_dut_record() -> RunRecord {
    let mut r = RunRecord::new("de2-with-ack-node", "broken-crc");
    r.wiring.nodes.push(BusNode { name: "acker".into(), timing: Timing::default(), acknowledges: true });
    r.divergence = Some(Divergence {
        kind: DivergenceKind::TxBit,
        time_ps: 1_234_000,
        bit: Some(470),
        frame: Some(1),
        field: Some(Field::Crc),
        register: None,
        expected: 1,
        seen: 0,
        context: "CRC bit 3".into(),
    });
    r
}

#[test]
fn divergence_names_field_frame_and_bit() {
    let d = diagnose(&broken_dut_record());
    assert_eq!(d.category, Category::DutDeviatesFromModel);
    assert_eq!(d.figures.field, Some(Field::Crc));
    assert_eq!(d.figures.bit, Some(470));
    assert_eq!(d.figures.frame, Some(1));
    assert!(d.what_happened.contains("CRC sequence"));
    assert!(d.root_cause.contains("CRC sequence"));
    assert!(d.to_text().contains("bit 470"));
}

#[test]
fn early_divergence_outranks_wiring() {
    // rx tied and a divergence before the model's first bus error: HDL bug first.
    let mut r = thesis_record();
    r.divergence = Some(Divergence { kind: DivergenceKind::TxBit, bit: Some(100), field: Some(Field::BusIdle), ..Default::default() });
    assert_eq!(diagnose(&r).category, Category::DutDeviatesFromModel);
    // a divergence after it (the error flag) is explained by the wiring
    let mut r = thesis_record();
    r.divergence = Some(Divergence { kind: DivergenceKind::TxBit, bit: Some(430), field: Some(Field::ActiveErrorFlag), ..Default::default() });
    let d = diagnose(&r);
    assert_eq!(d.category, Category::RxNotFollowingTx);
    assert!(d.also.iter().any(|f| f.category == Category::DutDeviatesFromModel));
}

#[test]
fn register_divergence_shows_sr_bits() {
    let mut r = RunRecord::new("sr", "rtl");
    r.divergence = Some(Divergence { kind: DivergenceKind::RegisterRead, register: Some("SR".into()), expected: 0x0C, seen: 0x04, ..Default::default() });
    let d = diagnose(&r);
    assert_eq!(d.category, Category::DutDeviatesFromModel);
    assert!(d.what_happened.contains("0x0C (TCS TBS)"), "{}", d.what_happened);
}

#[test]
fn failed_expectation_and_stuck_transfer_and_run_error() {
    let mut r = RunRecord::new("x", "model");
    r.expectations.push(Expectation { step: 3, what: "SR".into(), expected: "0x0C".into(), seen: "0x04".into(), passed: false });
    assert_eq!(diagnose(&r).category, Category::ExpectationFailed);
    let mut r = RunRecord::new("x", "model");
    r.wiring.nodes.push(BusNode { name: "acker".into(), timing: Timing::default(), acknowledges: true });
    r.stuck = Some(StuckTransfer { sr: 0x30, waited_bits: 1000, ..Default::default() });
    let d = diagnose(&r);
    assert_eq!(d.category, Category::StuckTransfer);
    assert!(d.what_happened.contains("TS = 1, TBS = 0"));
    let mut r = RunRecord::new("x", "ext");
    r.error = Some("verilator: can_top.v:12: syntax error".into());
    assert_eq!(diagnose(&r).category, Category::RunError);
}

#[test]
fn clean_run_passes() {
    let mut r = RunRecord::new("ok", "rtl");
    r.expectations.push(Expectation { step: 1, what: "SR".into(), expected: "0x0C".into(), seen: "0x0C".into(), passed: true });
    let d = diagnose(&r);
    assert_eq!(d.category, Category::Pass);
    assert!(d.to_text().contains("Pass"));
}

#[test]
fn record_and_diagnosis_round_trip_through_json() {
    let mut r = thesis_record();
    r.events.push(EngineEvent::new(9000, Side::Dut, EventKind::FaultState(FaultState::BusOff)));
    let back = RunRecord::from_json(&r.to_json()).unwrap();
    assert_eq!(back, r);
    let d = diagnose(&r);
    let j: serde_json::Value = serde_json::from_str(&d.to_json()).unwrap();
    assert_eq!(j["category"], "RxNotFollowingTx");
    assert_eq!(j["figures"]["field"], "Sof");
    assert_eq!(j["figures"]["first_attempt_tec"], 136);
    let back: Diagnosis = serde_json::from_str(&d.to_json()).unwrap();
    assert_eq!(back, d);
}

#[test]
fn category_names_round_trip() {
    for c in Category::ALL {
        assert_eq!(Category::from_name(c.name()), Some(c));
    }
    assert_eq!(Category::from_name("Nope"), None);
}

#[test]
fn push_bit_keeps_last_n() {
    let mut r = RunRecord::default();
    for i in 0..10 {
        r.push_bit(BusBit { bit: i, ..Default::default() }, 4);
    }
    assert_eq!(r.bus_bits.iter().map(|b| b.bit).collect::<Vec<_>>(), vec![6, 7, 8, 9]);
}

#[test]
fn pio_handshake_remarks_are_advisory() {
    let mut r = RunRecord::new("pio", "model");
    r.host_bus = HostBus::Pio;
    r.violations.push(Violation { cycle: 34, rule: "wb.cyc_dropped_before_ack".into(), message: "cyc fell".into() });
    let d = diagnose(&r);
    assert_eq!(d.category, Category::Pass, "{}", d.to_text());
    assert!(d.also[0].advisory);
    assert!(d.to_text().contains("Note (HostBusViolation)"));
    // the same on a Wishbone master is a violation
    r.host_bus = HostBus::Wishbone;
    assert_eq!(diagnose(&r).category, Category::HostBusViolation);
    // and on PIO with the rx wiring fault, the wiring is the diagnosis
    let mut t = thesis_record();
    t.host_bus = HostBus::Pio;
    t.violations.push(Violation { cycle: 34, rule: "wb.ack_without_request".into(), message: "ack".into() });
    assert_eq!(diagnose(&t).category, Category::RxNotFollowingTx);
}

#[test]
fn divergence_field_comes_from_the_models_bus_error_at_that_bit() {
    let mut r = broken_dut_record();
    r.divergence.as_mut().unwrap().field = Some(Field::ActiveErrorFlag);
    r.events.push(EngineEvent::new(470, Side::Model, EventKind::BusError { kind: ErrorKind::Bit, ecc: 0x08, field: Field::ActiveErrorFlag }));
    let d = diagnose(&r);
    assert_eq!(d.figures.field, Some(Field::Crc));
    assert!(d.what_happened.contains("CRC sequence"), "{}", d.what_happened);
}

#[test]
fn pio_timeout_says_missed_pulse_only_when_the_dut_answered() {
    let op = |acks: u32| {
        let mut o = HostOp::read(31, 0).reg("CDR");
        o.bfm = HostBus::Pio;
        o.error = Some("timeout".into());
        o.acks_seen = acks;
        o
    };
    let d = diagnose(&RunRecord::new("pio", "rtl").op(op(1)));
    assert_eq!(d.category, Category::HostBusTimeout);
    assert!(d.root_cause.contains("missed between two polls"), "{}", d.root_cause);
    let d = diagnose(&RunRecord::new("pio", "rtl").op(op(0)));
    assert_eq!(d.category, Category::HostBusTimeout);
    assert!(d.root_cause.contains("never raised wb_ack_o"), "{}", d.root_cause);
}

/// A record with a first divergence (tx bit at bit 21)
/// and, later, a read the derailed model names in its own register view
/// (RXFI intended, ACR0 in the model's reset mode) and a TX-buffer write it
/// calls locked.
fn diverged_then_model_view_symptoms(op_time_ps: u64) -> RunRecord {
    let mut r = RunRecord::new("pelican-frame-kinds", "upstream").with_mode(CanMode::PeliCan);
    r.divergence = Some(Divergence {
        kind: DivergenceKind::TxBit,
        time_ps: 35_000_000,
        bit: Some(21),
        frame: Some(1),
        field: Some(Field::ActiveErrorFlag),
        register: None,
        expected: 0,
        seen: 1,
        context: "at the sample point the model drives dominant and the DUT's tx_o is recessive".into(),
    });
    r.host_ops.push(HostOp::read(16, 0x02).reg("ACR0").intended("RXFI").mode(CanMode::PeliCan, true).at(op_time_ps));
    r.host_ops.push(
        HostOp::write(16, 0x43)
            .reg("TXFI")
            .mode(CanMode::PeliCan, false)
            .outcome(WriteOutcome::IgnoredTxBufferLocked)
            .at(op_time_ps + 1_000),
    );
    r
}

#[test]
fn the_first_divergence_leads_and_later_model_view_symptoms_follow_it() {
    let d = diagnose(&diverged_then_model_view_symptoms(900_000_000));
    assert_eq!(d.category, Category::DutDeviatesFromModel, "{}", d.to_text());
    assert_eq!(d.figures.bit, Some(21));
    assert!(d.what_happened.contains("tx_o differs"), "{}", d.what_happened);
    let later: Vec<&Finding> = d
        .also
        .iter()
        .filter(|f| matches!(f.category, Category::AddressModeConfusion | Category::TxBufferWriteWhileLocked))
        .collect();
    assert_eq!(later.len(), 2, "both symptoms are still listed: {}", d.to_text());
    for f in later {
        assert!(
            f.what_happened.starts_with("after the first divergence (tx bit at 35000000 ps, bit 21), in the model's view"),
            "marked as a later symptom: {}",
            f.what_happened
        );
        assert!(f.root_cause.starts_with("a later symptom"), "{}", f.root_cause);
    }
    // A program error before the divergence still leads: it may be its cause.
    let d = diagnose(&diverged_then_model_view_symptoms(1_000_000));
    assert_eq!(d.category, Category::AddressModeConfusion, "{}", d.to_text());
    assert!(!d.what_happened.contains("after the first divergence"));
}

/// de2-with-ack-node on the upstream core: the model derails at bit 16 and
/// then counts TEC 136, 144, 152, 160 per attempt, while the core ends
/// with TEC 0 (its TXERR read). The diagnosis quotes the DUT's TEC and
/// never presents the model's counts after the divergence as the DUT's.
#[test]
fn figures_come_from_the_dut_or_are_marked_as_the_models() {
    let mut r = RunRecord::new("de2-with-ack-node", "upstream").with_mode(CanMode::PeliCan);
    r.divergence = Some(Divergence {
        kind: DivergenceKind::RegisterRead,
        time_ps: 29_170_000,
        bit: Some(16),
        register: Some("SR".into()),
        expected: 0x00,
        seen: 0x20,
        ..Divergence::default()
    });
    r.tec_trace = (1..=4u32)
        .map(|a| TecStep { node: Side::Model, attempt: a, bit: 100 * a as u64, tec: 128 + 8 * a as u16, bus_off: false })
        .collect();
    r.final_dut = Some(FinalRegs { sr: 0x0C, ir: 0, tec: 0, rec: 0, ..FinalRegs::default() });
    let d = diagnose(&r);
    assert_eq!(d.category, Category::DutDeviatesFromModel);
    assert_eq!(d.figures.tec, Some(0), "the DUT's TXERR read");
    assert!(!d.figures.tec_from_model);
    assert_eq!(
        (d.figures.first_attempt_tec, d.figures.attempts),
        (None, None),
        "the model's attempts after the divergence say nothing about the DUT"
    );
    let text = d.to_text();
    for model_figure in ["136", "160", "4 attempts"] {
        assert!(!text.contains(model_figure), "{model_figure} in {text}");
    }
    assert!(text.contains("TEC 0;") || text.contains("TEC 0\n"), "{text}");
    // Without a DUT read of TXERR (BasicCAN), and with model attempts
    // before the divergence: the model's figures, and said to be.
    r.final_dut = None;
    r.divergence.as_mut().unwrap().bit = Some(250);
    let d = diagnose(&r);
    assert_eq!((d.figures.first_attempt_tec, d.figures.attempts, d.figures.tec), (Some(136), Some(2), Some(144)));
    assert!(d.figures.counts_from_model && d.figures.tec_from_model);
    let text = d.to_text();
    assert!(text.contains("TEC after attempt 1 = 136 (the model's)"), "{text}");
    assert!(text.contains("TEC 144 (the model's)"), "{text}");
    assert!(text.contains("2 attempts (the model's)"), "{text}");
    // With a DUT trace, the DUT's figures, unmarked.
    r.tec_trace.extend((1..=2u32).map(|a| TecStep { node: Side::Dut, attempt: a, bit: 100 * a as u64, tec: 8 * a as u16, bus_off: false }));
    let d = diagnose(&r);
    assert_eq!((d.figures.first_attempt_tec, d.figures.tec), (Some(8), Some(16)));
    assert!(!d.figures.counts_from_model && !d.to_text().contains("the model's)"));
}

/// BasicCAN has no counter registers: the scenario runner fills the DUT's
/// final TEC/REC from the model (`counters_from_model`). After a divergence
/// they are not the DUT's and are not quoted; without one they are, marked.
#[test]
fn counters_taken_from_the_model_are_marked_and_dropped_after_a_divergence() {
    let mut r = RunRecord::new("de2-with-ack-node", "upstream");
    r.final_dut = Some(FinalRegs { sr: 0x0C, tec: 160, rec: 0, counters_from_model: true, ..FinalRegs::default() });
    r.divergence = Some(Divergence { kind: DivergenceKind::RegisterRead, time_ps: 29_170_000, bit: Some(16), register: Some("SR".into()), expected: 0x00, seen: 0x20, ..Divergence::default() });
    let d = diagnose(&r);
    assert_eq!((d.figures.tec, d.figures.rec, d.figures.sr), (None, None, Some(0x0C)), "SR is the DUT's read");
    assert!(!d.to_text().contains("160"), "{}", d.to_text());
    r.divergence = None;
    r.expectations.push(Expectation { step: 3, what: "SR".into(), expected: "0x04".into(), seen: "0x0C".into(), passed: false });
    let d = diagnose(&r);
    assert_eq!(d.figures.tec, Some(160));
    assert!(d.to_text().contains("TEC 160 (the model's); REC 0 (the model's)"), "{}", d.to_text());
}

/// An access the core performed again (the PIO master held its
/// request past the core's one-clock ack) is named beside the primary
/// finding, and never becomes the primary one itself.
#[test]
fn accesses_the_core_repeated_are_named_as_the_host_s_doing() {
    let mut r = RunRecord::new("x", "ext");
    r.host_bus = HostBus::Pio;
    r.expectations.push(Expectation { step: 22, what: "RXFI".into(), expected: "0x01".into(), seen: "0x00".into(), passed: false });
    let mut rrb = HostOp::write(1, 0x04);
    rrb.bfm = HostBus::Pio;
    rrb.reg = Some("CMR".into());
    rrb.repeats = 1;
    r.host_ops.extend([HostOp::write(4, 0), rrb]);
    let d = diagnose(&r);
    assert_eq!(d.category, Category::ExpectationFailed);
    let note = d.also.iter().find(|f| f.what_happened.contains("more than once")).expect("the repeats are named");
    assert!(note.what_happened.contains("1 host access(es) more than once (1 extra in all, 1 of them a CMR write"), "{}", note.what_happened);
    assert!(note.advisory);
    // No repeats: no note.
    r.host_ops[1].repeats = 0;
    assert!(!diagnose(&r).also.iter().any(|f| f.what_happened.contains("more than once")));
}

/// A node with the same BTR on a clock off by less than the two timings'
/// oscillator tolerances (CAN 2.0B section 10) is a clock tolerance test,
/// not a mismatch; beyond them it is one.
#[test]
fn drifting_oscillator_is_a_mismatch_only_beyond_the_tolerance() {
    let drift = |hz: f64| {
        let mut r = RunRecord::new("drift", "rtl");
        r.wiring.nodes.push(BusNode { name: "n".into(), timing: Timing { can_clock_hz: hz, ..Timing::default() }, acknowledges: true });
        rules::bit_timing_mismatch(&r).is_some()
    };
    // Timing::default: 24 MHz, 0x41/0x25: 10 tq, SJW 2 tq: 1 % per node.
    assert!(!drift(24e6 * 1.015));
    assert!(!drift(24e6 * 0.985));
    assert!(drift(24e6 * 1.025));
    assert!(drift(24e6 * 0.97));
    assert!((can_proto::timing::BusTiming::from_btr(0x41, 0x25).oscillator_tolerance() - 0.01).abs() < 1e-12);
}
