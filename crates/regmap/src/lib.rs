//! The one SJA1000 register map.
//!
//! Everything that knows an SJA1000 address or bit (the golden model's
//! register file, the C headers, the `_hw.tcl`, the Markdown reference and
//! the RTL's Verilog include) derives it from the tables in this crate, so
//! there is no second hand-typed copy that can drift.
//!
//! Source of the facts: the Philips SJA1000 data sheet (2000 Jan 04),
//! sections 6.3 (BasicCAN), 6.4 (PeliCAN) and 6.5 (common registers).
//! Seed 000 annexe 1 (the DE2 thesis) has a summary table with errors; where
//! it differs from the data sheet, the data sheet wins and the table below
//! says so in a comment.
//!
//! Two views share the same pins: BasicCAN (PCA82C200 compatible, `CDR.7 =
//! 0`, 32 addresses) and PeliCAN (`CDR.7 = 1`, 128 addresses). In each view
//! the meaning of an address depends on the operating mode ([`OpMode`]:
//! reset mode while `MOD.RM` / `CR.RR` is 1) and on the direction
//! ([`Access`]); [`lookup`] answers "what does this access reach".
//!
//! Typed constants for code: [`peli`] and [`basic`] (e.g. `peli::SR`,
//! `peli::sr::TBS`, `peli::sr::lsb::TBS`, `peli::len::RXFIFO`) are emitted by
//! the same macro invocation that builds the tables.
#![warn(missing_docs)]

mod map;
pub mod frame;
pub mod generate;
pub use map::{basic, peli};

use std::fmt;

/// Which register view the controller presents (`CDR.7`, "CAN mode").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Mode {
    /// PCA82C200-compatible view, `CDR.7 = 0` (the hardware reset default).
    BasicCan,
    /// Extended view, `CDR.7 = 1`.
    PeliCan,
}

impl Mode {
    /// Both views, BasicCAN first.
    pub const ALL: [Mode; 2] = [Mode::BasicCan, Mode::PeliCan];

    /// The mode selected by a clock divider register value (`CDR.7`).
    pub const fn from_cdr(cdr: u8) -> Mode {
        if cdr & peli::cdr::CANMODE != 0 { Mode::PeliCan } else { Mode::BasicCan }
    }

    /// Number of defined addresses: 32 in BasicCAN, 128 in PeliCAN.
    ///
    /// The data sheet defines BasicCAN addresses 0..=31 and PeliCAN
    /// addresses 0..=127 only. This map does not guess a mirror for the
    /// rest: an address at or above this limit is [`RegError::OutOfRange`].
    pub const fn addr_limit(self) -> u16 {
        match self {
            Mode::BasicCan => 32,
            Mode::PeliCan => 128,
        }
    }

    /// Short name used in generated identifiers: `BASIC` or `PELI`.
    pub const fn tag(self) -> &'static str {
        match self {
            Mode::BasicCan => "BASIC",
            Mode::PeliCan => "PELI",
        }
    }
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Mode::BasicCan => "BasicCAN",
            Mode::PeliCan => "PeliCAN",
        })
    }
}

/// Reset mode (`MOD.RM` / `CR.RR` = 1) or operating mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum OpMode {
    /// Reset mode: configuration registers (ACR/AMR, BTR, OCR, ...) are writable.
    Reset,
    /// Operating mode: the controller is on the bus.
    Operating,
}

impl OpMode {
    /// Both, reset mode first.
    pub const ALL: [OpMode; 2] = [OpMode::Reset, OpMode::Operating];
}

impl fmt::Display for OpMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            OpMode::Reset => "reset mode",
            OpMode::Operating => "operating mode",
        })
    }
}

/// Direction of a host access.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Access {
    /// Host reads.
    Read,
    /// Host writes.
    Write,
}

impl Access {
    /// Both, read first.
    pub const ALL: [Access; 2] = [Access::Read, Access::Write];
}

/// A bit field of a register.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FieldDef {
    /// Data sheet symbol (e.g. `TBS`).
    pub name: &'static str,
    /// Least significant bit.
    pub lsb: u8,
    /// Width in bits.
    pub width: u8,
    /// What the field means, in a few words.
    pub meaning: &'static str,
}

impl FieldDef {
    /// In-register mask of the field (e.g. `0x04` for `SR.TBS`).
    pub const fn mask(&self) -> u8 {
        (((1u16 << self.width) - 1) << self.lsb) as u8
    }

    /// Extracts the field from a register value.
    pub const fn get(&self, reg: u8) -> u8 {
        (reg & self.mask()) >> self.lsb
    }

    /// Returns `reg` with the field replaced by `value` (extra bits dropped).
    pub const fn set(&self, reg: u8, value: u8) -> u8 {
        (reg & !self.mask()) | ((value << self.lsb) & self.mask())
    }
}

/// A reset value as the data sheet writes it: per bit 0, 1 or "x".
///
/// `x` means undefined after a hardware reset and unchanged when reset mode
/// is entered (by software or by bus-off).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ResetValue {
    /// Bits whose value the reset defines.
    pub defined: u8,
    /// Their value (bits outside `defined` are 0 here).
    pub value: u8,
}

impl ResetValue {
    /// Parses the data sheet notation, bit 7 first: `"0x1xxxx1"`; `_` is
    /// ignored. A malformed string fails at compile time in a `const`.
    pub const fn parse(s: &str) -> ResetValue {
        let b = s.as_bytes();
        let mut i = 0;
        let mut n = 0;
        let mut defined = 0u8;
        let mut value = 0u8;
        while i < b.len() {
            let c = b[i];
            i += 1;
            if c == b'_' {
                continue;
            }
            assert!(n < 8, "reset value has more than 8 bits");
            let bit = 7 - n;
            n += 1;
            match c {
                b'0' => defined |= 1 << bit,
                b'1' => {
                    defined |= 1 << bit;
                    value |= 1 << bit
                }
                b'x' => {}
                _ => panic!("reset value digits are 0, 1 or x"),
            }
        }
        assert!(n == 8, "reset value needs exactly 8 bits");
        ResetValue { defined, value }
    }

    /// The register after this reset, given its value before (kept bits).
    pub const fn apply(&self, old: u8) -> u8 {
        (old & !self.defined) | self.value
    }

    /// The data sheet notation back, bit 7 first (`"0x1xxxx1"`).
    pub fn notation(&self) -> String {
        (0..8)
            .rev()
            .map(|b| {
                if self.defined & (1 << b) == 0 {
                    'x'
                } else if self.value & (1 << b) != 0 {
                    '1'
                } else {
                    '0'
                }
            })
            .collect()
    }
}

/// One register (or a multi-byte window such as the RX FIFO) of one view.
#[derive(Debug, PartialEq, Eq)]
pub struct Register {
    /// Data sheet symbol, e.g. `SR`, `ACR0`, `RXFIFO`.
    pub name: &'static str,
    /// Long name, e.g. "status register".
    pub title: &'static str,
    /// The view it belongs to.
    pub mode: Mode,
    /// First address.
    pub addr: u8,
    /// Number of consecutive addresses (1 for a plain register).
    pub len: u8,
    /// Value after a hardware reset (`x` = undefined).
    pub reset_hw: ResetValue,
    /// Value after entering reset mode by software or bus-off (`x` = unchanged).
    pub reset_rm: ResetValue,
    /// Bit fields (empty for data bytes).
    pub fields: &'static [FieldDef],
    /// Notes on access rules and on where the thesis table differs.
    pub note: &'static str,
}

impl Register {
    /// The field called `name`, if any.
    pub fn field(&self, name: &str) -> Option<&'static FieldDef> {
        self.fields.iter().find(|f| f.name.eq_ignore_ascii_case(name))
    }

    /// True if `addr` falls inside this register.
    pub const fn contains(&self, addr: u8) -> bool {
        addr >= self.addr && (addr as u16) < self.addr as u16 + self.len as u16
    }

    /// True if the host can only write it in reset mode (configuration registers).
    pub fn reset_mode_only_write(&self) -> bool {
        let w = |op| lookup(self.mode, op, Access::Write, self.addr);
        let writes_reg = |v: Option<&RegisterView>| {
            v.and_then(RegisterView::register).is_some_and(|r| std::ptr::eq(r, self))
        };
        writes_reg(w(OpMode::Reset)) && !writes_reg(w(OpMode::Operating))
    }
}

/// What an access reaches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// The register (byte `addr - reg.addr` of it).
    Register(&'static Register),
    /// A read returns this constant (e.g. BasicCAN CMR reads `0xFF`).
    Constant(u8),
    /// A write has no effect.
    Nothing,
}

/// The meaning of one (mode, op mode, access, address) combination.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RegisterView {
    /// What the access reaches.
    pub target: Target,
    /// For a write to a register: the bits the write can change (others keep
    /// their value). `0xFF` for reads.
    pub write_mask: u8,
    /// Side effect or rule worth knowing (read-to-clear, ...), may be empty.
    pub note: &'static str,
}

impl RegisterView {
    /// The register reached, if the access reaches one.
    pub const fn register(&self) -> Option<&'static Register> {
        match self.target {
            Target::Register(r) => Some(r),
            _ => None,
        }
    }

    /// Byte index inside the reached register for an access at `addr`
    /// (0 for a plain register), or `None` if the access reaches no register.
    pub const fn index(&self, addr: u8) -> Option<u8> {
        match self.target {
            Target::Register(r) if r.contains(addr) => Some(addr - r.addr),
            _ => None,
        }
    }

    /// The constant a read returns, if it returns one.
    pub const fn constant(&self) -> Option<u8> {
        match self.target {
            Target::Constant(c) => Some(c),
            _ => None,
        }
    }
}

/// Errors of the register map queries.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RegError {
    /// The address is not defined in this view.
    #[error("address {addr} (0x{addr:02X}) is outside the {mode} register map (0..{limit})", limit = mode.addr_limit())]
    OutOfRange {
        /// The address asked for.
        addr: u8,
        /// The view.
        mode: Mode,
    },
    /// No register of that name in this view.
    #[error("no register named {name:?} in the {mode} register map")]
    UnknownRegister {
        /// The name asked for.
        name: String,
        /// The view.
        mode: Mode,
    },
    /// No field of that name in this register.
    #[error("register {register} has no field named {field:?} in the {mode} register map")]
    UnknownField {
        /// The register.
        register: &'static str,
        /// The field asked for.
        field: String,
        /// The view.
        mode: Mode,
    },
}

/// One row of an address allocation table (data sheet Tables 1 and 5).
#[derive(Debug)]
pub struct AddrRow {
    /// First address of the row.
    pub first: u8,
    /// Last address of the row (inclusive).
    pub last: u8,
    /// Operating mode, read.
    pub op_read: RegisterView,
    /// Operating mode, write.
    pub op_write: RegisterView,
    /// Reset mode, read.
    pub rst_read: RegisterView,
    /// Reset mode, write.
    pub rst_write: RegisterView,
}

impl AddrRow {
    /// The view for one op mode and direction.
    pub const fn view(&self, opmode: OpMode, access: Access) -> &RegisterView {
        match (opmode, access) {
            (OpMode::Operating, Access::Read) => &self.op_read,
            (OpMode::Operating, Access::Write) => &self.op_write,
            (OpMode::Reset, Access::Read) => &self.rst_read,
            (OpMode::Reset, Access::Write) => &self.rst_write,
        }
    }
}

/// Every register of a view, in address order (windows included).
pub fn registers(mode: Mode) -> &'static [&'static Register] {
    match mode {
        Mode::BasicCan => basic::REGISTERS,
        Mode::PeliCan => peli::REGISTERS,
    }
}

/// The address allocation table of a view: rows cover every address
/// `0..mode.addr_limit()` exactly once, in order.
pub fn address_table(mode: Mode) -> &'static [AddrRow] {
    match mode {
        Mode::BasicCan => map::BASIC_TABLE,
        Mode::PeliCan => map::PELI_TABLE,
    }
}

/// What an access means, or `None` if `addr` is outside the view
/// (see [`decode`] for the same answer as a `Result`).
pub fn lookup(mode: Mode, opmode: OpMode, access: Access, addr: u8) -> Option<&'static RegisterView> {
    address_table(mode)
        .iter()
        .find(|r| r.first <= addr && addr <= r.last)
        .map(|r| r.view(opmode, access))
}

/// Like [`lookup`], with a clear error for an address outside the view.
pub fn decode(mode: Mode, opmode: OpMode, access: Access, addr: u8) -> Result<&'static RegisterView, RegError> {
    lookup(mode, opmode, access, addr).ok_or(RegError::OutOfRange { addr, mode })
}

/// The register called `name` (data sheet symbol, case-insensitive) in a view.
pub fn register(mode: Mode, name: &str) -> Result<&'static Register, RegError> {
    registers(mode)
        .iter()
        .copied()
        .find(|r| r.name.eq_ignore_ascii_case(name))
        .ok_or_else(|| RegError::UnknownRegister { name: name.to_string(), mode })
}

/// The field `field` of register `reg` in a view.
pub fn field(mode: Mode, reg: &str, field: &str) -> Result<&'static FieldDef, RegError> {
    let r = register(mode, reg)?;
    r.field(field).ok_or_else(|| RegError::UnknownField {
        register: r.name,
        field: field.to_string(),
        mode,
    })
}

#[cfg(test)]
mod tests;
