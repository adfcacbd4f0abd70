//! Error code capture (ECC) and arbitration lost capture (ALC) encodings,
//! as the SJA1000 datasheet defines them (PeliCAN registers 11 and 12).

use crate::ErrorKind;
use can_proto::Field;

/// ECC segment codes (bits 4:0), datasheet table "bit interpretation of ECC".
pub(crate) mod seg {
    pub const SOF: u8 = 0b00011;
    pub const ID28_21: u8 = 0b00010;
    pub const ID20_18: u8 = 0b00110;
    pub const SRTR: u8 = 0b00100;
    pub const IDE: u8 = 0b00101;
    pub const ID17_13: u8 = 0b00111;
    pub const ID12_5: u8 = 0b01111;
    pub const ID4_0: u8 = 0b01110;
    pub const RTR: u8 = 0b01100;
    pub const R1: u8 = 0b01101;
    pub const R0: u8 = 0b01001;
    pub const DLC: u8 = 0b01011;
    pub const DATA: u8 = 0b01010;
    pub const CRC_SEQ: u8 = 0b01000;
    pub const CRC_DELIM: u8 = 0b11000;
    pub const ACK_SLOT: u8 = 0b11001;
    pub const ACK_DELIM: u8 = 0b11011;
    pub const EOF: u8 = 0b11010;
    pub const INTERMISSION: u8 = 0b10010;
    pub const ACTIVE_FLAG: u8 = 0b10001;
    pub const PASSIVE_FLAG: u8 = 0b10110;
    pub const TOLERATE_DOMINANT: u8 = 0b10011;
    pub const ERROR_DELIM: u8 = 0b10111;
    pub const OVERLOAD_FLAG: u8 = 0b11100;
}

/// ECC bits 7:6: 00 bit error, 01 form error, 10 stuff error, 11 other
/// (CRC and ACK errors have no code of their own).
const fn code(kind: ErrorKind) -> u8 {
    match kind {
        ErrorKind::Bit => 0b00,
        ErrorKind::Form => 0b01,
        ErrorKind::Stuff => 0b10,
        ErrorKind::Crc | ErrorKind::Ack => 0b11,
    }
}

/// The ECC register value. `rx`: the error happened during reception
/// (DIR = 1); a transmitter's errors have DIR = 0.
pub(crate) const fn ecc(kind: ErrorKind, rx: bool, segment: u8) -> u8 {
    (code(kind) << 6) | ((rx as u8) << 5) | (segment & 0x1f)
}

/// Segment code of bit `idx` (0 = first bit) of a frame field. Fields the
/// table does not list (bus idle, suspend) map to intermission; the overload
/// delimiter shares the error delimiter code (the table has one delimiter).
pub(crate) const fn segment(field: Field, idx: u8) -> u8 {
    match field {
        Field::Sof => seg::SOF,
        Field::BaseId => {
            if idx < 8 {
                seg::ID28_21
            } else {
                seg::ID20_18
            }
        }
        Field::SrrRtr => seg::SRTR,
        Field::Ide => seg::IDE,
        Field::ExtId => {
            if idx < 5 {
                seg::ID17_13
            } else if idx < 13 {
                seg::ID12_5
            } else {
                seg::ID4_0
            }
        }
        Field::Rtr => seg::RTR,
        Field::R1 => seg::R1,
        Field::R0 => seg::R0,
        Field::Dlc => seg::DLC,
        Field::Data => seg::DATA,
        Field::Crc => seg::CRC_SEQ,
        Field::CrcDelim => seg::CRC_DELIM,
        Field::AckSlot => seg::ACK_SLOT,
        Field::AckDelim => seg::ACK_DELIM,
        Field::Eof => seg::EOF,
        Field::Intermission | Field::BusIdle | Field::SuspendTransmission => seg::INTERMISSION,
        Field::ActiveErrorFlag => seg::ACTIVE_FLAG,
        Field::PassiveErrorFlag => seg::PASSIVE_FLAG,
        Field::ErrorDelimiter | Field::OverloadDelimiter => seg::ERROR_DELIM,
        Field::OverloadFlag => seg::OVERLOAD_FLAG,
    }
}

/// ALC bits 4:0 for a loss at bit `idx` of an arbitration field:
/// 0..=10 ID.28..ID.18, 11 SRR/RTR, 12 IDE, 13..=30 ID.17..ID.0, 31 RTR
/// of an extended frame.
pub(crate) const fn alc(field: Field, idx: u8) -> u8 {
    match field {
        Field::BaseId => idx,
        Field::SrrRtr => 11,
        Field::Ide => 12,
        Field::ExtId => 13 + idx,
        Field::Rtr => 31,
        _ => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Worked by hand from the bit layout: a stuff error in the data field
    /// while receiving is 10 1 01010 = 0xAA; a bit error at SOF while
    /// transmitting is 00 0 00011 = 0x03; an ACK error is "other" at the ACK
    /// slot, 11 0 11001 = 0xD9; a form error at the CRC delimiter while
    /// receiving is 01 1 11000 = 0x78.
    #[test]
    fn ecc_layout() {
        assert_eq!(ecc(ErrorKind::Stuff, true, segment(Field::Data, 3)), 0xAA);
        assert_eq!(ecc(ErrorKind::Bit, false, segment(Field::Sof, 0)), 0x03);
        assert_eq!(ecc(ErrorKind::Ack, false, segment(Field::AckSlot, 0)), 0xD9);
        assert_eq!(
            ecc(ErrorKind::Form, true, segment(Field::CrcDelim, 0)),
            0x78
        );
    }

    #[test]
    fn id_segments_split_as_the_table() {
        assert_eq!(segment(Field::BaseId, 7), seg::ID28_21);
        assert_eq!(segment(Field::BaseId, 8), seg::ID20_18);
        assert_eq!(segment(Field::ExtId, 4), seg::ID17_13);
        assert_eq!(segment(Field::ExtId, 5), seg::ID12_5);
        assert_eq!(segment(Field::ExtId, 12), seg::ID12_5);
        assert_eq!(segment(Field::ExtId, 13), seg::ID4_0);
    }

    #[test]
    fn alc_numbers() {
        assert_eq!(alc(Field::BaseId, 0), 0);
        assert_eq!(alc(Field::BaseId, 10), 10);
        assert_eq!(alc(Field::SrrRtr, 0), 11);
        assert_eq!(alc(Field::Ide, 0), 12);
        assert_eq!(alc(Field::ExtId, 0), 13);
        assert_eq!(alc(Field::ExtId, 17), 30);
        assert_eq!(alc(Field::Rtr, 0), 31);
    }
}
