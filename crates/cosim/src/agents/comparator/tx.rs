//! The tx checker: which sample points of the DUT's `tx_o` are compared
//! with the reference's, and with which levels. Not within
//! `tx_edge_tolerance` CAN clocks of a reference tx edge (a window centred
//! on the sample point: where an implementation puts its edge within the
//! sync segment is its own business), and not while a start of frame from
//! bus idle is excused (`sof_tolerance`: either side may go first; the lag
//! measured at the SOF is kept for the frame, the earlier side's tx delayed
//! by it). The coordinator ([`super::Comparator`]) judges what it returns.

use std::collections::VecDeque;

use super::{CompareConfig, Stamp};
use crate::types::CanPins;

/// A sample point waiting to reach the middle of the tx window.
#[derive(Clone, Copy, Debug)]
pub(super) struct TxSample {
    /// Its position in the window's push sequence.
    index: u64,
    /// Inside a start-of-frame grace window: not compared.
    excused: bool,
    pub(super) ref_tx: bool,
    pub(super) dut_tx: bool,
    sample: bool,
    pub(super) stamp: Stamp,
}

/// The tx window, the start-of-frame grace and the collect-mode tx latch.
pub(super) struct TxChecker {
    edge_tolerance: u32,
    sof_tolerance: u32,
    /// Clocks pushed into the tx window and the tx histories (every clock
    /// compared while not halted). The window is the last `2 * tol + 1`
    /// pushes; only what its check needs is kept: the sample points not
    /// yet in the middle, and where the (delayed) reference tx last changed.
    pushed: u64,
    samples: VecDeque<TxSample>,
    /// Push index of the last change of the window's reference tx.
    ref_changed_at: u64,
    last_win_ref_tx: bool,
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
    /// Collect mode: a tx difference was listed; its frame's later
    /// mismatches are its cascade (see [`super::Comparator::resume`]).
    pub(super) latched: bool,
    /// Frame in which tx was latched.
    pub(super) latch_frame: Option<u32>,
}

impl TxChecker {
    pub(super) fn new(cfg: &CompareConfig) -> TxChecker {
        TxChecker {
            edge_tolerance: cfg.tx_edge_tolerance,
            sof_tolerance: cfg.sof_tolerance,
            pushed: 0,
            samples: VecDeque::new(),
            ref_changed_at: 0,
            last_win_ref_tx: true,
            prev_ref_tx: true,
            prev_dut_tx: true,
            prev_idle: false,
            sof_grace: 0,
            grace_count: 0,
            grace_by_ref: false,
            ref_off: 0,
            dut_off: 0,
            tx_hist: TxRing::new(cfg.sof_tolerance as u64 + 1),
            latched: false,
            latch_frame: None,
        }
    }

    /// Nothing to do this clock but push it: not a sample point, no sample
    /// point in the window, no start of frame being excused, no offsets,
    /// and the same tx on both sides as the last clock (so no tx edge: no
    /// start of frame, no window change to check).
    #[inline]
    pub(super) fn quiet(&self, sample: bool, reference: &CanPins, dut: &CanPins) -> bool {
        !sample
            && self.samples.is_empty()
            && self.sof_grace == 0
            && (self.ref_off | self.dut_off) == 0
            && reference.tx == self.prev_ref_tx
            && reference.tx == self.last_win_ref_tx
            && dut.tx == self.prev_dut_tx
    }

    /// How many of the next clocks, none a sample point, with these inputs,
    /// [`TxChecker::clock`] does no more than [`TxChecker::quiet_clock`]
    /// (push them): the conditions of [`TxChecker::quiet`] but for sample
    /// points waiting in the window, until the first of those reaches its
    /// middle (before that, no sample point is popped or judged).
    #[inline]
    pub(super) fn quiet_for(&self, reference: &CanPins, dut: &CanPins) -> u32 {
        if !(self.sof_grace == 0
            && (self.ref_off | self.dut_off) == 0
            && reference.tx == self.prev_ref_tx
            && reference.tx == self.last_win_ref_tx
            && dut.tx == self.prev_dut_tx)
        {
            return 0;
        }
        match self.samples.front() {
            None => u32::MAX,
            // Judged (or dropped) at the push with index `index + tol`.
            Some(m) => (m.index + u64::from(self.edge_tolerance)).saturating_sub(self.pushed).min(u64::from(u32::MAX)) as u32,
        }
    }

    /// A [`TxChecker::quiet`] clock, or one of [`TxChecker::quiet_for`]'s.
    #[inline]
    pub(super) fn quiet_clock(&mut self, reference: &CanPins, dut: &CanPins, idle_now: bool) {
        let pushed = self.pushed;
        self.pushed += 1;
        self.tx_hist.push(pushed, reference.tx as u8 | (dut.tx as u8) << 1);
        self.prev_idle = idle_now;
    }

    /// `n` [`TxChecker::quiet`] clocks in a row with these inputs: what
    /// `n` calls of [`TxChecker::quiet_clock`] do.
    pub(super) fn quiet_clocks(&mut self, n: u32, reference: &CanPins, dut: &CanPins, idle_now: bool) {
        let v = reference.tx as u8 | (dut.tx as u8) << 1;
        self.tx_hist.push_n(self.pushed, u64::from(n), v);
        self.pushed += u64::from(n);
        self.prev_idle = idle_now;
    }

    /// Any other clock: the sample point that reached the middle of its
    /// window this clock, if it is to be compared (a sample point, not
    /// excused, not before `skip_until_bit`, the reference tx stable over
    /// the window).
    #[inline]
    pub(super) fn clock(
        &mut self,
        stamp: Stamp,
        sample: bool,
        reference: &CanPins,
        dut: &CanPins,
        idle_now: bool,
        skip_until_bit: u64,
    ) -> Option<TxSample> {
        // tx with an edge-tolerance window centred on the checked clock.
        let tol = self.edge_tolerance as usize;
        let pushed = self.pushed;
        self.pushed += 1;
        self.tx_hist.push(pushed, reference.tx as u8 | (dut.tx as u8) << 1);
        // Start of frame from bus idle: either side may go first, and the
        // shadow model never hard-synchronises on the DUT's SOF (it is not
        // on the bus), so the lag measured at the SOF is kept for the whole
        // frame: the earlier side's tx is delayed by it before comparing.
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
                && (self.prev_idle || stamp.field == Some(can_proto::Field::Sof))
                && reference.tx != dut.tx
                && self.sof_tolerance > 0
            {
                self.sof_grace = self.sof_tolerance;
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
        let n = self.pushed.min(self.sof_tolerance as u64 + 1);
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
                if mid.sample && !mid.excused && mid.stamp.bit >= skip_until_bit {
                    let stable = self.ref_changed_at <= pushed - width;
                    if stable {
                        return Some(mid);
                    }
                }
            }
        }
        None
    }

    /// CAN clocks until every sample point in the window is decided.
    pub(super) fn open_clocks(&self) -> u32 {
        if self.samples.is_empty() { 0 } else { 2 * self.edge_tolerance + 1 }
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

    /// Stores `v` as push numbers `index..index + n`: once the buffer
    /// wraps, only the last `size` of them are kept anyway.
    fn push_n(&mut self, index: u64, n: u64, v: u8) {
        while !self.full && index + n > self.buf.len() as u64 {
            self.grow();
        }
        let kept = n.min(self.buf.len() as u64);
        for i in index + n - kept..index + n {
            self.buf[(i & self.mask) as usize] = v;
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn pins(tx: bool) -> CanPins {
        CanPins { tx, irq_n: true, bus_on: true, clkout: false }
    }

    /// The sample points the checker hands on, as (bit, model tx, DUT tx).
    fn compared(cfg: &CompareConfig, ref_tx: &[bool], dut_tx: &[bool], samples: &[usize], skip: u64) -> Vec<(u64, bool, bool)> {
        let mut t = TxChecker::new(cfg);
        let mut out = Vec::new();
        for k in 0..ref_tx.len() {
            let s = Stamp { t_ps: k as u64, bit: k as u64, ..Stamp::default() };
            let (r, d, sample) = (pins(ref_tx[k]), pins(dut_tx[k]), samples.contains(&k));
            if t.quiet(sample, &r, &d) {
                t.quiet_clock(&r, &d, false);
            } else if let Some(m) = t.clock(s, sample, &r, &d, false, skip) {
                out.push((m.stamp.bit, m.ref_tx, m.dut_tx));
            }
        }
        out
    }

    #[test]
    fn a_sample_point_is_handed_on_once_its_window_is_full_and_stable() {
        let cfg = CompareConfig { tx_edge_tolerance: 2, sof_tolerance: 0, ..CompareConfig::default() };
        let rec = [true; 12];
        let mut dut = [true; 12];
        dut[5] = false;
        // Sample points at 5 and 9: both handed on (2 clocks later), with their levels.
        assert_eq!(compared(&cfg, &rec, &dut, &[5, 9], 0), vec![(5, true, false), (9, true, true)]);
        // Skipped bits are not.
        assert_eq!(compared(&cfg, &rec, &dut, &[5, 9], 6), vec![(9, true, true)]);
        // A reference edge within 2 clocks of the sample point: not compared.
        let mut edge = [true; 12];
        for e in edge.iter_mut().skip(4) {
            *e = false;
        }
        assert_eq!(compared(&cfg, &edge, &edge, &[5, 9], 0), vec![(9, false, false)]);
        // The window stays open until the sample point reaches its middle.
        let mut t = TxChecker::new(&cfg);
        let (r, s) = (pins(true), Stamp::default());
        assert!(t.clock(s, true, &r, &r, false, 0).is_none());
        assert_eq!(t.open_clocks(), 5);
    }
}
