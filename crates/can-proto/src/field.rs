//! Names of the fields and phases of the CAN bit stream, spelled as in the
//! CAN 2.0B specification; used by the decoder, the golden model, the
//! comparator and the diagnoser alike.

use core::fmt;

/// A field of a data/remote frame, or a phase of error/overload signalling.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Field {
    /// Bus idle (11 recessive bits seen, no frame under way).
    BusIdle,
    /// Start of frame (one dominant bit).
    Sof,
    /// Identifier bits ID.28..ID.18 (the whole 11-bit ID of a standard frame).
    BaseId,
    /// SRR (extended frames) or RTR (standard frames): decided by IDE.
    SrrRtr,
    /// Identifier extension bit.
    Ide,
    /// Identifier bits ID.17..ID.0 of an extended frame.
    ExtId,
    /// Remote transmission request bit of an extended frame.
    Rtr,
    /// Reserved bit r1 (extended frames).
    R1,
    /// Reserved bit r0.
    R0,
    /// Data length code.
    Dlc,
    /// Data field.
    Data,
    /// CRC sequence (15 bits).
    Crc,
    /// CRC delimiter (recessive).
    CrcDelim,
    /// ACK slot.
    AckSlot,
    /// ACK delimiter (recessive).
    AckDelim,
    /// End of frame (7 recessive bits).
    Eof,
    /// Intermission (3 recessive bits).
    Intermission,
    /// Suspend transmission (8 recessive bits, error-passive transmitter).
    SuspendTransmission,
    /// Active error flag (6 dominant bits).
    ActiveErrorFlag,
    /// Passive error flag (6 recessive bits).
    PassiveErrorFlag,
    /// Error delimiter (8 recessive bits).
    ErrorDelimiter,
    /// Overload flag (6 dominant bits).
    OverloadFlag,
    /// Overload delimiter (8 recessive bits).
    OverloadDelimiter,
}

impl Field {
    /// The specification's own words for the field.
    pub const fn spec_name(self) -> &'static str {
        match self {
            Field::BusIdle => "bus idle",
            Field::Sof => "start of frame",
            Field::BaseId => "identifier (ID.28-ID.18)",
            Field::SrrRtr => "SRR/RTR bit",
            Field::Ide => "IDE bit",
            Field::ExtId => "extended identifier (ID.17-ID.0)",
            Field::Rtr => "RTR bit",
            Field::R1 => "reserved bit r1",
            Field::R0 => "reserved bit r0",
            Field::Dlc => "data length code",
            Field::Data => "data field",
            Field::Crc => "CRC sequence",
            Field::CrcDelim => "CRC delimiter",
            Field::AckSlot => "ACK slot",
            Field::AckDelim => "ACK delimiter",
            Field::Eof => "end of frame",
            Field::Intermission => "intermission",
            Field::SuspendTransmission => "suspend transmission",
            Field::ActiveErrorFlag => "active error flag",
            Field::PassiveErrorFlag => "passive error flag",
            Field::ErrorDelimiter => "error delimiter",
            Field::OverloadFlag => "overload flag",
            Field::OverloadDelimiter => "overload delimiter",
        }
    }

    /// True for the fields covered by bit stuffing (SOF to CRC sequence).
    pub const fn is_stuffed(self) -> bool {
        matches!(
            self,
            Field::Sof
                | Field::BaseId
                | Field::SrrRtr
                | Field::Ide
                | Field::ExtId
                | Field::Rtr
                | Field::R1
                | Field::R0
                | Field::Dlc
                | Field::Data
                | Field::Crc
        )
    }
}

impl fmt::Display for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.spec_name())
    }
}
