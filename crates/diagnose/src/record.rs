//! [`RunRecord`]: the plain-data record of one run, filled by the
//! co-simulation (or by hand in tests) and read by the diagnoser.
//!
//! Everything is public data with `Default`, so a producer sets what it knows
//! and leaves the rest empty; the rules only use what is present.

use crate::named;
use can_engine::{ErrorKind, FaultState};
use can_proto::Field;
use serde::{Deserialize, Serialize};

/// SR bits (SJA1000 datasheet, status register; same in both modes).
pub mod sr {
    /// Bus status: bus-off.
    pub const BS: u8 = 0x80;
    /// Error status: TEC or REC at or above the error warning limit.
    pub const ES: u8 = 0x40;
    /// Transmit status: transmitting a message.
    pub const TS: u8 = 0x20;
    /// Receive status: receiving a message.
    pub const RS: u8 = 0x10;
    /// Transmission complete status.
    pub const TCS: u8 = 0x08;
    /// Transmit buffer status: 1 = released (the CPU may write it).
    pub const TBS: u8 = 0x04;
    /// Data overrun status.
    pub const DOS: u8 = 0x02;
    /// Receive buffer status.
    pub const RBS: u8 = 0x01;

    /// "BS ES TS RS TCS TBS DOS RBS" with the set bits named, e.g. `0x60 (ES TS)`.
    pub fn describe(v: u8) -> String {
        const NAMES: [&str; 8] = ["BS", "ES", "TS", "RS", "TCS", "TBS", "DOS", "RBS"];
        let set: Vec<&str> =
            NAMES.iter().enumerate().filter(|(i, _)| v & (0x80 >> i) != 0).map(|(_, n)| *n).collect();
        format!("0x{v:02X} ({})", if set.is_empty() { "none".into() } else { set.join(" ") })
    }
}

/// The field named by the segment code of an ECC value (bits 4:0, SJA1000
/// data sheet, error code capture register), or `None` for codes that name
/// no single field of ours.
pub fn field_from_ecc(ecc: u8) -> Option<Field> {
    Some(match ecc & 0x1F {
        0x03 => Field::Sof,
        0x02 | 0x06 => Field::BaseId,
        0x04 => Field::SrrRtr,
        0x05 => Field::Ide,
        0x07 | 0x0F | 0x0E => Field::ExtId,
        0x0C => Field::Rtr,
        0x0D => Field::R1,
        0x09 => Field::R0,
        0x0B => Field::Dlc,
        0x0A => Field::Data,
        0x08 => Field::Crc,
        0x18 => Field::CrcDelim,
        0x19 => Field::AckSlot,
        0x1B => Field::AckDelim,
        0x1A => Field::Eof,
        0x12 => Field::Intermission,
        0x11 => Field::ActiveErrorFlag,
        0x16 => Field::PassiveErrorFlag,
        0x17 => Field::ErrorDelimiter,
        0x1C => Field::OverloadFlag,
        _ => return None,
    })
}

/// The SJA1000 register view in use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum CanMode {
    /// BasicCAN (CDR.7 = 0, the reset default).
    #[default]
    BasicCan,
    /// PeliCAN (CDR.7 = 1).
    PeliCan,
}

/// Which host bus-functional model drove the DUT.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum HostBus {
    /// Wishbone classic cycles.
    #[default]
    Wishbone,
    /// Avalon-MM slave cycles (through a wrapper).
    Avalon,
    /// Soft CPU bit-banging the Wishbone pins through GPIO (PIO) registers.
    Pio,
    /// Intel-mode (8051) multiplexed bus: ALE, CS, RD, WR, shared port.
    I8051,
    /// AXI4-Lite: AW, W, B, AR, R channels.
    Axi4Lite,
    /// APB3/APB4: setup and access phases.
    Apb,
    /// Motorola-mode multiplexed bus: AS, CS, E, R/W, shared port.
    Motorola,
    /// A plain register port: read and write strobes, no acknowledge.
    Regport,
}

/// Bit timing and clocks of one node.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    /// CAN clock (clk_i) in Hz.
    pub can_clock_hz: f64,
    /// Host bus clock (wb_clk_i) in Hz (0 if not relevant).
    pub host_clock_hz: f64,
    /// BTR0 as written.
    pub btr0: u8,
    /// BTR1 as written.
    pub btr1: u8,
}

impl Default for Timing {
    fn default() -> Self {
        // The thesis setting (seed 000): 600 kbit/s at 24 MHz, 50 MHz host.
        Timing { can_clock_hz: 24e6, host_clock_hz: 50e6, btr0: 0x41, btr1: 0x25 }
    }
}

impl Timing {
    /// The decoded BTR0/BTR1.
    pub fn bus_timing(&self) -> can_proto::timing::BusTiming {
        can_proto::timing::BusTiming::from_btr(self.btr0, self.btr1)
    }

    /// Bit rate in bit/s.
    pub fn bit_rate(&self) -> f64 {
        self.bus_timing().bit_rate(self.can_clock_hz)
    }

    /// Sample point as a fraction of the bit.
    pub fn sample_point(&self) -> f64 {
        self.bus_timing().sample_point()
    }
}

/// What the DUT's rx_i is connected to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum RxWiring {
    /// The wired-AND bus (with the DUT's own tx on it if `tx_on_bus`).
    #[default]
    Bus,
    /// Tied to the recessive level (logic 1), as the thesis did through a PIO.
    TiedRecessive,
    /// Tied to the dominant level (logic 0).
    TiedDominant,
}

/// Another node on the bus (a golden-model node).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
pub struct BusNode {
    /// Name used in reports.
    pub name: String,
    /// Its bit timing and clock.
    pub timing: Timing,
    /// True if it acknowledges frames (not listen-only, not in reset).
    pub acknowledges: bool,
}

/// How the DUT is wired to the CAN bus.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Wiring {
    /// rx_i source.
    pub rx: RxWiring,
    /// tx_o drives the bus (so rx follows tx when `rx` is `Bus`): the
    /// transceiver loopback every real CAN transceiver provides.
    pub tx_on_bus: bool,
    /// Other nodes on the bus.
    pub nodes: Vec<BusNode>,
    /// DUT in self-test mode (PeliCAN MOD.STM): no acknowledge needed.
    pub self_test: bool,
    /// DUT in listen-only mode (PeliCAN MOD.LOM).
    pub listen_only: bool,
}

impl Default for Wiring {
    fn default() -> Self {
        Wiring { rx: RxWiring::Bus, tx_on_bus: true, nodes: Vec::new(), self_test: false, listen_only: false }
    }
}

impl Wiring {
    /// True if rx sees what tx sends.
    pub fn rx_follows_tx(&self) -> bool {
        self.rx == RxWiring::Bus && self.tx_on_bus
    }

    /// Number of other nodes that acknowledge.
    pub fn ack_nodes(&self) -> usize {
        self.nodes.iter().filter(|n| n.acknowledges).count()
    }
}

/// What the golden model did with a register write (mirrors
/// `sja1000::WriteOutcome`, kept here as plain data).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum WriteOutcome {
    /// The write took effect.
    #[default]
    Applied,
    /// Ignored: the register is writable in reset mode only (MOD.RM / CR.RR = 0).
    IgnoredNotInResetMode,
    /// Ignored: the TX buffer is locked while a transmission is pending (SR.TBS = 0).
    IgnoredTxBufferLocked,
    /// Ignored: read-only register or unmapped address.
    IgnoredReadOnly,
    /// Any other outcome the model reports, in its words.
    Other(String),
}

impl WriteOutcome {
    /// True if the write did not take effect.
    pub fn is_ignored(&self) -> bool {
        !matches!(self, WriteOutcome::Applied)
    }
}

/// Direction of a host operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Access {
    /// Register write.
    #[default]
    Write,
    /// Register read.
    Read,
}

/// One host register access.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
pub struct HostOp {
    /// Start time in picoseconds.
    pub time_ps: u64,
    /// Bus-functional model used.
    pub bfm: HostBus,
    /// Write or read.
    pub access: Access,
    /// Register address.
    pub addr: u8,
    /// Data written, or data read back.
    pub data: u8,
    /// The register at `addr` in the mode in force (from regmap), e.g. "ACR".
    pub reg: Option<String>,
    /// The register the program meant (the name the scenario used), when it
    /// differs from what the address selects in the mode in force.
    pub intended: Option<String>,
    /// Mode in force at the access.
    pub mode: CanMode,
    /// The controller was in reset mode at the access.
    pub reset_mode: bool,
    /// The golden model's verdict on a write.
    pub outcome: Option<WriteOutcome>,
    /// Host clock cycles the access took (until ack).
    pub cycles: u32,
    /// Error (timeout: no ack).
    pub error: Option<String>,
    /// Host cycles in which the DUT's ack (or Avalon's end of waitrequest)
    /// was high during the access: 0 on a failed access means the DUT never
    /// answered, more means the master missed the answer.
    #[serde(default)]
    pub acks_seen: u32,
    /// Times the DUT performed the access again because the master held
    /// the request past its ack (the reference performed it as often).
    #[serde(default)]
    pub repeats: u32,
    /// On a read: what the golden model read at the same access (the
    /// functional coverage counts register bits from the model's side).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_data: Option<u8>,
}

impl HostOp {
    /// A write of `data` at `addr`.
    pub fn write(addr: u8, data: u8) -> Self {
        HostOp { addr, data, access: Access::Write, ..Default::default() }
    }

    /// A read at `addr` returning `data`.
    pub fn read(addr: u8, data: u8) -> Self {
        HostOp { addr, data, access: Access::Read, ..Default::default() }
    }

    /// Sets the register name.
    pub fn reg(mut self, name: &str) -> Self {
        self.reg = Some(name.into());
        self
    }

    /// Sets the register the program meant.
    pub fn intended(mut self, name: &str) -> Self {
        self.intended = Some(name.into());
        self
    }

    /// Sets the model's verdict.
    pub fn outcome(mut self, o: WriteOutcome) -> Self {
        self.outcome = Some(o);
        self
    }

    /// Sets mode and reset mode.
    pub fn mode(mut self, mode: CanMode, reset_mode: bool) -> Self {
        self.mode = mode;
        self.reset_mode = reset_mode;
        self
    }

    /// Sets the time.
    pub fn at(mut self, time_ps: u64) -> Self {
        self.time_ps = time_ps;
        self
    }

    /// Sets the error.
    pub fn error(mut self, e: &str) -> Self {
        self.error = Some(e.into());
        self
    }
}

/// One bit time on the CAN bus, at the model's sample point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct BusBit {
    /// Bit index since the start of the run.
    pub bit: u64,
    /// Bus level (true = recessive).
    pub bus: bool,
    /// DUT tx_o.
    pub dut_tx: bool,
    /// Golden model tx.
    pub model_tx: bool,
    /// DUT rx_i.
    pub dut_rx: bool,
    /// Field the model is in.
    #[serde(with = "named::opt", default)]
    pub field: Option<Field>,
    /// Frame (attempt) number from the model's view, counting from 1.
    pub frame: Option<u32>,
}

/// Which side of the comparison a fact belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Side {
    /// The device under test.
    #[default]
    Dut,
    /// The golden model that shadows the DUT.
    Model,
    /// Another bus node (index into `Wiring::nodes`).
    Node(usize),
}

/// An engine event, as plain data (mirrors `can_engine::Event`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum EventKind {
    /// Bus error with its ECC value and field.
    BusError {
        /// Kind of error.
        #[serde(with = "named::one")]
        kind: ErrorKind,
        /// ECC register value.
        ecc: u8,
        /// Field of detection.
        #[serde(with = "named::one")]
        field: Field,
    },
    /// Transmission completed.
    TxComplete,
    /// Transmission dropped.
    TxAborted,
    /// Arbitration lost at ALC bit.
    ArbitrationLost {
        /// ALC bits 4:0.
        alc: u8,
    },
    /// Error warning changed.
    ErrorWarning(bool),
    /// Fault confinement state changed.
    FaultState(#[serde(with = "named::one")] FaultState),
    /// A frame was received.
    Received {
        /// Raw identifier.
        id: u32,
        /// DLC.
        dlc: u8,
        /// Own frame (self reception).
        own: bool,
    },
    /// Woken up by bus activity.
    WakeUp,
}

impl From<&can_engine::Event> for EventKind {
    fn from(e: &can_engine::Event) -> Self {
        use can_engine::Event as E;
        match e {
            E::Received { frame, own } => {
                EventKind::Received { id: frame.raw_id(), dlc: frame.dlc_raw(), own: *own }
            }
            E::TxComplete => EventKind::TxComplete,
            E::TxAborted => EventKind::TxAborted,
            E::ArbitrationLost { alc } => EventKind::ArbitrationLost { alc: *alc },
            E::BusError { kind, ecc, field } => EventKind::BusError { kind: *kind, ecc: *ecc, field: *field },
            E::ErrorWarning(b) => EventKind::ErrorWarning(*b),
            E::FaultState(s) => EventKind::FaultState(*s),
            E::WakeUp => EventKind::WakeUp,
        }
    }
}

/// An engine event with when and where it happened.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EngineEvent {
    /// Bit index.
    pub bit: u64,
    /// Node.
    pub node: Side,
    /// The event.
    pub kind: EventKind,
    /// TEC right after the event, if known.
    pub tec: Option<u16>,
    /// REC right after the event, if known.
    pub rec: Option<u16>,
}

impl EngineEvent {
    /// An event at `bit` on `node`.
    pub fn new(bit: u64, node: Side, kind: EventKind) -> Self {
        EngineEvent { bit, node, kind, tec: None, rec: None }
    }

    /// Sets TEC.
    pub fn tec(mut self, tec: u16) -> Self {
        self.tec = Some(tec);
        self
    }
}

/// What kind of mismatch the comparator saw first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum DivergenceKind {
    /// tx_o differs from the model's tx at the sample point.
    #[default]
    TxBit,
    /// A register read returned a different value.
    RegisterRead,
    /// irq_on differs.
    Irq,
    /// bus_off_on differs.
    BusOff,
    /// clkout_o's period or enable differs from the reference's CDR setting.
    Clkout,
}

/// The comparator's first divergence between DUT and golden model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
pub struct Divergence {
    /// Kind.
    pub kind: DivergenceKind,
    /// Time in picoseconds.
    pub time_ps: u64,
    /// Bit index (CAN bit times since start).
    pub bit: Option<u64>,
    /// Frame number from the model's view.
    pub frame: Option<u32>,
    /// Field the model was in.
    #[serde(with = "named::opt", default)]
    pub field: Option<Field>,
    /// Register (for `RegisterRead`), e.g. "SR".
    pub register: Option<String>,
    /// Expected value (model): a level (0/1) or a register value.
    pub expected: u32,
    /// Value seen on the DUT.
    pub seen: u32,
    /// Free text context from the comparator (bits around, waveform hint).
    pub context: String,
}

/// A host-bus protocol monitor violation.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct Violation {
    /// Host clock cycle.
    pub cycle: u64,
    /// Rule identifier, e.g. "wb.stb_without_cyc" or "avalon.cyc_from_begintransfer".
    pub rule: String,
    /// Monitor's message.
    pub message: String,
}

/// A transmission that was requested and never completed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct StuckTransfer {
    /// Time of the transmission request (CMR.TR) in picoseconds.
    pub requested_ps: u64,
    /// Bit index of the request.
    pub requested_bit: u64,
    /// How long the runner waited, in bit times.
    pub waited_bits: u64,
    /// SR at the end of the wait.
    pub sr: u8,
    /// Transmission attempts seen (SOFs sent by the DUT).
    pub attempts: u32,
}

impl StuckTransfer {
    /// SR.TS.
    pub fn ts(&self) -> bool {
        self.sr & sr::TS != 0
    }

    /// SR.TBS.
    pub fn tbs(&self) -> bool {
        self.sr & sr::TBS != 0
    }
}

/// A scenario expectation and whether it held.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct Expectation {
    /// Step number in the scenario (1-based).
    pub step: usize,
    /// What was checked, e.g. "SR & 0x0C == 0x0C".
    pub what: String,
    /// Expected value, as text.
    pub expected: String,
    /// Seen value, as text.
    pub seen: String,
    /// Held.
    pub passed: bool,
}

/// Status registers of one node at the end of the run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct FinalRegs {
    /// Status register.
    pub sr: u8,
    /// Interrupt register.
    pub ir: u8,
    /// Transmit error counter (values above 255 mean bus-off was reached).
    pub tec: u16,
    /// Receive error counter.
    pub rec: u16,
    /// Error code capture (PeliCAN).
    pub ecc: Option<u8>,
    /// Arbitration lost capture (PeliCAN).
    pub alc: Option<u8>,
    /// `tec`/`rec` are the model's, not read from this node (BasicCAN has
    /// no counter registers): a diagnosis marks them, and drops them after
    /// a divergence, when the model's counts say nothing about the DUT.
    #[serde(default)]
    pub counters_from_model: bool,
}

/// TEC at the end of one transmission attempt.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct TecStep {
    /// Node.
    pub node: Side,
    /// Attempt number, from 1.
    pub attempt: u32,
    /// Bit index at the end of the attempt.
    pub bit: u64,
    /// TEC after the attempt (above 255: bus-off).
    pub tec: u16,
    /// The node went bus-off during this attempt.
    pub bus_off: bool,
}

/// The record of one run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(default)]
pub struct RunRecord {
    /// Scenario name.
    pub scenario: String,
    /// DUT name (e.g. "rtl", "model", an external path).
    pub dut: String,
    /// The DUT's timing and clocks.
    pub timing: Timing,
    /// Register view at the end of configuration.
    pub mode: CanMode,
    /// Host BFM.
    pub host_bus: HostBus,
    /// CAN wiring.
    pub wiring: Wiring,
    /// Host register accesses in order.
    pub host_ops: Vec<HostOp>,
    /// The last bus bits (a ring: the producer keeps the last N).
    pub bus_bits: Vec<BusBit>,
    /// Engine events.
    pub events: Vec<EngineEvent>,
    /// First divergence DUT vs model.
    pub divergence: Option<Divergence>,
    /// Host-bus monitor violations.
    pub violations: Vec<Violation>,
    /// A transmission that never completed.
    pub stuck: Option<StuckTransfer>,
    /// Scenario expectations.
    pub expectations: Vec<Expectation>,
    /// DUT status at the end.
    pub final_dut: Option<FinalRegs>,
    /// Model status at the end.
    pub final_model: Option<FinalRegs>,
    /// TEC per attempt for DUT and model.
    pub tec_trace: Vec<TecStep>,
    /// A run error that stopped the run (timeout, DUT build failure...).
    pub error: Option<String>,
    /// Bit times simulated.
    pub bits_simulated: u64,
    /// Known deviations a waiver let through in this run, in plain words.
    pub waived: Vec<WaivedDeviation>,
}

/// A known deviation of the DUT that a waiver let through in a run: which
/// waiver, the deviation in plain words, the clause it breaks, how often.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(default)]
pub struct WaivedDeviation {
    /// Waiver id.
    pub waiver_id: String,
    /// The deviation in plain words (the first sentence of the waiver's explanation).
    pub summary: String,
    /// The datasheet or CAN 2.0B clause it breaks, if the waiver names it.
    pub clause: Option<String>,
    /// Divergences the waiver covered.
    pub hits: u32,
    /// Episodes of a waiver bounded by a host event (`until-read`): the
    /// differences its hits belong to; 0 for other waivers.
    #[serde(skip_serializing_if = "is_zero")]
    pub episodes: u32,
    /// That bound in words, printed with the hits (also a condition such
    /// as `after = "data-overrun"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bound: Option<String>,
    /// The profile the waiver matched the DUT through, when it names an
    /// ancestor of the DUT's profile (`extends`) and not the DUT itself.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub via: Option<String>,
}

fn is_zero(n: &u32) -> bool {
    *n == 0
}

impl WaivedDeviation {
    /// `; N episode(s), each ...` for a waiver with a host-event bound, `; only after ...` for a
    /// condition only, else empty.
    pub fn bound_text(&self) -> String {
        match &self.bound {
            Some(b) if self.episodes > 0 => format!("; {} episode(s), {b}", self.episodes),
            Some(b) => format!("; {b}"),
            None => String::new(),
        }
    }

    /// `summary (id, clause)`, and `; applied via family member P` for a
    /// waiver that matched through an ancestor profile.
    pub fn describe(&self) -> String {
        let via = self.via.as_ref().map(|p| format!("; applied via family member {p}")).unwrap_or_default();
        match &self.clause {
            Some(c) => format!("{} ({}, {c}{via})", self.summary, self.waiver_id),
            None => format!("{} ({}{via})", self.summary, self.waiver_id),
        }
    }
}

impl RunRecord {
    /// An empty record for `scenario` on `dut`.
    pub fn new(scenario: &str, dut: &str) -> Self {
        RunRecord { scenario: scenario.into(), dut: dut.into(), ..Default::default() }
    }

    /// Sets timing.
    pub fn with_timing(mut self, t: Timing) -> Self {
        self.timing = t;
        self
    }

    /// Sets wiring.
    pub fn with_wiring(mut self, w: Wiring) -> Self {
        self.wiring = w;
        self
    }

    /// Sets the mode.
    pub fn with_mode(mut self, m: CanMode) -> Self {
        self.mode = m;
        self
    }

    /// Appends a host op.
    pub fn op(mut self, op: HostOp) -> Self {
        self.host_ops.push(op);
        self
    }

    /// Appends an event.
    pub fn event(mut self, e: EngineEvent) -> Self {
        self.events.push(e);
        self
    }

    /// Keeps a bus bit, dropping the oldest beyond `keep`.
    pub fn push_bit(&mut self, b: BusBit, keep: usize) {
        if keep > 0 && self.bus_bits.len() >= keep {
            let excess = self.bus_bits.len() + 1 - keep;
            self.bus_bits.drain(..excess);
        }
        self.bus_bits.push(b);
    }

    /// TEC trace of one side, in attempt order.
    pub fn tec_of(&self, side: Side) -> Vec<TecStep> {
        let mut v: Vec<TecStep> = self.tec_trace.iter().copied().filter(|t| t.node == side).collect();
        v.sort_by_key(|t| t.attempt);
        v
    }

    /// Events of one side.
    pub fn events_of(&self, side: Side) -> impl Iterator<Item = &EngineEvent> {
        self.events.iter().filter(move |e| e.node == side)
    }

    /// The first bus error of `side`, with the field of detection (from the
    /// ECC segment code when it names one, else the recorded field).
    pub fn first_bus_error(&self, side: Side) -> Option<(&EngineEvent, ErrorKind, Field)> {
        self.events_of(side).find_map(|e| match e.kind {
            EventKind::BusError { kind, field, ecc } => Some((e, kind, field_from_ecc(ecc).unwrap_or(field))),
            _ => None,
        })
    }

    /// Serialises to pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a RunRecord always serialises")
    }

    /// Reads a record from JSON.
    pub fn from_json(s: &str) -> Result<Self, serde_json::Error> {
        serde_json::from_str(s)
    }
}
