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
pub use embedded_can::{ExtendedId, Frame as FrameTrait, Id, StandardId};
pub use field::Field;
pub use frame::CanFrame;

/// Recessive bus level (logic 1).
pub const RECESSIVE: bool = true;
/// Dominant bus level (logic 0); wins on the wired-AND bus.
pub const DOMINANT: bool = false;

/// A bit stream in transmission order.
pub type Bits = bitvec::vec::BitVec<u32, bitvec::order::Lsb0>;
