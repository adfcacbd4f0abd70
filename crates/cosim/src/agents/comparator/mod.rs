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

pub mod clkout;
mod pins;
mod policy;
mod reads;
mod tx;
pub use policy::{ComparatorAgent, Now};
use pins::PinChecker;
use reads::{PendingRead, ReadChecker, ReadVerdict};
use tx::{TxChecker, TxSample};

use can_proto::Field;
use diagnose::{Divergence, DivergenceKind};

use crate::types::CanPins;
// The reference side lives in `types` (dut.rs implements it too).
pub use crate::types::{IR_ADDR, PELI_STATUS_ADDRS, RMC_ADDR, RefView, Reference, SR_ADDR, Stamp};

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
    /// Check clkout_o's period and enable against the reference's CDR
    /// (`clkout`).
    pub compare_clkout: bool,
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
            compare_clkout: true,
        }
    }
}

impl CompareConfig {
    /// The tolerances in words, for the report.
    pub fn describe(&self) -> String {
        format!(
            "tx compared at sample points, not within {} CAN clocks of a model tx edge, a start of frame from bus idle may lag by {} CAN clocks; register reads exact except SR/IR and (PeliCAN) RXERR/TXERR/RMC \
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
    /// clkout_o: the CLKOUT check latches itself until the setting changes.
    Clkout,
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

/// The comparator: one checker per kind ([`tx`], [`reads`], [`pins`]) and
/// what is common to them: the divergences found, the halt until
/// [`Comparator::resume`], the bits a waiver skips, and the collect-mode
/// listing (each distinct difference once, repeats counted).
pub struct Comparator {
    cfg: CompareConfig,
    tx: TxChecker,
    reads: ReadChecker,
    pins: PinChecker,
    /// clkout_o against the reference's CDR.
    clkout: clkout::ClkoutCheck,
    /// Reads whose window closed this clock (kept to reuse its buffer).
    expired: Vec<PendingRead>,
    divergence: Option<Divergence>,
    found: VecDeque<Divergence>,
    halted: bool,
    last_kind: Option<DivergenceKind>,
    /// The latch of the divergence last found or taken (what `resume` latches).
    latch_info: Option<Latch>,
    /// The latches of `found`, in step with it.
    found_latch: VecDeque<Latch>,
    /// The irq report found: the pins had not agreed since the last one.
    irq_continues: Option<bool>,
    /// The last bit whose tx was compared and agreed (for the waivers).
    tx_agreed_bit: Option<u64>,
    /// Differences listed in collect mode, with their repeats.
    listed: Listed,
    skip_until_bit: u64,
    /// Reads and sample points compared (for the report).
    pub compared_bits: u64,
    /// Register reads compared.
    pub compared_reads: u64,
    /// Reads accepted only thanks to the status tolerance.
    pub tolerated_reads: u64,
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
            tx: TxChecker::new(&cfg),
            reads: ReadChecker::new(cfg.status_tolerance),
            pins: PinChecker::new(&cfg),
            clkout: clkout::ClkoutCheck::default(),
            expired: Vec::new(),
            divergence: None,
            found: VecDeque::new(),
            halted: false,
            last_kind: None,
            latch_info: None,
            found_latch: VecDeque::new(),
            irq_continues: None,
            tx_agreed_bit: None,
            listed: Listed::default(),
            skip_until_bit: 0,
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

    /// The register read of the divergence last taken, if it was one: its
    /// address and the DUT's value (what a collect-mode resync adopts).
    pub fn taken_read(&self) -> Option<(u8, u8)> {
        match self.latch_info {
            Some(Latch::Read(DiffKey::Read { addr, dut, .. })) => Some((addr, dut)),
            _ => None,
        }
    }

    /// Of the irq report just taken: true if the pins have not agreed since
    /// the previous irq report (the same difference again), once.
    pub fn take_irq_continues(&mut self) -> Option<bool> {
        self.irq_continues.take()
    }

    /// The last bit whose tx the comparator compared and found equal.
    pub fn tx_agreed_bit(&self) -> Option<u64> {
        self.tx_agreed_bit
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
                    self.tx.latched = true;
                    self.tx.latch_frame = frame;
                    // Only a difference whose field is known is one to recognise again.
                    if matches!(key, DiffKey::Tx { field: Some(_), .. }) {
                        self.listed.add(key);
                    }
                }
                Some(Latch::Irq) => self.pins.latch_irq(),
                Some(Latch::BusOff) => self.pins.latch_bus_off(),
                Some(Latch::Read(key)) => self.listed.add(key),
                Some(Latch::Clkout) | None => {}
            }
        }
        self.pins.restart();
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
            DivergenceKind::Clkout => Some(Latch::Clkout),
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
    /// it is a sample point; `sr`/`ir`/`peli` are the reference's peeks
    /// (`peli`: RXERR, TXERR, RMC, PeliCAN only).
    #[inline]
    pub fn can_clock(
        &mut self,
        stamp: Stamp,
        sample: bool,
        reference: &CanPins,
        dut: &CanPins,
        sr: u8,
        ir: u8,
        peli: Option<[u8; 3]>,
    ) {
        if self.halted {
            return;
        }
        if self.tx.quiet(sample, reference, dut) && self.reads.quiet(sr, ir, peli) && PinChecker::agree(reference, dut) {
            // Most clocks: the same tx, status and agreeing pins as the last
            // one, no sample point in the window, no read waiting, no start
            // of frame being excused. What the general path below would do
            // then, in short: no tx edge (so no start of frame, and the
            // offsets stay 0), no window change to check, no new status run,
            // the pins agree.
            self.quiet_clock(stamp.field, stamp.bit, reference, dut);
            return;
        }
        self.can_clock_general(stamp, sample, reference, dut, sr, ir, peli);
    }

    /// How many of the next clocks, none a sample point, with these inputs,
    /// [`Comparator::can_clock`] does no more than its short path
    /// ([`Comparator::quiet_clock`]) on (the test bench's quiet stretches;
    /// 0: none): the short path's condition but for sample points waiting
    /// in the tx window, until the first of them is judged
    /// (`TxChecker::quiet_for`). The short path changes nothing else the
    /// condition reads, so it holds for all of them.
    #[inline]
    pub(crate) fn quiet_ahead(&self, reference: &CanPins, dut: &CanPins, sr: u8, ir: u8, peli: Option<[u8; 3]>) -> u32 {
        if self.halted || !self.reads.quiet(sr, ir, peli) || !PinChecker::agree(reference, dut) {
            return 0;
        }
        self.tx.quiet_for(reference, dut)
    }

    /// The short path of [`Comparator::can_clock`] (its condition holds, or
    /// the clock is one of [`Comparator::quiet_ahead`]'s): `field` and `bit`
    /// as in the clock's stamp.
    #[inline]
    pub(crate) fn quiet_clock(&mut self, field: Option<Field>, bit: u64, reference: &CanPins, dut: &CanPins) {
        self.tx.quiet_clock(reference, dut, idle(field));
        self.reads.quiet_clock();
        self.pins.quiet_clock(bit < self.skip_until_bit);
    }

    /// `n` clocks in a row that take the short path with the same inputs
    /// (the test bench's quiet stretches): what `n` calls of
    /// [`Comparator::quiet_clock`] do (CLKOUT apart).
    pub(crate) fn quiet_clocks(&mut self, n: u32, field: Option<Field>, bit: u64, reference: &CanPins, dut: &CanPins) {
        self.tx.quiet_clocks(n, reference, dut, idle(field));
        self.reads.quiet_clocks(n);
        self.pins.quiet_clock(bit < self.skip_until_bit);
    }

    /// The CLKOUT check for the clocks of a quiet stretch, if they take its
    /// short path while it finds nothing ([`clkout::ClkoutCheck::settled_half_period`]):
    /// the check and the half period, for [`clkout::ClkoutCheck::settled_next`]
    /// on each, in place of [`Comparator::clkout_instants`] and
    /// [`Comparator::clkout_clock`].
    #[inline]
    pub(crate) fn quiet_clkout(&mut self, setting: clkout::ClkoutSetting) -> Option<(&mut clkout::ClkoutCheck, u32)> {
        if !self.cfg.compare_clkout {
            return None;
        }
        let h = self.clkout.settled_half_period(setting)?;
        Some((&mut self.clkout, h))
    }

    /// [`Comparator::can_clock`] on the clocks its short path does not
    /// take (not halted): each checker in turn, tx, reads, pins; what they
    /// find is judged here. Out of line: the short path inlined into the
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
        peli: Option<[u8; 3]>,
    ) {
        let skipping = stamp.bit < self.skip_until_bit;
        if let Some(mid) = self.tx.clock(stamp, sample, reference, dut, idle(stamp.field), self.skip_until_bit) {
            self.judge_tx(mid);
        }
        let mut expired = std::mem::take(&mut self.expired);
        self.tolerated_reads += self.reads.clock(sr, ir, peli, &mut expired);
        for p in expired.drain(..) {
            if !self.read_repeats(p.addr, p.dut, p.model) {
                // Only SR reads wait for the window (the PeliCAN three look back only).
                let context = format!("read of address {} returned 0x{:02X}, the model 0x{:02X}", p.addr, p.dut, p.model);
                self.diverge_read(p.stamp, p.addr, p.dut, p.model, reg_label(p.addr), context);
            }
        }
        self.expired = expired;
        for d in self.pins.clock(stamp, reference, dut, skipping).into_iter().flatten() {
            if d.kind == DivergenceKind::Irq {
                self.irq_continues = Some(d.continues);
            }
            self.diverge(d.kind, d.since, None, d.expected, d.seen, d.context);
        }
    }

    /// A sample point the tx checker compares: a difference is listed,
    /// or counted as a repeat or as its frame's cascade (collect mode).
    fn judge_tx(&mut self, mid: TxSample) {
        self.compared_bits += 1;
        if mid.dut_tx == mid.ref_tx {
            self.tx_agreed_bit = Some(mid.stamp.bit);
        }
        if self.tx.latched
            && mid.dut_tx == mid.ref_tx
            && (self.tx.latch_frame.is_none() || mid.stamp.frame != self.tx.latch_frame)
        {
            self.tx.latched = false;
        }
        let key = DiffKey::Tx {
            field: mid.stamp.field,
            model: mid.ref_tx,
            dut: mid.dut_tx,
        };
        if mid.dut_tx != mid.ref_tx && self.tx.latched {
            self.cascade += 1;
        } else if mid.dut_tx != mid.ref_tx && self.listed.repeat(key) {
            // Listed before, in an earlier frame: latch this frame too.
            self.repeated += 1;
            self.tx.latched = true;
            self.tx.latch_frame = mid.stamp.frame;
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

    /// One CAN clock of the CLKOUT checker ([`clkout::ClkoutCheck`], after
    /// [`Comparator::can_clock`] at the same clock, if `compare_clkout`):
    /// the reference's setting now and the DUT's `clkout_o`.
    #[inline]
    pub fn clkout_clock(&mut self, stamp: Stamp, setting: clkout::ClkoutSetting, dut_level: bool) {
        self.clkout_clock_with(|| stamp, setting, dut_level);
    }

    /// [`Comparator::clkout_clock`] with the stamp made only for a finding.
    #[inline]
    pub(crate) fn clkout_clock_with(&mut self, stamp: impl FnOnce() -> Stamp, setting: clkout::ClkoutSetting, dut_level: bool) {
        if self.cfg.compare_clkout
            && let Some(m) = self.clkout.clock(setting, dut_level)
        {
            self.clkout_divergence(stamp(), m);
        }
    }

    /// The levels `clkout_o` had at the DUT's instants since the last CAN
    /// clock ([`clkout::ClkoutCheck::instants`]), before [`Self::clkout_clock`].
    #[inline]
    pub fn clkout_instants(&mut self, levels: u8) {
        self.clkout.instants(levels);
    }

    /// A CLKOUT difference found by [`clkout::ClkoutCheck`].
    pub fn clkout_divergence(&mut self, stamp: Stamp, m: clkout::ClkoutMismatch) {
        if !self.halted {
            self.diverge(DivergenceKind::Clkout, stamp, None, m.expected, m.seen, m.what);
        }
    }

    /// A register read completed on both sides: `dut` from the DUT, `model`
    /// from the reference at the same edge.
    pub fn read(&mut self, stamp: Stamp, addr: u8, dut: u8, model: u8, name: Option<String>) {
        let taken_at = self.reads.begin_read();
        if self.halted {
            return;
        }
        self.compared_reads += 1;
        if dut == model {
            return;
        }
        match self.reads.judge(stamp, addr, dut, model, taken_at) {
            ReadVerdict::Tolerated => {
                self.tolerated_reads += 1;
                return;
            }
            ReadVerdict::Waiting => return,
            ReadVerdict::Differs => {}
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
        self.reads.reference_read_taken();
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
        let Some(p) = self.reads.take_tolerated() else { return false };
        if self.halted || p.addr != addr || p.dut != dut || p.model & mask != expected & mask || dut & mask == expected & mask {
            return false;
        }
        self.tolerated_reads -= 1;
        let context = format!(
            "read of {} (address {addr}) returned 0x{dut:02X}, the model 0x{:02X}: the model held 0x{dut:02X} within the {}-clock status tolerance, but the scenario's expectation at this read (0x{:02X} under mask 0x{mask:02X}) holds for the model's value, not the DUT's",
            status_label(addr),
            p.model,
            self.cfg.status_tolerance,
            expected & mask
        );
        self.diverge_read(p.stamp, addr, dut, p.model, status_label(addr), context);
        true
    }

    /// Reads still waiting for their tolerance window to close.
    pub fn pending_reads(&self) -> usize {
        self.reads.pending()
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

    /// CAN clocks until every read still within its look-ahead window is
    /// decided (0: none open, or halted).
    pub fn open_read_clocks(&self) -> u32 {
        if self.halted {
            return 0;
        }
        self.reads.open_clocks()
    }

    /// CAN clocks still needed to decide every comparison already under
    /// way: an SR read waiting for its look-ahead window, a pin mismatch
    /// within its tolerance, a sample point not yet in the middle of its tx
    /// window. A run must not end before them, or what the host read last
    /// goes uncompared ([`crate::Testbench::settle`]). 0 when halted.
    pub fn open_clocks(&self) -> u32 {
        if self.halted {
            return 0;
        }
        self.reads.open_clocks().max(self.pins.open_clocks()).max(self.tx.open_clocks())
    }
}

/// The reference's field is one where a start of frame comes from bus idle.
#[inline]
fn idle(field: Option<Field>) -> bool {
    matches!(field, Some(Field::BusIdle | Field::Intermission | Field::SuspendTransmission))
}

/// The name of a read the status window judged (SR, IR, or a PeliCAN
/// status register: only the PeliCAN view's are judged so).
fn status_label(addr: u8) -> String {
    match addr {
        14 => "RXERR".into(),
        15 => "TXERR".into(),
        RMC_ADDR => "RMC".into(),
        a => reg_label(a),
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
mod before;

#[cfg(test)]
mod tests;
