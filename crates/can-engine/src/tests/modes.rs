//! Operating modes: self test, self reception, listen only, single shot,
//! abort, sleep, reset mode.

use super::*;
use crate::{ErrorKind, FaultState};
use can_proto::DOMINANT;

fn self_test() -> Options {
    Options {
        self_test: true,
        ..Options::default()
    }
}

/// Self test (MOD.STM) with self reception (CMR.SRR), TX looped back, no
/// other node: the transmission succeeds without ACK, once, and the node
/// receives its own frame.
#[test]
fn self_test_loopback_succeeds_once() {
    let mut bus = TestBus::new(1, self_test());
    bus.run(11);
    let f = std_frame(0x7a, &[1, 2, 3, 4]);
    bus.nodes[0].request_tx(f, false, true);
    bus.run(600);
    assert_eq!(
        bus.events(0),
        vec![
            Event::Received {
                frame: f,
                own: true
            },
            Event::TxComplete
        ]
    );
    assert_eq!(
        bus.bits.iter().filter(|&&b| !b).count(),
        wire(&f).iter().filter(|&&b| !b).count()
    );
    assert_eq!((bus.nodes[0].tec(), bus.nodes[0].tx_pending()), (0, false));
}

/// Without self reception, a self-test transmission completes but the node
/// does not receive it.
#[test]
fn self_test_without_self_reception() {
    let mut bus = TestBus::new(1, self_test());
    bus.run(11);
    bus.nodes[0].request_tx(std_frame(0x7a, &[]), false, false);
    bus.run(300);
    assert_eq!(bus.events(0), vec![Event::TxComplete]);
}

/// Self reception in normal mode with an acknowledging receiver.
#[test]
fn self_reception_request_with_receiver() {
    let mut bus = TestBus::idle(2);
    let f = ext_frame(0x1234, &[5]);
    bus.nodes[0].request_tx(f, false, true);
    bus.run(300);
    assert_eq!(
        bus.events(0),
        vec![
            Event::Received {
                frame: f,
                own: true
            },
            Event::TxComplete
        ]
    );
    assert_eq!(
        bus.events(1),
        vec![Event::Received {
            frame: f,
            own: false
        }]
    );
}

/// Listen only: the node receives but never drives dominant (no ACK, no
/// error flag) and its counters stay frozen.
#[test]
fn listen_only_never_dominant() {
    let mut bus = TestBus::idle(2);
    bus.nodes[1].set_options(Options {
        listen_only: true,
        ..Options::default()
    });
    bus.nodes[0].request_tx(std_frame(0x10, &[0xaa]), false, false);
    let mut dominant = 0;
    for _ in 0..400 {
        bus.step();
        dominant += !bus.nodes[1].tx() as usize;
    }
    assert_eq!(dominant, 0);
    // Nobody acknowledges: ACK errors at the transmitter, the listener sees
    // form errors at the ACK delimiter and receives nothing.
    assert!(
        bus.count(0, |e| matches!(
            e,
            Event::BusError {
                kind: ErrorKind::Ack,
                ..
            }
        )) > 3
    );
    assert!(
        bus.count(1, |e| matches!(
            e,
            Event::BusError {
                kind: ErrorKind::Form,
                ..
            }
        )) > 3
    );
    assert_eq!(bus.count(1, |e| matches!(e, Event::Received { .. })), 0);
    assert_eq!(bus.nodes[1].rec(), 0);
    // A listen-only node requested to send does not.
    bus.nodes[1].request_tx(std_frame(0x1, &[]), false, false);
    bus.nodes[0].abort_tx();
    bus.run(200);
    assert!(bus.bits[bus.bits.len() - 100..].iter().all(|&b| b));
}

/// Single shot: after an error there is no retransmission.
#[test]
fn single_shot_after_ack_error() {
    let mut bus = TestBus::idle(1);
    bus.nodes[0].request_tx(std_frame(0x10, &[]), true, false);
    bus.run(400);
    let ev = bus.events(0);
    assert_eq!(
        ev.iter()
            .filter(|e| matches!(e, Event::BusError { .. }))
            .count(),
        1
    );
    assert!(ev.contains(&Event::TxAborted));
    assert_eq!(bus.nodes[0].tec(), 8);
    assert!(!bus.nodes[0].tx_pending());
}

/// Abort before the transmission started drops it at once; during it, the
/// attempt runs to its end and is not retried after an error.
#[test]
fn abort_transmission() {
    let mut e = node_idle();
    e.request_tx(std_frame(1, &[]), false, false);
    e.abort_tx();
    assert_eq!(e.take_events().collect::<Vec<_>>(), vec![Event::TxAborted]);
    assert!(!e.tx_pending());

    let mut bus = TestBus::idle(1);
    bus.nodes[0].request_tx(std_frame(0x10, &[]), false, false);
    bus.run(5);
    bus.nodes[0].abort_tx();
    assert!(bus.nodes[0].tx_pending(), "under way: not dropped yet");
    bus.run(300);
    assert_eq!(bus.count(0, |e| matches!(e, Event::BusError { .. })), 1);
    assert_eq!(bus.count(0, |e| *e == Event::TxAborted), 1);
}

/// Sleep: a dominant bit wakes the node (WakeUp); it then waits for 11
/// recessive bits before taking part.
#[test]
fn sleep_and_wake_up() {
    let mut e = node_idle();
    e.set_sleep(true);
    for _ in 0..50 {
        e.sample_bit(RECESSIVE);
    }
    assert!(!e.has_events() && e.is_sleeping());
    e.sample_bit(DOMINANT);
    assert_eq!(e.take_events().collect::<Vec<_>>(), vec![Event::WakeUp]);
    assert!(!e.is_sleeping());
    e.request_tx(std_frame(1, &[]), false, false);
    for _ in 0..10 {
        e.sample_bit(RECESSIVE);
        assert!(e.tx(), "still integrating");
    }
    e.sample_bit(RECESSIVE);
    assert!(!e.tx(), "SOF after 11 recessive bits");
}

/// Reset mode: recessive, no participation, request dropped; leaving it
/// needs bus integration. Counter writes report their status changes when
/// reset mode is left.
#[test]
fn reset_mode() {
    let mut e = node_idle();
    e.set_reset_mode(true);
    e.set_rec(200);
    assert!(!e.has_events());
    e.request_tx(std_frame(1, &[]), false, false);
    e.sample_bit(DOMINANT);
    assert!(e.tx());
    e.set_reset_mode(false);
    let ev: Vec<_> = e.take_events().collect();
    assert_eq!(
        ev,
        vec![
            Event::FaultState(FaultState::ErrorPassive),
            Event::ErrorWarning(true)
        ]
    );
    e.sample_bit(DOMINANT);
    for _ in 0..10 {
        e.sample_bit(RECESSIVE);
    }
    assert!(e.tx());
    e.sample_bit(RECESSIVE);
    assert!(
        !e.tx(),
        "SOF once 11 recessive bits followed the dominant one"
    );
}

/// EWL: the warning follows TEC/REC against the limit.
#[test]
fn error_warning_limit() {
    let mut bus = TestBus::idle(1);
    bus.nodes[0].set_options(Options {
        ewl: 16,
        ..Options::default()
    });
    bus.nodes[0].request_tx(std_frame(0x10, &[]), false, false);
    bus.run_until(1000, |b| b.nodes[0].error_warning());
    assert_eq!(bus.nodes[0].tec(), 16);
    assert_eq!(bus.count(0, |e| *e == Event::ErrorWarning(true)), 1);
}
