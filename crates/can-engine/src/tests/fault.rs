//! Fault confinement (CAN 2.0B §8) traces, per state.

use super::*;
use crate::{ErrorKind, FaultState};
use can_proto::DOMINANT;

/// Steps a one-node bus, recording TEC after every bit with a bus error.
fn run_recording(
    bus: &mut TestBus,
    max: usize,
    mut stop: impl FnMut(&TestBus) -> bool,
) -> Vec<(Field, u8)> {
    let mut trace = Vec::new();
    for _ in 0..max {
        let before = bus.log.len();
        bus.step();
        for l in &bus.log[before..] {
            if let Event::BusError { field, .. } = l.event {
                trace.push((field, bus.nodes[0].tec()));
            }
        }
        if stop(bus) {
            return trace;
        }
    }
    panic!("not reached in {max} bits");
}

// ---- error active -> error passive -> bus-off ----------------------------

/// A transmitter alone with its RX stuck recessive.
///
/// Derivation from CAN 2.0B §8 (rule numbers as in the specification):
/// - Attempt 1, error active, TEC 0. SOF is sent dominant and read
///   recessive: bit error; rule 3 (a transmitter sending an error flag)
///   gives TEC 8, and the flag is active.
/// - Every bit of the active error flag is read recessive: bit error while
///   sending an active error flag, rule 4: +8, and a new error flag starts
///   with the next bit. TEC 16, 24, ..., 120, 128: the bit error that takes
///   TEC from 120 to 128 was detected while error active, and rule 9 says
///   "an error condition letting a node become error passive causes the
///   node to send an active error flag". So one more active flag is sent;
///   its first bit is a bit error again (rule 4): TEC 136, and now, error
///   passive, the flag is passive. Attempt 1 ends at TEC 136 after 17 errors
///   (1 at SOF + 16 in active flags).
///   (Reading rule 9 without its second sentence, i.e. switching to a
///   passive flag as soon as TEC reaches 128, would end attempt 1 at 128
///   and give 17 attempts; the rule text does not allow that.)
/// - Passive flag (6 equal recessive bits), error delimiter (8), intermission
///   (3), suspend transmission (8, error-passive transmitter), then attempt
///   k >= 2: SOF bit error, rule 3: +8 (no exception applies: it is not an
///   ACK error nor a stuff error in arbitration). TEC = 136 + 8 (k - 1).
/// - Rule 10: bus-off when TEC >= 256, i.e. 136 + 8 (k - 1) = 256, k = 16.
///
/// So: 16 attempts, 32 bus errors, TEC trace 8, 16, ..., 136 then 144, ...,
/// 248 and bus-off at the 16th SOF (SJA1000: TXERR then reads 127, RXERR 0).
#[test]
fn transmitter_with_rx_stuck_recessive_goes_bus_off_after_16_attempts() {
    let mut bus = TestBus::new(1, Options::default());
    bus.stuck = Some(RECESSIVE);
    bus.run(11);
    bus.nodes[0].request_tx(std_frame(0x123, &[0xde, 0xad]), false, false);
    let trace = run_recording(&mut bus, 2000, |b| {
        b.nodes[0].fault_state() == FaultState::BusOff
    });

    let mut want = Vec::new();
    want.push((Field::Sof, 8));
    for k in 2..=17u8 {
        want.push((Field::ActiveErrorFlag, 8 * k)); // 16 ..= 136
    }
    // Attempts 2..=15 end at 144 ..= 248; attempt 16 reaches 256 = bus-off,
    // after which the SJA1000 shows TXERR = 127.
    for k in 2..=15u8 {
        want.push((Field::Sof, 136 + 8 * (k - 1)));
    }
    want.push((Field::Sof, 127));
    assert_eq!(trace, want);
    let attempts = trace.iter().filter(|(f, _)| *f == Field::Sof).count();
    assert_eq!(attempts, 16);

    let ev = bus.events(0);
    let passive_at = ev
        .iter()
        .position(|e| *e == Event::FaultState(FaultState::ErrorPassive))
        .unwrap();
    let errors_before_passive = ev[..passive_at]
        .iter()
        .filter(|e| matches!(e, Event::BusError { .. }))
        .count();
    assert_eq!(
        errors_before_passive, 16,
        "TEC reaches 128 at the 16th error (SOF + 15 flag bits)"
    );
    assert!(ev.contains(&Event::ErrorWarning(true)));
    assert_eq!(
        ev[ev.len() - 2..],
        [Event::FaultState(FaultState::BusOff), Event::TxAborted]
    );
    assert_eq!((bus.nodes[0].tec(), bus.nodes[0].rec()), (127, 0));
    assert!(bus.nodes[0].in_reset_mode(), "bus-off sets reset mode");
    assert!(!bus.nodes[0].tx_pending());
    // Every SOF bit error carries ECC 00 0 00011 (bit error, TX, SOF).
    for l in &bus.log {
        if let Event::BusError {
            kind,
            ecc,
            field: Field::Sof,
        } = l.event
        {
            assert_eq!((kind, ecc), (ErrorKind::Bit, 0x03));
        }
    }
    // Passive attempts are 26 bits apart: SOF 1 + passive flag 6 + error
    // delimiter 8 + intermission 3 + suspend transmission 8.
    let sofs: Vec<usize> = bus
        .log
        .iter()
        .filter(|l| {
            matches!(
                l.event,
                Event::BusError {
                    field: Field::Sof,
                    ..
                }
            )
        })
        .map(|l| l.bit)
        .collect();
    for w in sofs[1..].windows(2) {
        assert_eq!(w[1] - w[0], 26);
    }
}

/// Bus-off recovery (rule 12, SJA1000 TXERR): after reset mode is left,
/// 128 occurrences of 11 consecutive recessive bits, TXERR counting down
/// from 127; then error active with both counters 0.
#[test]
fn bus_off_recovery_takes_128_times_11_recessive_bits() {
    let mut e = node_idle();
    e.set_reset_mode(true);
    e.set_tec(255); // CPU-forced bus-off, performed when reset mode is left
    e.set_reset_mode(false);
    assert!(e.in_reset_mode(), "bus-off enters reset mode again");
    assert_eq!(e.fault_state(), FaultState::BusOff);
    assert_eq!(e.tec(), 127);
    let ev: Vec<_> = e.take_events().collect();
    assert!(ev.contains(&Event::FaultState(FaultState::BusOff)));
    // Nothing happens while in reset mode.
    for _ in 0..2000 {
        e.sample_bit(RECESSIVE);
    }
    assert_eq!(e.tec(), 127);
    e.set_reset_mode(false);
    // A dominant bit restarts the current 11-bit count.
    for _ in 0..10 {
        e.sample_bit(RECESSIVE);
    }
    e.sample_bit(DOMINANT);
    assert_eq!(e.tec(), 127);
    let mut n = 0;
    while e.fault_state() == FaultState::BusOff {
        e.sample_bit(RECESSIVE);
        n += 1;
        if n % 11 == 0 && n < 128 * 11 {
            assert_eq!(
                e.tec() as usize,
                127 - n / 11,
                "TXERR shows the recovery progress"
            );
        }
        assert!(n <= 128 * 11);
    }
    assert_eq!(n, 128 * 11);
    assert_eq!(
        (e.tec(), e.rec(), e.fault_state()),
        (0, 0, FaultState::ErrorActive)
    );
    let ev: Vec<_> = e.take_events().collect();
    assert_eq!(
        ev,
        vec![
            Event::FaultState(FaultState::ErrorActive),
            Event::ErrorWarning(false)
        ]
    );
    assert_eq!(e.field(), Field::BusIdle);
}

/// Writing TXERR 0..=254 while bus-off clears bus-off; one bus-free
/// sequence (11 recessive bits) after reset mode is left (datasheet).
#[test]
fn txerr_write_clears_bus_off() {
    let mut e = node_idle();
    e.set_reset_mode(true);
    e.set_tec(255);
    e.set_reset_mode(false);
    assert_eq!(e.fault_state(), FaultState::BusOff);
    assert!(e.in_reset_mode());
    e.set_tec(10);
    assert_eq!(e.fault_state(), FaultState::ErrorActive);
    assert_eq!(e.tec(), 10);
    e.set_reset_mode(false);
    for _ in 0..11 {
        e.sample_bit(RECESSIVE);
    }
    e.request_tx(std_frame(1, &[]), false, false);
    e.sample_bit(RECESSIVE);
    assert!(!e.tx(), "transmits after one bus-free sequence");
}

/// Datasheet TXERR: a write of 255 in reset mode changes nothing but the
/// counter (TXERR reads 255, no bus-off, no event) until reset mode is
/// left; then the bus-off is performed as one by errors: reset mode again,
/// TXERR 127, RXERR 0, bus-off and error warning reported, in that order.
#[test]
fn txerr_255_bus_off_waits_for_leaving_reset_mode() {
    let mut e = node_idle();
    e.set_reset_mode(true);
    e.set_rec(20);
    e.set_tec(255);
    assert_eq!((e.tec(), e.rec()), (255, 20), "the write shows in TXERR");
    assert_eq!(e.fault_state(), FaultState::ErrorActive, "no bus-off yet");
    assert!(!e.error_warning(), "no warning yet");
    assert_eq!(e.take_events().count(), 0, "no event in reset mode");
    for _ in 0..200 {
        e.sample_bit(RECESSIVE);
    }
    assert_eq!(e.fault_state(), FaultState::ErrorActive);
    e.set_reset_mode(false);
    assert!(e.in_reset_mode(), "bus-off enters reset mode again");
    assert_eq!(
        (e.tec(), e.rec(), e.fault_state()),
        (127, 0, FaultState::BusOff)
    );
    assert!(e.error_warning());
    let ev: Vec<_> = e.take_events().collect();
    assert_eq!(
        ev,
        vec![
            Event::FaultState(FaultState::BusOff),
            Event::ErrorWarning(true)
        ],
        "as a bus-off by errors; no error-passive step"
    );
}

/// The same node driven to bus-off by errors (TEC 248, one more SOF bit
/// error with RX stuck recessive) ends in the same state and reports the
/// same bus-off event as one forced by a TXERR write of 255.
#[test]
fn txerr_255_bus_off_matches_a_bus_off_by_errors() {
    let mut by_errors = node_idle();
    by_errors.set_reset_mode(true);
    by_errors.set_tec(248);
    by_errors.set_reset_mode(false);
    for _ in 0..11 {
        by_errors.sample_bit(RECESSIVE);
    }
    by_errors.take_events().for_each(drop);
    by_errors.request_tx(std_frame(1, &[]), false, false);
    let mut n = 0;
    while by_errors.fault_state() != FaultState::BusOff {
        let _ = by_errors.tx();
        by_errors.sample_bit(RECESSIVE); // RX stuck: bit error at SOF
        n += 1;
        assert!(n < 1000, "no bus-off by errors");
    }
    let mut forced = node_idle();
    forced.set_reset_mode(true);
    forced.set_tec(255);
    forced.take_events().for_each(drop);
    forced.set_reset_mode(false);
    let state = |e: &Engine| {
        (e.tec(), e.rec(), e.fault_state(), e.error_warning(), e.in_reset_mode())
    };
    assert_eq!(state(&forced), state(&by_errors));
    let faults = |e: &mut Engine| {
        e.take_events()
            .filter(|v| matches!(v, Event::FaultState(_) | Event::ErrorWarning(_)))
            .collect::<Vec<_>>()
    };
    // By errors the warning came at TEC 248 >= 96 already.
    assert_eq!(faults(&mut by_errors), vec![Event::FaultState(FaultState::BusOff)]);
    assert_eq!(faults(&mut forced)[0], Event::FaultState(FaultState::BusOff));
}

/// A TXERR write of 0..254 after 255 (still in reset mode) disarms the
/// bus-off: leaving reset mode applies the last value only.
#[test]
fn txerr_write_after_255_disarms_the_bus_off() {
    let mut e = node_idle();
    e.set_reset_mode(true);
    e.set_tec(255);
    e.set_tec(130);
    e.set_reset_mode(false);
    assert!(!e.in_reset_mode());
    assert_eq!((e.tec(), e.fault_state()), (130, FaultState::ErrorPassive));
}

/// Writes of 255 while bus-off change nothing (TXERR keeps counting the
/// recovery, the node stays bus-off).
#[test]
fn txerr_255_while_bus_off_is_a_no_op() {
    let mut e = node_idle();
    e.set_reset_mode(true);
    e.set_tec(255);
    e.set_reset_mode(false);
    e.take_events().for_each(drop);
    e.set_tec(255);
    assert_eq!((e.tec(), e.fault_state()), (127, FaultState::BusOff));
    e.set_reset_mode(false);
    assert!(!e.in_reset_mode(), "no second bus-off armed");
    assert_eq!(e.fault_state(), FaultState::BusOff, "the recovery runs");
}

// ---- ACK errors -----------------------------------------------------------

/// TX looped back to RX, no receiver: every attempt ends in an ACK error.
/// Error active: rule 3, +8 per attempt; the 16th takes TEC from 120 to
/// 128 (its flag is still active, rule 9). Error passive: rule 3 exception 1
/// (ACK error, and no dominant bit during the passive error flag since the
/// node is alone) leaves TEC at 128, so the node retransmits forever.
#[test]
fn ack_errors_stop_at_128_and_retransmit_forever() {
    let mut bus = TestBus::idle(1);
    bus.nodes[0].request_tx(std_frame(0x55, &[1, 2, 3]), false, false);
    let mut trace = Vec::new();
    while trace.len() < 16 + 50 {
        let before = bus.log.len();
        bus.step();
        for l in &bus.log[before..] {
            if let Event::BusError { kind, ecc, field } = l.event {
                assert_eq!((kind, ecc, field), (ErrorKind::Ack, 0xD9, Field::AckSlot));
                trace.push(bus.nodes[0].tec());
            }
        }
        if trace.len() > 16 {
            // SR: TS = 1 and TBS = 0 all the time.
            assert!(bus.nodes[0].is_transmitting());
            assert!(bus.nodes[0].tx_pending());
        }
        assert!(bus.bits.len() < 20_000);
    }
    let want: Vec<u8> = (1..=16)
        .map(|k| 8 * k)
        .chain(std::iter::repeat_n(128, 50))
        .collect();
    assert_eq!(trace, want);
    assert_eq!(bus.nodes[0].fault_state(), FaultState::ErrorPassive);
    assert_eq!(bus.count(0, |e| *e == Event::TxComplete), 0);
}

/// Rule 3 exception 1 needs no dominant bit during the passive flag: an
/// error-passive transmitter whose passive flag meets a dominant bit
/// (here forced) gets +8 after all.
#[test]
fn ack_error_with_dominant_during_passive_flag_counts() {
    let mut bus = TestBus {
        nodes: vec![node_error_passive(0, 130)],
        ..TestBus::new(0, Options::default())
    };
    bus.nodes[0].request_tx(std_frame(0x55, &[]), false, false);
    bus.run_until(200, |b| {
        b.log
            .iter()
            .any(|l| matches!(l.event, Event::BusError { .. }))
    });
    assert_eq!(bus.nodes[0].tec(), 130, "not yet: decided during the flag");
    let here = bus.bits.len();
    bus.force.push((here + 2, DOMINANT));
    bus.run(8);
    assert_eq!(bus.nodes[0].tec(), 138);
}

// ---- receive error counter ------------------------------------------------

/// Rule 8: a successful reception with REC above 127 sets it back into
/// 119..=127 (we use 127), and the node is error active again (rule 11).
#[test]
fn rule8_rec_above_127_goes_back_to_127() {
    let mut bus = TestBus::idle(2);
    bus.nodes[1] = node_error_passive(140, 0);
    bus.nodes[0].request_tx(std_frame(0x42, &[9]), false, false);
    bus.run_until(300, |b| !b.nodes[0].tx_pending());
    assert_eq!(bus.nodes[1].rec(), 127);
    assert_eq!(bus.nodes[1].fault_state(), FaultState::ErrorActive);
    assert!(
        bus.events(1)
            .contains(&Event::FaultState(FaultState::ErrorActive))
    );
}

/// Rule 6: 14 consecutive dominant bits after an active error flag (the 6
/// flag bits and 8 more) add 8, and every 8 more add 8 again; rule 2 gives
/// a receiver +8 for a dominant first bit after its flag.
#[test]
fn rule2_and_rule6_dominant_after_flag() {
    let mut bus = TestBus::idle(2);
    bus.nodes[0].request_tx(std_frame(0x42, &[0]), false, false);
    bus.run(1);
    // Corrupt a data-field bit as seen by everyone: transmitter bit error
    // (rule 3: TEC 8), receiver stuff or later error... simpler: force
    // node 1 (receiver) to see a stuff error by holding the bus dominant.
    let data = bus.bits.len() + 20;
    for i in 0..(6 + 24) {
        bus.force.push((data + i, DOMINANT));
    }
    bus.run(60);
    // Both nodes detect their first error within the forced run and send
    // 6-bit active flags while the bus stays dominant: for the receiver
    // rule 1 (+1), rule 2 (+8) and rule 6 at each 8th dominant bit after
    // its flag; for the transmitter rule 3 (+8) and rule 6.
    let err_bits: Vec<usize> = bus
        .log
        .iter()
        .filter(|l| matches!(l.event, Event::BusError { .. }))
        .map(|l| l.bit)
        .collect();
    assert_eq!(err_bits.len(), 2, "{:?}", bus.log);
    let end = data + 30; // first recessive bit
    let after = |node: usize| {
        let e = bus
            .log
            .iter()
            .find(|l| l.node == node && matches!(l.event, Event::BusError { .. }))
            .unwrap()
            .bit;
        end - (e + 1 + 6) // dominant bits after the flag
    };
    let (tx_after, rx_after) = (after(0), after(1));
    assert_eq!(bus.nodes[0].tec() as usize, 8 + 8 * (tx_after / 8));
    assert_eq!(bus.nodes[1].rec() as usize, 1 + 8 + 8 * (rx_after / 8));
    assert!(tx_after >= 16 && rx_after >= 16);
}

/// Error passive receiver: a stuff error gives +1 (rule 1) and a passive
/// flag; then, seen only by this node, a dominant first bit after the flag
/// gives +8 (rule 2) and the 8th and 16th consecutive dominant bits after
/// the passive flag +8 each (rule 6).
#[test]
fn passive_receiver_rules_1_2_6() {
    let mut bus = TestBus::idle(3);
    bus.nodes[1] = node_error_passive(128, 0);
    bus.nodes[0].request_tx(std_frame(0x0, &[0]), false, false);
    // SOF at bit 1; ID 0: stuffed bit 6 (SOF + 5) is a recessive stuff bit.
    let stuff = bus.bits.len() + 1 + 5;
    bus.force_rx.push((stuff, 1, DOMINANT));
    for k in 1..=6 {
        bus.force_rx.push((stuff + k, 1, RECESSIVE)); // passive flag completes
    }
    for k in 7..7 + 17 {
        bus.force_rx.push((stuff + k, 1, DOMINANT));
    }
    bus.run(stuff + 1 - bus.bits.len());
    assert_eq!(bus.nodes[1].rec(), 129);
    assert_eq!(bus.nodes[1].field(), Field::PassiveErrorFlag);
    bus.run(6);
    assert_eq!(bus.nodes[1].field(), Field::ErrorDelimiter);
    bus.run(1);
    assert_eq!(bus.nodes[1].rec(), 129 + 8, "rule 2");
    bus.run(6);
    assert_eq!(bus.nodes[1].rec(), 137);
    bus.run(1);
    assert_eq!(bus.nodes[1].rec(), 145, "rule 6 at the 8th dominant bit");
    bus.run(8);
    assert_eq!(bus.nodes[1].rec(), 153, "and at the 16th");
    bus.run(1);
    assert_eq!(bus.nodes[1].rec(), 153);
    // The other nodes were not disturbed by the passive flag.
    bus.run(200);
    assert_eq!(bus.count(2, |e| matches!(e, Event::Received { .. })), 1);
    assert_eq!(bus.count(0, |e| matches!(e, Event::BusError { .. })), 0);
}

/// A node at bus-on, after the 128 x 11 recessive bits of the recovery.
fn node_just_bus_on() -> Engine {
    let mut e = node_idle();
    e.set_reset_mode(true);
    e.set_tec(255);
    e.set_reset_mode(false); // the forced bus-off enters reset mode again
    e.set_reset_mode(false); // the recovery starts
    while e.fault_state() == FaultState::BusOff {
        e.sample_bit(RECESSIVE);
    }
    let _ = e.take_events().count();
    e
}

/// The resync for a DUT that waits one more bus-free sequence after bus-on
/// (waiver resync `model-waits-bus-free-after-bus-on`): only within 3 bits
/// of bus-on; the node integrates 11 recessive bits from its bus-on, holds
/// a pending frame at most 2 bits more for the DUT's start of frame, and
/// starts it at once when told.
#[test]
fn wait_bus_free_after_bus_on_holds_the_first_frame_for_the_duts_sof() {
    // Too late: 4 idle bits after bus-on.
    let mut e = node_just_bus_on();
    for _ in 0..4 {
        e.sample_bit(RECESSIVE);
    }
    assert!(!e.wait_bus_free_after_bus_on(3, 2), "4 bits after bus-on: refused");
    // Not after a bus-on at all (plain integration end).
    let mut plain = node_idle();
    assert!(!plain.wait_bus_free_after_bus_on(3, 2), "no bus-on: refused");
    // In time: 1 bit after bus-on, then a request.
    let mut e = node_just_bus_on();
    e.sample_bit(RECESSIVE);
    assert!(e.wait_bus_free_after_bus_on(3, 2));
    assert!(e.wait_bus_free_after_bus_on(3, 2), "a second hit of the waiver keeps it");
    e.request_tx(std_frame(0x123, &[1]), false, false);
    // Bits 2..10 after bus-on: still integrating, nothing held yet.
    for _ in 2..=10 {
        e.sample_bit(RECESSIVE);
        assert!(!e.tx_held() && e.tx() == RECESSIVE && !e.is_transmitting());
    }
    assert!(!e.start_held_tx_now(), "before the 11th bit nothing is held");
    e.sample_bit(RECESSIVE); // the 11th
    assert!(e.tx_held() && e.tx() == RECESSIVE, "held after 11 bits, no SOF of its own");
    assert!(e.start_held_tx_now());
    assert!(e.is_transmitting() && e.tx() == DOMINANT, "SOF driven at once");
    assert!(!e.tx_held());

    // The hold is bounded: 2 bits past the 11th, then the node starts itself.
    let mut e = node_just_bus_on();
    assert!(e.wait_bus_free_after_bus_on(3, 2));
    e.request_tx(std_frame(0x123, &[1]), false, false);
    let mut sof_after = None;
    for n in 1..=20 {
        e.sample_bit(RECESSIVE);
        if e.tx() == DOMINANT {
            sof_after = Some(n);
            break;
        }
    }
    assert_eq!(sof_after, Some(13), "SOF decided at the 13th bit after bus-on, not later");

    // A dominant bit while held ends the hold: the node integrates afresh.
    let mut e = node_just_bus_on();
    assert!(e.wait_bus_free_after_bus_on(3, 2));
    e.request_tx(std_frame(0x123, &[1]), false, false);
    for _ in 0..11 {
        e.sample_bit(RECESSIVE);
    }
    assert!(e.tx_held());
    e.sample_bit(DOMINANT);
    assert!(!e.tx_held() && !e.start_held_tx_now());
}
