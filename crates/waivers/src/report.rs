//! What a run did with its divergences: waived ones apart from failures,
//! stale waivers as warnings, in text, JSON and JUnit XML.

use std::fmt::Write as _;

use diagnose::{Divergence, DivergenceKind};
use serde::{Deserialize, Serialize};

use crate::file::KindName;
use crate::dut::{DutInfo, DutMatch, FamilyMember};
use crate::set::WaiverSet;

/// A divergence a waiver covered.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Waived {
    /// The divergence.
    pub divergence: Divergence,
    /// The waiver that covered it.
    pub waiver_id: String,
}

/// A scenario expectation that failed on a read a waiver covered: the DUT's
/// value missed it, the model's met it. Counted as waived, and listed.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct WaivedExpectation {
    /// Scenario step (1-based).
    pub step: usize,
    /// What was checked.
    pub what: String,
    /// Expected value and mask, as text.
    pub expected: String,
    /// The DUT's value (masked).
    pub seen: u8,
    /// The model's value (masked), which met the expectation.
    pub model: u8,
    /// The waiver that covered the read.
    pub waiver_id: String,
    /// True if DUT and model agreed on the read and the expectation is a
    /// listed consequence of the waiver (its `consequences`), waived
    /// because the waiver was hit earlier in the run.
    #[serde(default)]
    pub consequence: bool,
}

/// A waiver that never matched during the run.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stale {
    /// Waiver id.
    pub waiver_id: String,
    /// Where it is written (`file:line`).
    pub location: String,
}

/// The divergences of one run, sorted into waived and failures.
///
/// A run passes when there is no failure; stale waivers are warnings.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WaiverReport {
    /// DUT name.
    pub dut: String,
    /// DUT revision.
    pub revision: Option<String>,
    /// The DUT's names through its profile family (profiles it extends).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub family: Vec<FamilyMember>,
    /// Waiver file (empty if none).
    pub waiver_file: String,
    /// Divergences covered by a waiver, in the order seen.
    pub waived: Vec<Waived>,
    /// Divergences no waiver covered, in the order seen.
    pub failures: Vec<Divergence>,
    /// Scenario expectations that failed only on a waived read.
    #[serde(default)]
    pub waived_expectations: Vec<WaivedExpectation>,
    /// Why nearby waivers did not cover a failure, one line each.
    pub notes: Vec<String>,
    /// Waivers that never matched.
    pub stale: Vec<Stale>,
    /// The waivers that matched, in file order: the deviations the DUT
    /// showed, in plain words, with their hit counts.
    #[serde(default)]
    pub deviations: Vec<diagnose::WaivedDeviation>,
    /// The comparator stopped at the first failure (`--stop-at-first`).
    pub stopped_early: bool,
}

/// Counts for summaries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    /// Waived divergences.
    pub waived: usize,
    /// Failures.
    pub failures: usize,
    /// Stale waivers.
    pub stale: usize,
    /// Expectations that failed on a waived read.
    #[serde(default)]
    pub waived_expectations: usize,
}

/// One line describing a divergence: kind, where, values, context.
pub fn describe(d: &Divergence) -> String {
    let mut s = String::from(KindName::of(d.kind).as_str());
    if let Some(r) = &d.register {
        let _ = write!(s, " {r}");
    }
    if let Some(b) = d.bit {
        let _ = write!(s, " at bit {b}");
    }
    let _ = write!(s, " ({} ps", d.time_ps);
    if let Some(f) = d.frame {
        let _ = write!(s, ", frame {f}");
    }
    if let Some(f) = d.field {
        let _ = write!(s, ", {f:?}");
    }
    s.push(')');
    match d.kind {
        DivergenceKind::RegisterRead => {
            let _ = write!(s, ": model 0x{:02X}, DUT 0x{:02X}", d.expected, d.seen);
        }
        _ => {
            let _ = write!(s, ": model {}, DUT {}", d.expected, d.seen);
        }
    }
    if !d.context.is_empty() {
        let _ = write!(s, "; {}", d.context);
    }
    s
}

impl WaiverReport {
    /// An empty report for `dut` checked against `set`.
    pub fn new(set: &WaiverSet, dut: &DutInfo) -> Self {
        WaiverReport {
            dut: dut.name.clone(),
            revision: dut.revision.clone(),
            family: dut.family.clone(),
            waiver_file: set.name.clone(),
            ..Default::default()
        }
    }

    /// Fills `stale` from the set's hit counts (call at the end of the run).
    pub fn finish(&mut self, set: &WaiverSet) {
        self.stale = set
            .stale()
            .into_iter()
            .map(|w| Stale { waiver_id: w.id.clone(), location: format!("{}:{}", w.file, w.line) })
            .collect();
        let dut = self.dut_info();
        self.deviations = set
            .waivers()
            .iter()
            .filter(|w| w.hits > 0)
            .map(|w| {
                let mut d = w.deviation(w.hits);
                if let Some(DutMatch::Via(p)) = w.matched_by(&dut) {
                    d.via = Some(p.to_string());
                }
                d
            })
            .collect();
    }

    /// Counts.
    pub fn counts(&self) -> Counts {
        Counts {
            waived: self.waived.len(),
            failures: self.failures.len(),
            stale: self.stale.len(),
            waived_expectations: self.waived_expectations.len(),
        }
    }

    /// No unwaived divergence.
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }

    /// One warning per stale waiver.
    pub fn warnings(&self) -> Vec<String> {
        let why = if self.stopped_early {
            " (the run stopped at a failure: it may not have got that far)"
        } else {
            ": remove it or check it still applies"
        };
        self.stale
            .iter()
            .map(|s| format!("stale waiver `{}` ({}) never matched{why}", s.waiver_id, s.location))
            .collect()
    }

    /// The DUT the report is for, as the waivers saw it.
    pub fn dut_info(&self) -> DutInfo {
        DutInfo { name: self.dut.clone(), revision: self.revision.clone(), family: self.family.clone() }
    }

    fn dut_label(&self) -> String {
        match &self.revision {
            Some(r) => format!("{} {r}", self.dut),
            None => self.dut.clone(),
        }
    }

    /// Plain text: summary line, failures, waived, warnings, verdict.
    pub fn to_text(&self) -> String {
        let c = self.counts();
        let mut s = String::new();
        let file = if self.waiver_file.is_empty() { "no waiver file".into() } else { self.waiver_file.clone() };
        let _ = writeln!(s, "waivers: {} against {file}", self.dut_label());
        let _ = writeln!(
            s,
            "{} divergence(s): {} failure(s), {} waived; {} stale waiver(s){}",
            c.failures + c.waived,
            c.failures,
            c.waived,
            c.stale,
            if self.stopped_early { "; stopped at the first failure (--stop-at-first)" } else { "" }
        );
        for d in &self.failures {
            let _ = writeln!(s, "FAIL   {}", describe(d));
        }
        for n in &self.notes {
            let _ = writeln!(s, "       note: {n}");
        }
        for w in &self.waived {
            let _ = writeln!(s, "WAIVED [{}] {}", w.waiver_id, describe(&w.divergence));
        }
        for d in self.deviations.iter().filter(|d| d.via.is_some()) {
            let _ = writeln!(s, "VIA    waiver {} applied via family member {}", d.waiver_id, d.via.as_deref().unwrap_or_default());
        }
        for e in &self.waived_expectations {
            let _ = writeln!(
                s,
                "WAIVED [{}] expectation of step {}: {}: expected {}, DUT 0x{:02X} (model 0x{:02X}){}",
                e.waiver_id,
                if e.step == 0 { "-".to_string() } else { e.step.to_string() },
                e.what,
                e.expected,
                e.seen,
                e.model,
                if e.consequence { format!(" (a listed consequence of waiver {}, hit earlier)", e.waiver_id) } else { String::new() }
            );
        }
        for w in self.warnings() {
            let _ = writeln!(s, "WARNING {w}");
        }
        let verdict = match (self.passed(), c.stale) {
            (false, _) => "FAIL".to_string(),
            (true, 0) => "PASS".to_string(),
            (true, n) => format!("PASS with {n} warning(s)"),
        };
        let _ = writeln!(s, "result: {verdict}");
        s
    }

    /// Pretty JSON of the whole report, with `counts`, `passed` and
    /// `warnings` added (reading it back as a `WaiverReport` ignores them).
    pub fn to_json(&self) -> String {
        #[derive(Serialize)]
        struct Out<'a> {
            counts: Counts,
            passed: bool,
            warnings: Vec<String>,
            #[serde(flatten)]
            report: &'a WaiverReport,
        }
        let out = Out { counts: self.counts(), passed: self.passed(), warnings: self.warnings(), report: self };
        serde_json::to_string_pretty(&out).expect("a WaiverReport always serialises")
    }

    /// JUnit XML (written by `quick-junit`): a `<testsuites>` holding one
    /// `<testsuite>` named `suite` with one `<testcase>` per divergence,
    /// failures with `<failure>`, waived ones with `<skipped message="waived
    /// by ID">`, stale-waiver warnings in the suite's `<system-err>`.
    pub fn to_junit(&self, suite: &str) -> String {
        use quick_junit::{NonSuccessKind, Report, TestCase, TestCaseStatus, TestSuite};
        let classname = format!("waivers.{}", self.dut);
        let mut ts = TestSuite::new(suite);
        let mut n = 0;
        for d in &self.failures {
            n += 1;
            let mut status = TestCaseStatus::non_success(NonSuccessKind::Failure);
            status.set_message(describe(d)).set_type(KindName::of(d.kind).as_str()).set_description(d.context.as_str());
            let mut tc = TestCase::new(format!("divergence {n}: {}", short(d)), status);
            tc.set_classname(classname.as_str());
            ts.add_test_case(tc);
        }
        for x in &self.waived {
            n += 1;
            let msg = format!("waived by {}", x.waiver_id);
            let mut status = TestCaseStatus::skipped();
            status.set_message(msg.as_str());
            let mut tc = TestCase::new(format!("divergence {n}: {}", short(&x.divergence)), status);
            tc.set_classname(classname.as_str()).set_system_out(format!("{msg}: {}", describe(&x.divergence)));
            ts.add_test_case(tc);
        }
        for e in &self.waived_expectations {
            n += 1;
            let mut status = TestCaseStatus::skipped();
            status.set_message(if e.consequence {
                format!("waived: a listed consequence of waiver {}, hit earlier in the run", e.waiver_id)
            } else {
                format!("waived by {}", e.waiver_id)
            });
            let mut tc = TestCase::new(format!("expectation {n}: step {} {}", e.step, e.what), status);
            tc.set_classname(classname.as_str());
            ts.add_test_case(tc);
        }
        let warnings = self.warnings();
        if !warnings.is_empty() {
            ts.set_system_err(warnings.iter().map(|x| format!("warning: {x}")).collect::<Vec<_>>().join("\n"));
        }
        let mut report = Report::new(suite);
        report.add_test_suite(ts);
        report.to_string().expect("quick-junit writes a report to a String")
    }
}

/// Short name of a divergence for a JUnit test case.
fn short(d: &Divergence) -> String {
    let mut s = String::from(KindName::of(d.kind).as_str());
    if let Some(r) = &d.register {
        let _ = write!(s, " {r}");
    }
    if let Some(f) = d.field {
        let _ = write!(s, " in {f:?}");
    }
    match d.bit {
        Some(b) => {
            let _ = write!(s, " at bit {b}");
        }
        None => {
            let _ = write!(s, " at {} ps", d.time_ps);
        }
    }
    s
}
