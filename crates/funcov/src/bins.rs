//! The bin model: every bin, named the same way when listed and when hit.

use can_engine::{ErrorKind, FaultState};
use can_proto::Field;
use regmap::{Access, Mode, OpMode};

pub(crate) const FRAMES: &str = "frame kinds";
pub(crate) const ERRORS: &str = "error kinds x field";
pub(crate) const FAULT: &str = "fault confinement";
pub(crate) const ARBITRATION: &str = "arbitration loss";
pub(crate) const FILTER: &str = "acceptance filter";

/// `SFF data DLC 3`, `EFF remote DLC >8`.
pub(crate) fn frame(extended: bool, remote: bool, dlc: u8) -> String {
    let dlc = if dlc > 8 { ">8".to_string() } else { dlc.to_string() };
    format!("{} {} DLC {dlc}", if extended { "EFF" } else { "SFF" }, if remote { "remote" } else { "data" })
}

/// The fields each error kind can be detected in (CAN 2.0B §7.1, with
/// the ECC field the SJA1000 reports it in):
/// - bit: any bit a node sends dominant and may read recessive: the
///   arbitration bits a transmitter sends dominant, control, data and CRC,
///   a receiver's ACK, the dominant flags (a recessive bit sent in
///   arbitration that reads dominant is arbitration loss, not an error);
/// - stuff: the stuffed fields after SOF up to the CRC sequence;
/// - form: the fixed-form recessive bits and the delimiters;
/// - CRC: flagged after the ACK delimiter, the field the model reports;
/// - ACK: the ACK slot (transmitter).
pub(crate) const ERROR_FIELDS: &[(ErrorKind, &[Field])] = &[
    (
        ErrorKind::Bit,
        &[
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
            Field::AckSlot,
            Field::ActiveErrorFlag,
            Field::OverloadFlag,
        ],
    ),
    (
        ErrorKind::Stuff,
        &[Field::BaseId, Field::SrrRtr, Field::Ide, Field::ExtId, Field::Rtr, Field::R1, Field::R0, Field::Dlc, Field::Data, Field::Crc],
    ),
    (ErrorKind::Form, &[Field::CrcDelim, Field::AckDelim, Field::Eof, Field::ErrorDelimiter, Field::OverloadDelimiter]),
    (ErrorKind::Crc, &[Field::AckDelim]),
    (ErrorKind::Ack, &[Field::AckSlot]),
];

/// `stuff error in data field`.
pub(crate) fn error(kind: ErrorKind, field: Field) -> String {
    let k = match kind {
        ErrorKind::Bit => "bit",
        ErrorKind::Stuff => "stuff",
        ErrorKind::Crc => "CRC",
        ErrorKind::Form => "form",
        ErrorKind::Ack => "ACK",
    };
    format!("{k} error in {}", field.spec_name())
}

pub(crate) const WARNING_REACHED: &str = "error warning limit reached";
pub(crate) const WARNING_LEFT: &str = "error warning limit left";

fn state(s: FaultState) -> &'static str {
    match s {
        FaultState::ErrorActive => "error active",
        FaultState::ErrorPassive => "error passive",
        FaultState::BusOff => "bus-off",
    }
}

/// `error active -> error passive`; bus-off -> active is the recovery.
pub(crate) fn transition(from: FaultState, to: FaultState) -> String {
    let mut s = format!("{} -> {}", state(from), state(to));
    if from == FaultState::BusOff {
        s.push_str(" (recovery: 128 x 11 recessive bits)");
    }
    s
}

const TRANSITIONS: &[(FaultState, FaultState)] = &[
    (FaultState::ErrorActive, FaultState::ErrorPassive),
    (FaultState::ErrorPassive, FaultState::ErrorActive),
    (FaultState::ErrorPassive, FaultState::BusOff),
    (FaultState::BusOff, FaultState::ErrorActive),
];

/// ALC (datasheet table: 0..10 ID.28..ID.18, 11 SRR/RTR, 12 IDE,
/// 13..30 ID.17..ID.0, 31 RTR of an extended frame) by position class:
/// first, inner and last bit of each identifier part, and the single bits.
pub(crate) fn arbitration(alc: u8) -> String {
    match alc & 0x1F {
        0 => "first base ID bit (ID.28, ALC 0)",
        1..=9 => "inner base ID bit (ID.27-ID.19, ALC 1-9)",
        10 => "last base ID bit (ID.18, ALC 10)",
        11 => "SRR/RTR bit (ALC 11)",
        12 => "IDE bit (ALC 12)",
        13 => "first extended ID bit (ID.17, ALC 13)",
        14..=29 => "inner extended ID bit (ID.16-ID.1, ALC 14-29)",
        30 => "last extended ID bit (ID.0, ALC 30)",
        _ => "RTR bit of an extended frame (ALC 31)",
    }
    .to_string()
}

pub(crate) fn view_name(v: Mode) -> &'static str {
    match v {
        Mode::BasicCan => "BasicCAN",
        Mode::PeliCan => "PeliCAN",
    }
}

/// `registers PeliCAN reset write`.
pub(crate) fn register_group(v: Mode, op: OpMode, access: Access) -> String {
    let op = match op {
        OpMode::Reset => "reset",
        OpMode::Operating => "operating",
    };
    let a = match access {
        Access::Read => "read",
        Access::Write => "write",
    };
    format!("registers {} {op} {a}", view_name(v))
}

/// Addresses of a view.
pub(crate) fn addresses(v: Mode) -> std::ops::Range<u8> {
    match v {
        Mode::BasicCan => 0..32,
        Mode::PeliCan => 0..128,
    }
}

/// The register an access reaches and the bits it covers: for a write the
/// bits it can change, for a read the bits of the register's fields (all
/// eight of a data byte). A multi-byte window (TX buffer, RX FIFO, ACR
/// set...) is one name: its bytes share the bins.
pub(crate) fn register_bits(v: Mode, op: OpMode, access: Access, addr: u8) -> Option<(&'static str, u8)> {
    let view = regmap::lookup(v, op, access, addr)?;
    let r = view.register()?;
    let mask = match access {
        Access::Write => view.write_mask,
        Access::Read if r.fields.is_empty() => 0xFF,
        Access::Read => r.fields.iter().fold(0, |m, f| m | f.mask()),
    };
    (mask != 0).then_some((r.name, mask))
}

/// `MOD bit 3=1`.
pub(crate) fn register_bit(reg: &str, bit: u8, value: bool) -> String {
    format!("{reg} bit {bit}={}", value as u8)
}

/// `interrupts PeliCAN`.
pub(crate) fn interrupt_group(v: Mode) -> String {
    format!("interrupts {}", view_name(v))
}

/// IR's fields of a view (name, mask).
pub(crate) fn interrupt_fields(v: Mode) -> Vec<(&'static str, u8)> {
    regmap::register(v, "IR").map(|r| r.fields.iter().map(|f| (f.name, f.mask())).collect()).unwrap_or_default()
}

/// Address of IR (3 in both views).
pub(crate) fn ir_addr(v: Mode) -> u8 {
    regmap::register(v, "IR").map_or(3, |r| r.addr)
}

/// `BasicCAN SFF accepted`, `PeliCAN dual EFF rejected`.
pub(crate) fn filter(mode: &str, extended: bool, accepted: bool) -> String {
    format!("{mode} {} {}", if extended { "EFF" } else { "SFF" }, if accepted { "accepted" } else { "rejected" })
}

/// Every listed bin, in report order.
pub(crate) fn all() -> Vec<(String, String)> {
    let mut v = Vec::new();
    for ext in [false, true] {
        for remote in [false, true] {
            for dlc in 0..=9 {
                v.push((FRAMES.to_string(), frame(ext, remote, dlc)));
            }
        }
    }
    for (kind, fields) in ERROR_FIELDS {
        for f in *fields {
            v.push((ERRORS.to_string(), error(*kind, *f)));
        }
    }
    v.push((FAULT.to_string(), WARNING_REACHED.to_string()));
    v.push((FAULT.to_string(), WARNING_LEFT.to_string()));
    for (a, b) in TRANSITIONS {
        v.push((FAULT.to_string(), transition(*a, *b)));
    }
    let mut classes: Vec<String> = (0..32).map(arbitration).collect();
    classes.dedup();
    v.extend(classes.into_iter().map(|c| (ARBITRATION.to_string(), c)));
    for view in [Mode::BasicCan, Mode::PeliCan] {
        for op in [OpMode::Reset, OpMode::Operating] {
            for access in [Access::Write, Access::Read] {
                let group = register_group(view, op, access);
                let mut seen: Vec<(&str, u8)> = Vec::new();
                for addr in addresses(view) {
                    let Some((reg, mask)) = register_bits(view, op, access, addr) else { continue };
                    for bit in (0..8).rev().filter(|b| mask & (1 << b) != 0) {
                        if seen.contains(&(reg, bit)) {
                            continue;
                        }
                        seen.push((reg, bit));
                        for value in [true, false] {
                            v.push((group.clone(), register_bit(reg, bit, value)));
                        }
                    }
                }
            }
        }
    }
    for view in [Mode::BasicCan, Mode::PeliCan] {
        for (f, _) in interrupt_fields(view) {
            v.push((interrupt_group(view), format!("{f} raised")));
            v.push((interrupt_group(view), format!("{f} cleared")));
        }
    }
    v.push((FILTER.to_string(), filter("BasicCAN", false, true)));
    v.push((FILTER.to_string(), filter("BasicCAN", false, false)));
    v.push((FILTER.to_string(), filter("BasicCAN", true, false)));
    for mode in ["PeliCAN single", "PeliCAN dual"] {
        for ext in [false, true] {
            for acc in [true, false] {
                v.push((FILTER.to_string(), filter(mode, ext, acc)));
            }
        }
    }
    v
}
