//! Property tests of the register-access path: random
//! host accesses, at any address, in any mode, interleaved with bus
//! traffic, never panic, never hang, keep the status invariants, and the
//! accounting check still explains every frame.

#[path = "../../../can-proto/tests/support/time_bound.rs"]
mod time_bound;

use crate::common;
use common::*;

/// Bound of one case (a few thousand bit times on up to 4 nodes).
const CASE_BOUND: std::time::Duration = std::time::Duration::from_secs(5);

use proptest::prelude::*;
use regmap::peli;
use sja1000::Bus;
use sja1000::host::{self, Config};

#[derive(Clone, Debug)]
enum Op {
    Write { node: usize, addr: u8, data: u8 },
    Read { node: usize, addr: u8 },
    Send { node: usize, id: u16, len: usize },
    Bits(u64),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        3 => (0..2usize, any::<u8>(), any::<u8>()).prop_map(|(node, addr, data)| Op::Write { node, addr, data }),
        3 => (0..2usize, any::<u8>()).prop_map(|(node, addr)| Op::Read { node, addr }),
        2 => (0..2usize, 0..0x800u16, 0..=8usize).prop_map(|(node, id, len)| Op::Send { node, id, len }),
        2 => (1..300u64).prop_map(Op::Bits),
    ]
}

fn check_invariants(bus: &Bus) {
    for i in 0..bus.len() {
        let n = bus.node(i);
        let sr = n.peek(peli::SR);
        if n.mode() == regmap::Mode::PeliCan {
            let rmc = n.peek(peli::RMC);
            assert!(rmc <= 21, "at most 21 messages of 3 bytes fit in 64");
            assert_eq!(sr & peli::sr::RBS != 0, rmc > 0, "RBS iff RMC > 0");
        }
        assert_eq!(sr & peli::sr::BS != 0, n.bus_off());
        if n.bus_off() {
            assert!(n.in_reset_mode() || n.engine().fault_state() == sja1000::FaultState::BusOff);
        }
    }
}

proptest! {
    // PROPTEST_CASES=100000 for a long run.
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(256),
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_register_traffic_never_breaks_the_model(ops in proptest::collection::vec(op(), 1..100)) {
        let input = format!("{ops:?}");
        time_bound::within(CASE_BOUND, || input, || -> Result<(), TestCaseError> {
            let mut bus = bus_of(&[Config::pelican(), Config::pelican()]);
            for op in ops {
                match op {
                    Op::Write { node, addr, data } => {
                        let _ = bus.node_mut(node).write(addr, data);
                    }
                    Op::Read { node, addr } => {
                        let n = bus.node_mut(node);
                        let peeked = n.peek(addr);
                        let got = n.read(addr);
                        prop_assert_eq!(peeked, got, "peek and read agree at {}", addr);
                        prop_assert_eq!(n.try_read(addr).is_err(), addr as u16 >= n.mode().addr_limit());
                    }
                    Op::Send { node, id, len } => {
                        let data = vec![0x5A; len];
                        let _ = host::transmit(bus.node_mut(node), &std_frame(id, &data), peli::cmr::TR);
                    }
                    Op::Bits(n) => {
                        if bus.fast_path_ok() {
                            bus.run_bits(n);
                        } else {
                            bus.run_clocks(n.min(2_000));
                        }
                    }
                }
                check_invariants(&bus);
            }
            if let Err(e) = bus.check_accounting() {
                return Err(TestCaseError::fail(e.to_string()));
            }
            Ok(())
        })?;
    }
}

#[derive(Clone, Debug)]
enum Fault {
    Flip {
        frame: u64,
        bit: u32,
        node: Option<usize>,
    },
    Glitch {
        frame: u64,
        bit: u32,
        offset: u32,
        width: u32,
        node: Option<usize>,
    },
    Stuck {
        level: bool,
        node: Option<usize>,
        from_bit: u64,
        bits: u64,
    },
}

fn fault(nodes: usize) -> impl Strategy<Value = Fault> {
    let target = proptest::option::of(0..nodes);
    prop_oneof![
        4 => (0..6u64, 0..130u32, target.clone()).prop_map(|(frame, bit, node)| Fault::Flip { frame, bit, node }),
        2 => (0..6u64, 0..130u32, 0..40u32, 1..12u32, target.clone())
            .prop_map(|(frame, bit, offset, width, node)| Fault::Glitch { frame, bit, offset, width, node }),
        1 => (any::<bool>(), target, 0..600u64, 1..40u64)
            .prop_map(|(level, node, from_bit, bits)| Fault::Stuck { level, node, from_bit, bits }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(64),
        ..ProptestConfig::default()
    })]

    /// Random traffic between 2..4 nodes under random bit flips, glitches
    /// and short stuck-at faults: every frame is accounted for, and once
    /// the faults stop every pending frame gets through.
    #[test]
    fn random_faults_lose_nothing(
        nodes in 2..=4usize,
        seed in any::<u64>(),
        faults in proptest::collection::vec(fault(4), 0..4),
    ) {
        let input = format!("nodes {nodes} seed {seed} faults {faults:?}");
        time_bound::within(CASE_BOUND, || input, || -> Result<(), TestCaseError> {
            use sja1000::bus::{FlipBit, Glitch, StuckAt, Target};
            let mut bus = sja1000::workload::pelican_bus(nodes);
            let cpb = bus.clocks_per_bit() as u64;
            let t = |n: Option<usize>| n.filter(|&i| i < nodes).map_or(Target::All, Target::Node);
            for f in &faults {
                match *f {
                    Fault::Flip { frame, bit, node } => bus.add_fault(FlipBit { frame, bit, target: t(node) }),
                    Fault::Glitch { frame, bit, offset, width, node } => {
                        bus.add_fault(Glitch { frame, bit, offset, width, target: t(node) })
                    }
                    Fault::Stuck { level, node, from_bit, bits } => bus.add_fault(StuckAt {
                        level,
                        target: t(node),
                        from: from_bit * cpb,
                        until: Some((from_bit + bits) * cpb),
                    }),
                }
            }
            let mut rng = <rand::rngs::StdRng as rand::SeedableRng>::seed_from_u64(seed);
            let st = sja1000::workload::exchange(&mut bus, &mut rng, 1_500);
            prop_assert!(st.frames_requested >= nodes as u64);
            // Faults over, no new request: every pending frame goes out.
            bus.clear_faults();
            bus.run_bits(3_000);
            for i in 0..nodes {
                let n = bus.node(i);
                prop_assert!(
                    n.in_reset_mode() || n.peek(peli::SR) & peli::sr::TBS != 0,
                    "node {} still has a frame pending (SR {:#04x})", i, n.peek(peli::SR)
                );
            }
            if let Err(e) = bus.check_accounting() {
                return Err(TestCaseError::fail(format!("{e} (faults {faults:?})")));
            }
            check_invariants(&bus);
            Ok(())
        })?;
    }
}
