//! `campaign`: constrained-random co-simulation against any core that
//! `regress` takes: plans drawn from `(seed, index)`, run in lockstep with
//! the golden model and judged by a scoreboard; failures shrunk and saved
//! as scenarios.

use anyhow::Context;
use campaign::plan::DrawLimits;
use campaign::random::{RandomConfig, run_campaign};
use scenario::regress::parse_shard;
use std::path::PathBuf;

/// Arguments of `cancosim campaign`.
#[derive(clap::Args)]
pub struct Args {
    /// Seed of every random choice; a run is reproduced by (seed, index) alone.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Stop once this many frames (the model nodes' and the DUT's) were run.
    #[arg(long)]
    frames: Option<u64>,
    /// Stop starting runs after this many minutes (with --frames: whichever comes first).
    #[arg(long)]
    minutes: Option<f64>,
    /// Index of the first run (a later part of a campaign).
    #[arg(long, default_value_t = 0)]
    first_index: u64,
    #[command(flatten)]
    dut: super::regress::DutArgs,
    #[command(flatten)]
    host: super::run::HostArgs,
    #[command(flatten)]
    waivers: super::run::WaiverArgs,
    /// Worker threads (0 = one per core).
    #[arg(long, short, default_value_t = 0)]
    jobs: usize,
    /// Run only shard k of n (e.g. 2/4): run indices first + k - 1 + j n.
    #[arg(long, value_parser = parse_shard)]
    shard: Option<(usize, usize)>,
    /// Model nodes on the bus besides the DUT, as MIN..MAX.
    #[arg(long, default_value = "2..8", value_parser = parse_range)]
    nodes: (usize, usize),
    /// Frames per run, as MIN..MAX.
    #[arg(long, default_value = "3..16", value_parser = parse_range)]
    frames_per_run: (usize, usize),
    /// Probability that a frame of a run carries a fault (flip, stuck, glitch).
    #[arg(long, default_value_t = 0.25)]
    fault_rate: f64,
    /// Largest BRP drawn (0..63; a run's cost grows with the quantum).
    #[arg(long, default_value_t = 63)]
    max_brp: u8,
    /// Plans tried when shrinking one failure (0: no shrinking).
    #[arg(long, default_value_t = 80)]
    shrink_runs: usize,
    /// Stop after this many failing runs.
    #[arg(long, default_value_t = 5)]
    max_failures: usize,
    /// Write each failure, shrunk, as a scenario here (`cancosim run` replays it).
    #[arg(long, value_name = "DIR")]
    save_failures: Option<PathBuf>,
    /// Write the results as JSON here (totals, failures with their shrinking, waivers hit, every run).
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Write JUnit XML here (one testcase per run).
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// Write the HTML report here (DIR/index.html; each failing run, shrunk, with its waveform).
    #[arg(long, value_name = "DIR")]
    html: Option<PathBuf>,
}

fn parse_range(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = s.split_once("..").unwrap_or((s, s));
    let a: usize = a.trim().parse().map_err(|_| format!("'{s}': expected MIN..MAX, e.g. 2..8"))?;
    let b: usize = b.trim_start_matches('=').trim().parse().map_err(|_| format!("'{s}': expected MIN..MAX, e.g. 2..8"))?;
    if a > b {
        return Err(format!("'{s}': MIN is above MAX"));
    }
    Ok((a, b))
}

/// Runs the subcommand: exit 0 when no run failed, 1 on a failure, 2 on bad input, 125 when the core does not build.
pub fn run_cmd(a: Args) -> anyhow::Result<i32> {
    if !(0.0..=1.0).contains(&a.fault_rate) {
        anyhow::bail!("--fault-rate {} must be between 0 and 1", a.fault_rate);
    }
    if a.nodes.0 < 1 || a.nodes.1 > 8 {
        anyhow::bail!("--nodes {}..{}: between 1 and 8 model nodes", a.nodes.0, a.nodes.1);
    }
    if a.frames_per_run.0 < 1 || a.frames_per_run.1 > 64 {
        anyhow::bail!("--frames-per-run {}..{}: between 1 and 64", a.frames_per_run.0, a.frames_per_run.1);
    }
    if a.max_brp > 63 {
        anyhow::bail!("--max-brp {}: BRP is 6 bits (0..63)", a.max_brp);
    }
    if a.dut.duts.len() + a.dut.externals.len() > 1 {
        anyhow::bail!("a campaign runs on one DUT: give one --dut or one --external");
    }
    let frames = match (a.frames, a.minutes) {
        (None, None) => Some(200),
        (f, _) => f,
    };
    let duts = match super::regress::setup_duts(&a.dut, None, a.host.bfm(), &a.waivers.waivers, false) {
        Ok(d) => d,
        Err(super::regress::SetupError::Input(e)) => return Err(e),
        Err(super::regress::SetupError::Unbuildable(e)) => {
            eprintln!("cancosim: the core does not build (exit 125): {e:#}");
            return Ok(scenario::regress::EXIT_UNBUILDABLE);
        }
    };
    let mut dut = duts.into_iter().next().expect("setup gives at least our RTL");
    // Reports and waivers name an external core "<profile> (<dir>)".
    if let (scenario::DutKind::External { path, .. }, Some(p)) = (&dut.kind, &dut.profile) {
        dut.name = format!("{} ({})", p.name, path.display());
    }
    let cfg = RandomConfig {
        seed: a.seed,
        first_index: a.first_index,
        frames,
        minutes: a.minutes,
        limits: DrawLimits { nodes: a.nodes, frames: a.frames_per_run, fault_rate: a.fault_rate, max_brp: a.max_brp, avoid: Vec::new(), whole_quantum_glitches: false },
        dut,
        waivers: a.waivers.waivers.clone(),
        dut_revision: a.waivers.dut_revision.clone(),
        host: a.host.bfm(),
        jobs: a.jobs,
        shard: a.shard,
        shrink_runs: a.shrink_runs,
        save_failures: a.save_failures.clone(),
        max_failures: a.max_failures.max(1),
        progress: std::io::IsTerminal::is_terminal(&std::io::stderr()),
        held_inputs: Vec::new(),
        custom_dut: None,
    };
    let res = run_campaign(&cfg);
    print!("{}", res.to_text(&cfg));
    if let Some(p) = &a.json {
        std::fs::write(p, res.to_json(&cfg)).with_context(|| format!("writing {}", p.display()))?;
        println!("JSON: {}", p.display());
    }
    if let Some(p) = &a.junit {
        std::fs::write(p, res.report.to_junit()).with_context(|| format!("writing {}", p.display()))?;
        println!("JUnit: {}", p.display());
    }
    if let Some(dir) = &a.html {
        let opts = scenario::RegressOptions {
            waivers: cfg.waivers.clone(),
            dut_revision: cfg.dut_revision.clone(),
            host: cfg.host,
            jobs: 1,
            ..Default::default()
        };
        // Only the failing runs carry a page of their own (each rerun, shrunk, with its waveform).
        let page = scenario::html::write_report(dir, &res.failing_report(), &res.failing_scenarios, std::slice::from_ref(&cfg.dut), &opts)
            .with_context(|| format!("writing the HTML report in {}", dir.display()))?;
        println!("HTML report: {}", page.display());
    }
    Ok(if res.passed() { 0 } else { 1 })
}
