//! The raw `tb/*.toml` layout, as serde reads it. Every table rejects keys it
//! does not know (`deny_unknown_fields`), and tables that need a line number
//! in later checks are wrapped in [`toml::Spanned`]. The doc comments are the
//! reference's descriptions (`cancosim gen reference`); a default written as
//! "Default: ..." is the one the validation in `lib.rs` applies.

use serde::Deserialize;
use toml::Spanned;

/// A register given by name (`"BTR0"`, `"TXDATA+1"`) or by address.
#[derive(Clone, Debug, Deserialize, PartialEq, schemars::JsonSchema)]
#[serde(untagged)]
pub enum RegRef {
    /// Data sheet name, optionally `+offset` into a window.
    Name(String),
    /// Address.
    Addr(i64),
}

/// A scenario file (`tb/*.toml`): what it verifies, its clocks, host and DUT, the
/// host program (`[[step]]`), golden-model nodes, faults, bit-level senders and the
/// expected outcome. Unknown keys are rejected; errors read `file:line: key: message`.
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawScenario {
    /// Name in reports, lists and waivers' `consequences`. Default: the file stem.
    pub name: Option<String>,
    /// What the scenario checks, one line. Required.
    pub purpose: String,
    /// What it verifies, one entry per claim (datasheet or CAN 2.0B clause). Default: none.
    #[serde(default)]
    pub verifies: Vec<String>,
    /// The test sequence in words, one entry per stage. Default: none.
    #[serde(default)]
    pub sequence: Vec<String>,
    /// The clocks. Required.
    #[schemars(with = "RawClocks")]
    pub clocks: Spanned<RawClocks>,
    /// The host bus-functional model. Default: Wishbone.
    #[serde(default)]
    pub host: RawHost,
    /// The device under test. Default: our RTL (`kind = "rtl"`).
    #[serde(default)]
    #[schemars(with = "Option<RawDut>")]
    pub dut: Option<Spanned<RawDut>>,
    /// How the DUT's rx and tx meet the bus. Default: both on the bus.
    #[serde(default)]
    pub wiring: RawWiring,
    /// Run limits and waivers. Default: 20000 bit times, no waivers.
    #[serde(default)]
    pub run: RawRun,
    /// The host program, one action per step, in order (also written as one
    /// `step = [ {...}, ... ]` array at the top of the file). Default: none.
    #[serde(default, rename = "step")]
    #[schemars(with = "Vec<RawStep>")]
    pub steps: Vec<Spanned<RawStep>>,
    /// Golden-model nodes on the bus. Default: none.
    #[serde(default, rename = "node")]
    #[schemars(with = "Vec<RawNode>")]
    pub nodes: Vec<Spanned<RawNode>>,
    /// Faults injected on the bus, the DUT's rx or a node. Default: none.
    #[serde(default, rename = "fault")]
    #[schemars(with = "Vec<RawFault>")]
    pub faults: Vec<Spanned<RawFault>>,
    /// Bit-level senders on the wire (a lower tester). Default: none.
    #[serde(default, rename = "raw-node")]
    #[schemars(with = "Vec<RawRawNode>")]
    pub raw_nodes: Vec<Spanned<RawRawNode>>,
    /// The expected outcome, checked against the diagnosis. Default: a pass.
    #[serde(default)]
    #[schemars(with = "Option<RawExpect>")]
    pub expect: Option<Spanned<RawExpect>>,
}

/// `[clocks]`.
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawClocks {
    /// Host clock (`wb_clk_i`), MHz. Required.
    pub host_mhz: f64,
    /// CAN clock (`clk_i`), MHz. Required.
    pub can_mhz: f64,
    /// Intended bit rate; if given, some BTR setting of `can_mhz` must reach it and the
    /// BTR values the program writes are checked against it. Default: not checked.
    pub bit_rate: Option<u32>,
}

/// `[host]`.
#[derive(Debug, Deserialize, Default, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawHost {
    /// `"wishbone"`, `"avalon"`, `"pio"` or `"i8051"` (`--host` overrides it). Default: `"wishbone"`.
    pub bfm: Option<String>,
    /// Avalon only: `"wrapper"` or `"begintransfer-cyc"`. Default: `"wrapper"`.
    pub avalon_map: Option<String>,
    /// Host cycles before an access with no ack is a timeout. Default: 1000.
    pub timeout_cycles: Option<u32>,
    /// Why the host wiring is the point of this scenario: a run with a
    /// host override (`--host`) skips it with this reason. Default: none.
    pub fixed: Option<String>,
}

/// `[dut]`.
#[derive(Debug, Deserialize, Default, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawDut {
    /// `"rtl"`, `"avalon-wrapper"`, `"model"` or `"external"`. Default: `"rtl"`.
    pub kind: Option<String>,
    /// External only: the core's source directory. Required with `"external"`.
    pub path: Option<String>,
    /// External only: the top module. Default: `"can_top"`.
    pub top: Option<String>,
    /// External only: Verilog defines (`NAME` or `NAME=VALUE`). Default: none.
    #[serde(default)]
    pub defines: Vec<String>,
    /// External only: include directories. Default: none.
    #[serde(default)]
    pub includes: Vec<String>,
}

/// `[wiring]`.
#[derive(Debug, Deserialize, Default, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawWiring {
    /// The DUT's rx: `"bus"`, `"tied-recessive"` or `"tied-dominant"`. Default: `"bus"`.
    pub rx: Option<String>,
    /// tx_o drives the bus. Default: true.
    pub tx_to_bus: Option<bool>,
}

/// `[run]`.
#[derive(Debug, Deserialize, Default, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawRun {
    /// Run length limit in bit times. Default: 20000.
    pub max_bits: Option<u64>,
    /// Bus bits kept in the run record. Default: 256.
    pub keep_bits: Option<usize>,
    /// Waiver files, relative to the scenario file. Default: none.
    pub waivers: Option<Vec<String>>,
}

/// One `[[step]]`: exactly one action key (`write`, `read`, `wait_irq`,
/// `wait_sr_set`/`wait_sr_clear`, `wait_bits`, `load_tx`, `block`).
#[derive(Debug, Deserialize, Default, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawStep {
    /// Text echoed in the run's output. Default: none.
    pub note: Option<String>,
    /// Write a register: its name in the view in force (CDR.7), `"TXB+1"`, or an address.
    pub write: Option<RegRef>,
    /// The byte `write` writes. Required with `write`.
    pub value: Option<i64>,
    /// Read a register (name or address); checked if `expect` is given.
    pub read: Option<RegRef>,
    /// The read must give this under `mask`. Default: not checked.
    pub expect: Option<i64>,
    /// Bits of the read that `expect` checks. Default: 0xFF.
    pub mask: Option<i64>,
    /// Use this register view's address for the name (`"basic"` / `"peli"`),
    /// whatever mode the controller is in (to reproduce address confusion).
    /// Default: the view in force.
    pub view: Option<String>,
    /// Wait until the DUT's interrupt pin is active.
    pub wait_irq: Option<bool>,
    /// Wait (polling SR) until these SR bits are set. Default: 0.
    pub wait_sr_set: Option<i64>,
    /// Wait (polling SR) until these SR bits are clear. Default: 0.
    pub wait_sr_clear: Option<i64>,
    /// Wait this many bit times.
    pub wait_bits: Option<i64>,
    /// Bit times a `wait_irq`/`wait_sr_*` may take before the run fails. Default: 100000.
    pub timeout_bits: Option<i64>,
    /// Fill the TX buffer with this frame (expands to register writes).
    pub load_tx: Option<RawFrame>,
    /// Accesses (write, read, load_tx steps) done as one Wishbone block
    /// cycle: cyc and stb held from the first to the last ack (single
    /// accesses on other host buses).
    #[schemars(with = "Option<Vec<serde_json::Value>>")]
    pub block: Option<Vec<RawStep>>,
    /// With `wait_irq`: a timeout ends the wait instead of failing the run.
    pub optional: Option<bool>,
    /// Read and release up to this many received messages while SR.RBS = 1.
    pub drain: Option<i64>,
    /// Release up to this many messages while SR.RBS = 1, without reading them.
    pub release: Option<i64>,
    /// Wait (up to `timeout_bits`) for SR.TBS = 1 in operating mode, then
    /// fill the TX buffer with this frame and write `command` to CMR; skipped
    /// when the buffer stays locked, the node is bus-off or in reset mode.
    pub transmit: Option<RawFrame>,
    /// With `transmit`: the CMR value (default 0x01, TR).
    pub command: Option<i64>,
}

/// A CAN frame in a file (`load_tx`, a node's `send`).
#[derive(Debug, Deserialize, Default, Clone, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawFrame {
    /// Identifier (11 bits, 29 with `extended`). Required.
    pub id: i64,
    /// 29-bit identifier. Default: false.
    #[serde(default)]
    pub extended: bool,
    /// Remote frame. Default: false.
    #[serde(default)]
    pub rtr: bool,
    /// Data bytes (at most 8). Default: none.
    #[serde(default)]
    pub data: Vec<i64>,
    /// Data length code. Default: the number of data bytes.
    pub dlc: Option<i64>,
    /// Send DLC 9..15 on purpose (legal on the wire, means 8 bytes). Default: false.
    #[serde(default)]
    pub raw_dlc: bool,
    /// Node traffic only: bit time at which to request transmission. Default: 0.
    pub at_bit: Option<i64>,
}

/// One `[[node]]`: a golden-model node on the bus.
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawNode {
    /// Its name, for faults' `target` and `[expect] received`. Required.
    pub name: String,
    /// Its own oscillator in MHz (clock tolerance), below twice `clocks.can_mhz`. Default: `clocks.can_mhz`.
    pub can_mhz: Option<f64>,
    /// Bus timing register 0. Required.
    pub btr0: i64,
    /// Bus timing register 1. Required.
    pub btr1: i64,
    /// `"basic"` or `"peli"`. Default: `"basic"`.
    pub mode: Option<String>,
    /// Acceptance code: BasicCAN one byte; PeliCAN up to four. Default: 0.
    #[serde(default)]
    pub acr: Vec<i64>,
    /// Acceptance mask (as `acr`). Default: 0xFF (accept all).
    #[serde(default)]
    pub amr: Vec<i64>,
    /// Listen-only mode (no ACK, no error flags). Default: false.
    #[serde(default)]
    pub listen_only: bool,
    /// Frames it sends, each at its `at_bit`. Default: none.
    #[serde(default, rename = "send")]
    #[schemars(with = "Vec<RawFrame>")]
    pub traffic: Vec<Spanned<RawFrame>>,
    /// Frames of a candump log sent as this node's traffic. Default: none.
    pub replay: Option<RawReplay>,
}

/// `replay = { file = "capture.log", bit_rate = 500000, start_bit = 100 }`.
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawReplay {
    /// candump log (`candump -l`), relative to the scenario file. Required.
    pub file: String,
    /// Bit rate the log was captured at (its gaps are kept in bit times).
    /// Default: the node's own bit rate (gaps kept in seconds).
    pub bit_rate: Option<u32>,
    /// Bit time of the log's first frame. Default: 0.
    pub start_bit: Option<i64>,
    /// Replay only the lines of this interface. Default: every line.
    pub iface: Option<String>,
}

/// One `[[fault]]`. Frames count SOFs on the bus from 1; bits are wire bits from
/// SOF = 0, stuff bits included.
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawFault {
    /// `"stuck-dominant"`, `"stuck-recessive"`, `"flip"` or `"glitch"`. Required.
    pub kind: String,
    /// Bit time of the run it starts at (or `frame` and `bit_in_frame`).
    pub at_bit: Option<i64>,
    /// Frame it hits (with `bit_in_frame`).
    pub frame: Option<i64>,
    /// Wire bit of `frame` it starts at.
    pub bit_in_frame: Option<i64>,
    /// Bit times it lasts. Default: 1.
    pub duration_bits: Option<i64>,
    /// Glitch only: first time quantum of the pulse within the bit
    /// (0 = SYNC_SEG), in the DUT's quanta (2 * (BRP + 1) CAN clocks).
    /// Default: 1/8 bit wide from 1/4 into the bit.
    pub offset_tq: Option<i64>,
    /// Glitch only: pulse length in time quanta (with `offset_tq`).
    pub width_tq: Option<i64>,
    /// `"bus"` (every node and the DUT), `"dut-rx"` (the DUT and its shadow model
    /// only), or a node name. Default: `"bus"`.
    pub target: Option<String>,
    /// Glitch only: first CAN clock of the pulse, counted from the start of
    /// the bit (the bench's bit grid), instead of 1/4 into the bit; `target = "dut-rx"` only.
    pub offset_clocks: Option<i64>,
    /// Glitch only: pulse length in CAN clocks (with `offset_clocks`).
    pub width_clocks: Option<i64>,
    /// Placed glitch only: the level the pulse forces (`"dominant"` or
    /// `"recessive"`). Default: it inverts the wire's.
    pub level: Option<String>,
    /// Placed glitch only: `"sof"` counts the bit and offset on the nominal
    /// grid from the frame's SOF edge (no resynchronisation), not on the
    /// bench's grid. Default: `"bench"`.
    pub grid: Option<String>,
}

/// One `[[raw-node]]`: a bit-level sender (the lower tester) on the wire.
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawRawNode {
    /// Its name in reports. Required.
    pub name: String,
    /// Start: at this bit time of the run, ...
    pub at_bit: Option<i64>,
    /// ... or at this wire bit (from SOF = 0) of this frame (SOFs on the bus from 1), ...
    pub frame: Option<i64>,
    /// ... the wire bit of `frame` to start at.
    pub bit_in_frame: Option<i64>,
    /// ... or after this many recessive bit times in a row (11: bus idle).
    pub idle_bits: Option<i64>,
    /// The levels, one per bit time: "0" dominant, "1" recessive; spaces and `_` ignored.
    pub bits: Option<String>,
    /// Or a frame described by its fields.
    pub fields: Option<RawFields>,
    /// Levels expected on the wire from its first bit on ("0", "1", "x" any). Default: not checked.
    pub expect_bits: Option<String>,
    /// Its first bit starts this many of the DUT's time quanta after the
    /// start point (inside that bit), ... Default: 0.
    pub offset_tq: Option<i64>,
    /// ... or this many CAN clocks after it.
    pub offset_clocks: Option<i64>,
}

/// `fields = { id = 0x123, data = [1], r0 = 1, ... }`: a frame with any
/// field at a non-nominal value (levels 0 = dominant, 1 = recessive).
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawFields {
    /// Identifier. Required.
    pub id: i64,
    /// 29-bit identifier. Default: false.
    #[serde(default)]
    pub extended: bool,
    /// Remote frame. Default: false.
    #[serde(default)]
    pub rtr: bool,
    /// Data bytes. Default: none.
    #[serde(default)]
    pub data: Vec<i64>,
    /// Data length code. Default: the number of data bytes.
    pub dlc: Option<i64>,
    /// SRR level (extended frames). Default: nominal (1).
    pub srr: Option<i64>,
    /// r1 level. Default: nominal (0).
    pub r1: Option<i64>,
    /// r0 level. Default: nominal (0).
    pub r0: Option<i64>,
    /// CRC sent instead of the one computed over the bits as sent. Default: computed.
    pub crc: Option<i64>,
    /// Level driven in the ACK slot (default 1: it is the transmitter).
    pub ack: Option<i64>,
    /// Wire bits (SOF = 0, after stuffing) sent inverted. Default: none.
    #[serde(default)]
    pub flip: Vec<i64>,
    /// Last wire bit sent. Default: the whole frame.
    pub until_bit: Option<i64>,
    /// The node expects a dominant ACK slot (another node's ACK). Default: false.
    #[serde(default)]
    pub expect_ack: bool,
}

/// `[expect]`: the expected outcome, checked against the diagnosis.
#[derive(Debug, Deserialize, Default, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RawExpect {
    /// The diagnosis category (`diagnose::Category` name, `"RxNotFollowingTx"`). Default: `"Pass"`.
    pub category: Option<String>,
    /// The CAN field the diagnosis names (`"Sof"`). Default: not checked.
    pub field: Option<String>,
    /// TEC after the first attempt. Default: not checked.
    pub first_attempt_tec: Option<u16>,
    /// Final TEC (or plateau). Default: not checked.
    pub tec: Option<u16>,
    /// Final SR. Default: not checked.
    pub sr: Option<i64>,
    /// Transmission attempts. Default: not checked.
    pub attempts: Option<u32>,
    /// Attempt during which bus-off happened. Default: not checked.
    pub bus_off_attempt: Option<u32>,
    /// Frames each listed node must have received (name = count). Default: not checked.
    #[serde(default)]
    pub received: std::collections::BTreeMap<String, u32>,
}

/// The JSON schema of a scenario file, for the generated reference
/// (`cancosim gen reference`): doc comments are the descriptions.
pub fn file_schema() -> schemars::Schema {
    schemars::schema_for!(RawScenario)
}
