//! The 8051 host bus's timing in nanoseconds, and its host-clock cycles at
//! a given host clock: an [`I8051AcTiming`] names each
//! phase of an Intel-mode access the way an AC-characteristics table
//! does (ALE pulse width, address hold after ALE, RD and WR pulse widths,
//! data set-up before and hold after WR), and
//! [`I8051AcTiming::cycles`] rounds each up to whole host cycles.
//!
//! Where the numbers come from. The authority for the minimums a
//! controller needs is the SJA1000 data sheet's AC characteristics table
//! (Philips/NXP, 2000 Jan 04, section 10, Intel mode). That table was not
//! in the reference material we could search (the data sheet's pages that
//! were found stop at the DC characteristics), so no value here is quoted
//! from it. The defaults are the kit's long-standing 50 MHz cycle counts
//! ([`crate::I8051Timing::default`]: one 12 MHz 80C51 `MOVX` cycle, the RD
//! strobe and recovery stretched for our `can_top_8051`) written in
//! nanoseconds, so that they keep their meaning at another host clock.
//! Every field is configurable: a user with the table enters its
//! minimums (plus the host's own margins) here.

use crate::I8051Timing;

/// Phase lengths of an 8051 access, nanoseconds (each a minimum the
/// master holds; rounded up to host cycles by [`I8051AcTiming::cycles`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct I8051AcTiming {
    /// ALE pulse width, the address driven (and set up) meanwhile.
    pub ale_ns: u32,
    /// Address hold after ALE falls.
    pub addr_hold_ns: u32,
    /// Read: port released before RD (bus turn-around).
    pub read_float_ns: u32,
    /// Write: data set up before WR is asserted.
    pub data_setup_ns: u32,
    /// RD pulse width.
    pub rd_ns: u32,
    /// WR pulse width.
    pub wr_ns: u32,
    /// Write: data (and CS) held after WR is released.
    pub data_hold_ns: u32,
    /// Idle time after an access.
    pub recovery_ns: u32,
}

impl Default for I8051AcTiming {
    /// [`I8051Timing::default`] at 50 MHz (20 ns per cycle), in ns.
    fn default() -> Self {
        I8051AcTiming {
            ale_ns: 120,
            addr_hold_ns: 40,
            read_float_ns: 160,
            data_setup_ns: 160,
            rd_ns: 760,
            wr_ns: 400,
            data_hold_ns: 40,
            recovery_ns: 260,
        }
    }
}

impl I8051AcTiming {
    /// Host cycles at `host_hz`: each phase rounded up, at least one cycle
    /// (a phase the master never shows could not be checked).
    pub fn cycles(&self, host_hz: u64) -> I8051Timing {
        let c = |ns: u32| ((ns as u64 * host_hz).div_ceil(1_000_000_000)).max(1) as u32;
        I8051Timing {
            ale: c(self.ale_ns),
            addr_hold: c(self.addr_hold_ns),
            read_float: c(self.read_float_ns),
            data_setup: c(self.data_setup_ns),
            rd: c(self.rd_ns),
            wr: c(self.wr_ns),
            data_hold: c(self.data_hold_ns),
            recovery: c(self.recovery_ns),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_are_the_50_mhz_cycle_counts() {
        assert_eq!(I8051AcTiming::default().cycles(50_000_000), I8051Timing::default());
    }

    #[test]
    fn cycles_round_up_and_scale_with_the_host_clock() {
        let t = I8051AcTiming::default();
        let at100 = t.cycles(100_000_000);
        assert_eq!((at100.ale, at100.rd, at100.recovery), (12, 76, 26));
        // 33 MHz: 30.3 ns per cycle; 120 ns is 3.96 cycles -> 4, 40 ns -> 2.
        let at33 = t.cycles(33_000_000);
        assert_eq!((at33.ale, at33.addr_hold, at33.wr), (4, 2, 14));
        // Never shorter than asked: cycles x period >= ns for every phase.
        for hz in [12_000_000u64, 24_000_000, 33_333_333, 50_000_000, 125_000_000] {
            let c = t.cycles(hz);
            for (cy, ns) in [(c.ale, t.ale_ns), (c.rd, t.rd_ns), (c.wr, t.wr_ns), (c.data_hold, t.data_hold_ns)] {
                assert!(cy as u64 * 1_000_000_000 >= ns as u64 * hz, "{hz} Hz: {cy} cycles < {ns} ns");
            }
        }
        let zero = I8051AcTiming { data_hold_ns: 0, ..t }.cycles(50_000_000);
        assert_eq!(zero.data_hold, 1, "at least one cycle");
    }
}
