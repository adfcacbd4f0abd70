//! Strict expected failures in a regression (the file format is
//! `waivers::expected`). A (scenario, DUT, host) that an
//! `[[expected-failure]]` entry names is run in collect mode, so the whole
//! scenario is judged, and its failure signature is compared with the
//! entry's: exactly the same lines is an expected failure (not a failure of
//! the regression); a pass is an unexpected pass (the entry is stale) and any
//! other failure is a failure, with the lines that differ.

use crate::Scenario;
use crate::run::{RunOptions, RunOutcome};
use waivers::{CollectMode, DutInfo, ExpectedFailure, Place, SignatureDiff, WaiverSet};

/// How a run compared with the expected-failure entry that named it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum XfailVerdict {
    /// Failed with exactly the entry's signature.
    Exact,
    /// Passed: the entry is stale.
    UnexpectedPass,
    /// Failed otherwise: the lines missing from / added to the signature.
    Different(SignatureDiff),
}

/// An entry that named a run, and the verdict.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct XfailResult {
    /// The entry.
    pub entry: ExpectedFailure,
    /// How the run compared.
    pub verdict: XfailVerdict,
}

/// The host a run of `s` with `opts` goes through (its own or the override).
pub fn run_host(s: &Scenario, opts: &RunOptions) -> String {
    opts.host.unwrap_or(s.host).name().to_string()
}

/// The failure signature of a run (see `waivers::expected`): its unwaived
/// divergences, its failed expectations that no waiver took, and the ways
/// its outcome missed `[expect]`; distinct lines, in the order found.
pub fn signature(o: &RunOutcome) -> Vec<String> {
    signature_in(o, Place::Bit)
}

/// [`signature`] with its divergence lines placed as `place` says (by bit
/// time, or by the scenario step they happened in: `waivers::expected`).
pub fn signature_in(o: &RunOutcome, place: Place) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut add = |l: String| {
        let l = waivers::expected::normalise(&l);
        if !lines.contains(&l) {
            lines.push(l);
        }
    };
    let waived: Vec<usize> = o.waivers.as_ref().map_or_else(Vec::new, |r| r.waived_expectations.iter().map(|w| w.step).collect());
    if let Some(r) = &o.waivers {
        for d in &r.failures {
            add(match place {
                Place::Bit => waivers::signature_line(d),
                Place::Step => waivers::signature_line_in_step(d, o.step_at(d.time_ps)),
            });
        }
    }
    for e in o.record.expectations.iter().filter(|e| !e.passed && !waived.contains(&e.step)) {
        add(format!("expectation step {}: {} expected {}, seen {}", e.step, e.what, e.expected, e.seen));
    }
    for m in &o.mismatches {
        add(format!("verdict {m}"));
    }
    lines
}

/// The expected-failure entries of the run's waiver files (the scenario's
/// own and the run's) for `s` through its host, before the DUT is known.
/// A file that does not load gives none: the run itself reports it.
pub fn candidates(s: &Scenario, opts: &RunOptions) -> Vec<ExpectedFailure> {
    let files: Vec<&std::path::PathBuf> = s.waivers.iter().chain(&opts.waivers).collect();
    if files.is_empty() {
        return Vec::new();
    }
    let host = run_host(s, opts);
    match WaiverSet::load_all(&files) {
        Ok(set) => set.expected_failures().iter().filter(|e| e.is_for(&s.name, &host)).cloned().collect(),
        Err(_) => Vec::new(),
    }
}

/// The DUT as the waivers see it after a run ("<profile> (<dir>)" for an
/// external core), with the run's revision.
pub fn waiver_dut(o: &RunOutcome, opts: &RunOptions) -> DutInfo {
    DutInfo {
        name: o.waivers.as_ref().map(|r| r.dut.clone()).unwrap_or_else(|| o.dut.clone()),
        revision: opts.dut_revision.clone(),
        family: o.waivers.as_ref().map(|r| r.family.clone()).unwrap_or_default(),
    }
}

/// Runs `s` with `runner`, judged against the expected-failure entries that
/// name it: with one, in collect mode, and the verdict; with none, as asked.
/// Two entries for the same run are an error (`Err` with both places).
pub fn run_judged(
    s: &Scenario,
    opts: &RunOptions,
    runner: &(impl Fn(&Scenario, &RunOptions) -> RunOutcome + Sync),
) -> (RunOutcome, Result<Option<XfailResult>, String>) {
    let cands = candidates(s, opts);
    if cands.is_empty() {
        return (runner(s, opts), Ok(None));
    }
    let mut collect = opts.clone();
    collect.collect = CollectMode::Collect;
    let out = runner(s, &collect);
    let dut = waiver_dut(&out, opts);
    let hits: Vec<&ExpectedFailure> = cands.iter().filter(|e| e.applies_to(&dut)).collect();
    match hits.as_slice() {
        [] => {
            // Not for this DUT: the run as the user asked for it.
            let out = if opts.collect == CollectMode::Collect { out } else { runner(s, opts) };
            (out, Ok(None))
        }
        [e] => {
            let verdict = judge(e, &out);
            (out, Ok(verdict.map(|verdict| XfailResult { entry: (*e).clone(), verdict })))
        }
        many => {
            let places: Vec<String> = many.iter().map(|e| format!("`{}` ({})", e.id, e.location())).collect();
            (out, Err(format!("{} expected-failure entries name this run: {}; keep one", many.len(), places.join(", "))))
        }
    }
}

/// The verdict of an entry on a run; `None` for a run that was skipped or
/// could not be made (that is not the core's failure: it stays an error).
pub fn judge(e: &ExpectedFailure, o: &RunOutcome) -> Option<XfailVerdict> {
    if o.skipped.is_some() || o.record.error.is_some() {
        return None;
    }
    if o.passed {
        return Some(XfailVerdict::UnexpectedPass);
    }
    let d = e.diff(&signature_in(o, e.place));
    Some(if d.is_exact() { XfailVerdict::Exact } else { XfailVerdict::Different(d) })
}

/// What a regression prints about a run an entry named: one line for an
/// expected failure or an unexpected pass; for another failure, the line
/// and the diff (`- ` missing, `+ ` extra), one signature line each.
pub fn describe(scenario: &str, dut: &str, r: &XfailResult) -> String {
    let e = &r.entry;
    match &r.verdict {
        XfailVerdict::Exact => format!(
            "expected failure {scenario} on {dut}: `{}` ({}, {}; {}): failed with exactly its {} signature line(s)",
            e.id,
            e.deviation,
            e.clause,
            e.location(),
            e.signature.len()
        ),
        XfailVerdict::UnexpectedPass => format!(
            "UNEXPECTED PASS {scenario} on {dut}: expected-failure `{}` ({}, {}) expects a failure and the run passed: the entry is stale (the DUT changed?); remove it",
            e.id,
            e.deviation,
            e.location()
        ),
        XfailVerdict::Different(d) => format!(
            "FAIL {scenario} on {dut}: not the failure expected-failure `{}` ({}, {}) records: {} line(s) missing (-), {} extra (+), judged in collect mode; if the new failure is the right one, re-record it (--record-expected-failures FILE)\n{}",
            e.id,
            e.deviation,
            e.location(),
            d.missing.len(),
            d.extra.len(),
            d.to_text().lines().map(|l| format!("  {l}")).collect::<Vec<_>>().join("\n")
        ),
    }
}
