//! Engine tests on a tiny wired-AND bus of engines, grouped per state.

mod arbitration;
mod errors;
mod fault;
mod frames;
mod modes;
mod timing;

use crate::{Engine, Event, Options};
use can_proto::timing::BusTiming;
use can_proto::{CanFrame, Field, FrameTrait, RECESSIVE};

/// 500 kbit/s at 16 MHz: BRP 0, 16 tq, sample point 81 %.
pub(crate) const TIMING: BusTiming = BusTiming {
    brp: 0,
    sjw: 3,
    tseg1: 11,
    tseg2: 2,
    sam: false,
};

/// Something that happened at bus bit `bit` on node `node`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Logged {
    pub bit: usize,
    pub node: usize,
    pub event: Event,
}

/// N engines on one wired-AND bus, stepped one bit at a time (fast path).
pub(crate) struct TestBus {
    pub nodes: Vec<Engine>,
    /// Bus level of every bit so far.
    pub bits: Vec<bool>,
    /// Field node 0 was in at every bit (before sampling it).
    pub fields: Vec<Field>,
    pub log: Vec<Logged>,
    /// Bus level forced at absolute bit indices (all nodes see it).
    pub force: Vec<(usize, bool)>,
    /// Level one node sees at one bit: (bit, node, level).
    pub force_rx: Vec<(usize, usize, bool)>,
    /// Bus stuck at this level (the nodes' drivers are ignored).
    pub stuck: Option<bool>,
}

impl TestBus {
    pub fn new(n: usize, opt: Options) -> Self {
        let nodes = (0..n).map(|_| Engine::new(TIMING, opt)).collect();
        TestBus {
            nodes,
            bits: Vec::new(),
            fields: Vec::new(),
            log: Vec::new(),
            force: Vec::new(),
            force_rx: Vec::new(),
            stuck: None,
        }
    }

    /// `n` nodes that have finished bus integration (bus idle).
    pub fn idle(n: usize) -> Self {
        let mut b = Self::new(n, Options::default());
        b.run(11);
        assert!(b.nodes.iter().all(|e| e.field() == Field::BusIdle));
        b.log.clear();
        b
    }

    pub fn step(&mut self) {
        let i = self.bits.len();
        let mut bus = self.nodes.iter().fold(RECESSIVE, |a, e| a & e.tx());
        if let Some(l) = self.stuck {
            bus = l;
        }
        if let Some(&(_, l)) = self.force.iter().find(|(b, _)| *b == i) {
            bus = l;
        }
        self.fields.push(self.nodes[0].field());
        for (k, e) in self.nodes.iter_mut().enumerate() {
            let rx = self
                .force_rx
                .iter()
                .find(|(b, n, _)| *b == i && *n == k)
                .map_or(bus, |f| f.2);
            e.sample_bit(rx);
            for event in e.take_events() {
                self.log.push(Logged {
                    bit: i,
                    node: k,
                    event,
                });
            }
        }
        self.bits.push(bus);
    }

    pub fn run(&mut self, n: usize) {
        for _ in 0..n {
            self.step();
        }
    }

    /// Steps until `done` holds (checked after each bit); panics after `max` bits.
    pub fn run_until(&mut self, max: usize, mut done: impl FnMut(&TestBus) -> bool) {
        for _ in 0..max {
            self.step();
            if done(self) {
                return;
            }
        }
        panic!(
            "condition not reached in {max} bits; last events: {:?}",
            &self.log[self.log.len().saturating_sub(8)..]
        );
    }

    /// Events of one node, in order.
    pub fn events(&self, node: usize) -> Vec<Event> {
        self.log
            .iter()
            .filter(|l| l.node == node)
            .map(|l| l.event.clone())
            .collect()
    }

    /// Bit index of the first bit node 0 spent in `field` at or after `from`.
    pub fn first_bit_in(&self, field: Field, from: usize) -> Option<usize> {
        (from..self.fields.len()).find(|&i| self.fields[i] == field)
    }

    pub fn count(&self, node: usize, f: impl Fn(&Event) -> bool) -> usize {
        self.log
            .iter()
            .filter(|l| l.node == node && f(&l.event))
            .count()
    }
}

pub(crate) fn std_frame(id: u16, data: &[u8]) -> CanFrame {
    CanFrame::new(CanFrame::std_id(id).unwrap(), data).unwrap()
}

pub(crate) fn ext_frame(id: u32, data: &[u8]) -> CanFrame {
    CanFrame::new(CanFrame::ext_id(id).unwrap(), data).unwrap()
}

/// A node alone that is error active and idle.
pub(crate) fn node_idle() -> Engine {
    let mut e = Engine::new(TIMING, Options::default());
    for _ in 0..11 {
        e.sample_bit(RECESSIVE);
    }
    e.take_events().for_each(drop);
    e
}

/// An idle node made error passive by a CPU write of REC in reset mode.
pub(crate) fn node_error_passive(rec: u8, tec: u8) -> Engine {
    let mut e = node_idle();
    e.set_reset_mode(true);
    e.set_rec(rec);
    e.set_tec(tec);
    e.set_reset_mode(false);
    for _ in 0..11 {
        e.sample_bit(RECESSIVE);
    }
    assert_eq!(e.fault_state(), crate::FaultState::ErrorPassive);
    e.take_events().for_each(drop);
    e
}

/// Bus level pattern of a standalone stuffed frame, for sanity checks.
pub(crate) fn wire(frame: &CanFrame) -> Vec<bool> {
    frame.wire_bits().iter().by_vals().collect()
}
