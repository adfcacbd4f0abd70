//! A node with its own oscillator (`Bus::set_node_clock`): its bits are
//! shorter or longer in proportion, resynchronisation keeps it in step
//! within the CAN 2.0B clock tolerance, and far outside it frames fail.

use crate::common;
use common::*;

use can_proto::RECESSIVE;
use regmap::peli;
use sja1000::Bus;
use sja1000::host::{self, Config};

/// Bus clocks a lone self-test node takes for one frame at `node_hz`
/// against a 24 MHz bus.
fn frame_clocks(node_hz: u64) -> u64 {
    let mut bus = bus_of(&[Config { self_test: true, ..Config::pelican() }]);
    bus.set_node_clock(0, node_hz, 24_000_000);
    host::transmit(bus.node_mut(0), &std_frame(0x555, &[0x55; 8]), peli::cmr::SRR).unwrap();
    let start = bus.clocks();
    while bus.node(0).peek(peli::SR) & peli::sr::TCS == 0 {
        bus.clock();
        assert!(bus.clocks() - start < 1_000_000, "the self-test frame never completed");
    }
    bus.clocks() - start
}

#[test]
fn a_faster_oscillator_makes_shorter_bits() {
    let same = frame_clocks(24_000_000);
    let fast = frame_clocks(25_000_000);
    let slow = frame_clocks(23_000_000);
    // Bit lengths scale with 1/f within one bit of jitter per frame.
    let expect = |hz: f64| same as f64 * 24e6 / hz;
    assert!((fast as f64 - expect(25e6)).abs() < 40.0, "fast {fast}, same {same}");
    assert!((slow as f64 - expect(23e6)).abs() < 40.0, "slow {slow}, same {same}");
}

/// Node 1 runs `ppm` off the bus clock; both send `frames` frames with
/// long edge-free stretches (stuff-limited). Returns (delivered to node 1,
/// delivered to node 0, any error counted).
fn exchange(btr0: u8, btr1: u8, node1_hz: u64, frames: usize) -> (usize, usize, bool) {
    let cfg = Config { btr0, btr1, ..Config::pelican() };
    let mut bus: Bus = bus_of(&[cfg, cfg]);
    bus.set_node_clock(1, node1_hz, 24_000_000);
    let (mut got0, mut got1) = (0, 0);
    let mut errors = false;
    let patterns = [[0x00u8; 8], [0xFF; 8], [0x0F; 8], [0xE0; 8]];
    for k in 0..frames {
        let from = k % 2;
        let f = std_frame(0x7F0 | (k as u16 & 0xF), &patterns[k % patterns.len()]);
        host::transmit(bus.node_mut(from), &f, peli::cmr::TR).unwrap();
        let mut idle = 0;
        let done = bus.run_until(600, |b| {
            idle = if b.level() == RECESSIVE { idle + 1 } else { 0 };
            b.node(from).peek(peli::SR) & peli::sr::TBS != 0 && idle > 20
        });
        for i in 0..2 {
            let n = bus.node_mut(i);
            errors |= n.read(peli::RXERR) != 0 || n.read(peli::TXERR) != 0;
        }
        while host::receive(bus.node_mut(1)).is_some() {
            got1 += 1;
        }
        while host::receive(bus.node_mut(0)).is_some() {
            got0 += 1;
        }
        if !done {
            errors = true;
            break;
        }
    }
    bus.set_check_on_drop(false);
    (got1, got0, errors)
}

/// SJW = 2 tq, 10 tq per bit (phase segment 2 = 3 tq): CAN 2.0B's
/// tolerance is min(SJW / (20 x 10), 3 / (2 x (130 - 3))) = 1 % per node,
/// so two nodes may be 2 % apart. 1.5 % and -1.5 %: no error.
#[test]
fn within_tolerance_every_frame_arrives_without_error() {
    for hz in [24_360_000, 23_640_000] {
        let (to1, to0, errors) = exchange(0x41, 0x25, hz, 16);
        assert_eq!((to1, to0, errors), (8, 8, false), "node 1 at {hz} Hz");
    }
}

/// SJW = 1 tq (tolerance 0.5 % per node): 5 % apart the receiver samples
/// the wrong bits; errors are counted.
#[test]
fn far_outside_tolerance_errors_are_counted() {
    let (_, _, errors) = exchange(0x01, 0x25, 25_200_000, 8);
    assert!(errors, "5 % clock difference with SJW = 1 tq went unnoticed");
}
