//! The runner: plays a [`Scenario`] on a `cosim` [`Testbench`], completes
//! the run record (TEC per attempt, final registers, wiring as the scenario
//! states it), calls the diagnoser and checks the expected outcome.

use crate::{Action, DutKind, FaultKind, FaultSpec, HostBfm, NodeSpec, RxWire, Scenario};
use cosim::{AvalonWiring, DutChoice, ExternalCore, NodeConfig, ReferenceChoice, TbConfig, TbError, Testbench};
use diagnose::{Diagnosis, EventKind, Expectation, FinalRegs, RunRecord, Side, TecStep, diagnose};
use can_proto::Field;
use regmap::Mode;
use sja1000::{FaultInjector, Target};
use std::time::{Duration, Instant};

/// A device to run scenarios against (the regression's columns).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DutSpec {
    /// Column name in reports, e.g. "rtl", "model", "upstream-r3".
    pub name: String,
    /// What it is. `Rtl` becomes our Avalon wrapper when a scenario asks
    /// for `avalon-wrapper`.
    pub kind: DutKind,
    /// Its declared freedoms (`--profile`); None: our RTL's implicit
    /// `rtl.toml`, the model's own timing, or (an external core through
    /// the library) accesses taken at the ack with default tolerances.
    pub profile: Option<cosim::Profile>,
}

impl DutSpec {
    /// Our RTL.
    pub fn rtl() -> Self {
        DutSpec { name: "rtl".into(), kind: DutKind::Rtl, profile: None }
    }

    /// The golden model as DUT.
    pub fn model() -> Self {
        DutSpec { name: "model".into(), kind: DutKind::Model, profile: None }
    }

    /// An external core directory with the `can_top` ports.
    pub fn external(name: &str, dir: impl Into<std::path::PathBuf>, top: &str) -> Self {
        DutSpec {
            name: name.into(),
            kind: DutKind::External { path: dir.into(), top: top.into(), defines: Vec::new(), includes: Vec::new() },
            profile: None,
        }
    }

    /// The same DUT with a profile; an external core is then named
    /// "<profile> (<dir>)" in reports (waiver `dut` globs match it).
    pub fn with_profile(mut self, p: cosim::Profile) -> Self {
        if let DutKind::External { path, .. } = &self.kind {
            self.name = format!("{} ({})", p.name, path.display());
        }
        self.profile = Some(p);
        self
    }
}

/// Options of one run.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Run against this DUT instead of the scenario's own.
    pub dut: Option<DutSpec>,
    /// Write our VCD here.
    pub vcd: Option<std::path::PathBuf>,
    /// Override the scenario's run length (bit times).
    pub max_bits: Option<u64>,
    /// Waiver files added to the scenario's own `[run] waivers`.
    pub waivers: Vec<std::path::PathBuf>,
    /// DUT revision the waivers' `revisions` are matched against.
    pub dut_revision: Option<String>,
    /// Stop at the first unwaived divergence (default) or collect them all.
    pub collect: waivers::CollectMode,
    /// Run with this host instead of the scenario's own (`--host`): on our
    /// RTL, `Avalon` means the `can_avalon` wrapper driven by the Avalon
    /// BFM, `Wishbone` plain `can_top`, `Pio` the level-ack `can_top_pio`.
    /// A scenario whose point is its host wiring (`[host] fixed`) is
    /// skipped, see [`RunOutcome::skipped`].
    pub host: Option<HostBfm>,
    /// Build the DUT with Verilator's coverage and write its counters to
    /// this `.dat` at the end of the run (`regress --coverage`).
    pub coverage_dat: Option<std::path::PathBuf>,
    /// Inputs of an external core held at a constant for the whole run
    /// ([`cosim::ExternalCore::held_inputs`]: the mutant select of `cancosim mutate`).
    pub held_inputs: Vec<(String, u64)>,
    /// A DUT in Rust built by the caller instead of the scenario's own
    /// (tests: the golden model with one behaviour altered, no HDL build).
    pub custom_dut: Option<cosim::CustomDut>,
}

/// The scenario as run with a host override: the host replaced, and our
/// RTL behind the Avalon wrapper exactly when the host is Avalon-MM.
pub fn with_host(s: &Scenario, host: HostBfm) -> Scenario {
    let mut o = s.clone();
    o.host = host;
    o.dut = match (&s.dut, host) {
        (DutKind::Rtl | DutKind::AvalonWrapper, HostBfm::Avalon { begintransfer_cyc: false }) => DutKind::AvalonWrapper,
        (DutKind::AvalonWrapper, _) => DutKind::Rtl,
        (d, _) => d.clone(),
    };
    o
}

/// The result of one run.
#[derive(Clone, Debug)]
pub struct RunOutcome {
    /// The record the diagnosis was made from.
    pub record: RunRecord,
    /// The diagnosis.
    pub diagnosis: Diagnosis,
    /// The outcome matched the scenario's `[expect]`.
    pub passed: bool,
    /// Each way the outcome differs from `[expect]`, in words.
    pub mismatches: Vec<String>,
    /// Frames each model node received, by node name.
    pub received: Vec<(String, u32)>,
    /// DUT name used.
    pub dut: String,
    /// Wall time of the run.
    pub wall: Duration,
    /// Divergences waived and not, stale waivers (None if no test bench ran).
    pub waivers: Option<waivers::WaiverReport>,
    /// Non-fatal remarks: stale waivers.
    pub warnings: Vec<String>,
    /// Not run, and why: the scenario's host wiring is its point
    /// (`[host] fixed`) and a host override was asked for. Counts as passed.
    pub skipped: Option<String>,
    /// The run's bus log (frames, the DUT's error frames), for `--candump`
    /// ([`cosim::candump::write_log`]).
    pub bus_log: Vec<cosim::candump::LogEntry>,
    /// The messages the host read out of the DUT's RX FIFO (`drain` steps),
    /// in order, each with the bit time it was read at.
    pub delivered: Vec<(u64, can_proto::CanFrame)>,
    /// Where the program was: (step number, its start in ps) per step
    /// played, then (0, the end of the last step). Places a divergence by
    /// step ([`RunOutcome::step_at`]).
    pub steps: Vec<(usize, u64)>,
}

impl RunOutcome {
    /// The step the program was in at `t_ps` (`waivers::StepAt`). A step
    /// starts the instant the one before ends, so a read that ends then
    /// (and its divergence) belongs to the step before.
    pub fn step_at(&self, t_ps: u64) -> waivers::StepAt {
        match self.steps.iter().rev().find(|(_, t)| *t < t_ps) {
            None => waivers::StepAt::Before,
            Some((0, _)) => waivers::StepAt::After,
            Some((n, _)) => waivers::StepAt::In(*n),
        }
    }
}

/// Frame and bit of a frame-relative fault (frames counted from 1 in files, from 0 on the bus).
fn injector(f: &FaultSpec, target: Target, clocks_per_bit: u64) -> Box<dyn FaultInjector> {
    match (f.kind, f.frame_bit) {
        (FaultKind::StuckDominant | FaultKind::StuckRecessive, Some((fr, b))) => Box::new(sja1000::StuckInFrame {
            level: f.kind == FaultKind::StuckRecessive,
            target,
            frame: fr as u64 - 1,
            bit: b,
            bits: f.duration_bits,
            until: None,
        }),
        (FaultKind::StuckDominant | FaultKind::StuckRecessive, None) => {
            let level = f.kind == FaultKind::StuckRecessive;
            let from = f.at_bit.unwrap_or(0) * clocks_per_bit;
            Box::new(sja1000::StuckAt { level, target, from, until: Some(from + f.duration_bits * clocks_per_bit) })
        }
        (FaultKind::Flip, Some((fr, b))) => Box::new(sja1000::FlipBit { frame: fr as u64 - 1, bit: b, target }),
        // Placed in the bit (offset_clocks/offset_tq; dut-rx only, whose
        // context numbers bits from boundary to boundary, so the pulse may
        // cross the sample point and stay in its bit).
        (FaultKind::Glitch, Some((fr, b))) if f.pulse_clocks.is_some() && f.pulse_on_sof_grid => {
            let (offset, width) = f.pulse_clocks.unwrap_or_default();
            Box::new(crate::pulse::SofGridPulse::new(fr as u64 - 1, b, offset, width, f.pulse_level, target))
        }
        (FaultKind::Glitch, Some((fr, b))) if f.pulse_clocks.is_some() => {
            let (offset, width) = f.pulse_clocks.unwrap_or_default();
            match f.pulse_level {
                Some(level) => Box::new(crate::pulse::ForcedPulse { frame: fr as u64 - 1, bit: b, offset, width, level, target }),
                None => Box::new(sja1000::Glitch { frame: fr as u64 - 1, bit: b, offset, width, target }),
            }
        }
        (FaultKind::Glitch, Some((fr, b))) => Box::new(sja1000::Glitch {
            frame: fr as u64 - 1,
            bit: b,
            offset: (clocks_per_bit / 4) as u32,
            width: (clocks_per_bit / 8).max(1) as u32,
            target,
        }),
        // Absolute-time flips and glitches: a stuck level for one bit.
        (FaultKind::Flip | FaultKind::Glitch, None) => {
            let from = f.at_bit.unwrap_or(0) * clocks_per_bit;
            Box::new(sja1000::StuckAt { level: can_proto::DOMINANT, target, from, until: Some(from + clocks_per_bit) })
        }
    }
}

/// Register writes that configure a model node (reset mode, filters, timing, operating mode).
fn node_init(n: &NodeSpec) -> Vec<(u8, u8)> {
    let mut v = vec![(0, 0x01)];
    match n.mode {
        Mode::BasicCan => {
            v.extend([(31, 0x00), (4, n.acr[0]), (5, n.amr[0]), (6, n.btr0), (7, n.btr1), (8, 0xDA), (0, 0x00)]);
        }
        Mode::PeliCan => {
            v.push((31, 0x80));
            for i in 0..4u8 {
                v.push((16 + i, n.acr[i as usize]));
                v.push((20 + i, n.amr[i as usize]));
            }
            v.extend([(6, n.btr0), (7, n.btr1), (8, 0xDA), (0, if n.listen_only { 0x02 } else { 0x00 })]);
        }
    }
    v
}

/// The external core a DUT spec names (sources, defines, includes, and the
/// `[vhdl]` options of its profile); `None` for bundled DUTs.
/// Driven over the 8051 bus (`host`), a core whose profile declares an
/// `inout` port (`[access.i8051] inout-drive`) is wrapped in the split-port
/// shell (`cosim::i8051_shell`).
pub fn external_core(d: &DutSpec, host: Option<HostBfm>) -> Result<Option<ExternalCore>, String> {
    external_core_of(&d.kind, d.profile.as_ref(), host)
}

fn external_core_of(kind: &DutKind, profile: Option<&cosim::Profile>, host: Option<HostBfm>) -> Result<Option<ExternalCore>, String> {
    let DutKind::External { path, top, defines, includes } = kind else { return Ok(None) };
    let core = ExternalCore {
        dir: path.clone(),
        top: top.clone(),
        defines: defines.clone(),
        include_dirs: includes.clone(),
        vhdl: profile.map(|p| p.vhdl.clone()).unwrap_or_default(),
        ..ExternalCore::default()
    };
    match (host, profile.and_then(|p| p.i8051_inout_drive.as_deref())) {
        (Some(HostBfm::I8051), Some(drive)) => {
            cosim::i8051_shell::wrap(&core, drive, &cosim::cache_dir()).map(Some).map_err(|e| e.to_string())
        }
        _ => Ok(Some(core)),
    }
}

/// Builds the test-bench configuration for `s` on `dut`.
pub fn tb_config(s: &Scenario, dut: &DutKind, opts: &RunOptions) -> Result<TbConfig, String> {
    // An AXI4-Lite or APB top with one clock port for the bus and the core
    // (its profile's bus clock is its CAN clock): the host runs on the CAN
    // clock, as on the register port (both clocks drive the same port).
    let one_clock = opts.dut.as_ref().and_then(|d| d.profile.as_ref()).is_some_and(|p| match s.host {
        HostBfm::Axi4Lite => p.ports.axi4lite.pin("clock").name == p.ports.can_clock.name,
        HostBfm::Apb | HostBfm::Apb3 => p.ports.apb.pin("clock").name == p.ports.can_clock.name,
        _ => false,
    });
    let on_can_clock;
    let s = if one_clock && s.host_hz != s.can_hz {
        on_can_clock = Scenario { host_hz: s.can_hz, ..s.clone() };
        &on_can_clock
    } else {
        s
    };
    let avalon_dut = matches!(s.dut, DutKind::AvalonWrapper);
    let choice = match dut {
        _ if opts.custom_dut.is_some() => DutChoice::Custom(opts.custom_dut.clone().expect("checked")),
        DutKind::Rtl | DutKind::AvalonWrapper if avalon_dut && matches!(s.host, HostBfm::Avalon { begintransfer_cyc: false }) => DutChoice::RtlAvalon,
        // A PIO master polls ack through a GPIO: our RTL needs its level
        // acknowledge (four-phase handshake, can_top ACK_LEVEL = 1) there,
        // as the thesis board would.
        DutKind::Rtl | DutKind::AvalonWrapper if matches!(s.host, HostBfm::Pio | HostBfm::PioEdgeCapture) => {
            if cosim::bundled_tops().contains(&"can_top_pio") {
                DutChoice::Bundled("can_top_pio".into())
            } else {
                DutChoice::External(ExternalCore {
                    dir: std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../rtl"),
                    top: "can_top".into(),
                    extra_args: vec!["-GACK_LEVEL=1".into()],
                    ..ExternalCore::default()
                })
            }
        }
        DutKind::Rtl | DutKind::AvalonWrapper => DutChoice::Rtl,
        DutKind::Model => DutChoice::Model,
        DutKind::External { .. } => DutChoice::External({
            let mut core = external_core_of(dut, opts.dut.as_ref().and_then(|d| d.profile.as_ref()), Some(s.host))?.expect("an external kind");
            core.held_inputs = opts.held_inputs.clone();
            core
        }),
    };
    let host = match s.host {
        HostBfm::Wishbone => cosim::HostBfm::Wishbone,
        HostBfm::Pio => cosim::HostBfm::Pio(bfm::PioTiming::default()),
        HostBfm::PioEdgeCapture => cosim::HostBfm::Pio(bfm::PioTiming { ack_input: bfm::PioAckInput::EdgeCapture, ..Default::default() }),
        // DutChoice::Rtl is can_top_8051 under this host.
        HostBfm::I8051 => cosim::HostBfm::I8051(cosim::i8051_timing_for_rtl(s.host_hz as u64, s.can_hz as u64)),
        // DutChoice::Rtl is can_top_mcu under this host: the same phases
        // as the 8051 host's (AS for ALE, E for RD/WR), in ns.
        // DutChoice::Rtl is can_regport; the bench runs the host on the CAN
        // clock (cosim::Testbench::new).
        // Strobe, read latency, gap and addresses: the profile's
        // `[access.regport]`, else can_regport's.
        HostBfm::Regport => cosim::HostBfm::Regport(opts.dut.as_ref().and_then(|d| d.profile.as_ref()).map_or_else(bfm::RegportConfig::default, |p| p.regport.config())),
        // The phases the profile's `[access.motorola]` gives, in ns; the
        // rest as for can_top_mcu.
        HostBfm::Motorola => {
            let base = cosim::i8051_timing_for_rtl(s.host_hz as u64, s.can_hz as u64);
            cosim::HostBfm::Motorola(opts.dut.as_ref().and_then(|d| d.profile.as_ref()).map_or(base, |p| p.motorola.cycles(base, s.host_hz as u64)))
        }
        // DutChoice::Rtl is can_axi4lite / can_apb under these hosts; the
        // register layout is the profile's (our wrappers: 4 and 0).
        HostBfm::Axi4Lite => {
            let l = opts.dut.as_ref().and_then(|d| d.profile.as_ref()).map_or(cosim::RegLayout::WORD, |p| p.axi4lite_layout);
            cosim::HostBfm::Axi4Lite(bfm::Axi4LiteConfig { stride: l.stride, byte_lane: l.byte_lane, period_ps: 1_000_000_000_000 / s.host_hz as u64, ..Default::default() })
        }
        HostBfm::Apb | HostBfm::Apb3 => {
            let l = opts.dut.as_ref().and_then(|d| d.profile.as_ref()).map_or(cosim::RegLayout::WORD, |p| p.apb_layout);
            cosim::HostBfm::Apb(bfm::ApbConfig { apb4: s.host == HostBfm::Apb, stride: l.stride, byte_lane: l.byte_lane, period_ps: 1_000_000_000_000 / s.host_hz as u64, ..Default::default() })
        }
        HostBfm::Avalon { begintransfer_cyc: true } => cosim::HostBfm::Avalon {
            // SOPC Builder without waitrequest: fixed wait states.
            timing: bfm::AvalonTiming::FixedWaitStates { read: 1, write: 1 },
            wiring: AvalonWiring::Seed000,
        },
        HostBfm::Avalon { begintransfer_cyc: false } => cosim::HostBfm::Avalon {
            timing: bfm::AvalonTiming::Waitrequest,
            wiring: if matches!(choice, DutChoice::RtlAvalon) { AvalonWiring::Native } else { AvalonWiring::Bridge },
        },
    };
    let (btr0, btr1) = s.dut_timing();
    let cpb = can_proto::timing::BusTiming::from_btr(btr0, btr1).clocks_per_bit() as u64;
    let mut faults = Vec::new();
    let mut dut_rx_faults = Vec::new();
    let mut bus_faults_seen = Vec::new();
    for f in &s.faults {
        let target = match f.target.as_str() {
            // Everyone on the bus: each model node, and the DUT through the
            // bench's rx_i injectors (the bench gives the DUT the bus level
            // before the bus's own injectors, so `Target::All` would not
            // reach it; one injector per node keeps a bench that does route
            // them from applying the fault twice).
            "bus" => {
                for i in 0..s.nodes.len() {
                    faults.push(injector(f, Target::Node(i), cpb));
                }
                // The DUT, and the bench's field decoder (which names fields as
                // the nodes see them): with model nodes, in the bus's own list,
                // so the fault lands on the wire bit it lands on for the nodes
                // (the bus counts frames its way); without, on the bench's bit clock.
                let (dut, seen) = (injector(f, Target::Node(s.nodes.len()), cpb), injector(f, Target::Node(s.nodes.len() + 1), cpb));
                if s.nodes.is_empty() {
                    dut_rx_faults.push(dut);
                    bus_faults_seen.push(seen);
                } else {
                    faults.push(dut);
                    faults.push(seen);
                }
                continue;
            }
            // What the DUT (and its shadow model) receive: the bench applies
            // these on rx_i, the DUT being node index `nodes.len()` there.
            "dut-rx" => {
                dut_rx_faults.push(injector(f, Target::Node(s.nodes.len()), cpb));
                continue;
            }
            name => Target::Node(s.nodes.iter().position(|n| n.name == name).ok_or(format!("fault target `{name}` is not a node"))?),
        };
        faults.push(injector(f, target, cpb));
    }
    let profile = opts.dut.as_ref().and_then(|d| d.profile.clone());
    // The comparator's tolerances: the profile's, our RTL's rtl.toml, else the defaults.
    let tolerances = match (&profile, &choice) {
        (Some(p), _) => p.tolerances,
        (None, DutChoice::Rtl | DutChoice::RtlAvalon) => cosim::Profile::rtl().tolerances,
        (None, DutChoice::Bundled(t)) if t == "can_top_pio" => cosim::Profile::rtl().tolerances,
        _ => cosim::CompareConfig::default(),
    };
    let files: Vec<&std::path::PathBuf> = s.waivers.iter().chain(&opts.waivers).collect();
    let waiver_set = if files.is_empty() { waivers::WaiverSet::empty() } else { waivers::WaiverSet::load_all(&files).map_err(|e| e.to_string())? };
    Ok(TbConfig {
        scenario: s.name.clone(),
        dut: choice,
        host,
        host_hz: s.host_hz as u64,
        can_hz: s.can_hz as u64,
        btr0,
        btr1,
        rx: match s.rx {
            RxWire::Bus => diagnose::RxWiring::Bus,
            RxWire::TiedRecessive => diagnose::RxWiring::TiedRecessive,
            RxWire::TiedDominant => diagnose::RxWiring::TiedDominant,
        },
        tx_on_bus: s.tx_to_bus,
        nodes: s.nodes.iter().map(|n| NodeConfig { name: n.name.clone(), init: node_init(n) }).collect(),
        faults,
        dut_rx_faults,
        bus_faults_seen,
        raw_nodes: s
            .raw_nodes
            .iter()
            .map(|r| cosim::agents::raw::RawNode::new(r.name.clone(), r.start, r.bits.clone()).expecting(r.expect.clone()).delayed(r.delay_clocks))
            .collect(),
        lockstep: Some((ReferenceChoice::Model, tolerances)),
        vcd: opts.vcd.clone(),
        keep_bits: s.keep_bits,
        op_timeout_cycles: s.timeout_cycles as u64,
        waivers: waiver_set,
        dut_revision: opts.dut_revision.clone(),
        collect: collect_mode(s.expect.category, opts.collect),
        profile,
        coverage_dat: opts.coverage_dat.clone(),
        ..TbConfig::default()
    })
}

/// TEC per transmission attempt from one side's bus-error events: an attempt
/// starts with a bus error detected in the frame itself; errors detected
/// while signalling (error flag, delimiter) belong to the same attempt.
pub fn tec_trace_from_events(r: &RunRecord, side: Side) -> Vec<TecStep> {
    let signalling = |f: Field| {
        matches!(
            f,
            Field::ActiveErrorFlag | Field::PassiveErrorFlag | Field::ErrorDelimiter | Field::OverloadFlag | Field::OverloadDelimiter
        )
    };
    let mut out: Vec<TecStep> = Vec::new();
    for e in r.events_of(side) {
        match e.kind {
            EventKind::BusError { field, ecc, .. } => {
                let field = diagnose::field_from_ecc(ecc).unwrap_or(field);
                let tec = e.tec.unwrap_or(0);
                if !signalling(field) || out.is_empty() {
                    out.push(TecStep { node: side, attempt: out.len() as u32 + 1, bit: e.bit, tec, bus_off: tec > 255 });
                } else if let Some(last) = out.last_mut() {
                    last.tec = tec;
                    last.bit = e.bit;
                    last.bus_off |= tec > 255;
                }
            }
            EventKind::FaultState(sja1000::FaultState::BusOff) => {
                if let Some(last) = out.last_mut() {
                    last.bus_off = true;
                    last.tec = last.tec.max(256);
                }
            }
            _ => {}
        }
    }
    out
}

/// Plays the steps; returns early on the first test-bench error.
fn play(
    tb: &mut Testbench,
    s: &Scenario,
    traffic: &mut Vec<(u64, usize, can_proto::CanFrame)>,
    max_bits: u64,
    delivered: &mut Vec<(u64, can_proto::CanFrame)>,
    marks: &mut Vec<(usize, u64)>,
) -> Result<(), TbError> {
    for (i, st) in s.steps.iter().enumerate() {
        marks.push((st.n, tb.now_ps()));
        log::info!("{}: step {} (line {}){}", s.name, st.n, st.line, st.note.as_ref().map(|n| format!(": {n}")).unwrap_or_default());
        fire_traffic(tb, traffic);
        if let Some(b) = st.block
            && (i == 0 || s.steps[i - 1].block != Some(b))
        {
            tb.begin_block(&block_accesses(&s.steps[i..], b))?;
        }
        match &st.action {
            Action::Write { addr, value, .. } => {
                tb.write(*addr, *value)?;
            }
            Action::Read { addr, name, expect: None } => {
                let _ = name;
                tb.read(*addr)?;
            }
            Action::Read { addr, name, expect: Some((mask, value)) } => {
                let what = format!("{} & 0x{mask:02X}", name.clone().unwrap_or_else(|| format!("@{addr}")));
                tb.expect(st.n, &what, *addr, *mask, *value)?;
            }
            Action::WaitIrq { timeout_bits } => {
                advance_until(tb, traffic, *timeout_bits, "irq", |tb| !tb.pins().irq_n)?;
            }
            Action::WaitSr { set, clear, timeout_bits } => {
                let mask = set | clear;
                let start = tb.bits();
                loop {
                    fire_traffic(tb, traffic);
                    // Poll in slices that end where the next node frame is
                    // due, so node traffic starts at its `at_bit`.
                    let now = tb.bits();
                    let due = traffic.iter().map(|t| t.0).min().unwrap_or(u64::MAX).saturating_sub(now + 1);
                    match tb.wait_sr(mask, *set, 64.min(*timeout_bits).min(due)) {
                        Ok(_) => break,
                        Err(TbError::Timeout { .. }) if tb.bits() - start < *timeout_bits => continue,
                        Err(e) => return Err(e),
                    }
                }
            }
            Action::WaitBits(n) => advance(tb, traffic, *n)?,
            Action::WaitIrqOrTimeout { timeout_bits } => {
                let end = tb.bits() + timeout_bits;
                while tb.pins().irq_n && tb.bits() < end {
                    fire_traffic(tb, traffic);
                    tb.run_bits(1)?;
                }
            }
            Action::Drain { max, read } => {
                for _ in 0..*max {
                    if tb.read(2)? & diagnose::sr::RBS == 0 {
                        break;
                    }
                    if *read {
                        let f = read_rx_message(tb, st.mode)?;
                        delivered.push((tb.bits(), f));
                    }
                    tb.write(1, 0x04)?;
                }
            }
            Action::Transmit { frame, command, timeout_bits } => transmit_when_free(tb, traffic, frame, *command, *timeout_bits, st.mode)?,
        }
        if tb.bits() > max_bits {
            return Err(TbError::Timeout { what: format!("the scenario's steps (step {})", st.n), bits: max_bits });
        }
    }
    Ok(())
}

/// Reads the message at the head of the RX FIFO through the receive
/// window (PeliCAN 16.., BasicCAN 20..). A frame the window cannot hold
/// (an identifier out of range) is impossible by construction of the
/// fields; its bytes are masked into range.
fn read_rx_message(tb: &mut Testbench, mode: Mode) -> Result<can_proto::CanFrame, TbError> {
    let (id, ext, rtr, dlc, data_at) = if mode == Mode::PeliCan {
        let fi = tb.read(16)?;
        let ext = fi & 0x80 != 0;
        if ext {
            let b: Vec<u8> = (17..21).map(|a| tb.read(a)).collect::<Result<_, _>>()?;
            let id = (b[0] as u32) << 21 | (b[1] as u32) << 13 | (b[2] as u32) << 5 | (b[3] as u32) >> 3;
            (id, true, fi & 0x40 != 0, fi & 0x0F, 21u8)
        } else {
            let b: Vec<u8> = (17..19).map(|a| tb.read(a)).collect::<Result<_, _>>()?;
            ((b[0] as u32) << 3 | (b[1] as u32) >> 5, false, fi & 0x40 != 0, fi & 0x0F, 19u8)
        }
    } else {
        let b0 = tb.read(20)?;
        let b1 = tb.read(21)?;
        ((b0 as u32) << 3 | (b1 as u32) >> 5, false, b1 & 0x10 != 0, b1 & 0x0F, 22u8)
    };
    let n = if rtr { 0 } else { dlc.min(8) };
    let data: Vec<u8> = (0..n).map(|i| tb.read(data_at + i)).collect::<Result<_, _>>()?;
    let ident = if ext { can_proto::CanFrame::ext_id(id & 0x1FFF_FFFF) } else { can_proto::CanFrame::std_id((id & 0x7FF) as u16) };
    Ok(can_proto::CanFrame::with_dlc(ident.expect("masked into range"), rtr, dlc, &data).expect("data length follows the DLC"))
}

/// The `transmit` step: polls SR once a bit until TBS = 1; a node that is
/// bus-off or in reset mode (MOD.RM / CR.RR, set by bus-off too) does not
/// transmit. Before writing the buffer the bus runs two more bit times, so
/// a reference whose TBS rises a few clocks after the DUT's (the status
/// latency the comparator tolerates) has released the buffer too.
fn transmit_when_free(
    tb: &mut Testbench,
    traffic: &mut Vec<(u64, usize, can_proto::CanFrame)>,
    frame: &can_proto::CanFrame,
    command: u8,
    timeout_bits: u64,
    mode: Mode,
) -> Result<(), TbError> {
    let start = tb.bits();
    loop {
        let sr = tb.read(2)?;
        if sr & diagnose::sr::BS != 0 {
            return Ok(());
        }
        if sr & diagnose::sr::TBS != 0 {
            break;
        }
        if tb.bits() - start >= timeout_bits {
            return Ok(());
        }
        advance(tb, traffic, 1)?;
    }
    advance(tb, traffic, 2)?;
    if tb.read(0)? & 0x01 != 0 {
        return Ok(());
    }
    for (addr, value) in crate::tx_buffer_bytes(frame, mode) {
        tb.write(addr, value)?;
    }
    tb.write(1, command)?;
    Ok(())
}

/// The accesses `(write, addr, data)` of block `b`, from its first step on.
fn block_accesses(steps: &[crate::Step], b: usize) -> Vec<(bool, u8, u8)> {
    steps
        .iter()
        .take_while(|st| st.block == Some(b))
        .filter_map(|st| match &st.action {
            Action::Write { addr, value, .. } => Some((true, *addr, *value)),
            Action::Read { addr, .. } => Some((false, *addr, 0)),
            _ => None,
        })
        .collect()
}

/// Requests transmission on model nodes whose time has come. A frame whose
/// node still holds an earlier one (TX buffer locked) waits for it, so
/// back-to-back frames (a replayed log) are sent in order, none dropped.
fn fire_traffic(tb: &mut Testbench, traffic: &mut Vec<(u64, usize, can_proto::CanFrame)>) {
    let now = tb.bits();
    traffic.retain(|(at, node, frame)| *at > now || sja1000::host::transmit(tb.bus_mut().node_mut(*node), frame, 0x01).is_err());
}

fn advance(tb: &mut Testbench, traffic: &mut Vec<(u64, usize, can_proto::CanFrame)>, n: u64) -> Result<(), TbError> {
    let end = tb.bits() + n;
    while tb.bits() < end {
        fire_traffic(tb, traffic);
        let next = traffic.iter().map(|t| t.0).min().unwrap_or(u64::MAX).max(tb.bits() + 1);
        tb.run_bits(next.min(end) - tb.bits())?;
    }
    Ok(())
}

fn advance_until(
    tb: &mut Testbench,
    traffic: &mut Vec<(u64, usize, can_proto::CanFrame)>,
    max_bits: u64,
    what: &str,
    done: impl Fn(&Testbench) -> bool,
) -> Result<(), TbError> {
    let start = tb.bits();
    while !done(tb) {
        if tb.bits() - start >= max_bits {
            return Err(TbError::Timeout { what: what.into(), bits: max_bits });
        }
        fire_traffic(tb, traffic);
        tb.run_bits(1)?;
    }
    Ok(())
}

/// After the steps: if a transmission is still pending, keep the bus running
/// (polling SR every 100 bit times) until it completes or is dropped, or
/// the run length is reached; then it is a stuck transfer.
fn run_out(tb: &mut Testbench, traffic: &mut Vec<(u64, usize, can_proto::CanFrame)>, max_bits: u64, requested_bit: Option<u64>) -> Result<(), TbError> {
    let Some(req) = requested_bit else { return Ok(()) };
    loop {
        let sr = tb.read(2)?;
        if sr & diagnose::sr::TBS != 0 && sr & diagnose::sr::TS == 0 {
            return Ok(());
        }
        if tb.bits() >= max_bits {
            let frames = tb.record().bus_bits.last().and_then(|b| b.frame).unwrap_or(0);
            return Err(TbError::Timeout { what: format!("transmission requested at bit {req} (SR 0x{sr:02X}, {frames} frames)"), bits: max_bits });
        }
        advance(tb, traffic, 100.min(max_bits.saturating_sub(tb.bits())).max(1))?;
    }
}

/// Runs `s` (on `opts.dut` or the scenario's own DUT), diagnoses the run and
/// checks the expected outcome. Never panics on a bad DUT: build failures,
/// host timeouts and divergences all end in a diagnosis.
pub fn run(s: &Scenario, opts: &RunOptions) -> RunOutcome {
    let t0 = Instant::now();
    let overridden;
    let s = match opts.host {
        None => s,
        Some(h) => {
            if let Some(why) = &s.host_fixed {
                return skipped(s, opts, format!("host wiring fixed by the scenario ({}): {why}", s.host));
            }
            overridden = with_host(s, h);
            &overridden
        }
    };
    let dut = opts.dut.clone().unwrap_or_else(|| DutSpec {
        name: match &s.dut {
            DutKind::Rtl => "rtl".into(),
            DutKind::AvalonWrapper => "rtl".into(),
            DutKind::Model => "model".into(),
            DutKind::External { path, .. } => path.display().to_string(),
        },
        kind: s.dut.clone(),
        profile: None,
    });
    let max_bits = opts.max_bits.unwrap_or(s.max_bits);
    let mut received = Vec::new();
    let mut waived_received: Vec<String> = Vec::new();
    let mut report = None;
    // With two or more golden-model nodes, every frame one
    // of them sends must reach the others or be explained (error frame,
    // overrun, off the bus); checked at the end of every run.
    let mut lost = None;
    let mut bus_log = Vec::new();
    let mut delivered = Vec::new();
    let mut steps = Vec::new();
    let mut record = match tb_config(s, &dut.kind, opts).map_err(|e| e.to_string()).and_then(|c| Testbench::new(c).map_err(|e| e.to_string())) {
        Err(e) => {
            let mut r = RunRecord::new(&s.name, &dut.name);
            r.error = Some(e);
            r
        }
        Ok(mut tb) => {
            // A node with its own oscillator (`can_mhz` of the node): clock tolerance.
            for (i, n) in s.nodes.iter().enumerate() {
                tb.bus_mut().set_node_clock(i, n.can_hz.round() as u64, s.can_hz.round() as u64);
            }
            let account = tb.bus().len() > 1;
            if account {
                tb.bus_mut().set_accounting(true);
                tb.bus_mut().set_check_on_drop(false);
            }
            let mut traffic: Vec<(u64, usize, can_proto::CanFrame)> = s
                .nodes
                .iter()
                .enumerate()
                .flat_map(|(i, n)| n.traffic.iter().map(move |f| (f.at_bit, i, f.frame)))
                .collect();
            let mut result = play(&mut tb, s, &mut traffic, max_bits, &mut delivered, &mut steps);
            steps.push((0, tb.now_ps()));
            // Last transmission request (CMR.TR or CMR.SRR) of the program.
            let requested = tb.record().host_ops.iter().rev().find(|o| o.addr == 1 && o.access == diagnose::Access::Write && o.data & 0x11 != 0).map(|_| tb.bits());
            if result.is_ok() {
                result = run_out(&mut tb, &mut traffic, max_bits, requested);
            }
            let mut r = tb.record();
            // Each raw node must have run its whole sequence and seen the
            // wire it expects: one step-0 expectation each.
            for n in tb.raw_nodes() {
                let (seen, passed) = match n.verdict() {
                    Ok(v) => (v, true),
                    Err(e) => (e, false),
                };
                r.expectations.push(Expectation { step: 0, what: format!("raw node {}", n.name), expected: "its sequence run, the wire as expected".into(), seen, passed });
            }
            match result {
                // Everything completed: a stuck transfer noted by a partial
                // SR wait (polled in slices so node traffic can fire) is void.
                Ok(()) => r.stuck = None,
                Err(TbError::Diverged(_)) => {}
                Err(TbError::Timeout { what, bits }) => {
                    if r.stuck.is_none() && what.starts_with("transmission requested") {
                        let sr = r.host_ops.iter().rev().find(|o| o.addr == 2 && o.access == diagnose::Access::Read).map(|o| o.data).unwrap_or(0);
                        r.stuck = Some(diagnose::StuckTransfer {
                            requested_ps: 0,
                            requested_bit: requested.unwrap_or(0),
                            waited_bits: bits,
                            sr,
                            attempts: r.bus_bits.last().and_then(|b| b.frame).unwrap_or(0),
                        });
                    } else if !what.starts_with("transmission requested") {
                        r.expectations.push(Expectation { step: 0, what: format!("wait for {what}"), expected: format!("within {bits} bit times"), seen: "timeout".into(), passed: false });
                    }
                }
                Err(e) => {
                    if r.error.is_none() {
                        r.error = Some(e.to_string());
                    }
                }
            }
            complete_record(&mut r, s, &dut);
            received = received_counts(&mut tb, s);
            if account {
                let names: Vec<String> = s.nodes.iter().enumerate().map(|(i, n)| format!("{i} = {}", n.name)).collect();
                lost = tb.bus().check_accounting().err().map(|e| format!("frame accounting between the model nodes: {e} (nodes {})", names.join(", ")));
            }
            // A received count that is a listed consequence of a deviation
            // waived in this run is waived (and listed in the report).
            if r.error.is_none() {
                for (name, want) in &s.expect.received {
                    let got = received.iter().find(|(n, _)| n == name).map(|(_, c)| *c);
                    if got != Some(*want) && tb.waive_received_consequence(name, *want, got).is_some() {
                        waived_received.push(name.clone());
                    }
                }
            }
            report = Some(tb.waiver_report());
            bus_log = tb.bus_log().to_vec();
            if let Some(vcd) = &opts.vcd {
                // A GTKWave view next to the VCD, on the first divergence.
                let (btr0, btr1) = s.dut_timing();
                let cpb = can_proto::timing::BusTiming::from_btr(btr0, btr1).clocks_per_bit() as f64;
                let bit_ps = (cpb * 1e12 / s.can_hz) as u64;
                let view = cosim::gtkw::save_file(vcd, r.divergence.as_ref().map(|d| d.time_ps), bit_ps, tb.kernel().now_ps());
                if let Err(e) = std::fs::write(cosim::gtkw::path_for(vcd), view) {
                    log::warn!("{}: cannot write the GTKWave view next to {}: {e}", s.name, vcd.display());
                }
            }
            r
        }
    };
    if record.scenario.is_empty() {
        record.scenario = s.name.clone();
    }
    // The diagnosis names the known deviations the DUT showed.
    if let Some(rep) = &report {
        record.waived = rep.deviations.clone();
    }
    let diagnosis = diagnose(&record);
    let mut mismatches = check_expect(s, &diagnosis);
    // Reads still judged behind an expected set-up verdict (see the function).
    let waived: Vec<usize> = report.as_ref().map_or_else(Vec::new, |r| r.waived_expectations.iter().map(|w| w.step).collect());
    mismatches.extend(failed_reads_under_bus_setup_verdict(s.expect.category, diagnosis.category, &record.expectations, &waived));
    mismatches.extend(lost);
    for (name, want) in &s.expect.received {
        let got = received.iter().find(|(n, _)| n == name).map(|(_, c)| *c);
        if record.error.is_none() && got != Some(*want) && !waived_received.contains(name) {
            mismatches.push(format!("received by {name}: expected {want}, got {}", got.map(|g| g.to_string()).unwrap_or_else(|| "none".into())));
        }
    }
    let mut warnings = Vec::new();
    if let Some(rep) = &report {
        if let Some(m) = unwaived_divergence_mismatch(s.expect.category, rep) {
            mismatches.push(m);
        }
        for w in rep.warnings() {
            log::warn!("{}: {w}", s.name);
            warnings.push(w);
        }
    }
    RunOutcome {
        skipped: None,
        passed: mismatches.is_empty(),
        record,
        diagnosis,
        mismatches,
        received,
        dut: dut.name,
        wall: t0.elapsed(),
        waivers: report,
        warnings,
        bus_log,
        delivered,
        steps,
    }
}

/// Failed step expectations that count although the diagnosis names the
/// category the scenario expects, when that category is a set-up one: a bus
/// set-up (BitTimingMismatch, NoAcknowledge), a board wiring the model shares
/// (RxNotFollowingTx: rx tied, as in the DE2 thesis), or a program the DUT and
/// the model both obey (ConfigWriteOutsideReset, TxBufferWriteWhileLocked,
/// AddressModeConfusion, as in tb/registers/*.toml). There the DUT, its host
/// and the model agree, so a wrong read is the scenario's finding, not a
/// consequence; without this it hid behind the expected category. Left out:
/// a host-bus violation or timeout (the reads themselves are suspect) and the
/// categories that are themselves the finding (DutDeviatesFromModel, ...).
/// Expectations a waiver took (`waived_steps`: a waived read, or a listed
/// consequence) are the waiver's, reported with it. For other categories the
/// diagnosis itself is the finding and `check_expect` judges it.
fn failed_reads_under_bus_setup_verdict(
    expected: Option<diagnose::Category>,
    diagnosed: diagnose::Category,
    expectations: &[Expectation],
    waived_steps: &[usize],
) -> Vec<String> {
    if !reads_trusted_under(diagnosed) || expected != Some(diagnosed) {
        return Vec::new();
    }
    expectations
        .iter()
        .filter(|e| !e.passed && !waived_steps.contains(&e.step))
        .map(|e| format!("step {}: {} expected {}, seen {}", e.step, e.what, e.expected, e.seen))
        .collect()
}

/// The set-up verdicts under which a failed read still counts (see
/// [`failed_reads_under_bus_setup_verdict`]).
fn reads_trusted_under(c: diagnose::Category) -> bool {
    use diagnose::Category as C;
    matches!(
        c,
        C::BitTimingMismatch | C::NoAcknowledge | C::RxNotFollowingTx | C::ConfigWriteOutsideReset | C::TxBufferWriteWhileLocked | C::AddressModeConfusion
    )
}

/// The comparator's mode for a scenario expecting `expected`: collect
/// whenever a divergence is the expected symptom and the reads are still
/// judged under that verdict (ConfigWriteOutsideReset,
/// TxBufferWriteWhileLocked, AddressModeConfusion). Stopping at the first
/// divergence there ended the run before the reads after it were judged,
/// while the diagnosis stayed the expected one: a DUT reading a wrong value
/// there passed (a false pass of `run`, `regress` and `mutate` without
/// `--collect`). Elsewhere stopping loses nothing: for `Pass` or a bus-level
/// verdict the divergence itself fails the run; under a host-bus verdict or
/// `DutDeviatesFromModel` the reads are not judged.
pub fn collect_mode(expected: Option<diagnose::Category>, asked: waivers::CollectMode) -> waivers::CollectMode {
    match expected {
        Some(c) if divergence_is_the_symptom(c) && reads_trusted_under(c) => waivers::CollectMode::Collect,
        _ => asked,
    }
}

/// The outcome of a scenario not run (host override on a fixed host wiring).
fn skipped(s: &Scenario, opts: &RunOptions, why: String) -> RunOutcome {
    let dut = opts.dut.as_ref().map(|d| d.name.clone()).unwrap_or_else(|| "rtl".into());
    let record = RunRecord::new(&s.name, &dut);
    let diagnosis = diagnose(&record);
    RunOutcome {
        record,
        diagnosis,
        passed: true,
        mismatches: Vec::new(),
        received: Vec::new(),
        dut,
        wall: Duration::ZERO,
        waivers: None,
        warnings: Vec::new(),
        skipped: Some(why),
        bus_log: Vec::new(),
        delivered: Vec::new(),
        steps: Vec::new(),
    }
}

/// Scenario facts the test bench cannot know: node timings and listen-only,
/// self test from the program, the TEC trace per attempt.
fn complete_record(r: &mut RunRecord, s: &Scenario, dut: &DutSpec) {
    r.dut = dut.name.clone();
    r.wiring.nodes = s
        .nodes
        .iter()
        .map(|n| diagnose::BusNode {
            name: n.name.clone(),
            timing: diagnose::Timing { can_clock_hz: n.can_hz, host_clock_hz: 0.0, btr0: n.btr0, btr1: n.btr1 },
            acknowledges: !n.listen_only,
        })
        .collect();
    r.timing.can_clock_hz = s.can_hz;
    for st in &s.steps {
        if let Action::Write { addr: 0, value, .. } = st.action
            && st.mode == Mode::PeliCan
        {
            r.wiring.self_test = value & 0x04 != 0;
            r.wiring.listen_only = value & 0x02 != 0;
        }
    }
    // Writes that reach nothing in operating mode (configuration registers)
    // are named after the register the address holds in reset mode.
    for op in r.host_ops.iter_mut().filter(|o| o.reg.is_none()) {
        let mode = if op.mode == diagnose::CanMode::PeliCan { Mode::PeliCan } else { Mode::BasicCan };
        let write = op.access == diagnose::Access::Write;
        op.reg = crate::register_name(mode, true, write, op.addr).or_else(|| crate::register_name(mode, false, write, op.addr));
    }
    mark_intended(r, s);
    r.tec_trace = tec_trace_from_events(r, Side::Model);
    if dut.kind == DutKind::Model {
        let dut_side: Vec<TecStep> = r.tec_trace.iter().map(|t| TecStep { node: Side::Dut, ..*t }).collect();
        r.tec_trace.extend(dut_side);
    }
    if r.final_dut.is_none()
        && let Some(sr) = r.host_ops.iter().rev().find(|o| o.addr == 2 && o.access == diagnose::Access::Read && o.error.is_none()).map(|o| o.data)
    {
        // SR as the DUT last reported it; counters are the model's (no TEC
        // register in BasicCAN), valid while DUT and model agree: marked so.
        let (tec, rec) = r.final_model.map(|m| (m.tec, m.rec)).unwrap_or((0, 0));
        r.final_dut = Some(FinalRegs { sr, ir: 0, tec, rec, ecc: None, alc: None, counters_from_model: true });
    }
}

/// Base of a register name: `TXDATA+1`, `TXDATA[1]` -> `TXDATA`.
fn base_name(n: &str) -> &str {
    n.split(['+', '[']).next().unwrap_or(n).trim()
}

/// Marks host ops whose address reaches another register than the name the
/// scenario used (address confusion between the BasicCAN and PeliCAN maps):
/// the named steps are matched to the host ops in order.
fn mark_intended(r: &mut RunRecord, s: &Scenario) {
    let named: Vec<(u8, bool, &str)> = s
        .steps
        .iter()
        .filter_map(|st| match &st.action {
            Action::Write { addr, name: Some(n), .. } => Some((*addr, true, n.as_str())),
            Action::Read { addr, name: Some(n), .. } => Some((*addr, false, n.as_str())),
            Action::Write { addr, name: None, .. } => Some((*addr, true, "")),
            Action::Read { addr, name: None, .. } => Some((*addr, false, "")),
            _ => None,
        })
        .collect();
    let mut next = 0;
    for op in r.host_ops.iter_mut() {
        let Some(&(addr, write, name)) = named.get(next) else { break };
        if op.addr != addr || (op.access == diagnose::Access::Write) != write {
            continue;
        }
        next += 1;
        if name.is_empty() {
            continue;
        }
        let differs = op.reg.as_deref().is_none_or(|g| !base_name(g).eq_ignore_ascii_case(base_name(name)));
        if differs {
            op.intended = Some(name.to_string());
        }
    }
}

/// Frames each model node received (drained from its RX FIFO at the end).
fn received_counts(tb: &mut Testbench, s: &Scenario) -> Vec<(String, u32)> {
    (0..s.nodes.len()).map(|i| (s.nodes[i].name.clone(), count_received(tb, i))).collect()
}

fn count_received(tb: &mut Testbench, node: usize) -> u32 {
    let mut n = 0;
    while sja1000::host::receive(tb.bus_mut().node_mut(node)).is_some() {
        n += 1;
        if n > 1000 {
            break;
        }
    }
    n
}

/// Expected categories whose point is that the DUT departs from the golden
/// model because of how it is driven (a host-bus violation, a program
/// error the host makes): there an unwaived divergence is the expected
/// symptom, and the diagnosis judges the run. A wiring fault (rx that does
/// not follow tx) or a transfer stuck for a bus-level reason is not one:
/// the reference is clocked with the DUT's own rx, so a correct core agrees
/// with it bit for bit all the way to bus-off, and a divergence there is
/// the core's.
pub fn divergence_is_the_symptom(c: diagnose::Category) -> bool {
    use diagnose::Category as C;
    matches!(
        c,
        C::HostBusViolation
            | C::HostBusTimeout
            | C::AddressModeConfusion
            | C::ConfigWriteOutsideReset
            | C::TxBufferWriteWhileLocked
            | C::DutDeviatesFromModel
    )
}

/// The mismatch an unwaived divergence adds to a run's verdict, if any.
/// A scenario expecting `Pass` or a bus-level outcome that DUT and model
/// share (e.g. `NoAcknowledge`: a lone node; both see the ACK errors) must
/// not pass with an unwaived difference: the category alone would be a
/// false pass (pelican-self-test-abort on the opencores core would
/// "pass" with 44 unwaived divergences).
pub fn unwaived_divergence_mismatch(expected: Option<diagnose::Category>, rep: &waivers::WaiverReport) -> Option<String> {
    let want = expected.unwrap_or(diagnose::Category::Pass);
    (!rep.passed() && !divergence_is_the_symptom(want))
        .then(|| format!("{} unwaived divergence(s) from the golden model", rep.failures.len()))
}

/// Compares the diagnosis with the scenario's `[expect]`.
pub fn check_expect(s: &Scenario, d: &Diagnosis) -> Vec<String> {
    let e = &s.expect;
    let mut m = Vec::new();
    let want = e.category.unwrap_or(diagnose::Category::Pass);
    if d.category != want {
        m.push(format!("category: expected {want}, diagnosed {}", d.category));
    }
    let f = &d.figures;
    let mut num = |what: &str, want: Option<u64>, got: Option<u64>| {
        if let Some(w) = want
            && got != Some(w)
        {
            m.push(format!("{what}: expected {w}, got {}", got.map(|g| g.to_string()).unwrap_or_else(|| "none".into())));
        }
    };
    num("first_attempt_tec", e.first_attempt_tec.map(u64::from), f.first_attempt_tec.map(u64::from));
    num("tec", e.tec.map(u64::from), f.tec.map(u64::from));
    num("sr", e.sr.map(u64::from), f.sr.map(u64::from));
    num("attempts", e.attempts.map(u64::from), f.attempts.map(u64::from));
    num("bus_off_attempt", e.bus_off_attempt.map(u64::from), f.bus_off_attempt.map(u64::from));
    if let Some(field) = e.field
        && f.field != Some(field)
    {
        m.push(format!("field: expected {field:?}, got {:?}", f.field));
    }
    m
}


#[cfg(test)]
mod judge_tests {
    use super::{failed_reads_under_bus_setup_verdict, unwaived_divergence_mismatch};
    use diagnose::{Category, Divergence, DivergenceKind};
    use waivers::WaiverReport;

    fn report(failures: usize) -> WaiverReport {
        WaiverReport {
            failures: vec![Divergence { kind: DivergenceKind::RegisterRead, ..Default::default() }; failures],
            ..Default::default()
        }
    }

    #[test]
    fn an_expected_no_acknowledge_does_not_pass_with_an_unwaived_divergence() {
        // Before: only an expected Pass was failed by the report, so a
        // NoAcknowledge scenario passed whatever the comparator found.
        let m = unwaived_divergence_mismatch(Some(Category::NoAcknowledge), &report(3));
        assert_eq!(m.as_deref(), Some("3 unwaived divergence(s) from the golden model"));
        assert!(unwaived_divergence_mismatch(None, &report(1)).is_some());
        assert!(unwaived_divergence_mismatch(Some(Category::BitTimingMismatch), &report(1)).is_some());
        // Nothing unwaived: nothing to add.
        assert_eq!(unwaived_divergence_mismatch(Some(Category::NoAcknowledge), &report(0)), None);
    }

    #[test]
    fn a_host_caused_failure_category_is_judged_by_its_diagnosis() {
        // There the divergence is the expected symptom (de2-avalon-begintransfer).
        assert_eq!(unwaived_divergence_mismatch(Some(Category::HostBusViolation), &report(2)), None);
    }

    #[test]
    fn a_wiring_fault_scenario_does_not_pass_with_an_unwaived_divergence() {
        // de2-thesis: the reference takes the DUT's own rx, so a correct core
        // agrees with it to bus-off; a difference there is the core's (the
        // opencores core's SR at bus-off passed unnoticed before).
        assert!(unwaived_divergence_mismatch(Some(Category::RxNotFollowingTx), &report(1)).is_some());
        assert!(unwaived_divergence_mismatch(Some(Category::StuckTransfer), &report(1)).is_some());
        assert_eq!(unwaived_divergence_mismatch(Some(Category::RxNotFollowingTx), &report(0)), None);
    }

    fn expectation(step: usize, passed: bool) -> diagnose::Expectation {
        let seen = if passed { "0x10" } else { "0x08" };
        diagnose::Expectation { step, what: "TXERR & 0xFF".into(), expected: "0x10 (mask 0xFF)".into(), seen: seen.into(), passed }
    }

    #[test]
    fn a_failed_read_under_an_expected_no_acknowledge_verdict_fails_the_scenario() {
        // pelican-self-test-abort: the verdict NoAcknowledge is the expected
        // one, yet TXERR read 8 where the scenario wants 16: that must count.
        let reads = [expectation(53, true), expectation(55, false)];
        let m = failed_reads_under_bus_setup_verdict(Some(Category::NoAcknowledge), Category::NoAcknowledge, &reads, &[]);
        assert_eq!(m, vec!["step 55: TXERR & 0xFF expected 0x10 (mask 0xFF), seen 0x08".to_string()]);
        // The same under an expected BitTimingMismatch.
        let m = failed_reads_under_bus_setup_verdict(Some(Category::BitTimingMismatch), Category::BitTimingMismatch, &reads, &[]);
        assert_eq!(m.len(), 1);
        // And under the thesis's wiring fault (rx tied, shared by the model):
        // a wrong SR read passed there before (found by a coverage scenario).
        let m = failed_reads_under_bus_setup_verdict(Some(Category::RxNotFollowingTx), Category::RxNotFollowingTx, &reads, &[]);
        assert_eq!(m.len(), 1);
        let m = failed_reads_under_bus_setup_verdict(Some(Category::AddressModeConfusion), Category::AddressModeConfusion, &reads, &[]);
        assert_eq!(m.len(), 1);
    }

    #[test]
    fn a_failed_read_a_waiver_took_does_not_fail_the_scenario_but_others_still_do() {
        let reads = [expectation(53, false), expectation(54, false), expectation(55, false)];
        let m = failed_reads_under_bus_setup_verdict(Some(Category::NoAcknowledge), Category::NoAcknowledge, &reads, &[53, 55]);
        assert_eq!(m, vec!["step 54: TXERR & 0xFF expected 0x10 (mask 0xFF), seen 0x08".to_string()]);
        let all = failed_reads_under_bus_setup_verdict(Some(Category::NoAcknowledge), Category::NoAcknowledge, &reads, &[53, 54, 55]);
        assert!(all.is_empty(), "{all:?}");
    }

    #[test]
    fn failed_reads_are_left_to_the_diagnosis_outside_an_expected_bus_setup_verdict() {
        let reads = [expectation(55, false)];
        // Another verdict than the expected one: check_expect reports that mismatch.
        assert!(failed_reads_under_bus_setup_verdict(Some(Category::NoAcknowledge), Category::BitTimingMismatch, &reads, &[]).is_empty());
        // A diagnosis category that is itself the finding (ExpectationFailed and the like).
        assert!(failed_reads_under_bus_setup_verdict(Some(Category::ExpectationFailed), Category::ExpectationFailed, &reads, &[]).is_empty());
        // A broken host bus: its reads are not evidence.
        assert!(failed_reads_under_bus_setup_verdict(Some(Category::HostBusViolation), Category::HostBusViolation, &reads, &[]).is_empty());
    }
}
