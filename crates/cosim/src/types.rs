//! The types both sides of the comparison use: the DUT's CAN-side pins
//! (`dut` produces them, `compare` checks them), the [`Stamp`] of a
//! comparison (the observer makes it) and the [`Reference`] a DUT
//! is compared with (`model` and `dut` implement it, `compare` and
//! `testbench` drive it). Here so that neither `dut` nor `compare` imports
//! the other.

use can_proto::Field;
use diagnose::{CanMode, EventKind, WriteOutcome};

/// The CAN-side outputs of a DUT.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CanPins {
    /// `tx_o`: `true` = recessive.
    pub tx: bool,
    /// `irq_on`: active low (`false` = interrupt pending).
    pub irq_n: bool,
    /// `bus_off_on`: `true` while on the bus, `false` while bus-off.
    pub bus_on: bool,
    /// `clkout_o`.
    pub clkout: bool,
}

/// Where in the run something is compared or recorded (the observer
/// stamps, the comparator reports with it).
#[derive(Clone, Copy, Debug, Default)]
pub struct Stamp {
    /// Time, ps.
    pub t_ps: u64,
    /// Bit index.
    pub bit: u64,
    /// Field (reference's, else decoder's).
    pub field: Option<Field>,
    /// Frame number.
    pub frame: Option<u32>,
}

/// SR address (both register views).
pub const SR_ADDR: u8 = 2;
/// IR address (both register views).
pub const IR_ADDR: u8 = 3;
/// RMC address (PeliCAN view; a receive buffer byte in BasicCAN).
pub const RMC_ADDR: u8 = 29;
/// The PeliCAN registers whose values change at an instant of an event the
/// datasheet leaves to the implementation (the error counters at an error
/// or a success, RMC when a message is stored), judged with the status
/// window: RXERR, TXERR, RMC. In BasicCAN these addresses are buffer bytes.
pub const PELI_STATUS_ADDRS: [u8; 3] = [14, 15, RMC_ADDR];

/// What the comparator needs from the reference after one CAN clock
/// ([`Reference::step`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RefView {
    /// Output pins ([`Reference::pins`]).
    pub pins: CanPins,
    /// Field ([`Reference::field`]).
    pub field: Option<Field>,
    /// SR as a peek would return it.
    pub sr: u8,
    /// IR as a peek would return it.
    pub ir: u8,
    /// RXERR, TXERR and RMC as peeks would return them, in the PeliCAN
    /// view ([`PELI_STATUS_ADDRS`]; None in BasicCAN).
    pub peli: Option<[u8; 3]>,
    /// [`Reference::drain_events`] may have something (false: it has nothing).
    pub events: bool,
}

/// A reference the DUT is compared with: host access by direct calls and
/// one CAN clock at a time.
pub trait Reference {
    /// What it is.
    fn name(&self) -> String;
    /// Hardware reset.
    fn hard_reset(&mut self);
    /// Host write; the model's verdict if it has one.
    fn write(&mut self, addr: u8, data: u8) -> Option<WriteOutcome>;
    /// Host read (with side effects).
    fn read(&mut self, addr: u8) -> u8;
    /// Read without side effects.
    fn peek(&self, addr: u8) -> u8;
    /// One CAN clock with rx level `rx`.
    fn clock(&mut self, rx: bool);
    /// One CAN clock with rx level `rx`, then everything the test bench
    /// and the comparator look at after it, in one call. The default asks
    /// the other methods; a reference may answer from a cache, as long as
    /// it is exactly what they would return.
    fn step(&mut self, rx: bool) -> RefView {
        self.clock(rx);
        RefView {
            pins: self.pins(),
            field: self.field(),
            sr: self.peek(SR_ADDR),
            ir: self.peek(IR_ADDR),
            peli: matches!(self.mode(), Some((CanMode::PeliCan, _))).then(|| PELI_STATUS_ADDRS.map(|a| self.peek(a))),
            events: true,
        }
    }
    /// Output pins after the last clock.
    fn pins(&self) -> CanPins;
    /// Field of the bit stream the reference is in, if it knows.
    fn field(&self) -> Option<Field> {
        None
    }
    /// TEC and REC, if it has them.
    fn counters(&self) -> Option<(u16, u16)> {
        None
    }
    /// Register view and reset mode, if it has them.
    fn mode(&self) -> Option<(CanMode, bool)> {
        None
    }
    /// What its CLKOUT does now (the CDR divider), for the CLKOUT check.
    fn clkout_setting(&self) -> crate::clkout::ClkoutSetting {
        crate::clkout::ClkoutSetting::Unchecked
    }
    /// Register name at `addr` in the view in force.
    fn reg_name(&self, _addr: u8, _write: bool) -> Option<String> {
        None
    }
    /// Messages it lost to an RX FIFO overrun since its FIFO was last
    /// emptied (reset mode, hardware reset), if it knows (the waivers'
    /// `after = "data-overrun"`).
    fn lost_messages(&self) -> Option<u32> {
        None
    }
    /// True when the host aborted its last transmission request (CMR.AT
    /// since the last TR/SRR), if it knows (the waivers' `after-abort`).
    fn aborted_since_request(&self) -> Option<bool> {
        None
    }
    /// Engine events since the last call.
    fn drain_events(&mut self, _out: &mut Vec<EventKind>) {}
    /// Takes the DUT's error counters after a waived divergence (waivers
    /// `adopt-dut-tec` / `adopt-dut-rec`), re-evaluating the fault state;
    /// false if this reference cannot.
    fn adopt_counters(&mut self, _tec: Option<u8>, _rec: Option<u8>) -> bool {
        false
    }
    /// Takes the DUT's value of a register after a waived read divergence
    /// (`adopt-dut-register`); false if this reference cannot.
    fn adopt_register(&mut self, _addr: u8, _value: u8) -> bool {
        false
    }
    /// Leaves sleep without a wake-up interrupt, as a DUT without sleep mode
    /// never entered it (`model-skips-sleep`); false if this reference cannot.
    fn skip_sleep(&mut self) -> bool {
        false
    }
    /// Waits one more bus-free sequence after a bus-on within the last bits,
    /// holding the next frame for the DUT's start of frame
    /// (`model-waits-bus-free-after-bus-on`); false if this reference cannot
    /// or the bus-on is not recent.
    fn wait_bus_free_after_bus_on(&mut self) -> bool {
        false
    }
    /// Starts the frame held by [`Reference::wait_bus_free_after_bus_on`]
    /// at this clock (the DUT's tx just went dominant); false if none is held.
    fn start_held_tx_now(&mut self) -> bool {
        false
    }
}
