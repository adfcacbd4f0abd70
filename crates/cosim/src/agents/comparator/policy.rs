//! What a divergence does to the run, in one place: the waiver session
//! judges each divergence the checkers find (waived: resync and go on;
//! collect mode: list it and go on; else stop), the resync steps are
//! applied (skip bits here, the reference's own through the reference
//! agent, a counter adopted at its next read), and a missed scenario
//! expectation is judged against the waivers.

use diagnose::RunRecord;
use waivers::{Action, Observed, Resync, Session, WaiverReport};

use super::{Comparator, CompareConfig, Stamp};
use crate::agents::reference::ReferenceAgent;
use crate::model::AnyRef;
use crate::types::{CanPins, RefView};

/// The checkers of a lockstep run and the waiver and resync policy.
pub struct ComparatorAgent {
    /// The checkers (tx bits, reads, pins); `None` without lockstep.
    comparator: Option<Comparator>,
    waivers: Session,
    /// An unwaived divergence ended the comparison.
    stopped: bool,
    /// A waiver allowed adopting the DUT's TEC/REC whose value the
    /// comparator could not see: taken from the next TXERR/RXERR read.
    adopt_tec_at_read: bool,
    adopt_rec_at_read: bool,
    /// The last bit at whose sample point the DUT drove dominant and read
    /// recessive on its rx (a bit error it detects itself).
    dut_bit_error_bit: Option<u64>,
}

/// The clocks a waiver's bounds are measured in, at a divergence.
#[derive(Clone, Copy, Debug)]
pub struct Now {
    /// Simulated time, ps.
    pub t_ps: u64,
    /// CAN clock frequency, Hz.
    pub can_hz: u64,
    /// CAN clocks per bit of the bit timing in force.
    pub clocks_per_bit: u32,
}

impl ComparatorAgent {
    /// Checkers with tolerances `cfg` (none: no lockstep), judged by `waivers`.
    pub fn new(cfg: Option<CompareConfig>, waivers: Session) -> ComparatorAgent {
        ComparatorAgent {
            comparator: cfg.map(Comparator::new),
            waivers,
            stopped: false,
            adopt_tec_at_read: false,
            dut_bit_error_bit: None,
            adopt_rec_at_read: false,
        }
    }

    /// The checkers, if lockstep.
    pub fn comparator(&self) -> Option<&Comparator> {
        self.comparator.as_ref()
    }

    /// An unwaived divergence ended the comparison.
    #[inline]
    pub fn stopped(&self) -> bool {
        self.stopped
    }

    /// The waiver session.
    pub fn waivers(&mut self) -> &mut Session {
        &mut self.waivers
    }

    /// At the sample point of `bit`, the DUT drove dominant and its rx read
    /// recessive: a bit error it detects itself (for the waivers' episodes).
    pub fn dut_bit_error(&mut self, bit: u64) {
        self.dut_bit_error_bit = Some(bit);
    }

    /// The tolerances in words (for reports), if lockstep.
    pub fn tolerances(&self) -> Option<String> {
        self.comparator.as_ref().map(|c| c.config().describe())
    }

    /// The levels clkout_o had at the DUT's instants since the last CAN
    /// clock (bit 0 low, bit 1 high), given before [`Self::can_clock`].
    #[inline]
    pub fn clkout_instants(&mut self, levels: u8) {
        if let Some(c) = &mut self.comparator {
            c.clkout_instants(levels);
        }
    }

    /// One CAN clock compared (lockstep and not stopped; else nothing),
    /// CLKOUT included (`clkout`: the reference's setting, asked only when
    /// checked): true when a divergence waits for
    /// [`ComparatorAgent::handle_divergences`].
    #[inline]
    pub fn can_clock(
        &mut self,
        stamp: impl FnOnce() -> Stamp,
        sample: bool,
        v: &RefView,
        dut: &CanPins,
        clkout: impl FnOnce() -> super::clkout::ClkoutSetting,
    ) -> bool {
        match &mut self.comparator {
            Some(c) if !self.stopped => {
                let stamp = stamp();
                c.can_clock(stamp, sample, &v.pins, dut, v.sr, v.ir, v.peli);
                if c.config().compare_clkout {
                    c.clkout_clock(stamp, clkout(), dut.clkout);
                }
                c.halted()
            }
            _ => false,
        }
    }

    /// How many of the next CAN clocks, if none is a sample point and the
    /// reference's view `v` and the DUT's pins `dut` stay as they are, take
    /// the comparator's short path ([`Comparator::quiet_ahead`]); 0 without
    /// lockstep or once stopped.
    #[inline]
    pub fn quiet_ahead(&self, v: &RefView, dut: &CanPins) -> u32 {
        match &self.comparator {
            Some(c) if !self.stopped => c.quiet_ahead(&v.pins, dut, v.sr, v.ir, v.peli),
            _ => 0,
        }
    }

    /// One of those clocks: what [`ComparatorAgent::can_clock`] does on it
    /// (`field`, `bit`: the stamp's; the stamp itself is made only for a
    /// CLKOUT finding): true when a divergence waits for
    /// [`ComparatorAgent::handle_divergences`].
    #[inline]
    pub fn quiet_clock(
        &mut self,
        stamp: impl FnOnce() -> Stamp,
        field: Option<can_proto::Field>,
        bit: u64,
        v: &RefView,
        dut: &CanPins,
        clkout: impl FnOnce() -> super::clkout::ClkoutSetting,
    ) -> bool {
        match &mut self.comparator {
            Some(c) if !self.stopped => {
                c.quiet_clock(field, bit, &v.pins, dut);
                if c.config().compare_clkout {
                    c.clkout_clock_with(stamp, clkout(), dut.clkout);
                }
                c.halted()
            }
            _ => false,
        }
    }

    /// The CLKOUT part of quiet clocks, while it finds nothing to report
    /// ([`Comparator::quiet_clkout`]); None without lockstep, once stopped,
    /// or when the clocks need [`ComparatorAgent::quiet_clock`] in full.
    #[inline]
    pub fn quiet_clkout(&mut self, setting: super::clkout::ClkoutSetting) -> Option<(&mut super::clkout::ClkoutCheck, u32)> {
        match &mut self.comparator {
            Some(c) if !self.stopped => c.quiet_clkout(setting),
            _ => None,
        }
    }

    /// The rest of `n` quiet clocks in a row whose CLKOUT part was done
    /// ([`ComparatorAgent::quiet_clkout`]): what `quiet_clock` does on them
    /// besides it, which finds nothing.
    pub fn quiet_clocks(&mut self, n: u32, field: Option<can_proto::Field>, bit: u64, v: &RefView, dut: &CanPins) {
        if let Some(c) = &mut self.comparator
            && !self.stopped
        {
            c.quiet_clocks(n, field, bit, &v.pins, dut);
        }
    }

    /// A register read completed on both sides (see [`Comparator::read`]):
    /// true when a divergence waits for [`ComparatorAgent::handle_divergences`].
    pub fn read(&mut self, stamp: Stamp, addr: u8, dut: u8, model: u8, name: Option<String>) -> bool {
        // A read of IR ends the episodes of `until-read` waivers.
        if let Some(n) = &name {
            self.waivers.host_read(n, stamp.t_ps);
        }
        match &mut self.comparator {
            Some(c) if !self.stopped => {
                c.read(stamp, addr, dut, model, name);
                c.halted()
            }
            _ => false,
        }
    }

    /// The reference has just taken the read the DUT completes next.
    pub fn reference_read_taken(&mut self) {
        if let Some(c) = &mut self.comparator {
            c.reference_read_taken();
        }
    }

    /// CAN clocks until every read within its look-ahead window is decided
    /// (0: none, or the comparison stopped).
    pub fn open_read_clocks(&self) -> u32 {
        if self.stopped {
            return 0;
        }
        self.comparator.as_ref().map_or(0, |c| c.open_read_clocks())
    }

    /// CAN clocks until every open comparison is decided (0: none, or the
    /// comparison stopped).
    pub fn open_clocks(&self) -> u32 {
        if self.stopped {
            return 0;
        }
        self.comparator.as_ref().map_or(0, |c| c.open_clocks())
    }

    /// See [`Comparator::hold_tolerated_read`]: true when it made the read
    /// a divergence (waiting for [`ComparatorAgent::handle_divergences`]).
    pub fn hold_tolerated_read(&mut self, addr: u8, dut: u8, mask: u8, expected: u8) -> bool {
        match &mut self.comparator {
            Some(c) if !self.stopped => c.hold_tolerated_read(addr, dut, mask, expected),
            _ => false,
        }
    }

    /// A read of `reg` returned `value` on the DUT: a pending
    /// `adopt-dut-tec`/`-rec` takes it into the reference now. True if the
    /// reference adopted it (its read value is then the DUT's); a reference
    /// that cannot is noted, never hidden.
    pub fn adopt_at_read(&mut self, reg: Option<&str>, value: u8, refm: &mut AnyRef, t_ps: u64) -> bool {
        let (tried, adopt) = match reg {
            Some("TXERR") if self.adopt_tec_at_read => {
                self.adopt_tec_at_read = false;
                (true, refm.adopt_counters(Some(value), None))
            }
            Some("RXERR") if self.adopt_rec_at_read => {
                self.adopt_rec_at_read = false;
                (true, refm.adopt_counters(None, Some(value)))
            }
            _ => (false, false),
        };
        if tried && !adopt {
            // Never hidden: the waiver asked for it, the reference could not.
            self.waivers.note(format!(
                "{} cannot adopt the DUT's {} = {} read at {} ps: it keeps its own counter",
                refm.name(),
                reg.unwrap_or("counter"),
                value,
                t_ps
            ));
        }
        adopt
    }

    /// Hands each new divergence to the waiver session and applies its
    /// verdict: resync and go on, go on (collect), or stop. The first one
    /// goes into `record`; `dut_tx` is the DUT's tx now (a held frame
    /// starts at its next falling edge).
    pub fn handle_divergences(&mut self, now: Now, reference: &mut ReferenceAgent, dut_tx: bool, record: &mut RunRecord) {
        let (Some(c), Some(r)) = (&mut self.comparator, &reference.model) else {
            return;
        };
        // The DUT is seen through its pins and host reads only; the clock
        // lets a waiver bound how late a pin may be (`late-by`).
        let can_clock_ps = 1_000_000_000_000 / now.can_hz.max(1);
        let mut observed = Observed::timed(now.t_ps, can_clock_ps * now.clocks_per_bit as u64, can_clock_ps);
        // The model's MOD (PeliCAN: address 0), for `model-mod-bits`.
        if let Some((diagnose::CanMode::PeliCan, _)) = r.mode() {
            observed.model_mod = Some(r.peek(0));
        }
        // The model's pending interrupts (IR read without clearing), for `model-ir-bits`.
        observed.model_ir = Some(r.peek(crate::types::IR_ADDR));
        // The model's mode, for `model-mode`.
        observed.model_basic = r.mode().map(|(m, _)| m == diagnose::CanMode::BasicCan);
        // Messages the model lost to an overrun, for `after = "data-overrun"`.
        observed.model_lost_messages = r.lost_messages();
        // The host's abort of the model's request, for `after-abort`.
        observed.model_aborted = r.aborted_since_request();
        // The model's RX frame information (operating mode: address 16 is
        // the RX buffer), for `model-rx-frame`.
        if let Some(m) = observed.model_mod
            && m & 0x01 == 0
        {
            observed.model_rx_frame_info = Some(r.peek(16));
        }
        // What ends or restarts a tx-bit waiver's episode.
        observed.tx_agreed_bit = c.tx_agreed_bit();
        observed.dut_bit_error_bit = self.dut_bit_error_bit;
        while let Some(d) = c.take_divergence() {
            let bit = d.bit;
            // An irq report: the same difference again, or a new one
            // (`until-read` episodes).
            observed.pin_continues = if d.kind == diagnose::DivergenceKind::Irq { c.take_irq_continues() } else { None };
            match self.waivers.divergence_observed(d.clone(), &observed) {
                Action::Resync(steps) => {
                    let mut skip_to = None;
                    for step in steps {
                        let applied = match step {
                            Resync::SkipBits(n) => {
                                skip_to = bit.map(|b| b + n as u64);
                                true
                            }
                            Resync::AdoptTec(None) => {
                                self.adopt_tec_at_read = true;
                                true
                            }
                            Resync::AdoptRec(None) => {
                                self.adopt_rec_at_read = true;
                                true
                            }
                            _ => reference.resync(&step, dut_tx).unwrap_or(false),
                        };
                        if !applied {
                            self.waivers.note(format!(
                                "resync {step:?} could not be applied: {} cannot, it keeps its own state",
                                reference.name()
                            ));
                        }
                    }
                    c.resume(skip_to, false);
                }
                Action::Continue => {
                    // Collect mode: the difference is listed; the reference
                    // then takes the DUT's value where it can (storage
                    // registers, TXERR/RXERR, SR's latched flags), so later
                    // reads show the next real difference, not this one's
                    // cascade. Derived registers keep the
                    // model's value.
                    if let Some((addr, value)) = c.taken_read()
                        && let Some(r) = &mut reference.model
                    {
                        r.adopt_register(addr, value);
                    }
                    record.divergence.get_or_insert(d);
                    c.resume(None, true);
                }
                Action::Stop => {
                    // The first unwaived one ends the comparison: later ones
                    // found at the same clock are not handed on.
                    record.divergence = Some(d);
                    self.stopped = true;
                    break;
                }
            }
        }
    }

    /// A scenario expectation missed on a read of `v`: waived if the read's
    /// own divergence was waived (the model's value meets it), or if it is a
    /// listed consequence of a deviation waived earlier in this run. Returns
    /// what to add to the "seen" text when waived. `waived_before`: the
    /// waived count before the read.
    #[allow(clippy::too_many_arguments)]
    pub fn waive_missed_expectation(
        &mut self,
        waived_before: usize,
        scenario: &str,
        step: usize,
        what: &str,
        mask: u8,
        expected: u8,
        v: u8,
    ) -> Option<String> {
        // A miss that is the read's own waived deviation (the model's value
        // meets the expectation) is waived, and listed in the waiver report.
        if let Some(id) = self.waivers.waive_expectation(waived_before, step, what, mask, expected, v) {
            return Some(format!(" (waived by {id})"));
        }
        // A miss on a read the model agrees with (no read diverged) may be a
        // listed consequence of a deviation waived earlier in this run.
        // Waived tx or pin divergences during the read do not count: a slow
        // bus's read (the 8051's, about a bit time) overlaps them.
        let read_waived = self.waivers.report().waived[waived_before..]
            .iter()
            .any(|w| w.divergence.kind == diagnose::DivergenceKind::RegisterRead);
        if !read_waived
            && let Some(id) = self.waivers.waive_consequence(scenario, step, what, mask, expected, v)
        {
            return Some(format!(" (waived: a consequence of {id})"));
        }
        // A miss on a read that diverged (waived) where the model misses too:
        // a listed consequence of a deviation waived before this read.
        if read_waived
            && let Some(id) = self.waivers.waive_consequence_on_waived_read(
                waived_before,
                scenario,
                step,
                what,
                mask,
                expected,
                v,
            )
        {
            return Some(format!(" (waived: a consequence of {id})"));
        }
        None
    }

    /// Waived divergences, failures and stale waivers so far, with the
    /// collect-mode repeats and cascade and any adoption still pending.
    pub fn waiver_report(&self) -> WaiverReport {
        let mut r = self.waivers.snapshot();
        if let Some(c) = &self.comparator {
            // Collect mode lists each difference once: say what came again.
            let repeats = c.repeats();
            if !repeats.is_empty() {
                r.notes.push(format!(
                    "{} later occurrence(s) of differences already listed are not listed again: {}",
                    c.repeated,
                    repeats.join("; ")
                ));
            }
            if c.cascade > 0 {
                r.notes.push(format!(
                    "{} more mismatching sample point(s) in frames whose first tx difference is listed (or counted above) are not listed",
                    c.cascade
                ));
            }
        }
        for (pending, reg) in [
            (self.adopt_tec_at_read, "TXERR"),
            (self.adopt_rec_at_read, "RXERR"),
        ] {
            if pending {
                r.notes.push(format!(
                    "resync adopt the DUT's {reg} not applied yet: no {reg} read since the waived divergence"
                ));
            }
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::agents::reference::{RefTiming, ReferenceChoice};
    use waivers::{CollectMode, DutInfo, WaiverSet};

    const IRQ_WAIVER: &str = r#"
[[waiver]]
id = "irq-early"
kind = "irq"
dut = ["fixture"]
explanation = "irq pending early, accepted for this test"
resync = ["adopt-dut-rec"]
"#;

    fn agent(waivers: &str, mode: CollectMode) -> ComparatorAgent {
        let set = if waivers.is_empty() { WaiverSet::empty() } else { WaiverSet::parse(waivers, "t.toml").unwrap() };
        ComparatorAgent::new(Some(CompareConfig::default()), Session::new(set, DutInfo::new("fixture"), mode))
    }

    fn reference() -> ReferenceAgent {
        ReferenceAgent::new(Some(ReferenceChoice::Model), None, RefTiming::AtAck)
    }

    const NOW: Now = Now { t_ps: 0, can_hz: 24_000_000, clocks_per_bit: 10 };

    /// Clocks `n` CAN clocks with the DUT's irq pending and the model's not;
    /// handles each divergence; returns how many there were.
    fn irq_differs(a: &mut ComparatorAgent, r: &mut ReferenceAgent, rec: &mut RunRecord, n: u64) -> u32 {
        irq_differs_from(a, r, rec, 0, n)
    }

    /// [`irq_differs`] for the clocks `from..from + n` (stamped so).
    fn irq_differs_from(a: &mut ComparatorAgent, r: &mut ReferenceAgent, rec: &mut RunRecord, from: u64, n: u64) -> u32 {
        let view = RefView { pins: CanPins { tx: true, irq_n: true, bus_on: true, clkout: false }, ..RefView::default() };
        let dut = CanPins { irq_n: false, ..view.pins };
        let mut found = 0;
        for k in from..from + n {
            let stamp = || Stamp { t_ps: k, bit: k / 10, field: None, frame: None };
            if a.can_clock(stamp, k % 10 == 7, &view, &dut, || super::super::clkout::ClkoutSetting::Unchecked) {
                found += 1;
                a.handle_divergences(NOW, r, true, rec);
            }
        }
        found
    }

    #[test]
    fn stop_at_first_ends_the_comparison_and_collect_goes_on_listing_once() {
        let (mut r, mut rec) = (reference(), RunRecord::new("t", "fixture"));
        let mut a = agent("", CollectMode::StopAtFirst);
        assert_eq!(irq_differs(&mut a, &mut r, &mut rec, 200), 1, "the 49th clock diverges, then nothing is compared");
        assert!(a.stopped());
        assert_eq!(rec.divergence.as_ref().map(|d| d.kind), Some(diagnose::DivergenceKind::Irq));
        assert_eq!((a.open_clocks(), a.open_read_clocks()), (0, 0));
        assert!(!a.read(Stamp::default(), 4, 1, 2, None), "no read compared once stopped");
        assert_eq!(a.waiver_report().failures.len(), 1);

        let (mut r, mut rec) = (reference(), RunRecord::new("t", "fixture"));
        let mut a = agent("", CollectMode::Collect);
        assert_eq!(irq_differs(&mut a, &mut r, &mut rec, 200), 1, "listed once while it lasts");
        assert!(!a.stopped());
        assert!(rec.divergence.is_some());
        assert!(a.read(Stamp::default(), 4, 1, 2, None), "reads are still compared");
    }

    #[test]
    fn a_waived_divergence_resyncs_and_a_counter_is_adopted_at_its_next_read() {
        let (mut r, mut rec) = (reference(), RunRecord::new("t", "fixture"));
        let mut a = agent(IRQ_WAIVER, CollectMode::StopAtFirst);
        // Not latched after a waived one: the waiver sees every occurrence.
        assert!(irq_differs(&mut a, &mut r, &mut rec, 200) >= 3);
        assert!(!a.stopped() && rec.divergence.is_none());
        let report = a.waiver_report();
        assert!(report.notes.iter().any(|n| n.contains("RXERR not applied yet")), "{:?}", report.notes);
        // A TXERR read does not take the pending RXERR; the RXERR read does.
        let m = r.model.as_mut().unwrap();
        assert!(!a.adopt_at_read(Some("TXERR"), 5, m, 0));
        assert!(a.adopt_at_read(Some("RXERR"), 7, m, 0));
        assert_eq!(m.counters(), Some((0, 7)));
        assert!(!a.adopt_at_read(Some("RXERR"), 9, m, 0), "adopted once");
        assert!(!a.waiver_report().notes.iter().any(|n| n.contains("not applied yet")));
    }

    const IRQ_UNTIL_READ: &str = r#"
[[waiver]]
id = "ei-early"
kind = "irq"
dut = ["fixture"]
explanation = "EI pending early on the DUT, until the host reads IR"
until-read = "IR"
max-hits = 1
resync = ["none"]
"#;

    #[test]
    fn an_until_read_episode_ends_at_the_hosts_read_of_ir() {
        // The DUT's irq pending, the model's not, for 2000 clocks (41
        // reports): one episode, waived, as long as no IR read came.
        let (mut r, mut rec) = (reference(), RunRecord::new("t", "fixture"));
        let mut a = agent(IRQ_UNTIL_READ, CollectMode::StopAtFirst);
        assert_eq!(irq_differs(&mut a, &mut r, &mut rec, 2000), 40);
        assert!(!a.stopped() && rec.divergence.is_none());
        // Other reads do not end it; the host's read of IR does: the pin
        // still differing more than the tolerance after it is a failure.
        let at = Stamp { t_ps: 2000, ..Stamp::default() };
        assert!(!a.read(at, 2, 0x0C, 0x0C, Some("SR".into())));
        assert_eq!(irq_differs_from(&mut a, &mut r, &mut rec, 2000, 100), 2, "still the same episode");
        assert!(!a.stopped());
        // Reported at 2106 (its run began at 2058, before the read: within
        // the pin tolerance after it) and at 2155 (began at 2107: not).
        assert!(!a.read(Stamp { t_ps: 2100, ..at }, 3, 0x04, 0x04, Some("IR".into())));
        assert_eq!(irq_differs_from(&mut a, &mut r, &mut rec, 2100, 100), 2);
        assert!(a.stopped(), "the pin outlasted the IR read");
        assert_eq!(rec.divergence.as_ref().map(|d| d.time_ps), Some(2107));
        let report = a.waiver_report();
        assert!(report.notes.iter().any(|n| n.contains("still differed after the host's read of IR")), "{:?}", report.notes);
    }

    #[test]
    fn without_lockstep_nothing_is_compared() {
        let mut a = ComparatorAgent::new(None, Session::new(WaiverSet::empty(), DutInfo::new("x"), CollectMode::StopAtFirst));
        let (mut r, mut rec) = (reference(), RunRecord::new("t", "x"));
        assert_eq!(irq_differs(&mut a, &mut r, &mut rec, 100), 0);
        assert!(a.comparator().is_none() && a.tolerances().is_none());
    }
}
