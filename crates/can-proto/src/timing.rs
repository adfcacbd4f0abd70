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
}
