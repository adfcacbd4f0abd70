//! CAN 2.0B protocol engine, as the SJA1000 splits it from its host
//! interface: the bit timing logic (BTL), the bit stream processor (BSP) and
//! fault confinement. It knows nothing of registers: the `sja1000` crate
//! drives it through this API and maps its [`Event`]s onto SR/IR/ECC/ALC and
//! the RX FIFO.
//!
//! Time: [`Engine::clock`] is one period of the CAN clock `clk_i`; all work
//! happens on time-quantum boundaries (tq = 2 * (BRP + 1) clocks).
//! [`Engine::sample_bit`] is the fast path used when every node on a bus
//! shares one clock and timing, so no resynchronisation can ever occur: one
//! call per bit time, at the sample point. Both paths run the same bit
//! stream processor, so they produce the same bits and events.
//!
//! Modules: `btl` bit timing, `bsp` frame state machine,
//! `fault` confinement rules (CAN 2.0B §8), `ecc` ECC/ALC encodings.
//!
//! Readings of the sources where they leave a choice:
//! - rule 9 of §8 is applied with its second sentence ("an error condition
//!   letting a node become error passive causes the node to send an active
//!   error flag"): the flag type is decided by the state before the
//!   error's own increment. A lone transmitter with RX stuck recessive thus
//!   ends its first attempt at TEC 136 and goes bus-off at the 16th;
//! - rule 8 sets a REC above 127 back to 127 (the rule allows 119..=127);
//! - a CRC error is detected at the ACK delimiter: ECC segment 11011;
//! - transmitters report a dominant bit in a recessive fixed-form field
//!   (delimiters, EOF) as a form error, not a bit error;
//! - triple sampling votes over the last three quanta of TSEG1 (the
//!   datasheet only says "sampled three times");
//! - own frames (self reception) are reported when the transmission
//!   succeeds (end of EOF); other frames at the last-but-one EOF bit;
//! - error status (SR.ES) stays set while bus-off.
#![warn(missing_docs)]
// The workspace MSRV (1.85) has neither let chains nor `is_multiple_of`.
#![allow(clippy::collapsible_if, clippy::manual_is_multiple_of)]

mod bsp;
mod btl;
mod ecc;
mod fault;
#[cfg(test)]
mod tests;

use bsp::{Bsp, TxRequest};
use btl::{Btl, Tq};
use can_proto::{CanFrame, Field, RECESSIVE};

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
    /// `own` is true when the node received its own transmission: only with
    /// a self-reception request (CMR.SRR, `self_rx`), in normal or self-test
    /// mode; it is reported at the end of EOF, just before
    /// [`Event::TxComplete`]. Listen-only nodes receive too.
    Received {
        /// The frame.
        frame: CanFrame,
        /// Received back from our own transmission.
        own: bool,
    },
    /// The pending transmission completed successfully (end of EOF).
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
    /// Reported at the bit where it is detected, before the counter change
    /// it causes; a CRC error is detected (and flagged) at the ACK
    /// delimiter, so its segment is 11011. Counter changes without an error
    /// (rules 2 and 6, dominant bits after a flag) raise no `BusError`.
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
    /// The fault confinement state changed. At bus-off the engine has also
    /// set TEC to 127, REC to 0, entered reset mode and dropped the request
    /// ([`Event::TxAborted`] follows).
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
        Options {
            listen_only: false,
            self_test: false,
            ewl: 96,
        }
    }
}

/// Where the bit timing's phase (prescaler and bit position) starts from:
/// an implementation freedom, as neither the SJA1000 datasheet nor CAN
/// 2.0B fix it (in bus idle nothing synchronises two nodes' bit timers).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PhaseOrigin {
    /// The bit timing stands still in reset mode and starts from zero when
    /// reset mode is left (our RTL, rtl/can_btl.v).
    #[default]
    ResetModeExit,
    /// The bit timing runs from the hardware reset on, through reset mode;
    /// a BTR0/BTR1 write changes the lengths from the next quantum or bit
    /// on, without restarting the count (the opencores core).
    HardwareReset,
}

/// One CAN node's protocol engine (BTL + BSP + fault confinement).
///
/// The API below is the contract with the `sja1000` crate.
#[derive(Clone, Debug)]
pub struct Engine {
    timing: BusTiming,
    btl: Btl,
    bsp: Bsp,
    /// Level driven on the bus now.
    tx_out: bool,
    /// Bits sampled since creation (both paths).
    bits: u64,
    /// Wake-ups by the bus seen outside a sample point (the bit timing
    /// stopped in sleep).
    wakes: u64,
    /// Where the bit timing's phase starts from.
    origin: PhaseOrigin,
    /// CAN clocks after a quantum's end in which a bit-timing change still
    /// decides that quantum (hardware-reset origin only; 0: none).
    segment_lag: u32,
}

impl Engine {
    /// A node in the bus-idle state waiting for 11 recessive bits (bus integration).
    pub fn new(timing: BusTiming, options: Options) -> Self {
        Engine {
            timing,
            btl: Btl::new(timing),
            bsp: Bsp::new(options),
            tx_out: RECESSIVE,
            bits: 0,
            wakes: 0,
            origin: PhaseOrigin::ResetModeExit,
            segment_lag: 0,
        }
    }

    /// Sets the DUT's declared segment lag (profile `segment-lag`): a
    /// bit-timing change in reset mode that lands less than `lag` CAN
    /// clocks after a quantum's end redoes that quantum with the new
    /// lengths, as a core whose segment logic acts `lag` clocks after its
    /// prescaler's quantum does; a transmission request in bus idle that
    /// lands that soon after a sample point is taken at it
    /// ([`Engine::request_tx`]). Kept across [`Engine::hard_reset`].
    pub fn set_segment_lag(&mut self, lag: u32) {
        self.segment_lag = lag;
        self.btl.set_redo_lag(lag);
    }

    /// The declared segment lag ([`Engine::set_segment_lag`]).
    pub fn segment_lag(&self) -> u32 {
        self.segment_lag
    }

    /// Sets where the bit timing's phase starts from (kept across
    /// [`Engine::hard_reset`]); takes effect at the next reset-mode exit
    /// or timing change.
    pub fn set_phase_origin(&mut self, origin: PhaseOrigin) {
        self.origin = origin;
        if origin == PhaseOrigin::HardwareReset {
            // Set at the hardware reset (before the first clock): a bit
            // timing running from the reset starts in TSEG1.
            self.btl.start_in_tseg1();
        }
    }

    /// Where the bit timing's phase starts from.
    pub fn phase_origin(&self) -> PhaseOrigin {
        self.origin
    }

    /// Back to the power-on state (hardware reset): counters 0, error
    /// active, no request, bus integration pending. Options and timing kept.
    pub fn hard_reset(&mut self) {
        let opt = self.bsp.opt;
        self.bsp = Bsp::new(opt);
        self.btl = Btl::new(self.timing);
        self.btl.set_redo_lag(self.segment_lag);
        self.tx_out = RECESSIVE;
    }

    /// Changes the bit timing (the controller allows it in reset mode only).
    pub fn set_timing(&mut self, timing: BusTiming) {
        self.timing = timing;
        match self.origin {
            PhaseOrigin::ResetModeExit => self.btl.set_timing(timing),
            PhaseOrigin::HardwareReset => self.btl.retime(timing, self.bsp.reset_mode),
        }
    }

    /// The bit timing in use.
    pub fn timing(&self) -> BusTiming {
        self.timing
    }

    /// Changes listen-only / self-test / EWL.
    pub fn set_options(&mut self, options: Options) {
        self.bsp.opt = options;
        self.bsp.fc.set_ewl(options.ewl, options.listen_only);
        if !self.bsp.reset_mode {
            self.bsp.fc.update(&mut self.bsp.ev);
        }
    }

    /// The options in use.
    pub fn options(&self) -> Options {
        self.bsp.opt
    }

    /// Enters (true) or leaves (false) the controller's reset mode. In reset
    /// mode the engine sends recessive and takes part in no frame, and a
    /// pending request is dropped (the controller releases its buffer).
    /// Leaving it starts bus integration (11 recessive bits), or while
    /// bus-off the recovery count (128 x 11 recessive bits).
    pub fn set_reset_mode(&mut self, on: bool) {
        let leaving = !on && self.bsp.reset_mode;
        self.bsp.set_reset_mode(on);
        if on {
            self.tx_out = RECESSIVE;
        }
        if leaving && self.origin == PhaseOrigin::ResetModeExit {
            // The bit timing logic stands still in reset mode: its
            // prescaler starts from zero when the mode is left, so the time
            // quanta line up with that instant (as in rtl/can_btl.v).
            self.btl.restart_idle();
        }
    }

    /// True in reset mode. The engine enters it by itself at bus-off, as the
    /// SJA1000 sets MOD.RM then.
    pub fn in_reset_mode(&self) -> bool {
        self.bsp.reset_mode
    }

    /// Sleep mode: stop until a dominant bit wakes the node ([`Event::WakeUp`]);
    /// after a wake-up the node waits for 11 recessive bits before taking part.
    pub fn set_sleep(&mut self, on: bool) {
        let was = self.is_sleeping();
        self.bsp.set_sleep(on);
        if on {
            self.tx_out = RECESSIVE;
        }
        if was && !self.is_sleeping() {
            self.restart_after_sleep();
        }
    }

    /// With the reset-mode-exit origin the bit timing stands still while
    /// the node does not run, asleep as in reset mode (the SJA1000 stops its
    /// oscillator in sleep mode, datasheet MOD.SM): its prescaler starts
    /// from zero at the wake-up, as in rtl/can_btl.v.
    fn restart_after_sleep(&mut self) {
        if self.origin == PhaseOrigin::ResetModeExit {
            self.btl.restart_idle();
        }
    }

    /// Leaves sleep as if it had never been entered (back to the phase it
    /// left, e.g. bus idle, without the wake-up's bus integration): the
    /// lockstep reference's resync for a DUT that has no sleep mode.
    pub fn cancel_sleep(&mut self) {
        self.bsp.cancel_sleep();
    }

    /// True while sleeping.
    pub fn is_sleeping(&self) -> bool {
        self.bsp.phase == bsp::Phase::Sleep
    }

    /// One CAN clock period (clk_i) with the bus level `rx`; returns `tx`.
    /// Work happens only at time-quantum boundaries.
    #[inline]
    pub fn clock(&mut self, rx: bool) -> bool {
        if self.halted() {
            // The bit timing stands still; a dominant level wakes the node
            // at once and the prescaler starts from zero.
            if !rx {
                self.bsp.wake_by_bus();
                self.restart_after_sleep();
                self.wakes += 1;
            }
            return self.tx_out;
        }
        if !self.btl.clock() {
            return self.tx_out;
        }
        self.tq(rx)
    }

    /// CAN clocks until the next time-quantum boundary (at least 1): the
    /// next `n - 1` calls of [`Engine::clock`] only count and return the
    /// same level.
    pub fn clocks_to_next_tq(&self) -> u32 {
        // Asleep with the bit timing stopped, every clock may wake the node.
        if self.halted() { 1 } else { self.btl.clocks_to_next_tq() }
    }

    /// CAN clocks from now in which, with the bus staying at `rx`, nothing
    /// but counting happens: the next that many calls of [`Engine::clock`]
    /// with `rx` return the same level and move neither
    /// [`Engine::activity`] nor the events. Beyond
    /// [`Engine::clocks_to_next_tq`]: the quanta that end with no edge and
    /// no sample point count too, a bit start among them if it drives the
    /// level already driven (and in reset mode, where the bit stream
    /// processor takes no part, every quantum once tx is recessive).
    pub fn quiet_clocks(&self, rx: bool) -> u32 {
        if self.halted() {
            return 0;
        }
        let in_tq = self.btl.clocks_to_next_tq() - 1;
        if self.bsp.reset_mode {
            return if self.tx_out == RECESSIVE { u32::MAX } else { in_tq };
        }
        // A bit start that drives the level already driven changes nothing.
        let same_tx = self.bsp.tx == self.tx_out;
        in_tq + self.btl.quiet_tqs(rx, same_tx) * self.btl.clocks_per_tq()
    }

    /// `n` of the [`Engine::quiet_clocks`] of `rx`: what `n` calls of
    /// [`Engine::clock`] with `rx` do, the clocks within a quantum counted
    /// at once.
    pub fn quiet_run(&mut self, n: u32, rx: bool) {
        debug_assert!(n <= self.quiet_clocks(rx));
        let mut left = n;
        while left > 0 {
            let to_tq = self.btl.clocks_to_next_tq();
            if left < to_tq {
                self.btl.count(left);
                return;
            }
            self.btl.count(to_tq - 1);
            left -= to_tq;
            // The quantum's end, a quiet one.
            let _ = self.clock(rx);
        }
    }

    /// Asleep with the reset-mode-exit origin: the bit timing stands still
    /// and each clock's rx level is looked at (a dominant one wakes the node).
    #[inline]
    fn halted(&self) -> bool {
        self.origin == PhaseOrigin::ResetModeExit && self.bsp.phase == bsp::Phase::Sleep
    }

    /// Sample points plus wake-ups by the bus since creation: when it moves,
    /// the bit stream processor did something a caller may want to look at
    /// (status, events); between two moves a clock only counts or moves tx.
    pub fn activity(&self) -> u64 {
        self.bits + self.wakes
    }

    fn tq(&mut self, rx: bool) -> bool {
        if self.bsp.reset_mode {
            if self.origin == PhaseOrigin::HardwareReset {
                // The bit timing keeps running (and resynchronising on
                // edges); the bit stream processor takes no part.
                let _ = self.btl.tq(rx, false, false);
            }
            self.tx_out = RECESSIVE;
            return RECESSIVE;
        }
        // Until our own SOF is on the wire the bus is idle for us: another
        // node's SOF edge hard-synchronises (CAN 2.0B §9.2.4 rule 3) and
        // starts our SOF with it. Once we drive it, its edge was the bit's
        // one synchronisation (rule 1).
        let hard = self.bsp.hard_sync_allowed() || (self.tx_out == RECESSIVE && self.bsp.sof_pending());
        match self.btl.tq(rx, hard, !self.tx_out) {
            Tq::Quiet => {}
            Tq::Sample(v) => {
                self.bits += 1;
                self.bsp.bit(v)
            }
            Tq::BitStart => self.tx_out = self.bsp.tx,
        }
        self.tx_out
    }

    /// Resync for a DUT that waits for one more bus-free sequence (11
    /// recessive bits) after bus-on before it starts a frame: if this node
    /// came out of bus-off at most `max_since` bits ago and has been idle
    /// since, it integrates again as if the sequence had begun at its
    /// bus-on (SR shows TS = RS = 1, waiting), and a transmission then
    /// pending is held for at most `slack` more bits, for the DUT's start
    /// of frame ([`Engine::start_held_tx_now`]). False if it does not
    /// apply (no recent bus-on, a frame already started).
    pub fn wait_bus_free_after_bus_on(&mut self, max_since: u8, slack: u8) -> bool {
        self.bsp.wait_bus_free_after_bus_on(max_since, slack)
    }

    /// A transmission held by [`Engine::wait_bus_free_after_bus_on`] waits
    /// for another node's start of frame.
    pub fn tx_held(&self) -> bool {
        self.bsp.tx_held()
    }

    /// Starts the held transmission at this clock: the start of frame is
    /// driven now and the bit timing starts a bit here (as a hard
    /// synchronisation on the DUT's own SOF edge would). False (nothing
    /// changed) if no transmission is held.
    pub fn start_held_tx_now(&mut self) -> bool {
        if !self.bsp.start_held_tx() {
            return false;
        }
        self.btl.restart();
        self.tx_out = self.bsp.tx;
        true
    }

    /// Level this node drives for the current bit (fast path and BTL).
    #[inline]
    pub fn tx(&self) -> bool {
        self.tx_out
    }

    /// Fast path: process one whole bit whose sampled bus level is `rx`.
    /// Valid only when all nodes share one clock and timing (no resync).
    #[inline]
    pub fn sample_bit(&mut self, rx: bool) {
        if self.bsp.reset_mode {
            return;
        }
        self.bits += 1;
        self.bsp.bit(rx);
        self.tx_out = self.bsp.tx;
    }

    /// Number of bits sampled so far outside reset mode (both paths); lets
    /// a harness find the sample points of the clocked path.
    pub fn bits_sampled(&self) -> u64 {
        self.bits
    }

    /// Requests transmission of `frame` (CMR.TR / CMR.SRR). `single_shot`:
    /// no retransmission after an error or lost arbitration (TR + AT).
    /// `self_rx`: also receive the frame ourselves (self-reception request).
    /// The transmission starts at the next bus-idle bit; a request made
    /// while another one is under way replaces it for later attempts only
    /// (the controller never does this: TBS is 0 then).
    ///
    /// With a segment lag ([`Engine::set_segment_lag`]) a request made in
    /// bus idle less than that many CAN clocks after a sample point counts
    /// as pending at that sample point: the core's sample point, as its
    /// segments, comes that late, so it still sees the request there.
    pub fn request_tx(&mut self, frame: CanFrame, single_shot: bool, self_rx: bool) {
        self.bsp
            .request(TxRequest::new(frame, single_shot, self_rx));
        if self.btl.within_lag_of_sample_point() && !self.bsp.reset_mode {
            self.bsp.start_idle_request();
        }
    }

    /// CMR.AT: drop the pending request if its transmission has not started
    /// ([`Event::TxAborted`] now); if it is under way it completes or, after
    /// an error or lost arbitration, is dropped instead of retransmitted.
    pub fn abort_tx(&mut self) {
        self.bsp.abort();
    }

    /// True while a transmission request is pending or under way.
    pub fn tx_pending(&self) -> bool {
        self.bsp.pending.is_some()
    }

    /// The frame pending or under way.
    pub fn pending_frame(&self) -> Option<CanFrame> {
        self.bsp.pending.as_ref().map(|r| r.frame)
    }

    /// Drains the events produced since the last call.
    pub fn take_events(&mut self) -> std::vec::Drain<'_, Event> {
        self.bsp.ev.drain(..)
    }

    /// True if events are waiting (cheap check for the fast path).
    #[inline]
    pub fn has_events(&self) -> bool {
        !self.bsp.ev.is_empty()
    }

    /// Transmit error counter (0..=255; bus-off is reported by [`Engine::fault_state`]).
    /// During bus-off recovery it counts 127 down to 0 (SJA1000 TXERR).
    pub fn tec(&self) -> u8 {
        self.bsp.fc.tec()
    }

    /// Receive error counter.
    pub fn rec(&self) -> u8 {
        self.bsp.fc.rec()
    }

    /// Writes TEC (the controller allows it in reset mode only); may change
    /// the fault state: 255 forces bus-off, any other value while bus-off
    /// clears it (datasheet TXERR). Warning/passive changes show when reset
    /// mode is left; so does the bus-off forced by 255 in reset mode (TEC
    /// reads 255 until then, and leaving reset mode enters it again, with
    /// TEC 127 and REC 0, as a bus-off by errors).
    pub fn set_tec(&mut self, v: u8) {
        self.bsp.write_counters(Some(v), None);
    }

    /// Writes REC (reset mode only; ignored while bus-off).
    pub fn set_rec(&mut self, v: u8) {
        self.bsp.write_counters(None, Some(v));
    }

    /// Fault confinement state.
    pub fn fault_state(&self) -> FaultState {
        self.bsp.fc.state()
    }

    /// Error status: TEC or REC at or above the warning limit (held while bus-off).
    pub fn error_warning(&self) -> bool {
        self.bsp.fc.warning()
    }

    /// SR.RS: a frame is being received (from SOF to the end of the
    /// intermission that follows it, error and overload signalling included).
    pub fn is_receiving(&self) -> bool {
        // The datasheet reads RS = TS = 0 as "bus idle", and the bus is not
        // idle before the intermission ends: a receiver keeps RS through it.
        !self.bsp.role_tx && (self.bsp.busy() || self.bsp.phase == bsp::Phase::Intermission)
    }

    /// SR.TS: a frame is being transmitted (from SOF until the bus is idle,
    /// so it stays set between automatic retransmissions).
    pub fn is_transmitting(&self) -> bool {
        self.bsp.role_tx
    }

    /// In suspend transmission (an error-passive transmitter's 8 bits
    /// after intermission; still a transmitter, [`Engine::is_transmitting`]).
    pub fn in_suspend(&self) -> bool {
        self.bsp.phase == bsp::Phase::Suspend
    }

    /// Bus idle: integrated, no frame, intermission or suspension under
    /// way (the datasheet's "no bus activity" condition for sleep).
    pub fn is_bus_idle(&self) -> bool {
        self.bsp.phase == bsp::Phase::Idle
    }

    /// The field the engine is in, for diagnostics and waveforms.
    pub fn field(&self) -> Field {
        self.bsp.field()
    }
}
