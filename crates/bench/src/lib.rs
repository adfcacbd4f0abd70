//! Fixed, seeded performance workloads and the table of ratios, measured
//! in one run. The CLI exposes it as `cancosim bench [--smoke]`.
//!
//! Workloads:
//! 1. the golden model alone, 1, 2, 8 and 64 nodes exchanging seeded
//!    random frames ([`model::exchange`]): simulated bit times per second on
//!    one core and how the cost grows with the node count;
//! 2. the self-test loopback workload ([`workload`]: one PeliCAN node in
//!    self test sending DLC-8 frames to itself with SRR, 40 clocks per bit)
//!    on the golden model alone, in co-simulation (our Verilated RTL +
//!    Wishbone BFM + golden model + comparator, [`cosim_run`]), on the raw
//!    C++ Verilator harness (`tb/bench/harness.cpp`) and under Icarus
//!    (`tb/bench/bench_tb.v`), all with the same register sequence and the
//!    same frames;
//! 3. peak RSS of each ([`measure`]).
//!
//! Times are CPU seconds of the thread or child process (the machine may
//! be shared; wall time is reported too). Ratios compare rates (cycles or
//! bit times per CPU second), so the Icarus run may be shorter than the
//! others.
#![warn(missing_docs)]

pub mod cosim_run;
pub mod external;
pub mod measure;
pub mod model;
pub mod workload;

use std::fmt::Write as _;
use std::path::PathBuf;

use serde::Serialize;

pub use external::Built;
pub use measure::Cost;

/// Why the bench could not complete. Each prints as one sentence or paragraph.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A tool or a source file is missing.
    #[error("bench: {0}")]
    Missing(String),
    /// A build step failed.
    #[error("bench: building {what} failed:\n{log}")]
    Build {
        /// What was built.
        what: String,
        /// The end of the tool's output.
        log: String,
    },
    /// A process could not be started or waited for.
    #[error("bench: could not run {what}: {error}")]
    Spawn {
        /// What.
        what: String,
        /// The OS error.
        error: std::io::Error,
    },
    /// A simulator ran but did not finish the workload.
    #[error("bench: {what} did not complete the workload: {detail}")]
    Run {
        /// Which simulator.
        what: String,
        /// What it said.
        detail: String,
    },
    /// The co-simulation failed (build, host access, timeout, divergence).
    #[error("bench: co-simulation: {0}")]
    Cosim(#[from] cosim::TbError),
    /// A workload read back something else than it sent.
    #[error(
        "bench: {what}: {errors} read-back mismatches in {frames} frames (the DUT does not pass the self test)"
    )]
    Mismatch {
        /// Which simulator.
        what: String,
        /// Mismatches.
        errors: u64,
        /// Frames.
        frames: u64,
    },
    /// File system.
    #[error("bench: {what}: {error}")]
    Io {
        /// What was being done.
        what: String,
        /// The OS error.
        error: std::io::Error,
    },
}

/// What to run. [`BenchOptions::default`] is the full bench; with `smoke`
/// set, the counts are capped to the `SMOKE_*` values (a few seconds in
/// all, for CI).
#[derive(Clone, Debug, Serialize)]
pub struct BenchOptions {
    /// CI-sized run: caps `frames`, `icarus_frames` and `model_bits`.
    pub smoke: bool,
    /// Frames of the self-test workload (model, co-simulation, raw harness).
    pub frames: u32,
    /// Frames under Icarus (slow; its rate per cycle is what is compared).
    pub icarus_frames: u32,
    /// Seed of every workload.
    pub seed: u64,
    /// Bit times of the 1- and 2-node model runs (8 nodes: 1/4, 64 nodes: 1/32).
    pub model_bits: u64,
    /// Project root (with `rtl/` and `tb/bench/`); default: this source tree.
    pub root: Option<PathBuf>,
    /// Where builds are cached; default: `$TMPDIR/cancosim-bench`.
    pub work_dir: Option<PathBuf>,
    /// The co-simulation rows and the raw harness run this many times,
    /// interleaved, and each keeps its least CPU time: on a shared or
    /// virtual machine a neighbour's burst slows one run, never speeds one
    /// up, so the minimum is the figure that compares.
    pub repeat: u32,
}

impl BenchOptions {
    /// Smoke cap on `frames`.
    pub const SMOKE_FRAMES: u32 = 4;
    /// Smoke cap on `icarus_frames`.
    pub const SMOKE_ICARUS_FRAMES: u32 = 1;
    /// Smoke cap on `model_bits`.
    pub const SMOKE_MODEL_BITS: u64 = 20_000;

    /// The CI-sized run.
    pub fn smoke() -> Self {
        BenchOptions {
            smoke: true,
            repeat: 1,
            ..Self::default()
        }
    }

    /// The counts actually run.
    pub fn effective(&self) -> BenchOptions {
        let mut o = self.clone();
        if o.smoke {
            o.frames = o.frames.min(Self::SMOKE_FRAMES);
            o.icarus_frames = o.icarus_frames.min(Self::SMOKE_ICARUS_FRAMES);
            o.model_bits = o.model_bits.min(Self::SMOKE_MODEL_BITS);
        }
        o.repeat = o.repeat.max(1);
        o.frames = o.frames.max(1);
        o.icarus_frames = o.icarus_frames.max(1);
        o.model_bits = o.model_bits.max(1_000);
        o
    }

    fn root(&self) -> PathBuf {
        self.root
            .clone()
            .unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")))
    }

    fn work_dir(&self) -> PathBuf {
        self.work_dir
            .clone()
            .unwrap_or_else(|| std::env::temp_dir().join("cancosim-bench"))
    }
}

impl Default for BenchOptions {
    fn default() -> Self {
        BenchOptions {
            smoke: false,
            frames: 1000,
            icarus_frames: 40,
            seed: 1,
            model_bits: 2_000_000,
            root: None,
            work_dir: None,
            repeat: 3,
        }
    }
}

/// One node count of the model scaling workload.
#[derive(Clone, Debug, Serialize)]
pub struct ScalingRow {
    /// Nodes on the bus.
    pub nodes: usize,
    /// Bit times simulated.
    pub bit_times: u64,
    /// Frames read out of the RX FIFOs.
    pub frames_received: u64,
    /// Its cost.
    pub cost: Cost,
    /// Bit times per CPU second (one core).
    pub bit_times_per_s: f64,
    /// CPU nanoseconds per bit time.
    pub ns_per_bit_time: f64,
    /// CPU nanoseconds per bit time per node (flat = linear growth).
    pub ns_per_node_bit: f64,
}

/// One simulator on the self-test loopback workload.
#[derive(Clone, Debug, Serialize)]
pub struct SelfTestRow {
    /// Short name: `model`, `cosim`, `cosim-no-lockstep`, `cosim-de2-clocks`, `verilator-raw`, `icarus`.
    pub name: String,
    /// What it is.
    pub what: String,
    /// Frames sent and read back.
    pub frames: u64,
    /// CAN clock cycles simulated (the model: bit times x 40).
    pub cycles: u64,
    /// Read-back mismatches: 0 when the simulated DUT passes the self test.
    pub errors: u64,
    /// Its cost.
    pub cost: Cost,
    /// Clock cycles per CPU second.
    pub cycles_per_s: f64,
    /// Bit times per CPU second.
    pub bit_times_per_s: f64,
    /// Frames per CPU second.
    pub frames_per_s: f64,
}

/// A target and where we stand.
#[derive(Clone, Debug, Serialize)]
pub struct Target {
    /// What is measured.
    pub name: String,
    /// How it is computed.
    pub definition: String,
    /// The measured value.
    pub value: f64,
    /// The target, in words (">= 100").
    pub target: String,
    /// Whether the value meets it.
    pub met: bool,
}

/// Everything one run measured.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// The counts run.
    pub options: BenchOptions,
    /// Build steps (not part of any timing).
    pub builds: Vec<(String, Built)>,
    /// Model alone, by node count.
    pub scaling: Vec<ScalingRow>,
    /// The self-test workload, by simulator.
    pub selftest: Vec<SelfTestRow>,
    /// Ratios and rates against the targets.
    pub targets: Vec<Target>,
}

fn per_s(n: f64, s: f64) -> f64 {
    // A run too short for the clock still gets a finite rate.
    n / s.max(1e-9)
}

fn selftest_row(
    name: &str,
    what: &str,
    frames: u64,
    cycles: u64,
    errors: u64,
    cost: Cost,
) -> SelfTestRow {
    // A simulator that read back something else still ran the same
    // stimulus, so its speed is reported; the mismatch shows in the table
    // and in `BenchReport::check`.
    SelfTestRow {
        name: name.into(),
        what: what.into(),
        frames,
        cycles,
        errors,
        cost,
        cycles_per_s: per_s(cycles as f64, cost.cpu_s),
        bit_times_per_s: per_s(cycles as f64 / workload::CLOCKS_PER_BIT as f64, cost.cpu_s),
        frames_per_s: per_s(frames as f64, cost.cpu_s),
    }
}

/// Times the model runs the self-test workload in one measurement.
pub const MODEL_SELFTEST_REPEAT: u64 = 10;

/// Node counts of the scaling workload.
pub const NODE_COUNTS: [usize; 4] = [1, 2, 8, 64];

/// Runs every workload once and returns the figures.
pub fn run(opts: &BenchOptions) -> Result<BenchReport, BenchError> {
    let o = opts.effective();
    let root = o.root();
    let work = o.work_dir();
    std::fs::create_dir_all(&work).map_err(|e| BenchError::Io {
        what: format!("creating {}", work.display()),
        error: e,
    })?;

    // Builds first, outside every timing.
    let harness = external::build_harness(&root, &work)?;
    let icarus = external::build_icarus(&root, &work)?;

    let mut scaling = Vec::new();
    for &n in &NODE_COUNTS {
        let bits = o.model_bits * 2 / n.max(2) as u64;
        let ((bit_times, received), cost) =
            measure::in_process(|| Ok::<_, BenchError>(model::exchange(n, o.seed, bits)))?;
        let cpu_ns = cost.cpu_s * 1e9;
        scaling.push(ScalingRow {
            nodes: n,
            bit_times,
            frames_received: received,
            cost,
            bit_times_per_s: per_s(bit_times as f64, cost.cpu_s),
            ns_per_bit_time: cpu_ns / bit_times.max(1) as f64,
            ns_per_node_bit: cpu_ns / (bit_times.max(1) * n as u64) as f64,
        });
    }

    let frames = o.frames as u64;
    let mut st = Vec::new();
    // The model runs the workload in milliseconds: repeat it so the
    // clock resolution does not matter (its rate is per bit time anyway).
    let ((out, bits), cost) = measure::in_process(|| {
        let mut total = (workload::SelfTestOutcome::default(), 0);
        for _ in 0..MODEL_SELFTEST_REPEAT {
            let (out, bits) = model::selftest(frames, o.seed)?;
            total.0.frames += out.frames;
            total.0.errors += out.errors;
            total.1 += bits;
        }
        Ok::<_, BenchError>(total)
    })?;
    st.push(selftest_row(
        "model",
        "golden model alone (register calls, per-bit fast path; the workload run 10 times)",
        out.frames,
        bits * workload::CLOCKS_PER_BIT,
        out.errors,
        cost,
    ));
    // The rows of the co-sim / raw C++ ratio, interleaved, best of `repeat`.
    let best = |slot: &mut Option<(workload::SelfTestOutcome, u64, Cost)>, run: (workload::SelfTestOutcome, u64, Cost)| {
        if slot.as_ref().is_none_or(|b| run.2.cpu_s < b.2.cpu_s) {
            *slot = Some(run);
        }
    };
    let (mut lock, mut plain, mut de2, mut raw) = (None, None, None, None);
    for k in 0..o.repeat {
        let ((out, cycles), cost) =
            measure::in_process(|| cosim_run::selftest(frames, o.seed, true, cosim_run::CLOCK_HZ))?;
        best(&mut lock, (out, cycles, cost));
        let ((out, cycles), cost) =
            measure::in_process(|| cosim_run::selftest(frames, o.seed, false, cosim_run::CLOCK_HZ))?;
        best(&mut plain, (out, cycles, cost));
        if k == 0 {
            let ((out, cycles), cost) = measure::in_process(|| {
                cosim_run::selftest(frames, o.seed, true, cosim_run::DE2_HOST_HZ)
            })?;
            de2 = Some((out, cycles, cost));
        }
        let r = external::run_harness(&harness.path, frames, o.seed)?;
        let out = workload::SelfTestOutcome { frames: r.frames, errors: r.errors };
        best(&mut raw, (out, r.cycles, r.cost));
    }
    for (name, what, row) in [
        ("cosim", "co-simulation: Verilated RTL + Wishbone BFM + golden model + comparator", lock),
        ("cosim-no-lockstep", "co-simulation without the lockstep model (RTL + BFM)", plain),
        (
            "cosim-de2-clocks",
            "co-simulation with lockstep, host clock 50 MHz and CAN clock 24 MHz as on the DE2 (not in the ratios)",
            de2,
        ),
        ("verilator-raw", "raw C++ Verilator harness (-O3, one clock loop)", raw),
    ] {
        let (out, cycles, cost) = row.expect("repeat >= 1 ran every row");
        st.push(selftest_row(name, what, out.frames, cycles, out.errors, cost));
    }
    let r = external::run_icarus(&icarus.path, o.icarus_frames as u64, o.seed)?;
    st.push(selftest_row(
        "icarus",
        "Icarus Verilog test bench (vvp)",
        r.frames,
        r.cycles,
        r.errors,
        r.cost,
    ));

    let row = |n: &str| {
        st.iter()
            .find(|r| r.name == n)
            .expect("every row was pushed above")
    };
    let two = scaling
        .iter()
        .find(|r| r.nodes == 2)
        .expect("2 is in NODE_COUNTS");
    let targets = vec![
        Target {
            name: "model rate, 2 nodes".into(),
            definition: "simulated bit times per CPU second, golden model alone, 2 nodes, random frames".into(),
            value: two.bit_times_per_s,
            target: ">= 50e6".into(),
            met: two.bit_times_per_s >= 50e6,
        },
        Target {
            name: "model / Verilated RTL".into(),
            definition: "bit times per CPU second on the self-test workload: golden model alone over the raw C++ harness".into(),
            value: row("model").bit_times_per_s / row("verilator-raw").bit_times_per_s,
            target: ">= 100".into(),
            met: row("model").bit_times_per_s / row("verilator-raw").bit_times_per_s >= 100.0,
        },
        Target {
            name: "co-sim / raw C++".into(),
            definition: "CPU time per simulated clock cycle: co-simulation (with lockstep) over the raw C++ harness".into(),
            value: row("verilator-raw").cycles_per_s / row("cosim").cycles_per_s,
            target: "<= 1.15".into(),
            met: row("verilator-raw").cycles_per_s / row("cosim").cycles_per_s <= 1.15,
        },
        Target {
            name: "Icarus / co-sim".into(),
            definition: "CPU time per simulated clock cycle: Icarus over the co-simulation (with lockstep)".into(),
            value: row("cosim").cycles_per_s / row("icarus").cycles_per_s,
            target: ">= 30".into(),
            met: row("cosim").cycles_per_s / row("icarus").cycles_per_s >= 30.0,
        },
    ];
    Ok(BenchReport {
        options: o,
        builds: vec![
            ("raw C++ Verilator harness".into(), harness),
            ("Icarus test bench".into(), icarus),
        ],
        scaling,
        selftest: st,
        targets,
    })
}

fn si(v: f64) -> String {
    let (d, u) = if v >= 1e9 {
        (1e9, "G")
    } else if v >= 1e6 {
        (1e6, "M")
    } else if v >= 1e3 {
        (1e3, "k")
    } else {
        (1.0, "")
    };
    format!("{:.2} {u}", v / d)
}

impl BenchReport {
    /// Ok when every simulator read back what it sent; else the mismatch
    /// (the timings are still valid, the DUT or a simulator is not).
    pub fn check(&self) -> Result<(), BenchError> {
        match self.selftest.iter().find(|r| r.errors != 0) {
            Some(r) => Err(BenchError::Mismatch {
                what: r.what.clone(),
                errors: r.errors,
                frames: r.frames,
            }),
            None => Ok(()),
        }
    }

    /// Every figure the report carries, by name (for checks).
    pub fn figures(&self) -> Vec<(String, f64)> {
        let mut v = Vec::new();
        for r in &self.scaling {
            let n = r.nodes;
            v.push((format!("scaling[{n}].cpu_s"), r.cost.cpu_s));
            v.push((format!("scaling[{n}].wall_s"), r.cost.wall_s));
            v.push((
                format!("scaling[{n}].max_rss_kib"),
                r.cost.max_rss_kib as f64,
            ));
            v.push((format!("scaling[{n}].bit_times_per_s"), r.bit_times_per_s));
            v.push((format!("scaling[{n}].ns_per_node_bit"), r.ns_per_node_bit));
        }
        for r in &self.selftest {
            let n = &r.name;
            v.push((format!("{n}.cycles"), r.cycles as f64));
            v.push((format!("{n}.cpu_s"), r.cost.cpu_s));
            v.push((format!("{n}.wall_s"), r.cost.wall_s));
            v.push((format!("{n}.max_rss_kib"), r.cost.max_rss_kib as f64));
            v.push((format!("{n}.cycles_per_s"), r.cycles_per_s));
            v.push((format!("{n}.frames_per_s"), r.frames_per_s));
        }
        for t in &self.targets {
            v.push((t.name.clone(), t.value));
        }
        v
    }

    /// The report as pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("the report holds only plain numbers and strings")
    }

    /// The report as a plain-text table.
    pub fn to_table(&self) -> String {
        let mut s = String::new();
        let o = &self.options;
        let _ = writeln!(
            s,
            "cancosim bench{} (seed {}; times are CPU seconds of one thread or child process)",
            if o.smoke { " --smoke" } else { "" },
            o.seed
        );
        let _ = writeln!(
            s,
            "\n1. golden model alone, random frames, fast per-bit path"
        );
        let _ = writeln!(
            s,
            "{:>6} {:>10} {:>9} {:>9} {:>14} {:>12} {:>14} {:>10}",
            "nodes",
            "bit times",
            "frames",
            "cpu s",
            "bit times/s",
            "ns/bit time",
            "ns/node-bit",
            "peak RSS"
        );
        for r in &self.scaling {
            let _ = writeln!(
                s,
                "{:>6} {:>10} {:>9} {:>9.3} {:>14} {:>12.1} {:>14.1} {:>7} MiB",
                r.nodes,
                r.bit_times,
                r.frames_received,
                r.cost.cpu_s,
                si(r.bit_times_per_s),
                r.ns_per_bit_time,
                r.ns_per_node_bit,
                r.cost.max_rss_kib / 1024
            );
        }
        let _ = writeln!(
            s,
            "\n2. self-test loopback, 8-byte frames, 40 clocks per bit, same register sequence and frames (co-sim and raw rows: least CPU time of {} interleaved runs)", self.options.repeat
        );
        let _ = writeln!(
            s,
            "{:<18} {:>6} {:>10} {:>9} {:>9} {:>12} {:>12} {:>10} {:>10}  read-back",
            "simulator",
            "frames",
            "cycles",
            "cpu s",
            "wall s",
            "cycles/s",
            "bit times/s",
            "frames/s",
            "peak RSS"
        );
        for r in &self.selftest {
            let _ = writeln!(
                s,
                "{:<18} {:>6} {:>10} {:>9.3} {:>9.3} {:>12} {:>12} {:>10.1} {:>6} MiB  {}",
                r.name,
                r.frames,
                r.cycles,
                r.cost.cpu_s,
                r.cost.wall_s,
                si(r.cycles_per_s),
                si(r.bit_times_per_s),
                r.frames_per_s,
                r.cost.max_rss_kib / 1024,
                if r.errors == 0 {
                    "ok".to_string()
                } else {
                    format!("{} MISMATCHES", r.errors)
                }
            );
        }
        let _ = writeln!(
            s,
            "  (cycles: CAN clock cycles; host and CAN clocks both 24 MHz except cosim-de2-clocks. Peak RSS: a child's own VmHWM; for the \
             in-process rows, the bench process's peak while the row ran, which includes what it already held)"
        );
        let _ = writeln!(s, "\n3. targets");
        for t in &self.targets {
            let _ = writeln!(
                s,
                "{:<28} {:>12.2}  target {:<8} {}",
                t.name,
                t.value,
                t.target,
                if t.met { "met" } else { "NOT MET" }
            );
            let _ = writeln!(s, "    {}", t.definition);
        }
        let _ = writeln!(s, "\nbuilds (not timed above):");
        for (what, b) in &self.builds {
            let _ = writeln!(
                s,
                "  {what}: {} ({})",
                b.path.display(),
                if b.cached {
                    "cached".to_string()
                } else {
                    format!("built in {:.1} s", b.build_s)
                }
            );
        }
        s
    }
}
