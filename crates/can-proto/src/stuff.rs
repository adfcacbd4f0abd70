//! Bit stuffing (CAN 2.0B §3.1.1 "Bit stuffing"): after five equal bits the
//! transmitter inserts one bit of the opposite level; stuff bits count for
//! the next run. Applies from SOF to the end of the CRC sequence.

use crate::Bits;

/// Number of equal consecutive bits after which a stuff bit is inserted.
pub const STUFF_WIDTH: u8 = 5;

/// Stuffs a destuffed stream (SOF..CRC sequence).
pub fn stuff(bits: &bitvec::slice::BitSlice<u32>) -> Bits {
    let mut out = Bits::with_capacity(bits.len() + bits.len() / 4 + 1);
    let mut last = None;
    let mut run = 0u8;
    for b in bits.iter().by_vals() {
        push_counted(&mut out, b, &mut last, &mut run);
        if run == STUFF_WIDTH {
            push_counted(&mut out, !b, &mut last, &mut run);
        }
    }
    out
}

fn push_counted(out: &mut Bits, b: bool, last: &mut Option<bool>, run: &mut u8) {
    if *last == Some(b) {
        *run += 1;
    } else {
        *last = Some(b);
        *run = 1;
    }
    out.push(b);
}

/// Removes stuff bits. Returns `Err(index)` with the stuffed-stream index of
/// the first stuff error (a sixth equal bit where a stuff bit was due).
pub fn destuff(bits: &bitvec::slice::BitSlice<u32>) -> Result<Bits, usize> {
    let mut out = Bits::with_capacity(bits.len());
    let mut last = None;
    let mut run = 0u8;
    let mut expect_stuff = false;
    for (i, b) in bits.iter().by_vals().enumerate() {
        if expect_stuff {
            if Some(b) == last {
                return Err(i);
            }
            last = Some(b);
            run = 1;
            expect_stuff = false;
            continue;
        }
        if Some(b) == last {
            run += 1;
        } else {
            last = Some(b);
            run = 1;
        }
        out.push(b);
        if run == STUFF_WIDTH {
            expect_stuff = true;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Bits, CanFrame};
    use alloc::vec::Vec;
    use proptest::prelude::*;

    /// Longest run of equal bits.
    fn longest_run(bits: &bitvec::slice::BitSlice<u32>) -> usize {
        let v: Vec<bool> = bits.iter().by_vals().collect();
        v.chunk_by(|a, b| a == b)
            .map(|c| c.len())
            .max()
            .unwrap_or(0)
    }

    fn to_bits(s: &str) -> Bits {
        s.chars()
            .filter(|c| !c.is_whitespace())
            .map(|c| c == '1')
            .collect()
    }

    #[test]
    fn known_stuffing() {
        // Five equal bits get the opposite bit; the stuff bit starts a new run.
        assert_eq!(stuff(&to_bits("00000")), to_bits("00000 1"));
        assert_eq!(stuff(&to_bits("0000011110")), to_bits("00000 1 1111 0 0"));
        assert_eq!(stuff(&to_bits("1111")), to_bits("1111"));
        assert_eq!(
            destuff(&to_bits("00000 1 1111 0 0")),
            Ok(to_bits("0000011110"))
        );
        // A sixth equal bit where the stuff bit was due: error at index 5.
        assert_eq!(destuff(&to_bits("000000")), Err(5));
    }

    proptest! {
        #[test]
        fn stuffing_round_trips_and_breaks_runs(x in prop::collection::vec(any::<bool>(), 0..300)) {
            let x: Bits = x.into_iter().collect();
            let s = stuff(&x);
            prop_assert!(longest_run(&s) <= STUFF_WIDTH as usize);
            prop_assert_eq!(destuff(&s), Ok(x.clone()));
            // At most one stuff bit per 4 data bits after the first five.
            prop_assert!(s.len() <= x.len() + x.len() / 4 + 1);
        }

        /// In every frame the stuffed part (SOF to the end of CRC) never holds
        /// six equal bits.
        #[test]
        fn frames_never_hold_six_equal_stuffed_bits(
            ext in any::<bool>(), id in 0u32..(1 << 29), rtr in any::<bool>(), dlc in 0u8..=15, data in any::<[u8; 8]>(),
        ) {
            let id = if ext { CanFrame::ext_id(id).unwrap() } else { CanFrame::std_id((id & 0x7FF) as u16).unwrap() };
            let n = if rtr { 0 } else { dlc.min(8) as usize };
            let f = CanFrame::with_dlc(id, rtr, dlc, &data[..n]).unwrap();
            let w = f.wire_bits();
            let stuffed = &w[..w.len() - 10];
            prop_assert!(longest_run(stuffed) <= 5);
            prop_assert_eq!(destuff(stuffed), Ok(f.unstuffed_bits()));
        }
    }
}
