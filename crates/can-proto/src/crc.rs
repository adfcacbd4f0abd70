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
    use alloc::vec;
    use alloc::vec::Vec;
    use proptest::prelude::*;

    /// The generator x^15+x^14+x^10+x^8+x^7+x^4+x^3+1 as coefficients from
    /// x^15 down to x^0 (0xC599).
    const GENERATOR: [bool; 16] = {
        let mut g = [false; 16];
        let mut i = 0;
        while i < 16 {
            g[i] = (0xC599u16 >> (15 - i)) & 1 != 0;
            i += 1;
        }
        g
    };

    /// Reference CRC straight from CAN 2.0B §3.1.1.6: the remainder of the
    /// message polynomial times x^15 divided by the generator, by long
    /// division over the coefficients (GF(2): subtraction is XOR). Shares no
    /// code with [`Crc15`].
    fn crc_reference(message: &[bool]) -> u16 {
        let mut dividend: Vec<bool> = message.to_vec();
        dividend.extend([false; 15]);
        for i in 0..message.len() {
            if dividend[i] {
                for (j, &g) in GENERATOR.iter().enumerate() {
                    dividend[i + j] ^= g;
                }
            }
        }
        dividend[message.len()..]
            .iter()
            .fold(0, |acc, &b| (acc << 1) | b as u16)
    }

    fn bits(s: &str) -> Vec<bool> {
        s.chars().map(|c| c == '1').collect()
    }

    #[test]
    fn generator_constant_matches_poly() {
        assert!(GENERATOR[0], "x^15 term");
        let low = GENERATOR[1..]
            .iter()
            .fold(0u16, |acc, &b| (acc << 1) | b as u16);
        assert_eq!(low, POLY);
    }

    /// Hand-checked vectors (remainders of m(x) * x^15 mod g(x)):
    /// - "1": x^15 mod g = g - x^15 = x^14+x^10+x^8+x^7+x^4+x^3+1 = 0x4599.
    /// - "10": x^16 = x * x^15 = x^15+x^11+x^9+x^8+x^5+x^4+x; subtracting g
    ///   cancels x^15, x^8, x^4 and adds x^14, x^10, x^7, x^3, 1:
    ///   x^14+x^11+x^10+x^9+x^7+x^5+x^3+x+1 = 0x4EAB.
    /// - "11": x^16 + x^15, so the sum of the two above: 0x4EAB ^ 0x4599 = 0x0B32.
    /// - "0...0": zero (leading zeros change nothing).
    #[test]
    fn known_vectors() {
        for (msg, crc) in [
            ("1", 0x4599),
            ("10", 0x4EAB),
            ("11", 0x0B32),
            ("0000000000", 0),
            ("0001", 0x4599),
        ] {
            assert_eq!(crc_reference(&bits(msg)), crc, "reference, {msg}");
            assert_eq!(Crc15::of(bits(msg)), crc, "Crc15, {msg}");
        }
        // The DE2 thesis frame (seed 000), SOF to the end of data:
        // SOF 0, ID 0x529, RTR 0, IDE 0, r0 0, DLC 0001, data 0x51.
        let thesis = bits("0 10100101001 000 0001 01010001".replace(' ', "").as_str());
        assert_eq!(crc_reference(&thesis), 0x7D2A);
        assert_eq!(Crc15::of(thesis), 0x7D2A);
    }

    #[test]
    fn register_starts_at_zero_and_zeros_keep_it() {
        let mut c = Crc15::new();
        assert_eq!(c.value(), 0);
        c.push(true);
        assert_eq!(c.value(), POLY);
        assert_eq!(Crc15::of(vec![false; 20]), 0);
    }

    proptest! {
        /// The shift register equals the long division for any message.
        #[test]
        fn register_matches_long_division(msg in prop::collection::vec(any::<bool>(), 0..200)) {
            prop_assert_eq!(Crc15::of(msg.iter().copied()), crc_reference(&msg));
        }

        /// A message followed by its own CRC divides exactly: remainder 0.
        #[test]
        fn message_with_its_crc_divides_exactly(msg in prop::collection::vec(any::<bool>(), 1..200)) {
            let crc = crc_reference(&msg);
            let mut all = msg.clone();
            all.extend((0..15).rev().map(|i| (crc >> i) & 1 != 0));
            prop_assert_eq!(crc_reference(&all), 0);
            prop_assert_eq!(Crc15::of(all), 0);
        }
    }
}
