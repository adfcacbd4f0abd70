//! `profile infer`: a core profile from probe runs (the `profile-infer`
//! crate), written with its evidence; candidate deviations reported, never
//! absorbed.

use anyhow::Context;
use std::path::PathBuf;

/// Arguments of `cancosim profile`.
#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: Sub,
}

#[derive(clap::Subcommand)]
enum Sub {
    /// Find an external core's port roles and measure each freedom of its profile from short probe runs.
    Infer(InferArgs),
}

/// Arguments of `cancosim profile infer`.
#[derive(clap::Args)]
pub struct InferArgs {
    /// The core's source directory (Verilog; also an include directory).
    #[arg(long, value_name = "DIR")]
    external: PathBuf,
    /// Its top module.
    #[arg(long, default_value = "can_top")]
    top: String,
    /// Verilog define (repeatable; CAN_WISHBONE_IF is always defined).
    #[arg(long = "define", value_name = "NAME[=VALUE]")]
    defines: Vec<String>,
    /// Extra include directory (repeatable).
    #[arg(long = "include", value_name = "DIR")]
    includes: Vec<PathBuf>,
    /// The host bus the probes drive. `wishbone`, `avalon`, `pio`: the top's Wishbone roles
    /// ([ports]), the timing written to all three; `axi4-lite`, `apb`, `apb3`, `regport`,
    /// `motorola`: that bus's roles ([ports.<bus>]) and its [access.<bus>] entry only.
    #[arg(long, default_value = "wishbone", value_parser = ["wishbone", "avalon", "pio", "axi4-lite", "apb", "apb3", "regport", "motorola"])]
    host: String,
    /// A port role the names leave open, ROLE=NAME or ROLE=NAME:low|high (repeatable),
    /// e.g. --port host-clock=clk --port reset=nrst:low; a host bus's role as BUS.ROLE,
    /// e.g. --port apb.psel=SEL --port regport.wr=we_n:low.
    #[arg(long = "port", value_name = "ROLE=NAME")]
    ports: Vec<String>,
    /// The register port's read latency in clocks after the strobe (--host regport), when
    /// known; without it the least latency at which the probes' reads agree is measured.
    #[arg(long, value_name = "CLOCKS")]
    read_latency: Option<u32>,
    /// The profile's name (default: the top's).
    #[arg(long)]
    name: Option<String>,
    /// Waiver file of deviations already known and accepted (repeatable): the probes run with it,
    /// as regress --waivers does; its `dut` globs match "<name> (<dir>)".
    #[arg(long = "waivers", value_name = "FILE")]
    waivers: Vec<PathBuf>,
    /// Where to write the profile.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
}

/// Runs the subcommand: 0 when the profile was written with no candidate
/// deviation, 1 when a measurement fell outside its bound (the profile is
/// written with that entry at its bound, the deviation printed), 2 for bad
/// input or a core that does not build.
pub fn run(a: Args) -> anyhow::Result<i32> {
    let Sub::Infer(a) = a.command;
    let ports = a
        .ports
        .iter()
        .map(|p| p.split_once('=').map(|(r, n)| (r.trim().to_string(), n.trim().to_string())).with_context(|| format!("--port {p}: expected ROLE=NAME")))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let opts = profile_infer::InferOptions {
        dir: a.external.clone(),
        top: a.top.clone(),
        defines: a.defines,
        includes: a.includes,
        host: scenario::HostBfm::from_name(&a.host).context("--host")?,
        read_latency: a.read_latency,
        ports,
        name: a.name.unwrap_or_else(|| a.top.clone()),
        waivers: a.waivers,
    };
    // A bad waiver file is one error before any probe.
    cosim::waivers::WaiverSet::load_all(&opts.waivers)?;
    let inf = profile_infer::infer(&opts)?;
    for e in &inf.evidence {
        println!("{:<13} {}", e.key, e.line);
    }
    std::fs::write(&a.out, &inf.toml).with_context(|| format!("writing {}", a.out.display()))?;
    println!(
        "profile written to {} ({} probe runs in {:.1} s; build {:.1} s{})",
        a.out.display(),
        inf.runs,
        inf.probing.as_secs_f64(),
        inf.build.as_secs_f64(),
        if inf.build.as_secs_f64() < 1.0 { ", cached" } else { "" }
    );
    if inf.deviations.is_empty() {
        let host = if a.host == "wishbone" { String::new() } else { format!(" --host {}", a.host) };
        println!("next: cancosim regress tb/regression.list --external mine={} --top {} --profile {}{host}", a.external.display(), a.top, a.out.display());
        return Ok(0);
    }
    for d in &inf.deviations {
        println!("{d}");
    }
    println!(
        "{} candidate deviation(s): not written into the profile (each entry stays at its bound). \
         If the datasheet allows it after all, say so in the profile by hand; if not, the core deviates: accept it only with a waiver naming the clause (docs/guide/bring-your-own-core.md).",
        inf.deviations.len()
    );
    Ok(1)
}
