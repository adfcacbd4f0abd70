//! `cancosim bench --mutants K`: the time per mutant with one `-ctrl` build
//! for all against rebuilding each mutant (yosys + Verilator per mutant),
//! the same scenario on both, measured in one run from cold builds.

use crate::instrument::{CoreSources, InstrumentError, MutationSource, SELECT, instrument, yosys};
use serde::Serialize;
use std::time::Instant;

/// The row's figures.
#[derive(Clone, Debug, Serialize)]
pub struct CtrlVsRebuild {
    /// Mutants measured on both paths.
    pub mutants: usize,
    /// Scenario each mutant ran.
    pub scenario: String,
    /// One build of all mutants behind the select (yosys + Verilator), s.
    pub ctrl_build_s: f64,
    /// Their simulations, s (total).
    pub ctrl_sim_s: f64,
    /// One build per mutant (yosys + Verilator), s (total).
    pub rebuild_build_s: f64,
    /// Their simulations, s (total).
    pub rebuild_sim_s: f64,
    /// Rebuild time per mutant over `-ctrl` time per mutant, as measured.
    pub ratio: f64,
    /// The same ratio at the size of a real run (`projected_mutants`), from
    /// the measured build and mean simulation times.
    pub projected_ratio: f64,
    /// The run size of `projected_ratio`.
    pub projected_mutants: usize,
}

impl CtrlVsRebuild {
    /// One table row.
    pub fn row(&self) -> String {
        let k = self.mutants as f64;
        format!(
            "mutants ({}, {}): one -ctrl build {:.2} s/mutant ({:.1} s build + {:.2} s sim each) vs rebuild each {:.2} s/mutant: {:.1}x measured, {:.0}x at {} mutants",
            self.mutants,
            self.scenario,
            (self.ctrl_build_s + self.ctrl_sim_s) / k,
            self.ctrl_build_s,
            self.ctrl_sim_s / k,
            (self.rebuild_build_s + self.rebuild_sim_s) / k,
            self.ratio,
            self.projected_ratio,
            self.projected_mutants
        )
    }
}

/// Measures both paths on `count` mutants (seed `seed`) of `sources`, each
/// running `scenario`; builds go to fresh directories under `work` (cold).
pub fn ctrl_vs_rebuild(sources: &CoreSources, scenario: &scenario::Scenario, profile: &cosim::Profile, count: u32, seed: u64, work: &std::path::Path, projected_mutants: usize) -> Result<CtrlVsRebuild, crate::MutateError> {
    let io = |what: String| move |source| crate::MutateError::Io { what, source };
    let run = |dir: &std::path::Path, held: Vec<(String, u64)>| {
        let dut = scenario::DutSpec {
            name: String::new(),
            kind: scenario::DutKind::External { path: dir.to_path_buf(), top: sources.top.clone(), defines: Vec::new(), includes: Vec::new() },
            profile: None,
        }
        .with_profile(profile.clone());
        let t = Instant::now();
        let out = scenario::run(scenario, &scenario::RunOptions { dut: Some(dut), host: Some(scenario::HostBfm::Wishbone), held_inputs: held, ..Default::default() });
        (t.elapsed().as_secs_f64(), out.record.error)
    };
    let t0 = Instant::now();
    let inst = instrument(sources, &MutationSource::Sample { count, seed }, work)?;
    cosim::build_external(&inst.external_core())?;
    let ctrl_build_s = t0.elapsed().as_secs_f64();
    let mut ctrl_sim_s = 0.0;
    for m in &inst.mutations {
        let (s, err) = run(&inst.dir, vec![(SELECT.into(), m.id as u64)]);
        if let Some(e) = err {
            return Err(crate::MutateError::NoBaseline(format!("mutant {} did not run: {e}", m.id)));
        }
        ctrl_sim_s += s;
    }
    let (mut rebuild_build_s, mut rebuild_sim_s) = (0.0, 0.0);
    for m in &inst.mutations {
        let t = Instant::now();
        let dir = work.join(format!("single-{}", m.id));
        std::fs::create_dir_all(&dir).map_err(io(format!("creating {}", dir.display())))?;
        let script = format!("read_rtlil {}\nmutate {}\nopt_clean\nwrite_verilog -noattr mutated.v\n", inst.design.display(), m.args);
        yosys(&script, &dir, "single").map_err(crate::MutateError::from)?;
        cosim::build_external(&cosim::ExternalCore { dir: dir.clone(), top: sources.top.clone(), ..Default::default() })?;
        rebuild_build_s += t.elapsed().as_secs_f64();
        let (s, err) = run(&dir, Vec::new());
        if let Some(e) = err {
            return Err(crate::MutateError::Instrument(InstrumentError::Yosys { step: format!("mutant {} alone", m.id), message: e }));
        }
        rebuild_sim_s += s;
    }
    let k = inst.mutations.len() as f64;
    let ctrl_per = (ctrl_build_s + ctrl_sim_s) / k;
    let rebuild_per = (rebuild_build_s + rebuild_sim_s) / k;
    let n = projected_mutants as f64;
    let ctrl_per_n = (ctrl_build_s + n * ctrl_sim_s / k) / n;
    Ok(CtrlVsRebuild {
        mutants: inst.mutations.len(),
        scenario: scenario.name.clone(),
        ctrl_build_s,
        ctrl_sim_s,
        rebuild_build_s,
        rebuild_sim_s,
        ratio: rebuild_per / ctrl_per,
        projected_ratio: rebuild_per / ctrl_per_n,
        projected_mutants,
    })
}
