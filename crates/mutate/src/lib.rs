//! Mutation testing of a CAN core against a regression list (`cancosim
//! mutate`): mutations from `yosys mutate -list` over the core's
//! sources, all inserted behind one run-time select input (as mcy does),
//! the core verilated once, each mutant one simulation per scenario with
//! the select held ([`cosim::ExternalCore::held_inputs`]), killed at the
//! first failing scenario. Survivors get a bounded formal check
//! ([`formal`]) that proves them equivalent or gives an input trace, turned
//! into a scenario skeleton.
#![warn(missing_docs)]

pub mod bench;
pub mod campaign;
pub mod formal;
pub mod instrument;
pub mod mutation;
pub mod report;
pub mod reset_proof;
pub mod shared_undef;
pub mod suite;
pub mod waiver_audit;
pub mod widen;

pub use campaign::{Baseline, CampaignOptions, MutantResult, Suite, TestInfo, TestResult, Verdict};
pub use formal::{FormalOptions, FormalVerdict};
pub use instrument::{CoreSources, Instrumented, MutationSource, SELECT, instrument};
pub use mutation::Mutation;
pub use report::{Counts, Report};

use std::path::PathBuf;
use std::time::Instant;

/// What can stop a mutation run.
#[derive(Debug, thiserror::Error)]
pub enum MutateError {
    /// Yosys, the list, files.
    #[error(transparent)]
    Instrument(#[from] instrument::InstrumentError),
    /// Verilator could not build the mutated core.
    #[error("the mutated core did not build: {0}")]
    Build(#[from] cosim::BridgeError),
    /// The journal or the report could not be written.
    #[error("{what}: {source}")]
    Io {
        /// What was being done.
        what: String,
        /// The error.
        source: std::io::Error,
    },
    /// No scenario passes on the original core: nothing can kill.
    #[error("no scenario passes on the original core (select 0): nothing could kill a mutant; baseline: {0}")]
    NoBaseline(String),
}

/// A mutation run of a core against scenarios.
pub struct MutateConfig {
    /// The core.
    pub sources: CoreSources,
    /// The mutations.
    pub from: MutationSource,
    /// The scenarios (a regression list).
    pub scenarios: Vec<scenario::Scenario>,
    /// The core's profile.
    pub profile: cosim::Profile,
    /// Run options of every scenario (waivers, host); the DUT is set here.
    pub run: scenario::RunOptions,
    /// The mutant loop.
    pub campaign: CampaignOptions,
    /// Formal check of survivors (None: skipped).
    pub formal: Option<FormalOptions>,
    /// Each mutant that survives the scenarios gets a random campaign of
    /// this many frames (0: none) with this seed, on the same DUT, host
    /// and waivers; a failing run kills it.
    pub campaign_frames: u64,
    /// Seed of those campaigns.
    pub campaign_seed: u64,
    /// Output directory: journal-<build>.jsonl, report.json, report.md, skeletons/.
    pub out: PathBuf,
    /// Build cache.
    pub cache: PathBuf,
}

/// Gives each survivor a random campaign (`::campaign::random`, the one
/// `cancosim campaign` runs) on the mutated build with its select held; the
/// first failing run kills it, named by its seed and run index.
fn random_campaign_kills(mutants: &mut [MutantResult], dut: scenario::DutSpec, cfg: &MutateConfig, log: &mut dyn FnMut(&str)) {
    let survivors: Vec<usize> = (0..mutants.len()).filter(|&i| mutants[i].verdict == Verdict::Survived).collect();
    log(&format!("random campaign of {} frames (seed {}) on {} survivor(s)", cfg.campaign_frames, cfg.campaign_seed, survivors.len()));
    let mut killed = 0;
    for i in survivors {
        let m = &mut mutants[i];
        let mut rc = ::campaign::random::RandomConfig::new(cfg.campaign_seed, cfg.campaign_frames, dut.clone());
        rc.waivers = cfg.run.waivers.clone();
        rc.host = cfg.run.host;
        rc.held_inputs = vec![(instrument::SELECT.into(), m.id as u64)];
        rc.jobs = cfg.campaign.jobs;
        rc.max_failures = 1;
        rc.shrink_runs = 0;
        let t = Instant::now();
        let r = ::campaign::random::run_campaign(&rc);
        m.seconds += t.elapsed().as_secs_f64();
        if let Some(f) = r.failures.first() {
            killed += 1;
            m.verdict = Verdict::Killed { test: format!("campaign seed {} run {}", cfg.campaign_seed, f.index), why: f.what.clone(), field: None };
            log(&format!("  mutant {} killed by campaign run {}: {}", m.id, f.index, f.what));
        }
    }
    log(&format!("random campaign killed {killed}"));
}

fn io(what: impl Into<String>) -> impl FnOnce(std::io::Error) -> MutateError {
    let what = what.into();
    move |source| MutateError::Io { what, source }
}

/// Builds the mutants once, runs the baseline and every mutant, checks the
/// survivors, writes the report files in `cfg.out`.
pub fn mutate(cfg: &MutateConfig, log: &mut dyn FnMut(&str)) -> Result<Report, MutateError> {
    std::fs::create_dir_all(&cfg.out).map_err(io(format!("creating {}", cfg.out.display())))?;
    let t0 = Instant::now();
    let inst = instrument(&cfg.sources, &cfg.from, &cfg.cache)?;
    log(&format!("{} mutations ({} not insertable); mutated core {}", inst.mutations.len(), inst.build_errors.len(), inst.verilog.display()));
    std::fs::copy(inst.dir.join("list.txt"), cfg.out.join("mutations.list")).map_err(io("copying the mutation list"))?;
    cosim::build_external(&inst.external_core())?;
    let build_seconds = t0.elapsed().as_secs_f64();
    log(&format!("built once in {build_seconds:.1} s"));
    let dut = scenario::DutSpec {
        name: String::new(),
        kind: scenario::DutKind::External { path: inst.dir.clone(), top: inst.top.clone(), defines: Vec::new(), includes: Vec::new() },
        profile: None,
    }
    .with_profile(cfg.profile.clone());
    let mut run = cfg.run.clone();
    run.dut = Some(dut);
    let scenarios = suite::ScenarioSuite { scenarios: cfg.scenarios.clone(), options: run };
    // Every passing run's waiver hits are recorded for the waiver audit.
    let suite = waiver_audit::AuditedSuite::new(&scenarios);
    let base = campaign::baseline(&suite, cfg.campaign.jobs);
    for b in base.iter().filter(|b| !b.passed) {
        log(&format!("not used: {}: {}", b.test, b.note.as_deref().unwrap_or("")));
    }
    if !base.iter().any(|b| b.passed) {
        return Err(MutateError::NoBaseline(base.iter().map(|b| format!("{}: {}", b.test, b.note.as_deref().unwrap_or(""))).collect::<Vec<_>>().join("; ")));
    }
    let t1 = Instant::now();
    let mut copts = cfg.campaign.clone();
    // One journal per build of the mutants (sources, list) and suite: after
    // an edit of the core, a mutation with the same options is a different
    // mutant; with other scenarios or waivers a survivor must run again.
    let key = inst.dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    copts.journal.get_or_insert_with(|| cfg.out.join(journal_name(&key, &cfg.scenarios, &cfg.run)));
    let mut mutants = campaign::run_mutants(&suite, &base, &inst.mutations, &inst.build_errors, &copts).map_err(io("mutant loop"))?;
    if cfg.campaign_frames > 0 {
        random_campaign_kills(&mut mutants, scenarios.options.dut.clone().expect("set above"), cfg, log);
    }
    let (hidden, audit) = waiver_audit::audit(&suite, &base, &mutants, log);
    let run_seconds = t1.elapsed().as_secs_f64();
    let mut report = Report {
        core: format!("{} ({})", inst.top, cfg.sources.dir.display()),
        source: match &cfg.from {
            MutationSource::Sample { count, seed } => format!("yosys mutate -list {count} -seed {seed}"),
            MutationSource::Saved(p) => format!("list {}", p.display()),
        },
        baseline: base,
        mutants,
        formal: Vec::new(),
        hidden,
        audit,
        build_seconds,
        run_seconds,
    };
    if let Some(f) = &cfg.formal {
        check_survivors_from_reset(&mut report, &cfg.sources, &inst, f, &cfg.out, log)?;
    }
    std::fs::write(cfg.out.join("report.json"), report.to_json()).map_err(io("writing report.json"))?;
    std::fs::write(cfg.out.join("report.md"), report.to_markdown()).map_err(io("writing report.md"))?;
    Ok(report)
}

/// The journal's file name: the build of the mutants (`build_key`) and the
/// suite the verdicts were reached with (the scenarios as loaded, the run
/// options, the waiver files' text), so that a verdict is only resumed
/// with the same scenarios and waivers.
pub fn journal_name(build_key: &str, scenarios: &[scenario::Scenario], run: &scenario::RunOptions) -> String {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    instrument::fnv1a(&mut h, format!("{scenarios:?}{run:?}").as_bytes());
    for w in scenarios.iter().flat_map(|s| &s.waivers).chain(&run.waivers) {
        instrument::fnv1a(&mut h, &std::fs::read(w).unwrap_or_default());
    }
    format!("journal-{build_key}-{h:016x}.jsonl")
}

/// The formal check of every survivor; skeletons in `out/skeletons/`.
pub fn check_survivors(report: &mut Report, inst: &Instrumented, f: &FormalOptions, out: &std::path::Path, log: &mut dyn FnMut(&str)) -> Result<(), MutateError> {
    // A survivor hidden by a waiver behaves differently: no proof to seek.
    let ids: Vec<u32> = report.mutants.iter().filter(|m| m.verdict == Verdict::Survived && report.hidden_by(m.id).is_none()).map(|m| m.id).collect();
    for id in ids {
        let v = formal::check(inst, id, f, &out.join("formal"))?;
        if let FormalVerdict::Differs { trace, .. } = &v {
            let m = report.mutants.iter().find(|m| m.id == id).expect("a survivor of this report");
            let dir = out.join("skeletons");
            std::fs::create_dir_all(&dir).map_err(io(format!("creating {}", dir.display())))?;
            let path = dir.join(format!("mutant-{id}.toml"));
            std::fs::write(&path, formal::skeleton(id, &m.location, &m.description, trace)).map_err(io(format!("writing {}", path.display())))?;
        }
        log(&format!("mutant {id}: {}", v.describe()));
        report.formal.push((id, v));
    }
    Ok(())
}

/// The formal check of every survivor of `report`: per module from reset
/// ([`reset_proof::check_in_module`]); the whole-core bounded check
/// ([`crate::formal::check`], registers from zero) where a module has more
/// than one clock. Module traces in `out/formal/mutant-N/trace.txt`,
/// whole-core skeletons in `out/skeletons/`.
pub fn check_survivors_from_reset(
    report: &mut Report,
    src: &CoreSources,
    inst: &Instrumented,
    f: &FormalOptions,
    out: &std::path::Path,
    log: &mut dyn FnMut(&str),
) -> Result<(), MutateError> {
    let ids: Vec<u32> = report.mutants.iter().filter(|m| m.verdict == Verdict::Survived).map(|m| m.id).collect();
    let work = out.join("formal");
    for id in ids {
        let m = report.mutants.iter().find(|m| m.id == id).expect("a survivor of this report").mutation.clone();
        match reset_proof::check_in_module(src, &m, f, &work)? {
            Ok(c) => {
                log(&format!("mutant {id}: {} [{}, {:.1} s]", c.verdict.describe(), c.module, c.seconds));
                // Not proved in its module (its inputs free): again with the
                // modules that drive it (widen.rs).
                let verdict = if matches!(c.verdict, FormalVerdict::Equivalent { .. }) {
                    c.verdict
                } else {
                    // A scope yosys cannot build (an inout port, a name it
                    // rejects) leaves the per-module verdict, said in the log.
                    let wide = widen::check_widened(src, &m, None, f, &work).unwrap_or_else(|e| {
                        log(&format!("mutant {id}: no widened check: {}", e.to_string().lines().last().unwrap_or("")));
                        Vec::new()
                    });
                    for w in &wide {
                        log(&format!("mutant {id}: {} [{}, {:.1} s]", w.verdict.describe(), w.label, w.seconds));
                    }
                    widen::combine(&c.module, c.verdict, &wide)
                };
                if let FormalVerdict::ModuleDiffers { trace, .. } = &verdict {
                    let lines: Vec<String> = trace.iter().map(|t| format!("{} {} {}", t.step, t.port, t.value)).collect();
                    let p = work.join(format!("mutant-{id}/trace.txt"));
                    std::fs::write(&p, lines.join("\n") + "\n").map_err(|source| MutateError::Io { what: format!("writing {}", p.display()), source })?;
                }
                report.formal.push((id, verdict));
            }
            Err(why) => {
                log(&format!("mutant {id}: not checked per module ({why:?}): whole-core bounded check"));
                let mut one = Report { mutants: report.mutants.iter().filter(|r| r.id == id).cloned().collect(), formal: Vec::new(), ..report.clone() };
                check_survivors(&mut one, inst, f, out, log)?;
                report.formal.extend(one.formal);
            }
        }
    }
    Ok(())
}
