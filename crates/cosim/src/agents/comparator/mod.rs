//! The lockstep comparator. The DUT and a reference (the golden model, or
//! the Rust twin of a fixture) get the same host transactions, the
//! reference at the very edge the DUT acknowledged each one, and see the
//! same rx. Compared:
//!
//! - `tx` at every sample point, except within `tx_edge_tolerance` CAN
//!   clocks of a reference tx edge (either side): where an implementation
//!   puts its tx edge within the sync segment is its own business;
//! - every register read, exactly, except SR and IR, whose bits change at
//!   implementation-defined instants: a read of those matches if the
//!   reference held the same value at some CAN clock within
//!   `status_tolerance` clocks before the read (or, for SR, after it);
//! - a start of frame from bus idle may come up to `sof_tolerance` CAN
//!   clocks earlier or later on the DUT: in bus idle nothing synchronises
//!   the bit timers, so where a node starts its SOF is its own; the shadow
//!   model is not on the bus and never hard-synchronises on the DUT's SOF,
//!   so the lag measured there is compensated until the bus is idle again;
//! - `irq_on` and `bus_off_on`, which may differ for at most
//!   `pin_tolerance` CAN clocks in a row.
//!
//! The tolerances are part of the report ([`CompareConfig::describe`]).
//! A divergence halts the comparison; the record keeps the bits before it.
//! The test bench may then hand it to a waiver session (crate `waivers`)
//! and [`Comparator::resume`]: after a waived divergence (skipping the bits
//! the waiver allows), or after an unwaived one in collect mode.

use std::collections::VecDeque;

mod policy;
pub use policy::{ComparatorAgent, Now};

use can_proto::Field;
use diagnose::{Divergence, DivergenceKind};

use crate::types::CanPins;
// The reference side lives in `types` (dut.rs implements it too).
pub use crate::types::{IR_ADDR, RefView, Reference, SR_ADDR};

/// Comparator tolerances.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CompareConfig {
    /// No tx comparison within this many CAN clocks of a reference tx edge.
    pub tx_edge_tolerance: u32,
    /// SR/IR reads match any reference value within this many CAN clocks.
    pub status_tolerance: u32,
    /// irq_on / bus_off_on may differ for this many CAN clocks in a row.
    pub pin_tolerance: u32,
    /// Compare irq_on.
    pub compare_irq: bool,
    /// Compare bus_off_on.
    pub compare_bus_off: bool,
    /// A start of frame from bus idle may come this many CAN clocks apart on
    /// the two sides: in bus idle nothing synchronises the bit timers, so
    /// the phase at which a node starts its SOF is its own (needs a
    /// reference that reports its field).
    pub sof_tolerance: u32,
}

impl Default for CompareConfig {
    fn default() -> Self {
        CompareConfig {
            tx_edge_tolerance: 4,
            status_tolerance: 48,
            pin_tolerance: 48,
            compare_irq: true,
            compare_bus_off: true,
            sof_tolerance: 40,
        }
    }
}

impl CompareConfig {
    /// The tolerances in words, for the report.
    pub fn describe(&self) -> String {
        format!(
            "tx compared at sample points, not within {} CAN clocks of a model tx edge, a start of frame from bus idle may lag by {} CAN clocks; register reads exact except SR/IR \
             (match if the model held that value within {} CAN clocks); irq_on{} / bus_off_on{} may differ for at most {} CAN clocks",
            self.tx_edge_tolerance,
            self.sof_tolerance,
            self.status_tolerance,
            if self.compare_irq {
                ""
            } else {
                " (not compared)"
            },
            if self.compare_bus_off {
                ""
            } else {
                " (not compared)"
            },
            self.pin_tolerance
        )
    }
}

/// Where in the run a comparison happens.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stamp {
    /// Time, ps.
    pub t_ps: u64,
    /// Bit index.
    pub bit: u64,
    /// Field (reference's, else decoder's).
    pub field: Option<Field>,
    /// Frame number.
    pub frame: Option<u32>,
}

/// A sample point waiting to reach the middle of the tx window.
#[derive(Clone, Copy, Debug)]
struct TxSample {
    /// Its position in the window's push sequence.
    index: u64,
    /// Inside a start-of-frame grace window: not compared.
    excused: bool,
    ref_tx: bool,
    dut_tx: bool,
    sample: bool,
    stamp: Stamp,
}

#[derive(Clone, Debug)]
struct PendingRead {
    addr: u8,
    dut: u8,
    model: u8,
    clocks_left: u32,
    stamp: Stamp,
}

/// What a collect-mode [`Comparator::resume`] stops re-reporting after a
/// divergence.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Latch {
    /// tx: the rest of this frame (bus frame number; `None`: no frame yet,
    /// until tx agrees again), and the same difference in later frames.
    Tx(Option<u32>, DiffKey),
    /// A register read: the same address with the same DUT and model values.
    Read(DiffKey),
    /// irq_on, until the pins agree.
    Irq,
    /// bus_off_on, until the pins agree.
    BusOff,
}

/// One distinct difference, as collect mode lists it once.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum DiffKey {
    /// tx at a sample point: the field, the model's and the DUT's level.
    Tx { field: Option<Field>, model: bool, dut: bool },
    /// A register read: address, DUT value, model value.
    Read { addr: u8, dut: u8, model: u8 },
}

impl std::fmt::Display for DiffKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let lvl = |b: bool| if b { "recessive" } else { "dominant" };
        match *self {
            DiffKey::Tx { field, model, dut } => write!(
                f,
                "tx in {} (model {}, DUT {})",
                field.map(|x| x.to_string()).unwrap_or_else(|| "unknown field".into()),
                lvl(model),
                lvl(dut)
            ),
            DiffKey::Read { addr, dut, model } => write!(
                f,
                "read of {} (DUT 0x{dut:02X}, model 0x{model:02X})",
                reg_label(addr)
            ),
        }
    }
}

/// The differences listed so far in collect mode, with how often each
/// came again.
#[derive(Debug, Default)]
struct Listed {
    keys: Vec<(DiffKey, u64)>,
}

impl Listed {
    fn add(&mut self, k: DiffKey) {
        if !self.keys.iter().any(|e| e.0 == k) {
            self.keys.push((k, 0));
        }
    }

    /// True, and counted, if `k` was listed.
    fn repeat(&mut self, k: DiffKey) -> bool {
        match self.keys.iter_mut().find(|e| e.0 == k) {
            Some(e) => {
                e.1 += 1;
                true
            }
            None => false,
        }
    }
}

/// The comparator's state.
pub struct Comparator {
    cfg: CompareConfig,
    /// Clocks pushed into the tx window and the tx histories (every clock
    /// compared while not halted). The window is the last `2 * tol + 1`
    /// pushes; only what its check needs is kept: the sample points not
    /// yet in the middle, and where the (delayed) reference tx last changed.
    pushed: u64,
    samples: VecDeque<TxSample>,
    /// Push index of the last change of the window's reference tx.
    ref_changed_at: u64,
    last_win_ref_tx: bool,
    /// Status history for tolerant reads: the last `status_tolerance + 1`
    /// values of SR and IR, kept as runs (value, index of its first clock
    /// in `status_pushed`).
    status_pushed: u64,
    sr_hist: VecDeque<(u8, u64)>,
    ir_hist: VecDeque<(u8, u64)>,
    prev_ref_tx: bool,
    prev_dut_tx: bool,
    prev_idle: bool,
    sof_grace: u32,
    grace_count: u32,
    grace_by_ref: bool,
    ref_off: usize,
    dut_off: usize,
    /// Reference tx (bit 0) and DUT tx (bit 1) of the last
    /// `sof_tolerance + 1` clocks.
    tx_hist: TxRing,
    /// The newest SR and IR of the histories (256: none yet).
    sr_last: u16,
    ir_last: u16,
    irq_bad: u32,
    irq_since: Stamp,
    bus_bad: u32,
    bus_since: Stamp,
    pending: Vec<PendingRead>,
    divergence: Option<Divergence>,
    found: VecDeque<Divergence>,
    halted: bool,
    last_kind: Option<DivergenceKind>,
    /// The latch of the divergence last found or taken (what `resume` latches).
    latch_info: Option<Latch>,
    /// The latches of `found`, in step with it.
    found_latch: VecDeque<Latch>,
    /// Frame in which tx was latched (see [`Latch::Tx`]).
    tx_latch_frame: Option<u32>,
    /// Differences listed in collect mode, with their repeats.
    listed: Listed,
    skip_until_bit: u64,
    tx_latched: bool,
    irq_latched: bool,
    bus_latched: bool,
    /// Reads and sample points compared (for the report).
    pub compared_bits: u64,
    /// Register reads compared.
    pub compared_reads: u64,
    /// Reads accepted only thanks to the status tolerance.
    pub tolerated_reads: u64,
    /// `status_pushed` when the reference took the read now under way, if
    /// it took it before the DUT's ack ([`Comparator::reference_read_taken`]).
    read_taken_at: Option<u64>,
    /// The last read, if the status tolerance accepted it (DUT and model
    /// differed at the read): see [`Comparator::hold_tolerated_read`].
    tolerated_read: Option<PendingRead>,
    /// Differences not listed again because the same one was listed before
    /// (collect mode): reads, and tx differences in later frames.
    pub repeated: u64,
    /// Mismatching sample points not listed because an earlier tx
    /// difference of the same frame was (collect mode).
    pub cascade: u64,
}

impl Comparator {
    /// A comparator with these tolerances.
    pub fn new(cfg: CompareConfig) -> Comparator {
        Comparator {
            cfg,
            pushed: 0,
            samples: VecDeque::new(),
            ref_changed_at: 0,
            last_win_ref_tx: true,
            status_pushed: 0,
            sr_hist: VecDeque::new(),
            ir_hist: VecDeque::new(),
            prev_ref_tx: true,
            prev_dut_tx: true,
            prev_idle: false,
            sof_grace: 0,
            grace_count: 0,
            grace_by_ref: false,
            ref_off: 0,
            dut_off: 0,
            tx_hist: TxRing::new(cfg.sof_tolerance as u64 + 1),
            sr_last: 256,
            ir_last: 256,
            irq_bad: 0,
            irq_since: Stamp::default(),
            bus_bad: 0,
            bus_since: Stamp::default(),
            pending: Vec::new(),
            divergence: None,
            found: VecDeque::new(),
            halted: false,
            last_kind: None,
            latch_info: None,
            found_latch: VecDeque::new(),
            tx_latch_frame: None,
            listed: Listed::default(),
            skip_until_bit: 0,
            tx_latched: false,
            irq_latched: false,
            bus_latched: false,
            compared_bits: 0,
            compared_reads: 0,
            tolerated_reads: 0,
            read_taken_at: None,
            tolerated_read: None,
            repeated: 0,
            cascade: 0,
        }
    }

    /// The tolerances.
    pub fn config(&self) -> &CompareConfig {
        &self.cfg
    }

    /// The first divergence, once found.
    pub fn divergence(&self) -> Option<&Divergence> {
        self.divergence.as_ref()
    }

    /// The next divergence not yet taken (each divergence once, in order).
    pub fn take_divergence(&mut self) -> Option<Divergence> {
        let d = self.found.pop_front();
        if d.is_some() {
            self.latch_info = self.found_latch.pop_front();
        }
        d
    }

    /// The register read of the divergence last taken, if it was one: its
    /// address and the DUT's value (what a collect-mode resync adopts).
    pub fn taken_read(&self) -> Option<(u8, u8)> {
        match self.latch_info {
            Some(Latch::Read(DiffKey::Read { addr, dut, .. })) => Some((addr, dut)),
            _ => None,
        }
    }

    /// True while a divergence halts the comparison (until [`Comparator::resume`]).
    pub fn halted(&self) -> bool {
        self.halted
    }

    /// Compares again after the last divergence was handled.
    ///
    /// `skip_to_bit`: no tx or pin comparison before this bit index (a
    /// waiver's `SkipBits(n)` after a divergence at bit `b` gives `b + n`).
    /// `latch`: the divergence (the one last taken) was not waived (collect
    /// mode): the same difference is not listed again while it lasts, so a
    /// lasting deviation counts once: tx for the rest of its frame (until
    /// tx agrees at a sample point of a later frame; before the first
    /// frame, until it agrees), irq/bus-off until the pins agree, a
    /// register read while the same address reads the same DUT and model
    /// values again (any other value, or an agreeing read, ends it: the
    /// next read is compared afresh). Repeats are counted in `repeated`.
    /// Not latched after a waived one, so a waiver's bounds see every bit
    /// of the deviation.
    pub fn resume(&mut self, skip_to_bit: Option<u64>, latch: bool) {
        self.halted = false;
        if let Some(b) = skip_to_bit {
            self.skip_until_bit = self.skip_until_bit.max(b);
        }
        if latch {
            match self.latch_info {
                Some(Latch::Tx(frame, key)) => {
                    self.tx_latched = true;
                    self.tx_latch_frame = frame;
                    // Only a difference whose field is known is one to recognise again.
                    if matches!(key, DiffKey::Tx { field: Some(_), .. }) {
                        self.listed.add(key);
                    }
                }
                Some(Latch::Irq) => self.irq_latched = true,
                Some(Latch::BusOff) => self.bus_latched = true,
                Some(Latch::Read(key)) => self.listed.add(key),
                None => {}
            }
        }
        self.irq_bad = 0;
        self.bus_bad = 0;
    }

    fn diverge(
        &mut self,
        kind: DivergenceKind,
        s: Stamp,
        register: Option<String>,
        expected: u32,
        seen: u32,
        context: String,
    ) {
        let d = Divergence {
            kind,
            time_ps: s.t_ps,
            bit: Some(s.bit),
            frame: s.frame,
            field: s.field,
            register,
            expected,
            seen,
            context: format!("{context}; tolerances: {}", self.cfg.describe()),
        };
        if self.divergence.is_none() {
            self.divergence = Some(d.clone());
        }
        self.found.push_back(d);
        self.halted = true;
        self.last_kind = Some(kind);
        let latch = match kind {
            DivergenceKind::Irq => Some(Latch::Irq),
            DivergenceKind::BusOff => Some(Latch::BusOff),
            DivergenceKind::RegisterRead => None,
            _ => Some(Latch::Tx(
                s.frame,
                DiffKey::Tx {
                    field: s.field,
                    model: expected != 0,
                    dut: seen != 0,
                },
            )),
        };
        if let Some(l) = latch {
            self.found_latch.push_back(l);
            self.latch_info = Some(l);
        }
    }

    /// A register read divergence (latched by its address and values).
    fn diverge_read(&mut self, s: Stamp, addr: u8, dut: u8, model: u8, label: String, context: String) {
        self.diverge(DivergenceKind::RegisterRead, s, Some(label), model as u32, dut as u32, context);
        let l = Latch::Read(DiffKey::Read { addr, dut, model });
        self.found_latch.push_back(l);
        self.latch_info = Some(l);
    }

    /// Was this read difference listed already (a repeat, counted, not listed)?
    fn read_repeats(&mut self, addr: u8, dut: u8, model: u8) -> bool {
        let r = self.listed.repeat(DiffKey::Read { addr, dut, model });
        self.repeated += r as u64;
        r
    }


    /// One CAN clock, after both sides were clocked: `sample` says whether
    /// it is a sample point; `sr`/`ir` are the reference's peeks.
    #[inline]
    pub fn can_clock(
        &mut self,
        stamp: Stamp,
        sample: bool,
        reference: &CanPins,
        dut: &CanPins,
        sr: u8,
        ir: u8,
    ) {
        if self.halted {
            return;
        }
        let skipping = stamp.bit < self.skip_until_bit;
        // Start of frame from bus idle: either side may go first, and the
        // shadow model never hard-synchronises on the DUT's SOF (it is not
        // on the bus), so the lag measured at the SOF is kept for the whole
        // frame: the earlier side's tx is delayed by it before comparing.
        let idle_now = matches!(
            stamp.field,
            Some(Field::BusIdle | Field::Intermission | Field::SuspendTransmission)
        );
        if !sample
            && self.samples.is_empty()
            && self.pending.is_empty()
            && self.sof_grace == 0
            && (self.ref_off | self.dut_off) == 0
            && reference.tx == self.prev_ref_tx
            && reference.tx == self.last_win_ref_tx
            && dut.tx == self.prev_dut_tx
            && sr as u16 == self.sr_last
            && ir as u16 == self.ir_last
            && reference.irq_n == dut.irq_n
            && reference.bus_on == dut.bus_on
        {
            // Most clocks: the same tx, status and agreeing pins as the last
            // one, no sample point in the window, no read waiting, no start
            // of frame being excused. What the general path below would do
            // then, in short: no tx edge (so no start of frame, and the
            // offsets stay 0), no window change to check, no new status run,
            // the pins agree.
            let pushed = self.pushed;
            self.pushed += 1;
            self.tx_hist
                .push(pushed, reference.tx as u8 | (dut.tx as u8) << 1);
            self.prev_idle = idle_now;
            self.status_pushed += 1;
            self.irq_latched = false;
            self.bus_latched = false;
            if !skipping {
                if self.cfg.compare_irq {
                    self.irq_bad = 0;
                }
                if self.cfg.compare_bus_off {
                    self.bus_bad = 0;
                }
            }
            return;
        }
        self.can_clock_general(stamp, sample, reference, dut, sr, ir);
    }

    /// [`Comparator::can_clock`] on the clocks its short path does not
    /// take (not halted). Out of line: the short path inlined into the
    /// test bench's per-clock loop stays small.
    #[inline(never)]
    fn can_clock_general(
        &mut self,
        stamp: Stamp,
        sample: bool,
        reference: &CanPins,
        dut: &CanPins,
        sr: u8,
        ir: u8,
    ) {
        let skipping = stamp.bit < self.skip_until_bit;
        // tx with an edge-tolerance window centred on the checked clock.
        let tol = self.cfg.tx_edge_tolerance as usize;
        // Start of frame from bus idle: see `can_clock`.
        let idle_now = matches!(
            stamp.field,
            Some(Field::BusIdle | Field::Intermission | Field::SuspendTransmission)
        );
        let pushed = self.pushed;
        self.pushed += 1;
        self.tx_hist
            .push(pushed, reference.tx as u8 | (dut.tx as u8) << 1);
        if self.sof_grace > 0 {
            self.grace_count += 1;
            if reference.tx == dut.tx {
                self.sof_grace = 0;
                if !reference.tx {
                    if self.grace_by_ref {
                        self.ref_off = self.grace_count as usize;
                    } else {
                        self.dut_off = self.grace_count as usize;
                    }
                }
            } else {
                self.sof_grace -= 1;
            }
        } else {
            let sof_edge = (self.prev_ref_tx && !reference.tx) || (self.prev_dut_tx && !dut.tx);
            if sof_edge
                && (self.prev_idle || stamp.field == Some(Field::Sof))
                && reference.tx != dut.tx
                && self.cfg.sof_tolerance > 0
            {
                self.sof_grace = self.cfg.sof_tolerance;
                self.grace_count = 0;
                self.grace_by_ref = !reference.tx;
                self.ref_off = 0;
                self.dut_off = 0;
            } else if idle_now && reference.tx && dut.tx {
                self.ref_off = 0;
                self.dut_off = 0;
            }
        }
        let excused = self.sof_grace > 0;
        self.prev_ref_tx = reference.tx;
        self.prev_dut_tx = dut.tx;
        self.prev_idle = idle_now;
        // The tx histories hold the last `sof_tolerance + 1` clocks.
        let n = self.pushed.min(self.cfg.sof_tolerance as u64 + 1);
        let ref_tx = if self.ref_off == 0 {
            reference.tx
        } else {
            self.tx_hist.back(pushed, (self.ref_off as u64).min(n - 1)) & 1 != 0
        };
        let dut_tx = if self.dut_off == 0 {
            dut.tx
        } else {
            self.tx_hist.back(pushed, (self.dut_off as u64).min(n - 1)) & 2 != 0
        };
        // The window of the last 2 * tol + 1 clocks, centred on the checked
        // one: it is stable when the reference tx did not change after its
        // oldest clock.
        if pushed > 0 && ref_tx != self.last_win_ref_tx {
            self.ref_changed_at = pushed;
        }
        self.last_win_ref_tx = ref_tx;
        if sample {
            self.samples.push_back(TxSample {
                index: pushed,
                excused,
                ref_tx,
                dut_tx,
                sample,
                stamp,
            });
        }
        let width = 2 * tol as u64;
        if pushed >= width && !self.samples.is_empty() {
            let mid_index = pushed - tol as u64;
            // Sample points before the first full window are never checked.
            while self.samples.front().is_some_and(|m| m.index < mid_index) {
                self.samples.pop_front();
            }
            if self.samples.front().is_some_and(|m| m.index == mid_index) {
                let mid = self.samples.pop_front().expect("front checked above");
                if mid.sample && !mid.excused && mid.stamp.bit >= self.skip_until_bit {
                    let stable = self.ref_changed_at <= pushed - width;
                    if stable {
                        self.compared_bits += 1;
                        if self.tx_latched
                            && mid.dut_tx == mid.ref_tx
                            && (self.tx_latch_frame.is_none() || mid.stamp.frame != self.tx_latch_frame)
                        {
                            self.tx_latched = false;
                        }
                        let key = DiffKey::Tx {
                            field: mid.stamp.field,
                            model: mid.ref_tx,
                            dut: mid.dut_tx,
                        };
                        if mid.dut_tx != mid.ref_tx && self.tx_latched {
                            self.cascade += 1;
                        } else if mid.dut_tx != mid.ref_tx && self.listed.repeat(key) {
                            // Listed before, in an earlier frame: latch this frame too.
                            self.repeated += 1;
                            self.tx_latched = true;
                            self.tx_latch_frame = mid.stamp.frame;
                        } else if mid.dut_tx != mid.ref_tx {
                            let lvl = |b: bool| if b { "recessive" } else { "dominant" };
                            self.diverge(
                                DivergenceKind::TxBit,
                                mid.stamp,
                                None,
                                mid.ref_tx as u32,
                                mid.dut_tx as u32,
                                format!(
                                    "at the sample point the model drives {} and the DUT's tx_o is {}",
                                    lvl(mid.ref_tx),
                                    lvl(mid.dut_tx)
                                ),
                            );
                        }
                    }
                }
            }
        }
        // Status history for tolerant reads (runs of equal values).
        let at = self.status_pushed;
        self.status_pushed += 1;
        if sr as u16 != self.sr_last {
            self.sr_last = sr as u16;
            self.sr_hist.push_back((sr, at));
            prune_runs(
                &mut self.sr_hist,
                self.status_pushed,
                self.cfg.status_tolerance,
            );
        }
        if ir as u16 != self.ir_last {
            self.ir_last = ir as u16;
            self.ir_hist.push_back((ir, at));
            prune_runs(
                &mut self.ir_hist,
                self.status_pushed,
                self.cfg.status_tolerance,
            );
        }
        // Pending SR reads: look forward.
        let mut k = 0;
        while k < self.pending.len() {
            let p = &mut self.pending[k];
            if p.addr == SR_ADDR && sr == p.dut {
                self.tolerated_reads += 1;
                let p = self.pending.swap_remove(k);
                self.tolerated_read = Some(p);
                continue;
            }
            if p.clocks_left == 0 {
                let p = self.pending.swap_remove(k);
                if !self.read_repeats(p.addr, p.dut, p.model) {
                    self.diverge_read(
                        p.stamp,
                        p.addr,
                        p.dut,
                        p.model,
                        reg_label(p.addr),
                        format!(
                            "read of address {} returned 0x{:02X}, the model 0x{:02X}",
                            p.addr, p.dut, p.model
                        ),
                    );
                }
                continue;
            }
            p.clocks_left -= 1;
            k += 1;
        }
        // Pins: a mismatch may last pin_tolerance clocks.
        if self.irq_latched && reference.irq_n == dut.irq_n {
            self.irq_latched = false;
        }
        if self.bus_latched && reference.bus_on == dut.bus_on {
            self.bus_latched = false;
        }
        if self.cfg.compare_irq && !skipping && !self.irq_latched {
            if reference.irq_n != dut.irq_n {
                if self.irq_bad == 0 {
                    self.irq_since = stamp;
                }
                self.irq_bad += 1;
                if self.irq_bad > self.cfg.pin_tolerance {
                    let s = self.irq_since;
                    self.diverge(
                        DivergenceKind::Irq,
                        s,
                        None,
                        reference.irq_n as u32,
                        dut.irq_n as u32,
                        format!(
                            "irq_on (active low) differs for more than {} CAN clocks",
                            self.cfg.pin_tolerance
                        ),
                    );
                }
            } else {
                self.irq_bad = 0;
            }
        }
        if self.cfg.compare_bus_off && !skipping && !self.bus_latched {
            if reference.bus_on != dut.bus_on {
                if self.bus_bad == 0 {
                    self.bus_since = stamp;
                }
                self.bus_bad += 1;
                if self.bus_bad > self.cfg.pin_tolerance {
                    let s = self.bus_since;
                    self.diverge(
                        DivergenceKind::BusOff,
                        s,
                        None,
                        reference.bus_on as u32,
                        dut.bus_on as u32,
                        format!(
                            "bus_off_on (high = on the bus) differs for more than {} CAN clocks",
                            self.cfg.pin_tolerance
                        ),
                    );
                }
            } else {
                self.bus_bad = 0;
            }
        }
    }

    /// A register read completed on both sides: `dut` from the DUT, `model`
    /// from the reference at the same edge.
    pub fn read(&mut self, stamp: Stamp, addr: u8, dut: u8, model: u8, name: Option<String>) {
        let taken_at = self.read_taken_at.take();
        self.tolerated_read = None;
        if self.halted {
            return;
        }
        self.compared_reads += 1;
        if dut == model {
            return;
        }
        let (pushed, tol) = (self.status_pushed, self.cfg.status_tolerance);
        let hist = match addr {
            SR_ADDR => Some(&mut self.sr_hist),
            IR_ADDR => Some(&mut self.ir_hist),
            _ => None,
        };
        // Reading IR clears its flags: once the reference has taken this
        // read, its IR is the value after the read, which the DUT's read
        // cannot return. Only values the reference held before it count.
        let before = match taken_at {
            Some(t) if addr == IR_ADDR => t,
            _ => u64::MAX,
        };
        if let Some(h) = hist {
            prune_runs(h, pushed, tol);
            if h.iter().any(|v| v.0 == dut && v.1 < before) {
                self.tolerated_reads += 1;
                self.tolerated_read = Some(PendingRead { addr, dut, model, clocks_left: 0, stamp });
                return;
            }
            if addr == SR_ADDR && self.cfg.status_tolerance > 0 {
                self.pending.push(PendingRead {
                    addr,
                    dut,
                    model,
                    clocks_left: self.cfg.status_tolerance,
                    stamp,
                });
                return;
            }
        }
        if self.read_repeats(addr, dut, model) {
            return;
        }
        let label = name.unwrap_or_else(|| reg_label(addr));
        let context = format!(
            "read of {label} (address {addr}) returned 0x{dut:02X}, the model 0x{model:02X}"
        );
        self.diverge_read(stamp, addr, dut, model, label, context);
    }

    /// The reference has just taken the read that the DUT will complete
    /// next (it takes accesses when the DUT's CAN side does, before the
    /// ack): from here on its IR is the value after that read.
    pub fn reference_read_taken(&mut self) {
        self.read_taken_at = Some(self.status_pushed);
    }

    /// A scenario expectation `value & mask == expected & mask` failed on
    /// the last read, of `addr`, which returned `dut`, while the model's
    /// value meets it, and the comparator accepted that read only because
    /// the model held the DUT's value within the status tolerance. The
    /// tolerance excuses *when* a status bit changes; the scenario has put
    /// its read where the value must hold, and the model (and a datasheet
    /// core, whatever its latency within the tolerance) meets it there. So
    /// the read is a difference after all: reported as a divergence (a
    /// waiver may take it, with its clause). Returns whether it did.
    pub fn hold_tolerated_read(&mut self, addr: u8, dut: u8, mask: u8, expected: u8) -> bool {
        let Some(p) = self.tolerated_read.take() else { return false };
        if self.halted || p.addr != addr || p.dut != dut || p.model & mask != expected & mask || dut & mask == expected & mask {
            return false;
        }
        self.tolerated_reads -= 1;
        let context = format!(
            "read of {} (address {addr}) returned 0x{dut:02X}, the model 0x{:02X}: the model held 0x{dut:02X} within the {}-clock status tolerance, but the scenario's expectation at this read (0x{:02X} under mask 0x{mask:02X}) holds for the model's value, not the DUT's",
            reg_label(addr),
            p.model,
            self.cfg.status_tolerance,
            expected & mask
        );
        self.diverge_read(p.stamp, addr, dut, p.model, reg_label(addr), context);
        true
    }

    /// Reads still waiting for their tolerance window to close.
    pub fn pending_reads(&self) -> usize {
        self.pending.len()
    }

    /// Collect mode: each listed difference that came again, with how
    /// often (for the report).
    pub fn repeats(&self) -> Vec<String> {
        self.listed
            .keys
            .iter()
            .filter(|e| e.1 > 0)
            .map(|(k, n)| format!("{k}: {n} more time(s)"))
            .collect()
    }

    /// CAN clocks still needed to decide every comparison already under
    /// way: an SR read waiting for its look-ahead window, a pin mismatch
    /// within its tolerance, a sample point not yet in the middle of its tx
    /// window. A run must not end before them, or what the host read last
    /// goes uncompared ([`crate::Testbench::settle`]). 0 when halted.
    /// CAN clocks until every read still within its look-ahead window is
    /// decided (0: none open).
    pub fn open_read_clocks(&self) -> u32 {
        if self.halted {
            return 0;
        }
        self.pending.iter().map(|p| p.clocks_left + 1).max().unwrap_or(0)
    }

    /// CAN clocks until every open comparison is decided (0: none open).
    pub fn open_clocks(&self) -> u32 {
        if self.halted {
            return 0;
        }
        let reads = self.pending.iter().map(|p| p.clocks_left + 1).max().unwrap_or(0);
        let pin = |bad: u32| {
            if bad > 0 {
                (self.cfg.pin_tolerance + 1).saturating_sub(bad)
            } else {
                0
            }
        };
        let tx = if self.samples.is_empty() {
            0
        } else {
            2 * self.cfg.tx_edge_tolerance + 1
        };
        reads.max(pin(self.irq_bad)).max(pin(self.bus_bad)).max(tx)
    }
}

/// Drops the runs that ended before the last `tolerance + 1` of `pushed`
/// clocks (a run ends where the next one starts; the last one is current).
#[inline]
fn prune_runs(h: &mut VecDeque<(u8, u64)>, pushed: u64, tolerance: u32) {
    let first = pushed.saturating_sub(tolerance as u64 + 1);
    while h.len() >= 2 && h[1].1 <= first {
        h.pop_front();
    }
}

/// The last `cap` values pushed (a byte each), indexed back from the
/// newest. Grows to the next power of two above `cap` only as values come,
/// like the deques it replaces, so a huge tolerance costs no memory up front.
struct TxRing {
    buf: Vec<u8>,
    /// `buf.len() - 1` (a power of two minus one once anything was pushed).
    mask: u64,
    size: u64,
    /// `buf` has reached `size`: positions wrap.
    full: bool,
}

impl TxRing {
    fn new(cap: u64) -> TxRing {
        TxRing {
            buf: Vec::new(),
            mask: 0,
            size: cap.max(1).next_power_of_two(),
            full: false,
        }
    }

    /// Stores push number `index` (0, 1, 2, ...: every push, in order).
    #[inline(always)]
    fn push(&mut self, index: u64, v: u8) {
        if !self.full && index >= self.buf.len() as u64 {
            self.grow();
        }
        self.buf[(index & self.mask) as usize] = v;
    }

    /// Doubles the buffer (up to `size`): rare, kept out of `push`'s way.
    /// Not wrapped yet, so positions are indices and growing keeps them.
    #[cold]
    #[inline(never)]
    fn grow(&mut self) {
        let len = self.buf.len() as u64;
        let new_len = (len * 2).max(64).min(self.size);
        self.buf.resize(new_len as usize, 0);
        self.mask = new_len - 1;
        self.full = new_len == self.size;
    }

    /// The value pushed `k` pushes before push number `newest` (`k` below
    /// `cap` and at most `newest`).
    #[inline]
    fn back(&self, newest: u64, k: u64) -> u8 {
        self.buf[((newest - k) & self.mask) as usize]
    }
}

fn reg_label(addr: u8) -> String {
    match addr {
        SR_ADDR => "SR".into(),
        IR_ADDR => "IR".into(),
        a => format!("address {a}"),
    }
}

/// The comparator as it was before its per-clock work was made cheaper
/// (a deque entry per clock for the tx window, the tx histories and the
/// status history): the differential test below checks that the current
/// one reaches exactly the same verdicts.
#[cfg(test)]
#[allow(dead_code, missing_docs)]
mod before {
    use std::collections::VecDeque;

    use can_proto::Field;
    use diagnose::{Divergence, DivergenceKind};

    use super::{CompareConfig, DiffKey, IR_ADDR, Latch, Listed, SR_ADDR, Stamp, reg_label};
    use crate::types::CanPins;

    #[derive(Clone, Copy, Debug)]
    struct OldTxSample {
        /// Inside a start-of-frame grace window: not compared.
        excused: bool,
        ref_tx: bool,
        dut_tx: bool,
        sample: bool,
        stamp: Stamp,
    }

    struct OldPendingRead {
        addr: u8,
        dut: u8,
        model: u8,
        clocks_left: u32,
        stamp: Stamp,
    }

    /// The comparator's state.
    pub struct OldComparator {
        cfg: CompareConfig,
        window: VecDeque<OldTxSample>,
        sr_hist: VecDeque<u8>,
        ir_hist: VecDeque<u8>,
        prev_ref_tx: bool,
        prev_dut_tx: bool,
        prev_idle: bool,
        sof_grace: u32,
        grace_count: u32,
        grace_by_ref: bool,
        ref_off: usize,
        dut_off: usize,
        ref_hist: VecDeque<bool>,
        dut_hist: VecDeque<bool>,
        irq_bad: u32,
        irq_since: Stamp,
        bus_bad: u32,
        bus_since: Stamp,
        pending: Vec<OldPendingRead>,
        divergence: Option<Divergence>,
        found: VecDeque<Divergence>,
        halted: bool,
        last_kind: Option<DivergenceKind>,
        latch_info: Option<Latch>,
        found_latch: VecDeque<Latch>,
        tx_latch_frame: Option<u32>,
        listed: Listed,
        skip_until_bit: u64,
        tx_latched: bool,
        irq_latched: bool,
        bus_latched: bool,
        /// Reads and sample points compared (for the report).
        pub compared_bits: u64,
        /// Register reads compared.
        pub compared_reads: u64,
        /// Reads accepted only thanks to the status tolerance.
        pub tolerated_reads: u64,
        pub repeated: u64,
        pub cascade: u64,
    }

    impl OldComparator {
        /// A comparator with these tolerances.
        pub fn new(cfg: CompareConfig) -> OldComparator {
            OldComparator {
                cfg,
                window: VecDeque::with_capacity(2 * cfg.tx_edge_tolerance as usize + 2),
                sr_hist: VecDeque::new(),
                ir_hist: VecDeque::new(),
                prev_ref_tx: true,
                prev_dut_tx: true,
                prev_idle: false,
                sof_grace: 0,
                grace_count: 0,
                grace_by_ref: false,
                ref_off: 0,
                dut_off: 0,
                ref_hist: VecDeque::new(),
                dut_hist: VecDeque::new(),
                irq_bad: 0,
                irq_since: Stamp::default(),
                bus_bad: 0,
                bus_since: Stamp::default(),
                pending: Vec::new(),
                divergence: None,
                found: VecDeque::new(),
                halted: false,
                last_kind: None,
                latch_info: None,
                found_latch: VecDeque::new(),
                tx_latch_frame: None,
                listed: Listed::default(),
                skip_until_bit: 0,
                tx_latched: false,
                irq_latched: false,
                bus_latched: false,
                compared_bits: 0,
                compared_reads: 0,
                tolerated_reads: 0,
                repeated: 0,
                cascade: 0,
            }
        }

        /// The tolerances.
        pub fn config(&self) -> &CompareConfig {
            &self.cfg
        }

        /// The first divergence, once found.
        pub fn divergence(&self) -> Option<&Divergence> {
            self.divergence.as_ref()
        }

        /// The next divergence not yet taken (each divergence once, in order).
        pub fn take_divergence(&mut self) -> Option<Divergence> {
            let d = self.found.pop_front();
            if d.is_some() {
                self.latch_info = self.found_latch.pop_front();
            }
            d
        }

        /// True while a divergence halts the comparison (until [`Comparator::resume`]).
        pub fn halted(&self) -> bool {
            self.halted
        }

        /// Compares again after the last divergence was handled.
        ///
        /// `skip_to_bit`: no tx or pin comparison before this bit index (a
        /// waiver's `SkipBits(n)` after a divergence at bit `b` gives `b + n`).
        /// `latch`: the divergence (the one last taken) was not waived (collect
        /// mode): the same difference is not listed again while it lasts, so a
        /// lasting deviation counts once: tx for the rest of its frame (until
        /// tx agrees at a sample point of a later frame; before the first
        /// frame, until it agrees), irq/bus-off until the pins agree, a
        /// register read while the same address reads the same DUT and model
        /// values again (any other value, or an agreeing read, ends it: the
        /// next read is compared afresh). Repeats are counted in `repeated`.
        /// Not latched after a waived one, so a waiver's bounds see every bit
        /// of the deviation.
        pub fn resume(&mut self, skip_to_bit: Option<u64>, latch: bool) {
            self.halted = false;
            if let Some(b) = skip_to_bit {
                self.skip_until_bit = self.skip_until_bit.max(b);
            }
            if latch {
                match self.latch_info {
                    Some(Latch::Tx(frame, key)) => {
                        self.tx_latched = true;
                        self.tx_latch_frame = frame;
                        // Only a difference whose field is known is one to recognise again.
                        if matches!(key, DiffKey::Tx { field: Some(_), .. }) {
                            self.listed.add(key);
                        }
                    }
                    Some(Latch::Irq) => self.irq_latched = true,
                    Some(Latch::BusOff) => self.bus_latched = true,
                    Some(Latch::Read(key)) => self.listed.add(key),
                    None => {}
                }
            }
            self.irq_bad = 0;
            self.bus_bad = 0;
        }

        fn diverge(
            &mut self,
            kind: DivergenceKind,
            s: Stamp,
            register: Option<String>,
            expected: u32,
            seen: u32,
            context: String,
        ) {
            let d = Divergence {
                kind,
                time_ps: s.t_ps,
                bit: Some(s.bit),
                frame: s.frame,
                field: s.field,
                register,
                expected,
                seen,
                context: format!("{context}; tolerances: {}", self.cfg.describe()),
            };
            if self.divergence.is_none() {
                self.divergence = Some(d.clone());
            }
            self.found.push_back(d);
            self.halted = true;
            self.last_kind = Some(kind);
            let latch = match kind {
                DivergenceKind::Irq => Some(Latch::Irq),
                DivergenceKind::BusOff => Some(Latch::BusOff),
                DivergenceKind::RegisterRead => None,
                _ => Some(Latch::Tx(
                    s.frame,
                    DiffKey::Tx {
                        field: s.field,
                        model: expected != 0,
                        dut: seen != 0,
                    },
                )),
            };
            if let Some(l) = latch {
                self.found_latch.push_back(l);
                self.latch_info = Some(l);
            }
        }

        /// A register read divergence (latched by its address and values).
        fn diverge_read(&mut self, s: Stamp, addr: u8, dut: u8, model: u8, label: String, context: String) {
            self.diverge(DivergenceKind::RegisterRead, s, Some(label), model as u32, dut as u32, context);
            let l = Latch::Read(DiffKey::Read { addr, dut, model });
            self.found_latch.push_back(l);
            self.latch_info = Some(l);
        }

        /// Was this read difference listed already (a repeat, counted, not listed)?
        fn read_repeats(&mut self, addr: u8, dut: u8, model: u8) -> bool {
            let r = self.listed.repeat(DiffKey::Read { addr, dut, model });
            self.repeated += r as u64;
            r
        }


        /// One CAN clock, after both sides were clocked: `sample` says whether
        /// it is a sample point; `sr`/`ir` are the reference's peeks.
        #[inline]
        pub fn can_clock(
            &mut self,
            stamp: Stamp,
            sample: bool,
            reference: &CanPins,
            dut: &CanPins,
            sr: u8,
            ir: u8,
        ) {
            if self.halted {
                return;
            }
            let skipping = stamp.bit < self.skip_until_bit;
            // tx with an edge-tolerance window centred on the checked clock.
            let tol = self.cfg.tx_edge_tolerance as usize;
            // Start of frame from bus idle: either side may go first, and the
            // shadow model never hard-synchronises on the DUT's SOF (it is not
            // on the bus), so the lag measured at the SOF is kept for the whole
            // frame: the earlier side's tx is delayed by it before comparing.
            let idle_now = matches!(
                stamp.field,
                Some(Field::BusIdle | Field::Intermission | Field::SuspendTransmission)
            );
            let cap = self.cfg.sof_tolerance as usize + 1;
            self.ref_hist.push_back(reference.tx);
            self.dut_hist.push_back(dut.tx);
            if self.ref_hist.len() > cap {
                self.ref_hist.pop_front();
                self.dut_hist.pop_front();
            }
            if self.sof_grace > 0 {
                self.grace_count += 1;
                if reference.tx == dut.tx {
                    self.sof_grace = 0;
                    if !reference.tx {
                        if self.grace_by_ref {
                            self.ref_off = self.grace_count as usize;
                        } else {
                            self.dut_off = self.grace_count as usize;
                        }
                    }
                } else {
                    self.sof_grace -= 1;
                }
            } else {
                let sof_edge = (self.prev_ref_tx && !reference.tx) || (self.prev_dut_tx && !dut.tx);
                if sof_edge
                    && (self.prev_idle || stamp.field == Some(Field::Sof))
                    && reference.tx != dut.tx
                    && self.cfg.sof_tolerance > 0
                {
                    self.sof_grace = self.cfg.sof_tolerance;
                    self.grace_count = 0;
                    self.grace_by_ref = !reference.tx;
                    self.ref_off = 0;
                    self.dut_off = 0;
                } else if idle_now && reference.tx && dut.tx {
                    self.ref_off = 0;
                    self.dut_off = 0;
                }
            }
            let excused = self.sof_grace > 0;
            self.prev_ref_tx = reference.tx;
            self.prev_dut_tx = dut.tx;
            self.prev_idle = idle_now;
            let n = self.ref_hist.len();
            let ref_tx = self.ref_hist[n - 1 - self.ref_off.min(n - 1)];
            let dut_tx = self.dut_hist[n - 1 - self.dut_off.min(n - 1)];
            self.window.push_back(OldTxSample {
                excused,
                ref_tx,
                dut_tx,
                sample,
                stamp,
            });
            if self.window.len() > 2 * tol + 1 {
                self.window.pop_front();
            }
            if self.window.len() == 2 * tol + 1 {
                let mid = self.window[tol];
                if mid.sample && !mid.excused && mid.stamp.bit >= self.skip_until_bit {
                    let stable = self.window.iter().all(|w| w.ref_tx == mid.ref_tx);
                    if stable {
                        self.compared_bits += 1;
                        if self.tx_latched
                            && mid.dut_tx == mid.ref_tx
                            && (self.tx_latch_frame.is_none() || mid.stamp.frame != self.tx_latch_frame)
                        {
                            self.tx_latched = false;
                        }
                        let key = DiffKey::Tx {
                            field: mid.stamp.field,
                            model: mid.ref_tx,
                            dut: mid.dut_tx,
                        };
                        if mid.dut_tx != mid.ref_tx && self.tx_latched {
                            self.cascade += 1;
                        } else if mid.dut_tx != mid.ref_tx && self.listed.repeat(key) {
                            // Listed before, in an earlier frame: latch this frame too.
                            self.repeated += 1;
                            self.tx_latched = true;
                            self.tx_latch_frame = mid.stamp.frame;
                        } else if mid.dut_tx != mid.ref_tx {
                            let lvl = |b: bool| if b { "recessive" } else { "dominant" };
                            self.diverge(
                                DivergenceKind::TxBit,
                                mid.stamp,
                                None,
                                mid.ref_tx as u32,
                                mid.dut_tx as u32,
                                format!(
                                    "at the sample point the model drives {} and the DUT's tx_o is {}",
                                    lvl(mid.ref_tx),
                                    lvl(mid.dut_tx)
                                ),
                            );
                        }
                    }
                }
            }
            // Status history for tolerant reads.
            let depth = self.cfg.status_tolerance as usize + 1;
            self.sr_hist.push_back(sr);
            self.ir_hist.push_back(ir);
            if self.sr_hist.len() > depth {
                self.sr_hist.pop_front();
                self.ir_hist.pop_front();
            }
            // Pending SR reads: look forward.
            let mut k = 0;
            while k < self.pending.len() {
                let p = &mut self.pending[k];
                if p.addr == SR_ADDR && sr == p.dut {
                    self.tolerated_reads += 1;
                    self.pending.swap_remove(k);
                    continue;
                }
                if p.clocks_left == 0 {
                    let p = self.pending.swap_remove(k);
                    if !self.read_repeats(p.addr, p.dut, p.model) {
                        self.diverge_read(
                            p.stamp,
                            p.addr,
                            p.dut,
                            p.model,
                            reg_label(p.addr),
                            format!(
                                "read of address {} returned 0x{:02X}, the model 0x{:02X}",
                                p.addr, p.dut, p.model
                            ),
                        );
                    }
                    continue;
                }
                p.clocks_left -= 1;
                k += 1;
            }
            // Pins: a mismatch may last pin_tolerance clocks.
            if self.irq_latched && reference.irq_n == dut.irq_n {
                self.irq_latched = false;
            }
            if self.bus_latched && reference.bus_on == dut.bus_on {
                self.bus_latched = false;
            }
            if self.cfg.compare_irq && !skipping && !self.irq_latched {
                if reference.irq_n != dut.irq_n {
                    if self.irq_bad == 0 {
                        self.irq_since = stamp;
                    }
                    self.irq_bad += 1;
                    if self.irq_bad > self.cfg.pin_tolerance {
                        let s = self.irq_since;
                        self.diverge(
                            DivergenceKind::Irq,
                            s,
                            None,
                            reference.irq_n as u32,
                            dut.irq_n as u32,
                            format!(
                                "irq_on (active low) differs for more than {} CAN clocks",
                                self.cfg.pin_tolerance
                            ),
                        );
                    }
                } else {
                    self.irq_bad = 0;
                }
            }
            if self.cfg.compare_bus_off && !skipping && !self.bus_latched {
                if reference.bus_on != dut.bus_on {
                    if self.bus_bad == 0 {
                        self.bus_since = stamp;
                    }
                    self.bus_bad += 1;
                    if self.bus_bad > self.cfg.pin_tolerance {
                        let s = self.bus_since;
                        self.diverge(
                            DivergenceKind::BusOff,
                            s,
                            None,
                            reference.bus_on as u32,
                            dut.bus_on as u32,
                            format!(
                                "bus_off_on (high = on the bus) differs for more than {} CAN clocks",
                                self.cfg.pin_tolerance
                            ),
                        );
                    }
                } else {
                    self.bus_bad = 0;
                }
            }
        }

        /// A register read completed on both sides: `dut` from the DUT, `model`
        /// from the reference at the same edge.
        pub fn read(&mut self, stamp: Stamp, addr: u8, dut: u8, model: u8, name: Option<String>) {
            if self.halted {
                return;
            }
            self.compared_reads += 1;
            if dut == model {
                return;
            }
            let hist = match addr {
                SR_ADDR => Some(&self.sr_hist),
                IR_ADDR => Some(&self.ir_hist),
                _ => None,
            };
            if let Some(h) = hist {
                if h.iter().any(|v| *v == dut) {
                    self.tolerated_reads += 1;
                    return;
                }
                if addr == SR_ADDR && self.cfg.status_tolerance > 0 {
                    self.pending.push(OldPendingRead {
                        addr,
                        dut,
                        model,
                        clocks_left: self.cfg.status_tolerance,
                        stamp,
                    });
                    return;
                }
            }
            if self.read_repeats(addr, dut, model) {
                return;
            }
            let label = name.unwrap_or_else(|| reg_label(addr));
            let context = format!(
                "read of {label} (address {addr}) returned 0x{dut:02X}, the model 0x{model:02X}"
            );
            self.diverge_read(stamp, addr, dut, model, label, context);
        }

        /// Reads still waiting for their tolerance window to close.
        pub fn pending_reads(&self) -> usize {
            self.pending.len()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pins(tx: bool) -> CanPins {
        CanPins {
            tx,
            irq_n: true,
            bus_on: true,
            clkout: false,
        }
    }

    fn run(cfg: CompareConfig, ref_tx: &[bool], dut_tx: &[bool], samples: &[usize]) -> Comparator {
        run_in(cfg, ref_tx, dut_tx, samples, None)
    }

    fn run_in(
        cfg: CompareConfig,
        ref_tx: &[bool],
        dut_tx: &[bool],
        samples: &[usize],
        field: Option<Field>,
    ) -> Comparator {
        let mut c = Comparator::new(cfg);
        for k in 0..ref_tx.len() {
            let s = Stamp {
                t_ps: k as u64,
                bit: k as u64,
                field,
                ..Stamp::default()
            };
            c.can_clock(
                s,
                samples.contains(&k),
                &pins(ref_tx[k]),
                &pins(dut_tx[k]),
                0,
                0,
            );
        }
        c
    }

    #[test]
    fn tx_edges_within_tolerance_are_not_compared_but_sample_points_are() {
        let cfg = CompareConfig {
            tx_edge_tolerance: 2,
            ..CompareConfig::default()
        };
        // Model edge at clock 10, DUT edge at 12 (late by 2): sample at 11 is
        // inside the window, sample at 20 is stable and equal.
        let r: Vec<bool> = (0..30).map(|k| k < 10).collect();
        let d: Vec<bool> = (0..30).map(|k| k < 12).collect();
        let c = run(cfg, &r, &d, &[11, 20]);
        assert!(c.divergence().is_none());
        assert_eq!(c.compared_bits, 1);
        // Late by 5 with a sample at 14: a divergence at 14.
        let d: Vec<bool> = (0..30).map(|k| k < 15).collect();
        let c = run(cfg, &r, &d, &[14, 20]);
        let dv = c.divergence().expect("divergence");
        assert_eq!(dv.kind, DivergenceKind::TxBit);
        assert_eq!(dv.time_ps, 14);
        assert_eq!((dv.expected, dv.seen), (0, 1));
        assert!(
            dv.context.contains("not within 2 CAN clocks"),
            "tolerance printed: {}",
            dv.context
        );
    }

    #[test]
    fn a_start_of_frame_from_bus_idle_may_lag_within_the_sof_tolerance() {
        let cfg = CompareConfig {
            tx_edge_tolerance: 2,
            sof_tolerance: 20,
            ..CompareConfig::default()
        };
        // Model SOF at clock 10, DUT SOF at 22 (12 clocks later), sample at 15.
        let r: Vec<bool> = (0..40).map(|k| k < 10).collect();
        let d: Vec<bool> = (0..40).map(|k| k < 22).collect();
        let c = run_in(cfg, &r, &d, &[15, 30], Some(Field::BusIdle));
        assert!(c.divergence().is_none(), "{:?}", c.divergence());
        assert_eq!(
            c.compared_bits, 1,
            "the sample after the DUT's SOF is compared"
        );
        // The same lag inside a frame (not from bus idle) is a divergence.
        let c = run_in(cfg, &r, &d, &[15, 30], Some(Field::Data));
        assert_eq!(c.divergence().map(|d| d.time_ps), Some(15));
        // A DUT that never starts is caught once the grace expires.
        let d: Vec<bool> = vec![true; 40];
        let c = run_in(cfg, &r, &d, &[15, 35], Some(Field::BusIdle));
        assert_eq!(c.divergence().map(|d| d.time_ps), Some(35));
    }

    #[test]
    fn an_ir_read_is_not_matched_by_the_value_the_reference_read_left_behind() {
        // Issue 19: the reference takes a read when the DUT's CAN side does,
        // before the ack; reading IR clears DOI, so for the clocks up to the
        // ack the model's IR is 0x01. A DUT that never raised DOI returned
        // 0x01 and the window took it (pelican-fifo-overrun steps 23, 38).
        let mut c = Comparator::new(CompareConfig { status_tolerance: 40, ..CompareConfig::default() });
        let p = pins(true);
        for _ in 0..50 {
            c.can_clock(Stamp::default(), false, &p, &p, 0, 0x09);
        }
        c.reference_read_taken();
        for _ in 0..4 {
            c.can_clock(Stamp::default(), false, &p, &p, 0, 0x01);
        }
        c.read(Stamp::default(), IR_ADDR, 0x01, 0x09, None);
        let d = c.divergence().expect("IR 0x01 only after the read cleared DOI");
        assert_eq!((d.register.as_deref(), d.expected, d.seen), (Some("IR"), 0x09, 0x01));
        // A value the model held before the read is still within the window.
        let mut c = Comparator::new(CompareConfig { status_tolerance: 40, ..CompareConfig::default() });
        for ir in [0x01, 0x01, 0x09, 0x09] {
            c.can_clock(Stamp::default(), false, &p, &p, 0, ir);
        }
        c.reference_read_taken();
        c.can_clock(Stamp::default(), false, &p, &p, 0, 0x01);
        c.read(Stamp::default(), IR_ADDR, 0x01, 0x09, None);
        assert!(c.divergence().is_none(), "IR 0x01 two clocks before the read");
        assert_eq!(c.tolerated_reads, 1);
        // Without an early take (reference at the ack) nothing changes.
        let mut c = Comparator::new(CompareConfig { status_tolerance: 40, ..CompareConfig::default() });
        for ir in [0x01, 0x09] {
            c.can_clock(Stamp::default(), false, &p, &p, 0, ir);
        }
        c.read(Stamp::default(), IR_ADDR, 0x01, 0x09, None);
        assert!(c.divergence().is_none());
    }

    #[test]
    fn a_tolerated_read_that_misses_an_expectation_the_model_meets_is_a_divergence() {
        // pelican-fifo-overrun step 70: SR 0x0F (DOS, RBS) 20 clocks after
        // the release of the last message, where the model reads 0x0E and
        // the scenario expects RBS = 0, DOS = 1 (mask 0x03).
        let setup = || {
            let mut c = Comparator::new(CompareConfig { status_tolerance: 40, ..CompareConfig::default() });
            let p = pins(true);
            for k in 0..60 {
                c.can_clock(Stamp::default(), false, &p, &p, if k < 40 { 0x0F } else { 0x0E }, 0);
            }
            c.read(Stamp { t_ps: 9, ..Stamp::default() }, SR_ADDR, 0x0F, 0x0E, None);
            assert!(c.divergence().is_none(), "the window accepts it");
            c
        };
        let mut c = setup();
        assert!(c.hold_tolerated_read(SR_ADDR, 0x0F, 0x03, 0x02));
        let d = c.divergence().expect("held to the expectation");
        assert_eq!((d.time_ps, d.register.as_deref(), d.expected, d.seen), (9, Some("SR"), 0x0E, 0x0F));
        assert!(d.context.contains("expectation"), "{}", d.context);
        assert_eq!(c.tolerated_reads, 0);
        // An expectation the model misses too: the scenario's problem, not a divergence.
        let mut c = setup();
        assert!(!c.hold_tolerated_read(SR_ADDR, 0x0F, 0x03, 0x00));
        assert!(c.divergence().is_none());
        // An expectation the DUT meets: nothing to hold.
        let mut c = setup();
        assert!(!c.hold_tolerated_read(SR_ADDR, 0x0F, 0x0C, 0x0C));
        // Only the last read: a later exact read forgets it.
        let mut c = setup();
        c.read(Stamp::default(), 4, 0, 0, None);
        assert!(!c.hold_tolerated_read(SR_ADDR, 0x0F, 0x03, 0x02));
        assert!(c.divergence().is_none());
    }

    #[test]
    fn status_reads_use_the_window_other_reads_are_exact() {
        let mut c = Comparator::new(CompareConfig {
            status_tolerance: 3,
            ..CompareConfig::default()
        });
        let p = pins(true);
        for sr in [0x0C, 0x0C, 0x3C] {
            c.can_clock(Stamp::default(), false, &p, &p, sr, 0);
        }
        c.read(Stamp::default(), SR_ADDR, 0x0C, 0x3C, None);
        assert!(
            c.divergence().is_none(),
            "SR 0x0C was the model's value 1 clock ago"
        );
        assert_eq!(c.tolerated_reads, 1);
        // SR value the model takes 2 clocks after the read: accepted too.
        c.read(Stamp::default(), SR_ADDR, 0x1C, 0x3C, None);
        assert_eq!(c.pending_reads(), 1);
        c.can_clock(Stamp::default(), false, &p, &p, 0x3C, 0);
        c.can_clock(Stamp::default(), false, &p, &p, 0x1C, 0);
        assert_eq!(c.pending_reads(), 0);
        assert!(c.divergence().is_none());
        // SR value never taken: divergence once the window closes.
        c.read(
            Stamp {
                t_ps: 77,
                ..Stamp::default()
            },
            SR_ADDR,
            0xFF,
            0x1C,
            None,
        );
        for _ in 0..5 {
            c.can_clock(Stamp::default(), false, &p, &p, 0x1C, 0);
        }
        let d = c.divergence().expect("SR 0xFF never held");
        assert_eq!(
            (d.kind, d.time_ps, d.register.as_deref()),
            (DivergenceKind::RegisterRead, 77, Some("SR"))
        );
        // Another register: exact.
        let mut c = Comparator::new(CompareConfig::default());
        c.read(Stamp::default(), 6, 0x41, 0x41, Some("BTR0".into()));
        assert!(c.divergence().is_none());
        c.read(Stamp::default(), 6, 0x40, 0x41, Some("BTR0".into()));
        assert_eq!(c.divergence().unwrap().register.as_deref(), Some("BTR0"));
    }

    /// Reference tx all recessive with a sample point every 10 clocks (bit
    /// k at clock 10k + 5); the DUT drives dominant at the given bits.
    fn run_bits(
        c: &mut Comparator,
        bits: std::ops::Range<u64>,
        dominant: &[u64],
        mut on_div: impl FnMut(&mut Comparator, Divergence),
    ) {
        for bit in bits {
            for k in 0..10u64 {
                let s = Stamp {
                    t_ps: bit * 10 + k,
                    bit,
                    ..Stamp::default()
                };
                let dut_tx = !(dominant.contains(&bit) && k >= 2);
                c.can_clock(s, k == 5, &pins(true), &pins(dut_tx), 0, 0);
                while let Some(d) = c.take_divergence() {
                    on_div(c, d);
                }
            }
        }
    }

    #[test]
    fn resume_goes_on_after_a_divergence_and_skip_bits_are_not_compared() {
        let mut c = Comparator::new(CompareConfig {
            tx_edge_tolerance: 2,
            ..CompareConfig::default()
        });
        let mut seen = vec![];
        // Without resume: halted at the first one, as before.
        run_bits(&mut c, 0..20, &[3, 4, 12], |_, d| seen.push(d.bit.unwrap()));
        assert_eq!(seen, [3]);
        assert!(c.halted());
        assert_eq!(c.divergence().unwrap().bit, Some(3));
        // Resume after each (a waiver with skip-bits 2): bit 4 is skipped, 12 reported.
        let mut c = Comparator::new(CompareConfig {
            tx_edge_tolerance: 2,
            ..CompareConfig::default()
        });
        let mut seen = vec![];
        run_bits(&mut c, 0..20, &[3, 4, 12], |c, d| {
            seen.push(d.bit.unwrap());
            c.resume(d.bit.map(|b| b + 2), false);
        });
        assert_eq!(seen, [3, 12]);
        assert_eq!(
            c.divergence().unwrap().bit,
            Some(3),
            "divergence() stays the first"
        );
        // Resume without skipping, not latched (waived): every bit reported.
        let mut c = Comparator::new(CompareConfig {
            tx_edge_tolerance: 2,
            ..CompareConfig::default()
        });
        let mut seen = vec![];
        run_bits(&mut c, 0..20, &[3, 4, 12], |c, d| {
            seen.push(d.bit.unwrap());
            c.resume(None, false);
        });
        assert_eq!(seen, [3, 4, 12]);
        // Collect mode latches: a lasting deviation counts once until tx agrees again.
        let mut c = Comparator::new(CompareConfig {
            tx_edge_tolerance: 2,
            ..CompareConfig::default()
        });
        let mut seen = vec![];
        run_bits(&mut c, 0..20, &[3, 4, 5, 12], |c, d| {
            seen.push(d.bit.unwrap());
            c.resume(None, true);
        });
        assert_eq!(seen, [3, 12]);
    }

    #[test]
    fn a_waiver_session_drives_the_comparator() {
        use waivers::{Action, CollectMode, DutInfo, Resync, Session, WaiverSet};
        let set = WaiverSet::parse(
            r#"
[[waiver]]
id = "late-flag"
kind = "tx-bit"
dut = ["fixture"]
late-bits = 1
explanation = "one dominant bit late, accepted for this test"
resync = ["skip-bits 1"]
"#,
            "t.toml",
        )
        .unwrap();
        for (mode, dominant, waived, failures) in [
            (CollectMode::StopAtFirst, vec![3], 1, 0),
            (CollectMode::StopAtFirst, vec![3, 4], 1, 1),
            (CollectMode::Collect, vec![3, 4, 5, 15], 2, 1),
        ] {
            let mut s = Session::new(set.clone(), DutInfo::new("fixture"), mode);
            let mut c = Comparator::new(CompareConfig {
                tx_edge_tolerance: 2,
                ..CompareConfig::default()
            });
            run_bits(&mut c, 0..20, &dominant, |c, d| {
                let bit = d.bit.unwrap();
                match s.divergence(d) {
                    Action::Resync(steps) => {
                        let skip = steps
                            .iter()
                            .map(|r| {
                                if let Resync::SkipBits(n) = r {
                                    *n as u64
                                } else {
                                    0
                                }
                            })
                            .max();
                        c.resume(skip.map(|n| bit + n), false);
                    }
                    Action::Continue => c.resume(None, true),
                    Action::Stop => {}
                }
            });
            let (r, _) = s.finish();
            assert_eq!(
                (r.waived.len(), r.failures.len()),
                (waived, failures),
                "{mode:?} {dominant:?}: {}",
                r.to_text()
            );
        }
    }

    #[test]
    fn irq_may_differ_briefly_but_not_longer_than_the_tolerance() {
        let mut c = Comparator::new(CompareConfig {
            pin_tolerance: 3,
            ..CompareConfig::default()
        });
        let r = CanPins {
            irq_n: false,
            ..pins(true)
        };
        let d = pins(true);
        for k in 0..3 {
            c.can_clock(
                Stamp {
                    t_ps: k,
                    ..Stamp::default()
                },
                false,
                &r,
                &d,
                0,
                0,
            );
        }
        assert!(c.divergence().is_none());
        c.can_clock(Stamp::default(), false, &r, &r, 0, 0);
        for k in 10..14 {
            c.can_clock(
                Stamp {
                    t_ps: k,
                    ..Stamp::default()
                },
                false,
                &r,
                &d,
                0,
                0,
            );
        }
        let dv = c.divergence().expect("irq divergence");
        assert_eq!((dv.kind, dv.time_ps), (DivergenceKind::Irq, 10));
    }

    /// Collect mode lists each tx difference once: the first mismatch of a
    /// frame is listed; later mismatches of that frame are its cascade
    /// (counted); the same difference (field, levels) in a later frame is
    /// a repeat (counted, and the rest of its frame its cascade); a difference in
    /// another field is listed; a waived one (not latched) never is
    /// deduplicated.
    #[test]
    fn collect_mode_lists_each_tx_difference_once() {
        // Ten bits per frame; the DUT is dominant at these bits, in these fields.
        let plan: [(u64, Field); 7] = [
            (3, Field::Data),
            (4, Field::Data),
            (13, Field::Data),
            (15, Field::Crc),
            (24, Field::Crc),
            (33, Field::AckSlot),
            (45, Field::Crc),
        ];
        for latch in [true, false] {
            let mut c = Comparator::new(CompareConfig { tx_edge_tolerance: 2, ..CompareConfig::default() });
            let mut listed = vec![];
            for bit in 0..50u64 {
                let field = plan.iter().find(|p| p.0 == bit).map(|p| p.1).or(Some(Field::Data));
                for k in 0..10u64 {
                    let s = Stamp { t_ps: bit * 10 + k, bit, field, frame: Some(bit as u32 / 10 + 1) };
                    let dominant = plan.iter().any(|p| p.0 == bit) && k >= 2;
                    c.can_clock(s, k == 5, &pins(true), &pins(!dominant), 0, 0);
                    while let Some(d) = c.take_divergence() {
                        listed.push((d.bit.unwrap(), d.field));
                        c.resume(None, latch);
                    }
                }
            }
            if latch {
                assert_eq!(listed, [(3, Some(Field::Data)), (24, Some(Field::Crc)), (33, Some(Field::AckSlot))]);
                assert_eq!(
                    (c.repeated, c.cascade),
                    (2, 2),
                    "bits 13 and 45 repeat; bit 4 is bit 3's cascade, bit 15 bit 13's"
                );
                assert_eq!(c.repeats().len(), 2, "{:?}", c.repeats());
                assert!(c.repeats()[0].starts_with("tx in data field (model recessive, DUT dominant): 1 more"), "{:?}", c.repeats());
            } else {
                assert_eq!(listed.len(), plan.len(), "waived: every bit is handed on");
                assert_eq!((c.repeated, c.cascade), (0, 0));
            }
        }
    }

    /// Differential test against the declared tolerance (issue 19): on
    /// random status sequences with random reads, interleaved with tx and
    /// irq divergences at random clocks, a read diverges exactly when its
    /// DUT value differs from the model's at the read and from every value
    /// the model's SR held in the clocks [P - 1 - tol, P + tol] around it
    /// (IR: [P - 1 - tol, P - 1]; other registers: none), P being the
    /// clocks before the read. The run ends with `open_clocks()` clocks, as
    /// the test bench's settle does, so the last reads are judged too.
    #[test]
    fn a_read_diverges_exactly_when_the_model_never_held_the_value_in_the_window() {
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let mut rnd = move |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        };
        let values = [0x0Cu8, 0x1C, 0x3C, 0x0D, 0x00, 0x04];
        let (mut bad_total, mut good_total) = (0, 0);
        for st_tol in [0u32, 1, 3, 48] {
            let cfg = CompareConfig {
                tx_edge_tolerance: 1,
                status_tolerance: st_tol,
                pin_tolerance: 2,
                ..CompareConfig::default()
            };
            let mut c = Comparator::new(cfg);
            let clocks = 40_000usize;
            let total = clocks + 200;
            let mut sr = vec![0u8; total];
            let mut ir = vec![0u8; total];
            for k in 1..total {
                sr[k] = if rnd(4) == 0 { values[rnd(6) as usize] } else { sr[k - 1] };
                ir[k] = if rnd(6) == 0 { values[rnd(6) as usize] } else { ir[k - 1] };
            }
            // (read id, address, P, DUT value, model value)
            let mut reads: Vec<(u64, u8, usize, u8, u8)> = Vec::new();
            let mut flagged = std::collections::BTreeSet::new();
            let mut clk = 0usize;
            let step = |c: &mut Comparator, clk: usize, rnd: &mut dyn FnMut(u64) -> u64| {
                let sample = clk % 10 == 5;
                // The DUT's tx is wrong at some sample points, its irq now and then.
                let dut_tx = !(sample && rnd(7) == 0);
                let irq_bad = clk % 97 < 5 && rnd(3) == 0;
                let r = pins(true);
                let d = CanPins { tx: dut_tx, irq_n: !irq_bad, ..pins(true) };
                let stamp = Stamp { t_ps: clk as u64, bit: clk as u64 / 10, frame: Some(clk as u32 / 200), ..Stamp::default() };
                c.can_clock(stamp, sample, &r, &d, sr[clk], ir[clk]);
            };
            let drain = |c: &mut Comparator, flagged: &mut std::collections::BTreeSet<u64>| {
                while let Some(d) = c.take_divergence() {
                    let read = d.kind == DivergenceKind::RegisterRead;
                    if read {
                        assert!(flagged.insert(d.time_ps), "one divergence per read");
                    }
                    c.resume(None, !read);
                }
            };
            while clk < clocks {
                step(&mut c, clk, &mut rnd);
                clk += 1;
                drain(&mut c, &mut flagged);
                if rnd(5) == 0 {
                    let addr = [SR_ADDR, IR_ADDR, 6][rnd(3) as usize];
                    let model = match addr {
                        SR_ADDR => sr[clk - 1],
                        IR_ADDR => ir[clk - 1],
                        _ => values[rnd(6) as usize],
                    };
                    let dut = if rnd(3) == 0 { model } else { values[rnd(6) as usize] };
                    let id = 1_000_000 + reads.len() as u64;
                    let stamp = Stamp { t_ps: id, ..Stamp::default() };
                    c.read(stamp, addr, dut, model, None);
                    reads.push((id, addr, clk, dut, model));
                    drain(&mut c, &mut flagged);
                }
            }
            let open = c.open_clocks() as usize;
            assert!(open <= (st_tol.max(2) + 3) as usize, "open {open}");
            for _ in 0..open {
                step(&mut c, clk, &mut rnd);
                clk += 1;
                drain(&mut c, &mut flagged);
            }
            assert_eq!(c.pending_reads(), 0, "every read judged");
            let tol = st_tol as usize;
            for &(id, addr, p, dut, model) in &reads {
                let held = |h: &[u8], lo: usize, hi: usize| (lo..=hi).any(|k| h[k] == dut);
                let back = p.saturating_sub(1 + tol);
                let ok = dut == model
                    || match addr {
                        SR_ADDR => held(&sr, back, if tol > 0 { p + tol } else { p - 1 }),
                        IR_ADDR => held(&ir, back, p - 1),
                        _ => false,
                    };
                assert_eq!(
                    flagged.contains(&id),
                    !ok,
                    "tol {st_tol}: read {id} of {addr} at P = {p}: DUT 0x{dut:02X}, model 0x{model:02X}"
                );
                if ok { good_total += 1 } else { bad_total += 1 }
            }
        }
        assert!(bad_total > 1000 && good_total > 1000, "{bad_total} / {good_total}");
    }

    /// The comparator reaches exactly the verdicts of the one it replaced
    /// (`before::OldComparator`) on random pin, status and read sequences,
    /// with halts, resumes, skips and latches, for several tolerances.
    #[test]
    fn same_verdicts_as_the_per_clock_deque_comparator() {
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut rnd = move |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        };
        let fields = [
            None,
            Some(Field::BusIdle),
            Some(Field::Sof),
            Some(Field::Data),
            Some(Field::Intermission),
            Some(Field::Crc),
            Some(Field::SuspendTransmission),
        ];
        let statuses = [0x0C, 0x1C, 0x3C, 0x0D, 0x00];
        let mut divergences = 0;
        // Busy sequences (something changes nearly every clock) and calm
        // ones (long stretches where nothing does, as on a real bus).
        for (calm, (tx_tol, sof_tol, st_tol, pin_tol)) in [
            (4, 40, 48, 48),
            (0, 0, 0, 0),
            (1, 3, 2, 1),
            (2, 20, 3, 3),
            (3, 100, 70, 5),
            (8, 63, 1, 60),
        ]
        .into_iter()
        .flat_map(|c| [(1, c), (25, c)])
        {
            let cfg = CompareConfig {
                tx_edge_tolerance: tx_tol,
                status_tolerance: st_tol,
                pin_tolerance: pin_tol,
                compare_irq: rnd(4) != 0,
                compare_bus_off: rnd(4) != 0,
                sof_tolerance: sof_tol,
            };
            let mut new = Comparator::new(cfg);
            let mut old = before::OldComparator::new(cfg);
            let mut ref_tx_hist = vec![true; 64];
            let (mut lag, mut field, mut phase) = (0usize, None, 5u64);
            let (mut rp, mut dp) = (pins(true), pins(true));
            let (mut sr, mut ir) = (0x0C, 0);
            for clk in 0..60_000u64 {
                // Reference tx in runs; the DUT follows it late by `lag`, with glitches.
                let last = *ref_tx_hist.last().unwrap();
                ref_tx_hist.push(if rnd(12 * calm) == 0 { !last } else { last });
                if rnd(400) == 0 {
                    lag = [0, 1, 2, 5, 12, 30, 45][rnd(7) as usize];
                }
                let n = ref_tx_hist.len();
                rp.tx = ref_tx_hist[n - 1];
                dp.tx = ref_tx_hist[n - 1 - lag] ^ (rnd(300 * calm) == 0);
                if rnd(60) == 0 {
                    field = fields[rnd(fields.len() as u64) as usize];
                }
                if rnd(50 * calm) == 0 {
                    rp.irq_n = !rp.irq_n;
                }
                if rnd(50 * calm) == 0 {
                    rp.bus_on = !rp.bus_on;
                }
                if rnd(7 * calm) == 0 {
                    dp.irq_n = rp.irq_n ^ (rnd(9) == 0);
                    dp.bus_on = rp.bus_on ^ (rnd(9) == 0);
                }
                if rnd(20 * calm) == 0 {
                    sr = statuses[rnd(5) as usize];
                }
                if rnd(30 * calm) == 0 {
                    ir = statuses[rnd(5) as usize];
                }
                if rnd(500) == 0 {
                    phase = rnd(10);
                }
                let stamp = Stamp {
                    t_ps: clk,
                    bit: clk / 10,
                    field,
                    frame: Some((clk / 1000) as u32),
                };
                // Calm: a sample point every 40 clocks, as at 40 clocks per bit.
                let sample = clk % (10 * calm.min(4)) == phase;
                new.can_clock(stamp, sample, &rp, &dp, sr, ir);
                old.can_clock(stamp, sample, &rp, &dp, sr, ir);
                if rnd(90 * calm) == 0 {
                    let addr = [SR_ADDR, IR_ADDR, 6][rnd(3) as usize];
                    let dut = statuses[rnd(5) as usize];
                    let model = if rnd(2) == 0 {
                        sr
                    } else {
                        statuses[rnd(5) as usize]
                    };
                    new.read(stamp, addr, dut, model, None);
                    old.read(stamp, addr, dut, model, None);
                }
                loop {
                    let (a, b) = (new.take_divergence(), old.take_divergence());
                    assert_eq!(a, b, "clock {clk}, config {cfg:?}");
                    if a.is_none() {
                        break;
                    }
                    divergences += 1;
                }
                assert_eq!(new.halted(), old.halted(), "clock {clk}");
                if new.halted() && rnd(3) != 0 {
                    let skip = (rnd(2) == 0).then(|| clk / 10 + rnd(5));
                    let latch = rnd(2) == 0;
                    new.resume(skip, latch);
                    old.resume(skip, latch);
                }
            }
            assert_eq!(new.divergence(), old.divergence());
            assert_eq!(
                (
                    new.compared_bits,
                    new.compared_reads,
                    new.tolerated_reads,
                    new.pending_reads()
                ),
                (
                    old.compared_bits,
                    old.compared_reads,
                    old.tolerated_reads,
                    old.pending_reads()
                ),
                "{cfg:?}"
            );
            assert!(
                new.compared_bits > 100,
                "{cfg:?}: too few bits compared to mean anything"
            );
        }
        assert!(
            divergences > 100,
            "the sequences exercise divergences ({divergences})"
        );
    }
}
