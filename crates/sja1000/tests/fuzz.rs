//! Property tests of the register-access path (issue 8 item 2): random
//! host accesses, at any address, in any mode, interleaved with bus
//! traffic, never panic, never hang, keep the status invariants, and the
//! accounting check still explains every frame.

mod common;
use common::*;

use proptest::prelude::*;
use regmap::peli;
use sja1000::host::{self, Config};
use sja1000::Bus;

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
    }
}
