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
    /// Print candidate waiver entries (TOML) for the record's divergence; nothing is written or applied.
    #[arg(long)]
    suggest_waivers: bool,
    /// DUT revision to put in the suggested waivers.
    #[arg(long, value_name = "R", requires = "suggest_waivers")]
    dut_revision: Option<String>,
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
    if a.suggest_waivers {
        let mut dut = waivers::DutInfo::new(&record.dut);
        if let Some(r) = &a.dut_revision {
            dut = dut.revision(r);
        }
        let divergences: Vec<diagnose::Divergence> = record.divergence.iter().cloned().collect();
        if divergences.is_empty() {
            eprintln!("no divergence in {}: nothing to waive", a.record.display());
        } else {
            // Printed for a human to review, never written or applied.
            println!("{}", waivers::suggest(&divergences, &dut));
        }
    }
    Ok(0)
}
