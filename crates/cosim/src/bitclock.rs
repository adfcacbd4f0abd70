//! The test bench's own bit clock: finds the sample points on the bus from
//! the programmed bit timing (BTR0/BTR1), hard-synchronising on every
//! recessive-to-dominant edge. It stamps bits for the record and the VCD,
//! and tells the comparator where to compare tx, when the reference does
//! not report its own sample points.

use can_proto::timing::BusTiming;

/// Sample-point finder on a bus level sampled once per CAN clock.
#[derive(Clone, Debug)]
pub struct BitClock {
    timing: BusTiming,
    count: u32,
    prev: bool,
    bits: u64,
    /// `sample_clock()` and `clocks_per_bit()` of `timing`, kept (asked every clock).
    sample_at: u32,
    per_bit: u32,
}

impl BitClock {
    /// A bit clock for `timing`, bus idle (recessive).
    pub fn new(timing: BusTiming) -> BitClock {
        let mut c = BitClock {
            timing,
            count: 0,
            prev: true,
            bits: 0,
            sample_at: 0,
            per_bit: 0,
        };
        c.set_timing(timing);
        c
    }

    /// Changes the timing (the host wrote BTR0/BTR1).
    pub fn set_timing(&mut self, timing: BusTiming) {
        self.timing = timing;
        self.count = 0;
        self.sample_at = self.sample_clock();
        self.per_bit = self.clocks_per_bit();
    }

    /// The timing in use.
    pub fn timing(&self) -> BusTiming {
        self.timing
    }

    /// CAN clocks per bit.
    pub fn clocks_per_bit(&self) -> u32 {
        self.timing.clocks_per_bit()
    }

    /// Index within the bit of the clock at which the bus is sampled: the
    /// last clock of TSEG1.
    pub fn sample_clock(&self) -> u32 {
        (1 + self.timing.tseg1 as u32 + 1) * self.timing.clocks_per_tq() - 1
    }

    /// CAN clocks since the start of the current bit.
    pub fn sub(&self) -> u32 {
        self.count
    }

    /// Bits sampled so far.
    pub fn bits(&self) -> u64 {
        self.bits
    }

    /// Index (in `bits()` numbering) of the bit whose sync segment started
    /// last, asked before [`BitClock::clock`] for the coming clock: unlike
    /// `bits()` it advances at the bit boundary, not at the sample point.
    /// Faults aimed at one bit use it, so a flipped bit spans the whole bit
    /// time and every node whose sample point lies anywhere in that bit (a
    /// DUT and a reference a few clocks apart) sees it in the same bit; a
    /// window from sample point to sample point put its edge next to one
    /// node's sample point and into another's previous bit.
    pub fn bit_in_progress(&self) -> u64 {
        self.bits - u64::from(self.count > self.sample_at)
    }

    /// How many of the next clocks, with the bus staying at `level`, are
    /// not sample points (0 if the level differs from the last clock's: an
    /// edge may hard-synchronise). `count` is below `per_bit` and
    /// `sample_at` below `per_bit` (see `set_timing`).
    #[inline]
    pub fn clocks_before_sample(&self, level: bool) -> u32 {
        if self.prev != level {
            return 0;
        }
        if self.count <= self.sample_at {
            self.sample_at - self.count
        } else {
            self.per_bit - self.count + self.sample_at
        }
    }

    /// `n` clocks with the bus at the last clock's level, none of them a
    /// sample point (`n` at most [`BitClock::clocks_before_sample`] of that
    /// level): what `clock` does `n` times.
    #[inline]
    pub fn quiet_clocks(&mut self, n: u32) {
        debug_assert!(n <= self.clocks_before_sample(self.prev));
        // Below two bits' worth (see `clocks_before_sample`): one wrap at most.
        self.count += n;
        if self.count >= self.per_bit {
            self.count -= self.per_bit;
        }
    }

    /// One CAN clock with bus `level`; true if this clock is a sample point.
    #[inline]
    pub fn clock(&mut self, level: bool) -> bool {
        if self.prev && !level {
            self.count = 0;
        }
        self.prev = level;
        let sample = self.count == self.sample_at;
        self.count += 1;
        if self.count >= self.per_bit {
            self.count = 0;
        }
        if sample {
            self.bits += 1;
        }
        sample
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clocks_before_sample_counts_exactly_the_clocks_that_do_not_sample() {
        let t = BusTiming::from_btr(0x41, 0x25);
        let mut c = BitClock::new(t);
        for level in [true, false] {
            // A level change first (its falling edge hard-synchronises): no promise.
            if c.prev != level {
                assert_eq!(c.clocks_before_sample(level), 0);
                c.clock(level);
            }
            for _ in 0..200 {
                let n = c.clocks_before_sample(level);
                let mut probe = c.clone();
                for k in 0..n {
                    assert!(!probe.clock(level), "clock {k} of {n} promised quiet sampled");
                }
                assert!(probe.clock(level), "the clock after the {n} quiet ones samples");
                c.clock(level);
            }
        }
    }

    #[test]
    fn samples_once_per_bit_at_the_end_of_tseg1_after_hard_sync() {
        // Thesis timing: BTR0 0x41 (BRP 1: 4 clocks/tq), BTR1 0x25 (TSEG1 5, TSEG2 2): 10 tq.
        let t = BusTiming::from_btr(0x41, 0x25);
        let mut c = BitClock::new(t);
        assert_eq!(c.clocks_per_bit(), 40);
        assert_eq!(c.sample_clock(), 27);
        let mut samples = Vec::new();
        // 3 recessive bits then a dominant edge at clock 100, then 3 bits dominant.
        for k in 0..(100 + 120) {
            let level = k < 100;
            if c.clock(level) {
                samples.push(k);
            }
        }
        assert_eq!(
            samples,
            vec![27, 67, 127, 167, 207],
            "free-running, then re-synced at clock 100"
        );
        assert_eq!(c.bits(), 5);
    }

    #[test]
    fn the_bit_in_progress_advances_at_the_bit_boundary_not_at_the_sample_point() {
        // 40 clocks a bit, sample clock 27; a dominant edge (hard sync) at clock 100.
        let t = BusTiming::from_btr(0x41, 0x25);
        let mut c = BitClock::new(t);
        let mut starts = Vec::new();
        let mut last = c.bit_in_progress();
        for k in 0..(100 + 120) {
            let level = k < 100;
            // Asked before the clock, as the bench's fault context is.
            let now = c.bit_in_progress();
            if now != last {
                starts.push(k);
                last = now;
            }
            c.clock(level);
        }
        // Bits start at 40 and 80; the hard sync at 100 restarts bit 2 (its
        // sample point comes at 127), so the next starts at 140, then 180.
        // Never at a sample point (27, 67, 127, 167), where bits() advances.
        assert_eq!(starts, vec![40, 80, 140, 180]);
    }
}
