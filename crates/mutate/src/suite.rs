//! The scenarios of a regression list as a mutation [`Suite`]: each run is
//! `scenario::run` on the one build of the mutated core, its select input
//! held at the mutant's value.

use crate::campaign::{Suite, TestInfo, TestResult};
use crate::instrument::SELECT;
use scenario::{RunOptions, Scenario};

/// Scenarios against one external core.
pub struct ScenarioSuite {
    /// The scenarios.
    pub scenarios: Vec<Scenario>,
    /// Options of every run (its `dut` is the mutated core); the select is added per run.
    pub options: RunOptions,
}

impl Suite for ScenarioSuite {
    fn tests(&self) -> Vec<TestInfo> {
        self.scenarios.iter().map(|s| TestInfo { name: s.name.clone() }).collect()
    }

    fn run(&self, index: usize, select: u64) -> TestResult {
        result_of(&self.outcome(index, select))
    }
}

impl ScenarioSuite {
    /// The whole outcome of test `index` with the select at `select` (the
    /// waiver audit reads its waiver hits).
    pub fn outcome(&self, index: usize, select: u64) -> scenario::RunOutcome {
        let s = &self.scenarios[index];
        // a set-up verdict's reads are judged by scenario::run itself (collect_mode)
        let mut o = self.options.clone();
        o.held_inputs.push((SELECT.into(), select));
        scenario::run(s, &o)
    }
}

/// A run's outcome as a test result: pass, skipped, or the first failure in words.
pub fn result_of(out: &scenario::RunOutcome) -> TestResult {
    {
        if let Some(why) = &out.skipped {
            return TestResult::Skipped(why.clone());
        }
        if out.passed {
            return TestResult::Pass;
        }
        let f = &out.diagnosis.figures;
        let field = f.field.map(|x| format!("{x:?}"));
        let mut w = vec![format!("{:?}", out.diagnosis.category)];
        if let Some(x) = f.frame {
            w.push(format!("frame {x}"));
        }
        if let Some(x) = &field {
            w.push(x.clone());
        }
        if let Some(x) = f.bit {
            w.push(format!("bit {x}"));
        }
        if let Some(x) = &f.register {
            w.push(x.clone());
        }
        if let (Some(e), Some(s)) = (&f.expected, &f.seen) {
            w.push(format!("expected {e}, seen {s}"));
        }
        if let Some(e) = &out.record.error {
            w.push(e.clone());
        } else if out.diagnosis.category != diagnose::Category::DutDeviatesFromModel && !out.mismatches.is_empty() {
            w.push(out.mismatches.join("; "));
        }
        TestResult::Fail { why: w.join(", "), field }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;
    use waivers::CollectMode;

    fn load(file: &str) -> Scenario {
        Scenario::load(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tb").join(file)).unwrap()
    }

    /// A scenario expecting a set-up verdict (divergence as its symptom)
    /// runs collecting whatever the campaign asks (scenario::run decides,
    /// for run, regress and mutate alike); one expecting `Pass` keeps the
    /// campaign's mode.
    #[test]
    fn set_up_verdict_scenarios_run_collecting_the_others_stop_at_the_first_divergence() {
        let base = RunOptions::default();
        assert_eq!(base.collect, CollectMode::StopAtFirst);
        let setup = load("registers/basic-reset-values-and-access.toml");
        assert_eq!(setup.expect.category, Some(diagnose::Category::ConfigWriteOutsideReset), "the example moved");
        assert_eq!(scenario::run::collect_mode(setup.expect.category, base.collect), CollectMode::Collect);
        let pass = load("registers/basic-acr-amr-read-ffh-in-operating-mode.toml");
        assert_eq!(scenario::run::collect_mode(pass.expect.category, base.collect), CollectMode::StopAtFirst);
    }
}
