//! `regress`: every scenario of a list against one or more DUTs, in
//! parallel; a DUT x scenario table, JUnit XML, shards for CI matrices.

use anyhow::Context;
use scenario::regress::{RegressOptions, parse_shard};
use scenario::DutSpec;
use std::path::PathBuf;

/// Arguments of `cancosim regress`.
#[derive(clap::Args)]
pub struct Args {
    /// Regression list (one scenario path per line) or scenario files.
    #[arg(default_value = "tb/regression.list")]
    inputs: Vec<PathBuf>,
    #[command(flatten)]
    dut: DutArgs,
    /// The old revision to compare the (one) --external with, NAME=DIR[@PROFILE] or
    /// NAME=git:REPO@REV[:SUBDIR]: per scenario fixed / broken / still failing / still passing;
    /// exit 1 only when something broke.
    #[arg(long, value_name = "NAME=DIR[@PROFILE]")]
    baseline: Option<String>,
    /// Worker threads (0 = one per core).
    #[arg(long, short, default_value_t = 0)]
    jobs: usize,
    /// Run only shard k of n (e.g. 2/4).
    #[arg(long, value_parser = parse_shard)]
    shard: Option<(usize, usize)>,
    /// Write JUnit XML here (an expected failure is a skipped testcase
    /// whose message names its entry).
    #[arg(long)]
    junit: Option<PathBuf>,
    /// Write the results as JSON here (counts, and per cell its status; an
    /// expected failure with its entry and verdict).
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    /// Run every scenario in collect mode and write, for each run that did
    /// not pass (or did not fail as its [[expected-failure]] entry
    /// records), an [[expected-failure]] entry with the signature it showed,
    /// to paste into a waiver file after filling in deviation, clause and
    /// reason. Never edits a waiver file.
    #[arg(long, value_name = "FILE")]
    record_expected_failures: Option<PathBuf>,
    /// How the recorded entries place a divergence: `bit` (its bit time) or
    /// `step` (the scenario step it happened in, so one entry holds on every
    /// host: `place = "step"`; an expected failure whose entry places by bit
    /// is then recorded too, to move it).
    #[arg(long, value_name = "PLACE", default_value = "bit", value_parser = ["bit", "step"])]
    record_place: String,
    /// Write a self-contained HTML report (DIR/index.html, files of failed runs in DIR/runs/).
    #[arg(long, value_name = "DIR")]
    html: Option<PathBuf>,
    /// Code coverage: build each Verilated DUT with Verilator's line, toggle
    /// and branch coverage, merge the runs into DIR/<dut>/coverage.info and
    /// an HTML report (DIR/<dut>/html/index.html), print a summary per file.
    #[arg(long, value_name = "DIR")]
    coverage: Option<PathBuf>,
    /// Print the functional coverage table (protocol and registers, seen
    /// from the golden model's side) per DUT; also printed with --coverage.
    #[arg(long)]
    funcov: bool,
    /// Write the functional coverage bins per DUT as JSON here.
    #[arg(long, value_name = "FILE")]
    funcov_json: Option<PathBuf>,
    /// Override every scenario's run length, in bit times.
    #[arg(long)]
    max_bits: Option<u64>,
    #[command(flatten)]
    host: super::run::HostArgs,
    #[command(flatten)]
    waivers: super::run::WaiverArgs,
}

/// The devices under test of `regress` and `campaign`.
#[derive(clap::Args, Clone)]
pub struct DutArgs {
    /// Bundled DUTs to run against (repeatable): rtl, model.
    #[arg(long = "dut", value_parser = ["rtl", "model"])]
    pub duts: Vec<String>,
    /// External core as NAME=DIR or NAME=DIR@PROFILE (repeatable; define CAN_WISHBONE_IF, DIR as
    /// include dir). Each needs a profile: its own @PROFILE, else --profile.
    /// DIR may be `git:REPO@REV[:SUBDIR]` (exported with git archive into the build cache).
    #[arg(long = "external", value_name = "NAME=DIR[@PROFILE]")]
    pub externals: Vec<String>,
    /// Core profile (tb/profiles/NAME.toml or a file) of every --external without @PROFILE
    /// (e.g. --profile opencores-can); the column is then named "<profile> (<dir>)".
    #[arg(long, value_name = "NAME|FILE")]
    pub profile: Option<String>,
    /// Top module of the external cores (the opencores `can_top` port list).
    #[arg(long, default_value = "can_top")]
    pub top: String,
}

/// Why the DUTs could not be set up: the user's input (an `Err` of the
/// command: exit 2) or the core itself (exit 125, `git bisect run` skips).
pub enum SetupError {
    Input(anyhow::Error),
    Unbuildable(anyhow::Error),
}

impl From<anyhow::Error> for SetupError {
    fn from(e: anyhow::Error) -> Self {
        SetupError::Input(e)
    }
}

impl From<cosim::ProfileError> for SetupError {
    fn from(e: cosim::ProfileError) -> Self {
        SetupError::Input(e.into())
    }
}

/// Runs the subcommand: exit 0 only when every pair passed; the codes are
/// `scenario::regress::EXIT_*` (0 passed, 1 failed, 2 bad input, 125 the
/// core does not build).
pub fn run(a: Args) -> anyhow::Result<i32> {
    let duts = match setup_duts(&a.dut, a.baseline.as_ref(), a.host.bfm(), &a.waivers.waivers, a.coverage.is_some()) {
        Ok(d) => d,
        Err(SetupError::Input(e)) => return Err(e),
        Err(SetupError::Unbuildable(e)) => {
            eprintln!("cancosim: the core does not build (exit 125): {e:#}");
            return Ok(scenario::regress::EXIT_UNBUILDABLE);
        }
    };
    run_on(a, duts)
}

/// The DUTs of the command line, each external core checked and built.
pub fn setup_duts(
    a: &DutArgs,
    baseline: Option<&String>,
    host: Option<scenario::HostBfm>,
    waiver_files: &[PathBuf],
    coverage: bool,
) -> Result<Vec<DutSpec>, SetupError> {
    let unbuildable = SetupError::Unbuildable;
    let mut duts: Vec<DutSpec> = a
        .duts
        .iter()
        .map(|d| if d == "model" { DutSpec::model() } else { DutSpec::rtl() })
        .collect();
    // A bad waiver file (or [[expected-failure]] entry) is one error before
    // any run (exit 2, file:line: key), not an error cell per scenario.
    waivers::WaiverSet::load_all(waiver_files).map_err(|e| SetupError::Input(e.into()))?;
    let common = a.profile.as_deref().map(cosim::Profile::find).transpose()?;
    if baseline.is_some() && a.externals.len() != 1 {
        return Err(anyhow::anyhow!("--baseline compares with exactly one --external (the new revision)").into());
    }
    for e in baseline.into_iter().chain(&a.externals) {
        let (name, spec) = e.split_once('=').with_context(|| format!("--external {e}: expected NAME=DIR[@PROFILE]"))?;
        let (dir, own): (String, Option<cosim::Profile>) = if super::gitcore::parse(spec).is_some() {
            // A git name takes --profile (its @ is the revision's). A
            // revision without the SUBDIR cannot be tested (125); a
            // revision that does not exist is the user's input (2).
            match super::gitcore::export(spec) {
                Ok(d) => (d.display().to_string(), None),
                Err(x) if x.is::<super::gitcore::NotInRevision>() => return Err(unbuildable(x.context(format!("--external {e}")))),
                Err(x) => return Err(x.context(format!("--external {e}")).into()),
            }
        } else {
            match spec.rsplit_once('@') {
                Some((d, p)) => (d.to_string(), Some(cosim::Profile::find(p).with_context(|| format!("--external {e}"))?)),
                None => (spec.to_string(), None),
            }
        };
        let dir = dir.as_str();
        // The directory first: a path that holds no core is the first thing
        // to say. Missing, empty or without the top, the revision's core
        // cannot be tested (125), as when it does not build.
        let probe = cosim::ExternalCore { dir: dir.into(), top: a.top.clone(), ..Default::default() };
        probe.check().with_context(|| format!("--external {name}={dir}")).map_err(unbuildable)?;
        let Some(profile) = own.or_else(|| common.clone()) else {
            return Err(anyhow::anyhow!("--external {e}: {}", cosim::profile::missing_profile_message(std::path::Path::new(dir), &a.top)).into());
        };
        println!("{} ({dir}): {}", profile.name, profile.describe());
        println!("  tolerances: {}", profile.tolerances.describe());
        // The column keeps NAME; the DUT (waivers, records) is "<profile> (<dir>)".
        let mut d = DutSpec::external(dir, dir, &a.top).with_profile(profile);
        d.name = name.to_string();
        if let scenario::DutKind::External { defines, includes, .. } = &mut d.kind {
            // The opencores core's Wishbone build; over the 8051 bus its
            // default build (the profile's [access.i8051] says how).
            if host != Some(scenario::HostBfm::I8051) {
                defines.push("CAN_WISHBONE_IF".into());
            }
            includes.push(dir.into());
        }
        duts.push(d);
    }
    if duts.is_empty() {
        duts.push(DutSpec::rtl());
    }
    check_externals(&duts, host, coverage)?;
    Ok(duts)
}

/// Runs the regression on `duts` (set up and built) and reports it.
fn run_on(a: Args, duts: Vec<DutSpec>) -> anyhow::Result<i32> {
    let opts = RegressOptions {
        jobs: a.jobs,
        shard: a.shard,
        progress: std::io::IsTerminal::is_terminal(&std::io::stderr()),
        max_bits: a.max_bits,
        waivers: a.waivers.waivers.clone(),
        dut_revision: a.waivers.dut_revision.clone(),
        // Recording judges whole scenarios, as expected failures are judged.
        collect: if a.record_expected_failures.is_some() { waivers::CollectMode::Collect } else { a.waivers.mode() },
        host: a.host.bfm(),
        coverage_dir: a.coverage.clone(),
    };
    // A scenario that cannot be loaded is an error row; the others still run.
    let report = scenario::regress::regress_inputs(&a.inputs, &duts, &opts)?;
    if let Some(h) = opts.host {
        println!("host: {h} (override of every scenario's own host)");
    }
    print!("{}", report.to_table());
    if let Some(b) = &a.baseline {
        let old = b.split_once('=').map(|(n, _)| n).unwrap_or(b);
        let new = a.dut.externals[0].split_once('=').map(|(n, _)| n).unwrap_or(&a.dut.externals[0]);
        let rows = scenario::revdiff::diff(&report, old, new);
        print!("{}", scenario::revdiff::to_text(&rows, old, new));
        return Ok(if scenario::revdiff::any_broken(&rows) { 1 } else { 0 });
    }
    // The table cuts long cells; errors are printed whole (file:line:key).
    for c in &report.cells {
        if let scenario::regress::Status::Error(m) = &c.status {
            println!("error: {} on {}: {m}", c.scenario, c.dut);
        }
    }
    if a.funcov || a.coverage.is_some() {
        for d in &report.duts {
            println!("\nfunctional coverage on {d} (golden model's side, {} runs):", report.cells.iter().filter(|c| &c.dut == d && c.funcov.is_some()).count());
            print!("{}", report.funcov(d).to_table());
        }
    }
    if let Some(p) = &a.funcov_json {
        let all: std::collections::BTreeMap<&str, funcov::Coverage> = report.duts.iter().map(|d| (d.as_str(), report.funcov(d))).collect();
        std::fs::write(p, serde_json::to_string_pretty(&all)?).with_context(|| format!("writing {}", p.display()))?;
        println!("functional coverage JSON: {}", p.display());
    }
    if let Some(dir) = &a.coverage {
        code_coverage(dir, &report, &duts)?;
    }
    if let Some(p) = &a.junit {
        std::fs::write(p, report.to_junit()).with_context(|| format!("writing {}", p.display()))?;
        println!("JUnit: {}", p.display());
    }
    if let Some(p) = &a.json {
        std::fs::write(p, report.to_json()).with_context(|| format!("writing {}", p.display()))?;
        println!("JSON: {}", p.display());
    }
    if let Some(p) = &a.record_expected_failures {
        let place = if a.record_place == "step" { waivers::Place::Step } else { waivers::Place::Bit };
        let text = record_expected_failures(&report, place);
        std::fs::write(p, &text).with_context(|| format!("writing {}", p.display()))?;
        let n = text.lines().filter(|l| *l == "[[expected-failure]]").count();
        println!("expected-failure entries: {n} written to {} (paste into a waiver file after review; nothing was changed)", p.display());
    }
    if let Some(dir) = &a.html {
        // The loadable scenarios again, for the detail runs of failed cells.
        let mut scenarios = Vec::new();
        for p in &a.inputs {
            if p.extension().is_some_and(|e| e == "toml") {
                scenarios.extend(scenario::Scenario::load(p).ok());
            } else {
                scenarios.extend(scenario::load_list_entries(p)?.into_iter().filter_map(|(_, s)| s.ok()));
            }
        }
        let page = scenario::html::write_report(dir, &report, &scenarios, &duts, &opts).with_context(|| format!("writing the HTML report in {}", dir.display()))?;
        println!("HTML report: {}", page.display());
    }
    Ok(report.exit_code())
}

/// `--record-expected-failures`: an entry per run that did not pass or did
/// not fail as its entry records, with the signature it showed (collect mode).
fn record_expected_failures(report: &scenario::regress::RegressReport, place: waivers::Place) -> String {
    use scenario::regress::Status;
    let mut out = String::from(
        "# [[expected-failure]] entries recorded by `cancosim regress --record-expected-failures`\n\
         # (collect mode). Review each, fill in what is empty, paste into the waiver file.\n",
    );
    for c in &report.cells {
        // Recording by step also re-records an entry that held by bit, so it can be moved to `place = "step"`.
        let by_bit = place == waivers::Place::Step
            && matches!(c.status, Status::ExpectedFailure { .. })
            && c.xfail.as_ref().is_some_and(|r| r.entry.place == waivers::Place::Bit);
        let record = by_bit || matches!(c.status, Status::Diverged(_) | Status::Failed(_) | Status::WrongFailure { .. });
        let signature = if place == waivers::Place::Step { &c.step_signature } else { &c.signature };
        if !record || signature.is_empty() {
            continue;
        }
        out += &format!("\n# {} on {} through {}: {} line(s)\n", c.scenario, c.dut, c.host, signature.len());
        out += &waivers::expected::to_toml(&c.scenario, &c.waiver_dut, &c.host, signature, place, c.xfail.as_ref().map(|r| &r.entry));
    }
    out
}

/// `--coverage DIR`: per Verilated DUT, merges its runs' `.dat` files into
/// DIR/<dut>/ (merged.dat, coverage.info, html/, summary.json) and prints
/// line/toggle/branch per source file.
fn code_coverage(dir: &std::path::Path, report: &scenario::regress::RegressReport, duts: &[DutSpec]) -> anyhow::Result<()> {
    for d in duts {
        if d.kind == scenario::DutKind::Model {
            println!("\ncode coverage on {}: none (the golden model is not Verilated)", d.name);
            continue;
        }
        let safe = scenario::regress::file_safe(&d.name);
        let runs = report.cells.iter().filter(|c| c.dut == d.name && !matches!(c.status, scenario::regress::Status::Skipped(_))).count();
        let mut dats: Vec<PathBuf> = std::fs::read_dir(dir.join("dat").join(&safe))
            .map(|rd| rd.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.extension().is_some_and(|x| x == "dat")).collect())
            .unwrap_or_default();
        dats.sort();
        let out = dir.join(&safe);
        let r = codecov::report(&dats, &out).with_context(|| format!("code coverage of {}", d.name))?;
        std::fs::write(out.join("summary.json"), serde_json::to_string_pretty(&r.files)?).with_context(|| format!("writing {}", out.join("summary.json").display()))?;
        println!("\ncode coverage on {} ({} of {runs} runs wrote counters): lcov {}, HTML {}", d.name, r.runs, r.info.display(), r.html.display());
        print!("{}", codecov::to_table(&r.files));
    }
    Ok(())
}

/// An external core that does not build fails here, once, before the first
/// scenario (exit 125, so `git bisect run` skips the revision), not once
/// per scenario. Building the core here also hands every worker a warm
/// cache instead of one build per worker (the coverage build under
/// `--coverage`, the one the runs use).
fn check_externals(duts: &[DutSpec], host: Option<scenario::HostBfm>, coverage: bool) -> Result<(), SetupError> {
    for d in duts {
        // The 8051 shell is generated from the core's own ports.
        let core = scenario::run::external_core(d, host).map_err(|m| SetupError::Unbuildable(anyhow::anyhow!("--external {}: {m}", d.name)))?;
        if let Some(mut core) = core {
            core.coverage = coverage;
            let what = || format!("--external {}={}", d.name, core.dir.display());
            core.check().with_context(what).map_err(SetupError::Unbuildable)?;
            cosim::build_external(&core).with_context(what).map_err(SetupError::Unbuildable)?;
        }
    }
    Ok(())
}
