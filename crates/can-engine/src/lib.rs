//! CAN 2.0B protocol engine, as the SJA1000 splits it from its host
//! interface: the bit timing logic (BTL), the bit stream processor (BSP) and
//! fault confinement. It knows nothing of registers: the `sja1000` crate
//! drives it through this API and maps its [`Event`]s onto SR/IR/ECC/ALC and
//! the RX FIFO.
//!
//! Time: [`Engine::clock`] is one period of the CAN clock `clk_i`; all work
//! happens on time-quantum boundaries (tq = 2 * (BRP + 1) clocks).
//! [`Engine::bit`] is the fast path used when every node on a bus shares one
//! clock and timing, so no resynchronisation can ever occur: one call per
//! bit time, at the sample point.
#![warn(missing_docs)]

use can_proto::{CanFrame, Field};

pub use can_proto::timing::BusTiming;

/// Fault confinement state (CAN 2.0B §8).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FaultState {
    /// TEC and REC below 128: sends active error flags.
    ErrorActive,
    /// TEC or REC at least 128: sends passive error flags, suspends transmission.
    ErrorPassive,
    /// TEC above 255: off the bus until recovery.
    BusOff,
}

/// The five CAN error kinds (CAN 2.0B §7.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// Monitored level differs from the sent one.
    Bit,
    /// Six equal bits in a stuffed field.
    Stuff,
    /// Received CRC differs from the computed one.
    Crc,
    /// A fixed-form bit has the wrong level.
    Form,
    /// No dominant bit in the ACK slot (transmitter).
    Ack,
}

/// What the engine reports to the controller; drained with [`Engine::take_events`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Event {
    /// A frame was received valid (last-but-one EOF bit, CAN 2.0B §5).
    /// `own` is true when the node received its own transmission
    /// (self-reception request or self-test).
    Received {
        /// The frame.
        frame: CanFrame,
        /// Received back from our own transmission.
        own: bool,
    },
    /// The pending transmission completed successfully.
    TxComplete,
    /// The pending transmission was dropped (single shot after error or
    /// arbitration loss, abort, bus-off).
    TxAborted,
    /// Arbitration lost; `alc` is the SJA1000 ALC bit number (0 = ID.28 ...).
    ArbitrationLost {
        /// ALC register value bits 4:0.
        alc: u8,
    },
    /// A bus error was detected; `ecc` is the SJA1000 ECC register value
    /// (bits 7:6 error code, bit 5 direction: 1 = RX, bits 4:0 segment).
    BusError {
        /// Kind of error.
        kind: ErrorKind,
        /// ECC register value.
        ecc: u8,
        /// Field in which the error was detected.
        field: Field,
    },
    /// The error warning status (TEC or REC >= EWL) changed.
    ErrorWarning(bool),
    /// The fault confinement state changed.
    FaultState(FaultState),
    /// A dominant bit was seen while sleeping (wake-up).
    WakeUp,
}

/// Operating options the controller sets (from MOD and CMR).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// Listen only: never send a dominant bit (no ACK, no error flags).
    pub listen_only: bool,
    /// Self test: a transmission succeeds without acknowledgement.
    pub self_test: bool,
    /// Error warning limit (EWLR, default 96).
    pub ewl: u8,
}

impl Default for Options {
    fn default() -> Self {
        Options { listen_only: false, self_test: false, ewl: 96 }
    }
}

/// One CAN node's protocol engine (BTL + BSP + fault confinement).
///
/// The API below is the contract with the `sja1000` crate; bodies marked
/// `todo!` are being filled in.
#[derive(Clone, Debug)]
pub struct Engine {
    timing: BusTiming,
    options: Options,
    events: Vec<Event>,
    reset_mode: bool,
    sleep: bool,
    pending: Option<TxRequest>,
    tec: u8,
    rec: u8,
    state: FaultState,
    warning: bool,
    field: Field,
}

/// A transmission request as the controller gave it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct TxRequest {
    frame: CanFrame,
    single_shot: bool,
    self_rx: bool,
}

impl Engine {
    /// A node in the bus-idle state waiting for 11 recessive bits (bus integration).
    pub fn new(timing: BusTiming, options: Options) -> Self {
        Engine {
            timing,
            options,
            events: Vec::with_capacity(8),
            reset_mode: false,
            sleep: false,
            pending: None,
            tec: 0,
            rec: 0,
            state: FaultState::ErrorActive,
            warning: false,
            field: Field::BusIdle,
        }
    }

    /// Changes the bit timing (the controller allows it in reset mode only).
    pub fn set_timing(&mut self, timing: BusTiming) {
        self.timing = timing;
    }

    /// The bit timing in use.
    pub fn timing(&self) -> BusTiming {
        self.timing
    }

    /// Changes listen-only / self-test / EWL.
    pub fn set_options(&mut self, options: Options) {
        self.options = options;
    }

    /// The options in use.
    pub fn options(&self) -> Options {
        self.options
    }

    /// Enters (true) or leaves (false) the controller's reset mode. In reset
    /// mode the engine sends recessive and takes part in no frame; leaving it
    /// while bus-off starts the recovery count (128 x 11 recessive bits).
    pub fn set_reset_mode(&mut self, on: bool) {
        self.reset_mode = on;
    }

    /// Sleep mode: stop until a dominant bit wakes the node ([`Event::WakeUp`]).
    pub fn set_sleep(&mut self, on: bool) {
        self.sleep = on;
    }

    /// One CAN clock period (clk_i) with the bus level `rx`; returns `tx`.
    pub fn clock(&mut self, _rx: bool) -> bool {
        can_proto::RECESSIVE
    }

    /// Level this node drives for the current bit (fast path and BTL).
    pub fn tx(&self) -> bool {
        can_proto::RECESSIVE
    }

    /// Fast path: process one whole bit whose sampled bus level is `rx`.
    /// Valid only when all nodes share one clock and timing (no resync).
    pub fn sample_bit(&mut self, _rx: bool) {
    }

    /// Requests transmission of `frame` (CMR.TR / CMR.SRR). `single_shot`:
    /// no retransmission after an error or lost arbitration (TR + AT).
    /// `self_rx`: also receive the frame ourselves (self-reception request).
    pub fn request_tx(&mut self, frame: CanFrame, single_shot: bool, self_rx: bool) {
        self.pending = Some(TxRequest { frame, single_shot, self_rx });
    }

    /// CMR.AT: drop the pending request if its transmission has not started.
    pub fn abort_tx(&mut self) {
        if self.pending.take().is_some() {
            self.events.push(Event::TxAborted);
        }
    }

    /// True while a transmission request is pending or under way.
    pub fn tx_pending(&self) -> bool {
        self.pending.is_some()
    }

    /// Drains the events produced since the last call.
    pub fn take_events(&mut self) -> std::vec::Drain<'_, Event> {
        self.events.drain(..)
    }

    /// True if events are waiting (cheap check for the fast path).
    pub fn has_events(&self) -> bool {
        !self.events.is_empty()
    }

    /// Transmit error counter (0..=255; bus-off is reported by [`Engine::fault_state`]).
    pub fn tec(&self) -> u8 {
        self.tec
    }

    /// Receive error counter.
    pub fn rec(&self) -> u8 {
        self.rec
    }

    /// Writes TEC (the controller allows it in reset mode only); may change the fault state.
    pub fn set_tec(&mut self, v: u8) {
        self.tec = v;
    }

    /// Writes REC (reset mode only).
    pub fn set_rec(&mut self, v: u8) {
        self.rec = v;
    }

    /// Fault confinement state.
    pub fn fault_state(&self) -> FaultState {
        self.state
    }

    /// Error status: TEC or REC at or above the warning limit.
    pub fn error_warning(&self) -> bool {
        self.warning
    }

    /// SR.RS: a frame is being received.
    pub fn is_receiving(&self) -> bool {
        false
    }

    /// SR.TS: a frame is being transmitted.
    pub fn is_transmitting(&self) -> bool {
        false
    }

    /// The field the engine is in, for diagnostics and waveforms.
    pub fn field(&self) -> Field {
        self.field
    }
}
