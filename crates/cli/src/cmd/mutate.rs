//! `mutate`: mutation testing of a core against a regression list (issue
//! 14): yosys mutations behind one run-time select, one Verilator build,
//! each mutant killed at its first failing scenario; survivors checked
//! formally; report.json, report.md, skeletons/ in --out.

use anyhow::Context;
use std::path::PathBuf;

/// Arguments of `cancosim mutate`.
#[derive(clap::Args)]
pub struct Args {
    /// Regression list (one scenario path per line) or scenario files.
    #[arg(default_value = "tb/regression.list")]
    inputs: Vec<PathBuf>,
    /// External core directory (default: this repository's rtl/, top can_top).
    #[arg(long, value_name = "DIR")]
    external: Option<PathBuf>,
    /// Profile of the external core (tb/profiles/NAME.toml or a file); our rtl/ uses rtl.
    #[arg(long, value_name = "NAME|FILE")]
    profile: Option<String>,
    /// Top module (our rtl/ on i8051, motorola, axi4-lite, apb, apb3 or regport: that
    /// host's wrapper, can_top_8051, can_top_mcu, can_axi4lite, can_apb or can_regport).
    #[arg(long, default_value = "can_top")]
    top: String,
    /// Verilog define of the external core (repeatable; CAN_WISHBONE_IF is always set for it).
    #[arg(long = "define", value_name = "NAME[=VALUE]")]
    defines: Vec<String>,
    /// Number of mutations sampled by `yosys mutate -list`.
    #[arg(long, default_value_t = 200)]
    count: u32,
    /// Seed of the sample (recorded in the report; same seed, same mutants).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// A saved mutation list (lines of `mutate ...`) instead of a sample.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["count", "seed"])]
    list: Option<PathBuf>,
    /// Worker threads (0 = one per core).
    #[arg(long, short, default_value_t = 0)]
    jobs: usize,
    /// Run only shard k of n of the mutants (e.g. 2/4).
    #[arg(long, value_parser = scenario::regress::parse_shard)]
    shard: Option<(usize, usize)>,
    /// Output directory (journal-<build>.jsonl to resume, report.json, report.md, skeletons/).
    #[arg(long, default_value = "out/mutate")]
    out: PathBuf,
    /// Start over: ignore the journal of an earlier run in --out.
    #[arg(long)]
    fresh: bool,
    /// Skip the formal check of survivors.
    #[arg(long)]
    no_formal: bool,
    /// Steps of the bounded formal check (and induction depth).
    #[arg(long, default_value_t = 20)]
    formal_steps: u32,
    /// Host of every scenario (default wishbone: the mutated core is the can_top port list;
    /// on our rtl/ a host with its own wrapper mutates the wrapper with can_top).
    #[arg(long, default_value = "wishbone", value_parser = ["wishbone", "avalon", "pio", "pio-edge", "i8051", "axi4-lite", "apb", "apb3", "motorola", "regport"])]
    host: String,
    /// A mutant times out when its scenarios take longer than this many times
    /// the baseline's total (raise it on a loaded machine).
    #[arg(long, default_value_t = 4.0, value_name = "X")]
    budget_factor: f64,
    /// Give each mutant that survives the scenarios a random campaign of this many frames
    /// (`cancosim campaign`'s runs, on the same host and waivers); a failing run kills it.
    #[arg(long, default_value_t = 0)]
    campaign_frames: u64,
    /// Seed of those campaigns.
    #[arg(long, default_value_t = 1)]
    campaign_seed: u64,
    /// Waiver file (repeatable), added to the scenarios' own.
    #[arg(long = "waivers", value_name = "FILE")]
    waivers: Vec<PathBuf>,
}

/// Our rtl/ files of the can_top build (no other top).
pub const RTL_FILES: [&str; 8] = ["can_top.v", "can_wb_cdc.v", "can_regs.v", "can_btl.v", "can_bsp.v", "can_fce.v", "can_acf.v", "can_rxfifo.v"];

/// Our top for `host` when it is not can_top's Wishbone port, and the
/// rtl/ files it adds to [`RTL_FILES`].
pub fn wrapper_of(host: &str) -> Option<(&'static str, &'static [&'static str])> {
    match host {
        "i8051" => Some(("can_top_8051", &["can_top_8051.v"])),
        "motorola" => Some(("can_top_mcu", &["can_top_mcu.v", "can_top_8051.v"])),
        "axi4-lite" => Some(("can_axi4lite", &["can_axi4lite.v"])),
        "apb" | "apb3" => Some(("can_apb", &["can_apb.v"])),
        "regport" => Some(("can_regport", &["can_regport.v"])),
        _ => None,
    }
}

/// Runs the subcommand: exit 0 when no mutant survived (or timed out), 1 otherwise.
pub fn run(a: Args) -> anyhow::Result<i32> {
    anyhow::ensure!(a.budget_factor.is_finite() && a.budget_factor > 0.0, "--budget-factor {}: must be a number above 0", a.budget_factor);
    let (sources, profile) = match &a.external {
        None => {
            let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../rtl");
            let dir = dir.canonicalize().with_context(|| format!("our rtl/ at {}", dir.display()))?;
            let mut files: Vec<PathBuf> = RTL_FILES.iter().map(PathBuf::from).collect();
            // A host with a wrapper of its own mutates that wrapper with can_top.
            let top = match (a.top.as_str(), wrapper_of(&a.host)) {
                ("can_top", Some((top, extra))) => {
                    files.extend(extra.iter().map(PathBuf::from));
                    top.to_string()
                }
                _ => a.top.clone(),
            };
            (mutate::CoreSources { dir, top, files, ..Default::default() }, cosim::Profile::rtl())
        }
        Some(dir) => {
            let probe = cosim::ExternalCore { dir: dir.clone(), top: a.top.clone(), ..Default::default() };
            probe.check().with_context(|| format!("--external {}", dir.display()))?;
            let Some(p) = &a.profile else {
                anyhow::bail!("--external {}: {}", dir.display(), cosim::profile::missing_profile_message(dir, &a.top));
            };
            let mut defines = vec!["CAN_WISHBONE_IF".to_string()];
            defines.extend(a.defines.iter().cloned());
            let dir = dir.canonicalize().with_context(|| format!("--external {}", dir.display()))?;
            (mutate::CoreSources { dir, top: a.top.clone(), defines, ..Default::default() }, cosim::Profile::find(p)?)
        }
    };
    let mut scenarios = Vec::new();
    for p in &a.inputs {
        if p.extension().is_some_and(|e| e == "toml") {
            scenarios.push(scenario::Scenario::load(p)?);
        } else {
            scenarios.extend(scenario::load_list(p)?);
        }
    }
    if a.fresh {
        for e in std::fs::read_dir(&a.out).into_iter().flatten().flatten() {
            let n = e.file_name().to_string_lossy().into_owned();
            if n.starts_with("journal-") && n.ends_with(".jsonl") {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
    let cfg = mutate::MutateConfig {
        sources,
        from: match &a.list {
            Some(p) => mutate::MutationSource::Saved(p.clone()),
            None => mutate::MutationSource::Sample { count: a.count, seed: a.seed },
        },
        scenarios,
        profile,
        run: scenario::RunOptions { waivers: a.waivers.clone(), host: scenario::HostBfm::from_name(&a.host), ..Default::default() },
        campaign: mutate::CampaignOptions {
            jobs: a.jobs,
            shard: a.shard,
            progress: std::io::IsTerminal::is_terminal(&std::io::stderr()),
            budget_factor: a.budget_factor,
            ..Default::default()
        },
        formal: (!a.no_formal).then_some(mutate::FormalOptions { steps: a.formal_steps, induction: a.formal_steps, ..Default::default() }),
        out: a.out.clone(),
        cache: cosim::cache_dir(),
        campaign_frames: a.campaign_frames,
        campaign_seed: a.campaign_seed,
    };
    let report = mutate::mutate(&cfg, &mut |l| eprintln!("{l}"))?;
    println!("{}", report.summary());
    let surv = report.survivors();
    if !surv.is_empty() {
        println!("survivors:");
        for m in &surv {
            let f = match report.hidden_by(m.id) {
                Some(h) => h.describe(),
                None => report.formal_of(m.id).map(|f| f.describe()).unwrap_or_else(|| "not checked".into()),
            };
            println!("  {:>4} {:<18} {}  [{f}]", m.id, m.location, m.description);
        }
    }
    println!("report: {} and {}", a.out.join("report.md").display(), a.out.join("report.json").display());
    Ok(if surv.is_empty() { 0 } else { 1 })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each host's wrapper top is a module declared in the files mutate
    /// adds for it (a wrong name or a missing file would only show as a
    /// build failure of the mutated core).
    #[test]
    fn every_host_wrapper_is_a_module_of_its_files() {
        let rtl = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../rtl");
        for host in ["i8051", "motorola", "axi4-lite", "apb", "apb3", "regport"] {
            let (top, files) = wrapper_of(host).unwrap_or_else(|| panic!("{host}: no wrapper"));
            let text: String = files.iter().map(|f| std::fs::read_to_string(rtl.join(f)).unwrap_or_else(|e| panic!("{host}: {f}: {e}"))).collect();
            assert!(text.contains(&format!("module {top}")), "{host}: no `module {top}` in {files:?}");
        }
        for host in ["wishbone", "pio", "pio-edge"] {
            assert_eq!(wrapper_of(host), None, "{host} drives can_top itself");
        }
    }
}
