//! Acceptance filters as pure functions (SJA1000 data sheet §6.3.8-9 for
//! BasicCAN, §6.4.15 and Figures 10-13 for PeliCAN).
//!
//! Convention everywhere: a mask bit of 1 means "don't care"; a code bit
//! must equal the received bit where its mask bit is 0.
//!
//! Data-byte comparisons (PeliCAN single filter for standard frames, and
//! dual filter 1 for standard frames) only apply to data bytes the frame
//! actually carries: a remote frame, or a data frame with fewer bytes,
//! passes those comparisons.

use can_proto::{CanFrame, FrameTrait, Id};

/// PeliCAN acceptance filter mode (MOD.AFM).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FilterMode {
    /// MOD.AFM = 0: two shorter filters; the frame passes if either accepts.
    Dual,
    /// MOD.AFM = 1: one long filter over four code/mask bytes.
    Single,
}

/// True when every bit of `value` equals `code` where `mask` is 0.
#[inline]
pub const fn bits_match(value: u8, code: u8, mask: u8) -> bool {
    (value ^ code) & !mask == 0
}

/// BasicCAN filter (§6.3.9): ACR/AMR compare the 8 upper identifier bits
/// ID.10..ID.3 (ACR.7 = ID.10). `id11` is the 11-bit standard identifier.
#[inline]
pub const fn basic_accepts(acr: u8, amr: u8, id11: u16) -> bool {
    bits_match((id11 >> 3) as u8, acr, amr)
}

/// The bytes a PeliCAN filter sees for a frame.
struct Seen {
    ext: bool,
    id: u32,
    rtr: bool,
    data: [u8; 2],
    n: usize,
}

impl Seen {
    fn of(frame: &CanFrame) -> Seen {
        let (ext, id) = match frame.id() {
            Id::Standard(s) => (false, s.as_raw() as u32),
            Id::Extended(e) => (true, e.as_raw()),
        };
        let d = frame.data();
        let mut data = [0u8; 2];
        let n = d.len().min(2);
        data[..n].copy_from_slice(&d[..n]);
        Seen { ext, id, rtr: frame.is_remote_frame(), data, n }
    }
}

/// PeliCAN acceptance filter over ACR0..3 / AMR0..3 (§6.4.15).
pub fn pelican_accepts(mode: FilterMode, acr: [u8; 4], amr: [u8; 4], frame: &CanFrame) -> bool {
    let s = Seen::of(frame);
    let rtr = s.rtr as u8;
    // A data byte the frame does not carry passes its comparison.
    let data_ok = |i: usize, code: u8, mask: u8| i >= s.n || bits_match(s.data[i], code, mask);
    match (mode, s.ext) {
        // Figure 10: ACR0 = ID.28..21, ACR1.7..5 = ID.20..18, ACR1.4 = RTR,
        // ACR1.3..0 unused, ACR2 = data byte 1, ACR3 = data byte 2.
        (FilterMode::Single, false) => {
            let id = s.id;
            bits_match((id >> 3) as u8, acr[0], amr[0])
                && bits_match((((id & 7) << 5) as u8) | (rtr << 4), acr[1], amr[1] | 0x0F)
                && data_ok(0, acr[2], amr[2])
                && data_ok(1, acr[3], amr[3])
        }
        // Figure 11: ACR0..ACR2 = ID.28..5, ACR3.7..3 = ID.4..0, ACR3.2 = RTR,
        // ACR3.1..0 unused.
        (FilterMode::Single, true) => {
            let id = s.id;
            bits_match((id >> 21) as u8, acr[0], amr[0])
                && bits_match((id >> 13) as u8, acr[1], amr[1])
                && bits_match((id >> 5) as u8, acr[2], amr[2])
                && bits_match((((id & 0x1F) << 3) as u8) | (rtr << 2), acr[3], amr[3] | 0x03)
        }
        // Figure 12. Filter 1: ACR0 = ID.28..21, ACR1.7..5 = ID.20..18,
        // ACR1.4 = RTR, ACR1.3..0 = data byte 1 bits 7..4, ACR3.3..0 = data
        // byte 1 bits 3..0. Filter 2: ACR2 = ID.28..21, ACR3.7..5 =
        // ID.20..18, ACR3.4 = RTR.
        (FilterMode::Dual, false) => {
            let id = s.id;
            let hi = (id >> 3) as u8;
            let lo = (((id & 7) << 5) as u8) | (rtr << 4);
            let f1 = bits_match(hi, acr[0], amr[0])
                && bits_match(lo, acr[1], amr[1] | 0x0F)
                && data_ok(0, (acr[1] << 4) | (acr[3] & 0x0F), (amr[1] << 4) | (amr[3] & 0x0F));
            let f2 = bits_match(hi, acr[2], amr[2]) && bits_match(lo, acr[3], amr[3] | 0x0F);
            f1 || f2
        }
        // Figure 13. Filter 1: ACR0 = ID.28..21, ACR1 = ID.20..13.
        // Filter 2: ACR2 = ID.28..21, ACR3 = ID.20..13.
        (FilterMode::Dual, true) => {
            let hi = (s.id >> 21) as u8;
            let mid = (s.id >> 13) as u8;
            (bits_match(hi, acr[0], amr[0]) && bits_match(mid, acr[1], amr[1]))
                || (bits_match(hi, acr[2], amr[2]) && bits_match(mid, acr[3], amr[3]))
        }
    }
}
