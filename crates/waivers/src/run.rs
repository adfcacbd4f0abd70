//! The comparator's side of the waivers: what to do after each divergence.

use std::str::FromStr;

use diagnose::Divergence;
use serde::{Deserialize, Serialize};

use crate::file::ConsequenceOf;
use crate::report::{WaivedExpectation, Waived, WaiverReport};
use crate::dut::DutInfo;
use crate::set::{Observed, Resync, Verdict, WaiverSet};

/// What the comparator does with an unwaived divergence
/// (`--stop-at-first` / `--collect`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum CollectMode {
    /// Stop the comparison at the first unwaived divergence.
    #[default]
    StopAtFirst,
    /// Record it and keep comparing, to see every divergence of the run.
    Collect,
}

impl FromStr for CollectMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "stop-at-first" => Ok(CollectMode::StopAtFirst),
            "collect" => Ok(CollectMode::Collect),
            _ => Err(format!("unknown mode `{s}`: stop-at-first or collect")),
        }
    }
}

/// The comparator's next move after a divergence.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Action {
    /// Waived: apply these steps (in order) and keep comparing.
    Resync(Vec<Resync>),
    /// Unwaived, collect mode: recorded as a failure; keep comparing.
    Continue,
    /// Unwaived, stop-at-first mode: recorded; end the comparison.
    Stop,
}

/// One run's waiver bookkeeping: the set, the DUT, the mode and the report
/// being built. The comparator calls [`Session::divergence`] for every
/// divergence it finds and [`Session::finish`] at the end.
#[derive(Debug)]
pub struct Session {
    set: WaiverSet,
    dut: DutInfo,
    mode: CollectMode,
    report: WaiverReport,
}

impl Session {
    /// A session for `dut` with these waivers (use [`WaiverSet::empty`] for none).
    pub fn new(set: WaiverSet, dut: DutInfo, mode: CollectMode) -> Self {
        let report = WaiverReport::new(&set, &dut);
        Session { set, dut, mode, report }
    }

    /// The mode.
    pub fn mode(&self) -> CollectMode {
        self.mode
    }

    /// The host's read of `register` completed at `t_ps`: it ends the
    /// episodes of `until-read` waivers ([`WaiverSet::host_read`]).
    pub fn host_read(&mut self, register: &str, t_ps: u64) {
        self.set.host_read(register, t_ps);
    }

    /// A start of frame on the bus at `t_ps` ([`WaiverSet::frame_start`]).
    pub fn frame_start(&mut self, t_ps: u64) {
        self.set.frame_start(t_ps);
    }

    /// A divergence with nothing observed beyond it.
    pub fn divergence(&mut self, d: Divergence) -> Action {
        self.divergence_observed(d, &Observed::default())
    }

    /// A divergence, with what the comparator could observe of the DUT.
    pub fn divergence_observed(&mut self, d: Divergence, obs: &Observed) -> Action {
        match self.set.check_observed(&d, &self.dut, obs) {
            Verdict::Waived { waiver_id, resync } => {
                self.report.waived.push(Waived { divergence: d, waiver_id });
                Action::Resync(resync)
            }
            Verdict::Failure => {
                self.report.notes.extend(self.set.near_misses(&d, &self.dut, obs));
                self.report.failures.push(d);
                match self.mode {
                    CollectMode::StopAtFirst => {
                        self.report.stopped_early = true;
                        Action::Stop
                    }
                    CollectMode::Collect => Action::Continue,
                }
            }
        }
    }

    /// A scenario expectation `value & mask == expected & mask` failed on a
    /// register read. If that read's divergence was waived (the latest waived
    /// read with the DUT's value after the first `waived_before`) and the
    /// model's value meets the expectation, the failure is the waived
    /// deviation itself: it is listed in the report as a waived expectation
    /// and the id of the waiver is returned. Otherwise `None`: the
    /// expectation fails (the model would have missed it too, or the read
    /// did not diverge, or it diverged unwaived).
    pub fn waive_expectation(
        &mut self,
        waived_before: usize,
        step: usize,
        what: &str,
        mask: u8,
        expected: u8,
        seen: u8,
    ) -> Option<String> {
        if self.report.waived.len() <= waived_before || seen & mask == expected & mask {
            return None;
        }
        // The read's own divergence, the latest waived register read since
        // `waived_before` with the DUT's value and a model value that meets
        // the expectation: not only the last waived entry, since an earlier
        // step's SR read still in its status window may be decided (and
        // waived) in the same clocks, after this read's own divergence.
        let last = self.report.waived[waived_before..].iter().rev().find(|w| {
            let d = &w.divergence;
            d.kind == diagnose::DivergenceKind::RegisterRead
                && d.seen & 0xFF == seen as u32
                && d.expected <= 0xFF
                && (d.expected as u8) & mask == expected & mask
        })?;
        let model = last.divergence.expected as u8;
        let id = last.waiver_id.clone();
        self.report.waived_expectations.push(WaivedExpectation {
            step,
            what: what.into(),
            expected: format!("0x{:02X} (mask 0x{mask:02X})", expected & mask),
            seen: seen & mask,
            model: model & mask,
            waiver_id: id.clone(),
            consequence: false,
        });
        Some(id)
    }

    /// A scenario expectation failed on a read where the DUT and the model
    /// agree (no divergence to waive). If a waiver lists it among its
    /// `consequences` (`scenario` and `step`) AND that waiver was hit
    /// earlier in this run, the failure is a consequence of the waived
    /// deviation: it is listed in the report as such and the waiver's id is
    /// returned. Otherwise `None`: the expectation fails.
    pub fn waive_consequence(
        &mut self,
        scenario: &str,
        step: usize,
        what: &str,
        mask: u8,
        expected: u8,
        seen: u8,
    ) -> Option<String> {
        if seen & mask == expected & mask {
            return None;
        }
        let id = self.consequence_of(scenario, &ConsequenceOf::Step(step))?;
        self.report.waived_expectations.push(WaivedExpectation {
            step,
            what: what.into(),
            expected: format!("0x{:02X} (mask 0x{mask:02X})", expected & mask),
            seen: seen & mask,
            model: seen & mask,
            waiver_id: id.clone(),
            consequence: true,
        });
        Some(id)
    }

    /// A scenario expectation failed on a read that itself diverged and
    /// whose divergence a waiver took (the last waived one, after the first
    /// `waived_before`), and the model's value misses the expectation too:
    /// the read came at a moment the scenario did not intend (a waived
    /// deviation moved the host's wait), so neither the DUT's nor the
    /// model's value can meet it. Waived only as for
    /// [`Session::waive_consequence`]: the step is listed in a waiver's
    /// `consequences`, and that waiver was hit BEFORE this read. Listed in
    /// the report with the model's value. Otherwise `None`.
    #[allow(clippy::too_many_arguments)]
    pub fn waive_consequence_on_waived_read(
        &mut self,
        waived_before: usize,
        scenario: &str,
        step: usize,
        what: &str,
        mask: u8,
        expected: u8,
        seen: u8,
    ) -> Option<String> {
        if self.report.waived.len() <= waived_before || seen & mask == expected & mask {
            return None;
        }
        let d = &self.report.waived.last()?.divergence;
        if d.kind != diagnose::DivergenceKind::RegisterRead || d.seen & 0xFF != seen as u32 || d.expected > 0xFF {
            return None;
        }
        let model = d.expected as u8;
        // A model value that meets the expectation is the read's own
        // deviation (`waive_expectation`), not a consequence.
        if model & mask == expected & mask {
            return None;
        }
        let of = ConsequenceOf::Step(step);
        let earlier = &self.report.waived[..waived_before];
        let id = self
            .set
            .waivers()
            .iter()
            .find(|w| w.consequences.iter().any(|c| c.scenario == scenario && c.of == of) && earlier.iter().any(|x| x.waiver_id == w.id))
            .map(|w| w.id.clone())?;
        self.report.waived_expectations.push(WaivedExpectation {
            step,
            what: what.into(),
            expected: format!("0x{:02X} (mask 0x{mask:02X})", expected & mask),
            seen: seen & mask,
            model: model & mask,
            waiver_id: id.clone(),
            consequence: true,
        });
        Some(id)
    }

    /// The scenario's count of frames received by model node `node` is
    /// `got`, not `want`: waived (and listed, as step 0) only as for
    /// [`Session::waive_consequence`], with `"<scenario>:received by <node>"`.
    pub fn waive_received_consequence(&mut self, scenario: &str, node: &str, want: u32, got: Option<u32>) -> Option<String> {
        if got == Some(want) {
            return None;
        }
        let id = self.consequence_of(scenario, &ConsequenceOf::Received(node.into()))?;
        let clip = |n: u32| n.min(0xFF) as u8;
        self.report.waived_expectations.push(WaivedExpectation {
            step: 0,
            what: format!("frames received by {node}"),
            expected: want.to_string(),
            seen: got.map_or(0, clip),
            model: got.map_or(0, clip),
            waiver_id: id.clone(),
            consequence: true,
        });
        Some(id)
    }

    /// The first waiver that lists this expectation of `scenario` as a
    /// consequence and was hit earlier in this run.
    fn consequence_of(&self, scenario: &str, of: &ConsequenceOf) -> Option<String> {
        self.set
            .waivers()
            .iter()
            .find(|w| {
                w.consequences.iter().any(|c| c.scenario == scenario && &c.of == of)
                    && self.report.waived.iter().any(|x| x.waiver_id == w.id)
            })
            .map(|w| w.id.clone())
    }

    /// The number of divergences waived so far (pass it to
    /// [`Session::waive_expectation`] from before the read).
    pub fn waived_count(&self) -> usize {
        self.report.waived.len()
    }

    /// The report so far (stale waivers are filled in by `finish`).
    pub fn report(&self) -> &WaiverReport {
        &self.report
    }

    /// The report as if the run ended now (stale waivers included).
    pub fn snapshot(&self) -> WaiverReport {
        let mut r = self.report.clone();
        r.finish(&self.set);
        r
    }

    /// Adds a line to the report's notes, e.g. a resync the reference could not apply.
    pub fn note(&mut self, text: impl Into<String>) {
        self.report.notes.push(text.into());
    }

    /// The DUT.
    pub fn dut(&self) -> &DutInfo {
        &self.dut
    }

    /// Ends the run: the report with stale waivers, and the set (hit counts).
    pub fn finish(mut self) -> (WaiverReport, WaiverSet) {
        self.report.finish(&self.set);
        (self.report, self.set)
    }
}
