//! Core profile inference: finds a core's port roles and measures each
//! implementation freedom of its profile (`cosim::profile`) from short
//! probe runs on the co-simulation, and writes the profile with one
//! evidence line per entry.
//!
//! A *freedom* is a choice the SJA1000 datasheet and CAN 2.0B leave to the
//! implementation (when a host access reaches the CAN clock, where the bit
//! timing starts, pipeline latencies); a *deviation* is a behaviour they
//! forbid. Each freedom here has a bound ([`BOUNDS`]) with its reason: the
//! inference tries the candidate values within the bound and keeps the
//! narrowest under which the core agrees with the golden model on the
//! probes. When no value within the bound agrees, the measurement is never
//! written: the entry stays at its bound (so the comparator still flags
//! the behaviour) and the probe and its first divergence are reported as a
//! candidate [`Deviation`], for the user to judge and, if accepted, to
//! waive with a waiver that names the clause.

pub mod ports;
pub mod probes;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use cosim::holdoff::BusyAfterAck;
use cosim::profile::PortBus;
use cosim::{AccessTiming, CompareConfig, PhaseOrigin, Profile};
use probes::{BIT_CLOCKS, Probe, SJW_CLOCKS};
use scenario::{DutSpec, HostBfm, RunOptions};

/// Inference could not start or finish.
#[derive(Debug, thiserror::Error)]
pub enum InferError {
    /// The core does not build or load.
    #[error("{0}")]
    Build(String),
    /// A role has no port, or two ports could play it.
    #[error("{0}")]
    Ports(String),
}

/// What to infer a profile of.
#[derive(Clone, Debug)]
pub struct InferOptions {
    /// The core's source directory.
    pub dir: PathBuf,
    /// Its top module.
    pub top: String,
    /// Verilog defines.
    pub defines: Vec<String>,
    /// Include directories (the core's directory is always one).
    pub includes: Vec<PathBuf>,
    /// The host bus the probes drive: Wishbone, Avalon or PIO (the
    /// `[ports]` Wishbone roles), or AXI4-Lite, APB, the register port or
    /// the Motorola bus (that bus's `[ports.<bus>]` roles).
    pub host: HostBfm,
    /// The register port's read latency (clocks), when the user knows it;
    /// else it is measured (register port only).
    pub read_latency: Option<u32>,
    /// Roles named by the user: (role, NAME or NAME:low|high).
    pub ports: ports::Overrides,
    /// The profile's name (the DUT is "<name> (<dir>)", which waiver
    /// `dut` globs match).
    pub name: String,
    /// Waiver files of deviations already known and accepted: the probes
    /// run with them, as `regress --waivers` does (a deviation they cover
    /// is not measured into a freedom either).
    pub waivers: Vec<PathBuf>,
}

/// One bound: the freedom, its largest value, and why.
#[derive(Clone, Copy, Debug)]
pub struct Bound {
    /// The profile entry.
    pub key: &'static str,
    /// Its largest allowed value (CAN clocks or edges).
    pub max: u32,
    /// The datasheet / CAN 2.0B reason.
    pub reason: &'static str,
}

/// Largest access edge count (read, write, command).
pub const ACCESS_MAX: u32 = 8;
/// CAN clocks of E in a Motorola write at the probes' clocks (the kit's
/// 400 ns at 50 MHz host, 24 MHz CAN: 20 host cycles).
pub const MOTOROLA_E_WRITE: u32 = 10;
/// Largest access edge count on the Motorola bus, counted from E's rise:
/// a write waits for E's fall, then a sampling front and a crossing.
pub const MOTOROLA_ACCESS_MAX: u32 = MOTOROLA_E_WRITE + 2 * ACCESS_MAX;
/// Largest register-port read latency (clocks after the read strobe).
pub const READ_LATENCY_MAX: u32 = 2 * BIT_CLOCKS;
/// Largest tx edge window.
pub const TX_MAX: u32 = SJW_CLOCKS;
/// Largest lag of a start of frame from bus idle.
pub const SOF_MAX: u32 = BIT_CLOCKS;
/// Largest SR/IR latency.
pub const STATUS_MAX: u32 = BIT_CLOCKS;
/// Largest irq/bus-off pin latency.
pub const PINS_MAX: u32 = BIT_CLOCKS;
/// Added to a measured SR/IR or pin window (CAN clocks): the probes see an
/// event through polled reads one host read apart (13 host clocks at the
/// probes' 50 MHz, about 6 CAN clocks at 24 MHz), so the least window that
/// agrees depends on where the polling happened to land; another polling
/// phase (a scenario's own) needs up to one read more. Within the bound.
pub const POLL_MARGIN: u32 = 6;
/// Largest segment lag (CAN clocks).
pub const SEGMENT_LAG_MAX: u32 = SJW_CLOCKS;
/// Largest count of each stage of a handshake's return to idle.
pub const BUSY_MAX: u32 = ACCESS_MAX;

/// Every bound the inference keeps to.
pub const BOUNDS: &[Bound] = &[
    Bound {
        key: "access read/write/command",
        max: ACCESS_MAX,
        reason: "a host access crosses into the CAN clock through a synchroniser (two or three flops and a register stage); the SJA1000 itself takes a write at the end of /WR, so more than 8 CAN clocks is no crossing but a late register",
    },
    Bound {
        key: "access on the Motorola bus",
        max: MOTOROLA_ACCESS_MAX,
        reason: "edges count from the host edge raising E, and the datasheet takes a write at the end of E (10 CAN clocks at the probes' timing); the bus has no clock, so the core samples AS, E and R/W into its CAN clock (synchroniser flops, the strobe's edge, a registered request) before the access crosses as on a clocked bus: E, then two crossings bounded as one access each (8)",
    },
    Bound {
        key: "read-latency",
        max: READ_LATENCY_MAX,
        reason: "a register port has no acknowledge: the host samples read data a fixed number of clocks after the strobe; the SJA1000 drives read data within its /RD pulse, so data later than two bit times (80 CAN clocks at the probes' timing) is a port the host waits on, not a latency",
    },
    Bound {
        key: "phase-origin",
        max: 0,
        reason: "nothing synchronises a node's time quanta before the first bus edge (CAN 2.0B §10: hard synchronisation at the start of frame), so the phase in bus idle is the core's choice: from the hardware reset or from the reset-mode exit",
    },
    Bound {
        key: "segment-lag",
        max: SEGMENT_LAG_MAX,
        reason: "a bit timing that runs through reset mode may act on its prescaler's quantum through registers (the segment counters a few CAN clocks behind it); CAN 2.0B §10 lets a receiver correct a phase error of at most SJW (2 quanta, 8 CAN clocks at the probes' timing), so segment logic later than that is a late sample point, not a pipeline",
    },
    Bound {
        key: "busy-after-ack",
        max: BUSY_MAX,
        reason: "after an ack a request/acknowledge handshake returns to idle across the two clocks: each of its three stages (the core sees the request fall, the host side's acknowledge falls, the core lifts its block) is one synchroniser crossing, bounded as an access (at most 8 edges); searched as [w, w, c] with c at most w: the request's fall and the acknowledge's fall cross synchronisers as deep as the request's rise (w, the write edge)",
    },
    Bound {
        key: "count-from",
        max: 1,
        reason: "a core that synchronises cyc & stb from the wires straight into its CAN clock counts from the first CAN edge after they appear, one that registers them in the host clock first from the next host edge: at most one CAN edge apart, both a synchroniser the datasheet leaves open",
    },
    Bound {
        key: "sof",
        max: SOF_MAX,
        reason: "in bus idle nothing synchronises two nodes' bit timing (CAN 2.0B §10: the hard synchronisation comes with the start of frame itself), so a start of frame from bus idle may come anywhere in the other's bit, but not a whole bit (40 CAN clocks) late",
    },
    Bound {
        key: "tx-edge",
        max: TX_MAX,
        reason: "CAN 2.0B §10: a receiver resynchronises by at most SJW per edge; a tx edge later than SJW (2 quanta, 8 CAN clocks at the probes' timing) against the bit timing is a phase error no receiver corrects",
    },
    Bound {
        key: "status",
        max: STATUS_MAX,
        reason: "the datasheet sets each SR/IR bit at a given bit of the frame (RBS/RI at the end of frame, TCS/TI after it): a value later than one bit (40 CAN clocks) belongs to the next bit",
    },
    Bound {
        key: "status on the register port",
        max: STATUS_MAX,
        reason: "plus the read latency: the port has no acknowledge, so the host cannot tell when within the latency the core took the SR/IR value it returns",
    },
    Bound {
        key: "pins",
        max: PINS_MAX,
        reason: "the datasheet's INT output follows IR at once (INT is low while an enabled interrupt bit is set): a pin later than one bit after its interrupt bit is a late interrupt, not a pipeline",
    },
];

/// One evidence line: what was measured, on which probes, over how many runs.
#[derive(Clone, Debug)]
pub struct Evidence {
    /// The profile entry.
    pub key: String,
    /// The line.
    pub line: String,
}

/// A measurement outside its bound: not written into the profile.
#[derive(Clone, Debug)]
pub struct Deviation {
    /// The freedom (profile entry).
    pub freedom: String,
    /// Its bound and reason.
    pub bound: String,
    /// The probe that shows it.
    pub probe: String,
    /// That probe's first divergence at the bound.
    pub divergence: String,
}

impl std::fmt::Display for Deviation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "candidate deviation in `{}`: no value within the bound ({}) agrees; probe {} at the bound: {}", self.freedom, self.bound, self.probe, self.divergence)
    }
}

/// The result: the profile, its text with evidence, the candidate deviations.
#[derive(Clone, Debug)]
pub struct Inference {
    /// The inferred profile (entries of deviations at their bounds).
    pub profile: Profile,
    /// The profile file's text, each entry with its evidence comment.
    pub toml: String,
    /// Evidence, one line per entry.
    pub evidence: Vec<Evidence>,
    /// Measurements outside their bounds.
    pub deviations: Vec<Deviation>,
    /// Probe runs made.
    pub runs: usize,
    /// Time of the build (zero when cached) and of the probe runs.
    pub build: Duration,
    /// Time of the probe runs.
    pub probing: Duration,
}

/// Runs probes on the core under candidate profiles.
struct Prober {
    dut: DutSpec,
    host: HostBfm,
    waivers: Vec<PathBuf>,
    runs: usize,
}

impl Prober {
    /// Ok when the core agrees with the model on `probe` under `p`; else
    /// the first divergence in words.
    fn run(&mut self, probe: &Probe, p: &Profile) -> Result<(), String> {
        self.runs += 1;
        let opts = RunOptions { dut: Some(self.dut.clone().with_profile(p.clone())), host: Some(self.host), waivers: self.waivers.clone(), ..RunOptions::default() };
        let o = scenario::run(&probe.scenario, &opts);
        if o.passed {
            return Ok(());
        }
        let what = o.diagnosis.what_happened.lines().next().unwrap_or("").trim().to_string();
        Err(format!("{}: {what}", o.diagnosis.category))
    }

    /// Ok when every probe agrees; else the first that does not, and why.
    fn all(&mut self, probes: &[Probe], p: &Profile) -> Result<(), (String, String)> {
        for pr in probes {
            self.run(pr, p).map_err(|e| (pr.name.clone(), e))?;
        }
        Ok(())
    }

    /// The least value in `0..=max` under which every probe agrees
    /// (agreement only grows with a tolerance), else the failure at `max`.
    fn least(&mut self, probes: &[Probe], max: u32, with: impl Fn(u32) -> Profile) -> Result<u32, (String, String)> {
        self.all(probes, &with(max))?;
        let (mut lo, mut hi) = (0, max);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.all(probes, &with(mid)).is_ok() {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        Ok(lo)
    }
}

/// Every bus's entry: the probes drive one host, and the render writes
/// that host's entries only.
fn set_access(p: &mut Profile, t: AccessTiming) {
    p.wishbone = t;
    p.avalon = t;
    p.pio = t;
    p.axi4lite = Some(t);
    p.apb = Some(t);
    p.regport.timing = Some(t);
    p.motorola.timing = Some(t);
}

fn set_busy(p: &mut Profile, b: Option<BusyAfterAck>) {
    p.holdoff = cosim::profile::Holdoff { wishbone: b, avalon: b, pio: b };
}

fn set_wires(p: &mut Profile, on: bool) {
    p.count_from_wires = cosim::profile::CountFromWires { wishbone: on, avalon: on, pio: on };
}

fn busy(w: u32, c: u32) -> BusyAfterAck {
    BusyAfterAck { can: w, host: w, can_again: c }
}

/// One phase-stage candidate: origin, write edge and handshake, with the
/// tx lags it gave.
struct Cand {
    spread: i64,
    worst: i64,
    origin: PhaseOrigin,
    write: u32,
    busy: Option<BusyAfterAck>,
    sofs: Vec<i64>,
}

fn edges(read: u32, write: u32, command: u32) -> AccessTiming {
    AccessTiming::CanEdges { read, write, command }
}

fn range(v: &[u32]) -> String {
    match v {
        [] => "none".into(),
        [one] => one.to_string(),
        _ if v.windows(2).all(|w| w[1] == w[0] + 1) => format!("{}..{}", v[0], v[v.len() - 1]),
        _ => v.iter().map(u32::to_string).collect::<Vec<_>>().join(","),
    }
}

/// Infers the profile of the core `o` describes. Builds it (cached), finds
/// its ports, runs the probes.
pub fn infer(o: &InferOptions) -> Result<Inference, InferError> {
    let bus = ports::bus_of(o.host)?;
    if o.read_latency.is_some() && bus != Some(PortBus::Regport) {
        return Err(InferError::Ports(format!("--read-latency is the register port's (--host regport), not {}'s", o.host)));
    }
    if let Some(l) = o.read_latency.filter(|l| *l > 256) {
        return Err(InferError::Ports(format!("--read-latency {l}: at most 256 clocks")));
    }
    let t0 = Instant::now();
    let mut defines = o.defines.clone();
    if !defines.iter().any(|d| d == "CAN_WISHBONE_IF") {
        // The opencores core's Wishbone build; a core without the define ignores it.
        defines.push("CAN_WISHBONE_IF".into());
    }
    let mut includes = vec![o.dir.clone()];
    includes.extend(o.includes.iter().cloned());
    let core = cosim::ExternalCore { dir: o.dir.clone(), top: o.top.clone(), defines: defines.clone(), include_dirs: includes.clone(), ..Default::default() };
    core.check().map_err(|e| InferError::Build(format!("{}: {e}", o.dir.display())))?;
    let compiled = cosim::build_external(&core).map_err(|e| InferError::Build(format!("{}: {e}", o.dir.display())))?;
    let build = t0.elapsed();
    let mut model = compiled.instantiate(false);
    let mut ports = ports::find_roles(&ports::sigs(model.ports()), &o.ports, bus)?;
    let idle = ports::polarities(&mut model, &mut ports, bus, &o.ports)?;
    drop(model);

    let t1 = Instant::now();
    let mut dut = DutSpec::external(&o.name, &o.dir, &o.top);
    if let scenario::DutKind::External { defines: d, includes: i, .. } = &mut dut.kind {
        *d = defines;
        *i = includes;
    }
    let one_clock = bus.is_some_and(|b| {
        let bp = ports::bus_ports(&ports, b);
        bp.roles().contains(&"clock") && bp.pin("clock").name == ports.can_clock.name
    });
    let mut pr = Prober { dut, host: o.host, waivers: o.waivers.clone(), runs: 0 };
    let mut ev: Vec<Evidence> = Vec::new();
    let mut devs: Vec<Deviation> = Vec::new();
    let mut evidence = |key: &str, line: String| ev.push(Evidence { key: key.into(), line });
    let bound = |key: &str| BOUNDS.iter().find(|b| b.key.contains(key)).map(|b| format!("at most {}: {}", b.max, b.reason)).unwrap_or_default();

    let pname = |p: &ports::IdleLevels| format!("irq idle {} so active {}, bus-off idle {} so active {}", u8::from(p.irq), if p.irq { "low" } else { "high" }, u8::from(p.bus_off), if p.bus_off { "low" } else { "high" });
    let reset = bus.map_or(&ports.reset, |b| ports::bus_ports(&ports, b).pin("reset"));
    let roles = bus.map_or("roles".to_string(), |b| format!("[ports.{}] and CAN-side roles", b.key()));
    evidence("ports", format!("{roles} from the top's port names, directions and widths; {} after a reset in bus idle (no interrupt enabled, node on the bus); reset active {} by its name", pname(&idle), if reset.active_high { "high" } else { "low" }));
    if one_clock {
        // scenario::run::tb_config runs the host on the CAN clock for a
        // profile whose bus clock is its CAN clock.
        evidence("ports", format!("one clock ({}): the CAN clock is the bus clock; the probes, as run and regress, run the host at the CAN clock (24 MHz)", ports.can_clock.name));
    }
    // The largest access edge count on this host.
    let (access_max, access_key) = if bus == Some(PortBus::Motorola) { (MOTOROLA_ACCESS_MAX, "Motorola") } else { (ACCESS_MAX, "access read") };
    // The handshake and count-from families exist on Wishbone-family hosts only.
    let wb_family = bus.is_none();

    // Every stage isolates its own freedom: the others at their bounds or
    // not compared.
    let mut p = Profile::rtl();
    p.name = o.name.clone();
    p.description = format!("inferred by `cancosim profile infer` from probe runs on {} (top {})", o.dir.display(), o.top);
    p.file = None;
    p.ports = ports;
    p.tolerances = CompareConfig { tx_edge_tolerance: TX_MAX, sof_tolerance: TX_MAX, status_tolerance: 1000, pin_tolerance: 1000, compare_irq: false, compare_bus_off: false, ..CompareConfig::default() };
    if bus == Some(PortBus::Regport) {
        p.regport.one_address = Some(p.ports.regport.named("adr"));
    }

    // 0. The register port's read latency: the host samples read data a
    // fixed number of clocks after the strobe, and the port's monitor
    // fails a read whose data changes later than that. The least latency
    // at which every read of the probes agrees, on probes whose first
    // access after the reset is a read (the slowest on a port that
    // acknowledges through a clock crossing's reset) and a frame.
    if bus == Some(PortBus::Regport) {
        let lat_probes = [probes::first_read(), probes::phase(0)];
        let runs0 = pr.runs;
        let base = p.clone();
        let with = |l: u32| {
            let mut q = base.clone();
            q.regport.read_latency = Some(l);
            q
        };
        p.regport.read_latency = Some(match o.read_latency {
            Some(l) => {
                match pr.all(&lat_probes, &with(l)) {
                    Ok(()) => evidence("read-latency", format!("{l}: given with --read-latency; probes {} agree with it; {} runs", names(&lat_probes), pr.runs - runs0)),
                    Err((probe, why)) => evidence("read-latency", format!("{l}: given with --read-latency; probe {probe} disagrees with it ({}); {} runs", why.chars().take(160).collect::<String>(), pr.runs - runs0)),
                }
                l
            }
            None => match pr.least(&lat_probes, READ_LATENCY_MAX, with) {
                Ok(l) => {
                    let below = match l.checked_sub(1).map(|b| (b, pr.all(&lat_probes, &with(b)))) {
                        Some((b, Err((probe, why)))) => format!("; at {b} probe {probe}: {why}"),
                        _ => String::new(),
                    };
                    evidence("read-latency", format!("{l}: the least read latency at which every read of probes {} agrees (bound {READ_LATENCY_MAX}){below}; {} runs", names(&lat_probes), pr.runs - runs0));
                    l
                }
                Err(f) => {
                    devs.push(Deviation { freedom: "read-latency".into(), bound: bound("read-latency"), probe: f.0, divergence: f.1 });
                    evidence("read-latency", format!("NOT MEASURED: reads disagree at every latency up to {READ_LATENCY_MAX} clocks (candidate deviation; name it with --read-latency)"));
                    READ_LATENCY_MAX
                }
            },
        });
    }

    // On a port without acknowledge the host cannot tell when within the
    // read latency the core took its SR snapshot: the window's bound grows
    // by that latency.
    let status_max = STATUS_MAX + if bus == Some(PortBus::Regport) { p.regport.read_latency.unwrap_or(0) } else { 0 };

    // 1. Phase origin and the write edge: the tx edges of a self-test
    // frame after reset-mode exits at several offsets, the core's against
    // the model's (from the run's VCD). The right origin and write edge
    // give the same lag at every edge of every probe; the lag left is the
    // core's tx pipeline (the sof and tx-edge windows).
    let phase_probes: Vec<Probe> = [0, 1, 3, 5].into_iter().map(probes::phase).collect();
    let runs0 = pr.runs;
    // The lags of one candidate over the phase probes; None as soon as a
    // probe's frame differs from the model's or the lags spread over more
    // than a clock (no use running the others).
    let measure = |pr: &mut Prober, q: &Profile| -> Option<(Vec<i64>, Vec<i64>)> {
        let (mut lags, mut sofs) = (Vec::new(), Vec::new());
        for probe in &phase_probes {
            let l = pr.tx_edges(probe, q).and_then(|e| e.lags())?;
            sofs.push(l[0]);
            lags.extend(l);
            let (lo, hi) = (*lags.iter().min().expect("some"), *lags.iter().max().expect("some"));
            if hi - lo > 1 {
                // Not constant already: the spread so far is for the report.
                return Some((lags, sofs));
            }
        }
        Some((lags, sofs))
    };
    let mut cands: Vec<Cand> = Vec::new();
    let push = |cands: &mut Vec<Cand>, origin, w, b, r: Option<(Vec<i64>, Vec<i64>)>| {
        if let Some((lags, sofs)) = r {
            let (lo, hi) = (*lags.iter().min().expect("some"), *lags.iter().max().expect("some"));
            cands.push(Cand { spread: hi - lo, worst: lo.abs().max(hi.abs()), origin, write: w, busy: b, sofs });
        }
    };
    for (origin, writes) in [(PhaseOrigin::ResetModeExit, 0..=access_max), (PhaseOrigin::HardwareReset, 3..=3)] {
        for w in writes {
            let mut q = p.clone();
            q.phase_origin = origin;
            set_access(&mut q, edges(w, w, w));
            let r = measure(&mut pr, &q);
            push(&mut cands, origin, w, None, r);
        }
    }
    let good = |c: &Cand| c.spread <= 1 && c.worst <= TX_MAX as i64 && c.sofs.len() == phase_probes.len();
    if !cands.iter().any(good) && wb_family {
        // No constant lag with requests seen at once: a core that blocks
        // new requests after an ack (a handshake returning to idle) takes
        // back-to-back writes later than the model would. The handshake
        // family [w, w, c], c <= w (the `busy-after-ack` bound).
        // The first origin over every write edge; the second on the
        // write edges of the first's best candidates only (enough to tell
        // the origins apart).
        let mut best: Vec<u32> = Vec::new();
        for origin in [PhaseOrigin::HardwareReset, PhaseOrigin::ResetModeExit] {
            let writes: Vec<u32> = if best.is_empty() { (0..=access_max).collect() } else { best.clone() };
            for w in writes {
                for c in 0..=w.min(BUSY_MAX) {
                    let mut q = p.clone();
                    q.phase_origin = origin;
                    set_access(&mut q, edges(w, w, w));
                    set_busy(&mut q, Some(busy(w, c)));
                    let r = measure(&mut pr, &q);
                    push(&mut cands, origin, w, Some(busy(w, c)), r);
                }
            }
            if let Some(top) = cands.iter().filter(|c| good(c) && c.busy.is_some()).map(|c| (c.spread, c.worst)).min() {
                best = cands.iter().filter(|c| good(c) && c.busy.is_some() && (c.spread, c.worst) == top).map(|c| c.write).collect::<std::collections::BTreeSet<_>>().into_iter().collect();
            }
        }
    }
    // Complete candidates first, then the narrowest lags; ties: the
    // earliest write edge, then requests seen at once before a handshake.
    cands.sort_by_key(|c| (c.sofs.len() != phase_probes.len(), c.spread, c.worst, c.write, c.busy.is_some()));

    let write = match cands.first().filter(|c| good(c)) {
        Some(Cand { spread, worst, origin, write: w, busy: b, sofs }) => {
            p.phase_origin = *origin;
            // The handshake: the middle of the closing counts that agree
            // with this origin and write edge.
            let closing: Vec<u32> = cands.iter().filter(|c| good(c) && c.origin == *origin && c.write == *w && c.spread == *spread && c.worst == *worst).filter_map(|c| c.busy.map(|b| b.can_again)).collect();
            let b = b.map(|_| busy(*w, closing[closing.len() / 2]));
            set_busy(&mut p, b);
            let sof = sofs.iter().map(|l| l.unsigned_abs() as u32).max().unwrap_or(0);
            p.tolerances.sof_tolerance = sof;
            p.tolerances.tx_edge_tolerance = *worst as u32;
            set_access(&mut p, edges(*w, *w, *w));
            let what = match origin {
                PhaseOrigin::ResetModeExit => "reset-mode-exit",
                PhaseOrigin::HardwareReset => "hardware-reset",
            };
            let other = cands.iter().filter(|c| c.origin != *origin).map(|c| c.spread).min().map_or("no constant lag".to_string(), |s| format!("its lags spread over {s} CAN clocks"));
            evidence("phase-origin", format!("{what}: on probes {} (reset-mode exit moved by 0, 1, 3, 5 pad reads) the core's tx edges trail the model's by the same lag at every edge (spread {spread}); the other origin: {other}; {} runs", names(&phase_probes), pr.runs - runs0));
            let writes: Vec<u32> = cands.iter().filter(|c| good(c) && c.origin == *origin && c.spread == *spread && c.worst == *worst && c.busy.is_some() == b.is_some()).map(|c| c.write).collect::<std::collections::BTreeSet<_>>().into_iter().collect();
            match b {
                Some(b) => {
                    let none = cands.iter().filter(|c| c.busy.is_none()).map(|c| c.spread).min().map_or("no frame like the model's".to_string(), |s| format!("lags spread over {s} CAN clocks at best"));
                    evidence("busy-after-ack", format!("[{}, {}, {}]: with requests seen at once right after an ack the phase probes give {none}; the handshake [w, w, c] (c <= w, bound {BUSY_MAX}) gives the same lag at every edge for write edge {w} with c = {} (chosen {}, the middle)", b.can, b.host, b.can_again, range(&closing), b.can_again));
                }
                None if wb_family => evidence("busy-after-ack", "none: with requests seen at once right after an ack the phase probes' lags are constant".into()),
                None => evidence("busy-after-ack", format!("not searched: a request/acknowledge handshake's return to idle is modelled on wishbone, avalon and pio only ({} has no busy-after-ack entry)", o.host)),
            }
            if *origin == PhaseOrigin::ResetModeExit || b.is_some() {
                let at = if b.is_some() { " with the handshake" } else { " after the reset-mode exit" };
                evidence("write", format!("write edge {} gives the least lag ({worst} CAN clocks){at} (chosen {w}, the earliest)", range(&writes)));
            }
            evidence("sof", format!("tx lag at the start of frame: {} CAN clocks on the phase probes (bound {SOF_MAX})", range(&sofs.iter().map(|l| l.unsigned_abs() as u32).collect::<std::collections::BTreeSet<_>>().into_iter().collect::<Vec<_>>())));
            evidence("tx-edge", format!("tx lag at every edge of the phase probes' frames: at most {worst} CAN clocks (bound {TX_MAX})"));
            *w
        }
        None => {
            p.tolerances.sof_tolerance = TX_MAX;
            let why = match cands.first() {
                Some(Cand { spread, worst, .. }) => format!("the best candidate's tx lags spread over {spread} CAN clocks, up to {worst}"),
                None => "no candidate sent the same frame as the model".into(),
            };
            let probe = phase_probes[0].clone();
            let divergence = pr.run(&probe, &p).err().unwrap_or_else(|| why.clone());
            devs.push(Deviation { freedom: "phase-origin, write, sof, tx-edge".into(), bound: bound("sof"), probe: probe.name, divergence: format!("{divergence} ({why})") });
            evidence("phase-origin", format!("NOT MEASURED: {why} (candidate deviation)"));
            4
        }
    };
    // SR.TS in suspend transmission (a freedom, `ts-in-suspend`): the
    // recovery and passive probes read SR while an error-passive
    // transmitter waits out its suspend bits. The default unless only
    // "clear" agrees.
    {
        let ts_probes = [probes::recovery(), probes::passive()];
        let runs0 = pr.runs;
        let mut tp = p.clone();
        tp.tolerances.status_tolerance = status_max;
        match pr.all(&ts_probes, &tp) {
            Ok(()) => evidence("ts-in-suspend", format!("set (the default): SR agrees with TS = 1 in suspend transmission on probes {}; {} runs", names(&ts_probes), pr.runs - runs0)),
            Err((probe, why)) => {
                tp.ts_clear_in_suspend = true;
                if pr.all(&ts_probes, &tp).is_ok() {
                    p.ts_clear_in_suspend = true;
                    evidence("ts-in-suspend", format!("clear: with TS = 1 in suspend transmission probe {probe} disagrees ({}); with TS = 0 probes {} agree; {} runs", why.chars().take(120).collect::<String>(), names(&ts_probes), pr.runs - runs0));
                } else {
                    evidence("ts-in-suspend", format!("set (the default): probe {probe} disagrees with either reading ({}); the later stages report it; {} runs", why.chars().take(120).collect::<String>(), pr.runs - runs0));
                }
            }
        }
    }

    // A start of frame from bus idle after a bus-off recovery: the lag
    // of that frame (the sof window keeps it for the frame).
    let rec = probes::recovery();
    let runs0 = pr.runs;
    // SR at its bound, not uncompared: a waiver that realigns the model
    // after a register read (a known deviation) must see the read.
    let mut rp = p.clone();
    rp.tolerances.status_tolerance = status_max;
    if let Some(l) = pr.tx_edges(&rec, &rp).and_then(|e| e.lags()) {
        let sof = l.iter().map(|x| x.unsigned_abs() as u32).max().unwrap_or(0);
        if sof > p.tolerances.sof_tolerance && sof <= SOF_MAX {
            p.tolerances.sof_tolerance = sof;
        }
        evidence("sof", format!("tx lag of the frame from bus idle after a bus-off recovery (probe recovery): {sof} CAN clocks (bound {SOF_MAX}); {} run", pr.runs - runs0));
        if sof > SOF_MAX {
            let divergence = pr.run(&rec, &rp).err().unwrap_or_else(|| format!("lag {sof}"));
            devs.push(Deviation { freedom: "sof".into(), bound: bound("sof"), probe: rec.name.clone(), divergence });
            p.tolerances.sof_tolerance = SOF_MAX;
        }
    }
    // Where the frame's edges do not pair up, the least window that agrees.
    let base = p.clone();
    match pr.least(std::slice::from_ref(&rec), SOF_MAX, |n| {
        let mut q = base.clone();
        q.tolerances.sof_tolerance = n.max(base.tolerances.sof_tolerance);
        q.tolerances.status_tolerance = status_max;
        q.tolerances.tx_edge_tolerance = TX_MAX;
        q
    }) {
        Ok(n) if n > p.tolerances.sof_tolerance => {
            evidence("sof", format!("the frame from bus idle after a bus-off recovery agrees with a window of {n} CAN clocks, not less (bound {SOF_MAX})"));
            p.tolerances.sof_tolerance = n;
        }
        Ok(_) => {}
        Err(f) => {
            devs.push(Deviation { freedom: "sof".into(), bound: bound("sof"), probe: f.0, divergence: f.1 });
            p.tolerances.sof_tolerance = SOF_MAX;
        }
    }
    if p.phase_origin == PhaseOrigin::HardwareReset && p.holdoff.wishbone.is_none() {
        // The write edge does not move the phase: the earliest that agrees.
        let mut writes = Vec::new();
        for w in 0..=access_max {
            let mut q = p.clone();
            set_access(&mut q, edges(w, w, w));
            if pr.all(&phase_probes, &q).is_ok() {
                writes.push(w);
            }
        }
        if !writes.is_empty() {
            let w = writes[writes.len() / 2];
            set_access(&mut p, edges(w, w, w));
            evidence("write", format!("write edges agreeing on the phase probes: {} (chosen {w}, the middle)", range(&writes)));
        }
    }
    let write = match p.wishbone {
        AccessTiming::CanEdges { write, .. } => write,
        AccessTiming::AtAck => write,
    };

    // The segment lag (a bit timing running through reset mode only):
    // BTR writes at BRP 0 (2 CAN clocks a quantum) landing at other clocks
    // of the running reset-value bit; the least lag under which the core's
    // frame is the model's at each landing (a larger one redoes quanta the
    // core does not).
    let mut grid_probes: Vec<Probe> = Vec::new();
    if p.phase_origin == PhaseOrigin::HardwareReset && !devs.iter().any(|d| d.freedom.contains("phase-origin")) {
        grid_probes = (0..3).map(probes::grid).collect();
        let runs0 = pr.runs;
        let mut tried = Vec::new();
        let mut last_fail = (String::new(), String::new());
        let found = (0..=SEGMENT_LAG_MAX).find(|&n| {
            let mut q = p.clone();
            q.segment_lag = n;
            tried.push(n);
            match pr.all(&grid_probes, &q) {
                Ok(()) => true,
                Err(f) => {
                    last_fail = f;
                    false
                }
            }
        });
        match found {
            Some(n) => {
                p.segment_lag = n;
                let below = if n == 0 { "it is the least".to_string() } else { format!("{} disagree", range(&tried[..tried.len() - 1])) };
                evidence("segment-lag", format!("{n}: the least that agrees on probes {} (BTR writes at BRP 0 landing at 3 clocks of the running bit; {below}; bound {SEGMENT_LAG_MAX}); {} runs", names(&grid_probes), pr.runs - runs0));
            }
            None => {
                devs.push(Deviation { freedom: "segment-lag".into(), bound: bound("segment-lag"), probe: last_fail.0, divergence: last_fail.1 });
                evidence("segment-lag", format!("NOT MEASURED: no lag 0..{SEGMENT_LAG_MAX} agrees on probes {} (candidate deviation; left at 0)", names(&grid_probes)));
            }
        }
    }

    // Where the access's edges count from: the other choice on the probes
    // that placed the writes. Both agreeing: the probes cannot tell them
    // apart (a CAN edge between the wires and the next host edge moves a
    // write by one CAN clock, which the phase and grid probes see only
    // where it moves a BTR write or the reset-mode exit across a quantum's
    // end); the default stays.
    if !wb_family {
        evidence("count-from", format!("not measured: where the edges count from (host edge or wires) is a choice of wishbone, avalon and pio only; on {} they count from the edge the bus's own entry names", o.host));
    } else if !devs.iter().any(|d| d.freedom.contains("phase-origin")) {
        let runs0 = pr.runs;
        let mut on = phase_probes.clone();
        on.extend(grid_probes.iter().cloned());
        let mut q = p.clone();
        set_wires(&mut q, true);
        match pr.all(&on, &q) {
            Ok(()) => evidence("count-from", format!("host-edge (the default): \"wires\" agrees as well on probes {}, which cannot tell them apart (the two differ by one CAN clock in about half the host/CAN phases; no write of the probes crosses a quantum's end by it); {} runs", names(&on), pr.runs - runs0)),
            Err((probe, why)) => evidence("count-from", format!("host-edge: \"wires\" disagrees on probe {probe} ({}); {} runs", why.chars().take(120).collect::<String>(), pr.runs - runs0)),
        }
    }

    // 2. The command edge: the transmission request landing at other
    // clocks of the bit (0..12 pad reads).
    let cmd_probes: Vec<Probe> = (0..=12).map(probes::command).collect();
    let runs0 = pr.runs;
    let mut cmds = Vec::new();
    let mut tried = Vec::new();
    let mut last_fail = (String::new(), String::new());
    // Nearest the write edge first (a command crosses as a write does);
    // the first that agrees at every position is taken.
    let mut order: Vec<u32> = (0..=access_max).collect();
    order.sort_by_key(|c| (c.abs_diff(write), *c));
    for c in order {
        let mut q = p.clone();
        set_access(&mut q, edges(write, write, c));
        tried.push(c);
        match pr.all(&cmd_probes, &q) {
            Ok(()) => {
                cmds.push(c);
                break;
            }
            Err(f) => last_fail = f,
        }
    }
    let command = if cmds.is_empty() {
        devs.push(Deviation { freedom: "command".into(), bound: bound(access_key), probe: last_fail.0, divergence: last_fail.1 });
        evidence("command", format!("NOT MEASURED: no command edge 0..{access_max} agrees (candidate deviation)"));
        write
    } else {
        let c = cmds[0];
        let before = if tried.len() > 1 { format!("; nearer ones disagree: {}", range(&tried[..tried.len() - 1])) } else { String::new() };
        evidence("command", format!("command edge {c} (the nearest the write edge that agrees) agrees on probes command+0..12 (the request at 13 positions in the bit){before}; {} runs", pr.runs - runs0));
        c
    };
    set_access(&mut p, edges(write, write, command));

    // 3. The read edge and the SR/IR latency: for each read edge the least
    // status window under which the status probe agrees; the least overall.
    let st = [probes::status(), rec.clone(), probes::passive()];
    let runs0 = pr.runs;
    let mut best: Vec<(u32, u32)> = Vec::new();
    let mut last_fail = (String::new(), String::new());
    let with_read = |r: u32, s: u32| {
        let mut q = p.clone();
        set_access(&mut q, edges(r, write, command));
        q.tolerances.status_tolerance = s;
        // tx at its bound: the recovery's frame is measured last (stage 5).
        q.tolerances.tx_edge_tolerance = TX_MAX;
        q
    };
    // The least window at the write edge, then every other read edge tried
    // one clock narrower (and searched down only where that agrees).
    match pr.least(&st, status_max, |s| with_read(write, s)) {
        Ok(s) => best.push((write, s)),
        Err(f) => last_fail = f,
    }
    let at = best.first().map_or(status_max, |b| b.1);
    // A read is taken at E's rise on the Motorola bus (no E fall to wait
    // for): its front and crossing only.
    let read_max = if bus == Some(PortBus::Motorola) { 2 * ACCESS_MAX } else { access_max };
    for r in (0..=read_max).filter(|r| *r != write) {
        if at > 0 && pr.all(&st, &with_read(r, at - 1)).is_ok() {
            if let Ok(s) = pr.least(&st, at - 1, |s| with_read(r, s)) {
                best.push((r, s));
            }
        } else if best.is_empty() {
            match pr.least(&st, status_max, |s| with_read(r, s)) {
                Ok(s) => best.push((r, s)),
                Err(f) => last_fail = f,
            }
        } else if pr.all(&st, &with_read(r, at)).is_ok() {
            best.push((r, at));
        }
    }
    let read = match best.iter().map(|b| b.1).min() {
        None => {
            devs.push(Deviation { freedom: "status".into(), bound: bound("status"), probe: last_fail.0, divergence: last_fail.1 });
            evidence("status", format!("NOT MEASURED: SR/IR reads disagree at every read edge 0..{read_max} with a window of {status_max} (candidate deviation)"));
            p.tolerances.status_tolerance = status_max;
            write.saturating_sub(1)
        }
        Some(s) => {
            let reads: Vec<u32> = best.iter().filter(|b| b.1 == s).map(|b| b.0).collect();
            // Ties: the latest edge not after the write edge (a read crosses
            // by the same synchroniser as a write, no later).
            let r = reads.iter().copied().filter(|r| *r <= write).max().unwrap_or(reads[0]);
            let w = (s + POLL_MARGIN).min(status_max);
            p.tolerances.status_tolerance = w;
            evidence("read", format!("read edges with the least SR/IR window on probes status, recovery, passive: {} (chosen {r}, the latest not after the write edge)", range(&reads)));
            evidence("status", format!("{w}: SR/IR reads agree within {s} CAN clocks (least window, bound {status_max}; written with one polled read more, {POLL_MARGIN}) polling SR through a received and a sent frame, a bus-off recovery and error passive; {} runs", pr.runs - runs0));
            r
        }
    };
    set_access(&mut p, edges(read, write, command));

    // 4. The irq and bus-off pins.
    let pin_probes = [probes::status(), probes::phase(0), rec.clone(), probes::passive()];
    let runs0 = pr.runs;
    let base = p.clone();
    let with_pins = |n: u32| {
        let mut q = base.clone();
        q.tolerances.compare_irq = true;
        q.tolerances.compare_bus_off = true;
        q.tolerances.pin_tolerance = n;
        q.tolerances.tx_edge_tolerance = TX_MAX;
        q
    };
    match pr.least(&pin_probes, PINS_MAX, with_pins) {
        Ok(n) => {
            let w = (n + POLL_MARGIN).min(PINS_MAX);
            p.tolerances.pin_tolerance = w;
            evidence("pins", format!("{w}: irq/bus-off agree within {n} CAN clocks (least, bound {PINS_MAX}; written with one polled read more, {POLL_MARGIN}) on probes status, phase+0, recovery, passive (interrupts of a received, a sent and a self-received frame; bus-off and its recovery; error warning and passive); {} runs", pr.runs - runs0));
        }
        Err(f) => {
            p.tolerances.pin_tolerance = PINS_MAX;
            devs.push(Deviation { freedom: "pins".into(), bound: bound("pins"), probe: f.0, divergence: f.1 });
            evidence("pins", format!("NOT MEASURED: irq/bus-off disagree for more than {PINS_MAX} CAN clocks (candidate deviation)"));
        }
    }
    p.tolerances.compare_irq = true;
    p.tolerances.compare_bus_off = true;
    let pins_ok = !devs.iter().any(|d| d.freedom == "pins");
    let status_ok = !devs.iter().any(|d| d.freedom == "status");

    // 5. The tx edge window, over every probe, the others at their values
    // (a deviation's entry is left out of this comparison, not widened).
    let mut all: Vec<Probe> = phase_probes.clone();
    all.extend(cmd_probes.iter().cloned());
    all.extend(st.iter().cloned());
    let runs0 = pr.runs;
    let base = p.clone();
    let measured_tx = p.tolerances.tx_edge_tolerance;
    let with_tx = |n: u32| {
        let mut q = base.clone();
        q.tolerances.tx_edge_tolerance = n.max(measured_tx);
        q.tolerances.compare_irq &= pins_ok;
        q.tolerances.compare_bus_off &= pins_ok;
        if !status_ok {
            q.tolerances.status_tolerance = 1000;
        }
        q
    };
    let tx_result = match pr.all(&all, &with_tx(measured_tx)) {
        Ok(()) => Ok(measured_tx),
        Err(_) => pr.least(&all, TX_MAX, with_tx),
    };
    match tx_result {
        Ok(n) => {
            let n = n.max(measured_tx);
            p.tolerances.tx_edge_tolerance = n;
            evidence("tx-edge", format!("with {n} (at least the measured lag) tx agrees at every sample point on all {} probes; {} runs", all.len(), pr.runs - runs0));
        }
        Err(f) => {
            p.tolerances.tx_edge_tolerance = TX_MAX;
            devs.push(Deviation { freedom: "tx-edge".into(), bound: bound("tx-edge"), probe: f.0, divergence: f.1 });
            evidence("tx-edge", format!("NOT MEASURED: tx differs at sample points {TX_MAX} CAN clocks from a model tx edge (candidate deviation)"));
        }
    }
    match bus {
        None => evidence("access", format!("measured on {}; the other buses take the same crossing (re-run with --host avalon|pio to measure them)", o.host)),
        Some(b) => evidence("access", format!("measured on {}, written to [access.{}] only ([access.wishbone], [access.avalon], [access.pio], which the file format requires, say at-ack: not measured, the top has no Wishbone port)", o.host, b.key())),
    }
    match bus {
        Some(PortBus::Regport) => evidence("strobe", "strobe and gap: the kit's defaults for the register port (not measured: the probes agree with them)".into()),
        Some(PortBus::Motorola) => evidence("strobe", "AS, E and recovery phases: the kit's defaults (not measured: a probe that agrees shows the defaults suffice, not the core's minimums; enter the datasheet's as `*-ns` keys)".into()),
        _ => {}
    }

    let toml = render(&p, &ev, &devs, &o.host, bus, pr.runs);
    let profile = Profile::parse(&toml, "inferred profile").map_err(|e| InferError::Build(format!("the inferred profile does not parse (a bug): {e}")))?;
    Ok(Inference { profile, toml, evidence: ev, deviations: devs, runs: pr.runs, build, probing: t1.elapsed() })
}

fn names(p: &[Probe]) -> String {
    p.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
}

/// The profile file: every entry with its evidence as a comment above it.
fn render(p: &Profile, ev: &[Evidence], devs: &[Deviation], host: &HostBfm, bus: Option<PortBus>, runs: usize) -> String {
    let say = |key: &str| -> String {
        ev.iter().filter(|e| e.key == key).map(|e| format!("# evidence: {}\n", e.line)).collect()
    };
    let mut s = format!(
        "# Inferred by `cancosim profile infer` ({runs} probe runs, host {host}). Each entry has its\n\
         # evidence above it; each freedom is bounded (cosim profile docs, profile-infer BOUNDS).\n"
    );
    for d in devs {
        s += &format!("# {d}\n# Not absorbed: the entry is at its bound, so the comparator still shows it.\n");
    }
    s += &format!("name = {:?}\ndescription = {:?}\n\n", p.name, p.description);
    s += &say("phase-origin");
    s += &format!("phase-origin = \"{}\"\n\n", match p.phase_origin {
        PhaseOrigin::HardwareReset => "hardware-reset",
        PhaseOrigin::ResetModeExit => "reset-mode-exit",
    });
    if p.phase_origin == PhaseOrigin::HardwareReset {
        s += &say("segment-lag");
        s += &format!("segment-lag = {}\n\n", p.segment_lag);
    }
    s += &say("ts-in-suspend");
    s += &format!("ts-in-suspend = \"{}\"\n\n", if p.ts_clear_in_suspend { "clear" } else { "set" });
    let AccessTiming::CanEdges { read, write, command } = p.wishbone else { unreachable!("the inference writes edge counts") };
    let measured = |s: &mut String| {
        for k in ["access", "read-latency", "read", "write", "command", "busy-after-ack", "count-from", "strobe"] {
            *s += &say(k);
        }
    };
    match bus {
        None => {
            measured(&mut s);
            for bus in ["wishbone", "avalon", "pio"] {
                s += &format!("[access.{bus}]\n");
                if let Some(b) = p.holdoff.wishbone {
                    s += &format!("busy-after-ack = [{}, {}, {}]\n", b.can, b.host, b.can_again);
                }
                if p.count_from_wires.wishbone {
                    s += "count-from = \"wires\"\n";
                }
                s += &format!("takes-effect = \"can-edges\"\nread = {read}\nwrite = {write}\ncommand = {command}\n\n");
            }
        }
        Some(b) => {
            s += "# Not measured: the top has no Wishbone port (the file format requires these).\n";
            for w in ["wishbone", "avalon", "pio"] {
                s += &format!("[access.{w}]\ntakes-effect = \"at-ack\"\n\n");
            }
            measured(&mut s);
            s += &format!("[access.{}]\ntakes-effect = \"can-edges\"\nread = {read}\nwrite = {write}\ncommand = {command}\n", b.key());
            if b == PortBus::Regport {
                if let Some(l) = p.regport.read_latency {
                    s += &format!("read-latency = {l}\n");
                }
                if let Some(one) = p.regport.one_address {
                    s += &format!("addresses = \"{}\"\n", if one { "one" } else { "separate" });
                }
            }
            s += "\n";
        }
    }
    let t = &p.tolerances;
    s += "[tolerances]\n";
    for (k, v) in [("tx-edge", t.tx_edge_tolerance), ("sof", t.sof_tolerance), ("status", t.status_tolerance), ("pins", t.pin_tolerance)] {
        s += &say(k);
        s += &format!("{k} = {v}\n");
    }
    s += "\n";
    s += &say("ports");
    s += "[ports]\n";
    let m = &p.ports;
    let polar = |pin: &cosim::profile::Pin| format!("{{ name = {:?}, active = \"{}\" }}", pin.name, if pin.active_high { "high" } else { "low" });
    let wb = [
        ("host-clock", format!("{:?}", m.host_clock.name)),
        ("reset", polar(&m.reset)),
        ("dat-i", format!("{:?}", m.dat_i.name)),
        ("dat-o", format!("{:?}", m.dat_o.name)),
        ("cyc", format!("{:?}", m.cyc.name)),
        ("stb", format!("{:?}", m.stb.name)),
        ("we", format!("{:?}", m.we.name)),
        ("adr", format!("{:?}", m.adr.name)),
        ("ack", format!("{:?}", m.ack.name)),
    ];
    let can = [
        ("can-clock", format!("{:?}", m.can_clock.name)),
        ("rx", format!("{:?}", m.rx.name)),
        ("tx", format!("{:?}", m.tx.name)),
        ("irq", polar(&m.irq)),
        ("bus-off", polar(&m.bus_off)),
        ("clkout", format!("{:?}", m.clkout.name)),
    ];
    // On another bus the Wishbone roles are not bound: left out.
    for (k, v) in wb.into_iter().filter(|_| bus.is_none()).chain(can) {
        s += &format!("{k} = {v}\n");
    }
    if let Some(b) = bus {
        let bp = ports::bus_ports(m, b);
        s += &format!("\n[ports.{}]\n", b.key());
        for role in bp.roles().into_iter().filter(|r| bp.named(r)) {
            let pin = bp.pin(role);
            let v = if bp.polar(role) { polar(pin) } else { format!("{:?}", pin.name) };
            s += &format!("{role} = {v}\n");
        }
    }
    s
}

/// The DUT's and the model's tx edges of one run (CAN clocks from the
/// start, rounded), from the run's VCD.
struct TxEdges {
    dut: Vec<(i64, bool)>,
    model: Vec<(i64, bool)>,
    clock_ps: f64,
}

impl TxEdges {
    /// Lags (DUT minus model, CAN clocks) of the edges the two sides share
    /// in order; None when their edge sequences differ in length or level.
    fn lags(&self) -> Option<Vec<i64>> {
        if self.dut.len() != self.model.len() || self.dut.is_empty() {
            return None;
        }
        self.dut.iter().zip(&self.model).map(|(d, m)| (d.1 == m.1).then_some(((d.0 - m.0) as f64 / self.clock_ps).round() as i64)).collect()
    }
}

fn read_tx_edges(path: &std::path::Path, can_mhz: f64) -> Option<TxEdges> {
    let f = std::io::BufReader::new(std::fs::File::open(path).ok()?);
    let mut p = vcd::Parser::new(f);
    let h = p.parse_header().ok()?;
    let dut = h.find_var(&["cosim", "tx_o"])?.code;
    let model = h.find_var(&["cosim", "model_tx"])?.code;
    let clock_ps = 1e6 / can_mhz;
    let (mut t, mut e) = (0u64, TxEdges { dut: Vec::new(), model: Vec::new(), clock_ps });
    let (mut last_d, mut last_m) = (None, None);
    for c in p {
        match c.ok()? {
            vcd::Command::Timestamp(ts) => t = ts,
            vcd::Command::ChangeScalar(id, v) if id == dut || id == model => {
                let level = v == vcd::Value::V1;
                let (list, last) = if id == dut { (&mut e.dut, &mut last_d) } else { (&mut e.model, &mut last_m) };
                // Before the configuration ends the core is in reset mode and
                // sends nothing: a level it shows in its reset is no edge.
                if last.is_some_and(|l| l != level) && t as f64 > 200.0 * clock_ps {
                    list.push((t as i64, level));
                }
                *last = Some(level);
            }
            _ => {}
        }
    }
    Some(e)
}

impl Prober {
    /// Runs `probe` with a VCD and returns the tx edges of both sides.
    fn tx_edges(&mut self, probe: &Probe, p: &Profile) -> Option<TxEdges> {
        self.runs += 1;
        let dir = tempfile::tempdir().ok()?;
        let vcd = dir.path().join("probe.vcd");
        // Collect mode: the run goes on past a difference, so both sides'
        // edges are there to measure.
        let opts = RunOptions {
            dut: Some(self.dut.clone().with_profile(p.clone())),
            host: Some(self.host),
            vcd: Some(vcd.clone()),
            waivers: self.waivers.clone(),
            collect: cosim::waivers::CollectMode::Collect,
            ..RunOptions::default()
        };
        scenario::run(&probe.scenario, &opts);
        read_tx_edges(&vcd, probe.scenario.can_hz / 1e6)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_motorola_bound_has_the_kits_write_e() {
        let t = cosim::i8051_timing_for_rtl(50_000_000, 24_000_000);
        assert_eq!((t.wr * 24).div_ceil(50), MOTOROLA_E_WRITE, "E of a write in CAN clocks at the probes' 50 and 24 MHz");
    }
}
