//! Serde support for the workspace's plain enums (`Field`, `ErrorKind`,
//! `FaultState`) that do not derive serde themselves: they travel as their
//! variant names, so a JSON record reads `"field": "Sof"`.

use can_engine::{ErrorKind, FaultState};
use can_proto::Field;
use serde::{Deserialize, Deserializer, Serializer, de::Error as _};
use std::fmt::Debug;

/// An enum that can be written and read back by its variant name.
pub trait Named: Sized + Copy + Debug + 'static {
    /// Every variant, used to read a name back.
    const ALL: &'static [Self];

    /// The variant name (as `Debug` prints it).
    fn name(&self) -> String {
        format!("{self:?}")
    }

    /// Reads a variant back from its name.
    fn from_name(s: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|v| v.name() == s)
    }
}

impl Named for Field {
    const ALL: &'static [Self] = &[
        Field::BusIdle,
        Field::Sof,
        Field::BaseId,
        Field::SrrRtr,
        Field::Ide,
        Field::ExtId,
        Field::Rtr,
        Field::R1,
        Field::R0,
        Field::Dlc,
        Field::Data,
        Field::Crc,
        Field::CrcDelim,
        Field::AckSlot,
        Field::AckDelim,
        Field::Eof,
        Field::Intermission,
        Field::SuspendTransmission,
        Field::ActiveErrorFlag,
        Field::PassiveErrorFlag,
        Field::ErrorDelimiter,
        Field::OverloadFlag,
        Field::OverloadDelimiter,
    ];
}

impl Named for ErrorKind {
    const ALL: &'static [Self] =
        &[ErrorKind::Bit, ErrorKind::Stuff, ErrorKind::Crc, ErrorKind::Form, ErrorKind::Ack];
}

impl Named for FaultState {
    const ALL: &'static [Self] =
        &[FaultState::ErrorActive, FaultState::ErrorPassive, FaultState::BusOff];
}

/// `#[serde(with = "named::one")]` for a `Named` value.
pub mod one {
    use super::*;

    /// Writes the variant name.
    pub fn serialize<T: Named, S: Serializer>(v: &T, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&v.name())
    }

    /// Reads a variant name.
    pub fn deserialize<'de, T: Named, D: Deserializer<'de>>(d: D) -> Result<T, D::Error> {
        let s = String::deserialize(d)?;
        T::from_name(&s).ok_or_else(|| D::Error::custom(format!("unknown variant name `{s}`")))
    }
}

/// `#[serde(with = "named::opt", default)]` for an `Option` of a `Named` value.
pub mod opt {
    use super::*;

    /// Writes the variant name or null.
    pub fn serialize<T: Named, S: Serializer>(v: &Option<T>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => s.serialize_some(&v.name()),
            None => s.serialize_none(),
        }
    }

    /// Reads a variant name or null.
    pub fn deserialize<'de, T: Named, D: Deserializer<'de>>(d: D) -> Result<Option<T>, D::Error> {
        match Option::<String>::deserialize(d)? {
            None => Ok(None),
            Some(s) => T::from_name(&s)
                .map(Some)
                .ok_or_else(|| D::Error::custom(format!("unknown variant name `{s}`"))),
        }
    }
}
