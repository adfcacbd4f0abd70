//! Bit timing as the SJA1000 programs it in BTR0/BTR1 (datasheet §6.5.1-2):
//! BTR0 = SJW[7:6] BRP[5:0]; BTR1 = SAM[7] TSEG2[6:4] TSEG1[3:0].
//! One time quantum is 2 * (BRP + 1) CAN clock periods; a bit is
//! 1 (sync) + (TSEG1 + 1) + (TSEG2 + 1) quanta; the sample point is at the
//! end of TSEG1.

/// Decoded bus timing. Fields hold the register values (not the "+1" lengths).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BusTiming {
    /// Baud rate prescaler, 0..=63.
    pub brp: u8,
    /// Synchronisation jump width register value, 0..=3 (length SJW + 1 tq).
    pub sjw: u8,
    /// Time segment 1 register value, 0..=15 (length TSEG1 + 1 tq).
    pub tseg1: u8,
    /// Time segment 2 register value, 0..=7 (length TSEG2 + 1 tq).
    pub tseg2: u8,
    /// Triple sampling.
    pub sam: bool,
}

impl BusTiming {
    /// Decodes BTR0/BTR1.
    pub const fn from_btr(btr0: u8, btr1: u8) -> Self {
        BusTiming {
            brp: btr0 & 0x3f,
            sjw: btr0 >> 6,
            tseg1: btr1 & 0x0f,
            tseg2: (btr1 >> 4) & 0x07,
            sam: btr1 & 0x80 != 0,
        }
    }

    /// Encodes to (BTR0, BTR1).
    pub const fn to_btr(&self) -> (u8, u8) {
        (
            (self.sjw << 6) | (self.brp & 0x3f),
            ((self.sam as u8) << 7) | ((self.tseg2 & 7) << 4) | (self.tseg1 & 0x0f),
        )
    }

    /// CAN clock periods per time quantum: 2 * (BRP + 1).
    pub const fn clocks_per_tq(&self) -> u32 {
        2 * (self.brp as u32 + 1)
    }

    /// Time quanta per bit: sync + TSEG1 + TSEG2.
    pub const fn tq_per_bit(&self) -> u32 {
        1 + (self.tseg1 as u32 + 1) + (self.tseg2 as u32 + 1)
    }

    /// CAN clock periods per bit.
    pub const fn clocks_per_bit(&self) -> u32 {
        self.clocks_per_tq() * self.tq_per_bit()
    }

    /// Bit rate in bit/s for a CAN clock of `f_clk` Hz.
    pub fn bit_rate(&self, f_clk: f64) -> f64 {
        f_clk / self.clocks_per_bit() as f64
    }

    /// Sample point as a fraction of the bit time (end of TSEG1).
    pub fn sample_point(&self) -> f64 {
        (1 + self.tseg1 as u32 + 1) as f64 / self.tq_per_bit() as f64
    }

    /// Largest oscillator deviation per node (a fraction) that this timing
    /// absorbs, CAN 2.0B section 10: df <= min(PS1, PS2) / (2 (13 NBT - PS2))
    /// and df <= SJW / (20 NBT), in time quanta. The SJA1000's TSEG1 holds
    /// the propagation segment too, so all of it counts as PS1 here: an upper
    /// bound (two nodes may differ by up to twice this).
    pub fn oscillator_tolerance(&self) -> f64 {
        let nbt = self.tq_per_bit() as f64;
        let (ps1, ps2) = (self.tseg1 as f64 + 1.0, self.tseg2 as f64 + 1.0);
        let sjw = self.sjw as f64 + 1.0;
        (ps1.min(ps2) / (2.0 * (13.0 * nbt - ps2))).min(sjw / (20.0 * nbt))
    }
}

/// Largest bit-rate deviation from the target that [`BusTiming::candidates`]
/// lists and [`BusTiming::validate`] accepts: 0.5 %. A systematic error eats
/// into the oscillator tolerance of the whole network (at most 1.58 % with the
/// longest phase segments, CAN 2.0B §10), so it must stay a small part of it.
pub const BIT_RATE_TOLERANCE_PPM: u32 = 5_000;

/// Information processing time of the bit stream processor, in time quanta.
/// CAN 2.0B §10: "the information processing time is less than or equal to
/// 2 time quanta", and phase segment 2 must be at least that long.
pub const INFORMATION_PROCESSING_TQ: u32 = 2;

/// Fewest and most time quanta per bit (CAN 2.0B §10: "the total number of
/// time quanta in a bit time has to be programmable at least from 8 to 25").
pub const TQ_PER_BIT_RANGE: core::ops::RangeInclusive<u32> = 8..=25;

/// Highest bit rate of CAN 2.0 (bit/s).
pub const MAX_BIT_RATE: u32 = 1_000_000;

/// Highest bit rate at which the datasheet recommends triple sampling: SAM = 1
/// is "recommended for low/medium speed buses (SAE class A and B)", and SAE
/// class B ends at 125 kbit/s.
pub const MAX_TRIPLE_SAMPLING_BIT_RATE: u32 = 125_000;

/// One setting found by [`BusTiming::candidates`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// The register values (SJW is the longest the segments allow, SAM = 0).
    pub timing: BusTiming,
    /// Bit rate actually obtained, in bit/s.
    pub bit_rate: f64,
    /// Deviation from the target in parts per million (negative = slower).
    pub error_ppm: i32,
    /// Sample point as a fraction of the bit time.
    pub sample_point: f64,
    /// Time quanta per bit.
    pub tq_per_bit: u32,
}

/// A problem found by [`BusTiming::validate`]. `Display` gives one plain
/// sentence meant for a person reading a report.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TimingIssue {
    /// A register field holds a value its BTR0/BTR1 bits cannot hold.
    #[error("{name} = {value} does not fit its register field (at most {max}).")]
    FieldOutOfRange {
        /// Field name as in the datasheet (BRP, SJW, TSEG1, TSEG2).
        name: &'static str,
        /// The value found.
        value: u8,
        /// The largest value the field holds.
        max: u8,
    },
    /// The bit rate misses the target by more than [`BIT_RATE_TOLERANCE_PPM`].
    #[error(
        "The bit rate is {} kbit/s, {}% ({} ppm) {} the {} kbit/s target.",
        Kbps(*actual_bps), Percent(error_ppm.unsigned_abs()), error_ppm.unsigned_abs(),
        if *error_ppm < 0 { "below" } else { "above" }, Kbps(*target_bps as f64)
    )]
    BitRateOffTarget {
        /// Bit rate obtained, in bit/s.
        actual_bps: f64,
        /// Bit rate wanted, in bit/s.
        target_bps: u32,
        /// Deviation in parts per million (negative = slower).
        error_ppm: i32,
    },
    /// The bit rate exceeds [`MAX_BIT_RATE`].
    #[error("The bit rate is {} kbit/s, above the 1000 kbit/s maximum of CAN 2.0.", Kbps(*actual_bps))]
    BitRateTooHigh {
        /// Bit rate obtained, in bit/s.
        actual_bps: f64,
    },
    /// Fewer time quanta per bit than CAN 2.0B §10 asks controllers to support.
    #[error(
        "A bit is only {tq_per_bit} time quanta long, fewer than the 8 that CAN 2.0B requires."
    )]
    TooFewQuanta {
        /// Time quanta per bit.
        tq_per_bit: u32,
    },
    /// Sample point outside 50 %..=90 % of the bit time.
    #[error("The sample point is at {}% of the bit time, outside the usual 50% to 90%.", Percent(*permille as u32 * 1000))]
    SamplePointOutOfRange {
        /// Sample point in per mille of the bit time.
        permille: u16,
    },
    /// SJW longer than phase segment 2 (TSEG2): a resynchronisation could
    /// shorten phase segment 2 below zero.
    #[error("SJW is {sjw_tq} time quanta, longer than the {tseg2_tq} of phase segment 2 (TSEG2).")]
    SjwLongerThanTseg2 {
        /// SJW length in time quanta.
        sjw_tq: u32,
        /// TSEG2 length in time quanta.
        tseg2_tq: u32,
    },
    /// SJW longer than TSEG1 (propagation plus phase segment 1).
    #[error("SJW is {sjw_tq} time quanta, longer than the {tseg1_tq} of TSEG1.")]
    SjwLongerThanTseg1 {
        /// SJW length in time quanta.
        sjw_tq: u32,
        /// TSEG1 length in time quanta.
        tseg1_tq: u32,
    },
    /// TSEG2 shorter than the information processing time.
    #[error(
        "TSEG2 is {tseg2_tq} time quantum long, shorter than the 2 time quanta of information processing time that CAN 2.0B allows after the sample point{}.",
        if *brp == 0 { " (with BRP = 0 that leaves only 2 clock periods)" } else { "" }
    )]
    Tseg2BelowProcessingTime {
        /// TSEG2 length in time quanta.
        tseg2_tq: u32,
        /// The prescaler register value.
        brp: u8,
    },
    /// Triple sampling with a TSEG1 too short to hold the three samples.
    #[error(
        "Triple sampling (SAM = 1) needs TSEG1 of at least 3 time quanta to hold its three samples, but TSEG1 is {tseg1_tq}."
    )]
    TripleSamplingTseg1TooShort {
        /// TSEG1 length in time quanta.
        tseg1_tq: u32,
    },
    /// Triple sampling above [`MAX_TRIPLE_SAMPLING_BIT_RATE`].
    #[error("Triple sampling (SAM = 1) is meant for buses up to 125 kbit/s, not {} kbit/s; use single sampling.", Kbps(*actual_bps))]
    TripleSamplingTooFast {
        /// Bit rate obtained, in bit/s.
        actual_bps: f64,
    },
}

/// No setting reaches the target bit rate (see [`BusTiming::for_bit_rate`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "No SJA1000 bit timing reaches {} kbit/s within 0.5% from a {} MHz clock.",
    Kbps(*target_bps as f64), Mhz(*f_clk_hz)
)]
pub struct NoValidTiming {
    /// CAN clock frequency given.
    pub f_clk_hz: u32,
    /// Bit rate wanted.
    pub target_bps: u32,
}

/// Formats bit/s as kbit/s with at most one decimal ("125", "117.6").
struct Kbps(f64);

impl core::fmt::Display for Kbps {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        // Tenths of kbit/s, rounded half up (bit rates are never negative).
        write_tenths(f, (self.0 / 100.0 + 0.5) as u64)
    }
}

/// Writes `tenths / 10` with one decimal, or none when it is zero.
fn write_tenths(f: &mut core::fmt::Formatter<'_>, tenths: u64) -> core::fmt::Result {
    match (tenths / 10, tenths % 10) {
        (int, 0) => write!(f, "{int}"),
        (int, dec) => write!(f, "{int}.{dec}"),
    }
}

/// Formats a ppm magnitude as a percentage with at most one decimal.
struct Percent(u32);

impl core::fmt::Display for Percent {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write_tenths(f, (self.0 as u64 + 500) / 1000)
    }
}

/// Formats Hz as MHz with up to three decimals, trailing zeros dropped.
struct Mhz(u32);

impl core::fmt::Display for Mhz {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let khz = (self.0 + 500) / 1000;
        let (int, mut frac) = (khz / 1000, khz % 1000);
        write!(f, "{int}")?;
        if frac != 0 {
            let mut digits = 3;
            while frac % 10 == 0 {
                frac /= 10;
                digits -= 1;
            }
            write!(f, ".{frac:0digits$}")?;
        }
        Ok(())
    }
}

/// Deviation of `f_clk / clocks_per_bit` from `target`, in ppm, rounded to
/// the nearest integer (exact integer arithmetic, no float rounding).
fn error_ppm(f_clk_hz: u32, clocks_per_bit: u32, target_bps: u32) -> i32 {
    let den = target_bps as i128 * clocks_per_bit as i128;
    if den == 0 {
        return i32::MAX;
    }
    let num = (f_clk_hz as i128 - den) * 1_000_000;
    // Round half away from zero.
    let q = (2 * num.abs() + den) / (2 * den);
    let q = if num < 0 { -q } else { q };
    q.clamp(i32::MIN as i128, i32::MAX as i128) as i32
}

impl BusTiming {
    /// Length of the synchronisation jump width in time quanta (SJW + 1).
    pub const fn sjw_tq(&self) -> u32 {
        self.sjw as u32 + 1
    }

    /// Length of TSEG1 (propagation + phase segment 1) in time quanta.
    pub const fn tseg1_tq(&self) -> u32 {
        self.tseg1 as u32 + 1
    }

    /// Length of TSEG2 (phase segment 2) in time quanta.
    pub const fn tseg2_tq(&self) -> u32 {
        self.tseg2 as u32 + 1
    }

    /// Sample point in per mille of the bit time, rounded to nearest.
    pub const fn sample_point_permille(&self) -> u16 {
        let tq = self.tq_per_bit();
        (((1 + self.tseg1_tq()) * 1000 + tq / 2) / tq) as u16
    }

    /// True when the bit rate exceeds [`MAX_BIT_RATE`] by more than
    /// [`BIT_RATE_TOLERANCE_PPM`] (a 20.000001 MHz clock at 1 Mbit/s is fine).
    fn exceeds_max_bit_rate(&self, f_clk_hz: u32) -> bool {
        f_clk_hz as u128 * 1_000_000
            > MAX_BIT_RATE as u128
                * (1_000_000 + BIT_RATE_TOLERANCE_PPM as u128)
                * self.clocks_per_bit() as u128
    }

    /// Deviation of the bit rate from `target_bps` in ppm (negative = slower).
    pub fn error_ppm(&self, f_clk_hz: u32, target_bps: u32) -> i32 {
        error_ppm(f_clk_hz, self.clocks_per_bit(), target_bps)
    }

    /// Every setting the SJA1000 can be programmed with that gives
    /// `target_bps` within [`BIT_RATE_TOLERANCE_PPM`] from a CAN clock of
    /// `f_clk_hz`, best first. Empty when there is none (including targets
    /// above [`MAX_BIT_RATE`]).
    ///
    /// A setting is listed when (CAN 2.0B §10 and the datasheet field widths):
    /// BRP 0..=63, TSEG1 1..=16 tq, TSEG2 1..=8 tq; 8..=25 tq per bit;
    /// TSEG2 at least [`INFORMATION_PROCESSING_TQ`]; TSEG1 at least TSEG2
    /// (phase segment 2 may not exceed propagation + phase segment 1); sample
    /// point within 50 %..=90 %. SJW is the longest allowed, min(4, TSEG1,
    /// TSEG2) tq, for the widest oscillator tolerance; SAM is 0.
    ///
    /// Order: smallest |error| first, then the sample point closest to
    /// 87.5 % (the CiA recommendation), then more quanta per bit.
    pub fn candidates(f_clk_hz: u32, target_bps: u32) -> alloc::vec::Vec<Candidate> {
        let mut out = alloc::vec::Vec::new();
        if f_clk_hz == 0 || target_bps == 0 {
            return out;
        }
        for brp in 0..=63u8 {
            for tseg1 in 0..=15u8 {
                for tseg2 in 0..=7u8 {
                    let t0 = BusTiming {
                        brp,
                        sjw: 0,
                        tseg1,
                        tseg2,
                        sam: false,
                    };
                    let tq = t0.tq_per_bit();
                    if !TQ_PER_BIT_RANGE.contains(&tq)
                        || t0.tseg2_tq() < INFORMATION_PROCESSING_TQ
                        || t0.tseg1_tq() < t0.tseg2_tq()
                    {
                        continue;
                    }
                    let sp = 1 + t0.tseg1_tq();
                    // 50 % <= sp/tq <= 90 %, in integers.
                    if 2 * sp < tq || 10 * sp > 9 * tq {
                        continue;
                    }
                    let err = t0.error_ppm(f_clk_hz, target_bps);
                    if err.unsigned_abs() > BIT_RATE_TOLERANCE_PPM
                        || t0.exceeds_max_bit_rate(f_clk_hz)
                    {
                        continue;
                    }
                    let sjw_tq = 4.min(t0.tseg1_tq()).min(t0.tseg2_tq());
                    let timing = BusTiming {
                        sjw: (sjw_tq - 1) as u8,
                        ..t0
                    };
                    out.push(Candidate {
                        timing,
                        bit_rate: timing.bit_rate(f_clk_hz as f64),
                        error_ppm: err,
                        sample_point: timing.sample_point(),
                        tq_per_bit: tq,
                    });
                }
            }
        }
        // Distance of the sample point to 7/8, as |8*sp - 7*tq| / (8*tq),
        // compared by cross-multiplication to stay exact.
        let dist = |c: &Candidate| {
            let sp = 1 + c.timing.tseg1_tq() as i64;
            let tq = c.tq_per_bit as i64;
            ((8 * sp - 7 * tq).abs(), 8 * tq)
        };
        out.sort_by(|a, b| {
            let (na, da) = dist(a);
            let (nb, db) = dist(b);
            a.error_ppm
                .unsigned_abs()
                .cmp(&b.error_ppm.unsigned_abs())
                .then((na * db).cmp(&(nb * da)))
                .then(b.tq_per_bit.cmp(&a.tq_per_bit))
        });
        out
    }

    /// The best of [`BusTiming::candidates`], or an error naming the clock and
    /// the target when there is none.
    pub fn for_bit_rate(f_clk_hz: u32, target_bps: u32) -> Result<Candidate, NoValidTiming> {
        Self::candidates(f_clk_hz, target_bps)
            .into_iter()
            .next()
            .ok_or(NoValidTiming {
                f_clk_hz,
                target_bps,
            })
    }

    /// Everything wrong with this setting for `target_bps` at a CAN clock of
    /// `f_clk_hz`; empty when the setting is sound. Every setting listed by
    /// [`BusTiming::candidates`] validates clean.
    pub fn validate(&self, f_clk_hz: u32, target_bps: u32) -> alloc::vec::Vec<TimingIssue> {
        let mut issues = alloc::vec::Vec::new();
        for (name, value, max) in [
            ("BRP", self.brp, 63),
            ("SJW", self.sjw, 3),
            ("TSEG1", self.tseg1, 15),
            ("TSEG2", self.tseg2, 7),
        ] {
            if value > max {
                issues.push(TimingIssue::FieldOutOfRange { name, value, max });
            }
        }
        let actual_bps = self.bit_rate(f_clk_hz as f64);
        let err = self.error_ppm(f_clk_hz, target_bps);
        if err.unsigned_abs() > BIT_RATE_TOLERANCE_PPM {
            issues.push(TimingIssue::BitRateOffTarget {
                actual_bps,
                target_bps,
                error_ppm: err,
            });
        }
        if self.exceeds_max_bit_rate(f_clk_hz) {
            issues.push(TimingIssue::BitRateTooHigh { actual_bps });
        }
        let tq = self.tq_per_bit();
        if tq < *TQ_PER_BIT_RANGE.start() {
            issues.push(TimingIssue::TooFewQuanta { tq_per_bit: tq });
        }
        let sp = 1 + self.tseg1_tq();
        if 2 * sp < tq || 10 * sp > 9 * tq {
            issues.push(TimingIssue::SamplePointOutOfRange {
                permille: self.sample_point_permille(),
            });
        }
        if self.sjw_tq() > self.tseg2_tq() {
            issues.push(TimingIssue::SjwLongerThanTseg2 {
                sjw_tq: self.sjw_tq(),
                tseg2_tq: self.tseg2_tq(),
            });
        }
        if self.sjw_tq() > self.tseg1_tq() {
            issues.push(TimingIssue::SjwLongerThanTseg1 {
                sjw_tq: self.sjw_tq(),
                tseg1_tq: self.tseg1_tq(),
            });
        }
        if self.tseg2_tq() < INFORMATION_PROCESSING_TQ {
            issues.push(TimingIssue::Tseg2BelowProcessingTime {
                tseg2_tq: self.tseg2_tq(),
                brp: self.brp,
            });
        }
        if self.sam {
            if self.tseg1_tq() < 3 {
                issues.push(TimingIssue::TripleSamplingTseg1TooShort {
                    tseg1_tq: self.tseg1_tq(),
                });
            }
            if f_clk_hz as u64 > MAX_TRIPLE_SAMPLING_BIT_RATE as u64 * self.clocks_per_bit() as u64
            {
                issues.push(TimingIssue::TripleSamplingTooFast { actual_bps });
            }
        }
        issues
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thesis setting (seed 000): BTR0 = 0x41, BTR1 = 0x25 at 24 MHz:
    /// BRP = 1 -> tq = 4 clocks, TSEG1 = 5 (6 tq), TSEG2 = 2 (3 tq): 10 tq,
    /// 40 clocks per bit, 600 kbit/s.
    #[test]
    fn thesis_timing() {
        let t = BusTiming::from_btr(0x41, 0x25);
        assert_eq!((t.brp, t.sjw, t.tseg1, t.tseg2, t.sam), (1, 1, 5, 2, false));
        assert_eq!(t.clocks_per_bit(), 40);
        assert_eq!(t.bit_rate(24e6), 600_000.0);
        assert_eq!(t.to_btr(), (0x41, 0x25));
    }

    /// Seed 002: BTR0 = 0x03, BTR1 = 0xBB at 16 MHz: tq = 8 clocks, 17 tq per
    /// bit = 136 clocks, 117.6 kbit/s (not the 125 kbit/s the text intends).
    #[test]
    fn seed_002_timing_is_117k6() {
        let t = BusTiming::from_btr(0x03, 0xBB);
        assert_eq!(t.clocks_per_bit(), 136);
        assert!((t.bit_rate(16e6) - 117_647.06).abs() < 0.1);
    }

    use alloc::string::ToString;
    use alloc::vec::Vec;
    use proptest::prelude::*;

    /// Seed 002 meant 125 kbit/s (its comment says TSEG1 = 11, TSEG2 = 4, so
    /// 1 + 11 + 4 = 16 tq), but wrote the lengths into the registers, which
    /// hold length - 1: the bit is 1 + 12 + 4 = 17 tq of 8 clocks.
    /// 16 MHz / 136 = 117 647 bit/s; (117 647.06 - 125 000) / 125 000
    /// = -58 823.5 ppm, rounded away from zero to -58 824.
    #[test]
    fn seed_002_flags_the_bit_rate_and_nothing_else() {
        let t = BusTiming::from_btr(0x03, 0xBB);
        let issues = t.validate(16_000_000, 125_000);
        assert_eq!(
            issues,
            [TimingIssue::BitRateOffTarget {
                actual_bps: 16e6 / 136.0,
                target_bps: 125_000,
                error_ppm: -58_824
            }]
        );
        assert_eq!(
            issues[0].to_string(),
            "The bit rate is 117.6 kbit/s, 5.9% (58824 ppm) below the 125 kbit/s target."
        );
    }

    #[test]
    fn thesis_timing_is_clean() {
        assert_eq!(
            BusTiming::from_btr(0x41, 0x25).validate(24_000_000, 600_000),
            []
        );
    }

    #[test]
    fn faster_than_target_says_above() {
        // 16 tq of 2 clocks at 16 MHz: 500 kbit/s, twice 250 kbit/s.
        let t = BusTiming {
            brp: 0,
            sjw: 0,
            tseg1: 12,
            tseg2: 1,
            sam: false,
        };
        let msg = t.validate(16_000_000, 250_000)[0].to_string();
        assert_eq!(
            msg,
            "The bit rate is 500 kbit/s, 100% (1000000 ppm) above the 250 kbit/s target."
        );
    }

    /// 16 MHz, 125 kbit/s: 128 clocks per bit = 2 (BRP + 1) * tq, so 16 tq
    /// with BRP = 3 is exact, and 1 + 13 + 2 tq puts the sample point at
    /// 14/16 = 87.5 %. SJW = min(4, 13, 2) = 2 tq. BTR0 = 01 000011 = 0x43,
    /// BTR1 = 0 001 1100 = 0x1C.
    #[test]
    fn calculator_16mhz_125k() {
        let c = BusTiming::candidates(16_000_000, 125_000);
        let best = c[0];
        assert_eq!(best.timing.to_btr(), (0x43, 0x1C));
        assert_eq!(best.error_ppm, 0);
        assert_eq!(best.tq_per_bit, 16);
        assert_eq!(best.sample_point, 0.875);
        assert_eq!(best.bit_rate, 125_000.0);
        // The 8 tq setting (BRP = 7) is exact too but cannot reach 87.5 %
        // with TSEG2 >= 2 tq (1 + 5 + 2: 75 %), so it comes later.
        assert!(c.iter().any(|x| x.timing.brp == 7 && x.tq_per_bit == 8));
        assert_eq!(BusTiming::for_bit_rate(16_000_000, 125_000), Ok(best));
    }

    #[test]
    fn no_timing_gives_a_clear_error() {
        // 5 clocks per bit, but the shortest legal bit is 2 * 8 = 16 clocks.
        let e = BusTiming::for_bit_rate(5_000_000, 1_000_000).unwrap_err();
        assert_eq!(
            e.to_string(),
            "No SJA1000 bit timing reaches 1000 kbit/s within 0.5% from a 5 MHz clock."
        );
        assert!(
            BusTiming::candidates(24_000_000, 2_000_000).is_empty(),
            "above 1 Mbit/s"
        );
        assert_eq!(
            BusTiming::for_bit_rate(20_000_001, 1_000_000)
                .unwrap()
                .error_ppm,
            0
        );
        let e = BusTiming::for_bit_rate(24_576_000, 0).unwrap_err();
        assert_eq!(
            e.to_string(),
            "No SJA1000 bit timing reaches 0 kbit/s within 0.5% from a 24.576 MHz clock."
        );
    }

    #[test]
    fn each_rule_is_flagged() {
        let f = 16_000_000;
        // SJW 4 tq, TSEG2 2 tq, BRP 0, 16 tq: 500 kbit/s.
        let t = BusTiming {
            brp: 0,
            sjw: 3,
            tseg1: 12,
            tseg2: 1,
            sam: false,
        };
        assert_eq!(
            t.validate(f, 500_000),
            [TimingIssue::SjwLongerThanTseg2 {
                sjw_tq: 4,
                tseg2_tq: 2
            }]
        );
        assert_eq!(
            t.validate(f, 500_000)[0].to_string(),
            "SJW is 4 time quanta, longer than the 2 of phase segment 2 (TSEG2)."
        );
        // TSEG2 of one quantum with BRP = 0: 1 + 14 + 1 = 16 tq, 93.75 %.
        let t = BusTiming {
            brp: 0,
            sjw: 0,
            tseg1: 13,
            tseg2: 0,
            sam: false,
        };
        let issues = t.validate(f, 500_000);
        assert_eq!(
            issues,
            [
                TimingIssue::SamplePointOutOfRange { permille: 938 },
                TimingIssue::Tseg2BelowProcessingTime {
                    tseg2_tq: 1,
                    brp: 0
                }
            ]
        );
        assert_eq!(
            issues[0].to_string(),
            "The sample point is at 93.8% of the bit time, outside the usual 50% to 90%."
        );
        assert!(
            issues[1].to_string().contains("only 2 clock periods"),
            "{}",
            issues[1]
        );
        // Triple sampling at 500 kbit/s.
        let t = BusTiming {
            brp: 0,
            sjw: 0,
            tseg1: 12,
            tseg2: 1,
            sam: true,
        };
        assert_eq!(
            t.validate(f, 500_000),
            [TimingIssue::TripleSamplingTooFast {
                actual_bps: 500_000.0
            }]
        );
        // Triple sampling with TSEG1 of 2 tq: 1 + 2 + 2 = 5 tq per bit,
        // sample point 60 %, 32 clocks per tq: 100 kbit/s at 16 MHz.
        let t = BusTiming {
            brp: 15,
            sjw: 0,
            tseg1: 1,
            tseg2: 1,
            sam: true,
        };
        assert_eq!(
            t.validate(f, 100_000),
            [
                TimingIssue::TooFewQuanta { tq_per_bit: 5 },
                TimingIssue::TripleSamplingTseg1TooShort { tseg1_tq: 2 }
            ]
        );
        // SJW longer than TSEG1 too (and TSEG2), and too early a sample point.
        let t = BusTiming {
            brp: 1,
            sjw: 3,
            tseg1: 0,
            tseg2: 7,
            sam: false,
        };
        let issues = t.validate(f, 400_000);
        assert!(
            issues.contains(&TimingIssue::SjwLongerThanTseg1 {
                sjw_tq: 4,
                tseg1_tq: 1
            }),
            "{issues:?}"
        );
        assert!(
            issues.contains(&TimingIssue::SamplePointOutOfRange { permille: 200 }),
            "{issues:?}"
        );
        // Fields written directly beyond their register width.
        let t = BusTiming {
            brp: 64,
            sjw: 4,
            tseg1: 16,
            tseg2: 8,
            sam: false,
        };
        let issues = t.validate(f, 125_000);
        assert_eq!(
            issues[0].to_string(),
            "BRP = 64 does not fit its register field (at most 63)."
        );
        assert_eq!(
            issues
                .iter()
                .filter(|i| matches!(i, TimingIssue::FieldOutOfRange { .. }))
                .count(),
            4
        );
        // Above 1 Mbit/s: 8 tq of 2 clocks at 24 MHz is 1.5 Mbit/s.
        let t = BusTiming {
            brp: 0,
            sjw: 0,
            tseg1: 4,
            tseg2: 1,
            sam: false,
        };
        assert_eq!(
            t.validate(24_000_000, 1_500_000),
            [TimingIssue::BitRateTooHigh {
                actual_bps: 1_500_000.0
            }]
        );
    }

    #[test]
    fn btr_round_trips_for_every_register_pair() {
        for btr0 in 0..=255u8 {
            for btr1 in 0..=255u8 {
                assert_eq!(BusTiming::from_btr(btr0, btr1).to_btr(), (btr0, btr1));
            }
        }
    }

    proptest! {
        /// Any field values (even beyond the register widths), any clock and
        /// target: no panic, and each issue reads as one plain sentence.
        #[test]
        fn validate_never_panics_and_speaks_in_sentences(
            brp in any::<u8>(), sjw in any::<u8>(), tseg1 in any::<u8>(), tseg2 in any::<u8>(), sam in any::<bool>(),
            f_clk in any::<u32>(), target in any::<u32>(),
        ) {
            let t = BusTiming { brp, sjw, tseg1, tseg2, sam };
            for issue in t.validate(f_clk, target) {
                let msg = issue.to_string();
                prop_assert!(msg.starts_with(|c: char| c.is_ascii_uppercase()), "{}", msg);
                prop_assert!(msg.ends_with('.') && !msg[..msg.len() - 1].contains(". "), "{}", msg);
            }
            let in_range = brp <= 63 && sjw <= 3 && tseg1 <= 15 && tseg2 <= 7;
            prop_assert_eq!(
                in_range,
                !t.validate(f_clk, target).iter().any(|i| matches!(i, TimingIssue::FieldOutOfRange { .. }))
            );
        }

        /// Every listed setting validates clean, meets the target within the
        /// tolerance, and the list is in the documented order.
        #[test]
        fn candidates_are_valid_and_sorted(
            f_clk in 1_000_000u32..=40_000_000,
            target in prop::sample::select(alloc::vec![10_000u32, 20_000, 50_000, 83_333, 100_000,
                125_000, 250_000, 500_000, 800_000, 1_000_000, 1_004_000, 2_000_000]),
        ) {
            let c = BusTiming::candidates(f_clk, target);
            for x in &c {
                prop_assert_eq!(x.timing.validate(f_clk, target), Vec::<TimingIssue>::new(), "{:?}", x);
                prop_assert!(x.error_ppm.unsigned_abs() <= BIT_RATE_TOLERANCE_PPM);
                prop_assert_eq!(x.tq_per_bit, x.timing.tq_per_bit());
                let rel = (x.bit_rate - target as f64) / target as f64 * 1e6;
                prop_assert!((rel - x.error_ppm as f64) <= 0.501 && (x.error_ppm as f64 - rel) <= 0.501, "{} vs {}", rel, x.error_ppm);
            }
            for w in c.windows(2) {
                prop_assert!(w[0].error_ppm.unsigned_abs() <= w[1].error_ppm.unsigned_abs());
            }
            // for_bit_rate agrees with the list being empty or not.
            prop_assert_eq!(BusTiming::for_bit_rate(f_clk, target).is_ok(), !c.is_empty());
        }
    }
}
