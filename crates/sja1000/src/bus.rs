//! N controllers on one wired-AND CAN bus (dominant = `false` wins), with
//! per-node propagation delay, fault injectors wrapping the bus (the way
//! smoltcp's `FaultInjector` wraps a device), a fast per-bit path, and the
//! accounting check that no frame was lost.
//!
//! Time is counted in CAN clocks (clk_i) shared by every node. On the fast
//! path one step is one bit time and advances the clock count by the bit's
//! length in clocks, so both paths report the same units.

use std::collections::VecDeque;
use std::fmt;

use can_proto::{CanFrame, RECESSIVE};
use rand::{RngExt, SeedableRng, rngs::StdRng};

use crate::FaultState;
use crate::controller::{NodeEvent, RxOutcome, Sja1000};

/// Where the bus is, as a fault injector sees it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BusContext {
    /// CAN clocks since the bus was created.
    pub clock: u64,
    /// Index of the frame under way (0 = first SOF seen), if any.
    pub frame: Option<u64>,
    /// Bit of that frame, counted on the wire from SOF = 0 (stuff bits,
    /// error and overload flags included), until the next SOF.
    pub frame_bit: u32,
    /// Clock within the bit (always 0 on the fast path).
    pub sub: u32,
    /// Clocks per bit of the reference timing ([`Bus::clocks_per_bit`]).
    pub clocks_per_bit: u32,
}

/// Which nodes a fault applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// What every node receives.
    All,
    /// What one node receives.
    Node(usize),
}

impl Target {
    fn hits(self, node: usize) -> bool {
        match self {
            Target::All => true,
            Target::Node(n) => n == node,
        }
    }
}

/// A fault on the bus: turns the wired-AND level into what `node` receives.
pub trait FaultInjector: fmt::Debug {
    /// The level `node` sees when the bus carries `level`.
    fn apply(&mut self, ctx: &BusContext, node: usize, level: bool) -> bool;
    /// True if the fault acts inside a bit (glitch): the bus must then
    /// run clock by clock, not on the per-bit fast path.
    fn needs_clocks(&self) -> bool {
        false
    }
}

/// Receiver input stuck at one level (stuck-dominant / stuck-recessive),
/// from clock `from` on (forever if `until` is `None`).
#[derive(Clone, Copy, Debug)]
pub struct StuckAt {
    /// Level forced.
    pub level: bool,
    /// Who sees it.
    pub target: Target,
    /// First clock of the fault.
    pub from: u64,
    /// First clock after the fault.
    pub until: Option<u64>,
}

impl StuckAt {
    /// Stuck at `level` for `target`, from now on.
    pub fn forever(level: bool, target: Target) -> Self {
        StuckAt {
            level,
            target,
            from: 0,
            until: None,
        }
    }
}

impl FaultInjector for StuckAt {
    fn apply(&mut self, ctx: &BusContext, node: usize, level: bool) -> bool {
        let on = ctx.clock >= self.from && self.until.is_none_or(|u| ctx.clock < u);
        if on && self.target.hits(node) {
            self.level
        } else {
            level
        }
    }
}

/// Inverts bit `bit` (wire position, SOF = 0) of frame `frame` for `target`.
#[derive(Clone, Copy, Debug)]
pub struct FlipBit {
    /// Frame index (0 = first frame on the bus).
    pub frame: u64,
    /// Wire bit within the frame.
    pub bit: u32,
    /// Who sees the flipped bit.
    pub target: Target,
}

impl FlipBit {
    /// A flip at a seeded random position: frame in `0..frames`, bit in `0..bits`.
    pub fn random(seed: u64, frames: u64, bits: u32, target: Target) -> Self {
        let mut rng = StdRng::seed_from_u64(seed);
        FlipBit {
            frame: rng.random_range(0..frames.max(1)),
            bit: rng.random_range(0..bits.max(1)),
            target,
        }
    }
}

impl FaultInjector for FlipBit {
    fn apply(&mut self, ctx: &BusContext, node: usize, level: bool) -> bool {
        if ctx.frame == Some(self.frame) && ctx.frame_bit == self.bit && self.target.hits(node) {
            !level
        } else {
            level
        }
    }
}

/// `width` CAN clocks of `level` from clock `offset` of wire bit `bit` of
/// frame `frame`, counted like [`Glitch`]. A glitch inverts the wire's
/// level, which turns back into the opposite one as soon as the target
/// drives the wire itself inside the pulse; a forced pulse stays `level`.
#[derive(Clone, Copy, Debug)]
pub struct ForcedPulse {
    /// Frame index (0 = first frame on the bus).
    pub frame: u64,
    /// Wire bit within the frame.
    pub bit: u32,
    /// First clock of the pulse within the bit.
    pub offset: u32,
    /// Pulse length in clocks.
    pub width: u32,
    /// The level forced.
    pub level: bool,
    /// Who sees it.
    pub target: Target,
}

impl FaultInjector for ForcedPulse {
    fn apply(&mut self, ctx: &BusContext, node: usize, level: bool) -> bool {
        let inside = ctx.frame == Some(self.frame) && ctx.frame_bit == self.bit && ctx.sub >= self.offset && ctx.sub < self.offset + self.width;
        if inside && self.target.hits(node) { self.level } else { level }
    }

    fn needs_clocks(&self) -> bool {
        true
    }
}

/// `level` forced from wire bit `bit` of frame `frame` on, for `bits` bit
/// times (a stuck-dominant or stuck-recessive fault placed in a frame).
#[derive(Clone, Copy, Debug)]
pub struct StuckInFrame {
    /// The level forced.
    pub level: bool,
    /// Who sees it.
    pub target: Target,
    /// Frame index (0 = first frame on the bus).
    pub frame: u64,
    /// Wire bit of that frame where the fault starts.
    pub bit: u32,
    /// Length in bit times.
    pub bits: u64,
    /// First clock after the fault, once started (None before).
    pub until: Option<u64>,
}

impl FaultInjector for StuckInFrame {
    fn apply(&mut self, ctx: &BusContext, node: usize, level: bool) -> bool {
        if self.until.is_none() && ctx.frame == Some(self.frame) && ctx.frame_bit == self.bit {
            self.until = Some(ctx.clock + self.bits * u64::from(ctx.clocks_per_bit));
        }
        match self.until {
            Some(u) if self.target.hits(node) && ctx.clock < u => self.level,
            _ => level,
        }
    }
}

/// A short pulse of the opposite level inside one bit: `width` clocks
/// starting `offset` clocks into bit `bit` of frame `frame`.
#[derive(Clone, Copy, Debug)]
pub struct Glitch {
    /// Frame index.
    pub frame: u64,
    /// Wire bit within the frame.
    pub bit: u32,
    /// First clock of the pulse within the bit.
    pub offset: u32,
    /// Pulse length in clocks.
    pub width: u32,
    /// Who sees it.
    pub target: Target,
}

impl Glitch {
    /// A glitch at a seeded random place: frame in `0..frames`, bit in
    /// `0..bits`, offset anywhere in a bit of `clocks_per_bit`, 1..=`max_width` clocks.
    pub fn random(
        seed: u64,
        frames: u64,
        bits: u32,
        clocks_per_bit: u32,
        max_width: u32,
        target: Target,
    ) -> Self {
        let mut rng = StdRng::seed_from_u64(seed);
        Glitch {
            frame: rng.random_range(0..frames.max(1)),
            bit: rng.random_range(0..bits.max(1)),
            offset: rng.random_range(0..clocks_per_bit.max(1)),
            width: rng.random_range(1..=max_width.max(1)),
            target,
        }
    }
}

impl Glitch {
    /// A glitch placed in time quanta: `width_tq` quanta from quantum
    /// `offset_tq` of bit `bit` (quantum 0 is SYNC_SEG, counted from the
    /// bit's start on the bus), a quantum being `clocks_per_tq` CAN clocks
    /// (2 * (BRP + 1), SJA1000 datasheet BTR0). A pulse exactly one quantum
    /// wide covers exactly one quantum boundary of a receiver whose quanta
    /// are offset from the bus's by less than a quantum, so it can hit one
    /// of the three samples of SAM = 1 and no other.
    pub fn in_quanta(
        frame: u64,
        bit: u32,
        offset_tq: u32,
        width_tq: u32,
        clocks_per_tq: u32,
        target: Target,
    ) -> Self {
        Glitch {
            frame,
            bit,
            offset: offset_tq * clocks_per_tq,
            width: width_tq * clocks_per_tq,
            target,
        }
    }
}

impl FaultInjector for Glitch {
    fn apply(&mut self, ctx: &BusContext, node: usize, level: bool) -> bool {
        let inside = ctx.frame == Some(self.frame)
            && ctx.frame_bit == self.bit
            && ctx.sub >= self.offset
            && ctx.sub < self.offset + self.width;
        if inside && self.target.hits(node) {
            !level
        } else {
            level
        }
    }

    fn needs_clocks(&self) -> bool {
        true
    }
}

/// A fixed-length delay line of bus levels (propagation delay).
#[derive(Clone, Debug)]
struct DelayLine(VecDeque<bool>);

impl DelayLine {
    fn new(clocks: u32) -> Self {
        DelayLine(std::iter::repeat_n(RECESSIVE, clocks as usize).collect())
    }
    #[inline]
    fn push(&mut self, v: bool) -> bool {
        if self.0.is_empty() {
            return v;
        }
        self.0.push_back(v);
        self.0.pop_front().unwrap_or(v)
    }
}

/// Frame tracker on the true wired-AND level: a dominant level after at
/// least 10 recessive bits is a start of frame (11 recessive bits end every
/// frame, error and overload frame; a dominant third intermission bit is
/// itself a SOF, CAN 2.0B §9.1).
#[derive(Clone, Debug, Default)]
struct Tracker {
    recessive_clocks: u64,
    /// Recessive clocks that make the next dominant level a SOF: 10 bits
    /// less half a bit of tolerance for resynchronisation on the clock path.
    threshold: u64,
    threshold_cpb: u64,
    frame: Option<u64>,
    next_frame: u64,
    start: u64,
    /// SOF clocks, kept only for the accounting check.
    starts: Vec<u64>,
    record: bool,
}

impl Tracker {
    /// Threshold for bit times of `cpb` clocks (hoisted out of the loop).
    #[inline]
    fn set_cpb(&mut self, cpb: u64) {
        if self.threshold_cpb != cpb {
            self.threshold_cpb = cpb;
            self.threshold = 10 * cpb - cpb / 2;
        }
    }

    /// [`Tracker::step`] for one whole bit after [`Tracker::set_cpb`]: the
    /// level itself (random on a busy bus) selects, only a SOF branches.
    #[inline]
    fn step_bit(&mut self, clock: u64, level: bool, cpb: u64) {
        // One well-predicted branch, none on the level itself: a recessive
        // level masks the count to 0, below any threshold.
        let run = self.recessive_clocks & 0u64.wrapping_sub(!level as u64);
        if run >= self.threshold {
            self.frame = Some(self.next_frame);
            self.next_frame += 1;
            self.start = clock;
            if self.record {
                self.starts.push(clock);
            }
        }
        self.recessive_clocks = (self.recessive_clocks + cpb) & 0u64.wrapping_sub(level as u64);
    }

    #[inline]
    fn step(&mut self, clock: u64, level: bool, clocks: u64, cpb: u64) {
        if level {
            self.recessive_clocks += clocks;
        } else {
            if self.threshold_cpb != cpb {
                self.threshold_cpb = cpb;
                self.threshold = 10 * cpb - cpb / 2;
            }
            if self.recessive_clocks >= self.threshold {
                self.frame = Some(self.next_frame);
                self.next_frame += 1;
                self.start = clock;
                if self.record {
                    self.starts.push(clock);
                }
            }
            self.recessive_clocks = 0;
        }
    }
}

/// One journal entry with its time and node.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    /// CAN clock at which it was seen.
    pub clock: u64,
    /// Node index.
    pub node: usize,
    /// What happened.
    pub event: NodeEvent,
}

/// Totals of a passed accounting check.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Accounting {
    /// Frames whose transmission completed.
    pub sent: usize,
    /// (frame, receiving node) pairs checked.
    pub deliveries: usize,
    /// Of those, stored in the receiver's FIFO.
    pub stored: usize,
    /// Rejected by the receiver's acceptance filter.
    pub filtered: usize,
    /// Lost to a data overrun (flagged by DOS).
    pub overruns: usize,
    /// Missed by a node that was off the bus (reset mode, sleep, bus-off, integrating).
    pub off_bus: usize,
    /// Missed by a node that signalled an error frame.
    pub error_frames: usize,
    /// Receptions of a frame whose sender saw an error the receivers did
    /// not (error at the last EOF bit, passive ACK error) and retransmits:
    /// CAN's known double reception.
    pub duplicates: usize,
    /// Receptions whose sender is an external participant.
    pub external: usize,
    /// Receptions at the very end of the run whose sender had not yet
    /// reached the end of its EOF.
    pub in_flight: usize,
    /// Receptions whose sender left the bus before its last EOF bit.
    pub sender_cut_off: usize,
    /// Deliveries to a node that sent the identical frame at the same
    /// time: the two transmissions are one frame on the wire (no
    /// arbitration can tell them apart), and both complete.
    pub co_transmitted: usize,
}

/// A frame the accounting cannot explain.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum AccountingError {
    /// A node on the bus neither received a completed frame nor signalled an error.
    #[error(
        "frame {frame:?} sent by node {sender} at clock {clock} never reached node {receiver}, which was on the bus and signalled no error"
    )]
    Lost {
        /// The frame.
        frame: CanFrame,
        /// Transmitter.
        sender: usize,
        /// Receiver that missed it.
        receiver: usize,
        /// Clock of the transmitter's completion.
        clock: u64,
    },
    /// A node received a frame nobody sent.
    #[error(
        "node {receiver} received {frame:?} at clock {clock} but no node sent it and no error frame explains it"
    )]
    Phantom {
        /// The frame.
        frame: CanFrame,
        /// Receiver.
        receiver: usize,
        /// Clock of the reception.
        clock: u64,
    },
}

/// A node's oscillator against the bus clock (fractional clock divider).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct NodeClock {
    node_hz: u64,
    bus_hz: u64,
    /// Node clock phase in units of 1 / bus_hz of a node clock.
    phase: u64,
}

impl NodeClock {
    const SAME: NodeClock = NodeClock { node_hz: 1, bus_hz: 1, phase: 0 };

    /// Node clocks due in the next bus clock.
    #[inline]
    fn ticks(&mut self) -> u32 {
        if self.node_hz == self.bus_hz {
            return 1;
        }
        self.phase += self.node_hz;
        let n = self.phase / self.bus_hz;
        self.phase %= self.bus_hz;
        n as u32
    }
}

/// N SJA1000 nodes on one wired-AND bus.
#[derive(Debug)]
pub struct Bus {
    nodes: Vec<Sja1000>,
    tx_delay: Vec<DelayLine>,
    rx_delay: Vec<DelayLine>,
    delays: Vec<u32>,
    /// Each node's own oscillator against the bus clock: (node Hz, bus Hz)
    /// and the phase accumulated so far ([`Bus::set_node_clock`]).
    node_clock: Vec<NodeClock>,
    faults: Vec<Box<dyn FaultInjector>>,
    level: bool,
    clock: u64,
    tracker: Tracker,
    ledger: Vec<Entry>,
    accounting: bool,
    /// Run [`Bus::check_accounting`] when the bus is dropped (see [`Drop`]).
    check_on_drop: bool,
    /// Longest bit time (clocks) the bus has run with: the accounting's
    /// matching window, whatever node 0's timing is when it is checked.
    max_cpb: u64,
    external: bool,
    last_ctx: BusContext,
}

impl Default for Bus {
    fn default() -> Self {
        Bus::new()
    }
}

impl Bus {
    /// An empty bus, accounting on.
    pub fn new() -> Self {
        Bus {
            nodes: Vec::new(),
            tx_delay: Vec::new(),
            rx_delay: Vec::new(),
            delays: Vec::new(),
            node_clock: Vec::new(),
            faults: Vec::new(),
            level: RECESSIVE,
            clock: 0,
            tracker: Tracker {
                record: true,
                ..Tracker::default()
            },
            ledger: Vec::new(),
            accounting: true,
            check_on_drop: true,
            max_cpb: 1,
            external: false,
            last_ctx: BusContext::default(),
        }
    }

    /// Adds a node (configured or not); returns its index.
    pub fn add_node(&mut self, mut node: Sja1000) -> usize {
        let i = self.nodes.len();
        node.set_journal(self.accounting);
        if self.accounting {
            self.ledger.push(Entry {
                clock: self.clock,
                node: i,
                event: NodeEvent::ResetMode(node.in_reset_mode()),
            });
        }
        self.nodes.push(node);
        self.tx_delay.push(DelayLine::new(0));
        self.rx_delay.push(DelayLine::new(0));
        self.delays.push(0);
        self.node_clock.push(NodeClock::SAME);
        i
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// True with no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Node `i`.
    pub fn node(&self, i: usize) -> &Sja1000 {
        &self.nodes[i]
    }

    /// Node `i`, mutable (host accesses).
    pub fn node_mut(&mut self, i: usize) -> &mut Sja1000 {
        &mut self.nodes[i]
    }

    /// All nodes.
    pub fn nodes_mut(&mut self) -> &mut [Sja1000] {
        &mut self.nodes
    }

    /// Propagation delay between node `i` and the bus, in CAN clocks, each
    /// way (a round trip is twice this).
    pub fn set_delay(&mut self, i: usize, clocks: u32) {
        self.tx_delay[i] = DelayLine::new(clocks);
        self.rx_delay[i] = DelayLine::new(clocks);
        self.delays[i] = clocks;
    }

    /// Gives node `i` its own oscillator: `node_hz` against the bus clock's
    /// `bus_hz` (a clock tolerance test: CAN 2.0B section 9 lets each node's
    /// oscillator deviate, resynchronisation keeps them in step). Each bus
    /// clock the node gets `node_hz / bus_hz` clocks on average (0, 1 or 2
    /// in one bus clock, so at most one bus clock of jitter); it sees the
    /// bus level of the bus clock its edge falls in. `node_hz` must be
    /// below twice `bus_hz`; equal rates (the default) change nothing.
    pub fn set_node_clock(&mut self, i: usize, node_hz: u64, bus_hz: u64) {
        assert!(bus_hz > 0 && node_hz > 0 && node_hz < 2 * bus_hz, "node clock {node_hz} Hz against bus {bus_hz} Hz: must be in (0, 2 x bus)");
        self.node_clock[i] = if node_hz == bus_hz { NodeClock::SAME } else { NodeClock { node_hz, bus_hz, phase: 0 } };
    }

    /// Adds a fault injector; they apply in the order added.
    pub fn add_fault(&mut self, f: impl FaultInjector + 'static) {
        self.faults.push(Box::new(f));
    }

    /// Adds an already boxed fault injector (faults built from data).
    pub fn add_fault_boxed(&mut self, f: Box<dyn FaultInjector>) {
        self.faults.push(f);
    }

    /// Removes every fault injector.
    pub fn clear_faults(&mut self) {
        self.faults.clear();
    }

    /// Turns the journal and the accounting check on or off (the
    /// benchmark turns it off; every test keeps it on).
    /// Turning it on after nodes were added records where each node is
    /// now (reset mode, asleep, bus-off), so the check starts from there.
    pub fn set_accounting(&mut self, on: bool) {
        if on && !self.accounting {
            self.ledger = self.node_states();
        }
        self.accounting = on;
        self.tracker.record = on;
        for n in &mut self.nodes {
            n.set_journal(on);
        }
    }

    /// Journal entries stating where every node is now.
    fn node_states(&self) -> Vec<Entry> {
        let mut v = vec![];
        for (r, n) in self.nodes.iter().enumerate() {
            let at = |event| Entry { clock: self.clock, node: r, event };
            v.push(at(NodeEvent::ResetMode(n.in_reset_mode())));
            if n.is_sleeping() {
                v.push(at(NodeEvent::Sleep(true)));
            }
            if n.bus_off() {
                v.push(at(NodeEvent::FaultState(FaultState::BusOff)));
            }
        }
        v
    }

    /// Whether dropping the bus runs the accounting check (default on; see
    /// the [`Drop`] impl). Turn it off only in a test that loses a frame on
    /// purpose and checks [`Bus::check_accounting`] itself.
    pub fn set_check_on_drop(&mut self, on: bool) {
        self.check_on_drop = on;
    }

    /// The current wired-AND level (before faults).
    pub fn level(&self) -> bool {
        self.level
    }

    /// CAN clocks run so far.
    pub fn clocks(&self) -> u64 {
        self.clock
    }

    /// Clocks per bit of the reference timing: the first node out of
    /// reset mode (node 0 unless it is in reset mode, where its BTR may
    /// hold anything, e.g. the reset value after a hardware reset), else
    /// node 0. Found by `fuzz_host`: with node 0 reset to 6 clocks per bit
    /// the frame tracker took another node's ACK bit for a SOF.
    pub fn clocks_per_bit(&self) -> u32 {
        let n = self
            .nodes
            .iter()
            .find(|n| !n.in_reset_mode())
            .or(self.nodes.first());
        n.map_or(1, |n| n.engine().timing().clocks_per_bit())
    }

    /// Bit times run so far (reference timing).
    pub fn bit_times(&self) -> u64 {
        self.clock / self.clocks_per_bit() as u64
    }

    /// Frames seen on the bus so far (SOFs).
    pub fn frames_seen(&self) -> u64 {
        self.tracker.next_frame
    }

    /// The journal of every node, in time order.
    pub fn ledger(&self) -> &[Entry] {
        &self.ledger
    }

    fn context(&self, sub: u32) -> BusContext {
        BusContext {
            clock: self.clock,
            frame: self.tracker.frame,
            frame_bit: match self.tracker.frame {
                Some(_) => {
                    ((self.clock - self.tracker.start) / self.clocks_per_bit() as u64) as u32
                }
                None => 0,
            },
            sub,
            clocks_per_bit: self.clocks_per_bit(),
        }
    }

    /// True when [`Bus::run_bits`] can use the per-bit fast path: every
    /// node has the same timing, no propagation delay, no glitch.
    pub fn fast_path_ok(&self) -> bool {
        let Some(first) = self.nodes.first() else {
            return false;
        };
        let t = first.engine().timing();
        self.nodes.iter().all(|n| n.engine().timing() == t)
            && self.delays.iter().all(|&d| d == 0)
            && self.node_clock.iter().all(|c| c.node_hz == c.bus_hz)
            && self.faults.iter().all(|f| !f.needs_clocks())
    }

    /// One CAN clock for every node; returns the bus level.
    pub fn clock(&mut self) -> bool {
        self.clock_with(RECESSIVE)
    }

    /// One CAN clock with an external participant (a DUT, a CAN agent)
    /// driving `extra_tx`; returns the bus level every node saw before faults.
    pub fn clock_with(&mut self, extra_tx: bool) -> bool {
        if !extra_tx {
            self.external = true;
        }
        let mut level = extra_tx;
        for (i, n) in self.nodes.iter().enumerate() {
            level &= self.tx_delay[i].push(n.tx());
        }
        self.level = level;
        let cpb = self.clocks_per_bit() as u64;
        if self.accounting {
            self.note_timing();
        }
        self.tracker.step(self.clock, level, 1, cpb);
        let sub = ((self.clock - self.tracker.start) % cpb) as u32;
        let ctx = self.context(sub);
        self.last_ctx = ctx;
        for i in 0..self.nodes.len() {
            let mut rx = self.rx_delay[i].push(level);
            for f in &mut self.faults {
                rx = f.apply(&ctx, i, rx);
            }
            for _ in 0..self.node_clock[i].ticks() {
                self.nodes[i].clock(rx);
            }
        }
        self.clock += 1;
        self.collect();
        level
    }

    /// What an external participant receives for the clock just run by
    /// [`Bus::clock_with`]: the bus level through the fault injectors, with
    /// the participant as node index [`Bus::len`] (so `Target::All` and
    /// `Target::Node(bus.len())` reach it).
    pub fn external_rx(&mut self) -> bool {
        self.external_rx_of(self.nodes.len())
    }

    /// [`Bus::external_rx`] for a participant that is node index `me` to
    /// the fault injectors (`me >= len()`: several outside the bus, each
    /// with faults of its own, in the context the nodes had).
    pub fn external_rx_of(&mut self, me: usize) -> bool {
        let ctx = self.last_ctx;
        let mut rx = self.level;
        for f in &mut self.faults {
            rx = f.apply(&ctx, me, rx);
        }
        rx
    }

    /// Folds every node's bit time into the accounting's window (timings
    /// change only through host writes, between run calls).
    fn note_timing(&mut self) {
        for n in &self.nodes {
            self.max_cpb = self.max_cpb.max(n.engine().timing().clocks_per_bit() as u64);
        }
    }

    /// Runs `n` clocks.
    pub fn run_clocks(&mut self, n: u64) {
        self.note_timing();
        for _ in 0..n {
            self.clock();
        }
    }

    /// Runs `n` bit times: on the fast path when [`Bus::fast_path_ok`],
    /// else clock by clock. Do not switch paths in the middle of a frame.
    pub fn run_bits(&mut self, n: u64) {
        if !self.fast_path_ok() {
            self.run_clocks(n * self.clocks_per_bit() as u64);
            return;
        }
        let cpb = self.clocks_per_bit() as u64;
        self.note_timing();
        if self.faults.is_empty() && !self.accounting {
            // The hot loop: no fault to apply, no journal to collect.
            let mut level = self.level;
            self.tracker.set_cpb(cpb);
            for _ in 0..n {
                level = self.nodes.iter().fold(RECESSIVE, |l, n| l & n.tx());
                self.tracker.step_bit(self.clock, level, cpb);
                for node in &mut self.nodes {
                    node.sample_bit(level);
                }
                self.clock += cpb;
            }
            self.level = level;
            return;
        }
        for _ in 0..n {
            self.step_bit(cpb);
        }
    }

    /// Runs bit times until `done(self)` or `max_bits`; returns whether `done` held.
    pub fn run_until(&mut self, max_bits: u64, mut done: impl FnMut(&mut Bus) -> bool) -> bool {
        let fast = self.fast_path_ok();
        let cpb = self.clocks_per_bit() as u64;
        self.note_timing();
        for _ in 0..max_bits {
            if done(self) {
                return true;
            }
            if fast {
                self.step_bit(cpb);
            } else {
                self.run_clocks(cpb);
            }
        }
        done(self)
    }

    /// One bit time on the fast path.
    #[inline]
    fn step_bit(&mut self, cpb: u64) {
        let mut level = RECESSIVE;
        for n in &self.nodes {
            level &= n.tx();
        }
        self.level = level;
        self.tracker.step(self.clock, level, cpb, cpb);
        if self.faults.is_empty() {
            for n in &mut self.nodes {
                n.sample_bit(level);
            }
        } else {
            let ctx = self.context(0);
            for i in 0..self.nodes.len() {
                let mut rx = level;
                for f in &mut self.faults {
                    rx = f.apply(&ctx, i, rx);
                }
                self.nodes[i].sample_bit(rx);
            }
        }
        self.clock += cpb;
        self.collect();
    }

    #[inline]
    fn collect(&mut self) {
        if !self.accounting {
            return;
        }
        for (i, n) in self.nodes.iter_mut().enumerate() {
            if n.journal_pending() {
                let clock = self.clock;
                self.ledger
                    .extend(n.take_journal().into_iter().map(|event| Entry {
                        clock,
                        node: i,
                        event,
                    }));
            }
        }
    }

    /// The accounting check, for a bus whose nodes share
    /// one bit timing (on a bus mixing bit rates, a node reads the others'
    /// frames as noise at its own pace, and what it makes of them is not a
    /// delivery question): every frame a node finished
    /// sending reached every other node that was on the bus (stored,
    /// filtered out, or lost to a flagged overrun) or is explained by an
    /// error frame that node signalled; every frame a node received was
    /// sent by someone (or is a double reception explained by an error
    /// frame, or came from an external participant).
    ///
    /// Its time windows are in the longest bit time the bus has run with
    /// (not node 0's current one: a reset or a BTR write changes that).
    pub fn check_accounting(&self) -> Result<Accounting, AccountingError> {
        let cpb = self
            .nodes
            .iter()
            .map(|n| n.engine().timing().clocks_per_bit() as u64)
            .fold(self.max_cpb, u64::max);
        let max_delay = self.delays.iter().copied().max().unwrap_or(0) as u64 * 2;
        let window = 4 * cpb + max_delay;
        let mut acc = Accounting::default();
        // Journal entries carry the clock at the end of their bit, SOFs the
        // clock at its start: a SOF stamped `t` began after an entry at `t`
        // (the next frame, right after intermission), so it is excluded.
        let frame_start = |t: u64| -> u64 {
            let i = self.tracker.starts.partition_point(|&s| s < t);
            if i == 0 {
                0
            } else {
                self.tracker.starts[i - 1]
            }
        };
        // The ledger is in time order: look only at entries near `t`.
        let near = |t: u64| {
            let lo = self.ledger.partition_point(|x| x.clock + window < t);
            self.ledger[lo..]
                .iter()
                .take_while(move |x| x.clock <= t + window)
        };
        for e in &self.ledger {
            let NodeEvent::Sent(frame) = e.event else {
                continue;
            };
            acc.sent += 1;
            let start = frame_start(e.clock);
            for r in 0..self.nodes.len() {
                if r == e.node {
                    continue;
                }
                acc.deliveries += 1;
                let got = near(e.clock).find(|x| {
                    x.node == r && matches!(x.event, NodeEvent::Received { frame: f, own: false, .. } if f == frame)
                });
                match got.map(|x| &x.event) {
                    Some(NodeEvent::Received { outcome, .. }) => match outcome {
                        RxOutcome::Stored => acc.stored += 1,
                        RxOutcome::Overrun => acc.overruns += 1,
                        RxOutcome::Filtered | RxOutcome::ExtendedInBasicCan => acc.filtered += 1,
                    },
                    _ if near(e.clock).any(|x| x.node == r && x.event == NodeEvent::Sent(frame)) => {
                        acc.co_transmitted += 1
                    }
                    _ if self.off_bus(r, start.saturating_sub(11 * cpb), e.clock) => {
                        acc.off_bus += 1
                    }
                    _ if self.has_error(r, start, e.clock + window) => acc.error_frames += 1,
                    _ => {
                        return Err(AccountingError::Lost {
                            frame,
                            sender: e.node,
                            receiver: r,
                            clock: e.clock,
                        });
                    }
                }
            }
        }
        for e in &self.ledger {
            let NodeEvent::Received {
                frame, own: false, ..
            } = e.event
            else {
                continue;
            };
            let sent = near(e.clock).any(|x| x.node != e.node && x.event == NodeEvent::Sent(frame));
            if sent {
                continue;
            }
            // The sender saw an error in this frame that the receivers did
            // not (an error at its last EOF bit, or an ACK error while error
            // passive: its passive flag is recessive): it retransmits.
            let start = frame_start(e.clock);
            let dup = (0..self.nodes.len())
                .any(|s| s != e.node && self.has_error(s, start, e.clock + window));
            // The sender left the bus (reset mode, sleep, bus-off) before
            // its own last EOF bit: if that was in the ACK delimiter or EOF,
            // the receivers still see the recessive bits of a valid frame
            // (found by fuzz_host: reset mode entered in the ACK field).
            let cut = (0..self.nodes.len())
                .any(|s| s != e.node && self.left_bus(s, start, e.clock + window));
            if e.clock + window > self.clock {
                // The sender completes one bit after the receivers (EOF):
                // the run stopped in between.
                acc.in_flight += 1;
            } else if dup {
                acc.duplicates += 1;
            } else if cut {
                acc.sender_cut_off += 1;
            } else if self.external {
                acc.external += 1;
            } else {
                return Err(AccountingError::Phantom {
                    frame,
                    receiver: e.node,
                    clock: e.clock,
                });
            }
        }
        Ok(acc)
    }

    /// The accounting check, once, at the end of a run: the totals, or the
    /// first frame it cannot explain. The bus is consumed, so its [`Drop`]
    /// check does not run again.
    pub fn finish(mut self) -> Result<Accounting, AccountingError> {
        self.check_on_drop = false;
        self.check_accounting()
    }

    /// Forgets the journal so far (long runs: check, then clear). Node
    /// states are carried over so later checks still know who is off the bus.
    pub fn clear_accounting(&mut self) {
        self.ledger = self.node_states();
        let last = self.tracker.starts.last().copied();
        self.tracker.starts.clear();
        self.tracker.starts.extend(last);
    }

    /// True if node `r` was in reset mode, asleep or bus-off at some time
    /// in `from..=to`, or left one of those states during it.
    fn off_bus(&self, r: usize, from: u64, to: u64) -> bool {
        let (mut reset, mut sleep, mut busoff) = (false, false, false);
        for x in self.ledger.iter().filter(|x| x.node == r) {
            if x.clock > to {
                break;
            }
            match x.event {
                NodeEvent::ResetMode(v) => reset = v,
                NodeEvent::Sleep(v) => sleep = v,
                NodeEvent::FaultState(s) => busoff = s == FaultState::BusOff,
                _ => continue,
            }
            if x.clock >= from {
                return true;
            }
        }
        reset || sleep || busoff
    }

    /// True if node `r` entered reset mode, sleep or bus-off in `from..=to`.
    fn left_bus(&self, r: usize, from: u64, to: u64) -> bool {
        let lo = self.ledger.partition_point(|x| x.clock < from);
        self.ledger[lo..].iter().take_while(|x| x.clock <= to).any(|x| {
            x.node == r
                && matches!(
                    x.event,
                    NodeEvent::ResetMode(true) | NodeEvent::Sleep(true) | NodeEvent::FaultState(FaultState::BusOff)
                )
        })
    }

    fn has_error(&self, r: usize, from: u64, to: u64) -> bool {
        let lo = self.ledger.partition_point(|x| x.clock < from);
        self.ledger[lo..]
            .iter()
            .take_while(|x| x.clock <= to)
            .any(|x| x.node == r && matches!(x.event, NodeEvent::BusError { .. }))
    }
}

/// Every run with the journal on ends with the accounting check: a test cannot forget it. A bus whose accounting is on and that
/// is dropped with a frame the check cannot explain panics with the
/// [`AccountingError`] (unless the thread is already panicking, so the
/// first failure is the one reported). Buses with accounting off (the
/// benchmark, the co-simulation test bench) skip it.
impl Drop for Bus {
    fn drop(&mut self) {
        if !self.accounting || !self.check_on_drop || std::thread::panicking() {
            return;
        }
        if let Err(e) = self.check_accounting() {
            panic!(
                "accounting check when the bus was dropped: {e} \
                 (a test that loses a frame on purpose calls Bus::set_check_on_drop(false))"
            );
        }
    }
}
