//! Byte layout of the TX/RX buffer windows: where identifier, RTR and data
//! sit (data sheet 6.3.7/6.3.8 for BasicCAN, 6.4.13/6.4.14 for PeliCAN).
//! Bit fields of single bytes (frame information, BasicCAN ID2) are in the
//! register tables; this module adds the multi-byte arrangement.

/// PeliCAN: offsets from the frame information byte (address 16).
pub mod peli {
    /// Frame information (FF, RTR, DLC).
    pub const FI: u8 = 0;
    /// Identifier byte 1 (SFF: ID.28..21; EFF: ID.28..21).
    pub const ID1: u8 = 1;
    /// Identifier byte 2 (SFF: ID.20..18 in bits 7..5, RX RTR in bit 4; EFF: ID.20..13).
    pub const ID2: u8 = 2;
    /// First data byte of a standard frame.
    pub const SFF_DATA: u8 = 3;
    /// Identifier byte 3 of an extended frame (ID.12..5).
    pub const EFF_ID3: u8 = 3;
    /// Identifier byte 4 of an extended frame (ID.4..0 in bits 7..3, RX RTR in bit 2).
    pub const EFF_ID4: u8 = 4;
    /// First data byte of an extended frame.
    pub const EFF_DATA: u8 = 5;
    /// RTR copy in SFF identifier byte 2 (receive buffer).
    pub const SFF_ID2_RTR: u8 = 0x10;
    /// RTR copy in EFF identifier byte 4 (receive buffer).
    pub const EFF_ID4_RTR: u8 = 0x04;
}

/// BasicCAN: offsets from TX identifier 1 (address 10) or RX identifier 1 (address 20).
pub mod basic {
    /// Identifier byte 1 (ID.10..3).
    pub const ID1: u8 = 0;
    /// Identifier byte 2 (ID.2..0, RTR, DLC).
    pub const ID2: u8 = 1;
    /// First data byte.
    pub const DATA: u8 = 2;
}

/// PeliCAN identifier bytes of an 11-bit identifier (`ID1`, `ID2`), RTR not set.
pub const fn peli_sff_id(id: u16) -> [u8; 2] {
    [(id >> 3) as u8, ((id & 7) << 5) as u8]
}

/// The 11-bit identifier from PeliCAN SFF identifier bytes.
pub const fn peli_sff_id_from(b: [u8; 2]) -> u16 {
    ((b[0] as u16) << 3) | (b[1] >> 5) as u16
}

/// PeliCAN identifier bytes of a 29-bit identifier (`ID1`..`ID4`), RTR not set.
pub const fn peli_eff_id(id: u32) -> [u8; 4] {
    let v = (id & 0x1FFF_FFFF) << 3;
    [(v >> 24) as u8, (v >> 16) as u8, (v >> 8) as u8, (v as u8) & 0xF8]
}

/// The 29-bit identifier from PeliCAN EFF identifier bytes.
pub const fn peli_eff_id_from(b: [u8; 4]) -> u32 {
    (((b[0] as u32) << 24) | ((b[1] as u32) << 16) | ((b[2] as u32) << 8) | (b[3] as u32)) >> 3
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifier_bytes_follow_the_data_sheet() {
        // ID.28 is bit 7 of ID1; ID.0 is bit 3 of EFF ID4; ID.18 is bit 5 of SFF ID2.
        assert_eq!(peli_sff_id(0x400), [0x80, 0x00]);
        assert_eq!(peli_sff_id(0x001), [0x00, 0x20]);
        assert_eq!(peli_eff_id(0x1000_0000), [0x80, 0, 0, 0]);
        assert_eq!(peli_eff_id(1), [0, 0, 0, 0x08]);
        for id in [0u16, 1, 0x123, 0x7FF] {
            assert_eq!(peli_sff_id_from(peli_sff_id(id)), id);
        }
        for id in [0u32, 1, 0x1234_5678 & 0x1FFF_FFFF, 0x1FFF_FFFF] {
            assert_eq!(peli_eff_id_from(peli_eff_id(id)), id);
        }
        // The thesis wrote ID1=0xA5, ID2=0x21 for a standard frame: ID 0x529.
        assert_eq!(peli_sff_id_from([0xA5, 0x21]), 0x529);
    }
}
