//! The random campaign against any core: plans drawn from `(seed, index)`,
//! each written as a scenario and run on the same bench as `regress` (the
//! DUT, its profile, the waivers, the host), judged by the lockstep
//! comparator and the [`crate::scoreboard`]; a failure is shrunk to the
//! smallest plan that fails the same way and saved as a scenario that
//! `cancosim run` replays.

use crate::plan::{DrawLimits, HostOp, Plan, draw};
use crate::{render, scoreboard};
use scenario::regress::{Cell, RegressReport, Status};
use scenario::{DutSpec, HostBfm, RunOptions, RunOutcome, Scenario};
use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// What a campaign runs, and on what.
#[derive(Clone, Debug)]
pub struct RandomConfig {
    /// Seed of every choice.
    pub seed: u64,
    /// Index of the first run.
    pub first_index: u64,
    /// Stop once this many frames were run (None: `minutes` decides).
    pub frames: Option<u64>,
    /// Stop starting runs after this long.
    pub minutes: Option<f64>,
    /// Bounds of the draw.
    pub limits: DrawLimits,
    /// The device under test (with its profile).
    pub dut: DutSpec,
    /// Waiver files.
    pub waivers: Vec<PathBuf>,
    /// DUT revision for the waivers.
    pub dut_revision: Option<String>,
    /// Host override.
    pub host: Option<HostBfm>,
    /// Worker threads; 0 = one per core.
    pub jobs: usize,
    /// Shard `(k, n)`: run indices `first + k - 1 + j n`.
    pub shard: Option<(usize, usize)>,
    /// Shrink failures (re-runs at most `shrink_runs` plans each).
    pub shrink_runs: usize,
    /// Write each (shrunk) failure here as a scenario.
    pub save_failures: Option<PathBuf>,
    /// Stop after this many failing runs.
    pub max_failures: usize,
    /// A progress bar on stderr.
    pub progress: bool,
    /// Inputs of an external core held constant (a mutant's select).
    pub held_inputs: Vec<(String, u64)>,
    /// A DUT in Rust instead of `dut`'s own (tests: the golden model with
    /// one behaviour altered).
    pub custom_dut: Option<cosim::CustomDut>,
}

impl RandomConfig {
    /// A campaign of `frames` frames on `dut`, seed `seed`, defaults elsewhere.
    pub fn new(seed: u64, frames: u64, dut: DutSpec) -> Self {
        RandomConfig {
            seed,
            first_index: 0,
            frames: Some(frames),
            minutes: None,
            limits: DrawLimits::default(),
            dut,
            waivers: Vec::new(),
            dut_revision: None,
            host: None,
            jobs: 0,
            shard: None,
            shrink_runs: 80,
            save_failures: None,
            max_failures: 5,
            progress: false,
            held_inputs: Vec::new(),
            custom_dut: None,
        }
    }

    fn run_options(&self) -> RunOptions {
        RunOptions {
            dut: Some(self.dut.clone()),
            waivers: self.waivers.clone(),
            dut_revision: self.dut_revision.clone(),
            host: self.host,
            held_inputs: self.held_inputs.clone(),
            custom_dut: self.custom_dut.clone(),
            ..Default::default()
        }
    }

    /// The run indices of this shard, in order.
    pub fn index(&self, k: u64) -> u64 {
        match self.shard {
            None => self.first_index + k,
            Some((s, n)) => self.first_index + (s as u64 - 1) + k * n as u64,
        }
    }
}

/// How a run went wrong: the kind of its first failure, the part of the
/// plan it names; two runs with the same signature fail "the same way"
/// (what shrinking keeps).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Signature(pub String);

/// A judged run.
#[derive(Clone, Debug)]
pub struct Judged {
    /// Its verdict (a failure's words), none when it passed.
    pub failure: Option<String>,
    /// Signature of the failure.
    pub signature: Option<Signature>,
    /// The scoreboard's findings.
    pub scoreboard: Vec<String>,
}

/// Judges one outcome: an unwaived divergence, a host-bus failure, a run
/// error, the model nodes' frame accounting, and the scoreboard. What the
/// plan itself makes happen (bus-off, a request left pending in
/// listen-only mode) is the same on both sides and is not a failure.
pub fn judge(plan: &Plan, o: &RunOutcome) -> Judged {
    use diagnose::Category;
    let sb = scoreboard::check(plan, &o.bus_log, &o.delivered, &o.record);
    let first = o.waivers.as_ref().and_then(|w| w.failures.first().cloned()).or_else(|| {
        // Without a waiver session the record's own first divergence.
        o.waivers.is_none().then(|| o.record.divergence.clone()).flatten()
    });
    let (failure, sig) = if let Some(d) = first {
        let place = d.register.clone().or_else(|| d.field.map(|f| format!("{f:?}"))).unwrap_or_default();
        let at = d.bit.map(|b| format!(" at bit {b}")).unwrap_or_default();
        (
            Some(format!("{:?} {place}{at}: DUT 0x{:X}, model 0x{:X}", d.kind, d.seen, d.expected)),
            Some(Signature(format!("divergence {:?} {place}", d.kind))),
        )
    } else if matches!(o.diagnosis.category, Category::HostBusTimeout | Category::HostBusViolation | Category::RunError) {
        let what = o.record.error.clone().unwrap_or_else(|| o.diagnosis.what_happened.lines().next().unwrap_or("").to_string());
        (Some(format!("{}: {what}", o.diagnosis.category)), Some(Signature(format!("{}", o.diagnosis.category))))
    } else if let Some(m) = o.mismatches.iter().find(|m| m.starts_with("frame accounting")) {
        (Some(m.clone()), Some(Signature("frame accounting between model nodes".into())))
    } else if let Some(p) = sb.first() {
        let kind = ["never read out", "filter rejects", "never carried", "out of bus order"].into_iter().find(|k| p.contains(k)).unwrap_or("scoreboard");
        (Some(format!("scoreboard: {p}")), Some(Signature(format!("scoreboard: {kind}"))))
    } else {
        (None, None)
    };
    Judged { failure, signature: sig, scoreboard: sb }
}

/// The scenario a plan is run as (an error is a kit defect: the draw made
/// a plan the scenario format refuses; the render tests check many).
pub fn scenario_of(plan: &Plan, purpose: &str) -> Result<Scenario, scenario::ScenarioError> {
    let text = render::to_toml(plan, purpose, &[]);
    Scenario::parse(&text, format!("campaign/campaign-s{}-r{}.toml", plan.seed, plan.index))
}

/// Runs one plan and judges it. A plan that does not load, or a run that
/// panics, is a failed run named as a kit defect (so it is reported and
/// shrunk like any failure), never the end of the whole campaign.
pub fn run_plan(plan: &Plan, opts: &RunOptions) -> (RunOutcome, Judged) {
    let purpose = format!("Random run {} of seed {}: {}", plan.index, plan.seed, render::summary(plan));
    let s = match scenario_of(plan, &purpose) {
        Ok(s) => s,
        Err(e) => return kit_defect(plan, opts, "invalid plan", format!("the drawn plan is not a valid scenario: {e}")),
    };
    let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let o = scenario::run::run(&s, opts);
        let j = judge(plan, &o);
        (o, j)
    }));
    match run {
        Ok(r) => r,
        Err(p) => {
            let msg = p.downcast_ref::<String>().cloned().or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string())).unwrap_or_else(|| "a panic".into());
            let first = msg.lines().next().unwrap_or("").to_string();
            kit_defect(plan, opts, &format!("panic: {}", first.chars().take(60).collect::<String>()), format!("the run panicked: {msg}"))
        }
    }
}

/// A run that could not be made: a failure with the signature `kit defect: <kind>`.
fn kit_defect(plan: &Plan, opts: &RunOptions, kind: &str, what: String) -> (RunOutcome, Judged) {
    let dut = opts.dut.as_ref().map(|d| d.name.clone()).unwrap_or_default();
    let mut r = diagnose::RunRecord::new(&format!("campaign-s{}-r{}", plan.seed, plan.index), &dut);
    let what = format!("kit defect: {what}");
    r.error = Some(what.clone());
    let diagnosis = diagnose::diagnose(&r);
    let o = RunOutcome {
        record: r,
        diagnosis,
        passed: false,
        mismatches: vec![what.clone()],
        received: Vec::new(),
        dut,
        wall: Duration::ZERO,
        waivers: None,
        warnings: Vec::new(),
        skipped: None,
        bus_log: Vec::new(),
        delivered: Vec::new(),
        steps: Vec::new(),
    };
    (o, Judged { failure: Some(what), signature: Some(Signature(format!("kit defect: {kind}"))), scoreboard: Vec::new() })
}

/// The result of shrinking one failure.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Shrunk {
    /// The smallest failing plan found.
    #[serde(skip)]
    pub plan: Plan,
    /// Plans tried.
    pub tries: usize,
    /// Plans kept (each smaller, failing the same way).
    pub kept: usize,
    /// Size (frames + nodes + host operations + faults) before and after.
    pub size: (usize, usize),
    /// Frames before and after.
    pub frames: (usize, usize),
    /// Host operations before and after.
    pub ops: (usize, usize),
    /// Wall time.
    #[serde(serialize_with = "secs")]
    pub wall: Duration,
}

fn secs<S: serde::Serializer>(d: &Duration, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f64(d.as_secs_f64())
}

/// Smaller versions of `p`, biggest cuts first: faults, nodes, halves then
/// single frames and host operations, then simpler values (data zeroed,
/// oscillators nominal, the shortest quantum).
fn candidates(p: &Plan) -> Vec<Plan> {
    let mut out = Vec::new();
    if !p.faults.is_empty() {
        let mut q = p.clone();
        q.faults.clear();
        out.push(q);
        for i in 0..p.faults.len() {
            let mut q = p.clone();
            q.faults.remove(i);
            out.push(q);
        }
    }
    for i in 0..p.nodes.len() {
        let mut q = p.clone();
        q.nodes.remove(i);
        out.push(q);
    }
    for i in 0..p.nodes.len() {
        let n = p.nodes[i].frames.len();
        if n > 1 {
            for half in [0..n / 2, n / 2..n] {
                let mut q = p.clone();
                q.nodes[i].frames.drain(half);
                out.push(q);
            }
        }
        for j in 0..n {
            let mut q = p.clone();
            q.nodes[i].frames.remove(j);
            out.push(q);
        }
    }
    // The program is cut up to its tail (the final abort and drain the
    // scoreboard relies on), which stays.
    let n = crate::plan::tail_start(&p.program).unwrap_or(p.program.len());
    let mut chunk = n / 2;
    while chunk >= 1 {
        let mut start = 0;
        while start < n {
            let end = (start + chunk).min(n);
            let mut q = p.clone();
            q.program.drain(start..end);
            out.push(q);
            start = end;
        }
        chunk /= 2;
    }
    // Simpler values.
    let mut q = p.clone();
    let mut changed = false;
    for n in &mut q.nodes {
        changed |= n.ppm != 0;
        n.ppm = 0;
        for (_, f) in &mut n.frames {
            changed |= f.data.iter().any(|b| *b != 0);
            f.data.iter_mut().for_each(|b| *b = 0);
        }
    }
    if changed {
        out.push(q);
    }
    for (i, o) in p.program.iter().enumerate().take(n) {
        match o {
            HostOp::Wait(b) | HostOp::WaitIrq(b) if *b > 8 => {
                let mut q = p.clone();
                q.program[i] = match o {
                    HostOp::Wait(_) => HostOp::Wait(b / 2),
                    _ => HostOp::WaitIrq(b / 2),
                };
                out.push(q);
            }
            _ => {}
        }
    }
    out
}

/// Shrinks a failing plan: tries smaller plans and keeps each that fails
/// with the same signature, until none does or `max_tries` plans were run.
pub fn shrink(plan: &Plan, sig: &Signature, opts: &RunOptions, max_tries: usize) -> Shrunk {
    let t0 = Instant::now();
    let mut best = plan.clone();
    let mut tries = 0;
    let mut kept = 0;
    'outer: loop {
        for c in candidates(&best) {
            if tries >= max_tries {
                break 'outer;
            }
            tries += 1;
            let (_, j) = run_plan(&c, opts);
            if j.signature.as_ref() == Some(sig) {
                best = c;
                kept += 1;
                continue 'outer;
            }
        }
        break;
    }
    Shrunk {
        tries,
        kept,
        size: (plan.size(), best.size()),
        frames: (plan.frame_count(), best.frame_count()),
        ops: (plan.op_count(), best.op_count()),
        wall: t0.elapsed(),
        plan: best,
    }
}

/// One failing run of a campaign.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Failure {
    /// Run index.
    pub index: u64,
    /// What failed, in words.
    pub what: String,
    /// Its signature.
    pub signature: Signature,
    /// The plan's summary.
    pub plan: String,
    /// Shrinking, if done.
    pub shrunk: Option<Shrunk>,
    /// The saved scenario.
    pub saved: Option<PathBuf>,
    /// The saved scenario, run again, failed with the same signature.
    pub replayed: Option<bool>,
    /// The command that replays it.
    pub replay: Option<String>,
    /// The shrunk plan run with the golden model as DUT agreed with the
    /// reference (false: a kit defect, the model disagrees with itself).
    pub model_self_check: Option<bool>,
}

/// A whole campaign's result.
#[derive(Debug)]
pub struct CampaignResult {
    /// Per run, the regression cell (for the table, JSON, JUnit and HTML).
    pub report: RegressReport,
    /// Failures, by run index.
    pub failures: Vec<Failure>,
    /// Runs made.
    pub runs: u64,
    /// Frames run (nodes' and the DUT's).
    pub frames: u64,
    /// Wall time of the runs (shrinking excluded).
    pub wall: Duration,
    /// CPU time the runs took (each run's thread), shrinking excluded.
    pub busy: Duration,
    /// The failing runs' scenarios (their shrunk plans), for the HTML page.
    pub failing_scenarios: Vec<Scenario>,
    /// Triggers of known deviations kept out of the plans on this DUT (its
    /// `[[avoid]]` entries), one line each.
    pub avoided: Vec<String>,
}

impl CampaignResult {
    /// No failure.
    pub fn passed(&self) -> bool {
        self.failures.is_empty() && self.report.passed()
    }

    /// The report cut to the failing runs (the HTML page's rows).
    pub fn failing_report(&self) -> RegressReport {
        let cells: Vec<Cell> = self.report.cells.iter().filter(|c| !c.status.ok()).cloned().collect();
        RegressReport { scenarios: cells.iter().map(|c| c.scenario.clone()).collect(), duts: self.report.duts.clone(), cells, unloadable: Vec::new() }
    }

    /// Frames per second of simulation (one core).
    pub fn frames_per_cpu_second(&self) -> f64 {
        self.frames as f64 / self.busy.as_secs_f64().max(1e-9)
    }

    /// Text report: totals, waivers hit, each failure with its shrinking.
    pub fn to_text(&self, cfg: &RandomConfig) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let idx = match cfg.shard {
            None => format!("runs {}..{}", cfg.first_index, cfg.first_index + self.runs),
            Some((k, n)) => format!("shard {k}/{n} from run {}", cfg.first_index),
        };
        writeln!(
            s,
            "campaign seed {} on {} ({idx}): {} runs, {} frames in {:.1} s ({:.0} frames per CPU second), {} failing",
            cfg.seed,
            cfg.dut.name,
            self.runs,
            self.frames,
            self.wall.as_secs_f64(),
            self.frames_per_cpu_second(),
            self.failures.len()
        )
        .unwrap();
        if !self.avoided.is_empty() {
            writeln!(s, "kept out of the plans on this DUT (its [[avoid]] entries: known deviations no waiver can bound; its profile's freedoms):").unwrap();
            for a in &self.avoided {
                writeln!(s, "  {a}").unwrap();
            }
        }
        if self.failures.len() > 1 {
            // Failures by signature: how many kinds of defect, not how many runs.
            let mut by: std::collections::BTreeMap<&str, Vec<u64>> = std::collections::BTreeMap::new();
            for f in &self.failures {
                by.entry(f.signature.0.as_str()).or_default().push(f.index);
            }
            writeln!(s, "failures by signature:").unwrap();
            for (sig, runs) in &by {
                let shown: Vec<String> = runs.iter().take(8).map(|r| r.to_string()).collect();
                writeln!(s, "  {:>4} x {sig} (runs {}{})", runs.len(), shown.join(", "), if runs.len() > 8 { ", ..." } else { "" }).unwrap();
            }
        }
        let w = self.report.waivers_text();
        if !w.trim().is_empty() {
            s += &w;
        }
        for f in &self.failures {
            writeln!(s, "\nFAIL run {}: {}", f.index, f.what).unwrap();
            writeln!(s, "  plan: {}", f.plan).unwrap();
            if let Some(k) = &f.shrunk {
                writeln!(
                    s,
                    "  shrunk in {} tries ({} kept, {:.1} s): size {} -> {}, frames {} -> {}, host operations {} -> {}",
                    k.tries,
                    k.kept,
                    k.wall.as_secs_f64(),
                    k.size.0,
                    k.size.1,
                    k.frames.0,
                    k.frames.1,
                    k.ops.0,
                    k.ops.1
                )
                .unwrap();
            }
            if let Some(p) = &f.saved {
                let same = match f.replayed {
                    Some(true) => "replays with the same first failure",
                    Some(false) => "DOES NOT replay the same way (report this as a kit defect)",
                    None => "not replayed",
                };
                writeln!(s, "  saved: {} ({same})", p.display()).unwrap();
            }
            if let Some(c) = &f.replay {
                writeln!(s, "  replay: {c}").unwrap();
            }
            if f.model_self_check == Some(false) {
                writeln!(s, "  KIT DEFECT: the golden model as DUT diverges from the model as reference on this plan").unwrap();
            }
        }
        if self.failures.is_empty() {
            writeln!(s, "PASS: no divergence from the golden model, the scoreboard satisfied on every run").unwrap();
        }
        s
    }

    /// JSON: totals and failures (the per-run cells are in the JUnit file).
    pub fn to_json(&self, cfg: &RandomConfig) -> String {
        let v = serde_json::json!({
            "seed": cfg.seed,
            "first_index": cfg.first_index,
            "shard": cfg.shard.map(|(k, n)| format!("{k}/{n}")),
            "dut": cfg.dut.name,
            "host": cfg.host.map(|h| h.name()),
            "runs": self.runs,
            "frames": self.frames,
            "wall_s": self.wall.as_secs_f64(),
            "cpu_s": self.busy.as_secs_f64(),
            "frames_per_cpu_second": self.frames_per_cpu_second(),
            "passed": self.passed(),
            "avoided": self.avoided,
            "failures": self.failures,
            "waivers_hit": self.report.waivers_hit(&cfg.dut.name).iter().map(|w| serde_json::json!({"waiver": w.deviation.waiver_id, "clause": w.deviation.clause, "hits": w.deviation.hits, "runs": w.scenarios.len()})).collect::<Vec<_>>(),
            "regression": serde_json::from_str::<serde_json::Value>(&self.report.to_json()).unwrap_or_default(),
        });
        serde_json::to_string_pretty(&v).expect("plain values")
    }
}

/// The draw limits with the DUT's `[[avoid]]` triggers (from the waiver
/// files, matched by its name and profile family), and their report lines.
/// A waiver file that does not load avoids nothing here: every run then
/// reports the file's error.
pub fn avoided_limits(cfg: &RandomConfig) -> (DrawLimits, Vec<String>) {
    let mut limits = cfg.limits.clone();
    let mut lines = Vec::new();
    // A freedom of the profile, not an avoided deviation: stated the same way.
    if let Some(p) = cfg.dut.profile.as_ref().filter(|p| p.edges_every_clock) {
        limits.whole_quantum_glitches = true;
        lines.push(format!(
            "glitches are whole time quanta: profile {} sees edges at every CAN clock (edge-sampling = \"clock\"), the model once per quantum",
            p.name
        ));
    }
    let Ok(set) = waivers::WaiverSet::load_all(&cfg.waivers) else {
        return (limits, lines);
    };
    let mut dut = waivers::DutInfo::new(&cfg.dut.name);
    dut.revision = cfg.dut_revision.clone();
    if let Some(p) = &cfg.dut.profile {
        dut = dut.in_family(&p.name, &p.ancestors);
    }
    for a in set.avoids_for(&dut) {
        if !limits.avoid.contains(&a.trigger) {
            limits.avoid.push(a.trigger.clone());
        }
        lines.push(a.describe());
    }
    (limits, lines)
}

/// Runs a campaign: plans in parallel until the frame or time budget is
/// spent, failures shrunk and saved.
pub fn run_campaign(cfg: &RandomConfig) -> CampaignResult {
    let opts = cfg.run_options();
    let (limits, avoided) = avoided_limits(cfg);
    let t0 = Instant::now();
    let jobs = if cfg.jobs == 0 { std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1) } else { cfg.jobs };
    let next = AtomicU64::new(0);
    let frames = AtomicU64::new(0);
    let failing = AtomicUsize::new(0);
    let busy_us = AtomicU64::new(0);
    let stop = AtomicBool::new(false);
    let deadline = cfg.minutes.map(|m| t0 + Duration::from_secs_f64(m * 60.0));
    let bar = if cfg.progress {
        match cfg.frames {
            Some(n) => indicatif::ProgressBar::new(n),
            None => indicatif::ProgressBar::new((cfg.minutes.unwrap_or(0.0) * 60.0) as u64),
        }
    } else {
        indicatif::ProgressBar::hidden()
    };
    bar.set_style(indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {elapsed} {msg}").unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()));
    let results: Mutex<Vec<(u64, Plan, Cell, Judged)>> = Mutex::new(Vec::new());
    std::thread::scope(|sc| {
        for _ in 0..jobs.max(1) {
            sc.spawn(|| {
                loop {
                    if stop.load(Ordering::SeqCst) {
                        break;
                    }
                    if cfg.frames.is_some_and(|n| frames.load(Ordering::SeqCst) >= n) || deadline.is_some_and(|d| Instant::now() >= d) {
                        break;
                    }
                    let k = next.fetch_add(1, Ordering::SeqCst);
                    let index = cfg.index(k);
                    let plan = draw(cfg.seed, index, &limits);
                    let t = thread_cpu();
                    let (o, j) = run_plan(&plan, &opts);
                    busy_us.fetch_add(thread_cpu().saturating_sub(t).as_micros() as u64, Ordering::SeqCst);
                    let done = frames.fetch_add(plan.frame_count() as u64, Ordering::SeqCst) + plan.frame_count() as u64;
                    let mut cell = Cell::from_outcome(&format!("campaign-s{}-r{index}", cfg.seed), &o);
                    cell.host = o.record.host_ops.first().map(|h| format!("{:?}", h.bfm).to_lowercase()).unwrap_or_default();
                    cell.status = match (&j.failure, &cell.status) {
                        (None, _) => Status::Pass,
                        (Some(_), Status::Error(e)) => Status::Error(e.clone()),
                        (Some(f), _) if j.signature.as_ref().is_some_and(|s| s.0.starts_with("divergence")) => Status::Diverged(f.clone()),
                        (Some(f), _) => Status::Failed(f.clone()),
                    };
                    if j.failure.is_some() && failing.fetch_add(1, Ordering::SeqCst) + 1 >= cfg.max_failures {
                        stop.store(true, Ordering::SeqCst);
                    }
                    match cfg.frames {
                        Some(_) => bar.set_position(done),
                        None => bar.set_position(t0.elapsed().as_secs()),
                    }
                    bar.set_message(format!("run {index}, {} failing", failing.load(Ordering::SeqCst)));
                    results.lock().expect("no worker panics holding the lock").push((index, plan, cell, j));
                }
            });
        }
    });
    bar.finish_and_clear();
    let wall = t0.elapsed();
    let mut results = results.into_inner().unwrap_or_default();
    results.sort_by_key(|r| r.0);
    let mut failures = Vec::new();
    let mut failing_scenarios = Vec::new();
    for (index, plan, _, j) in &results {
        let (Some(what), Some(sig)) = (&j.failure, &j.signature) else { continue };
        let shrunk = (cfg.shrink_runs > 0).then(|| shrink(plan, sig, &opts, cfg.shrink_runs));
        let small = shrunk.as_ref().map(|s| &s.plan).unwrap_or(plan);
        // The failure as the shrunk plan shows it (no second run when nothing was shrunk or saved).
        let jj = if shrunk.is_some() || cfg.save_failures.is_some() { run_plan(small, &opts).1 } else { j.clone() };
        let purpose = format!("Random run {index} of seed {}{}: {}", cfg.seed, if shrunk.is_some() { ", shrunk" } else { "" }, jj.failure.clone().unwrap_or_else(|| what.clone()));
        let mut failure = Failure { index: *index, what: what.clone(), signature: sig.clone(), plan: render::summary(plan), shrunk: shrunk.clone(), saved: None, replayed: None, replay: None, model_self_check: None };
        if let Some(dir) = &cfg.save_failures {
            let path = dir.join(format!("campaign-s{}-r{index}.toml", cfg.seed));
            let header = vec![
                format!("Found by `cancosim campaign --seed {}` (run {index}) on {}.", cfg.seed, cfg.dut.name),
                format!("First failure: {}", jj.failure.clone().unwrap_or_else(|| what.clone())),
                format!("Plan before shrinking: {}", render::summary(plan)),
                format!("After: {}", render::summary(small)),
            ];
            // What a correct core does is what the golden model does: its
            // diagnosis category becomes the scenario's [expect], so the file
            // passes on a core without the defect and joins a list as it is.
            let category = match scenario_of(small, &purpose) {
                Ok(s) => scenario::run::run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() }).diagnosis.category,
                Err(_) => diagnose::Category::Pass,
            };
            // The model as DUT against the model as reference must agree; if
            // not, the kit (not the core) is at fault, and the file says so.
            failure.model_self_check = Some(category != diagnose::Category::DutDeviatesFromModel);
            let text = render::to_toml_expecting(small, &purpose, &header, category);
            let saved = std::fs::create_dir_all(dir).and_then(|_| std::fs::write(&path, &text));
            if saved.is_ok() {
                // Saving is serialisation: the file, loaded back, must fail the same way.
                let replayed = Scenario::load(&path).ok().map(|s| {
                    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| judge(small, &scenario::run::run(&s, &opts)).signature))
                        .map(|got| got.as_ref() == Some(sig))
                        // A panic replays a panic only through run_plan's signature.
                        .unwrap_or_else(|_| sig.0.starts_with("kit defect: panic"))
                });
                failure.replayed = replayed;
                failure.replay = Some(format!("cancosim run {}{}", path.display(), replay_flags(cfg)));
                failure.saved = Some(path);
            }
        }
        failing_scenarios.extend(scenario_of(small, &purpose).ok());
        failures.push(failure);
    }
    let runs = results.len() as u64;
    let scenarios: Vec<String> = results.iter().map(|r| r.2.scenario.clone()).collect();
    let report = RegressReport {
        scenarios,
        duts: vec![cfg.dut.name.clone()],
        cells: results.into_iter().map(|r| r.2).collect(),
        unloadable: Vec::new(),
    };
    CampaignResult { report, failures, runs, frames: frames.into_inner(), wall, busy: Duration::from_micros(busy_us.into_inner()), failing_scenarios, avoided }
}

/// CPU time of the calling thread (what a run cost, whatever else the
/// machine is doing).
fn thread_cpu() -> Duration {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: a valid pointer to a timespec; the clock id is a constant.
    let r = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if r != 0 {
        return Duration::ZERO;
    }
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}

/// The `cancosim run` flags that run a saved failure as the campaign ran it.
fn replay_flags(cfg: &RandomConfig) -> String {
    let d = &cfg.dut;
    let mut s = match &d.kind {
        scenario::DutKind::Model => " --dut model".to_string(),
        scenario::DutKind::External { path, top, defines, includes } => {
            let mut s = format!(" --external {} --top {top}", path.display());
            if let Some(p) = &d.profile {
                s += &format!(" --profile {}", p.file.as_ref().map(|x| x.display().to_string()).unwrap_or_else(|| p.name.clone()));
            }
            for x in defines {
                s += &format!(" --define {x}");
            }
            for x in includes {
                s += &format!(" --include {}", x.display());
            }
            s
        }
        _ => String::new(),
    };
    if let Some(h) = cfg.host {
        s += &format!(" --host {h}");
    }
    for w in &cfg.waivers {
        s += &format!(" --waivers {}", w.display());
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_indices() {
        let mut c = RandomConfig::new(1, 10, DutSpec::model());
        c.first_index = 100;
        let all: Vec<u64> = (0..12).map(|k| c.index(k)).collect();
        let mut parts = Vec::new();
        for s in 1..=3 {
            c.shard = Some((s, 3));
            parts.extend((0..4).map(|k| c.index(k)));
        }
        parts.sort();
        assert_eq!(parts, all);
    }

    #[test]
    fn every_candidate_is_smaller() {
        let p = draw(2, 9, &DrawLimits { fault_rate: 0.5, ..DrawLimits::default() });
        for c in candidates(&p) {
            assert!(c.size() < p.size() || c.nodes.iter().zip(&p.nodes).any(|(a, b)| a != b) || c.program != p.program, "{c:?}");
        }
    }
}
