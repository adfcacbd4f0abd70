//! The waiver audit ("waivers must not turn mutants into
//! survivors"). A waiver lets a known deviation of an external core pass;
//! a mutant that only changes what happens at a waived point passes too.
//! So every scenario run records the waivers it hit (id and values), the
//! unmutated core's runs (select 0) are the baseline, recorded once, and a
//! surviving mutant whose run of any scenario hits a waiver more or less
//! often, hits another waiver, or hits one with other values is classed
//! **hidden by a waiver**: named with the waiver and the values, and not
//! killed. The simulation is deterministic, so an equivalent mutant hits
//! exactly what the original hits.
//!
//! Compared per hit: waiver id, divergence kind, register, frame field,
//! model and DUT values (waived expectations: what was checked, model and
//! DUT values). Times and bit positions are not compared: the values are.

use crate::campaign::{Baseline, MutantResult, Suite, TestInfo, TestResult, Verdict};
use crate::suite::{ScenarioSuite, result_of};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::sync::Mutex;

/// One waiver hit of a run, as compared against the baseline.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct WaiverHit {
    /// The waiver.
    pub waiver_id: String,
    /// What it covered: divergence kind, register, field (or the expectation).
    pub what: String,
    /// The model's value.
    pub model: u32,
    /// The DUT's value.
    pub dut: u32,
}

impl std::fmt::Display for WaiverHit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}, model 0x{:02X}, DUT 0x{:02X}", self.waiver_id, self.what, self.model, self.dut)
    }
}

/// The hits of one run's waiver report, in the order seen.
pub fn hits_of(report: &waivers::WaiverReport) -> Vec<WaiverHit> {
    let mut v: Vec<WaiverHit> = report
        .waived
        .iter()
        .map(|w| {
            let d = &w.divergence;
            let mut what = format!("{:?}", d.kind);
            if let Some(r) = &d.register {
                what += &format!(" {r}");
            }
            if let Some(f) = d.field {
                what += &format!(" in {f:?}");
            }
            WaiverHit { waiver_id: w.waiver_id.clone(), what, model: d.expected, dut: d.seen }
        })
        .collect();
    v.extend(report.waived_expectations.iter().map(|e| WaiverHit {
        waiver_id: e.waiver_id.clone(),
        what: format!("expectation {} (expected {})", e.what, e.expected),
        model: e.model as u32,
        dut: e.seen as u32,
    }));
    v
}

/// How a mutant's hits in one scenario differ from the baseline's.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "how", rename_all = "kebab-case")]
pub enum HitDifference {
    /// A waiver the original's run of this scenario never hit.
    OtherWaiver {
        /// The mutant's first hit of it.
        hit: WaiverHit,
        /// Its hits in the mutant's run.
        count: usize,
    },
    /// The same waiver, more (or fewer) times.
    Count {
        /// The waiver.
        waiver_id: String,
        /// Hits on the original.
        baseline: usize,
        /// Hits on the mutant.
        mutant: usize,
        /// The mutant's first hit not in the baseline (None when only fewer).
        extra: Option<WaiverHit>,
    },
    /// The same waiver as often, with other values.
    Values {
        /// The mutant's hit with values the original never showed there.
        mutant: WaiverHit,
        /// The original's hit of that waiver it replaces (first unmatched).
        baseline: WaiverHit,
    },
}

impl HitDifference {
    /// The waiver concerned.
    pub fn waiver_id(&self) -> &str {
        match self {
            HitDifference::OtherWaiver { hit, .. } => &hit.waiver_id,
            HitDifference::Count { waiver_id, .. } => waiver_id,
            HitDifference::Values { mutant, .. } => &mutant.waiver_id,
        }
    }

    /// In words.
    pub fn describe(&self) -> String {
        match self {
            HitDifference::OtherWaiver { hit, count } => format!("hits waiver {} the original does not hit here ({count}x; first {hit})", hit.waiver_id),
            HitDifference::Count { waiver_id, baseline, mutant, extra } => {
                let more = if mutant > baseline { "more often" } else { "less often" };
                let mut s = format!("hits waiver {waiver_id} {more}: {mutant}x against {baseline}x on the original");
                if let Some(e) = extra {
                    s += &format!(" (first new hit {e})");
                }
                s
            }
            HitDifference::Values { mutant, baseline } => format!("hits waiver {} with other values: {mutant} where the original has {baseline}", mutant.waiver_id),
        }
    }
}

/// The differences of a mutant's hits from the baseline's in one scenario
/// (empty: the same hits, as a multiset).
pub fn compare(baseline: &[WaiverHit], mutant: &[WaiverHit]) -> Vec<HitDifference> {
    let mut ids: Vec<&str> = baseline.iter().chain(mutant).map(|h| h.waiver_id.as_str()).collect();
    ids.sort_unstable();
    ids.dedup();
    let mut out = Vec::new();
    for id in ids {
        let b: Vec<&WaiverHit> = baseline.iter().filter(|h| h.waiver_id == id).collect();
        let m: Vec<&WaiverHit> = mutant.iter().filter(|h| h.waiver_id == id).collect();
        // The mutant's hits left after taking away the baseline's, and back.
        let unmatched = |from: &[&WaiverHit], minus: &[&WaiverHit]| {
            let mut rest: Vec<&WaiverHit> = minus.to_vec();
            let mut left = Vec::new();
            for h in from {
                match rest.iter().position(|r| r == h) {
                    Some(i) => {
                        rest.remove(i);
                    }
                    None => left.push((*h).clone()),
                }
            }
            left
        };
        let new_in_m = unmatched(&m, &b);
        let gone_from_b = unmatched(&b, &m);
        if b.is_empty() {
            out.push(HitDifference::OtherWaiver { hit: m[0].clone(), count: m.len() });
        } else if b.len() != m.len() {
            out.push(HitDifference::Count { waiver_id: id.to_string(), baseline: b.len(), mutant: m.len(), extra: new_in_m.first().cloned() });
        } else if let (Some(mh), Some(bh)) = (new_in_m.first(), gone_from_b.first()) {
            out.push(HitDifference::Values { mutant: mh.clone(), baseline: bh.clone() });
        }
    }
    out
}

/// A survivor the waivers mask.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct HiddenByWaiver {
    /// The mutant.
    pub id: u32,
    /// The scenario whose run showed it.
    pub test: String,
    /// What differs (the first scenario's differences).
    pub differences: Vec<HitDifference>,
}

impl HiddenByWaiver {
    /// One line.
    pub fn describe(&self) -> String {
        format!("hidden by a waiver in {}: {}", self.test, self.differences.iter().map(HitDifference::describe).collect::<Vec<_>>().join("; "))
    }
}

/// What the audit compared, for the report.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct AuditSummary {
    /// Survivors re-judged.
    pub survivors: usize,
    /// Used scenarios run with a waiver file (the baseline's hits recorded).
    pub scenarios_with_waivers: usize,
    /// Of those, the ones whose baseline run hits at least one waiver.
    pub scenarios_with_hits: usize,
    /// Waiver hits in the whole baseline.
    pub baseline_hits: usize,
    /// Survivors found hidden by a waiver.
    pub hidden: usize,
}

impl AuditSummary {
    /// One line.
    pub fn describe(&self) -> String {
        format!(
            "waiver audit: {} survivor(s) compared with the unmutated core's waiver hits in {} scenario(s) run with waivers ({} of them hit a waiver, {} hits in all): {} hidden by a waiver",
            self.survivors, self.scenarios_with_waivers, self.scenarios_with_hits, self.baseline_hits, self.hidden
        )
    }
}

/// A [`ScenarioSuite`] that records the waiver hits of every passing run,
/// by (test, select); the runs themselves are unchanged.
pub struct AuditedSuite<'a> {
    /// The scenarios.
    pub inner: &'a ScenarioSuite,
    /// Hits of passing runs with a waiver report (None: the run had no waivers).
    hits: Mutex<HashMap<(usize, u64), Option<Vec<WaiverHit>>>>,
}

impl<'a> AuditedSuite<'a> {
    /// Records nothing yet.
    pub fn new(inner: &'a ScenarioSuite) -> Self {
        AuditedSuite { inner, hits: Mutex::new(HashMap::new()) }
    }

    fn recorded(&self, test: usize, select: u64) -> Option<Option<Vec<WaiverHit>>> {
        self.hits.lock().expect("no panics under the lock").get(&(test, select)).cloned()
    }
}

impl Suite for AuditedSuite<'_> {
    fn tests(&self) -> Vec<TestInfo> {
        self.inner.tests()
    }

    fn run(&self, index: usize, select: u64) -> TestResult {
        let out = self.inner.outcome(index, select);
        let r = result_of(&out);
        if r == TestResult::Pass {
            // A run without a waiver file has an empty report: nothing to audit.
            let with_waivers = out.waivers.as_ref().filter(|w| !w.waiver_file.is_empty());
            self.hits.lock().expect("no panics under the lock").insert((index, select), with_waivers.map(hits_of));
        }
        r
    }
}

/// Re-judges every survivor: the first scenario (in suite order) whose
/// waiver hits differ from the baseline's makes it hidden. Survivors resumed
/// from a journal have no recorded hits: their scenarios run again here.
/// Scenarios run without waivers are not audited (nothing to mask).
/// None when no used scenario ran with waivers.
pub fn audit(suite: &AuditedSuite, base: &[Baseline], mutants: &[MutantResult], log: &mut dyn FnMut(&str)) -> (Vec<HiddenByWaiver>, Option<AuditSummary>) {
    let usable: Vec<usize> = (0..base.len()).filter(|&i| base[i].passed).collect();
    let names = suite.tests();
    let mut hidden = Vec::new();
    let baselines: Vec<Vec<WaiverHit>> = usable.iter().filter_map(|&t| suite.recorded(t, 0).flatten()).collect();
    let survivors: Vec<&MutantResult> = mutants.iter().filter(|m| m.verdict == Verdict::Survived).collect();
    for m in &survivors {
        for &t in &usable {
            let Some(Some(b)) = suite.recorded(t, 0) else { continue };
            let mh = match suite.recorded(t, m.id as u64) {
                Some(h) => h,
                None => {
                    if suite.run(t, m.id as u64) != TestResult::Pass {
                        log(&format!("mutant {}: {} no longer passes on a second run (not deterministic?)", m.id, names[t].name));
                        continue;
                    }
                    suite.recorded(t, m.id as u64).flatten()
                }
            };
            let diffs = compare(&b, mh.as_deref().unwrap_or(&[]));
            if !diffs.is_empty() {
                let h = HiddenByWaiver { id: m.id, test: names[t].name.clone(), differences: diffs };
                log(&format!("mutant {}: {}", m.id, h.describe()));
                hidden.push(h);
                break;
            }
        }
    }
    let summary = (!baselines.is_empty()).then(|| AuditSummary {
        survivors: survivors.len(),
        scenarios_with_waivers: baselines.len(),
        scenarios_with_hits: baselines.iter().filter(|b| !b.is_empty()).count(),
        baseline_hits: baselines.iter().map(Vec::len).sum(),
        hidden: hidden.len(),
    });
    if let Some(s) = &summary {
        log(&s.describe());
    }
    (hidden, summary)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hit(id: &str, model: u32, dut: u32) -> WaiverHit {
        WaiverHit { waiver_id: id.into(), what: "RegisterRead SR".into(), model, dut }
    }

    #[test]
    fn the_same_hits_in_another_order_are_no_difference() {
        let b = [hit("a", 1, 2), hit("b", 3, 4), hit("a", 5, 6)];
        let m = [hit("b", 3, 4), hit("a", 5, 6), hit("a", 1, 2)];
        assert_eq!(compare(&b, &m), vec![]);
        assert_eq!(compare(&[], &[]), vec![]);
    }

    #[test]
    fn another_waiver_is_named_with_its_values() {
        let d = compare(&[hit("a", 1, 2)], &[hit("a", 1, 2), hit("b", 0x20, 0x30)]);
        assert_eq!(d, vec![HitDifference::OtherWaiver { hit: hit("b", 0x20, 0x30), count: 1 }]);
        assert_eq!(d[0].waiver_id(), "b");
        assert!(d[0].describe().contains("model 0x20, DUT 0x30"), "{}", d[0].describe());
    }

    #[test]
    fn more_and_fewer_hits_of_a_waiver_differ() {
        // A second copy of the same hit is the new one.
        let d = compare(&[hit("a", 1, 2)], &[hit("a", 1, 2), hit("a", 1, 2)]);
        assert_eq!(d, vec![HitDifference::Count { waiver_id: "a".into(), baseline: 1, mutant: 2, extra: Some(hit("a", 1, 2)) }]);
        assert!(d[0].describe().contains("more often: 2x against 1x"));
        let d = compare(&[hit("a", 1, 2), hit("a", 1, 2)], &[hit("a", 1, 2)]);
        assert_eq!(d, vec![HitDifference::Count { waiver_id: "a".into(), baseline: 2, mutant: 1, extra: None }]);
        assert!(d[0].describe().contains("less often"), "{}", d[0].describe());
        let d = compare(&[hit("a", 1, 2)], &[hit("a", 1, 2), hit("a", 7, 8)]);
        assert_eq!(d, vec![HitDifference::Count { waiver_id: "a".into(), baseline: 1, mutant: 2, extra: Some(hit("a", 7, 8)) }]);
    }

    #[test]
    fn other_values_as_often_differ() {
        let d = compare(&[hit("a", 1, 2), hit("a", 3, 4)], &[hit("a", 1, 2), hit("a", 3, 5)]);
        assert_eq!(d, vec![HitDifference::Values { mutant: hit("a", 3, 5), baseline: hit("a", 3, 4) }]);
        // Another register with the same numbers is another value too.
        let mut other = hit("a", 3, 4);
        other.what = "RegisterRead IR".into();
        assert_eq!(compare(&[hit("a", 3, 4)], std::slice::from_ref(&other)).len(), 1);
    }
}
