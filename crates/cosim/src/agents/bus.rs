//! The bus agent: the CAN bus the DUT sits on. The wired-AND of the DUT's
//! `tx_o` and the golden-model nodes (`sja1000::Bus`, clocked with it), the
//! faults on what those nodes receive (inside that bus) and on what the DUT
//! receives, and how the DUT's `rx_i` is wired (bus, tied recessive, tied
//! dominant). Raw nodes ([`super::raw`]) drive the wire with them.

use can_proto::RECESSIVE;
use diagnose::RxWiring;
use sja1000::{Bus, BusContext, FaultInjector, Sja1000};

use super::raw::RawNode;

/// A golden-model node on the bus, configured by register writes at start.
#[derive(Clone, Debug, Default)]
pub struct NodeConfig {
    /// Name for reports.
    pub name: String,
    /// Register writes applied right after its hardware reset.
    pub init: Vec<(u8, u8)>,
}

/// The bus, its model nodes and faults, and the DUT's rx wiring.
pub struct BusAgent {
    bus: Bus,
    /// Faults on what the DUT receives (it is node `bus.len()` to them).
    dut_faults: Vec<Box<dyn FaultInjector>>,
    rx_wiring: RxWiring,
    /// The DUT's `tx_o` drives the bus.
    tx_on_bus: bool,
    /// The bus level at the last CAN edge.
    level: bool,
    /// The DUT's `rx_i` from the last CAN edge.
    dut_rx: bool,
    /// Faults every node receives, applied for an observer (node index
    /// `bus.len() + 1` to them): what the nodes see of the bus.
    seen_faults: Vec<Box<dyn FaultInjector>>,
    /// The bus level through `seen_faults` at the last CAN edge.
    seen: bool,
    /// Bit-level senders on the wire (wired-AND with the DUT's tx and the
    /// model nodes); they follow the bench's bit clock.
    raw: Vec<RawNode>,
}

impl BusAgent {
    /// A bus with `nodes` (each reset, then its `init` writes), `faults` on
    /// what the nodes receive, `dut_faults` on what the DUT receives.
    pub fn new(
        nodes: &[NodeConfig],
        faults: Vec<Box<dyn FaultInjector>>,
        dut_faults: Vec<Box<dyn FaultInjector>>,
        rx_wiring: RxWiring,
        tx_on_bus: bool,
    ) -> BusAgent {
        let mut bus = Bus::new();
        bus.set_accounting(false);
        for n in nodes {
            let mut s = Sja1000::new();
            for &(a, d) in &n.init {
                s.write(a, d);
            }
            bus.add_node(s);
        }
        for f in faults {
            bus.add_fault_boxed(f);
        }
        BusAgent {
            bus,
            dut_faults,
            rx_wiring,
            tx_on_bus,
            level: RECESSIVE,
            dut_rx: RECESSIVE,
            seen_faults: Vec::new(),
            seen: RECESSIVE,
            raw: Vec::new(),
        }
    }

    /// The faults every node receives, once more for an observer (node
    /// index `bus.len() + 1` to them): [`BusAgent::seen_level`].
    pub fn with_faults_seen(mut self, faults: Vec<Box<dyn FaultInjector>>) -> Self {
        self.seen_faults = faults;
        self
    }

    /// The bus level as the nodes see it at the last CAN edge: the wire
    /// through the faults every node receives.
    #[inline]
    pub fn seen_level(&self) -> bool {
        self.seen
    }

    /// Puts raw nodes on the wire.
    pub fn with_raw_nodes(mut self, raw: Vec<RawNode>) -> BusAgent {
        self.raw = raw;
        self
    }

    /// The raw nodes.
    pub fn raw_nodes(&self) -> &[RawNode] {
        &self.raw
    }

    /// The model nodes.
    pub fn bus(&self) -> &Bus {
        &self.bus
    }

    /// The model nodes, to queue frames or change their configuration.
    pub fn bus_mut(&mut self) -> &mut Bus {
        &mut self.bus
    }

    /// The bus level at the last CAN edge.
    #[inline]
    pub fn level(&self) -> bool {
        self.level
    }

    /// The DUT's rx from the last CAN edge.
    #[inline]
    pub fn dut_rx(&self) -> bool {
        self.dut_rx
    }

    /// A CAN rising edge, before the DUT's eval: the bus level (wired-AND of
    /// the DUT's tx, if on the bus, and the model nodes, which are clocked
    /// with it) and the DUT's rx from it, through its faults, whose context
    /// `ctx` gives (asked only when there are some). Both are kept.
    #[inline]
    pub fn can_rise(&mut self, dut_tx: bool, ctx: impl FnOnce() -> BusContext) -> bool {
        let mut dut_tx = if self.tx_on_bus { dut_tx } else { RECESSIVE };
        // Asked once, only when something needs it.
        let ctx = (!self.dut_faults.is_empty() || !self.raw.is_empty() || !self.seen_faults.is_empty()).then(ctx);
        if let Some(c) = &ctx {
            // The raw nodes drive the wire like another transceiver.
            for r in &mut self.raw {
                dut_tx &= r.drive(c, self.level);
            }
        }
        let level = if self.bus.is_empty() { dut_tx } else { self.bus.clock_with(dut_tx) };
        self.level = level;
        // With model nodes, the faults every node receives are the bus's own,
        // also for the DUT (node `len()`) and the field decoder (`len() + 1`):
        // the same wire bit, counted as the nodes count frames.
        let (wire_rx, seen) = if self.bus.is_empty() {
            (level, level)
        } else {
            let n = self.bus.len();
            (self.bus.external_rx_of(n), self.bus.external_rx_of(n + 1))
        };
        self.seen = seen;
        if let Some(c) = ctx.as_ref().filter(|_| !self.seen_faults.is_empty()) {
            let me = self.bus.len() + 1;
            for f in &mut self.seen_faults {
                self.seen = f.apply(c, me, self.seen);
            }
        }
        let rx = match self.rx_wiring {
            RxWiring::Bus => {
                let mut rx = wire_rx;
                if let Some(ctx) = ctx.filter(|_| !self.dut_faults.is_empty()) {
                    let me = self.bus.len();
                    for f in &mut self.dut_faults {
                        rx = f.apply(&ctx, me, rx);
                    }
                }
                rx
            }
            RxWiring::TiedRecessive => true,
            RxWiring::TiedDominant => false,
        };
        self.dut_rx = rx;
        rx
    }

    /// How the DUT's rx is driven if nothing but its own tx drives the bus
    /// (no model nodes, no faults, no raw nodes): `Some(None)` its own tx, looped back;
    /// `Some(Some(level))` tied; `None` when nodes or faults are there.
    pub fn loopback_rx(&self) -> Option<Option<bool>> {
        if !self.bus.is_empty() || !self.dut_faults.is_empty() || !self.raw.is_empty() || !self.seen_faults.is_empty() {
            return None;
        }
        Some(match self.rx_wiring {
            RxWiring::Bus if self.tx_on_bus => None,
            RxWiring::Bus => Some(RECESSIVE),
            RxWiring::TiedRecessive => Some(true),
            RxWiring::TiedDominant => Some(false),
        })
    }

    /// The bus level [`BusAgent::replay_rise`] takes from `prev_tx`.
    #[inline]
    pub fn replay_level(&self, prev_tx: bool) -> bool {
        if self.tx_on_bus { prev_tx } else { RECESSIVE }
    }

    /// [`BusAgent::can_rise`] for an instant replayed from a batch (see
    /// [`BusAgent::loopback_rx`]): the DUT's tx of the instant before,
    /// the rx the batch drove.
    #[inline]
    pub fn replay_rise(&mut self, prev_tx: bool, rx: Option<bool>) {
        let level = self.replay_level(prev_tx);
        self.level = level;
        self.seen = level;
        self.dut_rx = rx.unwrap_or(level);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use can_proto::DOMINANT;
    use sja1000::{StuckAt, Target};

    fn ctx() -> BusContext {
        BusContext { clock: 0, frame: None, frame_bit: 0, sub: 0, clocks_per_bit: 10 }
    }

    #[test]
    fn without_nodes_the_bus_is_the_dut_tx_and_rx_follows_the_wiring() {
        let mut b = BusAgent::new(&[], Vec::new(), Vec::new(), RxWiring::Bus, true);
        assert_eq!(b.can_rise(DOMINANT, ctx), DOMINANT);
        assert_eq!((b.level(), b.dut_rx()), (DOMINANT, DOMINANT));
        assert_eq!(b.loopback_rx(), Some(None), "its own tx looped back");
        // tx not on the bus: the bus stays recessive.
        let mut b = BusAgent::new(&[], Vec::new(), Vec::new(), RxWiring::Bus, false);
        assert_eq!(b.can_rise(DOMINANT, ctx), RECESSIVE);
        assert_eq!(b.loopback_rx(), Some(Some(RECESSIVE)));
        // Tied rx: the bus level is still the DUT's tx.
        let mut b = BusAgent::new(&[], Vec::new(), Vec::new(), RxWiring::TiedDominant, true);
        assert_eq!(b.can_rise(RECESSIVE, ctx), DOMINANT);
        assert_eq!(b.level(), RECESSIVE);
        b.replay_rise(DOMINANT, Some(false));
        assert_eq!((b.level(), b.dut_rx()), (DOMINANT, DOMINANT));
    }

    #[test]
    fn a_fault_every_node_sees_reaches_the_seen_level_not_the_wire() {
        let stuck: Box<dyn FaultInjector> = Box::new(StuckAt::forever(DOMINANT, Target::Node(1)));
        let mut b = BusAgent::new(&[], Vec::new(), Vec::new(), RxWiring::Bus, true).with_faults_seen(vec![stuck]);
        assert_eq!(b.can_rise(RECESSIVE, ctx), RECESSIVE);
        assert_eq!((b.level(), b.seen_level(), b.dut_rx()), (RECESSIVE, DOMINANT, RECESSIVE));
        assert_eq!(b.loopback_rx(), None, "no batching past a fault");
        let mut clean = BusAgent::new(&[], Vec::new(), Vec::new(), RxWiring::Bus, true);
        clean.can_rise(DOMINANT, ctx);
        assert_eq!(clean.seen_level(), DOMINANT, "without faults the nodes see the wire");
    }

    #[test]
    fn a_fault_on_the_dut_rx_reaches_only_the_dut_and_stops_batching() {
        let stuck: Box<dyn FaultInjector> = Box::new(StuckAt::forever(DOMINANT, Target::All));
        let mut b = BusAgent::new(&[], Vec::new(), vec![stuck], RxWiring::Bus, true);
        let mut asked = 0;
        let rx = b.can_rise(RECESSIVE, || {
            asked += 1;
            ctx()
        });
        assert_eq!((rx, b.level()), (DOMINANT, RECESSIVE), "the DUT sees the fault, the bus does not");
        assert_eq!(asked, 1, "the fault's context is asked for");
        assert_eq!(b.loopback_rx(), None);
    }

    /// A fault every node receives, given to the bus for the DUT too (node
    /// `len()`), reaches the DUT's rx on the wire bit the bus counts for the
    /// nodes (frames: a dominant level after ten recessive bits), whatever
    /// the bench's own context says.
    #[test]
    fn a_bus_fault_reaches_the_dut_in_the_context_the_nodes_have() {
        use sja1000::FlipBit;
        let nodes = vec![NodeConfig { name: "n".into(), init: vec![] }];
        let flip: Box<dyn FaultInjector> = Box::new(FlipBit { frame: 0, bit: 2, target: Target::Node(1) });
        let mut b = BusAgent::new(&nodes, vec![flip], Vec::new(), RxWiring::Bus, true);
        let cpb = b.bus().clocks_per_bit() as usize;
        let sof = 12 * cpb;
        let mut flipped = Vec::new();
        for k in 0..sof + 5 * cpb {
            let tx = k < sof;
            // The bench's context never names a frame: not the one used.
            let rx = b.can_rise(tx, ctx);
            assert_eq!(b.level(), tx, "clock {k}: the wire is not faulted");
            if rx != tx {
                flipped.push(k);
            }
        }
        assert_eq!(flipped, (sof + 2 * cpb..sof + 3 * cpb).collect::<Vec<_>>(), "bit 2 of the first frame, every clock of it");
    }

    #[test]
    fn a_raw_node_drives_the_wire_for_the_dut_and_the_model_nodes() {
        use super::super::raw::RawStart;
        let nodes = vec![NodeConfig { name: "n".into(), init: vec![] }];
        let raw = RawNode::new("lt", RawStart::AtBit(1), vec![DOMINANT, RECESSIVE]);
        let mut b = BusAgent::new(&nodes, Vec::new(), Vec::new(), RxWiring::Bus, true).with_raw_nodes(vec![raw]);
        assert_eq!(b.loopback_rx(), None, "a raw node on the bus: no batch");
        let mut clock = 0;
        let mut levels = Vec::new();
        for _ in 0..40 {
            let c = BusContext { clock, ..ctx() };
            levels.push((b.can_rise(RECESSIVE, || c), b.level(), b.bus().level()));
            clock += 1;
        }
        // Bit 1 (clocks 10..20) dominant on the wire, in the DUT's rx and in
        // what the model nodes' bus carries; recessive before and after.
        for (k, &(rx, level, nodes_level)) in levels.iter().enumerate() {
            let want = !(10..20).contains(&k);
            assert_eq!((rx, level, nodes_level), (want, want, want), "clock {k}");
        }
        assert!(b.raw_nodes()[0].done());
        // A raw node alone (no model nodes): the wire is its level and the DUT's.
        let raw = RawNode::new("lt", RawStart::AtBit(0), vec![DOMINANT]);
        let mut b = BusAgent::new(&[], Vec::new(), Vec::new(), RxWiring::Bus, true).with_raw_nodes(vec![raw]);
        assert_eq!(b.can_rise(RECESSIVE, ctx), DOMINANT);
    }

    #[test]
    fn model_nodes_are_configured_and_wired_and_with_the_dut() {
        // A node in reset mode (MOD.RM after its hardware reset) drives recessive.
        let nodes = vec![NodeConfig { name: "n".into(), init: vec![(6, 0x41)] }];
        let mut b = BusAgent::new(&nodes, Vec::new(), Vec::new(), RxWiring::Bus, true);
        assert_eq!(b.bus().len(), 1);
        assert_eq!(b.loopback_rx(), None, "nodes on the bus: no batch");
        assert_eq!(b.can_rise(DOMINANT, ctx), DOMINANT, "wired-AND: the DUT's dominant wins");
        assert_eq!(b.can_rise(RECESSIVE, ctx), RECESSIVE);
        assert_eq!(b.bus_mut().node(0).peek(6), 0x41, "its init writes applied");
    }
}
