//! Error-free frames between two nodes: bus bits, ACK, events, counters.

use super::*;
use crate::FaultState;
use crate::bsp::TxRequest;
use can_proto::{DOMINANT, stuff};

fn exchange(frame: CanFrame) -> TestBus {
    let mut bus = TestBus::idle(2);
    let start = bus.bits.len();
    bus.nodes[0].request_tx(frame, false, false);
    bus.run_until(400, |b| !b.nodes[0].tx_pending());
    // The frame starts one bit after the request (next idle sample point).
    let sof = (start..bus.bits.len()).find(|&i| !bus.bits[i]).unwrap();
    let mut want = wire(&frame);
    let ack = want.len() - 9;
    want[ack] = DOMINANT; // the receiver's ACK
    assert_eq!(
        &bus.bits[sof..sof + want.len()],
        &want[..],
        "bus bits of {frame:?}"
    );
    assert_eq!(bus.events(0), vec![Event::TxComplete]);
    assert_eq!(bus.events(1), vec![Event::Received { frame, own: false }]);
    assert!(!bus.nodes[1].is_bus_idle(), "still in EOF/intermission");
    bus.run(4);
    assert!(bus.nodes.iter().all(|e| e.is_bus_idle()));
    // Received at the last-but-one EOF bit, TxComplete at the last.
    let rx_bit = bus.log.iter().find(|l| l.node == 1).unwrap().bit;
    let tx_bit = bus.log.iter().find(|l| l.node == 0).unwrap().bit;
    assert_eq!(rx_bit, sof + want.len() - 2);
    assert_eq!(tx_bit, sof + want.len() - 1);
    for e in &bus.nodes {
        assert_eq!(
            (e.tec(), e.rec(), e.fault_state()),
            (0, 0, FaultState::ErrorActive)
        );
    }
    bus
}

#[test]
fn precomputed_stuffing_matches_can_proto() {
    for f in [
        std_frame(0, &[]),
        std_frame(0x7ff, &[0xff; 8]),
        ext_frame(0, &[0; 8]),
        ext_frame(0x1555_5555, &[0x0f]),
    ] {
        let req = TxRequest::new(f, false, false);
        let want: Vec<bool> = stuff::stuff(&f.unstuffed_bits()).iter().by_vals().collect();
        assert_eq!(req.stuffed(), want);
    }
}

#[test]
fn standard_data_frame() {
    exchange(std_frame(0x529, &[0x51]));
}

#[test]
fn extended_frames_and_dlc_over_8() {
    exchange(ext_frame(
        0x1234_5678 & 0x1fff_ffff,
        &[1, 2, 3, 4, 5, 6, 7, 8],
    ));
    exchange(CanFrame::new_remote(CanFrame::ext_id(0x3ff).unwrap(), 3).unwrap());
    exchange(CanFrame::with_dlc(CanFrame::std_id(0x10).unwrap(), false, 13, &[0xaa; 8]).unwrap());
    exchange(CanFrame::new_remote(CanFrame::std_id(0x0).unwrap(), 0).unwrap());
}

/// A frame whose CRC sequence ends with five equal bits is followed by a
/// stuff bit before the CRC delimiter; the receiver must expect it.
#[test]
fn stuff_bit_after_crc() {
    let f = (0..2048u16)
        .map(|id| std_frame(id, &[]))
        .find(|f| {
            let s: Vec<bool> = stuff::stuff(&f.unstuffed_bits()).iter().by_vals().collect();
            let n = s.len();
            s[n - 6..n - 1].iter().all(|&b| b == s[n - 2]) && s[n - 1] != s[n - 2]
        })
        .expect("some ID ends its CRC with a stuff bit");
    exchange(f);
}

/// CAN 2.0B §3.2.5 / ISO 11898-1: a dominant third intermission bit is a
/// start of frame; a node with a message waiting sends its identifier next.
#[test]
fn dominant_third_intermission_bit_is_sof() {
    let mut bus = TestBus::idle(2);
    bus.nodes[0].request_tx(std_frame(0x100, &[1]), false, false);
    bus.run_until(300, |b| !b.nodes[0].tx_pending());
    // Node 1 now has a frame waiting; force the third intermission bit
    // dominant (as if a faster node had started early).
    bus.nodes[1].request_tx(std_frame(0x200, &[2]), false, false);
    let third = bus.bits.len() + 2;
    bus.force.push((third, DOMINANT));
    bus.run_until(300, |b| !b.nodes[1].tx_pending());
    let sof = bus.first_bit_in(Field::BaseId, third).unwrap();
    assert_eq!(
        sof,
        third + 1,
        "the identifier follows the forced SOF directly"
    );
    assert!(bus.events(0).contains(&Event::Received {
        frame: std_frame(0x200, &[2]),
        own: false
    }));
    assert!(bus.events(1).contains(&Event::TxComplete));
}

#[test]
fn back_to_back_frames_keep_three_bit_intermission() {
    let mut bus = TestBus::idle(2);
    bus.nodes[0].request_tx(std_frame(0x1, &[]), false, false);
    bus.run_until(300, |b| !b.nodes[0].tx_pending());
    let end = bus.bits.len(); // bit after the last EOF bit
    bus.nodes[0].request_tx(std_frame(0x2, &[]), false, false);
    bus.run_until(300, |b| !b.nodes[0].tx_pending());
    let sof = (end..bus.bits.len()).find(|&i| !bus.bits[i]).unwrap();
    assert_eq!(sof, end + 3, "SOF right after the 3 intermission bits");
}
