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
