//! The regression runner: scenarios x DUTs, in parallel (one test bench per
//! worker thread: a Verilated model never crosses threads), a progress bar,
//! JUnit XML, a DUT x scenario table, and shards for CI matrices.

use crate::run::{DutSpec, RunOptions, RunOutcome, run};
use crate::{Scenario, ScenarioError};
use diagnose::Category;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

/// Options of a regression.
#[derive(Clone, Debug, Default)]
pub struct RegressOptions {
    /// Worker threads; 0 = one per core.
    pub jobs: usize,
    /// `(k, n)`: run only the pairs whose index is `k - 1` modulo `n` (k from 1).
    pub shard: Option<(usize, usize)>,
    /// Show a progress bar on stderr.
    pub progress: bool,
    /// Override every scenario's run length (bit times).
    pub max_bits: Option<u64>,
    /// Waiver files for every run (added to each scenario's own).
    pub waivers: Vec<std::path::PathBuf>,
    /// DUT revision the waivers' `revisions` are matched against.
    pub dut_revision: Option<String>,
    /// Stop at the first unwaived divergence (default) or collect them all.
    pub collect: waivers::CollectMode,
    /// Host override for every run (see [`RunOptions::host`]).
    pub host: Option<crate::HostBfm>,
    /// `--coverage DIR`: every run builds its DUT with Verilator's coverage
    /// and writes [`coverage_dat`]`(DIR, dut, scenario)`.
    pub coverage_dir: Option<std::path::PathBuf>,
}

/// Where a run of `scenario` on `dut` writes its coverage counters under
/// `dir`: `dir/dat/<dut>/<scenario>.dat`, names made file-safe.
pub fn coverage_dat(dir: &std::path::Path, dut: &str, scenario: &str) -> std::path::PathBuf {
    dir.join("dat").join(file_safe(dut)).join(format!("{}.dat", file_safe(scenario)))
}

/// `name` with everything but letters, digits, `-`, `_` and `.` as `_`.
pub fn file_safe(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') { c } else { '_' }).collect()
}

/// Parses `--shard k/n` (1 <= k <= n).
pub fn parse_shard(s: &str) -> Result<(usize, usize), String> {
    let (k, n) = s.split_once('/').ok_or_else(|| format!("shard `{s}`: expected k/n, e.g. 2/4"))?;
    let k: usize = k.trim().parse().map_err(|_| format!("shard `{s}`: k is not a number"))?;
    let n: usize = n.trim().parse().map_err(|_| format!("shard `{s}`: n is not a number"))?;
    if n == 0 || k == 0 || k > n {
        return Err(format!("shard `{s}`: need 1 <= k <= n"));
    }
    Ok((k, n))
}

/// Exit codes of `cancosim regress`, chosen for `git bisect run`, which
/// reads 0 as good, 125 as "cannot be tested: skip", and 1..=127 otherwise
/// as bad. Every scenario passed (or was skipped on purpose).
pub const EXIT_PASSED: i32 = 0;
/// A scenario failed, diverged or could not run on a core that built.
pub const EXIT_FAILED: i32 = 1;
/// The user's input is wrong (arguments, an unreadable list, a scenario file
/// that does not load): not the revision's fault, so neither 0 nor 125.
pub const EXIT_BAD_INPUT: i32 = 2;
/// The core does not build (missing directory or sources, no top module,
/// Verilator/GHDL/C++ errors): `git bisect run` skips the revision.
pub const EXIT_UNBUILDABLE: i32 = 125;

/// Verdict of one (scenario, DUT) pair.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Status {
    /// The outcome matched `[expect]`.
    Pass,
    /// The DUT deviates from the golden model; where, in a few words.
    Diverged(String),
    /// The outcome differs from `[expect]` otherwise.
    Failed(String),
    /// The run could not be made (DUT build, bench error).
    Error(String),
    /// Not run, and why (a host override on a scenario whose point is its
    /// host wiring). Not a failure.
    Skipped(String),
    /// Failed with exactly the signature of the `[[expected-failure]]`
    /// entry `id` (deviation `deviation`, e.g. D6). Not a failure.
    ExpectedFailure {
        /// Entry id.
        id: String,
        /// The deviation it documents.
        deviation: String,
    },
    /// Passed although the entry `id` expects a failure: the entry is stale
    /// (the core changed). A failure of the regression.
    UnexpectedPass {
        /// Entry id.
        id: String,
    },
    /// Failed, but not with the signature of the entry `id`: the lines it
    /// did not show (missing) and those it showed besides (extra).
    WrongFailure {
        /// Entry id.
        id: String,
        /// The difference.
        diff: waivers::SignatureDiff,
    },
}

impl Status {
    /// Passed, skipped on purpose, or failed exactly as expected.
    pub fn ok(&self) -> bool {
        matches!(self, Status::Pass | Status::Skipped(_) | Status::ExpectedFailure { .. })
    }
}

/// One cell of the table.
#[derive(Clone, Debug)]
pub struct Cell {
    /// Scenario name.
    pub scenario: String,
    /// DUT name.
    pub dut: String,
    /// Verdict.
    pub status: Status,
    /// Diagnosis category.
    pub category: Category,
    /// Short diagnosis text (for JUnit bodies).
    pub report: String,
    /// Wall time.
    pub wall: Duration,
    /// Waived divergences: (waiver id, divergence in words).
    pub waived: Vec<(String, String)>,
    /// Other remarks of the run (stale waivers are judged over the whole
    /// suite instead: [`RegressReport::stale_warnings`]).
    pub warnings: Vec<String>,
    /// The run had a waiver report (a test bench ran).
    pub had_waivers: bool,
    /// Waivers that matched nothing in this run.
    pub stale: Vec<waivers::Stale>,
    /// The run stopped at its first unwaived divergence.
    pub stopped_early: bool,
    /// The waivers that matched in this run, in plain words, with counts.
    pub deviations: Vec<diagnose::WaivedDeviation>,
    /// What the run exercised, seen from the golden model's side (None: no
    /// run, or skipped).
    pub funcov: Option<funcov::Coverage>,
    /// The expected-failure entry that named this run, and its verdict.
    pub xfail: Option<crate::xfail::XfailResult>,
    /// The run's failure signature (`crate::xfail::signature`; empty if it passed).
    pub signature: Vec<String>,
    /// The same with its divergences placed by step (`waivers::Place::Step`).
    pub step_signature: Vec<String>,
    /// The DUT's name as waivers and expected failures match it.
    pub waiver_dut: String,
    /// The host the run went through (its own or the override).
    pub host: String,
}

impl Cell {
    /// The cell of one run (its verdict from the outcome and `[expect]`).
    pub fn from_outcome(scenario: &str, o: &RunOutcome) -> Cell {
        let d = &o.diagnosis;
        let status = if let Some(why) = &o.skipped {
            Status::Skipped(why.clone())
        } else if o.passed {
            Status::Pass
        } else if d.category == Category::DutDeviatesFromModel {
            let f = &d.figures;
            let mut w = Vec::new();
            if let Some(x) = f.field {
                w.push(format!("{x:?}"));
            }
            if let Some(x) = f.frame {
                w.push(format!("frame {x}"));
            }
            if let Some(x) = f.bit {
                w.push(format!("bit {x}"));
            }
            if let Some(x) = &f.register {
                w.push(x.clone());
            }
            Status::Diverged(w.join(" "))
        } else if d.category == Category::RunError {
            Status::Error(o.record.error.clone().unwrap_or_default())
        } else {
            Status::Failed(o.mismatches.join("; "))
        };
        let waived = o
            .waivers
            .as_ref()
            .map(|r| r.waived.iter().map(|w| (w.waiver_id.clone(), waivers::describe(&w.divergence))).collect())
            .unwrap_or_default();
        let mut report = d.to_text();
        if let Some(r) = o.waivers.as_ref().filter(|r| !r.waived.is_empty() || !r.failures.is_empty() || !r.stale.is_empty()) {
            report.push('\n');
            report += &r.to_text();
        }
        Cell {
            scenario: scenario.into(),
            dut: o.dut.clone(),
            status,
            category: d.category,
            report,
            wall: o.wall,
            waived,
            // Stale waivers are a property of the suite, not of one run.
            warnings: Vec::new(),
            had_waivers: o.waivers.is_some(),
            stale: o.waivers.as_ref().map(|r| r.stale.clone()).unwrap_or_default(),
            stopped_early: o.waivers.as_ref().is_some_and(|r| r.stopped_early),
            deviations: o.waivers.as_ref().map(|r| r.deviations.clone()).unwrap_or_default(),
            funcov: o.skipped.is_none().then(|| run_funcov(o)),
            xfail: None,
            signature: if o.passed || o.skipped.is_some() { Vec::new() } else { crate::xfail::signature(o) },
            step_signature: if o.passed || o.skipped.is_some() { Vec::new() } else { crate::xfail::signature_in(o, waivers::Place::Step) },
            waiver_dut: o.waivers.as_ref().map(|r| r.dut.clone()).unwrap_or_else(|| o.dut.clone()),
            host: String::new(),
        }
    }

    /// Applies the verdict of an expected-failure entry (or the error of
    /// two entries naming one run) to a cell made from the run.
    fn judged(mut self, x: Result<Option<crate::xfail::XfailResult>, String>) -> Cell {
        use crate::xfail::XfailVerdict;
        match x {
            Ok(None) => {}
            Err(e) => {
                self.report = format!("{e}\n{}", self.report);
                self.status = Status::Error(e);
            }
            Ok(Some(r)) => {
                let id = r.entry.id.clone();
                // A run that was not made stays an error (judge gives no verdict then).
                self.status = match &r.verdict {
                    XfailVerdict::Exact => Status::ExpectedFailure { id, deviation: r.entry.deviation.clone() },
                    XfailVerdict::UnexpectedPass => Status::UnexpectedPass { id },
                    XfailVerdict::Different(d) => Status::WrongFailure { id, diff: d.clone() },
                };
                self.report = format!("{}\n{}", crate::xfail::describe(&self.scenario, &self.dut, &r), self.report);
                self.xfail = Some(r);
            }
        }
        self
    }
}

/// Functional coverage of one run: its record and its bus frames.
pub fn run_funcov(o: &RunOutcome) -> funcov::Coverage {
    let frames: Vec<funcov::BusFrame> = o
        .bus_log
        .iter()
        .filter_map(|e| match e.kind {
            cosim::candump::LogKind::Frame(frame) => Some(funcov::BusFrame { t_ps: e.t_ps, frame }),
            _ => None,
        })
        .collect();
    let mut c = funcov::Coverage::new();
    c.observe(&o.record, &frames);
    c
}

/// A waiver that matched on a DUT somewhere in the suite.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WaiverUse {
    /// The deviation (hits summed over the scenarios).
    pub deviation: diagnose::WaivedDeviation,
    /// Scenarios in which it matched.
    pub scenarios: Vec<String>,
}

/// All cells of a regression.
#[derive(Clone, Debug, Default)]
pub struct RegressReport {
    /// Scenario names, in order.
    pub scenarios: Vec<String>,
    /// DUT names, in order.
    pub duts: Vec<String>,
    /// Cells that ran (a shard runs a subset).
    pub cells: Vec<Cell>,
    /// Scenarios that could not be loaded (their error cells are in
    /// `cells`): the user's input, so the exit code is [`EXIT_BAD_INPUT`].
    pub unloadable: Vec<String>,
}

impl RegressReport {
    /// Functional coverage on `dut`, merged over the scenarios that ran.
    pub fn funcov(&self, dut: &str) -> funcov::Coverage {
        let mut c = funcov::Coverage::new();
        for f in self.cells.iter().filter(|c| c.dut == dut).filter_map(|c| c.funcov.as_ref()) {
            c.merge(f);
        }
        c
    }

    /// Cells that failed exactly as an `[[expected-failure]]` entry records.
    pub fn expected_failures(&self) -> usize {
        self.cells.iter().filter(|c| matches!(c.status, Status::ExpectedFailure { .. })).count()
    }

    /// True if every cell passed, was skipped on purpose, or failed exactly
    /// as expected (no unexpected pass, no other failure).
    pub fn passed(&self) -> bool {
        self.cells.iter().all(|c| c.status.ok())
    }

    /// Process exit code: [`EXIT_BAD_INPUT`] if a scenario could not be
    /// loaded (after the others ran), else [`EXIT_PASSED`] if all passed,
    /// else [`EXIT_FAILED`].
    pub fn exit_code(&self) -> i32 {
        if !self.unloadable.is_empty() {
            EXIT_BAD_INPUT
        } else if self.passed() {
            EXIT_PASSED
        } else {
            EXIT_FAILED
        }
    }

    /// The waivers that matched on `dut`, in order of first use, with hits
    /// summed over the suite and the scenarios that hit them.
    pub fn waivers_hit(&self, dut: &str) -> Vec<WaiverUse> {
        let mut out: Vec<WaiverUse> = Vec::new();
        for c in self.cells.iter().filter(|c| c.dut == dut) {
            for d in &c.deviations {
                match out.iter_mut().find(|u| u.deviation.waiver_id == d.waiver_id) {
                    Some(u) => {
                        u.deviation.hits += d.hits;
                        u.deviation.episodes += d.episodes;
                        u.scenarios.push(c.scenario.clone());
                    }
                    None => out.push(WaiverUse { deviation: d.clone(), scenarios: vec![c.scenario.clone()] }),
                }
            }
        }
        out
    }

    /// Stale waivers, judged over the suite: a waiver is stale on a DUT only
    /// if it matched in none of the scenarios run on it. One line per
    /// (DUT, waiver); when some of those runs stopped at a failure, the line
    /// says the waiver may not have been reached instead.
    pub fn stale_warnings(&self) -> Vec<(String, String)> {
        let mut out = Vec::new();
        for dut in &self.duts {
            let runs: Vec<&Cell> = self.cells.iter().filter(|c| &c.dut == dut && c.had_waivers).collect();
            let used: std::collections::BTreeSet<&str> = runs.iter().flat_map(|c| c.deviations.iter().map(|d| d.waiver_id.as_str())).collect();
            let mut seen = std::collections::BTreeSet::new();
            for st in runs.iter().flat_map(|c| c.stale.iter()) {
                if used.contains(st.waiver_id.as_str()) || !seen.insert((st.waiver_id.clone(), st.location.clone())) {
                    continue;
                }
                let with: Vec<&&Cell> = runs.iter().filter(|c| c.stale.contains(st)).collect();
                let stopped = with.iter().filter(|c| c.stopped_early).count();
                let n = with.len();
                let line = if stopped == 0 {
                    format!("stale waiver `{}` ({}) never matched in the {n} scenario(s) run on {dut}: remove it or check it still applies", st.waiver_id, st.location)
                } else {
                    format!(
                        "waiver `{}` ({}) never matched in the {n} scenario(s) run on {dut}, but {stopped} of them stopped at a failure: it may not have got that far",
                        st.waiver_id, st.location
                    )
                };
                out.push((dut.clone(), line));
            }
        }
        out
    }

    /// The waivers hit per DUT, one line each: id, hits, scenarios, the
    /// deviation in plain words.
    pub fn waivers_text(&self) -> String {
        let mut out = String::new();
        for dut in &self.duts {
            let used = self.waivers_hit(dut);
            if used.is_empty() {
                continue;
            }
            out += &format!("known deviations waived on {dut} ({} waiver(s)):\n", used.len());
            for u in &used {
                let d = &u.deviation;
                out += &format!(
                    "  {} x{} in {} scenario(s){}: {}{}\n",
                    d.waiver_id,
                    d.hits,
                    u.scenarios.len(),
                    d.bound_text(),
                    d.summary,
                    d.clause.as_ref().map(|c| format!(" ({c})")).unwrap_or_default()
                );
            }
        }
        out
    }

    fn cell(&self, s: &str, d: &str) -> Option<&Cell> {
        self.cells.iter().find(|c| c.scenario == s && c.dut == d)
    }

    /// The DUT x scenario table: one row per scenario, one column per DUT.
    pub fn to_table(&self) -> String {
        let text = |c: Option<&Cell>| match c {
            None => "-".to_string(),
            Some(c) => match &c.status {
                Status::Pass if !c.waived.is_empty() => format!("pass ({} waived)", c.waived.len()),
                Status::Pass => format!("pass ({})", c.category),
                Status::Diverged(w) => format!("diverged ({w})"),
                Status::Failed(_) => format!("FAIL ({})", c.category),
                Status::Error(e) => format!("error ({})", e.chars().take(40).collect::<String>()),
                Status::Skipped(_) => "skipped (host fixed)".to_string(),
                Status::ExpectedFailure { id, deviation } => format!("xfail ({deviation}: {id})"),
                Status::UnexpectedPass { id } => format!("UNEXPECTED PASS ({id})"),
                Status::WrongFailure { id, diff } => format!("FAIL (not as {id}: -{} +{})", diff.missing.len(), diff.extra.len()),
            },
        };
        let mut rows: Vec<Vec<String>> = vec![std::iter::once("scenario".to_string()).chain(self.duts.iter().cloned()).collect()];
        for s in &self.scenarios {
            rows.push(std::iter::once(s.clone()).chain(self.duts.iter().map(|d| text(self.cell(s, d)))).collect());
        }
        let cols = rows[0].len();
        let widths: Vec<usize> = (0..cols).map(|i| rows.iter().map(|r| r[i].chars().count()).max().unwrap_or(0)).collect();
        let mut out = String::new();
        for (n, r) in rows.iter().enumerate() {
            let line: Vec<String> = r.iter().enumerate().map(|(i, c)| format!("{c:<w$}", w = widths[i])).collect();
            out += line.join(" | ").trim_end();
            out.push('\n');
            if n == 0 {
                out += &widths.iter().map(|w| "-".repeat(*w)).collect::<Vec<_>>().join("-+-");
                out.push('\n');
            }
        }
        let failed = self.cells.iter().filter(|c| !c.status.ok()).count();
        let skipped: Vec<&Cell> = self.cells.iter().filter(|c| matches!(c.status, Status::Skipped(_))).collect();
        let xfails = self.expected_failures();
        out += &format!(
            "{} run, {} passed, {}{} not passed{}\n",
            self.cells.len() - skipped.len(),
            self.cells.len() - failed - skipped.len() - xfails,
            if xfails == 0 { String::new() } else { format!("{xfails} expected failure(s), ") },
            failed,
            if skipped.is_empty() { String::new() } else { format!(", {} skipped", skipped.len()) }
        );
        for c in &self.cells {
            if let Some(r) = &c.xfail {
                out += &crate::xfail::describe(&c.scenario, &c.dut, r);
                out.push('\n');
            }
        }
        for c in &skipped {
            if let Status::Skipped(why) = &c.status {
                out += &format!("skipped {} on {}: {why}\n", c.scenario, c.dut);
            }
        }
        let waived: usize = self.cells.iter().map(|c| c.waived.len()).sum();
        if waived > 0 {
            out += &format!("{waived} divergence(s) waived\n");
        }
        out += &self.waivers_text();
        for c in &self.cells {
            for w in &c.warnings {
                out += &format!("WARNING {} on {}: {w}\n", c.scenario, c.dut);
            }
        }
        for (_, w) in self.stale_warnings() {
            out += &format!("WARNING {w}\n");
        }
        out
    }

    /// JSON: the counts and one object per cell (scenario, DUT, host,
    /// status, detail, waived divergences; for a run an expected-failure
    /// entry named, the entry and its verdict with the missing / extra
    /// signature lines). Exit code and `passed` as for the table.
    pub fn to_json(&self) -> String {
        use serde_json::json;
        let cells: Vec<serde_json::Value> = self
            .cells
            .iter()
            .map(|c| {
                let (status, detail) = match &c.status {
                    Status::Pass => ("pass", String::new()),
                    Status::Diverged(x) => ("diverged", x.clone()),
                    Status::Failed(x) => ("failed", x.clone()),
                    Status::Error(x) => ("error", x.clone()),
                    Status::Skipped(x) => ("skipped", x.clone()),
                    Status::ExpectedFailure { .. } => ("expected-failure", String::new()),
                    Status::UnexpectedPass { .. } => ("unexpected-pass", String::new()),
                    Status::WrongFailure { .. } => ("wrong-failure", String::new()),
                };
                let xfail = c.xfail.as_ref().map(|r| {
                    let (verdict, missing, extra) = match &r.verdict {
                        crate::xfail::XfailVerdict::Exact => ("exact", Vec::new(), Vec::new()),
                        crate::xfail::XfailVerdict::UnexpectedPass => ("unexpected-pass", Vec::new(), Vec::new()),
                        crate::xfail::XfailVerdict::Different(d) => ("different", d.missing.clone(), d.extra.clone()),
                    };
                    json!({
                        "id": r.entry.id, "deviation": r.entry.deviation, "clause": r.entry.clause,
                        "reason": r.entry.reason, "location": r.entry.location(), "verdict": verdict,
                        "missing": missing, "extra": extra,
                    })
                });
                json!({
                    "scenario": c.scenario, "dut": c.dut, "waiver_dut": c.waiver_dut, "host": c.host,
                    "status": status, "ok": c.status.ok(), "detail": detail, "category": c.category.name(),
                    "waived": c.waived.len(), "signature": c.signature, "expected_failure": xfail,
                })
            })
            .collect();
        let skipped = self.cells.iter().filter(|c| matches!(c.status, Status::Skipped(_))).count();
        let not_passed = self.cells.iter().filter(|c| !c.status.ok()).count();
        let xfails = self.expected_failures();
        let out = json!({
            "run": self.cells.len() - skipped,
            "passed": self.cells.len() - skipped - not_passed - xfails,
            "expected_failures": xfails,
            "not_passed": not_passed,
            "skipped": skipped,
            "ok": self.passed(),
            "cells": cells,
        });
        serde_json::to_string_pretty(&out).expect("a JSON value always serialises")
    }

    /// JUnit XML: one testsuite per DUT, one testcase per scenario.
    pub fn to_junit(&self) -> String {
        use quick_junit::{NonSuccessKind, Report, TestCase, TestCaseStatus, TestSuite};
        let secs = |c: &Cell| std::time::Duration::from_secs_f64(c.wall.as_secs_f64());
        let mut report = Report::new("cancosim regression");
        for d in &self.duts {
            let cells: Vec<&Cell> = self.cells.iter().filter(|c| &c.dut == d).collect();
            let mut suite = TestSuite::new(d.as_str());
            let mut warnings: Vec<String> =
                cells.iter().flat_map(|c| c.warnings.iter().map(move |w| format!("{}: {w}", c.scenario))).collect();
            warnings.extend(self.stale_warnings().into_iter().filter(|(x, _)| x == d).map(|(_, w)| format!("warning: {w}")));
            let hit: Vec<String> = self
                .waivers_hit(d)
                .iter()
                .map(|u| format!("waived {} x{} in {}: {}", u.deviation.waiver_id, u.deviation.hits, u.scenarios.join(", "), u.deviation.describe()))
                .collect();
            for c in &cells {
                // Each waived divergence is its own skipped testcase, so CI
                // shows what was let through and by which waiver.
                for (n, (id, what)) in c.waived.iter().enumerate() {
                    let mut status = TestCaseStatus::skipped();
                    status.set_message(format!("waived by {id}"));
                    let mut tc = TestCase::new(format!("{} waived {}: {what}", c.scenario, n + 1), status);
                    tc.set_classname(format!("{}.waivers", c.dut));
                    suite.add_test_case(tc);
                }
            }
            for c in cells {
                let status = match &c.status {
                    Status::Pass => TestCaseStatus::success(),
                    Status::Skipped(why) => {
                        let mut s = TestCaseStatus::skipped();
                        s.set_message(why.as_str());
                        s
                    }
                    // JUnit has no expected-failure state: skipped with the
                    // entry named in the message (as pytest's junitxml does
                    // for xfail), so CI counts it as not failing yet shows it
                    // apart from passes; the signature goes to system-out.
                    Status::ExpectedFailure { id, deviation } => {
                        let mut s = TestCaseStatus::skipped();
                        let reason = c.xfail.as_ref().map(|r| r.entry.reason.as_str()).unwrap_or("");
                        s.set_message(format!("expected failure {id} ({deviation}): {reason}")).set_type("xfail");
                        s
                    }
                    Status::Diverged(_) | Status::Failed(_) | Status::Error(_) | Status::UnexpectedPass { .. } | Status::WrongFailure { .. } => {
                        let (kind, msg) = match &c.status {
                            Status::Diverged(x) => (NonSuccessKind::Failure, format!("diverged from the golden model: {x}")),
                            Status::Failed(x) => (NonSuccessKind::Failure, x.clone()),
                            Status::Error(x) => (NonSuccessKind::Error, x.clone()),
                            Status::UnexpectedPass { id } => (NonSuccessKind::Failure, format!("unexpected pass: expected-failure {id} is stale")),
                            Status::WrongFailure { id, diff } => (
                                NonSuccessKind::Failure,
                                format!("not the failure expected-failure {id} records: {} line(s) missing, {} extra", diff.missing.len(), diff.extra.len()),
                            ),
                            _ => unreachable!(),
                        };
                        let mut s = TestCaseStatus::non_success(kind);
                        s.set_message(msg).set_type(c.category.name()).set_description(c.report.as_str());
                        s
                    }
                };
                let mut tc = TestCase::new(c.scenario.as_str(), status);
                tc.set_classname(c.dut.as_str()).set_time(secs(c));
                if let Some(r) = &c.xfail {
                    tc.set_system_out(format!("{}\nsignature of the run:\n{}", crate::xfail::describe(&c.scenario, &c.dut, r), c.signature.join("\n")));
                }
                suite.add_test_case(tc);
            }
            if !hit.is_empty() {
                suite.set_system_out(hit.join("\n"));
            }
            // Functional coverage (golden model's side) as properties:
            // the total, each group, and the holes by name.
            let fc = self.funcov(d);
            let pct = |g: &funcov::GroupSummary| format!("{}/{} ({:.1}%)", g.hit, g.total, g.percent());
            suite.add_property(quick_junit::Property::new("funcov", pct(&fc.totals())));
            for g in fc.summary() {
                suite.add_property(quick_junit::Property::new(format!("funcov {}", g.group), pct(&g)));
            }
            for g in fc.summary().iter().filter(|g| g.hit < g.total) {
                suite.add_property(quick_junit::Property::new(format!("funcov holes {}", g.group), fc.holes_in(&g.group).join(", ")));
            }
            // Bins marked unreachable (not counted above), each with its reason.
            for b in fc.unreachable() {
                suite.add_property(quick_junit::Property::new(format!("funcov unreachable {}: {}", b.group, b.name), b.unreachable.clone().unwrap_or_default()));
            }
            if !warnings.is_empty() {
                suite.set_system_err(warnings.join("\n"));
            }
            report.add_test_suite(suite);
        }
        report.to_string().expect("quick-junit writes a report to a String")
    }
}

/// Runs every (scenario, DUT) pair of the shard, in parallel.
pub fn regress(scenarios: &[Scenario], duts: &[DutSpec], opts: &RegressOptions) -> RegressReport {
    regress_with(scenarios, duts, opts, run)
}

/// [`regress`] with the runner given (tests use it to inject outcomes).
pub fn regress_with(
    scenarios: &[Scenario],
    duts: &[DutSpec],
    opts: &RegressOptions,
    runner: impl Fn(&Scenario, &RunOptions) -> RunOutcome + Sync,
) -> RegressReport {
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for si in 0..scenarios.len() {
        for di in 0..duts.len() {
            pairs.push((si, di));
        }
    }
    if let Some((k, n)) = opts.shard {
        pairs = pairs.into_iter().enumerate().filter(|(i, _)| i % n == k - 1).map(|(_, p)| p).collect();
    }
    let jobs = if opts.jobs == 0 { std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1) } else { opts.jobs };
    let bar = if opts.progress { indicatif::ProgressBar::new(pairs.len() as u64) } else { indicatif::ProgressBar::hidden() };
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {elapsed} {msg}").unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Cell>>> = Mutex::new(vec![None; pairs.len()]);
    std::thread::scope(|sc| {
        for _ in 0..jobs.min(pairs.len()).max(1) {
            sc.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(&(si, di)) = pairs.get(i) else { break };
                    let s = &scenarios[si];
                    let o = RunOptions {
                        dut: Some(duts[di].clone()),
                        max_bits: opts.max_bits,
                        waivers: opts.waivers.clone(),
                        dut_revision: opts.dut_revision.clone(),
                        collect: opts.collect,
                        host: opts.host,
                        // The golden model as DUT has no code to cover.
                        coverage_dat: opts.coverage_dir.as_deref().filter(|_| duts[di].kind != crate::DutKind::Model).map(|d| coverage_dat(d, &duts[di].name, &s.name)),
                        ..Default::default()
                    };
                    if let Some(dir) = o.coverage_dat.as_deref().and_then(std::path::Path::parent) {
                        // A failure shows as a missing .dat, which the merge reports.
                        let _ = std::fs::create_dir_all(dir);
                    }
                    let (out, xfail) = crate::xfail::run_judged(s, &o, &runner);
                    let mut cell = Cell::from_outcome(&s.name, &out).judged(xfail);
                    cell.host = crate::xfail::run_host(s, &o);
                    bar.set_message(format!("{} on {}", s.name, duts[di].name));
                    bar.inc(1);
                    results.lock().expect("no worker panics while holding the lock")[i] = Some(cell);
                }
            });
        }
    });
    bar.finish_and_clear();
    RegressReport {
        scenarios: scenarios.iter().map(|s| s.name.clone()).collect(),
        duts: duts.iter().map(|d| d.name.clone()).collect(),
        cells: results.into_inner().unwrap_or_default().into_iter().flatten().collect(),
        unloadable: Vec::new(),
    }
}

/// A scenario that could not be loaded: its name (the file stem) and why.
fn unloadable(path: &std::path::Path, e: &ScenarioError) -> (String, String) {
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| path.display().to_string());
    (name, e.to_string())
}

/// Loads every input (a `.toml` scenario or a regression list) and runs
/// [`regress`]. A scenario that cannot be loaded (bad key, missing file)
/// does not stop the others: it becomes an error cell on every DUT with its
/// `file:line:col: key` message, and the exit code is [`EXIT_BAD_INPUT`]. Only an
/// unreadable list is an error. With a shard, those cells go to shard 1.
pub fn regress_inputs(inputs: &[std::path::PathBuf], duts: &[DutSpec], opts: &RegressOptions) -> Result<RegressReport, ScenarioError> {
    let mut scenarios = Vec::new();
    let mut bad = Vec::new();
    for p in inputs {
        let entries = if p.extension().is_some_and(|e| e == "toml") {
            vec![(p.clone(), Scenario::load(p))]
        } else {
            crate::load_list_entries(p)?
        };
        for (path, r) in entries {
            match r {
                Ok(s) => scenarios.push(s),
                Err(e) => bad.push(unloadable(&path, &e)),
            }
        }
    }
    let mut report = regress(&scenarios, duts, opts);
    if opts.shard.is_none_or(|(k, _)| k == 1) {
        for (name, msg) in bad {
            for d in duts {
                report.cells.push(Cell {
                    scenario: name.clone(),
                    dut: d.name.clone(),
                    status: Status::Error(msg.clone()),
                    category: Category::RunError,
                    report: msg.clone(),
                    wall: Duration::ZERO,
                    waived: Vec::new(),
                    warnings: Vec::new(),
                    had_waivers: false,
                    stale: Vec::new(),
                    stopped_early: false,
                    deviations: Vec::new(),
                    funcov: None,
                    xfail: None,
                    signature: Vec::new(),
                    step_signature: Vec::new(),
                    waiver_dut: d.name.clone(),
                    host: String::new(),
                });
            }
            report.scenarios.push(name.clone());
            report.unloadable.push(name);
        }
    }
    Ok(report)
}
