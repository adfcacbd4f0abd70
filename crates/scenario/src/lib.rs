//! Scenario files of `tb/` (TOML), validated with file:line:key errors, the
//! runner that plays a scenario on a `cosim` test bench and diagnoses the
//! run, and the regression runner (scenarios x DUTs, parallel, JUnit, table,
//! shards).
//!
//! A scenario file reads like a CTU CAN FD feature test: a `purpose`, a
//! numbered `verifies` list and a `sequence`, then the set-up, the host
//! program, fault injections and the expected outcome. Every table rejects
//! unknown keys. See `tb/de2-thesis.toml` for a commented example.
//!
//! ```toml
//! name = "optional, defaults to the file stem"
//! purpose = "one line"
//! verifies = ["...", "..."]
//! sequence = ["...", "..."]
//!
//! [clocks]            # required
//! host_mhz = 50.0     # wb_clk_i
//! can_mhz = 24.0      # clk_i
//! bit_rate = 125000   # optional: some BTR setting must reach it; the BTR
//!                     # values the program writes are checked against it
//! [host]
//! bfm = "wishbone"    # | "avalon" | "pio" | "i8051" | "axi4-lite" | "apb" | "apb3"
//! avalon_map = "wrapper"   # | "begintransfer-cyc" (seed 000 Tableau 3.2)
//! timeout_cycles = 1000    # host cycles before an access without ack fails
//! fixed = "why"       # the host wiring is this scenario's point: a run
//!                     # with a host override (--host) skips it, saying why
//! [dut]
//! kind = "rtl"        # | "avalon-wrapper" | "model" | "external"
//! path = "..."; top = "can_top"; defines = []; includes = []   # external
//! [wiring]
//! rx = "bus"          # | "tied-recessive" | "tied-dominant"
//! tx_to_bus = true
//! [run]
//! max_bits = 20000    # run length limit (bit times)
//! keep_bits = 256     # bus bits kept in the record
//! waivers = ["waivers/x.toml"]   # waiver files, relative to this file
//!
//! [[step]]            # exactly one action per step; `note` is echoed
//! write = "BTR0"      # name (resolved in the view in force: CDR.7), "TXB+1", or address
//! value = 0x41
//! view = "peli"       # optional: use that view's address (reproduces confusion)
//! [[step]]
//! read = "SR"         # optional check: (read & mask) == expect
//! expect = 0x0C
//! mask = 0x0C
//! [[step]]
//! wait_irq = true     # or wait_sr_set / wait_sr_clear, or wait_bits = N
//! timeout_bits = 2000
//! [[step]]
//! wait_irq = true     # with optional = true: a timeout ends the wait, no failure
//! timeout_bits = 300
//! optional = true
//! [[step]]
//! load_tx = { id = 0x529, data = [0x51] }   # fills the TX buffer (extended, rtr, dlc, raw_dlc)
//! [[step]]
//! transmit = { id = 0x529, data = [0x51] }  # waits for SR.TBS (timeout_bits), then load_tx and
//! command = 0x01      # CMR = command; does nothing while bus-off, in reset mode or locked
//! [[step]]
//! drain = 64          # while SR.RBS: read the message, release it (at most 64)
//! [[step]]
//! release = 3         # while SR.RBS: release without reading (at most 3)
//! [[step]]            # accesses as one Wishbone block cycle (B4 §3.3): cyc and stb held
//! block = [ { load_tx = { id = 0x12, data = [1] } }, { read = "TXB", expect = 0x02 } ]
//!                     # from the first transfer to the last ack (write, read, load_tx entries;
//!                     # on Avalon, PIO or 8051 hosts: single accesses)
//! # The steps may instead be one array of inline tables at the top of the
//! # file, before any [table], one step per line (tb/pelican-*.toml):
//! # step = [ { write = "CR", value = 0x01 }, { wait_irq = true }, ... ]
//!
//! [[node]]            # golden-model node on the bus
//! name = "acker"; btr0 = 0x41; btr1 = 0x25; mode = "basic"; acr = [0xFF]; amr = [0xFF]
//! listen_only = false; can_mhz = 24.0   # its own oscillator (clock tolerance), below twice clocks.can_mhz
//! send = [{ id = 0x0F, data = [0x0F], at_bit = 100 }]
//! # and/or a candump log (`candump -l`) as its traffic, gaps kept: in bit
//! # times at the capture's bit_rate, else in seconds at the node's rate
//! replay = { file = "captures/x.log", bit_rate = 500000, start_bit = 100, iface = "can0" }
//!
//! [[fault]]
//! kind = "flip"       # | "stuck-dominant" | "stuck-recessive" | "glitch"
//! frame = 1; bit_in_frame = 20   # or at_bit = N; duration_bits; target = "bus" | "dut-rx" | node
//! offset_tq = 4; width_tq = 1     # glitch only: the pulse in the DUT's time quanta from the
//!                     # bit's start (0 = SYNC_SEG); default: 1/8 bit from 1/4 bit. One
//!                     # quantum wide it hits exactly one quantum end (e.g. one SAM sample)
//!                     # "bus": every model node and the DUT; "dut-rx": what the DUT (and
//!                     # its shadow model) receive only; frames count SOFs on the bus from 1,
//!                     # bits are wire bits from SOF = 0, stuff bits included
//! offset_clocks = 0; width_clocks = 24   # glitch only: the pulse in CAN clocks
//!                     # from the start of the bit (default: 1/8 bit, 1/4 into it);
//!                     # it may cross the bench's sample point and must end in the bit;
//!                     # target = "dut-rx" only (the grid is the DUT timing's)
//! level = "dominant"  # placed glitch only: the pulse forces this level instead of
//!                     # inverting the wire's (a pulse that must stay dominant while
//!                     # the DUT starts driving dominant itself, e.g. an early ACK edge)
//! grid = "sof"        # placed glitch only: bit and offset on the nominal grid from the
//!                     # frame's SOF edge (the lower tester's), which no resynchronisation
//!                     # moves; default "bench" (restarts at every edge of the wire)
//!
//! [[raw-node]]        # a bit-level sender on the wire (crate::rawnode)
//! name = "lt"; frame = 1; bit_in_frame = 57   # or at_bit = N, or idle_bits = 11
//! bits = "0 0000"     # levels per bit time (0 = dominant), or a frame by its fields:
//! fields = { id = 0x123, data = [1], r0 = 1 }  # srr, r1, crc, ack, flip; CRC and stuffing computed
//!
//! [expect]            # checked against the diagnosis
//! category = "RxNotFollowingTx"  # diagnose::Category name
//! field = "Sof"; first_attempt_tec = 136; bus_off_attempt = 16; tec = 128; sr = 0x60; attempts = 17
//! received = { acker = 1 }       # frames each node received
//! ```
//!
//! Entry points: [`Scenario::load`], [`run`](run::run), [`regress`](regress::regress),
//! [`load_list`] for regression lists (`tb/regression.list`).
#![warn(missing_docs)]

mod format;
mod pulse;
pub mod html;
pub mod rawnode;
pub mod regress;
pub mod replay;
pub mod revdiff;
pub mod run;
pub mod xfail;

pub use regress::{RegressOptions, RegressReport, regress};
pub use run::{DutSpec, RunOptions, RunOutcome, run};

use can_proto::timing::BusTiming;
use diagnose::Category;
use format::*;
pub use format::file_schema;
use regmap::{Access, Mode, OpMode};
use std::path::{Path, PathBuf};

/// A scenario file that could not be read or is not valid.
#[derive(Debug, thiserror::Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// File name.
        file: String,
        /// Cause.
        source: std::io::Error,
    },
    /// A syntax, type or meaning error at a place in the file.
    #[error("{file}:{line}:{col}: key `{key}`: {message}")]
    At {
        /// File name.
        file: String,
        /// Line, from 1.
        line: usize,
        /// Column, from 1.
        col: usize,
        /// The key at fault (dotted path when known).
        key: String,
        /// What is wrong.
        message: String,
    },
}

impl ScenarioError {
    /// Line of the error (0 for I/O errors).
    pub fn line(&self) -> usize {
        match self {
            ScenarioError::At { line, .. } => *line,
            ScenarioError::Io { .. } => 0,
        }
    }

    /// Key at fault ("" for I/O errors).
    pub fn key(&self) -> &str {
        match self {
            ScenarioError::At { key, .. } => key,
            ScenarioError::Io { .. } => "",
        }
    }
}

/// Which host bus-functional model drives the DUT.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HostBfm {
    /// Wishbone classic.
    Wishbone,
    /// Avalon-MM through a wrapper.
    Avalon {
        /// The seed 000 mapping: wb_cyc_i from begintransfer, ack on a conduit.
        begintransfer_cyc: bool,
    },
    /// Nios-style PIO bit-banging (seed 000 annexe 4).
    Pio,
    /// The same program and wiring with the ack PIO's edge capture
    /// register polled instead of its data register
    /// (`bfm::PioAckInput::EdgeCapture`): for a core whose ack is a
    /// one-clock pulse (`--host pio-edge`, command line only).
    PioEdgeCapture,
    /// Intel-mode (8051) multiplexed bus (ALE, CS, RD, WR, shared port):
    /// our RTL through `can_top_8051`.
    I8051,
    /// AXI4-Lite (five channels): our RTL through `can_axi4lite`.
    Axi4Lite,
    /// APB4 (setup and access phases, PSTRB/PPROT): our RTL through `can_apb`.
    Apb,
    /// APB3 (no PSTRB/PPROT): our RTL through `can_apb`.
    Apb3,
    /// Motorola-mode multiplexed bus (AS, CS, E, R/W, shared port): our
    /// RTL through `can_top_mcu` with MODE low, the golden model through
    /// `bfm::MotorolaBridge`.
    Motorola,
    /// A plain register port (strobes, no acknowledge) on the CAN clock:
    /// our RTL through `can_regport`, the golden model through
    /// `bfm::RegportBridge`.
    Regport,
}

impl HostBfm {
    /// The host given by name on a command line: `wishbone`, `avalon` (our
    /// Avalon-MM wrapper with the Avalon BFM) or `pio`.
    pub fn from_name(name: &str) -> Option<HostBfm> {
        match name.to_ascii_lowercase().as_str() {
            "wishbone" | "wb" => Some(HostBfm::Wishbone),
            "avalon" => Some(HostBfm::Avalon { begintransfer_cyc: false }),
            "pio" => Some(HostBfm::Pio),
            "pio-edge" => Some(HostBfm::PioEdgeCapture),
            "i8051" | "8051" => Some(HostBfm::I8051),
            "axi4-lite" | "axi4lite" | "axi" => Some(HostBfm::Axi4Lite),
            "apb" | "apb4" => Some(HostBfm::Apb),
            "apb3" => Some(HostBfm::Apb3),
            "motorola" | "68xx" => Some(HostBfm::Motorola),
            "regport" => Some(HostBfm::Regport),
            _ => None,
        }
    }

    /// Short name, as `from_name` takes it (`avalon-begintransfer` for the seed 000 map).
    pub fn name(&self) -> &'static str {
        match self {
            HostBfm::Wishbone => "wishbone",
            HostBfm::Avalon { begintransfer_cyc: false } => "avalon",
            HostBfm::Avalon { begintransfer_cyc: true } => "avalon-begintransfer",
            HostBfm::Pio => "pio",
            HostBfm::PioEdgeCapture => "pio-edge",
            HostBfm::I8051 => "i8051",
            HostBfm::Axi4Lite => "axi4-lite",
            HostBfm::Apb => "apb",
            HostBfm::Apb3 => "apb3",
            HostBfm::Motorola => "motorola",
            HostBfm::Regport => "regport",
        }
    }
}

impl std::fmt::Display for HostBfm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Which DUT the scenario asks for (the regression may override it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DutKind {
    /// The project's own RTL (`rtl/can_top`).
    Rtl,
    /// The project's own RTL behind its Avalon-MM wrapper.
    AvalonWrapper,
    /// The golden model itself.
    Model,
    /// An external core with the opencores `can_top` ports.
    External {
        /// Directory or file.
        path: PathBuf,
        /// Top module.
        top: String,
        /// `NAME` or `NAME=VALUE` defines.
        defines: Vec<String>,
        /// Include directories.
        includes: Vec<PathBuf>,
    },
}

/// What the DUT's rx_i is wired to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RxWire {
    /// The bus.
    Bus,
    /// Constant recessive.
    TiedRecessive,
    /// Constant dominant.
    TiedDominant,
}

/// A validated frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameSpec {
    /// The frame.
    pub frame: can_proto::CanFrame,
    /// Bit time at which a node requests its transmission.
    pub at_bit: u64,
}

/// One host step, resolved to addresses.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Register write.
    Write {
        /// Address.
        addr: u8,
        /// Value.
        value: u8,
        /// Name the scenario used (if any).
        name: Option<String>,
    },
    /// Register read, optionally checked: `(read & mask) == expect`.
    Read {
        /// Address.
        addr: u8,
        /// Name the scenario used.
        name: Option<String>,
        /// `(mask, value)` to check.
        expect: Option<(u8, u8)>,
    },
    /// Wait until irq_on is asserted.
    WaitIrq {
        /// Give up after this many bit times.
        timeout_bits: u64,
    },
    /// Poll SR until the `set` bits are 1 and the `clear` bits are 0.
    WaitSr {
        /// Bits that must be 1.
        set: u8,
        /// Bits that must be 0.
        clear: u8,
        /// Give up after this many bit times.
        timeout_bits: u64,
    },
    /// Let the bus run.
    WaitBits(u64),
    /// Wait until irq_on is asserted or `timeout_bits` pass, whichever
    /// comes first; neither is a failure (`wait_irq` with `optional`).
    WaitIrqOrTimeout {
        /// Bit times to wait at most.
        timeout_bits: u64,
    },
    /// While SR.RBS reads 1 and fewer than `max` were taken: read the
    /// received message (when `read`) and release it (CMR.RRB). The
    /// messages read are the run's delivered frames.
    Drain {
        /// Messages at most.
        max: u8,
        /// Read the message before releasing it (`drain`), or release only (`release`).
        read: bool,
    },
    /// Poll SR until TBS = 1 (at most `timeout_bits`); then, if the node is
    /// on the bus and in operating mode, fill the TX buffer and write
    /// `command` to CMR. Otherwise the step does nothing.
    Transmit {
        /// The frame.
        frame: can_proto::CanFrame,
        /// CMR value.
        command: u8,
        /// Bit times to wait for a free buffer.
        timeout_bits: u64,
    },
}

/// A numbered step with its place in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// Step number from 1 (echoed as "Step N" in logs).
    pub n: usize,
    /// Line in the file (of its `[[step]]` header).
    pub line: usize,
    /// Index of its `[[step]]` table in the file, from 1 (one `load_tx`
    /// table expands to several steps).
    pub table: usize,
    /// The scenario's note.
    pub note: Option<String>,
    /// Register view in force when the step runs (for names in reports).
    pub mode: Mode,
    /// Reset mode in force when the step runs.
    pub reset_mode: bool,
    /// The action.
    pub action: Action,
    /// Part of the Wishbone block cycle of this `[[step]]` table (its
    /// `block` key): consecutive steps with the same number are one cycle.
    pub block: Option<usize>,
}

/// A golden-model node on the bus.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeSpec {
    /// Name.
    pub name: String,
    /// CAN clock in Hz.
    pub can_hz: f64,
    /// BTR0.
    pub btr0: u8,
    /// BTR1.
    pub btr1: u8,
    /// Register view.
    pub mode: Mode,
    /// Acceptance code (BasicCAN uses byte 0).
    pub acr: [u8; 4],
    /// Acceptance mask (1 = don't care).
    pub amr: [u8; 4],
    /// Listen-only: never acknowledges.
    pub listen_only: bool,
    /// Frames it sends.
    pub traffic: Vec<FrameSpec>,
}

/// Kind of injected fault.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultKind {
    /// Level forced dominant.
    StuckDominant,
    /// Level forced recessive.
    StuckRecessive,
    /// One bit inverted.
    Flip,
    /// A short pulse inside a bit.
    Glitch,
}

/// A fault injection.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultSpec {
    /// Kind.
    pub kind: FaultKind,
    /// Absolute bit time, or...
    pub at_bit: Option<u64>,
    /// ...frame number (from 1) and bit within it (from 0, SOF = 0).
    pub frame_bit: Option<(u32, u32)>,
    /// Bits it lasts.
    pub duration_bits: u64,
    /// "bus", "dut-rx" or a node name.
    pub target: String,
    /// Glitch only: `(offset, width)` of the pulse in CAN clocks from the
    /// start of the bit (`offset_clocks`/`width_clocks`, or `offset_tq`/
    /// `width_tq` times the DUT's quantum); `None`: 1/8 of a bit starting
    /// 1/4 into it.
    pub pulse_clocks: Option<(u32, u32)>,
    /// Placed glitch only: the level the pulse forces (`level`); `None`:
    /// the pulse inverts the wire's level.
    pub pulse_level: Option<bool>,
    /// Placed glitch only: counted on the nominal grid from the frame's SOF
    /// edge (`grid = "sof"`), not on the bench's grid.
    pub pulse_on_sof_grid: bool,
}

/// The expected outcome.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ExpectSpec {
    /// Diagnosis category.
    pub category: Option<Category>,
    /// Field named by the diagnosis.
    pub field: Option<can_proto::Field>,
    /// TEC after the first attempt.
    pub first_attempt_tec: Option<u16>,
    /// Final TEC (or plateau).
    pub tec: Option<u16>,
    /// Final SR.
    pub sr: Option<u8>,
    /// Attempts.
    pub attempts: Option<u32>,
    /// Attempt during which bus-off happened.
    pub bus_off_attempt: Option<u32>,
    /// Frames received per node.
    pub received: Vec<(String, u32)>,
}

/// A validated scenario.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// Name (file stem unless `name` is given).
    pub name: String,
    /// File it came from.
    pub file: PathBuf,
    /// What it is for.
    pub purpose: String,
    /// What it verifies, numbered.
    pub verifies: Vec<String>,
    /// Test sequence, numbered.
    pub sequence: Vec<String>,
    /// Host clock in Hz.
    pub host_hz: f64,
    /// CAN clock in Hz.
    pub can_hz: f64,
    /// Host BFM.
    pub host: HostBfm,
    /// Host cycles before a non-acked access times out.
    pub timeout_cycles: u32,
    /// Set when the host wiring is the scenario's point (`[host] fixed`):
    /// why a host override does not apply.
    pub host_fixed: Option<String>,
    /// DUT.
    pub dut: DutKind,
    /// rx_i wiring.
    pub rx: RxWire,
    /// tx_o drives the bus.
    pub tx_to_bus: bool,
    /// Steps.
    pub steps: Vec<Step>,
    /// Other nodes.
    pub nodes: Vec<NodeSpec>,
    /// Fault injections.
    pub faults: Vec<FaultSpec>,
    /// Bit-level senders on the wire (`[[raw-node]]`).
    pub raw_nodes: Vec<rawnode::RawNodeSpec>,
    /// Expected outcome.
    pub expect: ExpectSpec,
    /// Run length limit in bit times.
    pub max_bits: u64,
    /// Bus bits kept in the record.
    pub keep_bits: usize,
    /// Waiver files named in `[run] waivers`, resolved against the
    /// scenario file's directory.
    pub waivers: Vec<PathBuf>,
    /// Non-fatal remarks (bit timing off target, ...).
    pub warnings: Vec<String>,
}

/// Byte offset to (line, column), both from 1.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let col = offset - before.rfind('\n').map(|p| p + 1).unwrap_or(0) + 1;
    (line, col)
}

struct Ctx<'a> {
    file: String,
    text: &'a str,
}

impl Ctx<'_> {
    fn err(&self, span: std::ops::Range<usize>, key: &str, message: impl Into<String>) -> ScenarioError {
        let (line, col) = line_col(self.text, span.start);
        ScenarioError::At { file: self.file.clone(), line, col, key: key.into(), message: message.into() }
    }

    /// Finds `key =` inside `span` to point at the key's own line.
    fn key_span(&self, span: &std::ops::Range<usize>, key: &str) -> std::ops::Range<usize> {
        if key.is_empty() {
            return span.clone();
        }
        // An array-of-tables span may cover only its `[[header]]`: search on
        // to the next table header.
        let mut end = span.end.min(self.text.len());
        if let Some(i) = self.text[end..].find("\n[") {
            end += i;
        } else {
            end = self.text.len();
        }
        let end = end.max(span.end.min(self.text.len()));
        let region = &self.text[span.start.min(end)..end];
        let mut pos = 0;
        while let Some(i) = region[pos..].find(key) {
            let at = pos + i;
            let before_ok = at == 0 || !region.as_bytes()[at - 1].is_ascii_alphanumeric() && region.as_bytes()[at - 1] != b'_';
            let rest = region[at + key.len()..].trim_start();
            if before_ok && rest.starts_with('=') {
                return span.start + at..span.start + at + key.len();
            }
            pos = at + key.len();
        }
        span.clone()
    }

    fn err_key(&self, span: &std::ops::Range<usize>, key: &str, path: &str, message: impl Into<String>) -> ScenarioError {
        self.err(self.key_span(span, key), path, message)
    }
}

/// Where a `[[step]]` table is: its line and its index from 1.
struct Placed {
    line: usize,
    table: usize,
}

/// The accesses of a `block = [...]` step, each a step of its own marked
/// with the table's index as its block (the register view and reset mode
/// follow the writes inside the block, as between steps).
#[allow(clippy::too_many_arguments)]
fn block_steps(
    ctx: &Ctx,
    span: &std::ops::Range<usize>,
    p: &str,
    block: &[RawStep],
    at: Placed,
    mode: &mut Mode,
    reset_mode: &mut bool,
    steps: &mut Vec<Step>,
) -> Result<(), ScenarioError> {
    let first = steps.len();
    for (j, st) in block.iter().enumerate() {
        let q = format!("{p}.block[{}]", j + 1);
        let waits = [
            st.wait_irq.is_some(),
            st.wait_sr_set.is_some() || st.wait_sr_clear.is_some(),
            st.wait_bits.is_some(),
            st.block.is_some(),
            st.timeout_bits.is_some(),
            st.drain.is_some() || st.release.is_some() || st.transmit.is_some(),
        ];
        let accesses = [st.write.is_some(), st.read.is_some(), st.load_tx.is_some()];
        if waits.iter().any(|w| *w) || accesses.iter().filter(|a| **a).count() != 1 {
            return Err(ctx.err_key(span, "block", &q, "each entry of a block is one access: write, read or load_tx (no waits: a block cycle holds the bus)"));
        }
        let view = match &st.view {
            None => *mode,
            Some(v) => parse_mode(ctx, span, "view", &format!("{q}.view"), v)?,
        };
        let mut push = |action: Action, mode: Mode, reset_mode: bool| {
            steps.push(Step { n: steps.len() + 1, line: at.line, table: at.table, note: st.note.clone(), mode, reset_mode, action, block: Some(at.table) });
        };
        if let Some(w) = &st.write {
            let (addr, name) = resolve(ctx, span, "write", &format!("{q}.write"), w, view)?;
            let v = st.value.ok_or_else(|| ctx.err_key(span, "block", &format!("{q}.value"), "a write needs `value`"))?;
            let value = byte(ctx, span, "block", &format!("{q}.value"), v)?;
            push(Action::Write { addr, value, name }, *mode, *reset_mode);
            if addr == 31 {
                *mode = Mode::from_cdr(value);
            }
            if addr == 0 {
                *reset_mode = value & 1 != 0;
            }
        } else if let Some(r) = &st.read {
            let (addr, name) = resolve(ctx, span, "read", &format!("{q}.read"), r, view)?;
            let expect = match st.expect {
                None => None,
                Some(e) => {
                    let e = byte(ctx, span, "block", &format!("{q}.expect"), e)?;
                    let m = byte(ctx, span, "block", &format!("{q}.mask"), st.mask.unwrap_or(0xFF))?;
                    Some((m, e))
                }
            };
            push(Action::Read { addr, name, expect }, *mode, *reset_mode);
        } else if let Some(f) = &st.load_tx {
            let fr = frame(ctx, span, &format!("{q}.load_tx"), f)?;
            for (addr, value) in tx_buffer_bytes(&fr, view) {
                push(Action::Write { addr, value, name: None }, *mode, *reset_mode);
            }
        }
    }
    if steps.len() - first < 2 {
        return Err(ctx.err_key(span, "block", &format!("{p}.block"), "a block cycle needs at least two accesses"));
    }
    Ok(())
}

fn byte(ctx: &Ctx, span: &std::ops::Range<usize>, key: &str, path: &str, v: i64) -> Result<u8, ScenarioError> {
    u8::try_from(v).map_err(|_| ctx.err_key(span, key, path, format!("{v} does not fit in a byte (0..=255)")))
}

fn parse_mode(ctx: &Ctx, span: &std::ops::Range<usize>, key: &str, path: &str, s: &str) -> Result<Mode, ScenarioError> {
    match s.to_ascii_lowercase().as_str() {
        "basic" | "basiccan" => Ok(Mode::BasicCan),
        "peli" | "pelican" => Ok(Mode::PeliCan),
        _ => Err(ctx.err_key(span, key, path, format!("`{s}` is not a register view; use \"basic\" or \"peli\""))),
    }
}

/// The key a TOML error span belongs to: the `key =` before it on its line
/// (the last key of an inline table), else the span's own text (a table
/// header), else `?`. Never empty, so every message names a key.
fn key_before(text: &str, span: &std::ops::Range<usize>) -> String {
    let start = span.start.min(text.len());
    let line = text.get(..start).map_or("", |t| &t[t.rfind('\n').map_or(0, |i| i + 1)..]);
    if let Some(eq) = line.rfind('=') {
        let k = line[..eq].rsplit(['{', ',']).next().unwrap_or("").trim();
        if !k.is_empty() {
            return k.to_string();
        }
    }
    let own = text.get(start..span.end.min(text.len())).unwrap_or("");
    let own = own.split(['=', '\n']).next().unwrap_or("").trim().trim_matches(['[', ']']).trim();
    if own.is_empty() { "?".into() } else { own.to_string() }
}

impl Scenario {
    /// Reads and validates a scenario file.
    pub fn load(path: impl AsRef<Path>) -> Result<Scenario, ScenarioError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)
            .map_err(|source| ScenarioError::Io { file: path.display().to_string(), source })?;
        Scenario::parse(&text, path)
    }

    /// Validates scenario text; `file` names it in errors and gives the default name.
    pub fn parse(text: &str, file: impl AsRef<Path>) -> Result<Scenario, ScenarioError> {
        let file = file.as_ref();
        let ctx = Ctx { file: file.display().to_string(), text };
        let raw: RawScenario = toml::from_str(text).map_err(|e| {
            let span = e.span().unwrap_or(0..0);
            let msg = e.message().to_string();
            let key = msg
                .split('`')
                .nth(1)
                .filter(|_| msg.starts_with("unknown field") || msg.starts_with("missing field") || msg.starts_with("duplicate"))
                .map(str::to_string)
                .unwrap_or_else(|| key_before(text, &span));
            let msg = if msg.starts_with("unknown field") {
                format!("unknown key; {msg}")
            } else {
                msg
            };
            ctx.err(span, &key, msg)
        })?;
        build(&ctx, raw, file)
    }

    /// The scenario's DUT node timing (from the first BTR0/BTR1 writes).
    pub fn dut_timing(&self) -> (u8, u8) {
        btr_written(&self.steps)
    }

    /// The CTU-style header: purpose, verifies, sequence, numbered.
    pub fn header(&self) -> String {
        let mut s = format!("{}: {}\n", self.name, self.purpose);
        if !self.verifies.is_empty() {
            s += "Verifies:\n";
            for (i, v) in self.verifies.iter().enumerate() {
                s += &format!("  {}. {v}\n", i + 1);
            }
        }
        if !self.sequence.is_empty() {
            s += "Sequence:\n";
            for (i, v) in self.sequence.iter().enumerate() {
                s += &format!("  {}. {v}\n", i + 1);
            }
        }
        s
    }
}

/// Resolves a register reference in `mode`: name (optionally `+offset`) or address.
fn resolve(
    ctx: &Ctx,
    span: &std::ops::Range<usize>,
    key: &str,
    path: &str,
    r: &RegRef,
    mode: Mode,
) -> Result<(u8, Option<String>), ScenarioError> {
    match r {
        RegRef::Addr(a) => {
            let limit = mode.addr_limit() as i64;
            if *a < 0 || *a >= limit {
                return Err(ctx.err_key(
                    span,
                    key,
                    path,
                    format!("register address {a} is out of range: the {mode} map has addresses 0..{}", limit - 1),
                ));
            }
            Ok((*a as u8, None))
        }
        RegRef::Name(n) => {
            let (base, off) = match n.split_once('+') {
                Some((b, o)) => {
                    let off: u8 = o.trim().parse().map_err(|_| ctx.err_key(span, key, path, format!("`{n}`: offset `{o}` is not a number")))?;
                    (b.trim(), off)
                }
                None => (n.trim(), 0),
            };
            let reg = regmap::register(mode, base).map_err(|e| {
                let other = if mode == Mode::BasicCan { Mode::PeliCan } else { Mode::BasicCan };
                let hint = if regmap::register(other, base).is_ok() {
                    format!(" ({base} is a {other} register; the controller is in {mode} mode at this step (CDR.7); add view = \"{}\" to use its {other} address anyway)", if other == Mode::PeliCan { "peli" } else { "basic" })
                } else {
                    String::new()
                };
                ctx.err_key(span, key, path, format!("{e}{hint}"))
            })?;
            if off >= reg.len {
                return Err(ctx.err_key(span, key, path, format!("`{n}`: {} has {} byte(s), offset {off} is out of range", reg.name, reg.len)));
            }
            Ok((reg.addr + off, Some(n.clone())))
        }
    }
}

/// An identifier as written: hex, or decimal when negative (hex would
/// show its two's complement).
fn show_id(id: i64) -> String {
    if id < 0 { id.to_string() } else { format!("0x{id:X}") }
}

fn frame(ctx: &Ctx, span: &std::ops::Range<usize>, path: &str, f: &RawFrame) -> Result<can_proto::CanFrame, ScenarioError> {
    let id = if f.extended {
        if !(0..=0x1FFF_FFFF).contains(&f.id) {
            return Err(ctx.err_key(span, "id", &format!("{path}.id"), format!("identifier {} is out of range for an extended frame (0..=0x1FFFFFFF)", show_id(f.id))));
        }
        can_proto::CanFrame::ext_id(f.id as u32)
    } else {
        if !(0..=0x7FF).contains(&f.id) {
            return Err(ctx.err_key(span, "id", &format!("{path}.id"), format!("identifier {} is out of range for a standard frame (0..=0x7FF); set extended = true for a 29-bit identifier", show_id(f.id))));
        }
        can_proto::CanFrame::std_id(f.id as u16)
    }
    .expect("range checked");
    if f.data.len() > 8 {
        return Err(ctx.err_key(span, "data", &format!("{path}.data"), format!("{} data bytes: a CAN 2.0 frame carries at most 8", f.data.len())));
    }
    let mut data = Vec::with_capacity(8);
    for v in &f.data {
        data.push(byte(ctx, span, "data", &format!("{path}.data"), *v)?);
    }
    let dlc = match f.dlc {
        None => data.len() as i64,
        Some(d) => d,
    };
    if !(0..=15).contains(&dlc) {
        return Err(ctx.err_key(span, "dlc", &format!("{path}.dlc"), format!("DLC {dlc} does not fit the 4-bit field (0..=15)")));
    }
    if dlc > 8 && !f.raw_dlc {
        return Err(ctx.err_key(span, "dlc", &format!("{path}.dlc"), format!("DLC {dlc} > 8: a classic CAN frame carries at most 8 data bytes (DLC 9..15 are legal on the wire and mean 8; set raw_dlc = true to send one on purpose)")));
    }
    let want = if f.rtr { 0 } else { (dlc as usize).min(8) };
    if !f.rtr && data.len() != want {
        return Err(ctx.err_key(span, "data", &format!("{path}.data"), format!("DLC {dlc} needs {want} data byte(s), {} given", data.len())));
    }
    if f.rtr && !data.is_empty() {
        return Err(ctx.err_key(span, "data", &format!("{path}.data"), "a remote frame (rtr = true) carries no data"));
    }
    Ok(can_proto::CanFrame::with_dlc(id, f.rtr, dlc as u8, &data).expect("validated above"))
}

#[allow(clippy::too_many_arguments)]
fn check_timing(ctx: &Ctx, span: &std::ops::Range<usize>, key: &str, path: &str, can_hz: f64, btr0: u8, btr1: u8, target: Option<u32>, warnings: &mut Vec<String>) -> Result<(), ScenarioError> {
    let t = BusTiming::from_btr(btr0, btr1);
    let rate = t.bit_rate(can_hz);
    if rate > can_proto::timing::MAX_BIT_RATE as f64 * 1.005 {
        return Err(ctx.err_key(
            span,
            key,
            path,
            format!("no valid bit timing: BTR0 = 0x{btr0:02X}, BTR1 = 0x{btr1:02X} at {} MHz give {:.0} bit/s, above the 1 Mbit/s CAN 2.0 maximum", can_hz / 1e6, rate),
        ));
    }
    for issue in t.validate(can_hz as u32, target.unwrap_or(rate.round() as u32)) {
        warnings.push(format!("{path}: {issue}"));
    }
    Ok(())
}

fn build(ctx: &Ctx, raw: RawScenario, file: &Path) -> Result<Scenario, ScenarioError> {
    let mut warnings = Vec::new();
    let name = raw
        .name
        .clone()
        .unwrap_or_else(|| file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default());

    // [clocks]
    let cspan = raw.clocks.span();
    let clocks = raw.clocks.into_inner();
    for (k, v) in [("host_mhz", clocks.host_mhz), ("can_mhz", clocks.can_mhz)] {
        if !(v.is_finite() && v > 0.0 && v <= 1000.0) {
            return Err(ctx.err_key(&cspan, k, &format!("clocks.{k}"), format!("{v} MHz is not a usable clock (0 < f <= 1000 MHz)")));
        }
    }
    let can_hz = clocks.can_mhz * 1e6;
    if let Some(rate) = clocks.bit_rate
        && let Err(e) = BusTiming::for_bit_rate(can_hz as u32, rate)
    {
        return Err(ctx.err_key(&cspan, "bit_rate", "clocks.bit_rate", format!("no valid bit timing: {e}")));
    }

    // [host]
    let host = match raw.host.bfm.as_deref().unwrap_or("wishbone") {
        "wishbone" => HostBfm::Wishbone,
        "pio" => HostBfm::Pio,
        "i8051" => HostBfm::I8051,
        "axi4-lite" => HostBfm::Axi4Lite,
        "apb" => HostBfm::Apb,
        "apb3" => HostBfm::Apb3,
        "motorola" => HostBfm::Motorola,
        "regport" => HostBfm::Regport,
        "avalon" => HostBfm::Avalon {
            begintransfer_cyc: match raw.host.avalon_map.as_deref().unwrap_or("wrapper") {
                "wrapper" => false,
                "begintransfer-cyc" => true,
                other => return Err(ctx.err(0..0, "host.avalon_map", format!("`{other}`: use \"wrapper\" or \"begintransfer-cyc\""))),
            },
        },
        other => return Err(ctx.err(find(ctx.text, "bfm"), "host.bfm", format!("`{other}` is not a host BFM; use \"wishbone\", \"avalon\", \"pio\", \"i8051\", \"axi4-lite\", \"apb\" or \"apb3\""))),
    };

    // [dut]
    let (dspan, d) = match raw.dut {
        Some(s) => (s.span(), s.into_inner()),
        None => (0..0, RawDut::default()),
    };
    let dut = match d.kind.as_deref().unwrap_or("rtl") {
        "rtl" => DutKind::Rtl,
        "avalon-wrapper" => DutKind::AvalonWrapper,
        "model" => DutKind::Model,
        "external" => DutKind::External {
            path: d.path.map(PathBuf::from).ok_or_else(|| ctx.err_key(&dspan, "kind", "dut.path", "an external DUT needs `path`"))?,
            top: d.top.unwrap_or_else(|| "can_top".into()),
            defines: d.defines,
            includes: d.includes.into_iter().map(PathBuf::from).collect(),
        },
        other => {
            return Err(ctx.err_key(&dspan, "kind", "dut.kind", format!("`{other}`: use \"rtl\", \"avalon-wrapper\", \"model\" or \"external\"")));
        }
    };

    // [wiring]
    let rx = match raw.wiring.rx.as_deref().unwrap_or("bus") {
        "bus" => RxWire::Bus,
        "tied-recessive" => RxWire::TiedRecessive,
        "tied-dominant" => RxWire::TiedDominant,
        other => return Err(ctx.err(find(ctx.text, "rx"), "wiring.rx", format!("`{other}`: use \"bus\", \"tied-recessive\" or \"tied-dominant\""))),
    };

    // steps, tracking the register view (CDR.7) and reset mode (MOD.RM / CR.RR)
    let mut mode = Mode::BasicCan;
    let mut reset_mode = true;
    let mut steps = Vec::new();
    for (i, st) in raw.steps.into_iter().enumerate() {
        let span = st.span();
        let st = st.into_inner();
        let p = format!("step[{}]", i + 1);
        let (line, _) = line_col(ctx.text, span.start);
        let timeout = match st.timeout_bits {
            None => 100_000,
            Some(t) if t > 0 => t as u64,
            Some(t) => return Err(ctx.err_key(&span, "timeout_bits", &format!("{p}.timeout_bits"), format!("{t}: a timeout must be positive"))),
        };
        let view = match &st.view {
            None => mode,
            Some(v) => parse_mode(ctx, &span, "view", &format!("{p}.view"), v)?,
        };
        let actions = [
            st.write.is_some(),
            st.read.is_some(),
            st.wait_irq.is_some(),
            st.wait_sr_set.is_some() || st.wait_sr_clear.is_some(),
            st.wait_bits.is_some(),
            st.load_tx.is_some(),
            st.block.is_some(),
            st.drain.is_some(),
            st.release.is_some(),
            st.transmit.is_some(),
        ];
        let count = actions.iter().filter(|a| **a).count();
        if count != 1 {
            return Err(ctx.err(span, &p, format!("a step needs exactly one action (write, read, wait_irq, wait_sr_set/wait_sr_clear, wait_bits, load_tx, block, drain, release, transmit); found {count}")));
        }
        if st.optional.is_some() && st.wait_irq.is_none() {
            return Err(ctx.err_key(&span, "optional", &format!("{p}.optional"), "`optional` goes with `wait_irq`"));
        }
        if st.command.is_some() && st.transmit.is_none() {
            return Err(ctx.err_key(&span, "command", &format!("{p}.command"), "`command` goes with `transmit`"));
        }
        if let Some(block) = &st.block {
            block_steps(&ctx, &span, &p, block, Placed { line, table: i + 1 }, &mut mode, &mut reset_mode, &mut steps)?;
            continue;
        }
        let mut push = |action: Action, mode: Mode, reset_mode: bool| {
            steps.push(Step { n: steps.len() + 1, line, table: i + 1, note: st.note.clone(), mode, reset_mode, action, block: None });
        };
        if let Some(w) = &st.write {
            let (addr, name) = resolve(ctx, &span, "write", &format!("{p}.write"), w, view)?;
            let v = st.value.ok_or_else(|| ctx.err(span.clone(), &format!("{p}.value"), "a write needs `value`"))?;
            let value = byte(ctx, &span, "value", &format!("{p}.value"), v)?;
            push(Action::Write { addr, value, name }, mode, reset_mode);
            if addr == 31 {
                mode = Mode::from_cdr(value);
            }
            if addr == 0 {
                reset_mode = value & 1 != 0;
            }
        } else if let Some(r) = &st.read {
            let (addr, name) = resolve(ctx, &span, "read", &format!("{p}.read"), r, view)?;
            let expect = match st.expect {
                None => None,
                Some(e) => {
                    let e = byte(ctx, &span, "expect", &format!("{p}.expect"), e)?;
                    let m = byte(ctx, &span, "mask", &format!("{p}.mask"), st.mask.unwrap_or(0xFF))?;
                    Some((m, e))
                }
            };
            push(Action::Read { addr, name, expect }, mode, reset_mode);
        } else if st.wait_irq.is_some() {
            if st.optional == Some(true) {
                push(Action::WaitIrqOrTimeout { timeout_bits: timeout }, mode, reset_mode);
            } else {
                push(Action::WaitIrq { timeout_bits: timeout }, mode, reset_mode);
            }
        } else if let Some(n) = st.drain.or(st.release) {
            let key = if st.drain.is_some() { "drain" } else { "release" };
            if !(1..=64).contains(&n) {
                return Err(ctx.err_key(&span, key, &format!("{p}.{key}"), format!("{n}: between 1 and 64 messages")));
            }
            push(Action::Drain { max: n as u8, read: st.drain.is_some() }, mode, reset_mode);
        } else if let Some(f) = &st.transmit {
            let fr = frame(ctx, &span, &format!("{p}.transmit"), f)?;
            let command = byte(ctx, &span, "command", &format!("{p}.command"), st.command.unwrap_or(0x01))?;
            push(Action::Transmit { frame: fr, command, timeout_bits: timeout }, mode, reset_mode);
        } else if st.wait_sr_set.is_some() || st.wait_sr_clear.is_some() {
            let set = byte(ctx, &span, "wait_sr_set", &format!("{p}.wait_sr_set"), st.wait_sr_set.unwrap_or(0))?;
            let clear = byte(ctx, &span, "wait_sr_clear", &format!("{p}.wait_sr_clear"), st.wait_sr_clear.unwrap_or(0))?;
            push(Action::WaitSr { set, clear, timeout_bits: timeout }, mode, reset_mode);
        } else if let Some(b) = st.wait_bits {
            if b <= 0 {
                return Err(ctx.err_key(&span, "wait_bits", &format!("{p}.wait_bits"), format!("{b}: must be positive")));
            }
            push(Action::WaitBits(b as u64), mode, reset_mode);
        } else if let Some(f) = &st.load_tx {
            let fr = frame(ctx, &span, &format!("{p}.load_tx"), f)?;
            for (addr, value) in tx_buffer_bytes(&fr, view) {
                push(Action::Write { addr, value, name: None }, mode, reset_mode);
            }
        }
    }
    // BTR writes: check the DUT's timing
    let mut btr = (None, None);
    for s in &steps {
        if let Action::Write { addr, value, .. } = s.action {
            match addr {
                6 => btr.0 = Some(value),
                7 => btr.1 = Some((value, s.line, s.table)),
                _ => {}
            }
        }
    }
    if let (Some(b0), Some((b1, l1, t1))) = btr {
        let start = ctx.text.lines().take(l1 - 1).map(|l| l.len() + 1).sum::<usize>();
        check_timing(ctx, &(start..start + 1), "value", &format!("step[{t1}].value"), can_hz, b0, b1, clocks.bit_rate, &mut warnings)?;
    }

    // nodes
    let mut nodes = Vec::new();
    for (i, n) in raw.nodes.into_iter().enumerate() {
        let span = n.span();
        let n = n.into_inner();
        let p = format!("node[{}]", i + 1);
        let node_hz = n.can_mhz.map(|m| m * 1e6).unwrap_or(can_hz);
        if !(node_hz.is_finite() && node_hz > 0.0) {
            return Err(ctx.err_key(&span, "can_mhz", &format!("{p}.can_mhz"), "not a usable clock"));
        }
        if node_hz >= 2.0 * can_hz {
            return Err(ctx.err_key(&span, "can_mhz", &format!("{p}.can_mhz"), format!("a node's clock must be below twice the bus clock ({} MHz)", clocks.can_mhz)));
        }
        let btr0 = byte(ctx, &span, "btr0", &format!("{p}.btr0"), n.btr0)?;
        let btr1 = byte(ctx, &span, "btr1", &format!("{p}.btr1"), n.btr1)?;
        check_timing(ctx, &span, "btr1", &format!("{p}.btr1"), node_hz, btr0, btr1, clocks.bit_rate, &mut warnings)?;
        let mode = match &n.mode {
            None => Mode::BasicCan,
            Some(m) => parse_mode(ctx, &span, "mode", &format!("{p}.mode"), m)?,
        };
        let max = if mode == Mode::BasicCan { 1 } else { 4 };
        let mut acr = [0u8; 4];
        let mut amr = [0xFFu8; 4];
        for (key, src, dst) in [("acr", &n.acr, &mut acr), ("amr", &n.amr, &mut amr)] {
            if src.len() > max {
                return Err(ctx.err_key(&span, key, &format!("{p}.{key}"), format!("{} bytes given; {mode} has {max}", src.len())));
            }
            for (j, v) in src.iter().enumerate() {
                dst[j] = byte(ctx, &span, key, &format!("{p}.{key}"), *v)?;
            }
        }
        let mut traffic = Vec::new();
        for (j, f) in n.traffic.into_iter().enumerate() {
            let fspan = f.span();
            let f = f.into_inner();
            let fr = frame(ctx, &fspan, &format!("{p}.send[{}]", j + 1), &f)?;
            traffic.push(FrameSpec { frame: fr, at_bit: f.at_bit.unwrap_or(0).max(0) as u64 });
        }
        if let Some(r) = &n.replay {
            let rate = match r.bit_rate {
                Some(0) => return Err(ctx.err_key(&span, "replay", &format!("{p}.replay.bit_rate"), "a bit rate must be positive")),
                Some(b) => b as f64,
                None => BusTiming::from_btr(btr0, btr1).bit_rate(node_hz),
            };
            let log = file.parent().unwrap_or(Path::new("")).join(&r.file);
            let start = r.start_bit.unwrap_or(0).max(0) as u64;
            let (frames, skipped) = replay::traffic(&log, rate, start, r.iface.as_deref())
                .map_err(|e| ctx.err_key(&span, "replay", &format!("{p}.replay"), e))?;
            if skipped > 0 {
                warnings.push(format!("{p}.replay: {skipped} error frame(s) in {} not replayed (a node sends data and remote frames only)", log.display()));
            }
            traffic.extend(frames);
        }
        if nodes.iter().any(|x: &NodeSpec| x.name == n.name) {
            return Err(ctx.err_key(&span, "name", &format!("{p}.name"), format!("node name `{}` is used twice", n.name)));
        }
        nodes.push(NodeSpec { name: n.name, can_hz: node_hz, btr0, btr1, mode, acr, amr, listen_only: n.listen_only, traffic });
    }

    // faults
    let mut faults = Vec::new();
    for (i, f) in raw.faults.into_iter().enumerate() {
        let span = f.span();
        let f = f.into_inner();
        let p = format!("fault[{}]", i + 1);
        let kind = match f.kind.as_str() {
            "stuck-dominant" => FaultKind::StuckDominant,
            "stuck-recessive" => FaultKind::StuckRecessive,
            "flip" => FaultKind::Flip,
            "glitch" => FaultKind::Glitch,
            other => return Err(ctx.err_key(&span, "kind", &format!("{p}.kind"), format!("`{other}`: use stuck-dominant, stuck-recessive, flip or glitch"))),
        };
        let frame_bit = match (f.frame, f.bit_in_frame) {
            (Some(fr), Some(b)) if fr >= 1 && b >= 0 => Some((fr as u32, b as u32)),
            (None, None) => None,
            _ => return Err(ctx.err_key(&span, "frame", &format!("{p}.frame"), "give frame (from 1) and bit_in_frame (from 0) together")),
        };
        if f.at_bit.is_none() == frame_bit.is_none() {
            return Err(ctx.err(span, &p, "give either at_bit or frame + bit_in_frame"));
        }
        let target = f.target.unwrap_or_else(|| "bus".into());
        if target != "bus" && target != "dut-rx" && !nodes.iter().any(|n| n.name == target) {
            return Err(ctx.err_key(&span, "target", &format!("{p}.target"), format!("`{target}` is neither \"bus\", \"dut-rx\" nor a node name")));
        }
        // A glitch's pulse placed in the bit (the DUT's bit grid, dut-rx
        // only): in CAN clocks or in the DUT's time quanta, one representation.
        let (btr0, btr1) = btr_written(&steps);
        let clocks_per_tq = 2 * (u32::from(btr0 & 0x3F) + 1);
        let per_bit = can_proto::timing::BusTiming::from_btr(btr0, btr1).clocks_per_bit();
        let (key, unit, placed) = match (f.offset_clocks, f.width_clocks, f.offset_tq, f.width_tq) {
            (None, None, None, None) => ("", 1, None),
            (Some(o), Some(w), None, None) => ("offset_clocks", 1, Some((o, w))),
            (None, None, Some(o), Some(w)) => ("offset_tq", clocks_per_tq, Some((o, w))),
            (None, None, _, _) => return Err(ctx.err_key(&span, "offset_tq", &format!("{p}.offset_tq"), "give offset_tq and width_tq together")),
            (_, _, None, None) => return Err(ctx.err_key(&span, "offset_clocks", &format!("{p}.offset_clocks"), "give offset_clocks and width_clocks together")),
            _ => return Err(ctx.err_key(&span, "offset_tq", &format!("{p}.offset_tq"), "place the pulse in clocks (offset_clocks, width_clocks) or in quanta (offset_tq, width_tq), not both")),
        };
        let pulse_clocks = match placed {
            None => None,
            Some(_) if kind != FaultKind::Glitch => {
                return Err(ctx.err_key(&span, key, &format!("{p}.{key}"), format!("{key} places a glitch's pulse; this fault is no glitch")));
            }
            Some(_) if target != "dut-rx" => {
                return Err(ctx.err_key(&span, key, &format!("{p}.{key}"), format!("{key} is counted on the DUT's bit grid: give target = \"dut-rx\"")));
            }
            Some(_) if frame_bit.is_none() => {
                return Err(ctx.err_key(&span, key, &format!("{p}.{key}"), format!("{key} needs frame + bit_in_frame (the bit it is counted from)")));
            }
            Some((o, w)) if o >= 0 && w >= 1 && (o + w) * i64::from(unit) <= i64::from(per_bit) => Some((o as u32 * unit, w as u32 * unit)),
            Some((o, w)) => {
                return Err(ctx.err_key(&span, key, &format!("{p}.{key}"), format!("{key} = {o}, width = {w}: the pulse must be at least 1 wide and end within the DUT's bit of {per_bit} CAN clocks, {} quanta (BTR0 = {btr0:#04X}, BTR1 = {btr1:#04X})", per_bit / clocks_per_tq)));
            }
        };
        let pulse_level = match f.level.as_deref() {
            None => None,
            Some(_) if pulse_clocks.is_none() => {
                return Err(ctx.err_key(&span, "level", &format!("{p}.level"), "level forces a placed glitch's pulse: give offset_clocks/width_clocks or offset_tq/width_tq"));
            }
            Some("dominant") => Some(can_proto::DOMINANT),
            Some("recessive") => Some(!can_proto::DOMINANT),
            Some(other) => return Err(ctx.err_key(&span, "level", &format!("{p}.level"), format!("`{other}`: use \"dominant\" or \"recessive\""))),
        };
        let pulse_on_sof_grid = match f.grid.as_deref() {
            None | Some("bench") => false,
            Some(_) if pulse_clocks.is_none() => {
                return Err(ctx.err_key(&span, "grid", &format!("{p}.grid"), "grid places a glitch's pulse: give offset_clocks/width_clocks or offset_tq/width_tq"));
            }
            Some("sof") => true,
            Some(other) => return Err(ctx.err_key(&span, "grid", &format!("{p}.grid"), format!("`{other}`: use \"sof\" (the nominal grid from the frame's SOF edge) or \"bench\""))),
        };
        faults.push(FaultSpec { kind, at_bit: f.at_bit.map(|b| b.max(0) as u64), frame_bit, duration_bits: f.duration_bits.unwrap_or(1).max(1) as u64, target, pulse_clocks, pulse_level, pulse_on_sof_grid });
    }

    let (btr0, btr1) = btr_written(&steps);
    let timing = can_proto::timing::BusTiming::from_btr(btr0, btr1);
    let raw_nodes = rawnode::build(ctx, raw.raw_nodes, &nodes, timing.clocks_per_tq(), timing.clocks_per_bit())?;

    // expect
    let (espan, e) = match raw.expect {
        Some(s) => (s.span(), s.into_inner()),
        None => (0..0, RawExpect::default()),
    };
    let category = match &e.category {
        None => None,
        Some(c) => Some(Category::from_name(c).ok_or_else(|| {
            let names: Vec<&str> = Category::ALL.iter().map(|c| c.name()).collect();
            ctx.err_key(&espan, "category", "expect.category", format!("`{c}` is not a diagnosis category; one of {}", names.join(", ")))
        })?),
    };
    let field = match &e.field {
        None => None,
        Some(f) => Some(<can_proto::Field as diagnose::named::Named>::from_name(f).ok_or_else(|| {
            ctx.err_key(&espan, "field", "expect.field", format!("`{f}` is not a CAN field name (Sof, BaseId, ..., AckSlot, Eof, ActiveErrorFlag...)"))
        })?),
    };
    let sr = match e.sr {
        None => None,
        Some(v) => Some(byte(ctx, &espan, "sr", "expect.sr", v)?),
    };
    for k in e.received.keys() {
        if !nodes.iter().any(|n| &n.name == k) && k != "dut" {
            return Err(ctx.err_key(&espan, k, &format!("expect.received.{k}"), format!("no node named `{k}`")));
        }
    }
    let expect = ExpectSpec {
        category,
        field,
        first_attempt_tec: e.first_attempt_tec,
        tec: e.tec,
        sr,
        attempts: e.attempts,
        bus_off_attempt: e.bus_off_attempt,
        received: e.received.into_iter().collect(),
    };

    Ok(Scenario {
        name,
        file: file.to_path_buf(),
        purpose: raw.purpose,
        verifies: raw.verifies,
        sequence: raw.sequence,
        host_hz: clocks.host_mhz * 1e6,
        can_hz,
        host,
        timeout_cycles: raw.host.timeout_cycles.unwrap_or(1000),
        host_fixed: raw.host.fixed.clone(),
        dut,
        rx,
        tx_to_bus: raw.wiring.tx_to_bus.unwrap_or(true),
        steps,
        nodes,
        faults,
        raw_nodes,
        expect,
        max_bits: raw.run.max_bits.unwrap_or(20_000),
        keep_bits: raw.run.keep_bits.unwrap_or(256),
        waivers: raw
            .run
            .waivers
            .unwrap_or_default()
            .iter()
            .map(|w| file.parent().unwrap_or(Path::new("")).join(w))
            .collect(),
        warnings,
    })
}

/// The last BTR0/BTR1 values the steps write (0 where none).
fn btr_written(steps: &[Step]) -> (u8, u8) {
    let mut b = (0u8, 0u8);
    for s in steps {
        if let Action::Write { addr, value, .. } = s.action {
            // BTR0/BTR1 sit at 6/7 in both views.
            if addr == 6 {
                b.0 = value;
            } else if addr == 7 {
                b.1 = value;
            }
        }
    }
    b
}

/// Span of the first `key =` in the text (for keys in untyped places).
fn find(text: &str, key: &str) -> std::ops::Range<usize> {
    let ctx = Ctx { file: String::new(), text };
    ctx.key_span(&(0..text.len()), key)
}

/// The TX buffer bytes (address, value) for `frame` in `mode`
/// (BasicCAN: addresses 10..; PeliCAN: frame information at 16, then ID, data).
pub fn tx_buffer_bytes(frame: &can_proto::CanFrame, mode: Mode) -> Vec<(u8, u8)> {
    use can_proto::FrameTrait;
    let id = frame.raw_id();
    let rtr = frame.is_remote_frame() as u8;
    let dlc = frame.dlc_raw() & 0x0F;
    let data = frame.data();
    let mut v = Vec::new();
    match mode {
        Mode::BasicCan => {
            v.push((10, (id >> 3) as u8));
            v.push((11, (((id & 7) as u8) << 5) | (rtr << 4) | dlc));
            for (i, b) in data.iter().enumerate() {
                v.push((12 + i as u8, *b));
            }
        }
        Mode::PeliCan => {
            let ext = frame.is_extended();
            v.push((16, ((ext as u8) << 7) | (rtr << 6) | dlc));
            let mut a = 17u8;
            if ext {
                for b in [(id >> 21) as u8, (id >> 13) as u8, (id >> 5) as u8, ((id & 0x1F) << 3) as u8] {
                    v.push((a, b));
                    a += 1;
                }
            } else {
                v.push((a, (id >> 3) as u8));
                v.push((a + 1, ((id & 7) << 5) as u8));
                a += 2;
            }
            for (i, b) in data.iter().enumerate() {
                v.push((a + i as u8, *b));
            }
        }
    }
    v
}

/// Names of the register at `addr` in `mode` for a read or write in reset or
/// operating mode (e.g. `"ACR"`, `"TXID1"`, `"RXB+2"`), from regmap.
pub fn register_name(mode: Mode, reset_mode: bool, write: bool, addr: u8) -> Option<String> {
    let op = if reset_mode { OpMode::Reset } else { OpMode::Operating };
    let acc = if write { Access::Write } else { Access::Read };
    let v = regmap::lookup(mode, op, acc, addr)?;
    let r = v.register()?;
    Some(if r.len > 1 { format!("{}+{}", r.name, addr - r.addr) } else { r.name.to_string() })
}

/// Reads a regression list and loads each scenario on its own: the path of
/// every entry with its scenario or the reason it could not be loaded, so
/// one bad file does not hide the others ([`regress::regress_inputs`]).
/// Only an unreadable list is an error.
pub fn load_list_entries(path: impl AsRef<Path>) -> Result<Vec<(PathBuf, Result<Scenario, ScenarioError>)>, ScenarioError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| ScenarioError::Io { file: path.display().to_string(), source })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    Ok(text
        .lines()
        .map(|line| line.split('#').next().unwrap_or("").trim())
        .filter(|l| !l.is_empty())
        .map(|l| {
            let p = dir.join(l);
            let s = Scenario::load(&p);
            (p, s)
        })
        .collect())
}

/// Reads a regression list (one scenario path per line, `#` comments),
/// paths relative to the list's directory.
pub fn load_list(path: impl AsRef<Path>) -> Result<Vec<Scenario>, ScenarioError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|source| ScenarioError::Io { file: path.display().to_string(), source })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    for line in text.lines() {
        let l = line.split('#').next().unwrap_or("").trim();
        if l.is_empty() {
            continue;
        }
        out.push(Scenario::load(dir.join(l))?);
    }
    Ok(out)
}
