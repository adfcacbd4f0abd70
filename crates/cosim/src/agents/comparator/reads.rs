//! The register-read checker: every read is compared exactly, except SR,
//! IR and the PeliCAN view's RXERR, TXERR and RMC, whose values change at
//! implementation-defined instants of an event: the error counters at the
//! error or success that moves them, as SR.ES does; RMC when a message is
//! stored, as RBS and RI. A read of those matches if the reference held the
//! same value at some CAN clock within `status_tolerance` clocks before it
//! (IR: only before the reference took the read, which clears its flags);
//! an SR read that matches nothing yet waits up to as many clocks for the
//! reference to take that value. The PeliCAN three look back only: the
//! model moves them at the earliest instant of their event. The coordinator ([`super::Comparator`]) judges what it
//! reports (collect-mode repeats, divergences).

use std::collections::VecDeque;

use super::{IR_ADDR, PELI_STATUS_ADDRS, SR_ADDR, Stamp};

/// A read the checker has not accepted (yet).
#[derive(Clone, Debug)]
pub(super) struct PendingRead {
    pub(super) addr: u8,
    pub(super) dut: u8,
    pub(super) model: u8,
    clocks_left: u32,
    pub(super) stamp: Stamp,
}

/// What a read comes to, for the coordinator.
pub(super) enum ReadVerdict {
    /// The reference held the DUT's value within the window.
    Tolerated,
    /// An SR read waiting for the reference to take the DUT's value.
    Waiting,
    /// A difference.
    Differs,
}

/// The status histories, the reads waiting for their window, the last
/// tolerated read.
pub(super) struct ReadChecker {
    status_tolerance: u32,
    /// Status history for tolerant reads: the last `status_tolerance + 1`
    /// values of SR and IR, kept as runs (value, index of its first clock
    /// in `status_pushed`).
    status_pushed: u64,
    sr_hist: VecDeque<(u8, u64)>,
    ir_hist: VecDeque<(u8, u64)>,
    /// RXERR's, TXERR's and RMC's histories ([`PELI_STATUS_ADDRS`]): 256
    /// while the reference is in BasicCAN.
    peli_hist: [VecDeque<(u16, u64)>; 3],
    /// The newest SR, IR, RXERR, TXERR and RMC of the histories (256: none
    /// yet; the PeliCAN three at 256: BasicCAN, 257: none yet).
    sr_last: u16,
    ir_last: u16,
    peli_last: [u16; 3],
    pending: Vec<PendingRead>,
    /// `status_pushed` when the reference took the read now under way, if
    /// it took it before the DUT's ack ([`ReadChecker::reference_read_taken`]).
    read_taken_at: Option<u64>,
    /// The last read, if the status tolerance accepted it (DUT and model
    /// differed at the read): see [`super::Comparator::hold_tolerated_read`].
    tolerated_read: Option<PendingRead>,
}

impl ReadChecker {
    pub(super) fn new(status_tolerance: u32) -> ReadChecker {
        ReadChecker {
            status_tolerance,
            status_pushed: 0,
            sr_hist: VecDeque::new(),
            ir_hist: VecDeque::new(),
            peli_hist: Default::default(),
            sr_last: 256,
            ir_last: 256,
            peli_last: [257; 3],
            pending: Vec::new(),
            read_taken_at: None,
            tolerated_read: None,
        }
    }

    /// Nothing to do this clock but count it: no read waiting, the same SR
    /// and IR as the last clock.
    #[inline]
    pub(super) fn quiet(&self, sr: u8, ir: u8, peli: Option<[u8; 3]>) -> bool {
        self.pending.is_empty() && sr as u16 == self.sr_last && ir as u16 == self.ir_last && peli_codes(peli) == self.peli_last
    }

    /// A [`ReadChecker::quiet`] clock.
    #[inline]
    pub(super) fn quiet_clock(&mut self) {
        self.status_pushed += 1;
    }

    /// `n` [`ReadChecker::quiet`] clocks in a row.
    pub(super) fn quiet_clocks(&mut self, n: u32) {
        self.status_pushed += u64::from(n);
    }

    /// Any other clock: the reference's SR, IR and PeliCAN three into the
    /// histories; the waiting SR reads look forward. Reads whose window closed go to
    /// `expired` (in order); returns how many were accepted this clock.
    pub(super) fn clock(&mut self, sr: u8, ir: u8, peli: Option<[u8; 3]>, expired: &mut Vec<PendingRead>) -> u64 {
        // Status history for tolerant reads (runs of equal values).
        let at = self.status_pushed;
        self.status_pushed += 1;
        if sr as u16 != self.sr_last {
            self.sr_last = sr as u16;
            self.sr_hist.push_back((sr, at));
            prune_runs(&mut self.sr_hist, self.status_pushed, self.status_tolerance);
        }
        if ir as u16 != self.ir_last {
            self.ir_last = ir as u16;
            self.ir_hist.push_back((ir, at));
            prune_runs(&mut self.ir_hist, self.status_pushed, self.status_tolerance);
        }
        let peli = peli_codes(peli);
        for k in 0..3 {
            if peli[k] != self.peli_last[k] {
                self.peli_last[k] = peli[k];
                self.peli_hist[k].push_back((peli[k], at));
                prune_runs(&mut self.peli_hist[k], self.status_pushed, self.status_tolerance);
            }
        }
        // Pending SR reads: look forward.
        let mut tolerated = 0;
        let mut k = 0;
        while k < self.pending.len() {
            let p = &mut self.pending[k];
            if p.addr == SR_ADDR && sr == p.dut {
                tolerated += 1;
                let p = self.pending.swap_remove(k);
                self.tolerated_read = Some(p);
                continue;
            }
            if p.clocks_left == 0 {
                expired.push(self.pending.swap_remove(k));
                continue;
            }
            p.clocks_left -= 1;
            k += 1;
        }
        tolerated
    }

    /// A read completes: forgets the last tolerated one and returns when the
    /// reference took it, if before the ack. First, halted or not.
    pub(super) fn begin_read(&mut self) -> Option<u64> {
        self.tolerated_read = None;
        self.read_taken_at.take()
    }

    /// A read that differs (`dut` != `model`): accepted by the status
    /// window, waiting for it (SR), or a difference. `taken_at`: from
    /// [`ReadChecker::begin_read`].
    pub(super) fn judge(&mut self, stamp: Stamp, addr: u8, dut: u8, model: u8, taken_at: Option<u64>) -> ReadVerdict {
        let (pushed, tol) = (self.status_pushed, self.status_tolerance);
        if let Some(k) = peli_index(addr) {
            // A status value only in the PeliCAN view; backward only: the
            // model moves these at the earliest instant of their event (the
            // sample point that decides it), so a core may be later, never
            // earlier. No read waits, so a difference is decided at once.
            if self.peli_last[k] >= 256 {
                return ReadVerdict::Differs;
            }
            prune_runs(&mut self.peli_hist[k], pushed, tol);
            if self.peli_hist[k].iter().any(|v| v.0 == dut as u16) {
                self.tolerated_read = Some(PendingRead { addr, dut, model, clocks_left: 0, stamp });
                return ReadVerdict::Tolerated;
            }
            return ReadVerdict::Differs;
        }
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
                self.tolerated_read = Some(PendingRead { addr, dut, model, clocks_left: 0, stamp });
                return ReadVerdict::Tolerated;
            }
            if addr == SR_ADDR && tol > 0 {
                self.pending.push(PendingRead { addr, dut, model, clocks_left: tol, stamp });
                return ReadVerdict::Waiting;
            }
        }
        ReadVerdict::Differs
    }

    /// The reference has just taken the read the DUT completes next.
    pub(super) fn reference_read_taken(&mut self) {
        self.read_taken_at = Some(self.status_pushed);
    }

    /// The last read, if the status window accepted it (taken: asked once).
    pub(super) fn take_tolerated(&mut self) -> Option<PendingRead> {
        self.tolerated_read.take()
    }

    /// Reads still waiting for their window to close.
    pub(super) fn pending(&self) -> usize {
        self.pending.len()
    }

    /// CAN clocks until every waiting read is decided (0: none).
    pub(super) fn open_clocks(&self) -> u32 {
        self.pending.iter().map(|p| p.clocks_left + 1).max().unwrap_or(0)
    }
}

/// The PeliCAN three in the histories' encoding: 256 for none (BasicCAN).
#[inline]
fn peli_codes(peli: Option<[u8; 3]>) -> [u16; 3] {
    peli.map_or([256; 3], |v| v.map(u16::from))
}

/// Index of `addr` among [`PELI_STATUS_ADDRS`].
#[inline]
fn peli_index(addr: u8) -> Option<usize> {
    PELI_STATUS_ADDRS.iter().position(|a| *a == addr)
}

/// Drops the runs that ended before the last `tolerance + 1` of `pushed`
/// clocks (a run ends where the next one starts; the last one is current).
#[inline]
fn prune_runs<T>(h: &mut VecDeque<(T, u64)>, pushed: u64, tolerance: u32) {
    let first = pushed.saturating_sub(tolerance as u64 + 1);
    while h.len() >= 2 && h[1].1 <= first {
        h.pop_front();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::types::RMC_ADDR;

    fn clock(c: &mut ReadChecker, sr: u8, ir: u8, expired: &mut Vec<PendingRead>) -> u64 {
        clock_rmc(c, sr, ir, None, expired)
    }

    fn clock_rmc(c: &mut ReadChecker, sr: u8, ir: u8, rmc: Option<u8>, expired: &mut Vec<PendingRead>) -> u64 {
        let peli = rmc.map(|r| [0, 0, r]);
        if c.quiet(sr, ir, peli) {
            c.quiet_clock();
            0
        } else {
            c.clock(sr, ir, peli, expired)
        }
    }

    #[test]
    fn a_status_read_matches_what_the_reference_held_within_the_window() {
        let mut c = ReadChecker::new(3);
        let mut ex = Vec::new();
        for sr in [0x0C, 0x0C, 0x1C, 0x1C] {
            clock(&mut c, sr, 0, &mut ex);
        }
        let s = Stamp::default();
        assert!(matches!(c.judge(s, SR_ADDR, 0x0C, 0x1C, None), ReadVerdict::Tolerated));
        assert!(c.take_tolerated().is_some() && c.take_tolerated().is_none());
        // Any other register is exact.
        assert!(matches!(c.judge(s, 4, 0x0C, 0x1C, None), ReadVerdict::Differs));
        // Out of the window: 4 more clocks of 0x1C.
        for _ in 0..4 {
            clock(&mut c, 0x1C, 0, &mut ex);
        }
        assert!(matches!(c.judge(s, IR_ADDR, 0x01, 0x00, None), ReadVerdict::Differs));
        // An SR value the reference never held waits for it ...
        assert!(matches!(c.judge(s, SR_ADDR, 0x3C, 0x1C, None), ReadVerdict::Waiting));
        assert_eq!((c.pending(), c.open_clocks()), (1, 4));
        assert_eq!(clock(&mut c, 0x3C, 0, &mut ex), 1, "taken within the window: accepted");
        assert_eq!(c.pending(), 0);
        // ... and expires after the window.
        assert!(matches!(c.judge(s, SR_ADDR, 0x7C, 0x3C, None), ReadVerdict::Waiting));
        for _ in 0..4 {
            clock(&mut c, 0x3C, 0, &mut ex);
        }
        assert_eq!(ex.len(), 1);
        assert_eq!((ex[0].addr, ex[0].dut, ex[0].model), (SR_ADDR, 0x7C, 0x3C));
    }

    #[test]
    fn an_ir_read_is_not_matched_by_what_the_reference_read_left_behind() {
        let mut c = ReadChecker::new(10);
        let mut ex = Vec::new();
        clock(&mut c, 0, 0x01, &mut ex);
        c.reference_read_taken();
        clock(&mut c, 0, 0x00, &mut ex);
        let taken = c.begin_read();
        // The DUT reads 0x00 (its IR after the read) where the model read 0x01.
        assert!(matches!(c.judge(Stamp::default(), IR_ADDR, 0x00, 0x01, taken), ReadVerdict::Differs));
        // Untaken, the same value would be held within the window.
        assert!(matches!(c.judge(Stamp::default(), IR_ADDR, 0x00, 0x01, None), ReadVerdict::Tolerated));
    }

    /// RMC counts a message at the instant RBS/RI report it, so in the
    /// PeliCAN view a DUT that counts it later within the window is
    /// accepted; earlier than the model, or later than the window, is a
    /// difference at once (no read waits); in BasicCAN (address 29 is a
    /// receive buffer byte) it is exact always.
    #[test]
    fn rmc_has_the_status_window_in_pelican_only() {
        let mut c = ReadChecker::new(3);
        let mut ex = Vec::new();
        let s = Stamp::default();
        for rmc in [0, 0, 1, 1] {
            clock_rmc(&mut c, 0, 0, Some(rmc), &mut ex);
        }
        // The DUT counts the message 2 clocks late: tolerated.
        assert!(matches!(c.judge(s, RMC_ADDR, 0, 1, None), ReadVerdict::Tolerated));
        // A count the reference never had (or has not had yet): a difference.
        assert!(matches!(c.judge(s, RMC_ADDR, 2, 1, None), ReadVerdict::Differs));
        // Late by more than the window: a difference.
        for _ in 0..4 {
            clock_rmc(&mut c, 0, 0, Some(1), &mut ex);
        }
        assert!(matches!(c.judge(s, RMC_ADDR, 0, 1, None), ReadVerdict::Differs));
        assert!(ex.is_empty() && c.pending() == 0, "no read waits");
        // BasicCAN: address 29 is data, exact.
        let mut b = ReadChecker::new(3);
        for _ in 0..4 {
            clock_rmc(&mut b, 0, 0, None, &mut ex);
        }
        assert!(matches!(b.judge(s, RMC_ADDR, 0, 1, None), ReadVerdict::Differs));
    }

    /// The error counters have the window too (PeliCAN), backward: RXERR
    /// counted up by the model at a sample point and by the DUT two clocks
    /// later is tolerated; a count the model never had (a +8 for a +1) is
    /// not; TXERR is exact in BasicCAN (address 15 is a TX buffer byte).
    #[test]
    fn error_counters_have_the_status_window_in_pelican() {
        let mut c = ReadChecker::new(4);
        let mut ex = Vec::new();
        let s = Stamp::default();
        for rec in [0x77, 0x77, 0x78, 0x78] {
            let peli = Some([rec, 0x00, 0]);
            if c.quiet(0, 0, peli) {
                c.quiet_clock();
            } else {
                c.clock(0, 0, peli, &mut ex);
            }
        }
        assert!(matches!(c.judge(s, 14, 0x77, 0x78, None), ReadVerdict::Tolerated));
        assert!(matches!(c.judge(s, 14, 0x7F, 0x78, None), ReadVerdict::Differs));
        assert!(matches!(c.judge(s, 15, 0x08, 0x00, None), ReadVerdict::Differs));
        let mut b = ReadChecker::new(4);
        b.clock(0, 0, None, &mut ex);
        assert!(matches!(b.judge(s, 14, 0x77, 0x77, None), ReadVerdict::Differs));
    }
}
