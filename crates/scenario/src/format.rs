//! The raw `tb/*.toml` layout, as serde reads it. Every table rejects keys it
//! does not know (`deny_unknown_fields`), and tables that need a line number
//! in later checks are wrapped in [`toml::Spanned`].

use serde::Deserialize;
use toml::Spanned;

/// A register given by name (`"BTR0"`, `"TXDATA+1"`) or by address.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum RegRef {
    /// Data sheet name, optionally `+offset` into a window.
    Name(String),
    /// Address.
    Addr(i64),
}

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScenario {
    pub name: Option<String>,
    pub purpose: String,
    #[serde(default)]
    pub verifies: Vec<String>,
    #[serde(default)]
    pub sequence: Vec<String>,
    pub clocks: Spanned<RawClocks>,
    #[serde(default)]
    pub host: RawHost,
    #[serde(default)]
    pub dut: Option<Spanned<RawDut>>,
    #[serde(default)]
    pub wiring: RawWiring,
    #[serde(default)]
    pub run: RawRun,
    #[serde(default, rename = "step")]
    pub steps: Vec<Spanned<RawStep>>,
    #[serde(default, rename = "node")]
    pub nodes: Vec<Spanned<RawNode>>,
    #[serde(default, rename = "fault")]
    pub faults: Vec<Spanned<RawFault>>,
    #[serde(default, rename = "raw-node")]
    pub raw_nodes: Vec<Spanned<RawRawNode>>,
    #[serde(default)]
    pub expect: Option<Spanned<RawExpect>>,
}

/// `[clocks]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawClocks {
    pub host_mhz: f64,
    pub can_mhz: f64,
    /// Intended bit rate; if given, some BTR setting of `can_mhz` must reach it.
    pub bit_rate: Option<u32>,
}

/// `[host]`.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawHost {
    pub bfm: Option<String>,
    /// Avalon only: "wrapper" (default) or "begintransfer-cyc" (seed 000).
    pub avalon_map: Option<String>,
    /// Host cycles before an access with no ack is a timeout.
    pub timeout_cycles: Option<u32>,
    /// Why the host wiring is the point of this scenario: a run with a
    /// host override (`--host`) skips it with this reason.
    pub fixed: Option<String>,
}

/// `[dut]`.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawDut {
    pub kind: Option<String>,
    pub path: Option<String>,
    pub top: Option<String>,
    #[serde(default)]
    pub defines: Vec<String>,
    #[serde(default)]
    pub includes: Vec<String>,
}

/// `[wiring]`.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawWiring {
    /// "bus" (default), "tied-recessive", "tied-dominant".
    pub rx: Option<String>,
    /// tx_o drives the bus (default true).
    pub tx_to_bus: Option<bool>,
}

/// `[run]`.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawRun {
    pub max_bits: Option<u64>,
    pub keep_bits: Option<usize>,
    /// Waiver files, relative to the scenario file.
    pub waivers: Option<Vec<String>>,
}

/// One `[[step]]`: exactly one action key.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawStep {
    pub note: Option<String>,
    pub write: Option<RegRef>,
    pub value: Option<i64>,
    pub read: Option<RegRef>,
    pub expect: Option<i64>,
    pub mask: Option<i64>,
    /// Use this register view's address for the name ("basic" / "peli"),
    /// whatever mode the controller is in (to reproduce address confusion).
    pub view: Option<String>,
    pub wait_irq: Option<bool>,
    pub wait_sr_set: Option<i64>,
    pub wait_sr_clear: Option<i64>,
    pub wait_bits: Option<i64>,
    pub timeout_bits: Option<i64>,
    /// Fill the TX buffer with this frame (expands to register writes).
    pub load_tx: Option<RawFrame>,
    /// Accesses (write, read, load_tx steps) done as one Wishbone block
    /// cycle: cyc and stb held from the first to the last ack.
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

/// A CAN frame in a file.
#[derive(Debug, Deserialize, Default, Clone)]
#[serde(deny_unknown_fields)]
pub struct RawFrame {
    pub id: i64,
    #[serde(default)]
    pub extended: bool,
    #[serde(default)]
    pub rtr: bool,
    #[serde(default)]
    pub data: Vec<i64>,
    pub dlc: Option<i64>,
    /// Send DLC 9..15 on purpose (legal on the wire, means 8 bytes).
    #[serde(default)]
    pub raw_dlc: bool,
    /// Node traffic only: bit time at which to request transmission.
    pub at_bit: Option<i64>,
}

/// One `[[node]]`: a golden-model node on the bus.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawNode {
    pub name: String,
    pub can_mhz: Option<f64>,
    pub btr0: i64,
    pub btr1: i64,
    /// "basic" (default) or "peli".
    pub mode: Option<String>,
    /// BasicCAN: one byte; PeliCAN: up to four.
    #[serde(default)]
    pub acr: Vec<i64>,
    #[serde(default)]
    pub amr: Vec<i64>,
    #[serde(default)]
    pub listen_only: bool,
    #[serde(default, rename = "send")]
    pub traffic: Vec<Spanned<RawFrame>>,
    /// Frames of a candump log sent as this node's traffic.
    pub replay: Option<RawReplay>,
}

/// `replay = { file = "capture.log", bit_rate = 500000, start_bit = 100 }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawReplay {
    /// candump log, relative to the scenario file.
    pub file: String,
    /// Bit rate the log was captured at (its gaps are kept in bit times);
    /// default: the node's own bit rate (gaps kept in seconds).
    pub bit_rate: Option<u32>,
    /// Bit time of the log's first frame (default 0).
    pub start_bit: Option<i64>,
    /// Replay only the lines of this interface (default: every line).
    pub iface: Option<String>,
}

/// One `[[fault]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFault {
    /// "stuck-dominant", "stuck-recessive", "flip", "glitch".
    pub kind: String,
    pub at_bit: Option<i64>,
    pub frame: Option<i64>,
    pub bit_in_frame: Option<i64>,
    pub duration_bits: Option<i64>,
    /// Glitch only: first time quantum of the pulse within the bit
    /// (0 = SYNC_SEG), in the DUT's quanta (2 * (BRP + 1) CAN clocks).
    pub offset_tq: Option<i64>,
    /// Glitch only: pulse length in time quanta (with `offset_tq`).
    pub width_tq: Option<i64>,
    /// "bus" (default), "dut-rx", or a node name.
    pub target: Option<String>,
    /// Glitch only: first CAN clock of the pulse, counted from the start of
    /// the bit (the bench's bit grid), instead of 1/4 into the bit.
    pub offset_clocks: Option<i64>,
    /// Glitch only: pulse length in CAN clocks (with `offset_clocks`).
    pub width_clocks: Option<i64>,
    /// Placed glitch only: the level the pulse forces ("dominant" or
    /// "recessive") instead of inverting the wire's.
    pub level: Option<String>,
    /// Placed glitch only: "sof" counts the bit and offset on the nominal
    /// grid from the frame's SOF edge (no resynchronisation), not on the
    /// bench's grid ("bench", the default).
    pub grid: Option<String>,
}

/// One `[[raw-node]]`: a bit-level sender (the lower tester) on the wire.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRawNode {
    pub name: String,
    /// Start: at this bit time of the run, ...
    pub at_bit: Option<i64>,
    /// ... or at this wire bit (from SOF = 0) of this frame (SOFs on the bus from 1), ...
    pub frame: Option<i64>,
    pub bit_in_frame: Option<i64>,
    /// ... or after this many recessive bit times in a row (11: bus idle).
    pub idle_bits: Option<i64>,
    /// The levels, one per bit time: "0" dominant, "1" recessive; spaces and `_` ignored.
    pub bits: Option<String>,
    /// Or a frame described by its fields.
    pub fields: Option<RawFields>,
    /// Levels expected on the wire from its first bit on ("0", "1", "x" any).
    pub expect_bits: Option<String>,
    /// Its first bit starts this many of the DUT's time quanta after the
    /// start point (inside that bit), ...
    pub offset_tq: Option<i64>,
    /// ... or this many CAN clocks after it.
    pub offset_clocks: Option<i64>,
}

/// `fields = { id = 0x123, data = [1], r0 = 1, ... }`: a frame with any
/// field at a non-nominal value (levels 0 = dominant, 1 = recessive).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFields {
    pub id: i64,
    #[serde(default)]
    pub extended: bool,
    #[serde(default)]
    pub rtr: bool,
    #[serde(default)]
    pub data: Vec<i64>,
    pub dlc: Option<i64>,
    pub srr: Option<i64>,
    pub r1: Option<i64>,
    pub r0: Option<i64>,
    /// CRC sent instead of the one computed over the bits as sent.
    pub crc: Option<i64>,
    /// Level driven in the ACK slot (default 1: it is the transmitter).
    pub ack: Option<i64>,
    /// Wire bits (SOF = 0, after stuffing) sent inverted.
    #[serde(default)]
    pub flip: Vec<i64>,
    /// Last wire bit sent.
    pub until_bit: Option<i64>,
    /// The node expects a dominant ACK slot (another node's ACK).
    #[serde(default)]
    pub expect_ack: bool,
}

/// `[expect]`: the expected outcome.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawExpect {
    pub category: Option<String>,
    pub field: Option<String>,
    pub first_attempt_tec: Option<u16>,
    pub tec: Option<u16>,
    pub sr: Option<i64>,
    pub attempts: Option<u32>,
    pub bus_off_attempt: Option<u32>,
    /// Frames each listed node must have received (name = count).
    #[serde(default)]
    pub received: std::collections::BTreeMap<String, u32>,
}
