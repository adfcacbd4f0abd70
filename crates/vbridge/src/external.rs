//! What an external core is: its sources, options and the way its VHDL
//! goes through GHDL. Built by the model module (Verilator) after
//! [`crate::vhdl`] (GHDL) has lowered its VHDL.

use std::path::PathBuf;

/// A Verilog top built at run time with Verilator's own makefile into a
/// shared library cached by a hash of its sources and options
/// ([`ExternalCore::build_in`]).
#[derive(Clone, Debug, Default)]
pub struct ExternalCore {
    /// Directory holding the sources.
    pub dir: PathBuf,
    /// Top module name.
    pub top: String,
    /// Source files; empty means every `*.v` / `*.sv` in `dir`.
    pub files: Vec<PathBuf>,
    /// `NAME` or `NAME=VALUE` macros.
    pub defines: Vec<String>,
    /// Extra include directories (`dir` is always one).
    pub include_dirs: Vec<PathBuf>,
    /// Build with Verilator's line, toggle and branch coverage (`--coverage`;
    /// a cache entry of its own): instances made with
    /// [`CompiledCore::instantiate_with_coverage`] write a `.dat` when dropped.
    pub coverage: bool,
    /// Extra Verilator arguments. `*.v` files are read as Verilog-2005
    /// (`+1364-2005ext+v`, so identifiers such as `do` that SystemVerilog
    /// reserves still parse); `*.sv` as SystemVerilog. `--coverage` and
    /// the like go here (the runtime classes they need are linked).
    pub extra_args: Vec<String>,
    /// C++ body of the inner loop ([`Model::run_inner_loop`]), if any.
    pub inner_loop: Option<String>,
    /// How VHDL sources (`*.vhd`, `*.vhdl`) go through GHDL ([`crate::vhdl`]).
    pub vhdl: VhdlOptions,
    /// Inputs held at a constant for the whole run, set on every instance
    /// before its first eval (the run-time mutant select of `cancosim
    /// mutate`). Not part of the cache key: one build serves every value.
    pub held_inputs: Vec<(String, u64)>,
}

/// The VHDL language revision GHDL analyses with (`--std=`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VhdlStandard {
    /// VHDL-93 (`--std=93`), strict.
    V93,
    /// VHDL-93 with GHDL's relaxations (`--std=93c`, GHDL's own default),
    /// which much VHDL-93 code in the field needs.
    #[default]
    V93c,
    /// VHDL-2008 (`--std=08`).
    V08,
}

impl VhdlStandard {
    /// From a profile's `standard` value: `93`, `93c`, `08` (or `2008`).
    pub fn from_name(s: &str) -> Option<VhdlStandard> {
        match s {
            "93" | "1993" => Some(VhdlStandard::V93),
            "93c" => Some(VhdlStandard::V93c),
            "08" | "2008" => Some(VhdlStandard::V08),
            _ => None,
        }
    }

    /// GHDL's option.
    pub fn ghdl_flag(self) -> &'static str {
        match self {
            VhdlStandard::V93 => "--std=93",
            VhdlStandard::V93c => "--std=93c",
            VhdlStandard::V08 => "--std=08",
        }
    }

    /// In words, for messages.
    pub fn describe(self) -> &'static str {
        match self {
            VhdlStandard::V93 => "VHDL-93",
            VhdlStandard::V93c => "VHDL-93 (GHDL's relaxed 93c)",
            VhdlStandard::V08 => "VHDL-2008",
        }
    }
}

/// How a core's VHDL is analysed (a profile's `[vhdl]` table).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct VhdlOptions {
    /// Language revision.
    pub standard: VhdlStandard,
    /// VHDL files in analysis order, relative to the core's directory;
    /// empty: every `.vhd`/`.vhdl` there, ordered by `ghdl --elab-order`.
    pub files: Vec<PathBuf>,
    /// Extra GHDL options for analysis and synthesis (e.g. `-fsynopsys`
    /// for `ieee.std_logic_arith`).
    pub ghdl_args: Vec<String>,
}

impl VhdlOptions {
    /// The options in one line, for report headers.
    pub fn describe(&self) -> String {
        let mut s = self.standard.describe().to_string();
        if !self.files.is_empty() {
            s.push_str(&format!(", {} file(s) in the profile's order", self.files.len()));
        }
        if !self.ghdl_args.is_empty() {
            s.push_str(&format!(", GHDL options {}", self.ghdl_args.join(" ")));
        }
        s
    }
}
