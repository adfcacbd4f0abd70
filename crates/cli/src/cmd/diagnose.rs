//! `diagnose`: re-read a saved run record and explain it.

use anyhow::Context;
use std::path::PathBuf;

/// Arguments of `cancosim diagnose`.
#[derive(clap::Args)]
pub struct Args {
    /// Run record saved by `cancosim run --record FILE`.
    record: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// Runs the subcommand: exit 0 when the record shows no failure.
pub fn run(a: Args) -> anyhow::Result<i32> {
    let text = std::fs::read_to_string(&a.record).with_context(|| format!("reading {}", a.record.display()))?;
    let record: diagnose::RunRecord =
        serde_json::from_str(&text).with_context(|| format!("{}: not a run record", a.record.display()))?;
    let d = diagnose::diagnose(&record);
    if a.json {
        println!("{}", d.to_json());
    } else {
        println!("{}", d.to_text());
    }
    Ok(0)
}
