//! `bench`: the performance table of issue 7, every ratio measured in one run.

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
    if a.json {
        println!("{}", report.to_json());
    } else {
        print!("{}", report.to_table());
    }
    Ok(if report.check().is_ok() { 0 } else { 1 })
}
