//! `campaign`: seeded random fault injection between the DUT and model
//! nodes; every counter, status and delivered frame compared.

use campaign::{CampaignConfig, DutChoice, run_campaign};

/// Arguments of `cancosim campaign`.
#[derive(clap::Args)]
pub struct Args {
    /// Seed of every random choice; a failing seed reproduces exactly.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Frames to run.
    #[arg(long, default_value_t = 100)]
    frames: u32,
    /// Index of the first frame (re-run a later segment).
    #[arg(long, default_value_t = 0)]
    first_frame: u32,
    /// DUT: `rtl` (our can_top) or `model` (self-check of the bench).
    #[arg(long, default_value = "rtl", value_parser = ["rtl", "model"])]
    dut: String,
    /// Probability that a frame carries a fault.
    #[arg(long, default_value_t = 0.7)]
    fault_rate: f64,
    /// Golden-model nodes besides the DUT (1..=4).
    #[arg(long, default_value_t = 2)]
    nodes: usize,
    /// No lockstep tolerance at all (tx, SOF, status and pins compared to
    /// the clock); the model against itself passes it, our RTL's status
    /// pipeline (up to ~16 CAN clocks) does not.
    #[arg(long)]
    strict: bool,
    /// Write the bench's VCD here (rewritten by each segment: use it with
    /// --first-frame to look at one disagreement).
    #[arg(long)]
    vcd: Option<std::path::PathBuf>,
}

/// Runs the subcommand: exit 1 on any disagreement.
pub fn run_cmd(a: Args) -> anyhow::Result<i32> {
    if !(0.0..=1.0).contains(&a.fault_rate) {
        anyhow::bail!("--fault-rate {} must be between 0 and 1", a.fault_rate);
    }
    if !(1..=4).contains(&a.nodes) {
        anyhow::bail!("--nodes {} must be between 1 and 4", a.nodes);
    }
    let cfg = CampaignConfig {
        seed: a.seed,
        frames: a.frames,
        first_frame: a.first_frame,
        dut: if a.dut == "model" { DutChoice::Model } else { DutChoice::Rtl },
        fault_rate: a.fault_rate,
        nodes: a.nodes,
        compare: a.strict.then(CampaignConfig::strict_compare),
        vcd: a.vcd,
        ..CampaignConfig::default()
    };
    let report = run_campaign(&cfg);
    print!("{}", report.to_text());
    Ok(if report.passed() { 0 } else { 1 })
}
