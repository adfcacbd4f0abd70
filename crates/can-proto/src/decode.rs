//! Decoder from sampled bus levels (one `bool` per bit time, `true` =
//! recessive) to field boundaries, stuff bits, frames and error signalling,
//! each stamped with its bit index (0 = the first bit pushed).
//!
//! The decoder is a passive observer: it never drives the bus, so it sees
//! what every receiver sees, and it follows the error and overload
//! signalling of the other nodes rather than sending its own.
//!
//! Rules it applies (Bosch CAN 2.0B; ISO 11898-1 where noted):
//! - **Integration.** After [`Decoder::new`] it waits for 11 consecutive
//!   recessive bits before it accepts a start of frame, so a stream that
//!   begins in the middle of a frame is not misread. The bus idle field is
//!   reported from the first of those 11 bits.
//! - **Stuffing.** From SOF to the end of the CRC sequence, the bit after
//!   five equal bits is a stuff bit; if it equals them it is a stuff error.
//!   A stuff bit may follow the last CRC bit.
//! - **CRC.** Checked when the last CRC bit arrives; the error is reported
//!   there, and the error flag is expected after the ACK delimiter.
//! - **Form.** CRC delimiter, ACK delimiter and EOF bits 1-6 must be
//!   recessive; so must error and overload delimiters except their last bit.
//!   A dominant last EOF bit is no error for receivers: the frame is valid
//!   and the dominant bit starts an overload flag.
//! - **Acknowledgement.** A recessive ACK slot followed by a dominant ACK
//!   delimiter is read as the transmitter's ACK error flag.
//! - **Error flags.** After an error the next bit starts the flag: dominant
//!   gives an active error flag, which lasts while the bus stays dominant
//!   (superposed flags of other nodes included); recessive gives a passive
//!   error flag, complete after 6 equal bits. The error delimiter starts at
//!   the first recessive bit after the flag and lasts 8 bits.
//! - **Overload.** A dominant bit in intermission bits 1-2, or in the last bit
//!   of an error or overload delimiter (ISO 11898-1), starts an overload flag;
//!   a dominant third intermission bit is a start of frame (ISO 11898-1).
//! - Suspend transmission looks like bus idle to an observer and is reported
//!   as such.

use crate::{CanFrame, Crc15, Field, Id, RECESSIVE};
use bitvec::{order::BitOrder, slice::BitSlice, store::BitStore};
use core::fmt;
use embedded_can::{ExtendedId, StandardId};

/// Consecutive recessive bits that integrate the decoder onto the bus.
pub const INTEGRATION_BITS: u8 = 11;

/// An error the decoder detected, named as in CAN 2.0B §7.1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BusError {
    /// Six equal bits in a stuffed field.
    Stuff,
    /// The received CRC sequence differs from the computed one.
    Crc,
    /// A fixed-form bit field holds an illegal bit.
    Form,
    /// The ACK slot stayed recessive (seen through the transmitter's flag).
    Acknowledge,
}

impl BusError {
    /// The matching [`embedded_can::ErrorKind`].
    pub const fn kind(self) -> embedded_can::ErrorKind {
        match self {
            BusError::Stuff => embedded_can::ErrorKind::Stuff,
            BusError::Crc => embedded_can::ErrorKind::Crc,
            BusError::Form => embedded_can::ErrorKind::Form,
            BusError::Acknowledge => embedded_can::ErrorKind::Acknowledge,
        }
    }
}

impl fmt::Display for BusError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            BusError::Stuff => "stuff error",
            BusError::Crc => "CRC error",
            BusError::Form => "form error",
            BusError::Acknowledge => "acknowledgement error",
        })
    }
}

/// A frame received without error up to the last EOF bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DecodedFrame {
    /// The frame.
    pub frame: CanFrame,
    /// Bit index of its SOF.
    pub start_bit: u64,
    /// Bit index of its last EOF bit.
    pub end_bit: u64,
    /// True when some node drove the ACK slot dominant.
    pub ack: bool,
}

/// One thing the decoder saw, in bus order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DecodeEvent {
    /// `field` begins at bit `bit`.
    FieldStart {
        /// The field.
        field: Field,
        /// Bit index of its first bit.
        bit: u64,
    },
    /// Bit `bit` is a stuff bit.
    StuffBit {
        /// Its bit index.
        bit: u64,
    },
    /// A complete frame (reported at its last EOF bit).
    Frame(DecodedFrame),
    /// An error detected at bit `bit` while in `field`.
    Error {
        /// What went wrong.
        error: BusError,
        /// The field in which it was detected.
        field: Field,
        /// Bit index where it was detected.
        bit: u64,
    },
}

impl DecodeEvent {
    /// The bit index the event is stamped with (a frame's last EOF bit).
    pub const fn bit(&self) -> u64 {
        match self {
            DecodeEvent::FieldStart { bit, .. }
            | DecodeEvent::StuffBit { bit }
            | DecodeEvent::Error { bit, .. } => *bit,
            DecodeEvent::Frame(f) => f.end_bit,
        }
    }
}

impl fmt::Display for DecodeEvent {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DecodeEvent::FieldStart { field, bit } => write!(f, "bit {bit}: {field}"),
            DecodeEvent::StuffBit { bit } => write!(f, "bit {bit}: stuff bit"),
            DecodeEvent::Frame(d) => write!(
                f,
                "bits {}-{}: frame id 0x{:x}{} dlc {}{}",
                d.start_bit,
                d.end_bit,
                d.frame.raw_id(),
                if embedded_can::Frame::is_extended(&d.frame) {
                    " (extended)"
                } else {
                    ""
                },
                d.frame.dlc_raw(),
                if d.ack { "" } else { ", not acknowledged" }
            ),
            DecodeEvent::Error { error, field, bit } => write!(f, "bit {bit}: {error} in {field}"),
        }
    }
}

/// The events of one [`Decoder::push`]; at most [`Events::CAPACITY`], held
/// inline so that pushing a bit never allocates.
#[derive(Clone, Debug)]
pub struct Events {
    buf: [Option<DecodeEvent>; Events::CAPACITY],
    next: u8,
}

impl Events {
    /// Most events one bit can produce (two happen, e.g. a field start and a
    /// form error on the same bit; one slot of margin).
    pub const CAPACITY: usize = 3;

    const fn new() -> Self {
        Events {
            buf: [None; Events::CAPACITY],
            next: 0,
        }
    }

    fn push(&mut self, e: DecodeEvent) {
        let slot = self.buf.iter_mut().find(|s| s.is_none());
        debug_assert!(
            slot.is_some(),
            "more than {} events for one bit",
            Events::CAPACITY
        );
        if let Some(s) = slot {
            *s = Some(e);
        }
    }
}

impl Iterator for Events {
    type Item = DecodeEvent;

    fn next(&mut self) -> Option<DecodeEvent> {
        let e = self.buf.get_mut(self.next as usize)?.take();
        if e.is_some() {
            self.next += 1;
        }
        e
    }
}

/// What an error/overload delimiter belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum DelimKind {
    Error,
    Overload,
}

/// The destuffing receiver for SOF..CRC.
#[derive(Clone, Copy, Debug)]
struct Rx {
    start_bit: u64,
    /// Field of the bit being received, bits left in it, whether its start
    /// has been reported.
    field: Field,
    left: u8,
    started: bool,
    /// Value of the current field so far (MSB first).
    acc: u32,
    /// Stuffing: level and length of the current run of equal bits.
    run_level: bool,
    run: u8,
    crc: Crc15,
    base_id: u16,
    srr_rtr: bool,
    ide: bool,
    ext_id: u32,
    rtr: bool,
    dlc: u8,
    data: [u8; 8],
    data_bits: u8,
    crc_ok: bool,
    /// The CRC sequence is complete (a stuff bit may still follow).
    done: bool,
}

impl Rx {
    const fn new(start_bit: u64) -> Self {
        Rx {
            start_bit,
            field: Field::Sof,
            left: 1,
            started: false,
            acc: 0,
            run_level: !RECESSIVE,
            run: 0,
            crc: Crc15::new(),
            base_id: 0,
            srr_rtr: false,
            ide: false,
            ext_id: 0,
            rtr: false,
            dlc: 0,
            data: [0; 8],
            data_bits: 0,
            crc_ok: false,
            done: false,
        }
    }

    fn data_len(&self) -> u8 {
        if self.rtr { 0 } else { self.dlc.min(8) }
    }

    fn frame(&self) -> Option<CanFrame> {
        let id = if self.ide {
            Id::Extended(ExtendedId::new(
                ((self.base_id as u32) << 18) | self.ext_id,
            )?)
        } else {
            Id::Standard(StandardId::new(self.base_id)?)
        };
        CanFrame::with_dlc(
            id,
            self.rtr,
            self.dlc,
            &self.data[..self.data_len() as usize],
        )
    }

    /// Moves to `field` with `len` bits.
    fn enter(&mut self, field: Field, len: u8) {
        self.field = field;
        self.left = len;
        self.started = false;
        self.acc = 0;
    }

    /// Takes one destuffed bit; reports the field start and a CRC error.
    fn take(&mut self, level: bool, bit: u64, ev: &mut Events) {
        if !self.started {
            self.started = true;
            ev.push(DecodeEvent::FieldStart {
                field: self.field,
                bit,
            });
        }
        if self.field != Field::Crc {
            self.crc.push(level);
        }
        self.acc = (self.acc << 1) | level as u32;
        if self.field == Field::Data {
            self.data_bits += 1;
            if self.data_bits & 7 == 0 {
                self.data[(self.data_bits / 8 - 1) as usize] = self.acc as u8;
                self.acc = 0;
            }
        }
        self.left -= 1;
        if self.left > 0 {
            return;
        }
        let v = self.acc;
        match self.field {
            Field::Sof => self.enter(Field::BaseId, 11),
            Field::BaseId => {
                self.base_id = v as u16;
                self.enter(Field::SrrRtr, 1);
            }
            Field::SrrRtr => {
                self.srr_rtr = level;
                self.enter(Field::Ide, 1);
            }
            Field::Ide => {
                self.ide = level;
                if level {
                    self.enter(Field::ExtId, 18);
                } else {
                    self.rtr = self.srr_rtr;
                    self.enter(Field::R0, 1);
                }
            }
            Field::ExtId => {
                self.ext_id = v;
                self.enter(Field::Rtr, 1);
            }
            Field::Rtr => {
                self.rtr = level;
                self.enter(Field::R1, 1);
            }
            // Reserved bits: receivers accept either level (CAN 2.0B §3.1.1.4).
            Field::R1 => self.enter(Field::R0, 1),
            Field::R0 => self.enter(Field::Dlc, 4),
            Field::Dlc => {
                self.dlc = v as u8;
                match self.data_len() {
                    0 => self.enter(Field::Crc, 15),
                    n => self.enter(Field::Data, 8 * n),
                }
            }
            Field::Data => self.enter(Field::Crc, 15),
            Field::Crc => {
                self.crc_ok = v as u16 == self.crc.value();
                self.done = true;
                if !self.crc_ok {
                    ev.push(DecodeEvent::Error {
                        error: BusError::Crc,
                        field: Field::Crc,
                        bit,
                    });
                }
            }
            _ => {}
        }
    }
}

/// Where the decoder is in the bit stream.
#[derive(Clone, Copy, Debug)]
enum State {
    /// Counting recessive bits before the first SOF may be accepted.
    Integrating { recessive: u8 },
    /// Bus idle; `announced` once its field start was reported.
    Idle { announced: bool },
    /// SOF..CRC (and a stuff bit after the CRC).
    Frame,
    /// CRC delimiter, ACK slot, ACK delimiter and EOF; `n` = bits of the
    /// current field already seen.
    Tail {
        field: Field,
        n: u8,
        ack: bool,
        ack_bit: u64,
    },
    /// `n` intermission bits seen.
    Intermission { n: u8 },
    /// First bit after an error: decides active or passive flag.
    ErrorFlagStart,
    /// Passive error flag: waiting for 6 equal bits.
    PassiveFlag { level: bool, run: u8 },
    /// Error flag complete or active: waiting for the first recessive bit.
    FlagTail,
    /// Overload flag, `dominant` bits seen.
    OverloadFlag { dominant: u8 },
    /// Error or overload delimiter, `n` recessive bits seen.
    Delimiter { kind: DelimKind, n: u8 },
}

/// Streaming decoder; see the module documentation for the rules.
#[derive(Clone, Debug)]
pub struct Decoder {
    state: State,
    /// The frame under way (meaningful in `Frame` and `Tail`).
    rx: Rx,
    bit: u64,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Decoder {
    /// A decoder that has not integrated yet (see the module documentation).
    pub const fn new() -> Self {
        Decoder {
            state: State::Integrating { recessive: 0 },
            rx: Rx::new(0),
            bit: 0,
        }
    }

    /// A decoder that takes the bus as already idle: the first dominant bit
    /// is a start of frame. For streams known to begin on an idle bus, such
    /// as a transmitter's own bits (see [`parse_frame`]).
    pub const fn integrated() -> Self {
        Decoder {
            state: State::Idle { announced: true },
            rx: Rx::new(0),
            bit: 0,
        }
    }

    /// Index the next pushed bit will get.
    pub const fn bit_index(&self) -> u64 {
        self.bit
    }

    /// Takes the bus level of one bit time (`true` = recessive) and returns
    /// what it completes or starts. Never allocates.
    pub fn push(&mut self, level: bool) -> Events {
        let bit = self.bit;
        self.bit += 1;
        let mut ev = Events::new();
        let dominant = !level;
        self.state = match self.state {
            State::Integrating { recessive } => {
                if dominant {
                    State::Integrating { recessive: 0 }
                } else if recessive + 1 == INTEGRATION_BITS {
                    ev.push(DecodeEvent::FieldStart {
                        field: Field::BusIdle,
                        bit: bit + 1 - INTEGRATION_BITS as u64,
                    });
                    State::Idle { announced: true }
                } else {
                    State::Integrating {
                        recessive: recessive + 1,
                    }
                }
            }
            State::Idle { announced } => {
                if dominant {
                    Self::sof(&mut self.rx, bit, &mut ev)
                } else {
                    if !announced {
                        ev.push(DecodeEvent::FieldStart {
                            field: Field::BusIdle,
                            bit,
                        });
                    }
                    State::Idle { announced: true }
                }
            }
            State::Frame => Self::frame_bit(&mut self.rx, level, bit, &mut ev),
            State::Tail {
                field,
                n,
                ack,
                ack_bit,
            } => Self::tail_bit(&self.rx, field, n, ack, ack_bit, level, bit, &mut ev),
            State::Intermission { n } => {
                if n == 0 {
                    ev.push(DecodeEvent::FieldStart {
                        field: Field::Intermission,
                        bit,
                    });
                }
                match (dominant, n) {
                    (false, 2) => State::Idle { announced: false },
                    (false, _) => State::Intermission { n: n + 1 },
                    // ISO 11898-1: a dominant third intermission bit is SOF.
                    (true, 2) => Self::sof(&mut self.rx, bit, &mut ev),
                    (true, _) => Self::overload_flag(bit, &mut ev),
                }
            }
            State::ErrorFlagStart => {
                if dominant {
                    ev.push(DecodeEvent::FieldStart {
                        field: Field::ActiveErrorFlag,
                        bit,
                    });
                    State::FlagTail
                } else {
                    ev.push(DecodeEvent::FieldStart {
                        field: Field::PassiveErrorFlag,
                        bit,
                    });
                    State::PassiveFlag { level, run: 1 }
                }
            }
            State::PassiveFlag { level: l, run } => {
                let run = if l == level { run + 1 } else { 1 };
                if run < 6 {
                    State::PassiveFlag { level, run }
                } else {
                    // The flag is complete; the node now sends recessive and
                    // waits for a recessive bus to start its delimiter.
                    State::FlagTail
                }
            }
            State::FlagTail => {
                if dominant {
                    State::FlagTail
                } else {
                    ev.push(DecodeEvent::FieldStart {
                        field: Field::ErrorDelimiter,
                        bit,
                    });
                    State::Delimiter {
                        kind: DelimKind::Error,
                        n: 1,
                    }
                }
            }
            State::OverloadFlag { dominant: d } => {
                if dominant {
                    State::OverloadFlag {
                        dominant: d.saturating_add(1),
                    }
                } else if d >= 6 {
                    ev.push(DecodeEvent::FieldStart {
                        field: Field::OverloadDelimiter,
                        bit,
                    });
                    State::Delimiter {
                        kind: DelimKind::Overload,
                        n: 1,
                    }
                } else {
                    ev.push(DecodeEvent::Error {
                        error: BusError::Form,
                        field: Field::OverloadFlag,
                        bit,
                    });
                    State::ErrorFlagStart
                }
            }
            State::Delimiter { kind, n } => {
                let field = match kind {
                    DelimKind::Error => Field::ErrorDelimiter,
                    DelimKind::Overload => Field::OverloadDelimiter,
                };
                match (dominant, n) {
                    (false, 7) => State::Intermission { n: 0 },
                    (false, _) => State::Delimiter { kind, n: n + 1 },
                    // ISO 11898-1: dominant last delimiter bit = overload.
                    (true, 7) => Self::overload_flag(bit, &mut ev),
                    (true, _) => {
                        ev.push(DecodeEvent::Error {
                            error: BusError::Form,
                            field,
                            bit,
                        });
                        State::ErrorFlagStart
                    }
                }
            }
        };
        ev
    }

    fn sof(rx: &mut Rx, bit: u64, ev: &mut Events) -> State {
        *rx = Rx::new(bit);
        rx.take(false, bit, ev);
        rx.run_level = false;
        rx.run = 1;
        State::Frame
    }

    fn overload_flag(bit: u64, ev: &mut Events) -> State {
        ev.push(DecodeEvent::FieldStart {
            field: Field::OverloadFlag,
            bit,
        });
        State::OverloadFlag { dominant: 1 }
    }

    fn frame_bit(rx: &mut Rx, level: bool, bit: u64, ev: &mut Events) -> State {
        if rx.run == crate::stuff::STUFF_WIDTH {
            if level == rx.run_level {
                // Reported in the field the receiver's bit counter is in: the
                // one the next data bit belongs to (CRC for a stuff bit after
                // the CRC sequence).
                ev.push(DecodeEvent::Error {
                    error: BusError::Stuff,
                    field: rx.field,
                    bit,
                });
                return State::ErrorFlagStart;
            }
            ev.push(DecodeEvent::StuffBit { bit });
            rx.run_level = level;
            rx.run = 1;
        } else {
            if level == rx.run_level {
                rx.run += 1;
            } else {
                rx.run_level = level;
                rx.run = 1;
            }
            rx.take(level, bit, ev);
        }
        if rx.done && rx.run < crate::stuff::STUFF_WIDTH {
            State::Tail {
                field: Field::CrcDelim,
                n: 0,
                ack: false,
                ack_bit: 0,
            }
        } else {
            State::Frame
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn tail_bit(
        rx: &Rx,
        field: Field,
        n: u8,
        mut ack: bool,
        mut ack_bit: u64,
        level: bool,
        bit: u64,
        ev: &mut Events,
    ) -> State {
        let dominant = !level;
        let form = |ev: &mut Events| {
            ev.push(DecodeEvent::Error {
                error: BusError::Form,
                field,
                bit,
            });
            State::ErrorFlagStart
        };
        match field {
            Field::AckDelim if dominant && !ack => {
                // The transmitter saw no ACK and flags it from here on.
                ev.push(DecodeEvent::Error {
                    error: BusError::Acknowledge,
                    field: Field::AckSlot,
                    bit: ack_bit,
                });
                ev.push(DecodeEvent::FieldStart {
                    field: Field::ActiveErrorFlag,
                    bit,
                });
                return State::FlagTail;
            }
            _ => {}
        }
        if n == 0 {
            ev.push(DecodeEvent::FieldStart { field, bit });
        }
        let next = |field, ack, ack_bit| State::Tail {
            field,
            n: 0,
            ack,
            ack_bit,
        };
        match field {
            Field::CrcDelim if dominant => form(ev),
            Field::CrcDelim => next(Field::AckSlot, false, 0),
            Field::AckSlot => {
                ack = dominant;
                ack_bit = bit;
                next(Field::AckDelim, ack, ack_bit)
            }
            Field::AckDelim if dominant => form(ev),
            // CAN 2.0B §7.2: a CRC error is flagged after the ACK delimiter.
            Field::AckDelim if !rx.crc_ok => State::ErrorFlagStart,
            Field::AckDelim => next(Field::Eof, ack, ack_bit),
            Field::Eof if n < 6 => {
                if dominant {
                    form(ev)
                } else {
                    State::Tail {
                        field,
                        n: n + 1,
                        ack,
                        ack_bit,
                    }
                }
            }
            Field::Eof => {
                // Last EOF bit: the frame is valid for receivers either way
                // (CAN 2.0B §5); a dominant level starts an overload flag.
                if let Some(frame) = rx.frame() {
                    ev.push(DecodeEvent::Frame(DecodedFrame {
                        frame,
                        start_bit: rx.start_bit,
                        end_bit: bit,
                        ack,
                    }));
                }
                if dominant {
                    Self::overload_flag(bit, ev)
                } else {
                    State::Intermission { n: 0 }
                }
            }
            _ => form(ev),
        }
    }

    /// Decodes a whole stream from a fresh decoder.
    pub fn decode<I: IntoIterator<Item = bool>>(levels: I) -> alloc::vec::Vec<DecodeEvent> {
        let mut d = Decoder::new();
        let mut out = alloc::vec::Vec::new();
        for l in levels {
            out.extend(d.push(l));
        }
        out
    }
}

/// Decodes a bit slice (transmission order) from a fresh decoder.
pub fn decode_bits<T: BitStore, O: BitOrder>(
    bits: &BitSlice<T, O>,
) -> alloc::vec::Vec<DecodeEvent> {
    Decoder::decode(bits.iter().by_vals())
}

/// Why [`parse_frame`] found no frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    /// The decoder detected an error.
    #[error("{error} in the {field} at bit {bit}")]
    Bus {
        /// What went wrong.
        error: BusError,
        /// Where.
        field: Field,
        /// Bit index from the start of the slice.
        bit: u64,
    },
    /// The bits end before the last EOF bit.
    #[error("the bit stream ends after {bits} bits, before the end of the frame")]
    Truncated {
        /// Length of the slice.
        bits: u64,
    },
}

/// Reads the first frame of a stream that starts on an idle bus (leading
/// recessive bits are idle), such as [`CanFrame::wire_bits`]: the frame with
/// bit indices from the start of the slice, or the first error.
pub fn parse_frame<T: BitStore, O: BitOrder>(
    bits: &BitSlice<T, O>,
) -> Result<DecodedFrame, FrameError> {
    let mut d = Decoder::integrated();
    for level in bits.iter().by_vals() {
        for e in d.push(level) {
            match e {
                DecodeEvent::Frame(f) => return Ok(f),
                DecodeEvent::Error { error, field, bit } => {
                    return Err(FrameError::Bus { error, field, bit });
                }
                _ => {}
            }
        }
    }
    Err(FrameError::Truncated {
        bits: bits.len() as u64,
    })
}

/// A character of a bit string that is neither a bit nor a separator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "character {ch:?} at position {pos} is not a bit (expected 0, 1, or a separator: space, _ or |)"
)]
pub struct NotABit {
    /// Character index in the string.
    pub pos: usize,
    /// The character.
    pub ch: char,
}

/// Decodes a string of `0` (dominant) and `1` (recessive); spaces, `_` and
/// `|` are separators for readability.
pub fn decode_str(s: &str) -> Result<alloc::vec::Vec<DecodeEvent>, NotABit> {
    let mut levels = alloc::vec::Vec::with_capacity(s.len());
    for (pos, ch) in s.chars().enumerate() {
        match ch {
            '0' => levels.push(false),
            '1' => levels.push(true),
            c if c.is_whitespace() || c == '_' || c == '|' => {}
            ch => return Err(NotABit { pos, ch }),
        }
    }
    Ok(Decoder::decode(levels))
}

#[cfg(test)]
mod tests;
