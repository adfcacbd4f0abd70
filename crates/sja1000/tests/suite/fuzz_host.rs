//! Fuzz of the register-access path, both views: random
//! host reads and writes at every address 0..=255, in BasicCAN and
//! PeliCAN, with reset/operating switching, BasicCAN <-> PeliCAN switching
//! through CDR.7, every command (TR, AT, RRB, CDO, SRR, GTS), sleep and
//! wake-up, hardware resets, transmissions of any frame (DLC 0..15,
//! 11- and 29-bit IDs), interleaved with bus time on both paths. Nothing
//! panics, each case ends within its time bound, out-of-range accesses are
//! errors that change nothing, the status invariants hold, and the bus's
//! accounting check explains every frame (it runs when the bus is dropped).
//!
//! CI runs 256 cases; the `#[ignore]`d `fuzz_host_large` runs `FUZZ_CASES`
//! (default 20 000): `cargo test -p sja1000 --test suite fuzz_host:: -- --ignored --nocapture`.

#[path = "../../../can-proto/tests/support/time_bound.rs"]
mod time_bound;

use crate::common;

use can_proto::CanFrame;
use proptest::prelude::*;
use proptest::test_runner::{Config as RunnerConfig, TestCaseError, TestRunner};
use regmap::{Mode, RegError, peli};
use sja1000::host::{self, Config};
use sja1000::{Bus, Sja1000};
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::time::{Duration, Instant};

/// Bound of one case: at most ~100 ops of at most 400 bit times on 3 nodes.
const CASE_BOUND: Duration = Duration::from_secs(3);

/// MOD (PeliCAN) / CR (BasicCAN), CMR, CDR: the same address in both views.
const MOD_CR: u8 = 0;
const CMR: u8 = 1;
const CDR: u8 = 31;

#[derive(Clone, Debug)]
enum Op {
    /// Any address, any value.
    Write { node: usize, addr: u8, data: u8 },
    /// Any address.
    Read { node: usize, addr: u8 },
    /// MOD/CR with the reset bit set (other bits random).
    EnterReset { node: usize, bits: u8 },
    /// MOD/CR with the reset bit clear (other bits random: LOM, STM, AFM, SM, interrupt enables).
    LeaveReset { node: usize, bits: u8 },
    /// Reset mode, CDR.7 = `peli` (other CDR bits random), then operating.
    SwitchView { node: usize, peli: bool, cdr: u8 },
    /// CMR with a mix of TR, AT, RRB, CDO, SRR/GTS.
    Command { node: usize, cmd: u8 },
    /// Sleep: PeliCAN MOD.SM / BasicCAN CMR.GTS, in operating mode.
    Sleep { node: usize },
    /// Hardware reset (the RST pin).
    HardReset { node: usize },
    /// Load the TX buffer with any frame and request it.
    Send { node: usize, frame: CanFrame, cmd: u8 },
    /// Bus time.
    Bits(u64),
    /// Bus time clock by clock.
    Clocks(u64),
}

fn arb_frame() -> impl Strategy<Value = CanFrame> {
    (any::<bool>(), any::<u32>(), any::<bool>(), 0u8..=15, any::<[u8; 8]>()).prop_map(|(ext, id, rtr, dlc, data)| {
        let id = if ext {
            CanFrame::ext_id(id & 0x1FFF_FFFF).unwrap()
        } else {
            CanFrame::std_id((id & 0x7FF) as u16).unwrap()
        };
        let n = if rtr { 0 } else { dlc.min(8) as usize };
        CanFrame::with_dlc(id, rtr, dlc, &data[..n]).unwrap()
    })
}

fn op(nodes: usize) -> impl Strategy<Value = Op> {
    let n = 0..nodes;
    prop_oneof![
        6 => (n.clone(), any::<u8>(), any::<u8>()).prop_map(|(node, addr, data)| Op::Write { node, addr, data }),
        // addresses where something lives: the defined ones, most of the time
        4 => (n.clone(), 0u8..40, any::<u8>()).prop_map(|(node, addr, data)| Op::Write { node, addr, data }),
        4 => (n.clone(), any::<u8>()).prop_map(|(node, addr)| Op::Read { node, addr }),
        2 => (n.clone(), any::<u8>()).prop_map(|(node, bits)| Op::EnterReset { node, bits: bits | 1 }),
        2 => (n.clone(), any::<u8>()).prop_map(|(node, bits)| Op::LeaveReset { node, bits: bits & !1 }),
        1 => (n.clone(), any::<bool>(), any::<u8>()).prop_map(|(node, peli, cdr)| Op::SwitchView { node, peli, cdr }),
        3 => (n.clone(), 0u8..32).prop_map(|(node, cmd)| Op::Command { node, cmd }),
        1 => n.clone().prop_map(|node| Op::Sleep { node }),
        1 => n.clone().prop_map(|node| Op::HardReset { node }),
        3 => (n.clone(), arb_frame(), prop_oneof![Just(0x01u8), Just(0x03), Just(0x10), Just(0x12), 0u8..32])
            .prop_map(|(node, frame, cmd)| Op::Send { node, frame, cmd }),
        3 => (1..400u64).prop_map(Op::Bits),
        1 => (1..3000u64).prop_map(Op::Clocks),
    ]
}

/// Starting set-up of a node.
fn start() -> impl Strategy<Value = (bool, bool)> {
    // (PeliCAN?, configured and operating?)
    (any::<bool>(), prop::bool::weighted(0.8))
}

fn node_from((peli, operating): (bool, bool)) -> Sja1000 {
    let mut n = Sja1000::new();
    if operating {
        host::configure(&mut n, &if peli { Config::pelican() } else { Config::basic(0, 0xFF) });
    } else if peli {
        n.write(CDR, peli::cdr::CANMODE);
    }
    n
}

/// What must hold after every operation, in either view.
fn invariants(bus: &Bus) -> Result<(), TestCaseError> {
    for i in 0..bus.len() {
        let n = bus.node(i);
        let sr = n.peek(2);
        // SR.BS (bit 7) in both views
        prop_assert_eq!(sr & 0x80 != 0, n.bus_off(), "node {}: SR {:#04x}", i, sr);
        if n.mode() == Mode::PeliCan {
            let rmc = n.peek(peli::RMC);
            prop_assert!(rmc <= 21, "node {}: RMC {} > 21", i, rmc);
            prop_assert_eq!(sr & peli::sr::RBS != 0, rmc > 0, "node {}: RBS iff RMC > 0", i);
        }
        if n.bus_off() {
            prop_assert!(n.in_reset_mode() || n.engine().fault_state() == sja1000::FaultState::BusOff);
        }
        if n.is_sleeping() {
            prop_assert!(!n.in_reset_mode(), "node {} asleep in reset mode", i);
        }
    }
    Ok(())
}

/// True when two nodes out of reset mode run different bit timings.
fn mixed_timing(bus: &Bus) -> bool {
    let mut t = (0..bus.len()).map(|i| bus.node(i)).filter(|n| !n.in_reset_mode()).map(|n| n.engine().timing());
    let first = t.next();
    t.any(|x| Some(x) != first)
}

/// Every in-range register as the host would see it (no side effects).
fn snapshot(n: &Sja1000) -> Vec<u8> {
    (0..n.mode().addr_limit()).map(|a| n.peek(a as u8)).collect()
}

/// Cases whose accounting was checked, frames they sent, mixed-rate cases.
static ACCOUNTED: AtomicU64 = AtomicU64::new(0);
static SENT: AtomicU64 = AtomicU64::new(0);
static MIXED: AtomicU64 = AtomicU64::new(0);

fn run_case(starts: &[(bool, bool)], ops: &[Op]) -> Result<(), TestCaseError> {
    time_bound::within(CASE_BOUND, || format!("starts {starts:?} ops {ops:?}"), || {
        let mut bus = Bus::new();
        // Checked explicitly at the end, so that a failure names the ops.
        bus.set_check_on_drop(false);
        for &s in starts {
            bus.add_node(node_from(s));
        }
        let mut mixed = mixed_timing(&bus);
        for op in ops {
            match *op {
                Op::Write { node, addr, data } => {
                    let n = bus.node_mut(node);
                    let limit = n.mode().addr_limit();
                    if addr as u16 >= limit {
                        // Out of range: an error naming the address, and nothing changes.
                        let before = snapshot(n);
                        let mode = n.mode();
                        prop_assert_eq!(n.try_write(addr, data), Err(RegError::OutOfRange { addr, mode }));
                        prop_assert_eq!(n.write(addr, data), sja1000::WriteOutcome::IgnoredReserved);
                        prop_assert_eq!(snapshot(n), before);
                    } else {
                        let _ = n.write(addr, data);
                    }
                }
                Op::Read { node, addr } => {
                    let n = bus.node_mut(node);
                    let peeked = n.peek(addr);
                    let got = n.read(addr);
                    prop_assert_eq!(peeked, got, "peek and read agree at {}", addr);
                    let out = addr as u16 >= n.mode().addr_limit();
                    prop_assert_eq!(n.try_read(addr).is_err(), out);
                    if out {
                        prop_assert_eq!(got, 0);
                    }
                }
                Op::EnterReset { node, bits } => {
                    let n = bus.node_mut(node);
                    let _ = n.write(MOD_CR, bits);
                    prop_assert!(n.in_reset_mode(), "MOD/CR = {:#04x} leaves reset mode", bits);
                }
                Op::LeaveReset { node, bits } => {
                    let _ = bus.node_mut(node).write(MOD_CR, bits);
                }
                Op::SwitchView { node, peli, cdr } => {
                    let n = bus.node_mut(node);
                    let _ = n.write(MOD_CR, 1);
                    let cdr = if peli { cdr | 0x80 } else { cdr & 0x7F };
                    let _ = n.write(CDR, cdr);
                    prop_assert_eq!(n.mode(), if peli { Mode::PeliCan } else { Mode::BasicCan });
                    let _ = n.write(MOD_CR, 0);
                }
                Op::Command { node, cmd } => {
                    let _ = bus.node_mut(node).write(CMR, cmd);
                }
                Op::Sleep { node } => {
                    let n = bus.node_mut(node);
                    match n.mode() {
                        Mode::PeliCan => {
                            let m = n.peek(MOD_CR);
                            let _ = n.write(MOD_CR, (m | 0x10) & !1);
                        }
                        Mode::BasicCan => {
                            let _ = n.write(CMR, 0x10);
                        }
                    }
                }
                Op::HardReset { node } => {
                    let n = bus.node_mut(node);
                    n.hard_reset();
                    prop_assert_eq!(n.mode(), Mode::BasicCan);
                    prop_assert!(n.in_reset_mode());
                }
                Op::Send { node, frame, cmd } => {
                    let _ = host::transmit(bus.node_mut(node), &frame, cmd);
                }
                Op::Bits(b) => bus.run_bits(b),
                Op::Clocks(c) => bus.run_clocks(c),
            }
            invariants(&bus)?;
            mixed |= mixed_timing(&bus);
        }
        if mixed {
            MIXED.fetch_add(1, Relaxed);
            // The accounting is defined for nodes sharing one bit timing
            // (see `Bus::check_accounting`); no panic and no hang is what
            // a mixed-rate bus is checked for.
            bus.run_bits(200);
            return invariants(&bus);
        }
        // Let the bus settle so the accounting sees whole frames, then check
        // it here (a failure names the ops); the drop check is then disarmed.
        bus.run_bits(200);
        invariants(&bus)?;
        match bus.finish() {
            Ok(acc) => {
                ACCOUNTED.fetch_add(1, Relaxed);
                SENT.fetch_add(acc.sent as u64, Relaxed);
                Ok(())
            }
            Err(e) => Err(TestCaseError::fail(format!("accounting: {e}"))),
        }
    })
}

fn case() -> impl Strategy<Value = (Vec<(bool, bool)>, Vec<Op>)> {
    (1..=3usize).prop_flat_map(|nodes| {
        (prop::collection::vec(start(), nodes), prop::collection::vec(op(nodes), 1..100))
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn random_host_traffic_in_both_views(c in case()) {
        run_case(&c.0, &c.1)?;
    }
}

/// Every address 0..=255 in every view and mode, read and written with
/// every bit pattern of interest: no panic; out-of-range is `OutOfRange`.
#[test]
fn every_address_in_every_view_and_mode() {
    for peli in [false, true] {
        for operating in [false, true] {
            for addr in 0..=255u8 {
                for data in [0x00, 0xFF, 0x55, 0xAA, 0x01, 0x80] {
                    let mut n = node_from((peli, operating));
                    let mode = n.mode();
                    let r = n.try_write(addr, data);
                    if addr as u16 >= mode.addr_limit() {
                        assert_eq!(r, Err(RegError::OutOfRange { addr, mode }));
                        assert!(r.unwrap_err().to_string().contains(&format!("address {addr}")));
                    } else {
                        assert!(r.is_ok(), "{mode:?} addr {addr}: {r:?}");
                    }
                    // reads after any write, at any address
                    for a in 0..=255u8 {
                        let _ = n.read(a);
                    }
                    // a few bits of bus time after it, as the hardware would
                    let mut bus = Bus::new();
                    bus.add_node(n);
                    bus.run_bits(30);
                }
            }
        }
    }
}

#[test]
#[ignore = "large fuzz run (minutes); run with FUZZ_CASES=N cargo test -p sja1000 --test suite fuzz_host::fuzz_host_large -- --ignored --nocapture"]
fn fuzz_host_large() {
    let cases = time_bound::large_cases(20_000);
    let mut runner = TestRunner::new(RunnerConfig { cases, failure_persistence: None, ..RunnerConfig::default() });
    let t = Instant::now();
    let r = runner.run(&case(), |(s, ops)| run_case(&s, &ops));
    println!(
        "fuzz sja1000 host access: {cases} cases in {:.1} s ({} with the accounting checked, {} frames sent; {} on a mixed-rate bus): {}",
        t.elapsed().as_secs_f64(),
        ACCOUNTED.load(Relaxed),
        SENT.load(Relaxed),
        MIXED.load(Relaxed),
        match &r {
            Ok(()) => "no failure".to_string(),
            Err(e) => format!("FAILED: {e}"),
        }
    );
    r.unwrap();
}

/// `common` is shared with the other test files; this one uses its frames.
#[test]
fn frames_of_every_shape_are_accepted_by_transmit() {
    for f in [common::std_frame(0x7FF, &[1; 8]), common::ext_frame(0x1FFF_FFFF, &[])] {
        let mut bus = common::bus_of(&[Config::pelican(), Config::pelican()]);
        host::transmit(bus.node_mut(0), &f, peli::cmr::TR).unwrap();
        bus.run_bits(200);
        assert_eq!(host::receive(bus.node_mut(1)), Some(f));
    }
}
