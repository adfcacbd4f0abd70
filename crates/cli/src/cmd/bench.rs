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
    /// Frames of the campaign rows (`cancosim campaign`, seed 1, quanta up to BRP 3, one job):
    /// frames per CPU second on our rtl/ and, with --campaign-external, on that core (0: no rows).
    #[arg(long, default_value_t = 300)]
    campaign_frames: u64,
    /// A second campaign row on this core: DIR@PROFILE (e.g. path/to/can@opencores-can; defines
    /// CAN_WISHBONE_IF, DIR as include dir).
    #[arg(long, value_name = "DIR@PROFILE")]
    campaign_external: Option<String>,
    /// A campaign row on our rtl/ through this host (repeatable): its wrapper and bus model.
    #[arg(long = "host", value_name = "HOST", value_parser = ["wishbone", "avalon", "pio", "pio-edge", "i8051", "axi4-lite", "apb", "apb3", "motorola", "regport"])]
    hosts: Vec<String>,
}

/// A campaign row: frames per CPU second of `cancosim campaign` on one DUT.
#[derive(serde::Serialize)]
struct CampaignRow {
    dut: String,
    frames: u64,
    runs: u64,
    cpu_s: f64,
    frames_per_cpu_second: f64,
    passed: bool,
}

/// Runs a fixed campaign on `dut` (one job, so the CPU time is the run's).
fn campaign_row(dut: scenario::DutSpec, frames: u64, host: Option<scenario::HostBfm>) -> CampaignRow {
    let mut c = campaign::random::RandomConfig::new(1, frames, dut);
    c.host = host;
    if let Some(h) = host {
        c.dut.name = format!("{} (host {})", c.dut.name, h.name());
    }
    c.jobs = 1;
    c.shrink_runs = 0;
    c.limits = campaign::plan::DrawLimits { max_brp: 3, ..Default::default() };
    let r = campaign::random::run_campaign(&c);
    CampaignRow { dut: c.dut.name.clone(), frames: r.frames, runs: r.runs, cpu_s: r.busy.as_secs_f64(), frames_per_cpu_second: r.frames_per_cpu_second(), passed: r.failures.is_empty() }
}

fn campaign_rows(a: &Args) -> anyhow::Result<Vec<CampaignRow>> {
    if a.campaign_frames == 0 {
        return Ok(Vec::new());
    }
    let frames = if a.smoke { a.campaign_frames.min(30) } else { a.campaign_frames };
    let mut rows = vec![campaign_row(scenario::DutSpec::rtl(), frames, None)];
    for h in &a.hosts {
        let host = scenario::HostBfm::from_name(h).ok_or_else(|| anyhow::anyhow!("--host {h}: no such host"))?;
        rows.push(campaign_row(scenario::DutSpec::rtl(), frames, Some(host)));
    }
    if let Some(e) = &a.campaign_external {
        let (dir, prof) = e.rsplit_once('@').ok_or_else(|| anyhow::anyhow!("--campaign-external {e}: expected DIR@PROFILE"))?;
        let mut d = scenario::DutSpec::external(dir, dir, "can_top").with_profile(cosim::Profile::find(prof)?);
        if let scenario::DutKind::External { defines, includes, .. } = &mut d.kind {
            defines.push("CAN_WISHBONE_IF".into());
            includes.push(dir.into());
        }
        rows.push(campaign_row(d, frames, None));
    }
    Ok(rows)
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
    let campaign = campaign_rows(&a)?;
    let mutation_row = match a.mutants {
        Some(k) => Some(mutation_row(k, a.rebuild, &a.mutant_scenarios, o.seed)?),
        None => None,
    };
    if a.json {
        let mut v: serde_json::Value = serde_json::from_str(&report.to_json())?;
        if let Some(r) = &mutation_row {
            v["mutation"] = serde_json::to_value(r)?;
        }
        v["campaign"] = serde_json::to_value(&campaign)?;
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        print!("{}", report.to_table());
        if let Some(r) = &mutation_row {
            println!("{}", r.row());
        }
        for r in &campaign {
            println!(
                "campaign on {}: {:.0} frames per CPU second ({} frames in {} runs, {:.1} s CPU; seed 1, BRP up to 3){}",
                r.dut,
                r.frames_per_cpu_second,
                r.frames,
                r.runs,
                r.cpu_s,
                if r.passed { "" } else { "; some runs diverged (judge them with `cancosim campaign` and the core's waivers)" }
            );
        }
    }
    // Our rtl/ must agree with the model; another core's deviations are judged by `campaign`.
    // (our rows come first: rtl/, then one per --host)
    let ours = campaign.iter().take(1 + a.hosts.len());
    Ok(if report.check().is_ok() && ours.into_iter().all(|r| r.passed) { 0 } else { 1 })
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
