//! The mutation report: score, survivors with file:line and the mutation in
//! words, JSON for tools, Markdown for people.

use crate::campaign::{Baseline, MutantResult, Verdict};
use crate::formal::FormalVerdict;
use crate::waiver_audit::{AuditSummary, HiddenByWaiver};
use serde::{Deserialize, Serialize};

/// A whole run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    /// The core, in words (directory, top).
    pub core: String,
    /// Where the mutations came from (`--count N --seed S` or a list file).
    pub source: String,
    /// The tests' baseline on the original (select 0).
    pub baseline: Vec<Baseline>,
    /// Every mutant of this run (shard).
    pub mutants: Vec<MutantResult>,
    /// Formal verdicts of survivors, by id.
    pub formal: Vec<(u32, FormalVerdict)>,
    /// Survivors the waiver audit found masked by a waiver (not killed).
    #[serde(default)]
    pub hidden: Vec<HiddenByWaiver>,
    /// What the waiver audit compared (None: no scenario ran with waivers).
    #[serde(default)]
    pub audit: Option<AuditSummary>,
    /// Wall time of the build (yosys + Verilator), seconds.
    pub build_seconds: f64,
    /// Wall time of the mutants' simulations, seconds.
    pub run_seconds: f64,
}

/// Counts behind the score.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    /// Mutants in the run.
    pub mutants: usize,
    /// Killed by a test.
    pub killed: usize,
    /// Every test passed, and no proof of equivalence.
    pub survived: usize,
    /// Every test passed only because a waiver masked the mutant (the
    /// waiver audit): not killed, not in `survived`.
    #[serde(default)]
    pub hidden_by_waiver: usize,
    /// Proved equivalent to the original (not in the score).
    pub equivalent: usize,
    /// Over the time budget.
    pub timed_out: usize,
    /// Yosys could not insert them (not in the score).
    pub build_errors: usize,
}

impl Report {
    /// The waiver audit's finding on a mutant, if a waiver hides it.
    pub fn hidden_by(&self, id: u32) -> Option<&HiddenByWaiver> {
        self.hidden.iter().find(|h| h.id == id)
    }

    /// The formal verdict of a mutant, if it was checked.
    pub fn formal_of(&self, id: u32) -> Option<&FormalVerdict> {
        self.formal.iter().find(|(i, _)| *i == id).map(|(_, f)| f)
    }

    /// The counts.
    pub fn counts(&self) -> Counts {
        let mut c = Counts { mutants: self.mutants.len(), ..Counts::default() };
        for m in &self.mutants {
            match &m.verdict {
                Verdict::Killed { .. } => c.killed += 1,
                Verdict::TimedOut { .. } => c.timed_out += 1,
                Verdict::BuildError { .. } => c.build_errors += 1,
                Verdict::Survived if self.hidden_by(m.id).is_some() => c.hidden_by_waiver += 1,
                Verdict::Survived if matches!(self.formal_of(m.id), Some(FormalVerdict::Equivalent { .. })) => c.equivalent += 1,
                Verdict::Survived => c.survived += 1,
            }
        }
        c
    }

    /// killed / (mutants - equivalent - build errors); None when nothing counts.
    pub fn score(&self) -> Option<f64> {
        let c = self.counts();
        let d = c.mutants - c.equivalent - c.build_errors;
        (d > 0).then(|| c.killed as f64 / d as f64)
    }

    /// Survivors (not proved equivalent) and timed-out mutants.
    pub fn survivors(&self) -> Vec<&MutantResult> {
        self.mutants
            .iter()
            .filter(|m| match m.verdict {
                Verdict::Survived => self.hidden_by(m.id).is_some() || !matches!(self.formal_of(m.id), Some(FormalVerdict::Equivalent { .. })),
                Verdict::TimedOut { .. } => true,
                _ => false,
            })
            .collect()
    }

    /// JSON (the whole report plus counts and score).
    pub fn to_json(&self) -> String {
        let mut v = serde_json::to_value(self).expect("plain data");
        v["counts"] = serde_json::to_value(self.counts()).expect("plain data");
        v["score"] = serde_json::to_value(self.score()).expect("plain data");
        serde_json::to_string_pretty(&v).expect("plain data")
    }

    /// One line: score and counts.
    pub fn summary(&self) -> String {
        let c = self.counts();
        let score = self.score().map(|s| format!("{:.1}%", s * 100.0)).unwrap_or_else(|| "n/a".into());
        format!(
            "mutation score {score} = {} killed / ({} mutants - {} equivalent - {} build errors); {} survived, {} hidden by a waiver, {} timed out",
            c.killed, c.mutants, c.equivalent, c.build_errors, c.survived, c.hidden_by_waiver, c.timed_out
        )
    }

    /// Markdown for people.
    pub fn to_markdown(&self) -> String {
        let mut s = format!("# Mutation report\n\n- core: {}\n- mutations: {}\n- {}\n", self.core, self.source, self.summary());
        s += &format!("- build (yosys + Verilator, once): {:.1} s; simulations: {:.1} s", self.build_seconds, self.run_seconds);
        let sims = self.mutants.iter().filter(|m| m.tests_run > 0).count();
        if sims > 0 {
            s += &format!(" ({:.2} s per mutant)", self.mutants.iter().map(|m| m.seconds).sum::<f64>() / sims as f64);
        }
        s += "\n";
        if let Some(a) = &self.audit {
            s += &format!("- {}\n", a.describe());
        }
        s += "\n";
        let unused: Vec<&Baseline> = self.baseline.iter().filter(|b| !b.passed).collect();
        if !unused.is_empty() {
            s += "Tests not used (they do not pass on the original, so cannot kill):\n\n";
            for b in unused {
                s += &format!("- {}: {}\n", b.test, b.note.as_deref().unwrap_or(""));
            }
            s += "\n";
        }
        let surv = self.survivors();
        if !surv.is_empty() {
            s += "## Survivors\n\n| id | where | mutation | formal check |\n|---|---|---|---|\n";
            for m in surv {
                let f = match (&m.verdict, self.formal_of(m.id)) {
                    (Verdict::TimedOut { tests_run }, _) => format!("timed out after {tests_run} tests"),
                    (_, _) if self.hidden_by(m.id).is_some() => self.hidden_by(m.id).map(HiddenByWaiver::describe).unwrap_or_default(),
                    (_, Some(f)) => f.describe(),
                    (_, None) => "not checked".into(),
                };
                s += &format!("| {} | {} | {} | {} |\n", m.id, m.location, m.description.replace('|', "\\|"), f.replace('|', "\\|"));
            }
            s += "\n";
        }
        if !self.hidden.is_empty() {
            s += "## Hidden by a waiver (survivors the waivers mask: not killed)\n\n| id | where | scenario | waiver | difference from the original's run |\n|---|---|---|---|---|\n";
            for h in &self.hidden {
                let loc = self.mutants.iter().find(|m| m.id == h.id).map(|m| m.location.clone()).unwrap_or_default();
                for d in &h.differences {
                    s += &format!("| {} | {} | {} | {} | {} |\n", h.id, loc, h.test, d.waiver_id(), d.describe().replace('|', "\\|"));
                }
            }
            s += "\n";
        }
        let eq: Vec<&MutantResult> = self.mutants.iter().filter(|m| matches!(self.formal_of(m.id), Some(FormalVerdict::Equivalent { .. }))).collect();
        if !eq.is_empty() {
            s += "## Equivalent (excluded from the score)\n\n| id | where | mutation | proof |\n|---|---|---|---|\n";
            for m in eq {
                s += &format!("| {} | {} | {} | {} |\n", m.id, m.location, m.description.replace('|', "\\|"), self.formal_of(m.id).map(|f| f.describe()).unwrap_or_default());
            }
            s += "\n";
        }
        let mut by_test: Vec<(String, usize)> = Vec::new();
        for m in &self.mutants {
            if let Verdict::Killed { test, .. } = &m.verdict {
                match by_test.iter_mut().find(|(t, _)| t == test) {
                    Some((_, n)) => *n += 1,
                    None => by_test.push((test.clone(), 1)),
                }
            }
        }
        by_test.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        if !by_test.is_empty() {
            s += "## Kills by scenario\n\n| scenario | kills |\n|---|---|\n";
            for (t, n) in by_test {
                s += &format!("| {t} | {n} |\n");
            }
            s += "\n";
        }
        s += "## Every mutant\n\n| id | where | mutation | verdict |\n|---|---|---|---|\n";
        for m in &self.mutants {
            let v = match &m.verdict {
                Verdict::Killed { test, why, .. } => format!("killed by {test}: {why}"),
                Verdict::Survived => match self.formal_of(m.id) {
                    _ if self.hidden_by(m.id).is_some() => format!("SURVIVED, {}", self.hidden_by(m.id).map(HiddenByWaiver::describe).unwrap_or_default()),
                    Some(FormalVerdict::Equivalent { .. }) => "equivalent".into(),
                    _ => "SURVIVED".into(),
                },
                Verdict::TimedOut { tests_run } => format!("timed out after {tests_run} tests"),
                Verdict::BuildError { message } => format!("build error: {message}"),
            };
            s += &format!("| {} | {} | {} | {} |\n", m.id, m.location, m.description.replace('|', "\\|"), v.replace('|', "\\|"));
        }
        s
    }
}
