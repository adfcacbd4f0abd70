//! Arbitration: random ID sets on the test bus.

use super::*;
use can_proto::Id;
use proptest::prelude::*;
use std::collections::HashSet;

/// The arbitration bits in ALC numbering: 0..=10 ID.28..ID.18, 11 SRR/RTR,
/// 12 IDE, 13..=30 ID.17..ID.0, 31 RTR of an extended frame.
fn arbitration_bits(f: &CanFrame) -> Vec<bool> {
    let mut v = Vec::with_capacity(32);
    match f.id() {
        Id::Standard(s) => {
            let id = s.as_raw() as u32;
            v.extend((0..11).rev().map(|i| (id >> i) & 1 != 0));
            v.push(f.is_remote_frame());
            v.push(false);
        }
        Id::Extended(e) => {
            let id = e.as_raw();
            v.extend((18..29).rev().map(|i| (id >> i) & 1 != 0));
            v.push(true);
            v.push(true);
            v.extend((0..18).rev().map(|i| (id >> i) & 1 != 0));
            v.push(f.is_remote_frame());
        }
    }
    v
}

fn frame_strategy() -> impl Strategy<Value = CanFrame> {
    (
        any::<bool>(),
        any::<u32>(),
        any::<bool>(),
        proptest::collection::vec(any::<u8>(), 0..=8),
    )
        .prop_map(|(ext, raw, rtr, data)| {
            let id = if ext {
                CanFrame::ext_id(raw & 0x1fff_ffff).unwrap()
            } else {
                CanFrame::std_id((raw & 0x7ff) as u16).unwrap()
            };
            if rtr {
                CanFrame::new_remote(id, data.len()).unwrap()
            } else {
                CanFrame::new(id, &data).unwrap()
            }
        })
}

fn check_arbitration(frames: Vec<CanFrame>) {
    let n = frames.len();
    let mut bus = TestBus::idle(n);
    for (k, f) in frames.iter().enumerate() {
        bus.nodes[k].request_tx(*f, false, false);
    }
    bus.run_until(n * 200, |b| b.nodes.iter().all(|e| !e.tx_pending()));

    // Completion order is arbitration order (lowest ID first).
    let order: Vec<usize> = bus
        .log
        .iter()
        .filter(|l| l.event == Event::TxComplete)
        .map(|l| l.node)
        .collect();
    let mut want: Vec<usize> = (0..n).collect();
    want.sort_by_key(|&k| frames[k].id());
    assert_eq!(order, want, "frames {frames:?}");
    let mut by_bits = want.clone();
    by_bits.sort_by_key(|&k| arbitration_bits(&frames[k]));
    assert_eq!(
        by_bits, want,
        "embedded-can Id order is the arbitration order"
    );

    // Every loss: ALC is the first bit where the loser sent recessive and the
    // round's winner (the next node to complete) sent dominant.
    let mut losses = 0;
    for (i, l) in bus.log.iter().enumerate() {
        if let Event::ArbitrationLost { alc } = l.event {
            losses += 1;
            let winner = bus.log[i..]
                .iter()
                .find(|w| w.event == Event::TxComplete)
                .unwrap()
                .node;
            let (a, b) = (
                arbitration_bits(&frames[l.node]),
                arbitration_bits(&frames[winner]),
            );
            let p = (0..32).find(|&p| a[p] != b[p]).unwrap();
            assert!(a[p] && !b[p]);
            assert_eq!(
                alc as usize, p,
                "loser {:?} winner {:?}",
                frames[l.node], frames[winner]
            );
        }
    }
    // All contend in every round: round r has n - r contenders.
    assert_eq!(losses, n * (n - 1) / 2);

    // The independent bus decoder of can-proto sees the same frames, all
    // acknowledged, no error, and the fields where node 0 says they are.
    let decoded = can_proto::decode::Decoder::decode(bus.bits.iter().copied());
    let frames_seen: Vec<CanFrame> = decoded
        .iter()
        .filter_map(|e| match e {
            can_proto::decode::DecodeEvent::Frame(d) => {
                assert!(d.ack);
                Some(d.frame)
            }
            can_proto::decode::DecodeEvent::Error { .. } => panic!("decoder error {e}"),
            _ => None,
        })
        .collect();
    assert_eq!(
        frames_seen,
        want.iter().map(|&k| frames[k]).collect::<Vec<_>>()
    );
    for e in &decoded {
        if let can_proto::decode::DecodeEvent::FieldStart { field, bit } = *e {
            // A receiver knows a bit is SOF only once it has sampled it.
            if field != Field::BusIdle
                && !(field == Field::Sof && bus.fields[bit as usize] == Field::BusIdle)
            {
                assert_eq!(bus.fields[bit as usize], field, "bit {bit}");
            }
        }
    }

    // Every frame reaches every other node exactly once; no errors.
    for k in 0..n {
        let got: Vec<CanFrame> = bus
            .events(k)
            .into_iter()
            .filter_map(|e| match e {
                Event::Received { frame, own: false } => Some(frame),
                Event::BusError { .. } => panic!("error on node {k}"),
                _ => None,
            })
            .collect();
        let mut expect: Vec<CanFrame> = want
            .iter()
            .filter(|&&j| j != k)
            .map(|&j| frames[j])
            .collect();
        expect.sort_by_key(|f| f.id());
        assert_eq!(got, expect);
        assert_eq!((bus.nodes[k].tec(), bus.nodes[k].rec()), (0, 0));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn lowest_id_wins_and_alc_is_first_lost_bit(frames in proptest::collection::vec(frame_strategy(), 2..=8)) {
        let mut seen = HashSet::new();
        let frames: Vec<CanFrame> = frames.into_iter().filter(|f| seen.insert(f.id())).collect();
        prop_assume!(frames.len() >= 2);
        check_arbitration(frames);
    }
}

/// Hand-picked cases: standard data beats extended with the same base ID at
/// SRR (ALC 11); standard remote ties SRR and wins at IDE (ALC 12); the
/// extended RTR bit (ALC 31).
#[test]
fn alc_at_srr_ide_and_extended_rtr() {
    let std_data = std_frame(0x123, &[1]);
    let ext = ext_frame(0x123 << 18, &[2]);
    let mut bus = TestBus::idle(2);
    bus.nodes[0].request_tx(ext, false, false);
    bus.nodes[1].request_tx(std_data, false, false);
    bus.run_until(400, |b| !b.nodes[0].tx_pending());
    assert_eq!(bus.events(0)[0], Event::ArbitrationLost { alc: 11 });

    let std_remote = CanFrame::new_remote(CanFrame::std_id(0x123).unwrap(), 1).unwrap();
    check_arbitration(vec![ext, std_remote]);
    let mut bus = TestBus::idle(2);
    bus.nodes[0].request_tx(ext, false, false);
    bus.nodes[1].request_tx(std_remote, false, false);
    bus.run_until(400, |b| !b.nodes[0].tx_pending());
    assert_eq!(bus.events(0)[0], Event::ArbitrationLost { alc: 12 });

    let ext_remote = CanFrame::new_remote(CanFrame::ext_id(0x1abc).unwrap(), 0).unwrap();
    let ext_data = ext_frame(0x1abc, &[]);
    let mut bus = TestBus::idle(2);
    bus.nodes[0].request_tx(ext_remote, false, false);
    bus.nodes[1].request_tx(ext_data, false, false);
    bus.run_until(400, |b| !b.nodes[0].tx_pending());
    assert_eq!(bus.events(0)[0], Event::ArbitrationLost { alc: 31 });
}

/// Single shot (TR + AT): a lost arbitration is not retried.
#[test]
fn single_shot_lost_arbitration_is_dropped() {
    let mut bus = TestBus::idle(2);
    bus.nodes[0].request_tx(std_frame(0x200, &[]), true, false);
    bus.nodes[1].request_tx(std_frame(0x100, &[]), false, false);
    bus.run(300);
    assert_eq!(
        bus.events(0)[..2],
        [Event::ArbitrationLost { alc: 1 }, Event::TxAborted]
    );
    assert_eq!(bus.count(0, |e| *e == Event::TxComplete), 0);
    assert_eq!(bus.count(1, |e| matches!(e, Event::Received { .. })), 0);
}
