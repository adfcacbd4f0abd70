//! Fault confinement (CAN 2.0B §8), kept apart from the frame state machine:
//! the bit stream processor says *what happened*, these rules say what the
//! counters do. Each method cites its rule number.
//!
//! SJA1000 specifics (datasheet, TXERR/RXERR): at bus-off TXERR is set to
//! 127 and RXERR to 0; during recovery TXERR counts the 128 bus-free
//! occurrences down; listen-only mode freezes both counters.

use crate::{Event, FaultState};

/// Error counters and the state they imply.
#[derive(Clone, Debug)]
pub(crate) struct Fault {
    /// Transmit error counter; wide enough to see 256 (bus-off, rule 10).
    tec: u16,
    rec: u8,
    state: FaultState,
    warning: bool,
    ewl: u8,
    /// Listen-only mode: counters stopped (SJA1000 MOD.LOM).
    frozen: bool,
}

impl Fault {
    pub(crate) fn new(ewl: u8) -> Self {
        Fault {
            tec: 0,
            rec: 0,
            state: FaultState::ErrorActive,
            warning: false,
            ewl,
            frozen: false,
        }
    }

    pub(crate) fn tec(&self) -> u8 {
        self.tec as u8
    }
    pub(crate) fn rec(&self) -> u8 {
        self.rec
    }
    pub(crate) fn state(&self) -> FaultState {
        self.state
    }
    pub(crate) fn warning(&self) -> bool {
        self.warning
    }
    pub(crate) fn is_active(&self) -> bool {
        self.state == FaultState::ErrorActive
    }
    pub(crate) fn set_ewl(&mut self, ewl: u8, frozen: bool) {
        self.ewl = ewl;
        self.frozen = frozen;
    }

    fn add_tec(&mut self, n: u16) {
        if !self.frozen {
            self.tec += n;
        }
    }
    fn add_rec(&mut self, n: u8) {
        if !self.frozen {
            self.rec = self.rec.saturating_add(n);
        }
    }

    /// Rule 1: a receiver detecting an error adds 1 to REC (bit errors
    /// during its own active error or overload flag go to rule 5 instead).
    pub(crate) fn rule1_receiver_error(&mut self, ev: &mut Vec<Event>) -> bool {
        self.add_rec(1);
        self.update(ev)
    }

    /// Rule 2: a receiver seeing dominant as the first bit after sending an
    /// error flag adds 8 to REC.
    pub(crate) fn rule2_dominant_after_flag(&mut self, ev: &mut Vec<Event>) -> bool {
        self.add_rec(8);
        self.update(ev)
    }

    /// Rule 3: a transmitter sending an error flag adds 8 to TEC (the caller
    /// applies exceptions 1 and 2 by not calling, or by calling late).
    pub(crate) fn rule3_transmitter_flag(&mut self, ev: &mut Vec<Event>) -> bool {
        self.add_tec(8);
        self.update(ev)
    }

    /// Rules 4 and 5: a bit error while sending an active error flag or an
    /// overload flag adds 8 to TEC (transmitter) or REC (receiver).
    pub(crate) fn rule4_5_bit_error_in_flag(
        &mut self,
        transmitter: bool,
        ev: &mut Vec<Event>,
    ) -> bool {
        if transmitter {
            self.add_tec(8)
        } else {
            self.add_rec(8)
        }
        self.update(ev)
    }

    /// Rule 6: after the 14th consecutive dominant bit following an active
    /// error flag or overload flag (the 8th after a passive one), and after
    /// each further 8, transmitters add 8 to TEC and receivers 8 to REC.
    pub(crate) fn rule6_dominant_sequence(
        &mut self,
        transmitter: bool,
        ev: &mut Vec<Event>,
    ) -> bool {
        self.rule4_5_bit_error_in_flag(transmitter, ev)
    }

    /// Rule 7: a successful transmission decrements TEC unless it is 0.
    pub(crate) fn rule7_transmit_success(&mut self, ev: &mut Vec<Event>) {
        if !self.frozen && self.tec > 0 {
            self.tec -= 1;
        }
        self.update(ev);
    }

    /// Rule 8: a successful reception (ACK sent) decrements REC if it is in
    /// 1..=127; above 127 it is set back into 119..=127 (we use 127).
    pub(crate) fn rule8_receive_success(&mut self, ev: &mut Vec<Event>) {
        if !self.frozen {
            if self.rec > 127 {
                self.rec = 127;
            } else if self.rec > 0 {
                self.rec -= 1;
            }
        }
        self.update(ev);
    }

    /// Rules 9 (error passive at 128), 10 (bus-off at 256) and 11 (back to
    /// error active when both are at most 127); emits the events. Returns
    /// true when the node has just gone bus-off.
    pub(crate) fn update(&mut self, ev: &mut Vec<Event>) -> bool {
        let mut bus_off = false;
        let new = if self.state == FaultState::BusOff {
            FaultState::BusOff
        } else if self.tec >= 256 {
            // SJA1000: TXERR := 127 to count the recovery, RXERR := 0.
            self.tec = 127;
            self.rec = 0;
            bus_off = true;
            FaultState::BusOff
        } else if self.tec >= 128 || self.rec >= 128 {
            FaultState::ErrorPassive
        } else {
            FaultState::ErrorActive
        };
        if new != self.state {
            self.state = new;
            ev.push(Event::FaultState(new));
        }
        self.update_warning(ev);
        bus_off
    }

    /// SR.ES: at or above EWL; held set while bus-off.
    fn update_warning(&mut self, ev: &mut Vec<Event>) {
        let w =
            self.state == FaultState::BusOff || self.tec >= self.ewl as u16 || self.rec >= self.ewl;
        if w != self.warning {
            self.warning = w;
            ev.push(Event::ErrorWarning(w));
        }
    }

    /// Rule 12 progress: one more bus-free occurrence during recovery, shown
    /// by TXERR counting down from 127. Returns true after the 128th: the
    /// node is error active again with both counters at 0.
    pub(crate) fn recovery_step(&mut self, occurrences: u8, ev: &mut Vec<Event>) -> bool {
        if occurrences >= 128 {
            self.tec = 0;
            self.rec = 0;
            self.state = FaultState::ErrorActive;
            ev.push(Event::FaultState(FaultState::ErrorActive));
            self.update_warning(ev);
            true
        } else {
            self.tec = 127 - occurrences as u16;
            false
        }
    }

    /// Forces bus-off through rule 10 (a CPU write of 255 to TXERR, when
    /// reset mode is left).
    pub(crate) fn force_bus_off(&mut self, ev: &mut Vec<Event>) {
        self.tec = 256;
        self.update(ev);
    }

    /// CPU write of TXERR/RXERR (reset mode): the new values take effect
    /// now; warning and error-passive changes are reported by
    /// [`Fault::update`] when reset mode is left (the datasheet defers them).
    /// A TXERR write while bus-off clears bus-off (reported now); RXERR
    /// writes are ignored while bus-off.
    pub(crate) fn write(&mut self, tec: Option<u8>, rec: Option<u8>, ev: &mut Vec<Event>) {
        if let Some(r) = rec {
            if self.state != FaultState::BusOff {
                self.rec = r;
            }
        }
        if let Some(t) = tec {
            self.tec = t as u16;
            if self.state == FaultState::BusOff {
                // The write ends bus-off now (BS clears). Whether the
                // counters make the node error passive is decided with the
                // next update, when reset mode is left (datasheet TXERR: an
                // error passive interrupt forced by the new content waits
                // until then), and it is a change from not passive: EPI.
                self.state = FaultState::ErrorActive;
                ev.push(Event::FaultState(self.state));
            }
        }
    }
}
