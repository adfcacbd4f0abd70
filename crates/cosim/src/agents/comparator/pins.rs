//! The pin checker: `irq_on` and `bus_off_on` may differ for at most
//! `pin_tolerance` CAN clocks in a row (a status pipeline's latency);
//! longer is a divergence, stamped where the difference began. In collect
//! mode a listed pin difference is latched until the pins agree again.

use diagnose::DivergenceKind;

use super::{CompareConfig, Stamp};
use crate::types::CanPins;

/// A pin difference that lasted too long.
pub(super) struct PinDiff {
    pub(super) kind: DivergenceKind,
    /// Where it began.
    pub(super) since: Stamp,
    pub(super) expected: u32,
    pub(super) seen: u32,
    pub(super) context: String,
    /// The pins have not agreed since this pin's previous report: the same
    /// difference reported again (an `until-read` waiver's episode goes on).
    pub(super) continues: bool,
}

/// One pin's run of differing clocks.
#[derive(Clone, Copy, Debug, Default)]
struct Run {
    bad: u32,
    since: Stamp,
    /// Collect mode: listed, not reported again until the pins agree.
    latched: bool,
    /// The pins agreed at some clock since this pin's last report.
    agreed: bool,
}

/// `irq_on` and `bus_off_on` against the reference's.
pub(super) struct PinChecker {
    tolerance: u32,
    compare_irq: bool,
    compare_bus_off: bool,
    irq: Run,
    bus: Run,
}

impl PinChecker {
    pub(super) fn new(cfg: &CompareConfig) -> PinChecker {
        PinChecker {
            tolerance: cfg.pin_tolerance,
            compare_irq: cfg.compare_irq,
            compare_bus_off: cfg.compare_bus_off,
            irq: Run::default(),
            bus: Run::default(),
        }
    }

    /// Both pins agree with the reference's.
    #[inline]
    pub(super) fn agree(reference: &CanPins, dut: &CanPins) -> bool {
        reference.irq_n == dut.irq_n && reference.bus_on == dut.bus_on
    }

    /// A clock at which [`PinChecker::agree`] holds (and `skipping`: a
    /// waiver's skipped bits, nothing compared).
    #[inline]
    pub(super) fn quiet_clock(&mut self, skipping: bool) {
        self.irq.latched = false;
        self.bus.latched = false;
        self.irq.agreed = true;
        self.bus.agreed = true;
        if !skipping {
            if self.compare_irq {
                self.irq.bad = 0;
            }
            if self.compare_bus_off {
                self.bus.bad = 0;
            }
        }
    }

    /// Any clock: the differences that outlasted the tolerance now, irq first.
    pub(super) fn clock(&mut self, stamp: Stamp, reference: &CanPins, dut: &CanPins, skipping: bool) -> [Option<PinDiff>; 2] {
        if reference.irq_n == dut.irq_n {
            self.irq.latched = false;
            self.irq.agreed = true;
        }
        if reference.bus_on == dut.bus_on {
            self.bus.latched = false;
            self.bus.agreed = true;
        }
        let tol = self.tolerance;
        let irq = (self.compare_irq && !skipping)
            .then(|| {
                self.irq.check(stamp, reference.irq_n, dut.irq_n, tol).map(|(since, e, s, continues)| PinDiff {
                    kind: DivergenceKind::Irq,
                    since,
                    expected: e,
                    seen: s,
                    context: format!("irq_on (active low) differs for more than {tol} CAN clocks"),
                    continues,
                })
            })
            .flatten();
        let bus = (self.compare_bus_off && !skipping)
            .then(|| {
                self.bus.check(stamp, reference.bus_on, dut.bus_on, tol).map(|(since, e, s, continues)| PinDiff {
                    kind: DivergenceKind::BusOff,
                    since,
                    expected: e,
                    seen: s,
                    context: format!("bus_off_on (high = on the bus) differs for more than {tol} CAN clocks"),
                    continues,
                })
            })
            .flatten();
        [irq, bus]
    }

    /// After a divergence was handled: each pin's run starts afresh.
    pub(super) fn restart(&mut self) {
        self.irq.bad = 0;
        self.bus.bad = 0;
    }

    /// Collect mode: `irq_on` listed, not again until the pins agree.
    pub(super) fn latch_irq(&mut self) {
        self.irq.latched = true;
    }

    /// Collect mode: `bus_off_on` listed, not again until the pins agree.
    pub(super) fn latch_bus_off(&mut self) {
        self.bus.latched = true;
    }

    /// CAN clocks until a difference under way is decided (0: none).
    pub(super) fn open_clocks(&self) -> u32 {
        let pin = |bad: u32| if bad > 0 { (self.tolerance + 1).saturating_sub(bad) } else { 0 };
        pin(self.irq.bad).max(pin(self.bus.bad))
    }
}

impl Run {
    /// One compared clock: (where it began, reference, DUT, the pins have
    /// not agreed since the last report) once the difference lasts more
    /// than `tol` clocks (and at every clock after).
    #[inline]
    fn check(&mut self, stamp: Stamp, reference: bool, dut: bool, tol: u32) -> Option<(Stamp, u32, u32, bool)> {
        if self.latched {
            return None;
        }
        if reference == dut {
            self.bad = 0;
            return None;
        }
        if self.bad == 0 {
            self.since = stamp;
        }
        self.bad += 1;
        if self.bad <= tol {
            return None;
        }
        let continues = !self.agreed;
        self.agreed = false;
        Some((self.since, reference as u32, dut as u32, continues))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pins(irq_n: bool, bus_on: bool) -> CanPins {
        CanPins { tx: true, irq_n, bus_on, clkout: false }
    }

    #[test]
    fn a_pin_may_differ_for_the_tolerance_and_is_stamped_where_it_began() {
        let cfg = CompareConfig { pin_tolerance: 3, ..CompareConfig::default() };
        let mut p = PinChecker::new(&cfg);
        let (r, d) = (pins(true, true), pins(false, true));
        let at = |bit| Stamp { bit, ..Stamp::default() };
        for bit in 0..3 {
            assert!(p.clock(at(bit), &r, &d, false).iter().all(Option::is_none));
        }
        assert_eq!(p.open_clocks(), 1);
        let [irq, bus] = p.clock(at(3), &r, &d, false);
        let irq = irq.expect("the 4th clock is one too many");
        assert_eq!((irq.kind, irq.since.bit, irq.expected, irq.seen), (DivergenceKind::Irq, 0, 1, 0));
        assert!(bus.is_none());
        // Latched (collect mode): not again until the pins agree.
        p.restart();
        p.latch_irq();
        for bit in 4..20 {
            assert!(p.clock(at(bit), &r, &d, false)[0].is_none());
        }
        assert!(p.clock(at(20), &r, &r, false)[0].is_none());
        for bit in 21..24 {
            assert!(p.clock(at(bit), &r, &d, false)[0].is_none());
        }
        assert_eq!(p.clock(at(24), &r, &d, false)[0].as_ref().map(|x| x.since.bit), Some(21));
    }

    #[test]
    fn a_report_says_whether_the_pins_agreed_since_the_last_one() {
        let cfg = CompareConfig { pin_tolerance: 2, ..CompareConfig::default() };
        let mut p = PinChecker::new(&cfg);
        let (r, d) = (pins(true, true), pins(false, true));
        let at = |bit| Stamp { bit, ..Stamp::default() };
        let report = |p: &mut PinChecker, from: u64| {
            (from..from + 3).find_map(|bit| p.clock(at(bit), &r, &d, false)[0].take()).map(|x| x.continues)
        };
        p.quiet_clock(false);
        assert_eq!(report(&mut p, 0), Some(false), "a new difference");
        // A waived report: the run restarts (as after any handled divergence).
        p.restart();
        assert_eq!(report(&mut p, 3), Some(true), "the same difference again");
        p.restart();
        assert!(p.clock(at(6), &r, &r, false)[0].is_none());
        assert_eq!(report(&mut p, 7), Some(false), "the pins agreed at bit 6: a new one");
    }

    #[test]
    fn skipped_bits_and_pins_not_compared_never_diverge() {
        let cfg = CompareConfig { pin_tolerance: 0, compare_bus_off: false, ..CompareConfig::default() };
        let mut p = PinChecker::new(&cfg);
        let (r, d) = (pins(true, true), pins(false, false));
        assert!(p.clock(Stamp::default(), &r, &d, true).iter().all(Option::is_none), "skipping");
        let [irq, bus] = p.clock(Stamp::default(), &r, &d, false);
        assert!(irq.is_some() && bus.is_none(), "bus_off_on not compared");
    }
}
