//! CAN 2.0A/B wire format: frames, CRC-15, bit stuffing, field names, bit
//! timing and a decoder from sampled bus levels back to frames.
//!
//! Conventions used across the whole workspace:
//! - a bus level is a `bool`: `true` is recessive (logic 1), `false` is
//!   dominant (logic 0); see [`RECESSIVE`] and [`DOMINANT`];
//! - bit streams are [`bitvec`] vectors in transmission order (first bit
//!   on the wire first).
//!
//! References: Bosch CAN Specification 2.0 part B (1991), ISO 11898-1.
//!
//! Decoding sampled bus levels (here: 11 idle bits, then the frame of the
//! DE2 thesis, ID 0x529 with one data byte 0x51, acknowledged):
//! ```
//! use can_proto::{decode_str, DecodeEvent, Field};
//! let ev = decode_str(
//!     "11111111111 0 10100101001 0 0 0 00 1 01 01010001 1111 0 10100101010 1 0 1 1111111 111",
//! )
//! .unwrap();
//! assert!(ev.contains(&DecodeEvent::FieldStart { field: Field::Data, bit: 11 + 20 }));
//! assert!(ev.contains(&DecodeEvent::StuffBit { bit: 11 + 17 }));
//! let DecodeEvent::Frame(f) = ev.iter().find(|e| matches!(e, DecodeEvent::Frame(_))).unwrap() else {
//!     unreachable!()
//! };
//! assert_eq!(f.frame.raw_id(), 0x529);
//! assert!(f.ack);
//! ```
//!
//! Choosing and checking BTR0/BTR1:
//! ```
//! use can_proto::BusTiming;
//! let best = BusTiming::for_bit_rate(16_000_000, 125_000).unwrap();
//! assert_eq!(best.timing.to_btr(), (0x43, 0x1C)); // 16 tq, sample point 87.5 %
//! let issues = BusTiming::from_btr(0x03, 0xBB).validate(16_000_000, 125_000);
//! assert_eq!(
//!     issues[0].to_string(),
//!     "The bit rate is 117.6 kbit/s, 5.9% (58824 ppm) below the 125 kbit/s target."
//! );
//! ```
#![no_std]
#![warn(missing_docs)]

extern crate alloc;
#[cfg(test)]
extern crate std;

pub mod crc;
pub mod decode;
pub mod field;
pub mod frame;
pub mod stuff;
pub mod timing;

pub use crc::Crc15;
pub use decode::{
    BusError, DecodeEvent, DecodedFrame, Decoder, decode_bits, decode_str, parse_frame,
};
pub use embedded_can::{ExtendedId, Frame as FrameTrait, Id, StandardId};
pub use field::Field;
pub use frame::{CanFrame, WireBit};
pub use timing::{BusTiming, Candidate, TimingIssue};

/// Recessive bus level (logic 1).
pub const RECESSIVE: bool = true;
/// Dominant bus level (logic 0); wins on the wired-AND bus.
pub const DOMINANT: bool = false;

/// A bit stream in transmission order.
pub type Bits = bitvec::vec::BitVec<u32, bitvec::order::Lsb0>;
