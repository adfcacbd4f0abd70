//! `cancosim bench --mutants K`: the time per mutant with one `-ctrl` build
//! for all against rebuilding each mutant (yosys + Verilator per mutant),
//! the same scenario set on both, measured in one run from cold builds
//! (the rebuild path on a few of the mutants, its mean per mutant used).

use crate::instrument::{CoreSources, MutationSource, SELECT, instrument, yosys};
use serde::Serialize;
use std::time::Instant;

/// The row's figures. Time per mutant = the build it needs, amortised
/// over the mutants that share it, plus its simulations on the scenario
/// set: one `-ctrl` build shared by all `mutants`, against one build per
/// mutant (measured on `rebuilt` of them, the first ones of the sample).
#[derive(Clone, Debug, Serialize)]
pub struct CtrlVsRebuild {
    /// Mutants in the one `-ctrl` build, each simulated.
    pub mutants: usize,
    /// Scenarios each mutant ran (all of them, on both paths).
    pub scenarios: Vec<String>,
    /// One build of all mutants behind the select (yosys + Verilator), s.
    pub ctrl_build_s: f64,
    /// Their simulations, s (total over `mutants`).
    pub ctrl_sim_s: f64,
    /// Mutants rebuilt alone (yosys + Verilator each) and simulated.
    pub rebuilt: usize,
    /// Their builds, s (total over `rebuilt`).
    pub rebuild_build_s: f64,
    /// Their simulations, s (total over `rebuilt`).
    pub rebuild_sim_s: f64,
    /// `(ctrl_build_s + ctrl_sim_s) / mutants`.
    pub ctrl_per_mutant_s: f64,
    /// `(rebuild_build_s + rebuild_sim_s) / rebuilt`.
    pub rebuild_per_mutant_s: f64,
    /// `rebuild_per_mutant_s / ctrl_per_mutant_s`, as measured.
    pub ratio: f64,
    /// Computed, not measured: the ratio at `projected_mutants` mutants if
    /// their `-ctrl` build cost what the measured one did and each
    /// simulated as long as the measured mean (None when not larger).
    pub projected_ratio: Option<f64>,
    /// The run size of `projected_ratio`.
    pub projected_mutants: usize,
}

impl CtrlVsRebuild {
    /// The table rows (the computed one labelled so).
    pub fn row(&self) -> String {
        let k = self.mutants as f64;
        let r = self.rebuilt as f64;
        let mut out = format!(
            "mutants (scenarios: {}): one -ctrl build of {} mutants {:.2} s/mutant ({:.1} s build / {} + {:.2} s sim) vs rebuild each {:.2} s/mutant ({:.1} s build + {:.2} s sim, mean of {} rebuilt): {:.1}x measured",
            self.scenarios.join(", "),
            self.mutants,
            self.ctrl_per_mutant_s,
            self.ctrl_build_s,
            self.mutants,
            self.ctrl_sim_s / k,
            self.rebuild_per_mutant_s,
            self.rebuild_build_s / r,
            self.rebuild_sim_s / r,
            self.rebuilt,
            self.ratio,
        );
        if let Some(p) = self.projected_ratio {
            out += &format!(
                "\nmutants at {} (computed, not measured: the measured -ctrl build shared by {}, the measured mean simulation each): {:.1}x",
                self.projected_mutants, self.projected_mutants, p
            );
        }
        out
    }
}

/// Measures both paths in one run: `count` mutants (seed `seed`) of
/// `sources` in one `-ctrl` build, each simulated on every scenario of
/// `scenarios`; then the first `rebuild` of them built alone and simulated
/// the same way. Builds go to fresh directories under `work` (cold).
#[allow(clippy::too_many_arguments)]
pub fn ctrl_vs_rebuild(
    sources: &CoreSources,
    scenarios: &[scenario::Scenario],
    profile: &cosim::Profile,
    count: u32,
    rebuild: usize,
    seed: u64,
    work: &std::path::Path,
    projected_mutants: usize,
) -> Result<CtrlVsRebuild, crate::MutateError> {
    let io = |what: String| move |source| crate::MutateError::Io { what, source };
    // Every scenario of the set on the core in `dir`: seconds, and the first
    // run that ended in an error (on a mutant a kill like any other, e.g. a
    // Wishbone acknowledge that never comes; on the original, a bench error).
    let run = |dir: &std::path::Path, held: Vec<(String, u64)>| -> (f64, Option<String>) {
        let dut = scenario::DutSpec {
            name: String::new(),
            kind: scenario::DutKind::External { path: dir.to_path_buf(), top: sources.top.clone(), defines: Vec::new(), includes: Vec::new() },
            profile: None,
        }
        .with_profile(profile.clone());
        let t = Instant::now();
        let mut first_error = None;
        for s in scenarios {
            let out = scenario::run(s, &scenario::RunOptions { dut: Some(dut.clone()), host: Some(scenario::HostBfm::Wishbone), held_inputs: held.clone(), ..Default::default() });
            if let Some(e) = out.record.error {
                first_error.get_or_insert(format!("{}: {e}", s.name));
            }
        }
        (t.elapsed().as_secs_f64(), first_error)
    };
    let t0 = Instant::now();
    let inst = instrument(sources, &MutationSource::Sample { count, seed }, work)?;
    cosim::build_external(&inst.external_core())?;
    let ctrl_build_s = t0.elapsed().as_secs_f64();
    // The original (select 0) must run: a check, not counted (both paths
    // would run it once).
    if let (_, Some(e)) = run(&inst.dir, vec![(SELECT.into(), 0)]) {
        return Err(crate::MutateError::NoBaseline(format!("the original (select 0) did not run: {e}")));
    }
    let mut ctrl_sim_s = 0.0;
    for m in &inst.mutations {
        ctrl_sim_s += run(&inst.dir, vec![(SELECT.into(), m.id as u64)]).0;
    }
    let (mut rebuild_build_s, mut rebuild_sim_s) = (0.0, 0.0);
    let rebuilt: Vec<_> = inst.mutations.iter().take(rebuild.max(1)).collect();
    for m in &rebuilt {
        let t = Instant::now();
        let dir = work.join(format!("single-{}", m.id));
        std::fs::create_dir_all(&dir).map_err(io(format!("creating {}", dir.display())))?;
        let script = format!("read_rtlil {}\nmutate {}\nopt_clean\nwrite_verilog -noattr mutated.v\n", inst.design.display(), m.args);
        yosys(&script, &dir, "single").map_err(crate::MutateError::from)?;
        cosim::build_external(&cosim::ExternalCore { dir: dir.clone(), top: sources.top.clone(), ..Default::default() })?;
        rebuild_build_s += t.elapsed().as_secs_f64();
        rebuild_sim_s += run(&dir, Vec::new()).0;
    }
    let mut row = CtrlVsRebuild::from_times((inst.mutations.len(), ctrl_build_s, ctrl_sim_s), (rebuilt.len(), rebuild_build_s, rebuild_sim_s), projected_mutants);
    row.scenarios = scenarios.iter().map(|s| s.name.clone()).collect();
    Ok(row)
}

impl CtrlVsRebuild {
    /// The figures from the measured times: `ctrl` = (mutants, build s,
    /// total simulation s), `rebuild` = (mutants rebuilt, total build s,
    /// total simulation s). Scenarios are left empty.
    pub fn from_times(ctrl: (usize, f64, f64), rebuild: (usize, f64, f64), projected_mutants: usize) -> CtrlVsRebuild {
        let (mutants, ctrl_build_s, ctrl_sim_s) = ctrl;
        let (rebuilt, rebuild_build_s, rebuild_sim_s) = rebuild;
        let k = mutants as f64;
        let ctrl_per_mutant_s = (ctrl_build_s + ctrl_sim_s) / k;
        let rebuild_per_mutant_s = (rebuild_build_s + rebuild_sim_s) / rebuilt as f64;
        let n = projected_mutants as f64;
        let projected_ratio = (projected_mutants > mutants).then(|| rebuild_per_mutant_s / ((ctrl_build_s + n * ctrl_sim_s / k) / n));
        CtrlVsRebuild {
            mutants,
            scenarios: Vec::new(),
            ctrl_build_s,
            ctrl_sim_s,
            rebuilt,
            rebuild_build_s,
            rebuild_sim_s,
            ctrl_per_mutant_s,
            rebuild_per_mutant_s,
            ratio: rebuild_per_mutant_s / ctrl_per_mutant_s,
            projected_ratio,
            projected_mutants,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::CtrlVsRebuild;

    #[test]
    fn time_per_mutant_shares_one_build_and_averages_the_rebuilt_ones() {
        // 20 mutants: one 100 s build, 1 s simulation each -> 6 s/mutant;
        // 2 rebuilt: 80 s + 1 s each -> 81 s/mutant; 13.5x.
        let r = CtrlVsRebuild::from_times((20, 100.0, 20.0), (2, 160.0, 2.0), 200);
        assert_eq!(r.ctrl_per_mutant_s, 6.0);
        assert_eq!(r.rebuild_per_mutant_s, 81.0);
        assert_eq!(r.ratio, 13.5);
        // computed at 200: (100 + 200 x 1) / 200 = 1.5 s/mutant -> 54x
        assert_eq!(r.projected_ratio, Some(54.0));
        let text = r.row();
        assert!(text.contains("13.5x measured") && text.contains("computed, not measured") && text.contains("54.0x"), "{text}");
        // measured at the projected size: no computed row
        let r = CtrlVsRebuild::from_times((200, 100.0, 200.0), (2, 160.0, 2.0), 200);
        assert_eq!(r.projected_ratio, None);
        assert!(!r.row().contains("computed"), "{}", r.row());
    }
}
