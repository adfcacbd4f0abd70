//! The one owner of time: picoseconds in a `u64`, and two independent
//! clocks, the CAN clock `clk_i` and the host clock `wb_clk_i` (24 MHz and
//! 50 MHz on the DE2). Edge times are computed from the edge index with
//! integer arithmetic, so a run is exactly reproducible and never drifts.

/// A free-running clock starting low at t = 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClockGen {
    freq_hz: u64,
    /// Edges already made.
    edges: u64,
    level: bool,
    /// Time of edge `edges + 1`, ps: n half periods rounded down, kept as
    /// quotient and remainder of `n * 1e12 / (2 f)` so each edge costs an
    /// add and a compare instead of a 128-bit division.
    next_t: u64,
    /// `(edges + 1) * 1e12 - next_t * 2 f`, always below `2 f`.
    next_rem: u64,
    /// Half period, ps: `1e12 / (2 f)` and its remainder.
    half_q: u64,
    half_r: u64,
}

/// Picoseconds per second.
const PS_PER_S: u64 = 1_000_000_000_000;

impl ClockGen {
    fn new(freq_hz: u64) -> ClockGen {
        let d = 2 * freq_hz;
        let (half_q, half_r) = (PS_PER_S / d, PS_PER_S % d);
        ClockGen {
            freq_hz,
            edges: 0,
            level: false,
            next_t: half_q,
            next_rem: half_r,
            half_q,
            half_r,
        }
    }

    /// Time of edge number `n` (n >= 1): n half periods, rounded down.
    #[cfg(test)]
    fn edge_time(&self, n: u64) -> u64 {
        ((n as u128 * PS_PER_S as u128) / (2 * self.freq_hz as u128)) as u64
    }

    #[inline(always)]
    fn next_edge(&self) -> u64 {
        self.next_t
    }

    /// Makes the next edge.
    #[inline(always)]
    fn step(&mut self) {
        self.edges += 1;
        self.level = !self.level;
        self.next_t += self.half_q;
        self.next_rem += self.half_r;
        let d = 2 * self.freq_hz;
        if self.next_rem >= d {
            self.next_rem -= d;
            self.next_t += 1;
        }
    }

    /// Frequency in Hz.
    pub fn freq_hz(&self) -> u64 {
        self.freq_hz
    }

    /// Rising edges so far (completed cycles).
    pub fn cycles(&self) -> u64 {
        self.edges.div_ceil(2)
    }

    /// Current level.
    pub fn level(&self) -> bool {
        self.level
    }
}

/// What changed at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tick {
    /// Time of the instant, ps.
    pub t_ps: u64,
    /// The host clock rose.
    pub host_rise: bool,
    /// The host clock fell.
    pub host_fall: bool,
    /// The CAN clock rose.
    pub can_rise: bool,
    /// The CAN clock fell.
    pub can_fall: bool,
}

/// Bad kernel configuration.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum KernelError {
    /// A clock of 0 Hz or above 500 GHz (one edge per picosecond).
    #[error("{which} clock frequency {hz} Hz is out of range (1 Hz ..= 500 GHz)")]
    BadFrequency {
        /// Which clock.
        which: &'static str,
        /// The value given.
        hz: u64,
    },
}

/// Time and the two clocks.
#[derive(Clone, Debug)]
pub struct Kernel {
    now_ps: u64,
    host: ClockGen,
    can: ClockGen,
}

impl Kernel {
    /// Clocks of `host_hz` (`wb_clk_i`) and `can_hz` (`clk_i`).
    pub fn new(host_hz: u64, can_hz: u64) -> Result<Kernel, KernelError> {
        for (which, hz) in [("host", host_hz), ("CAN", can_hz)] {
            if hz == 0 || hz > 500_000_000_000 {
                return Err(KernelError::BadFrequency { which, hz });
            }
        }
        Ok(Kernel {
            now_ps: 0,
            host: ClockGen::new(host_hz),
            can: ClockGen::new(can_hz),
        })
    }

    /// Advances to the next instant at which either clock changes, and
    /// says which edges happened (both clocks may change at once).
    #[inline]
    pub fn advance(&mut self) -> Tick {
        let th = self.host.next_edge();
        let tc = self.can.next_edge();
        let t = th.min(tc);
        self.now_ps = t;
        let mut tick = Tick {
            t_ps: t,
            ..Tick::default()
        };
        if th == t {
            self.host.step();
            tick.host_rise = self.host.level;
            tick.host_fall = !self.host.level;
        }
        if tc == t {
            self.can.step();
            tick.can_rise = self.can.level;
            tick.can_fall = !self.can.level;
        }
        tick
    }

    /// Makes the next instants as [`Kernel::advance`] would, until
    /// `levels` is full or the instant with the `can_rises`-th CAN rising
    /// edge (`can_rises` >= 1), and returns how many. Per instant `k`:
    /// `times[k]` its time, `levels[k]` bit 0 the host clock level after
    /// it, bit 1 the CAN clock level, bit 2 "the CAN clock rose", bit 3
    /// "the host clock rose" (the layout of `verilated::Batch`, which ignores
    /// bit 3). `times` is at least as long as `levels`. Not inlined: in a
    /// function of its own the clock's state stays in registers.
    #[inline(never)]
    pub(crate) fn plan(&mut self, levels: &mut [u8], times: &mut [u64], can_rises: u64) -> usize {
        let times = &mut times[..levels.len()];
        let (mut n, mut rises) = (0, 0);
        if self.host == self.can {
            // One clock twice (same frequency and phase, as when the host
            // and the CAN clock are one): every instant moves both, and a
            // rise of one is a rise of both. Rises and falls alternate, so
            // the count of instants is known up front; then the levels
            // and the times (`ClockGen::step` with its fields in locals)
            // in loops of their own.
            let mut c = self.can;
            // The next instant is a rise when the clock is low now.
            let first_up = !c.level;
            let to_rise = can_rises.saturating_mul(2).saturating_sub(first_up as u64);
            n = levels.len().min(usize::try_from(to_rise).unwrap_or(usize::MAX));
            for (k, l) in levels[..n].iter_mut().enumerate() {
                *l = (first_up as u8 ^ (k & 1) as u8) * 0b1111;
            }
            let (mut t, mut rem) = (c.next_t, c.next_rem);
            let d = 2 * c.freq_hz;
            for tk in &mut times[..n] {
                *tk = t;
                t += c.half_q;
                rem += c.half_r;
                if rem >= d {
                    rem -= d;
                    t += 1;
                }
            }
            (c.next_t, c.next_rem) = (t, rem);
            c.level ^= n % 2 == 1;
            c.edges += n as u64;
            if n > 0 {
                self.now_ps = times[n - 1];
            }
            self.host = c;
            self.can = c;
            return n;
        }
        while n < levels.len() && rises < can_rises {
            let t = self.advance();
            rises += t.can_rise as u64;
            levels[n] = self.host.level as u8
                | (self.can.level as u8) << 1
                | (t.can_rise as u8) << 2
                | (t.host_rise as u8) << 3;
            times[n] = t.t_ps;
            n += 1;
        }
        n
    }

    /// Current time, ps.
    pub fn now_ps(&self) -> u64 {
        self.now_ps
    }

    /// The host clock.
    pub fn host(&self) -> &ClockGen {
        &self.host
    }

    /// The CAN clock.
    pub fn can(&self) -> &ClockGen {
        &self.can
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_clocks_interleave_exactly_and_deterministically() {
        let mut k = Kernel::new(50_000_000, 24_000_000).unwrap();
        let mut host_rises = Vec::new();
        let mut can_rises = Vec::new();
        while k.now_ps() < 1_000_000 {
            let t = k.advance();
            if t.host_rise {
                host_rises.push(t.t_ps);
            }
            if t.can_rise {
                can_rises.push(t.t_ps);
            }
        }
        // 50 MHz: 20 ns period, first rise at 10 ns; 24 MHz: 41.666 ns.
        assert_eq!(&host_rises[..3], &[10_000, 30_000, 50_000]);
        assert_eq!(&can_rises[..3], &[20_833, 62_500, 104_166]);
        assert_eq!(host_rises.len(), 50);
        assert_eq!(can_rises.len(), 24);
        assert_eq!(k.host().cycles(), 50);
        // 24 edges of 24 MHz in 1 us: no drift.
        let mut k2 = Kernel::new(50_000_000, 24_000_000).unwrap();
        let mut again = Vec::new();
        while k2.now_ps() < 1_000_000 {
            let t = k2.advance();
            if t.can_rise {
                again.push(t.t_ps);
            }
        }
        assert_eq!(again, can_rises);
    }

    #[test]
    fn incremental_edge_times_equal_the_division() {
        for hz in [
            1,
            3,
            7_000_001,
            24_000_000,
            50_000_000,
            33_333_333,
            500_000_000_000,
        ] {
            let mut c = ClockGen::new(hz);
            for n in 1..=20_000u64 {
                assert_eq!(c.next_edge(), c.edge_time(n), "{hz} Hz edge {n}");
                c.step();
            }
        }
    }

    /// `plan` makes the instants `advance` makes, with one clock or two
    /// (locked or not), up to the CAN rise asked for or a full buffer.
    #[test]
    fn plan_is_advance_instant_for_instant() {
        for (host, can) in [
            (24_000_000, 24_000_000),
            (50_000_000, 24_000_000),
            (24_000_000, 50_000_000),
            (10_000_000, 10_000_000),
            (33_333_333, 7_000_001),
        ] {
            let mut planned = Kernel::new(host, can).unwrap();
            let mut stepped = planned.clone();
            for (round, &(len, rises)) in [(512, u64::MAX), (100, 7), (3, 1), (512, 200), (1, 1)]
                .iter()
                .cycle()
                .take(40)
                .enumerate()
            {
                let (mut lv, mut tm) = (vec![0u8; len], vec![0u64; len]);
                let n = planned.plan(&mut lv, &mut tm, rises);
                assert!(n >= 1, "{host}/{can} round {round}");
                let mut seen = 0;
                for k in 0..n {
                    let t = stepped.advance();
                    seen += t.can_rise as u64;
                    let want = stepped.host().level() as u8
                        | (stepped.can().level() as u8) << 1
                        | (t.can_rise as u8) << 2
                        | (t.host_rise as u8) << 3;
                    assert_eq!(
                        (lv[k], tm[k]),
                        (want, t.t_ps),
                        "{host}/{can} round {round} instant {k}"
                    );
                }
                assert!(
                    n == len || seen == rises,
                    "{host}/{can} round {round}: stopped early"
                );
                assert!(
                    seen <= rises,
                    "{host}/{can} round {round}: went past the rise"
                );
                assert_eq!(planned.now_ps(), stepped.now_ps());
                assert_eq!(planned.host(), stepped.host());
                assert_eq!(planned.can(), stepped.can());
            }
        }
    }

    #[test]
    fn simultaneous_edges_come_in_one_tick() {
        let mut k = Kernel::new(10_000_000, 10_000_000).unwrap();
        let t = k.advance();
        assert!(t.host_rise && t.can_rise);
        let t = k.advance();
        assert!(t.host_fall && t.can_fall);
    }

    #[test]
    fn zero_frequency_is_an_error() {
        assert_eq!(
            Kernel::new(0, 1).unwrap_err(),
            KernelError::BadFrequency {
                which: "host",
                hz: 0
            }
        );
    }
}
