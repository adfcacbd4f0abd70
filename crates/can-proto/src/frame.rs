//! The validated frame representation and its encoding to bits.

use crate::{Bits, Crc15, Field, Id, RECESSIVE, stuff};
use embedded_can::{ExtendedId, StandardId};

/// CRC-15 of each byte shifted in from a zero register (eight
/// [`Crc15::push`] steps at once).
const CRC15_BYTE: [u16; 256] = {
    let mut t = [0u16; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = (i as u16) << 7;
        let mut k = 0;
        while k < 8 {
            c = if c & 0x4000 != 0 {
                ((c << 1) & 0x7fff) ^ crate::crc::POLY
            } else {
                (c << 1) & 0x7fff
            };
            k += 1;
        }
        t[i] = c;
        i += 1;
    }
    t
};

/// A CAN 2.0A/B data or remote frame.
///
/// The DLC is kept as sent (0..=15): values 9..=15 are legal on the wire and
/// carry 8 data bytes (CAN 2.0B §3.1.1.4); remote frames carry none.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CanFrame {
    id: Id,
    rtr: bool,
    dlc: u8,
    data: [u8; 8],
}

impl CanFrame {
    /// Builds a frame with an explicit DLC. For data frames `data.len()` must
    /// be `min(dlc, 8)`; for remote frames `data` must be empty.
    pub fn with_dlc(id: impl Into<Id>, rtr: bool, dlc: u8, data: &[u8]) -> Option<Self> {
        if dlc > 15 {
            return None;
        }
        let want = if rtr { 0 } else { dlc.min(8) as usize };
        if data.len() != want {
            return None;
        }
        let mut buf = [0u8; 8];
        buf[..want].copy_from_slice(data);
        Some(CanFrame {
            id: id.into(),
            rtr,
            dlc,
            data: buf,
        })
    }

    /// Standard (11-bit) identifier from a raw value, if in range.
    pub fn std_id(raw: u16) -> Option<Id> {
        StandardId::new(raw).map(Id::Standard)
    }

    /// Extended (29-bit) identifier from a raw value, if in range.
    pub fn ext_id(raw: u32) -> Option<Id> {
        ExtendedId::new(raw).map(Id::Extended)
    }

    /// The raw identifier value (11 or 29 bits).
    pub fn raw_id(&self) -> u32 {
        match self.id {
            Id::Standard(s) => s.as_raw() as u32,
            Id::Extended(e) => e.as_raw(),
        }
    }

    /// The DLC as sent on the wire (0..=15).
    pub fn dlc_raw(&self) -> u8 {
        self.dlc
    }

    /// Number of data bytes on the wire (0 for remote frames).
    pub fn data_len(&self) -> usize {
        if self.rtr {
            0
        } else {
            self.dlc.min(8) as usize
        }
    }

    /// Calls `f(field, level)` for each destuffed bit from SOF to the last
    /// CRC bit, in transmission order; returns the CRC.
    pub fn for_each_unstuffed_bit(&self, mut f: impl FnMut(Field, bool)) -> u16 {
        let mut crc = Crc15::new();
        let mut put = |field: Field, value: u32, width: u32, crc: &mut Crc15| {
            for i in (0..width).rev() {
                let b = (value >> i) & 1 != 0;
                crc.push(b);
                f(field, b);
            }
        };
        put(Field::Sof, 0, 1, &mut crc);
        match self.id {
            Id::Standard(s) => {
                put(Field::BaseId, s.as_raw() as u32, 11, &mut crc);
                put(Field::SrrRtr, self.rtr as u32, 1, &mut crc);
                put(Field::Ide, 0, 1, &mut crc);
                put(Field::R0, 0, 1, &mut crc);
            }
            Id::Extended(e) => {
                let raw = e.as_raw();
                put(Field::BaseId, raw >> 18, 11, &mut crc);
                put(Field::SrrRtr, 1, 1, &mut crc);
                put(Field::Ide, 1, 1, &mut crc);
                put(Field::ExtId, raw & 0x3ffff, 18, &mut crc);
                put(Field::Rtr, self.rtr as u32, 1, &mut crc);
                put(Field::R1, 0, 1, &mut crc);
                put(Field::R0, 0, 1, &mut crc);
            }
        }
        put(Field::Dlc, self.dlc as u32, 4, &mut crc);
        for &byte in &self.data[..self.data_len()] {
            put(Field::Data, byte as u32, 8, &mut crc);
        }
        let value = crc.value();
        let mut sink = Crc15::new();
        put(Field::Crc, value as u32, 15, &mut sink);
        value
    }

    /// The bits of [`CanFrame::for_each_unstuffed_bit`] packed into the low
    /// `len` bits of a `u128`, SOF as the most significant, and the CRC:
    /// `(bits, len, crc)`. At most 118 bits. No call per bit (the CRC of the
    /// data bytes goes a byte at a time), for transmitters that prepare a
    /// frame on every request.
    pub fn unstuffed_packed(&self) -> (u128, u8, u16) {
        // SOF (dominant = 0) is the leading zero bit of the header.
        let (head, head_len): (u64, u32) = match self.id {
            Id::Standard(s) => {
                // SOF, ID, RTR, IDE = 0, r0 = 0, DLC.
                let h = ((s.as_raw() as u64) << 7) | ((self.rtr as u64) << 6) | self.dlc as u64;
                (h, 19)
            }
            Id::Extended(e) => {
                let raw = e.as_raw() as u64;
                // SOF, base ID, SRR = 1, IDE = 1, ext ID, RTR, r1 = 0, r0 = 0, DLC.
                let h = ((raw >> 18) << 27)
                    | (0b11 << 25)
                    | ((raw & 0x3ffff) << 7)
                    | ((self.rtr as u64) << 6)
                    | self.dlc as u64;
                (h, 39)
            }
        };
        let mut crc = Crc15::new();
        for i in (0..head_len).rev() {
            crc.push((head >> i) & 1 != 0);
        }
        let mut c = crc.value();
        let mut bits = head as u128;
        let mut len = head_len;
        for &byte in &self.data[..self.data_len()] {
            c = ((c << 8) & 0x7fff) ^ CRC15_BYTE[(((c >> 7) as u8) ^ byte) as usize];
            bits = (bits << 8) | byte as u128;
            len += 8;
        }
        bits = (bits << 15) | c as u128;
        (bits, (len + 15) as u8, c)
    }

    /// The CRC-15 of this frame.
    pub fn crc(&self) -> u16 {
        self.for_each_unstuffed_bit(|_, _| {})
    }

    /// Destuffed bits from SOF to the end of the CRC sequence.
    pub fn unstuffed_bits(&self) -> Bits {
        let mut bits = Bits::with_capacity(160);
        self.for_each_unstuffed_bit(|_, b| bits.push(b));
        bits
    }

    /// The whole frame as a transmitter sends it: stuffed SOF..CRC, then CRC
    /// delimiter, ACK slot (sent recessive), ACK delimiter and 7 EOF bits.
    pub fn wire_bits(&self) -> Bits {
        let mut bits = stuff::stuff(&self.unstuffed_bits());
        for _ in 0..10 {
            bits.push(RECESSIVE);
        }
        bits
    }

    /// [`CanFrame::wire_bits`] with the field of every bit, for fault
    /// injection and probes that target a field. A stuff bit carries the
    /// field of the data bit after it (the CRC for a stuff bit that follows
    /// the last CRC bit), as the decoder reports stuff errors.
    pub fn wire_layout(&self) -> alloc::vec::Vec<WireBit> {
        let mut plain = alloc::vec::Vec::with_capacity(160);
        self.for_each_unstuffed_bit(|field, level| plain.push((field, level)));
        let mut out = alloc::vec::Vec::with_capacity(plain.len() + plain.len() / 4 + 11);
        let (mut last, mut run) = (None, 0u8);
        for (i, &(field, level)) in plain.iter().enumerate() {
            out.push(WireBit {
                level,
                field,
                stuff: false,
            });
            run = if last == Some(level) { run + 1 } else { 1 };
            last = Some(level);
            if run == stuff::STUFF_WIDTH {
                let field = plain.get(i + 1).map_or(Field::Crc, |&(f, _)| f);
                out.push(WireBit {
                    level: !level,
                    field,
                    stuff: true,
                });
                (last, run) = (Some(!level), 1);
            }
        }
        let tail = [
            (Field::CrcDelim, 1),
            (Field::AckSlot, 1),
            (Field::AckDelim, 1),
            (Field::Eof, 7),
        ];
        for (field, n) in tail {
            for _ in 0..n {
                out.push(WireBit {
                    level: RECESSIVE,
                    field,
                    stuff: false,
                });
            }
        }
        out
    }

    /// Total bits on the wire from SOF to the end of EOF (without intermission).
    pub fn bit_len(&self) -> usize {
        self.wire_bits().len()
    }
}

/// One bit of [`CanFrame::wire_layout`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct WireBit {
    /// Bus level as transmitted (`true` = recessive; the ACK slot is sent
    /// recessive).
    pub level: bool,
    /// The field the bit belongs to.
    pub field: Field,
    /// True for a stuff bit.
    pub stuff: bool,
}

impl embedded_can::Frame for CanFrame {
    fn new(id: impl Into<Id>, data: &[u8]) -> Option<Self> {
        if data.len() > 8 {
            return None;
        }
        CanFrame::with_dlc(id, false, data.len() as u8, data)
    }

    fn new_remote(id: impl Into<Id>, dlc: usize) -> Option<Self> {
        if dlc > 15 {
            return None;
        }
        CanFrame::with_dlc(id, true, dlc as u8, &[])
    }

    fn is_extended(&self) -> bool {
        matches!(self.id, Id::Extended(_))
    }

    fn is_remote_frame(&self) -> bool {
        self.rtr
    }

    fn id(&self) -> Id {
        self.id
    }

    fn dlc(&self) -> usize {
        self.dlc as usize
    }

    fn data(&self) -> &[u8] {
        &self.data[..self.data_len()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_can::Frame;

    /// The frame of the DE2 thesis (seed 000): BasicCAN TX buffer 0xA5, 0x21,
    /// 0x51 gives ID = 0xA5<<3 | 0x21>>5 = 0x529, RTR = 0, DLC = 1, data 0x51.
    /// The thesis lists its start as SOF 0, ID 10100101001, RTR 0, r0 r1 0 0,
    /// DLC 0 0 0 1 with one stuff bit: five dominant bits (RTR, IDE, r0, DLC3,
    /// DLC2) are followed by a recessive stuff bit.
    #[test]
    fn thesis_frame_head() {
        let f = CanFrame::new(CanFrame::std_id(0x529).unwrap(), &[0x51]).unwrap();
        let w = f.wire_bits();
        let head: alloc::string::String = w
            .iter()
            .by_vals()
            .take(25)
            .map(|b| if b { '1' } else { '0' })
            .collect();
        // SOF | ID 10100101001 | RTR IDE r0 DLC3 DLC2 | stuff 1 | DLC1 DLC0 | data 01010001
        assert_eq!(head, "0101001010010000010101010");
        assert_eq!(&head[..12], "010100101001");
    }

    /// The thesis frame's layout: stuff bits at 17 (DLC) and 32 (CRC), CRC
    /// delimiter at 44, EOF 47..=53 (see decode tests for the whole map).
    #[test]
    fn thesis_frame_layout() {
        let f = CanFrame::new(CanFrame::std_id(0x529).unwrap(), &[0x51]).unwrap();
        let l = f.wire_layout();
        assert_eq!(l.len(), 54);
        let levels: Bits = l.iter().map(|b| b.level).collect();
        assert_eq!(levels, f.wire_bits());
        let stuffs: alloc::vec::Vec<(usize, Field)> = l
            .iter()
            .enumerate()
            .filter(|(_, b)| b.stuff)
            .map(|(i, b)| (i, b.field))
            .collect();
        assert_eq!(stuffs, [(17, Field::Dlc), (32, Field::Crc)]);
        assert_eq!(l[44].field, Field::CrcDelim);
        assert_eq!(l[45].field, Field::AckSlot);
        assert!(l[47..].iter().all(|b| b.field == Field::Eof));
        assert_eq!(l[12].field, Field::SrrRtr);
    }

    /// The packed bits and CRC are exactly the per-bit encoder's.
    #[test]
    fn unstuffed_packed_matches_encoder() {
        let mut seed = 0x1234_5678_9abc_def1u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for k in 0..2000 {
            let r = next();
            let id = if k % 2 == 0 {
                CanFrame::std_id((r & 0x7ff) as u16).unwrap()
            } else {
                CanFrame::ext_id((r & 0x1fff_ffff) as u32).unwrap()
            };
            let rtr = (r >> 40) & 7 == 0;
            let dlc = ((r >> 44) & 15) as u8;
            let data = next().to_le_bytes();
            let n = if rtr { 0 } else { dlc.min(8) as usize };
            let f = CanFrame::with_dlc(id, rtr, dlc, &data[..n]).unwrap();
            let mut want = alloc::vec::Vec::new();
            let crc = f.for_each_unstuffed_bit(|_, b| want.push(b));
            let (bits, len, c) = f.unstuffed_packed();
            assert_eq!(c, crc);
            let got: alloc::vec::Vec<bool> =
                (0..len).rev().map(|i| (bits >> i) & 1 != 0).collect();
            assert_eq!(got, want, "{f:?}");
        }
    }

    #[test]
    fn dlc_over_8_carries_8_bytes() {
        let id = CanFrame::std_id(1).unwrap();
        assert!(CanFrame::with_dlc(id, false, 12, &[0; 8]).is_some());
        assert!(CanFrame::with_dlc(id, false, 12, &[0; 7]).is_none());
        assert!(CanFrame::with_dlc(id, false, 16, &[0; 8]).is_none());
        let f = CanFrame::with_dlc(id, false, 15, &[1; 8]).unwrap();
        assert_eq!(f.data().len(), 8);
        assert_eq!(f.dlc(), 15);
    }
}
