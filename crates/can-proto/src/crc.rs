//! CRC-15 of CAN 2.0 (generator x^15+x^14+x^10+x^8+x^7+x^4+x^3+1 = 0x4599),
//! computed over the destuffed bits from SOF to the end of the data field.

/// The CAN CRC-15 generator polynomial without its x^15 term.
pub const POLY: u16 = 0x4599;

/// Incremental CRC-15, fed one destuffed bit at a time (CAN 2.0B §3.1.1.6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Crc15(u16);

impl Crc15 {
    /// A fresh register (all zeros, as the spec initialises it).
    pub const fn new() -> Self {
        Crc15(0)
    }

    /// Shifts one bit in (the spec's `CRC_NXT = NXTBIT EXOR CRC_RG(14)`).
    #[inline(always)]
    pub fn push(&mut self, bit: bool) {
        let nxt = bit ^ (self.0 & 0x4000 != 0);
        self.0 = (self.0 << 1) & 0x7fff;
        if nxt {
            self.0 ^= POLY;
        }
    }

    /// The 15-bit remainder so far.
    pub const fn value(&self) -> u16 {
        self.0
    }

    /// CRC of a whole bit sequence.
    pub fn of(bits: impl IntoIterator<Item = bool>) -> u16 {
        let mut c = Crc15::new();
        for b in bits {
            c.push(b);
        }
        c.value()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Long division by hand of the generator: a single 1 followed by 15 zeros
    /// leaves the polynomial itself as remainder.
    #[test]
    fn single_one_gives_the_polynomial() {
        let mut bits = [false; 16];
        bits[0] = true;
        // Shifting "1" then 15 zeros: after the first push the register is 0x4599
        // (bit XOR 0 = 1), then fifteen zero pushes divide further.
        let mut c = Crc15::new();
        c.push(true);
        assert_eq!(c.value(), POLY);
        for _ in 0..15 {
            c.push(false);
        }
        assert_ne!(c.value(), 0);
        assert_eq!(Crc15::of([false; 20]), 0, "zeros never change a zero register");
    }
}
