//! `bench`: the performance table, every ratio measured in one run.

use bench::{BenchOptions, run};

/// Arguments of `cancosim bench`.
#[derive(clap::Args)]
pub struct Args {
    /// CI-sized run (seconds): tiny frame counts, same table.
    #[arg(long)]
    smoke: bool,
    /// Frames of the self-test workload (model, co-simulation, raw C++ harness).
    #[arg(long)]
    frames: Option<u32>,
    /// Frames under Icarus (slow).
    #[arg(long)]
    icarus_frames: Option<u32>,
    /// Seed of every workload.
    #[arg(long)]
    seed: Option<u64>,
    /// Interleaved runs of the co-sim and raw-harness rows; each keeps its
    /// least CPU time (default 3; 1 with --smoke).
    #[arg(long)]
    repeat: Option<u32>,
    /// Print JSON instead of the table.
    #[arg(long)]
    json: bool,
    /// Add the mutation rows: time per mutant for K mutants of our rtl/ in one `-ctrl` build
    /// (build shared by the K, plus each one's simulations) vs a build per mutant (measured on
    /// --rebuild of them; cold Verilator builds: minutes). `--mutants` alone: 200, the size
    /// of the README's campaign.
    #[arg(long, value_name = "K", num_args = 0..=1, default_missing_value = "200")]
    mutants: Option<u32>,
    /// Mutants rebuilt alone for the comparison (their mean per mutant is used).
    #[arg(long, value_name = "N", default_value_t = 2)]
    rebuild: usize,
    /// Scenario set every mutant runs on both paths (scenario files or lists, repeatable;
    /// default tb/de2-pelican-selftest.toml).
    #[arg(long = "mutant-scenarios", value_name = "PATH")]
    mutant_scenarios: Vec<std::path::PathBuf>,
}

/// Runs the subcommand: exit 1 when a workload's read-back was wrong.
pub fn run_cmd(a: Args) -> anyhow::Result<i32> {
    let mut o = if a.smoke { BenchOptions::smoke() } else { BenchOptions::default() };
    if let Some(f) = a.frames {
        o.frames = f;
    }
    if let Some(f) = a.icarus_frames {
        o.icarus_frames = f;
    }
    if let Some(s) = a.seed {
        o.seed = s;
    }
    if let Some(r) = a.repeat {
        o.repeat = r;
    }
    let report = run(&o)?;
    let mutation_row = match a.mutants {
        Some(k) => Some(mutation_row(k, a.rebuild, &a.mutant_scenarios, o.seed)?),
        None => None,
    };
    if a.json {
        let mut v: serde_json::Value = serde_json::from_str(&report.to_json())?;
        if let Some(r) = &mutation_row {
            v["mutation"] = serde_json::to_value(r)?;
        }
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        print!("{}", report.to_table());
        if let Some(r) = &mutation_row {
            println!("{}", r.row());
        }
    }
    Ok(if report.check().is_ok() { 0 } else { 1 })
}

/// The mutation rows: `-ctrl` build vs a build per mutant, in this run.
fn mutation_row(k: u32, rebuild: usize, inputs: &[std::path::PathBuf], seed: u64) -> anyhow::Result<mutate::bench::CtrlVsRebuild> {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let rtl = root.join("rtl").canonicalize()?;
    let files = super::mutate::RTL_FILES.iter().map(std::path::PathBuf::from).collect();
    let sources = mutate::CoreSources { dir: rtl, top: "can_top".into(), files, ..Default::default() };
    let mut scenarios = Vec::new();
    for p in inputs {
        if p.extension().is_some_and(|e| e == "toml") {
            scenarios.push(scenario::Scenario::load(p)?);
        } else {
            scenarios.extend(scenario::load_list(p)?);
        }
    }
    if scenarios.is_empty() {
        scenarios.push(scenario::Scenario::load(root.join("tb/de2-pelican-selftest.toml"))?);
    }
    let work = tempfile_dir()?;
    // The 200 of the README's campaign, as a computed row.
    let r = mutate::bench::ctrl_vs_rebuild(&sources, &scenarios, &cosim::Profile::rtl(), k, rebuild, seed, &work, 200);
    let _ = std::fs::remove_dir_all(&work);
    Ok(r?)
}

/// A fresh directory for cold builds (under the build cache's parent, same file system).
fn tempfile_dir() -> anyhow::Result<std::path::PathBuf> {
    let d = cosim::cache_dir().join(format!("bench-mutants-{}-{}", std::process::id(), std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH)?.as_millis()));
    std::fs::create_dir_all(&d)?;
    Ok(d)
}
