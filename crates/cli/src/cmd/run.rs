//! `run` and `cosim`: play one scenario on a DUT in lockstep with the golden
//! model, print the numbered steps' verdict and the diagnosis.

use anyhow::Context;
use scenario::{DutSpec, RunOptions, Scenario, run};
use std::path::PathBuf;

/// Which DUT to run against, when not the scenario's own.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct DutArgs {
    /// Bundled DUT instead of the scenario's: `rtl` (our can_top) or `model` (the golden model).
    #[arg(long, value_parser = ["rtl", "model"], conflicts_with = "external")]
    pub dut: Option<String>,
    /// An external core's directory (Verilog and/or VHDL files; the opencores can_top port list or the 8051 bus).
    #[arg(long, value_name = "DIR")]
    pub external: Option<PathBuf>,
    /// Top module of the external core.
    #[arg(long, default_value = "can_top", requires = "external")]
    pub top: String,
    /// Verilog define for the external core (repeatable), e.g. CAN_WISHBONE_IF.
    #[arg(long = "define", value_name = "NAME[=VALUE]", requires = "external")]
    pub defines: Vec<String>,
    /// Include directory for the external core (repeatable).
    #[arg(long = "include", value_name = "DIR", requires = "external")]
    pub includes: Vec<PathBuf>,
    /// Name of the external core in reports (default "<profile name> (<dir>)").
    #[arg(long, requires = "external")]
    pub name: Option<String>,
    /// Core profile (tb/profiles/NAME.toml or a file): when host accesses take effect, the bit
    /// timing's phase origin, tolerances, port map. Required with --external; our RTL and the
    /// model have their own (rtl.toml, launch edge).
    #[arg(long, value_name = "NAME|FILE")]
    pub profile: Option<String>,
}

impl DutArgs {
    /// The DUT these arguments select, if any; an external core without
    /// `--profile` is an error that says what to declare.
    pub fn spec(&self) -> anyhow::Result<Option<DutSpec>> {
        let profile = self.profile.as_deref().map(cosim::Profile::find).transpose()?;
        if let Some(dir) = &self.external {
            let Some(p) = profile else {
                anyhow::bail!("{}", cosim::profile::missing_profile_message(dir, &self.top));
            };
            let mut d = DutSpec::external(&dir.display().to_string(), dir.clone(), &self.top).with_profile(p);
            if let Some(n) = &self.name {
                d.name.clone_from(n);
            }
            if let scenario::DutKind::External { defines, includes, .. } = &mut d.kind {
                defines.clone_from(&self.defines);
                includes.clone_from(&self.includes);
            }
            return Ok(Some(d));
        }
        let d = match self.dut.as_deref() {
            Some("rtl") => Some(DutSpec::rtl()),
            Some("model") => Some(DutSpec::model()),
            _ => None,
        };
        Ok(match (d, profile) {
            (Some(d), Some(p)) => Some(d.with_profile(p)),
            (None, Some(_)) => anyhow::bail!("--profile needs --dut or --external (the scenario's own DUT keeps its own profile)"),
            (d, None) => d,
        })
    }
}

/// Waivers of known DUT deviations, shared by `run`/`cosim` and `regress`.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct WaiverArgs {
    /// Waiver file (repeatable), added to the scenario's own `[run] waivers`.
    #[arg(long = "waivers", value_name = "FILE")]
    pub waivers: Vec<PathBuf>,
    /// DUT revision the waivers' `revisions` ranges are matched against.
    #[arg(long, value_name = "R")]
    pub dut_revision: Option<String>,
    /// Keep comparing after an unwaived divergence to see them all (default: stop at the first).
    #[arg(long, conflicts_with = "stop_at_first")]
    pub collect: bool,
    /// Stop the comparison at the first unwaived divergence (the default).
    #[arg(long)]
    pub stop_at_first: bool,
}

impl WaiverArgs {
    /// The comparator's mode these flags select.
    pub fn mode(&self) -> waivers::CollectMode {
        if self.collect { waivers::CollectMode::Collect } else { waivers::CollectMode::StopAtFirst }
    }
}

/// Arguments of `cancosim run` / `cancosim cosim`.
#[derive(clap::Args)]
pub struct Args {
    /// Scenario file (tb/*.toml).
    scenario: PathBuf,
    #[command(flatten)]
    dut: DutArgs,
    /// Write a VCD (DUT ports, model, bus, decoded fields) here, and a GTKWave view next to it (.gtkw).
    #[arg(long)]
    vcd: Option<PathBuf>,
    /// Save the run record (JSON) for `cancosim diagnose`.
    #[arg(long)]
    record: Option<PathBuf>,
    /// Write the bus traffic as a candump log (`candump -l` format, timestamps = simulated time).
    #[arg(long, value_name = "FILE")]
    candump: Option<PathBuf>,
    /// Interface name in the candump log.
    #[arg(long, default_value = "can0", requires = "candump")]
    candump_iface: String,
    /// Print the diagnosis as JSON instead of text.
    #[arg(long)]
    json: bool,
    /// Override the scenario's run length, in bit times.
    #[arg(long)]
    max_bits: Option<u64>,
    #[command(flatten)]
    host: HostArgs,
    #[command(flatten)]
    waivers: WaiverArgs,
}

/// Host override, shared by `run`/`cosim` and `regress`.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct HostArgs {
    /// Drive the DUT through this host instead of the scenario's own: `wishbone` (can_top),
    /// `avalon` (our can_avalon wrapper with the Avalon-MM BFM), `pio` (GPIO bit-banging,
    /// can_top_pio; the thesis's program polls ack as a level), `pio-edge` (the same program
    /// polling the ack PIO's edge capture register: for a core with a one-clock ack), `i8051` (the SJA1000's Intel-mode multiplexed bus, can_top_8051), `axi4-lite` (can_axi4lite), `apb` (APB4), `apb3` (can_apb), `motorola` (the SJA1000's Motorola-mode multiplexed bus, can_top_mcu with MODE low) or `regport` (a plain register port on the CAN clock, can_regport).
    /// Scenarios whose point is their host wiring (`[host] fixed`) are skipped.
    #[arg(long, value_parser = ["wishbone", "avalon", "pio", "pio-edge", "i8051", "axi4-lite", "apb", "apb3", "motorola", "regport"])]
    pub host: Option<String>,
}

impl HostArgs {
    /// The host these arguments select, if any.
    pub fn bfm(&self) -> Option<scenario::HostBfm> {
        self.host.as_deref().and_then(scenario::HostBfm::from_name)
    }
}

/// Runs the subcommand: exit 0 when the outcome matches the scenario's `[expect]`.
pub fn run_cmd(a: Args) -> anyhow::Result<i32> {
    let s = Scenario::load(&a.scenario)?;
    if let Some(dir) = &a.dut.external {
        // A directory that cannot hold the core is bad input (exit 2).
        let core = cosim::ExternalCore { dir: dir.clone(), top: a.dut.top.clone(), ..Default::default() };
        core.check().with_context(|| format!("--external {}", dir.display()))?;
    }
    let dut = a.dut.spec()?;
    // VHDL sources: GHDL's errors are bad input too (exit 2, file:line), said before the run.
    if let Some(core) = dut.as_ref().map(|d| scenario::run::external_core(d, a.host.bfm())).transpose().map_err(anyhow::Error::msg)?.flatten() {
        cosim::vhdl::lower(&core, &cosim::cache_dir()).with_context(|| format!("--external {}", core.dir.display()))?;
    }
    let opts = RunOptions {
        dut,
        vcd: a.vcd.clone(),
        max_bits: a.max_bits,
        waivers: a.waivers.waivers.clone(),
        dut_revision: a.waivers.dut_revision.clone(),
        collect: a.waivers.mode(),
        host: a.host.bfm(),
        ..Default::default()
    };
    if !a.json {
        println!("{}", s.header());
    }
    let out = run(&s, &opts);
    if let Some(why) = &out.skipped {
        println!("scenario: SKIPPED ({why})");
        return Ok(0);
    }
    if let Some(p) = &a.candump {
        std::fs::write(p, cosim::candump::write_log(&out.bus_log, &a.candump_iface)).with_context(|| format!("writing {}", p.display()))?;
    }
    if let Some(p) = &a.record {
        let json = serde_json::to_string_pretty(&out.record).context("serialising the run record")?;
        std::fs::write(p, json).with_context(|| format!("writing {}", p.display()))?;
    }
    if a.json {
        println!("{}", out.diagnosis.to_json());
    } else {
        let host = opts.host.map(|h| format!("   host: {h} (override)")).unwrap_or_default();
        println!("DUT: {}{host}   wall time: {:.2} s", out.dut, out.wall.as_secs_f64());
        if let Some(p) = opts.dut.as_ref().and_then(|d| d.profile.as_ref()) {
            println!("{}", p.describe());
            println!("tolerances: {}", p.tolerances.describe());
        }
        for (node, n) in &out.received {
            println!("node {node}: {n} frame(s) received");
        }
        println!();
        println!("{}", out.diagnosis.to_text());
        // The opencores core without its Wishbone define is its 8051 build:
        // say how to get the Wishbone one (regress adds the define itself).
        if a.dut.defines.is_empty()
            && out.record.error.as_deref().is_some_and(|e| e.contains("no port `wb_clk_i`") && e.contains("ale_i"))
        {
            println!("hint: this top has the 8051 port list; the opencores core selects its Wishbone interface with --define CAN_WISHBONE_IF (and --include DIR for timescale.v), as `regress --external` does\n");
        }
        if let Some(r) = out.waivers.as_ref().filter(|r| !r.waiver_file.is_empty() || !r.failures.is_empty()) {
            println!("{}", r.to_text());
        }
        if let Some(p) = &a.vcd {
            println!("waveform: {} (GTKWave view: {})", p.display(), cosim::gtkw::path_for(p).display());
        }
        if let Some(p) = &a.candump {
            println!("bus log: {} ({} line(s), candump -l format)", p.display(), out.bus_log.len());
        }
        if out.passed {
            println!("scenario: PASS (outcome as expected)");
        } else {
            println!("scenario: FAIL");
            for m in &out.mismatches {
                println!("  - {m}");
            }
        }
    }
    Ok(if out.passed { 0 } else { 1 })
}
