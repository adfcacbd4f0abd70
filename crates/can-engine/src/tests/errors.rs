//! Each error kind, with the ECC value the SJA1000 captures, and overload
//! frames. Three nodes: 0 transmits, 1 and 2 receive (and acknowledge).

use super::*;
use crate::ErrorKind;
use can_proto::DOMINANT;

/// A three-node bus with node 0 about to send `frame`; also returns the
/// bits and fields of a clean reference run of the same exchange, so a test
/// can aim a fault at a field (the runs are deterministic).
fn setup(frame: CanFrame) -> (TestBus, TestBus) {
    let mk = || {
        let mut b = TestBus::idle(3);
        b.bits.clear();
        b.fields.clear();
        b.nodes[0].request_tx(frame, false, false);
        b
    };
    let mut reference = mk();
    reference.run(250);
    assert_eq!(reference.count(0, |e| *e == Event::TxComplete), 1);
    assert!(
        reference
            .log
            .iter()
            .all(|l| !matches!(l.event, Event::BusError { .. }))
    );
    (mk(), reference)
}

fn nth_in(r: &TestBus, field: Field, n: usize) -> usize {
    (0..r.fields.len())
        .filter(|&i| r.fields[i] == field)
        .nth(n)
        .unwrap()
}

fn first_error(bus: &TestBus, node: usize) -> Event {
    bus.log
        .iter()
        .find(|l| l.node == node && matches!(l.event, Event::BusError { .. }))
        .unwrap()
        .event
        .clone()
}

/// A receiver that sees the bus as it is is a bus observer, like the
/// can-proto decoder: its first error must be the decoder's first error
/// (same bit, kind and field). One difference by design: the decoder
/// reports a CRC mismatch at the last CRC bit, a receiver signals it after
/// the ACK delimiter (CAN 2.0B §7.2), so an error seen in between (e.g. a
/// transmitter's flag making the CRC delimiter dominant) comes first.
fn assert_receiver_matches_decoder(bus: &TestBus, node: usize) {
    use can_proto::decode::{BusError, DecodeEvent, Decoder};
    // The decoder integrates first: 11 recessive bits before the recording.
    let levels = std::iter::repeat_n(RECESSIVE, 11).chain(bus.bits.iter().copied());
    let errors: Vec<(usize, BusError, Field)> = Decoder::decode(levels)
        .into_iter()
        .filter_map(|e| match e {
            DecodeEvent::Error { error, field, bit } => Some((bit as usize - 11, error, field)),
            _ => None,
        })
        .collect();
    assert!(!errors.is_empty(), "the decoder sees an error");
    let mine = bus
        .log
        .iter()
        .find(|l| l.node == node && matches!(l.event, Event::BusError { .. }))
        .unwrap();
    let Event::BusError {
        kind: k, field: f, ..
    } = mine.event
    else {
        unreachable!()
    };
    if (k, f) == (ErrorKind::Bit, Field::AckSlot) {
        // It sent its ACK dominant and read recessive: only the node knows.
        return;
    }
    let k2 = match k {
        ErrorKind::Stuff => BusError::Stuff,
        ErrorKind::Crc => BusError::Crc,
        ErrorKind::Form => BusError::Form,
        ErrorKind::Ack => BusError::Acknowledge,
        ErrorKind::Bit => panic!("a receiver has no bit error outside its own flags"),
    };
    if k2 == BusError::Crc {
        assert_eq!(errors[0].1, BusError::Crc, "{errors:?}");
        assert_eq!(f, Field::AckDelim);
        return;
    }
    let first = errors
        .iter()
        .find(|e| e.1 != BusError::Crc)
        .expect("a non-CRC error");
    assert_eq!((mine.bit, k2, f), *first, "decoder: {errors:?}");
}

fn bus_error(kind: ErrorKind, ecc: u8, field: Field) -> Event {
    Event::BusError { kind, ecc, field }
}

/// Bit error: the transmitter reads dominant where it sent a recessive
/// data-field bit. ECC 00 0 01010.
#[test]
fn bit_error_in_data_field() {
    let (mut bus, r) = setup(std_frame(0x321, &[0x0f, 0xf0]));
    let i = (0..r.fields.len())
        .find(|&i| r.fields[i] == Field::Data && r.bits[i])
        .unwrap();
    bus.force.push((i, DOMINANT));
    bus.run(250);
    assert_eq!(
        first_error(&bus, 0),
        bus_error(ErrorKind::Bit, 0x0A, Field::Data)
    );
    assert_receiver_matches_decoder(&bus, 1);
    assert_eq!(
        bus.log
            .iter()
            .find(|l| l.node == 0 && matches!(l.event, Event::BusError { .. }))
            .unwrap()
            .bit,
        i
    );
    // Retransmitted and delivered once to each receiver.
    assert_eq!(bus.count(0, |e| *e == Event::TxComplete), 1);
    assert_eq!(bus.count(1, |e| matches!(e, Event::Received { .. })), 1);
    assert_eq!(bus.nodes[0].tec(), 7, "rule 3 +8, rule 7 -1");
}

/// Stuff error: a receiver reads a sixth equal bit where a stuff bit was
/// due. ECC 10 1 01010; rule 1 gives REC 1.
#[test]
fn stuff_error_at_receiver() {
    let (mut bus, r) = setup(std_frame(0x321, &[0x00]));
    let i = (5..r.fields.len())
        .find(|&i| r.fields[i] == Field::Data && r.bits[i] && r.bits[i - 5..i].iter().all(|&b| !b))
        .unwrap();
    bus.force_rx.push((i, 1, DOMINANT));
    bus.run_until(250, |b| b.log.iter().any(|l| l.node == 1));
    assert_eq!(
        first_error(&bus, 1),
        bus_error(ErrorKind::Stuff, 0xAA, Field::Data)
    );
    assert_eq!(bus.nodes[1].rec(), 1);
    bus.run(250);
    assert_eq!(bus.count(1, |e| matches!(e, Event::Received { .. })), 1);
    assert_eq!(bus.count(0, |e| *e == Event::TxComplete), 1);
}

/// CRC error: one receiver sees a data bit flipped. It sends no ACK and
/// flags the error after the ACK delimiter (ECC 11 1 11011, "other" in the
/// ACK delimiter); the others see its flag as a form error in EOF.
/// Counters: receiver 1 gets rule 1 (+1) and rule 2 (+8: the others' flags
/// make the first bit after its own flag dominant); receiver 2 rule 1
/// (+1); the transmitter rule 3 (+8). The retransmission then succeeds.
#[test]
fn crc_error_flags_after_ack_delimiter() {
    let (mut bus, r) = setup(std_frame(0x321, &[0x55]));
    let i = nth_in(&r, Field::Data, 3);
    bus.force_rx.push((i, 1, !r.bits[i]));
    let ack_delim = nth_in(&r, Field::AckDelim, 0);
    bus.run_until(250, |b| b.log.iter().any(|l| l.node == 1));
    assert_eq!(
        first_error(&bus, 1),
        bus_error(ErrorKind::Crc, 0xFB, Field::AckDelim)
    );
    assert_eq!(bus.bits.len() - 1, ack_delim);
    bus.run(20);
    assert_eq!(
        first_error(&bus, 0),
        bus_error(ErrorKind::Form, 0x5A, Field::Eof)
    );
    assert_eq!(
        first_error(&bus, 2),
        bus_error(ErrorKind::Form, 0x7A, Field::Eof)
    );
    assert_eq!(
        (bus.nodes[0].tec(), bus.nodes[1].rec(), bus.nodes[2].rec()),
        (8, 9, 1)
    );
    bus.run(200);
    assert_eq!(
        (bus.nodes[0].tec(), bus.nodes[1].rec(), bus.nodes[2].rec()),
        (7, 8, 0)
    );
    for n in 1..3 {
        assert_eq!(bus.count(n, |e| matches!(e, Event::Received { .. })), 1);
    }
}

/// Form error: a dominant CRC delimiter. Transmitter ECC 01 0 11000,
/// receivers 01 1 11000.
#[test]
fn form_error_at_crc_delimiter() {
    let (mut bus, r) = setup(ext_frame(0x0ab_cdef, &[1, 2]));
    bus.force.push((nth_in(&r, Field::CrcDelim, 0), DOMINANT));
    bus.run(300);
    assert_eq!(
        first_error(&bus, 0),
        bus_error(ErrorKind::Form, 0x58, Field::CrcDelim)
    );
    assert_eq!(
        first_error(&bus, 1),
        bus_error(ErrorKind::Form, 0x78, Field::CrcDelim)
    );
    assert_eq!(
        first_error(&bus, 2),
        bus_error(ErrorKind::Form, 0x78, Field::CrcDelim)
    );
    assert_receiver_matches_decoder(&bus, 1);
    assert_eq!(bus.count(1, |e| matches!(e, Event::Received { .. })), 1);
}

/// Form error at the ACK delimiter; and an error delimiter whose last bit is
/// dominant starts an overload frame without any counter change.
#[test]
fn form_error_at_ack_delimiter_then_overload_at_delimiter_end() {
    let (mut bus, r) = setup(std_frame(0x7f0, &[]));
    let d = nth_in(&r, Field::AckDelim, 0);
    bus.force.push((d, DOMINANT));
    // Flag d+1..=d+6, error delimiter d+7..=d+14: force its last bit.
    bus.force.push((d + 14, DOMINANT));
    bus.run(d + 16);
    assert_eq!(
        first_error(&bus, 0),
        bus_error(ErrorKind::Form, 0x5B, Field::AckDelim)
    );
    assert_eq!(
        first_error(&bus, 1),
        bus_error(ErrorKind::Form, 0x7B, Field::AckDelim)
    );
    assert_receiver_matches_decoder(&bus, 2);
    assert_eq!(bus.fields[d + 14], Field::ErrorDelimiter);
    assert_eq!(bus.fields[d + 15], Field::OverloadFlag);
    assert_eq!((bus.nodes[0].tec(), bus.nodes[1].rec()), (8, 1));
    bus.run(200);
    assert_eq!(bus.count(2, |e| matches!(e, Event::Received { .. })), 1);
}

// ---- overload frames --------------------------------------------------------

/// A dominant first intermission bit: every node sends an overload flag (6),
/// overload delimiter (8), then intermission again; no counter changes.
#[test]
fn overload_at_first_intermission_bit() {
    let (mut bus, r) = setup(std_frame(0x1, &[7]));
    let f = nth_in(&r, Field::Intermission, 0);
    bus.force.push((f, DOMINANT));
    bus.run(f + 1);
    bus.nodes[1].request_tx(std_frame(0x2, &[8]), false, false);
    assert!(
        bus.log
            .iter()
            .all(|l| !matches!(l.event, Event::BusError { .. }))
    );
    bus.run(17);
    assert!((f + 1..f + 7).all(|i| bus.fields[i] == Field::OverloadFlag));
    assert!((f + 7..f + 15).all(|i| bus.fields[i] == Field::OverloadDelimiter));
    assert!((f + 15..f + 18).all(|i| bus.fields[i] == Field::Intermission));
    bus.run(200);
    assert!(
        bus.log
            .iter()
            .all(|l| !matches!(l.event, Event::BusError { .. }))
    );
    assert_eq!(
        bus.count(0, |e| *e
            == Event::Received {
                frame: std_frame(0x2, &[8]),
                own: false
            }),
        1
    );
    for e in &bus.nodes {
        assert_eq!((e.tec(), e.rec()), (0, 0));
    }
}

/// A dominant last EOF bit: receivers accept the frame and send an
/// overload flag; for the transmitter it is a form error, so it
/// retransmits (the receivers get the frame twice, as CAN allows).
#[test]
fn dominant_last_eof_bit() {
    let (mut bus, r) = setup(std_frame(0x3, &[1]));
    let eof7 = nth_in(&r, Field::Eof, 6);
    bus.force.push((eof7, DOMINANT));
    bus.run(eof7 + 2);
    assert_eq!(
        first_error(&bus, 0),
        bus_error(ErrorKind::Form, 0x5A, Field::Eof)
    );
    assert_eq!(bus.fields[eof7 + 1], Field::ActiveErrorFlag);
    assert_eq!(bus.nodes[1].field(), Field::OverloadFlag);
    assert!(
        bus.log
            .iter()
            .all(|l| l.node == 0 || !matches!(l.event, Event::BusError { .. }))
    );
    bus.run(200);
    assert_eq!(bus.count(1, |e| matches!(e, Event::Received { .. })), 2);
    assert_eq!(bus.count(0, |e| *e == Event::TxComplete), 1);
    assert_eq!((bus.nodes[1].rec(), bus.nodes[2].rec()), (0, 0));
}

/// Rule 5: a receiver reading recessive during its own active error flag
/// has a bit error (ECC 00 1 10001) and adds 8 to REC; a new flag follows.
#[test]
fn bit_error_in_receiver_active_flag() {
    let (mut bus, r) = setup(std_frame(0x321, &[0x00]));
    let i = (5..r.fields.len())
        .find(|&i| r.fields[i] == Field::Data && r.bits[i] && r.bits[i - 5..i].iter().all(|&b| !b))
        .unwrap();
    bus.force_rx.push((i, 1, DOMINANT)); // stuff error at node 1
    bus.force_rx.push((i + 2, 1, RECESSIVE)); // 2nd bit of its flag
    bus.run(i + 3);
    let errs: Vec<Event> = bus
        .events(1)
        .into_iter()
        .filter(|e| matches!(e, Event::BusError { .. }))
        .collect();
    assert_eq!(
        errs,
        vec![
            bus_error(ErrorKind::Stuff, 0xAA, Field::Data),
            bus_error(ErrorKind::Bit, 0x31, Field::ActiveErrorFlag)
        ]
    );
    assert_eq!(bus.nodes[1].rec(), 1 + 8);
    assert_eq!(bus.nodes[1].field(), Field::ActiveErrorFlag);
}

/// Suspend transmission: after its frame an error-passive transmitter
/// waits 8 more bits, so a waiting error-active node goes first even with
/// a lower priority.
#[test]
fn error_passive_transmitter_suspends() {
    let mut bus = TestBus::idle(2);
    bus.nodes[0] = node_error_passive(0, 130);
    bus.nodes[0].request_tx(std_frame(0x001, &[1]), false, false);
    bus.run(5);
    bus.nodes[1].request_tx(std_frame(0x700, &[2]), false, false);
    bus.run_until(300, |b| !b.nodes[0].tx_pending());
    let end = bus.bits.len();
    bus.nodes[0].request_tx(std_frame(0x001, &[3]), false, false);
    bus.run_until(300, |b| !b.nodes[1].tx_pending());
    assert_eq!(
        bus.first_bit_in(Field::SuspendTransmission, end),
        Some(end + 3)
    );
    assert!(
        bus.nodes[0].tx_pending(),
        "the passive node's second frame waits"
    );
    // Node 1's SOF is the first bit after intermission.
    assert!(!bus.bits[end + 3] && bus.bits[end..end + 3].iter().all(|&b| b));
    bus.run_until(300, |b| !b.nodes[0].tx_pending());
    assert_eq!(bus.nodes[0].tec(), 128);
}

/// Rule 3 exception 2: a recessive stuff bit in the arbitration field (before
/// RTR) monitored dominant is a stuff error for the transmitter too, and its
/// TEC does not change; receivers count it (rule 1). ECC 10 0 00010 at the
/// transmitter, 10 1 00010 at the receivers.
#[test]
fn stuff_error_in_arbitration_leaves_tec() {
    // ID 0: SOF and ID.28..ID.25 are five dominant bits, so stuffed bit 5
    // is a recessive stuff bit inside ID.28-ID.21.
    let (mut bus, r) = setup(std_frame(0x000, &[1]));
    let sof = (0..r.bits.len()).find(|&i| !r.bits[i]).unwrap();
    assert!(r.bits[sof + 5] && r.bits[sof..sof + 5].iter().all(|&b| !b));
    bus.force.push((sof + 5, DOMINANT));
    bus.run(sof + 6);
    assert_eq!(
        first_error(&bus, 0),
        bus_error(ErrorKind::Stuff, 0x82, Field::BaseId)
    );
    assert_eq!(
        first_error(&bus, 1),
        bus_error(ErrorKind::Stuff, 0xA2, Field::BaseId)
    );
    assert_receiver_matches_decoder(&bus, 2);
    assert_eq!(
        (bus.nodes[0].tec(), bus.nodes[1].rec(), bus.nodes[2].rec()),
        (0, 1, 1)
    );
    bus.run(200);
    assert_eq!(bus.count(0, |e| *e == Event::TxComplete), 1);
}

mod differential {
    use super::*;
    use proptest::prelude::*;

    fn frame() -> impl Strategy<Value = CanFrame> {
        (
            any::<bool>(),
            any::<u32>(),
            proptest::collection::vec(any::<u8>(), 0..=8),
        )
            .prop_map(|(ext, raw, data)| {
                if ext {
                    ext_frame(raw & 0x1fff_ffff, &data)
                } else {
                    std_frame((raw & 0x7ff) as u16, &data)
                }
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        /// One flipped bus bit anywhere in a frame: a receiver, being a bus
        /// observer, detects the same first error as can-proto's decoder,
        /// and the frame is delivered exactly once in the end.
        #[test]
        fn receivers_agree_with_the_decoder(f in frame(), at in 0usize..200) {
            let (mut bus, r) = setup(f);
            // Somewhere from SOF (bit 1) to the last EOF bit.
            let end = r.log.iter().find(|l| l.event == Event::TxComplete).unwrap().bit;
            let i = 1 + at % end;
            bus.force.push((i, !r.bits[i]));
            bus.run(400);
            if bus.log.iter().any(|l| l.node == 2 && matches!(l.event, Event::BusError { .. })) {
                assert_receiver_matches_decoder(&bus, 2);
            }
            prop_assert_eq!(bus.count(0, |e| *e == Event::TxComplete), 1);
            let got = bus.count(2, |e| matches!(e, Event::Received { .. }));
            // Twice only when the flip hit the last EOF bit (receivers had
            // accepted the frame already).
            prop_assert!(got == 1 || (got == 2 && r.fields[i] == Field::Eof), "received {} times, flip at {:?}", got, r.fields[i]);
        }
    }
}
