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
        Seen {
            ext,
            id,
            rtr: frame.is_remote_frame(),
            data,
            n,
        }
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
                && bits_match(
                    (((id & 0x1F) << 3) as u8) | (rtr << 2),
                    acr[3],
                    amr[3] | 0x03,
                )
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
                && data_ok(
                    0,
                    (acr[1] << 4) | (acr[3] & 0x0F),
                    (amr[1] << 4) | (amr[3] & 0x0F),
                );
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

#[cfg(test)]
mod tests {
    use super::*;
    use can_proto::{ExtendedId, StandardId};
    use rand::{RngExt, SeedableRng, rngs::StdRng};

    /// Seed 002's BasicCAN example: ACR = 0111 0010, AMR = 0011 1000
    /// accepts exactly the identifiers 0 1 x x x 0 1 0 x x x (ID.10..ID.0).
    #[test]
    fn basic_seed_002_example_all_2048_ids() {
        let (acr, amr) = (0b0111_0010, 0b0011_1000);
        for id in 0u16..2048 {
            let want = (id >> 9) == 0b01 && ((id >> 3) & 0b111) == 0b010;
            assert_eq!(basic_accepts(acr, amr, id), want, "id {id:011b}");
        }
    }

    /// Where each filtered bit sits, per data sheet Figures 10-13, as
    /// (register byte, bit) for each frame bit; an independent bit-by-bit
    /// reference for the byte-wise implementation above.
    #[derive(Clone, Copy)]
    enum Src {
        Id(u8),
        Rtr,
        Data(usize, u8),
    }

    fn reference(map: &[(Src, usize, u8)], acr: [u8; 4], amr: [u8; 4], f: &CanFrame) -> bool {
        let (id, _) = match f.id() {
            Id::Standard(s) => (s.as_raw() as u32, false),
            Id::Extended(e) => (e.as_raw(), true),
        };
        map.iter().all(|&(src, byte, bit)| {
            let v = match src {
                Src::Id(b) => (id >> b) & 1 != 0,
                Src::Rtr => f.is_remote_frame(),
                Src::Data(i, b) => match f.data().get(i) {
                    Some(d) => (d >> b) & 1 != 0,
                    None => return true,
                },
            };
            amr[byte] >> bit & 1 != 0 || (acr[byte] >> bit & 1 != 0) == v
        })
    }

    /// Standard IDs are numbered here as 10..0 (ID.28..ID.18 in the figures).
    fn single_std() -> Vec<(Src, usize, u8)> {
        let mut m = vec![];
        for k in 0..8 {
            m.push((Src::Id(10 - k), 0, 7 - k));
        }
        for k in 0..3 {
            m.push((Src::Id(2 - k), 1, 7 - k));
        }
        m.push((Src::Rtr, 1, 4));
        for b in 0..8 {
            m.push((Src::Data(0, b), 2, b));
            m.push((Src::Data(1, b), 3, b));
        }
        m
    }

    fn single_ext() -> Vec<(Src, usize, u8)> {
        let mut m = vec![];
        for k in 0..29u8 {
            // ID.28 is ACR0.7, ..., ID.0 is ACR3.3
            let pos = k as usize; // 0 = ID.28
            m.push((Src::Id(28 - k), pos / 8, 7 - (pos % 8) as u8));
        }
        m.push((Src::Rtr, 3, 2));
        m
    }

    fn dual_std() -> [Vec<(Src, usize, u8)>; 2] {
        let mut f1 = vec![];
        let mut f2 = vec![];
        for k in 0..8 {
            f1.push((Src::Id(10 - k), 0, 7 - k));
            f2.push((Src::Id(10 - k), 2, 7 - k));
        }
        for k in 0..3 {
            f1.push((Src::Id(2 - k), 1, 7 - k));
            f2.push((Src::Id(2 - k), 3, 7 - k));
        }
        f1.push((Src::Rtr, 1, 4));
        f2.push((Src::Rtr, 3, 4));
        for b in 0..4 {
            f1.push((Src::Data(0, b + 4), 1, b));
            f1.push((Src::Data(0, b), 3, b));
        }
        [f1, f2]
    }

    fn dual_ext() -> [Vec<(Src, usize, u8)>; 2] {
        let mut f1 = vec![];
        let mut f2 = vec![];
        for k in 0..16u8 {
            let pos = k as usize;
            f1.push((Src::Id(28 - k), pos / 8, 7 - (pos % 8) as u8));
            f2.push((Src::Id(28 - k), 2 + pos / 8, 7 - (pos % 8) as u8));
        }
        [f1, f2]
    }

    fn frame(rng: &mut StdRng, ext: bool) -> CanFrame {
        let id: Id = if ext {
            ExtendedId::new(rng.random_range(0..0x2000_0000))
                .unwrap()
                .into()
        } else {
            StandardId::new(rng.random_range(0..0x800)).unwrap().into()
        };
        let rtr = rng.random_bool(0.2);
        let dlc = rng.random_range(0..=8u8);
        let data: Vec<u8> = (0..if rtr { 0 } else { dlc })
            .map(|_| rng.random())
            .collect();
        CanFrame::with_dlc(id, rtr, dlc, &data).unwrap()
    }

    /// Codes and masks biased so that matches happen often: the mask is
    /// mostly ones, the code is taken from a frame.
    fn check(mode: FilterMode, ext: bool, n: usize) {
        let mut rng =
            StdRng::seed_from_u64(0x5a1000 + ext as u64 + 2 * (mode == FilterMode::Single) as u64);
        let (mut accepted, mut rejected) = (0, 0);
        for _ in 0..n {
            let f = frame(&mut rng, ext);
            let mut acr: [u8; 4] = rng.random();
            let amr: [u8; 4] = std::array::from_fn(|_| rng.random::<u8>() | rng.random::<u8>());
            if rng.random_bool(0.5) {
                // Make the code equal to the frame's bits to get acceptances.
                let mut b = [0u8; 13];
                let len = crate::host::encode_peli(&f, &mut b);
                let _ = len;
                acr = [b[1], b[2] | (f.is_remote_frame() as u8) << 4, b[3], b[4]];
            }
            let want = match (mode, ext) {
                (FilterMode::Single, false) => reference(&single_std(), acr, amr, &f),
                (FilterMode::Single, true) => reference(&single_ext(), acr, amr, &f),
                (FilterMode::Dual, false) => dual_std().iter().any(|m| reference(m, acr, amr, &f)),
                (FilterMode::Dual, true) => dual_ext().iter().any(|m| reference(m, acr, amr, &f)),
            };
            assert_eq!(
                pelican_accepts(mode, acr, amr, &f),
                want,
                "{mode:?} {f:?} acr {acr:02x?} amr {amr:02x?}"
            );
            if want { accepted += 1 } else { rejected += 1 }
        }
        assert!(
            accepted > n / 20 && rejected > n / 20,
            "both outcomes exercised: {accepted}/{rejected}"
        );
    }

    #[test]
    fn single_filter_standard_matches_figure_10() {
        check(FilterMode::Single, false, 20_000);
    }

    #[test]
    fn single_filter_extended_matches_figure_11() {
        check(FilterMode::Single, true, 20_000);
    }

    #[test]
    fn dual_filter_standard_matches_figure_12() {
        check(FilterMode::Dual, false, 20_000);
    }

    #[test]
    fn dual_filter_extended_matches_figure_13() {
        check(FilterMode::Dual, true, 20_000);
    }

    /// Every standard ID against an exact single-filter code with all
    /// data bits don't-care: exactly one ID (per RTR value) passes.
    #[test]
    fn single_filter_exact_id_accepts_only_that_id() {
        let target = 0x5A3u16;
        let acr = [(target >> 3) as u8, ((target & 7) << 5) as u8, 0, 0];
        let amr = [0, 0x1F, 0xFF, 0xFF]; // RTR don't care
        for id in 0u16..2048 {
            for rtr in [false, true] {
                let f = CanFrame::with_dlc(StandardId::new(id).unwrap(), rtr, 0, &[]).unwrap();
                assert_eq!(
                    pelican_accepts(FilterMode::Single, acr, amr, &f),
                    id == target
                );
            }
        }
    }

    /// Data-byte comparisons skip bytes the frame does not carry.
    #[test]
    fn missing_data_bytes_pass() {
        let id = StandardId::new(0x123).unwrap();
        let acr = [(0x123 >> 3) as u8, ((0x123 & 7) << 5) as u8, 0xAB, 0xCD];
        let amr = [0, 0x0F, 0, 0];
        let f0 = CanFrame::with_dlc(id, false, 0, &[]).unwrap();
        let f1_ok = CanFrame::with_dlc(id, false, 1, &[0xAB]).unwrap();
        let f1_bad = CanFrame::with_dlc(id, false, 1, &[0xAC]).unwrap();
        let f2_bad = CanFrame::with_dlc(id, false, 2, &[0xAB, 0xCE]).unwrap();
        let rtr = CanFrame::with_dlc(id, true, 2, &[]).unwrap();
        assert!(pelican_accepts(FilterMode::Single, acr, amr, &f0));
        assert!(pelican_accepts(FilterMode::Single, acr, amr, &f1_ok));
        assert!(!pelican_accepts(FilterMode::Single, acr, amr, &f1_bad));
        assert!(!pelican_accepts(FilterMode::Single, acr, amr, &f2_bad));
        // RTR bit in the code is 0: a remote frame fails on RTR, not on data.
        assert!(!pelican_accepts(FilterMode::Single, acr, amr, &rtr));
        let amr_rtr = [0, 0x1F, 0, 0];
        assert!(pelican_accepts(FilterMode::Single, acr, amr_rtr, &rtr));
    }
}
