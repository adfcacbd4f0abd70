//! Generators: files derived from the one register map.
//!
//! Every generator is a pure function returning the file text; the output
//! depends only on the map and the options (no dates, no paths), so
//! regenerating gives byte-identical files. [`write_all`] is the only I/O.

mod c;
mod devicetree;
mod docs;
mod i8051;
mod tcl;
mod verilog;

pub use c::{nios_header, pio_header};
pub use devicetree::{dt_node, DtOptions};
pub use docs::markdown;
pub use i8051::i8051_header;
pub use tcl::{hw_tcl, TclOptions, RTL_FILES};
pub use verilog::verilog_include;


use crate::{lookup, Access, OpMode, Register};
use std::io;
use std::path::{Path, PathBuf};

/// How the host sees consecutive SJA1000 registers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Spacing {
    /// One byte per register at `base + index`; accesses use
    /// `IORD_8DIRECT`/`IOWR_8DIRECT`. This matches `can_avalon`: an 8-bit
    /// Avalon slave with addressUnits WORDS (a word is one byte).
    #[default]
    Byte,
    /// One 16-bit half-word per register at `base + 2 * index`; accesses use
    /// `IORD_16DIRECT`/`IOWR_16DIRECT` (Linux's `reg-io-width = <2>`).
    Half,
    /// One 32-bit word per register at `base + 4 * index`; accesses use
    /// `IORD`/`IOWR` (for a wrapper with a 32-bit data bus).
    Word,
}

impl Spacing {
    /// Bytes from one register to the next: 1, 2 or 4.
    pub fn stride(self) -> u8 {
        match self {
            Spacing::Byte => 1,
            Spacing::Half => 2,
            Spacing::Word => 4,
        }
    }

    /// The spacing of a register stride in bytes (1, 2 or 4).
    pub fn from_stride(stride: u32) -> Result<Spacing, GenError> {
        match stride {
            1 => Ok(Spacing::Byte),
            2 => Ok(Spacing::Half),
            4 => Ok(Spacing::Word),
            _ => Err(GenError::BadStride(stride)),
        }
    }
}

impl std::str::FromStr for Spacing {
    type Err = GenError;

    /// `byte` or `word` (case-insensitive), for command lines.
    fn from_str(s: &str) -> Result<Self, GenError> {
        match s.to_ascii_lowercase().as_str() {
            "byte" | "8direct" => Ok(Spacing::Byte),
            "half" | "16direct" => Ok(Spacing::Half),
            "word" | "native" => Ok(Spacing::Word),
            _ => Err(GenError::BadSpacing(s.to_string())),
        }
    }
}

/// Errors in generator options.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GenError {
    /// The spacing is not `byte` or `word`.
    #[error("register spacing {0:?} is none of \"byte\" (IORD_8DIRECT), \"half\" (IORD_16DIRECT), \"word\" (IORD)")]
    BadSpacing(String),
    /// The stride is not 1, 2 or 4 bytes.
    #[error("register stride {0} is not 1, 2 or 4 bytes")]
    BadStride(u32),
    /// The byte lane is not inside the stride.
    #[error("byte lane {lane} is outside a register of {stride} byte(s): lanes 0..{max}", max = stride - 1)]
    BadLane {
        /// The lane asked for.
        lane: u32,
        /// The stride it must fit.
        stride: u8,
    },
    /// The Linux sja1000 driver cannot reach a register in that lane.
    #[error("byte lane {lane} at a {stride}-byte stride: Linux's sja1000 driver reads register n with a {stride}-byte access at base + n * {stride} and keeps bits 7..0 (lane 0); a core with its data in another lane needs a wrapper that moves it")]
    LaneNotForLinux {
        /// The lane.
        lane: u8,
        /// The stride.
        stride: u8,
    },
    /// The prefix would not make C identifiers.
    #[error("prefix {0:?} is not an upper-case C identifier (A-Z, 0-9, _; not starting with a digit)")]
    BadPrefix(String),
}

/// Options of the C header generators.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HeaderOptions {
    /// Upper-case identifier prefix, e.g. `CAN_SJA`; the file is `can_sja_regs.h`.
    pub prefix: String,
    /// Register spacing on the host bus (the stride).
    pub spacing: Spacing,
    /// Byte lane of the data inside a register's `stride` bytes (0 = bits
    /// 7..0 of a little-endian access, the byte at the lowest address).
    pub lane: u8,
}

impl Default for HeaderOptions {
    fn default() -> Self {
        HeaderOptions { prefix: "CAN_SJA".to_string(), spacing: Spacing::Byte, lane: 0 }
    }
}

impl HeaderOptions {
    /// Options with a checked prefix (upper-case C identifier, e.g. `CAN0`).
    pub fn new(prefix: &str, spacing: Spacing) -> Result<Self, GenError> {
        let ok = !prefix.is_empty()
            && !prefix.starts_with(|c: char| c.is_ascii_digit())
            && prefix.chars().all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_');
        if !ok {
            return Err(GenError::BadPrefix(prefix.to_string()));
        }
        Ok(HeaderOptions { prefix: prefix.to_string(), spacing, lane: 0 })
    }

    /// The same with the data in byte `lane` of each register's stride.
    pub fn with_lane(mut self, lane: u32) -> Result<Self, GenError> {
        let stride = self.spacing.stride();
        if lane >= stride as u32 {
            return Err(GenError::BadLane { lane, stride });
        }
        self.lane = lane as u8;
        Ok(self)
    }

    /// Byte offset of register `index`'s data from the base.
    pub fn offset(&self, index: u32) -> u32 {
        index * self.spacing.stride() as u32 + self.lane as u32
    }

    /// File name of the register header: `<prefix>_regs.h` in lower case.
    pub fn regs_file(&self) -> String {
        format!("{}_regs.h", self.prefix.to_lowercase())
    }

    /// File name of the PIO access header: `<prefix>_pio.h` in lower case.
    pub fn pio_file(&self) -> String {
        format!("{}_pio.h", self.prefix.to_lowercase())
    }

    /// File name of the 8051 (SDCC) header: `<prefix>_8051.h` in lower case.
    pub fn i8051_file(&self) -> String {
        format!("{}_8051.h", self.prefix.to_lowercase())
    }
}

/// Options of [`write_all`].
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct GenOptions {
    /// C header options.
    pub header: HeaderOptions,
    /// Platform Designer component options.
    pub tcl: TclOptions,
}

/// File name of the Markdown register reference.
pub const MARKDOWN_FILE: &str = "sja1000_registers.md";
/// File name of the Verilog include.
pub const VERILOG_FILE: &str = "sja1000_regs.vh";

/// Every generated file as (file name, contents), in a fixed order.
pub fn all_files(opts: &GenOptions) -> Vec<(String, String)> {
    vec![
        (opts.header.regs_file(), nios_header(&opts.header)),
        (opts.header.pio_file(), pio_header(&opts.header)),
        (opts.header.i8051_file(), i8051_header(&opts.header)),
        (format!("{}_hw.tcl", opts.tcl.name), hw_tcl(&opts.tcl)),
        (MARKDOWN_FILE.to_string(), markdown()),
        (VERILOG_FILE.to_string(), verilog_include()),
    ]
}

/// Writes every generated file into `dir` (created if missing) and returns
/// their paths.
pub fn write_all(dir: &Path, opts: &GenOptions) -> io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut out = Vec::new();
    for (name, text) in all_files(opts) {
        let p = dir.join(name);
        std::fs::write(&p, text)?;
        out.push(p);
    }
    Ok(out)
}

/// The "generated, do not edit" stamp (no date: output must be reproducible).
pub(crate) fn stamp() -> String {
    format!(
        "Generated by regmap {} from the one SJA1000 register map (crates/regmap). Do not edit: regenerate.",
        env!("CARGO_PKG_VERSION")
    )
}

/// Who can reach a register, summarised over all its bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Reach {
    pub op_read: bool,
    pub op_write: bool,
    pub rst_read: bool,
    pub rst_write: bool,
}

impl Reach {
    pub fn of(reg: &'static Register) -> Reach {
        let hits = |op, acc| {
            (reg.addr..reg.addr + reg.len).any(|a| {
                lookup(reg.mode, op, acc, a)
                    .and_then(|v| v.register())
                    .is_some_and(|r| std::ptr::eq(r, reg))
            })
        };
        Reach {
            op_read: hits(OpMode::Operating, Access::Read),
            op_write: hits(OpMode::Operating, Access::Write),
            rst_read: hits(OpMode::Reset, Access::Read),
            rst_write: hits(OpMode::Reset, Access::Write),
        }
    }

    pub fn readable(&self) -> bool {
        self.op_read || self.rst_read
    }

    pub fn writable(&self) -> bool {
        self.op_write || self.rst_write
    }

    /// Only reachable in reset mode.
    pub fn reset_mode_only(&self) -> bool {
        !self.op_read && !self.op_write
    }

    /// One line: "read: operating, reset; write: reset mode only".
    pub fn summary(&self) -> String {
        fn part(op: bool, rst: bool) -> &'static str {
            match (op, rst) {
                (true, true) => "both modes",
                (true, false) => "operating mode only",
                (false, true) => "reset mode only",
                (false, false) => "never",
            }
        }
        format!("read: {}; write: {}", part(self.op_read, self.rst_read), part(self.op_write, self.rst_write))
    }
}

#[cfg(test)]
mod tests;
