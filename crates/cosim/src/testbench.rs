//! The test bench the scenario runner drives: one DUT and one of each
//! agent ([`crate::agents`]): the host agent (BFM, monitors, reset), the
//! bus agent (model nodes, faults, rx wiring), the reference agent (the
//! lockstep model and the DUT's declared timing), the comparator agent
//! (checkers, waivers, resync) and the observer (bit clock, decoder, VCD,
//! run record). `Testbench` builds them, wires them to the DUT and steps
//! time; a host access (`op`) is the one sequence that runs through three
//! of them and lives here.
//!
//! Order of work at each instant (see [`Kernel::advance`]):
//! 1. on a CAN rising edge, the bus level is the wired-AND of the DUT's
//!    `tx_o` and every model node's tx *before* the edge; model nodes are
//!    clocked with it and the DUT's `rx_i` is set from it (or tied);
//! 2. the DUT is evaluated with the new clock levels;
//! 3. on a host rising edge, the BFM sees the DUT's outputs after the edge
//!    (the `bfm` stepping contract) and its next pins are applied;
//! 4. on a CAN rising edge, the reference is clocked with the DUT's rx, the
//!    bit clock finds sample points, and the comparator compares.

use std::path::PathBuf;

use bfm::{BfmError, OpHandle, OpResult};
use can_proto::RECESSIVE;
use diagnose::{
    Access as RecAccess, Expectation, FinalRegs, HostOp, RunRecord, RxWiring,
};
use sja1000::{Bus, FaultInjector};

use crate::agents::bus::BusAgent;
use crate::agents::host::{Again, HostAgent, HostSetup};
pub use crate::agents::host::{AvalonWiring, HostBfm, i8051_timing_for_rtl};
pub use crate::agents::bus::NodeConfig;
use crate::agents::observer::Observer;
use crate::agents::reference::{DutKind, HostKind, RefTiming, ReferenceAgent};
pub use crate::agents::reference::ReferenceChoice;
use crate::compare::{Comparator, ComparatorAgent, CompareConfig, IR_ADDR, Now, RefView, SR_ADDR, Stamp};
use crate::dut::{AnyDut, CanPins, EchoModel, HostPort, VerilatedDut};
use crate::kernel::{Kernel, Tick};
use crate::model::{AnyRef, ModelDut};
use crate::profile::{PhaseOrigin, PortMap, Profile};
use crate::wave::{Wave, WaveSample};
pub use crate::dut::{CustomDut, DutChoice};
pub use crate::error::TbError;
use waivers::{CollectMode, DutInfo, Session, WaiverReport, WaiverSet};

/// Everything a test bench is built from.
pub struct TbConfig {
    /// Scenario name (for the record).
    pub scenario: String,
    /// The DUT.
    pub dut: DutChoice,
    /// The host BFM.
    pub host: HostBfm,
    /// Host clock (`wb_clk_i`), Hz.
    pub host_hz: u64,
    /// CAN clock (`clk_i`), Hz.
    pub can_hz: u64,
    /// Host cycles `wb_rst_i` is held high at start.
    pub reset_cycles: u64,
    /// Bit timing the bit clock starts with (updated by host writes to BTR0/BTR1).
    pub btr0: u8,
    /// See `btr0`.
    pub btr1: u8,
    /// Where the DUT's `rx_i` comes from.
    pub rx: RxWiring,
    /// The DUT's `tx_o` drives the bus.
    pub tx_on_bus: bool,
    /// Golden-model nodes on the bus.
    pub nodes: Vec<NodeConfig>,
    /// Faults on what the model nodes receive (the `sja1000` injectors,
    /// `Target::Node(i)` = `nodes[i]`).
    pub faults: Vec<Box<dyn FaultInjector>>,
    /// Faults on what the DUT receives (it is node index `nodes.len()` for
    /// `Target::Node`). Their `BusContext` comes from the bench's bit clock
    /// and decoder (frame = SOFs seen, frame_bit = bits since that SOF).
    /// A fault every node receives belongs in `faults` instead when there
    /// are model nodes, targeted at `nodes.len()`: the bus then applies it
    /// to the DUT in the nodes' own context (the same wire bit).
    pub dut_rx_faults: Vec<Box<dyn FaultInjector>>,
    /// The faults every node receives (a scenario's `target = "bus"`), once
    /// more for the bench's field decoder (node index `nodes.len() + 1`),
    /// so the fields it names follow what the nodes see, not the wire
    /// before the fault. Frames stay counted on the wire. With model nodes
    /// they belong in `faults` instead, targeted at `nodes.len() + 1`.
    pub bus_faults_seen: Vec<Box<dyn FaultInjector>>,
    /// Bit-level senders on the wire (`agents::raw`), on the bench's bit clock.
    pub raw_nodes: Vec<crate::agents::raw::RawNode>,
    /// Lockstep reference and tolerances.
    pub lockstep: Option<(ReferenceChoice, CompareConfig)>,
    /// Our VCD (ports, bus, model, fields).
    pub vcd: Option<PathBuf>,
    /// Verilator's VCD of the DUT's internals.
    pub dut_trace: Option<PathBuf>,
    /// Bus bits kept in the record.
    pub keep_bits: usize,
    /// Per-operation timeout, host cycles.
    pub op_timeout_cycles: u64,
    /// Ack limit of the Wishbone monitor, host cycles.
    pub monitor_ack_timeout: u64,
    /// Known deviations of the DUT (`--waivers`); empty: none accepted.
    pub waivers: WaiverSet,
    /// The DUT's revision, matched against the waivers' revision ranges.
    pub dut_revision: Option<String>,
    /// Unwaived divergences stop the run or are collected
    /// (`--stop-at-first` / `--collect`).
    pub collect: CollectMode,
    /// The DUT's declared freedoms (`tb/profiles/*.toml`): when a host
    /// access takes effect, the bit timing's phase origin (given to the
    /// reference), the port map; None: our RTL's tops get `rtl.toml`
    /// implicitly, the golden model as DUT its launch-edge timing, any
    /// other DUT the ack (unknown). The tolerances in it are the caller's
    /// to put into `lockstep`.
    pub profile: Option<Profile>,
    /// The golden model as DUT (`DutChoice::Model`) starts its bit timing
    /// from here: it stands in for a core with either freedom.
    pub model_dut_phase_origin: PhaseOrigin,
    /// Build the DUT with Verilator's coverage and write its counters here
    /// when the bench is dropped ([`crate::coverage`]); a Verilated DUT only.
    pub coverage_dat: Option<PathBuf>,
}

impl Default for TbConfig {
    fn default() -> Self {
        TbConfig {
            scenario: "unnamed".into(),
            dut: DutChoice::Rtl,
            host: HostBfm::Wishbone,
            host_hz: 50_000_000,
            can_hz: 24_000_000,
            reset_cycles: 8,
            btr0: 0x41,
            btr1: 0x25,
            rx: RxWiring::Bus,
            tx_on_bus: true,
            nodes: Vec::new(),
            faults: Vec::new(),
            dut_rx_faults: Vec::new(),
            bus_faults_seen: Vec::new(),
            raw_nodes: Vec::new(),
            lockstep: None,
            vcd: None,
            dut_trace: None,
            keep_bits: 256,
            op_timeout_cycles: 2_000,
            monitor_ack_timeout: 1_000,
            waivers: WaiverSet::empty(),
            dut_revision: None,
            collect: CollectMode::StopAtFirst,
            profile: None,
            model_dut_phase_origin: PhaseOrigin::ResetModeExit,
            coverage_dat: None,
        }
    }
}

/// The test bench.
pub struct Testbench {
    kernel: Kernel,
    dut: AnyDut,
    dut_name: String,
    /// Host BFM, its wiring and monitors, the reset sequence.
    host: HostAgent,
    /// The DUT's CAN-side pins as of its last eval (read once per tick).
    dut_pins: crate::dut::CanPins,
    /// Levels of a Verilated DUT's clkout_o at its instants since the last
    /// CAN rising edge (bit 0 low, bit 1 high): the CLKOUT check with CD = 7.
    clkout_levels: u8,
    /// The reference model and the DUT's declared timing.
    reference: ReferenceAgent,
    /// The checkers and the waiver/resync policy.
    checks: ComparatorAgent,
    /// Wired-AND bus, model nodes, faults, the DUT's rx wiring.
    bus: BusAgent,
    can_clocks: u64,
    tracing: bool,
    /// Bit clock, decoder, VCD, run record, bus log.
    obs: Observer,
    /// Batches allowed (see [`Testbench::set_batching`]).
    batching: bool,
    /// Buffers of `run_batch` (clock levels in, pins out), kept between calls.
    batch_levels: Vec<u8>,
    batch_out: Vec<u8>,
    /// Times of a batch's instants.
    batch_times: Vec<u64>,
    /// CAN clock count after which the reference took the last host access.
    last_access_clock: Option<u64>,

    /// Accesses of the Wishbone block cycle under way, queued on the BFM
    /// and not yet done: `(write, addr, data, handle)` (see `begin_block`).
    block: std::collections::VecDeque<(bool, u8, u8, OpHandle)>,
}

/// Instants per batch (see `Testbench::run_batch`).
const BATCH: usize = 512;

/// A quiet stretch of `run_batch` (see `Testbench::quiet_clocks_ahead`).
#[derive(Clone, Copy)]
struct Stretch {
    /// CAN edges left in it.
    left: u32,
    /// The reference's view it holds for.
    view: RefView,
    /// The DUT's pins it holds for (tx, irq, bus-off: `out`)...
    pins: CanPins,
    /// ...as batch out bits 0..2.
    out: u8,
    /// The bus level and the DUT's rx it holds for.
    level: bool,
    rx: bool,
    /// The reference's CLKOUT setting over it.
    clkout: crate::clkout::ClkoutSetting,
}

impl Default for Stretch {
    /// No stretch.
    fn default() -> Self {
        Stretch {
            left: 0,
            view: RefView::default(),
            pins: CanPins::default(),
            out: 0,
            level: true,
            rx: true,
            clkout: crate::clkout::ClkoutSetting::Unchecked,
        }
    }
}

impl Testbench {
    /// Builds the DUT, the BFM, the bus and the reference, and runs the
    /// reset sequence.
    pub fn new(mut cfg: TbConfig) -> Result<Testbench, TbError> {
        // A plain register port has one clock, the core's: the host runs
        // on the CAN clock.
        if matches!(cfg.host, HostBfm::Regport(_)) && cfg.host_hz != cfg.can_hz {
            cfg.host_hz = cfg.can_hz;
        }
        let kernel = Kernel::new(cfg.host_hz, cfg.can_hz)?;
        let trace = cfg.dut_trace.is_some();
        // Our RTL's tops (all through rtl/can_wb_cdc.v) carry rtl.toml on
        // the hosts they are made for; can_top's one-cycle ack under a PIO
        // master (which holds the request and re-triggers it) keeps the
        // ack timing, as before profiles.
        let profile = cfg.profile.clone().or_else(|| match (&cfg.dut, cfg.host) {
            (DutChoice::Rtl, HostBfm::Wishbone | HostBfm::Avalon { .. } | HostBfm::Axi4Lite(_) | HostBfm::Apb(_) | HostBfm::Regport(_)) => Some(Profile::rtl()),
            (DutChoice::RtlAvalon, _) => Some(Profile::rtl()),
            (DutChoice::Bundled(t), HostBfm::Pio(_)) if t == "can_top_pio" => Some(Profile::rtl()),
            _ => None,
        });
        let default_ports = PortMap::default();
        let ports = profile.as_ref().map_or(&default_ports, |p| &p.ports);
        // A DUT driven over the 8051 bus binds that port list.
        let i8051 = matches!(cfg.host, HostBfm::I8051(_));
        let wb_or_8051 = match cfg.host {
            HostBfm::I8051(_) => HostPort::I8051,
            HostBfm::Axi4Lite(_) => HostPort::Axi4Lite,
            HostBfm::Apb(_) => HostPort::Apb,
            HostBfm::Motorola(_) => HostPort::Motorola,
            HostBfm::Regport(_) => HostPort::Regport,
            _ => HostPort::Wishbone,
        };
        // Our RTL on AXI4-Lite or APB is its wrapper of that bus.
        let rtl_wrapper = match cfg.host {
            HostBfm::Axi4Lite(_) => Some("can_axi4lite"),
            HostBfm::Apb(_) => Some("can_apb"),
            HostBfm::Motorola(_) => Some("can_top_mcu"),
            HostBfm::Regport(_) => Some("can_regport"),
            _ => None,
        };
        let covered = cfg.coverage_dat.as_deref().map(|dat| crate::coverage::covered_dut(&cfg.dut, wb_or_8051, ports, trace, dat)).transpose()?;
        let mut dut = if let Some(d) = covered { AnyDut::Verilated(d) } else { match &cfg.dut {
            DutChoice::Rtl if i8051 => AnyDut::Verilated(VerilatedDut::bundled(
                "can_top_8051",
                HostPort::I8051,
                trace,
            )?),
            DutChoice::Rtl if rtl_wrapper.is_some() => AnyDut::Verilated(VerilatedDut::bundled(
                rtl_wrapper.unwrap_or_default(),
                wb_or_8051,
                trace,
            )?),
            DutChoice::Rtl => {
                AnyDut::Verilated(VerilatedDut::bundled("can_top", HostPort::Wishbone, trace)?)
            }
            DutChoice::RtlAvalon => AnyDut::Verilated(VerilatedDut::bundled(
                "can_avalon",
                HostPort::Avalon,
                trace,
            )?),
            DutChoice::Bundled(top) => AnyDut::Verilated(VerilatedDut::with_ports(
                crate::verilated::bundled(top, trace)?,
                wb_or_8051,
                ports,
            )?),
            DutChoice::External(core) => AnyDut::Verilated(VerilatedDut::with_ports(
                crate::verilated::build_external(core)?.instantiate(trace),
                wb_or_8051,
                ports,
            )?),
            DutChoice::Model | DutChoice::Echo if i8051 => {
                return Err(TbError::Config(
                    "the 8051 host drives a DUT with the 8051 port list (can_top_8051 or an external core); the golden model and the echo model have Wishbone only".into(),
                ));
            }
            // A GPIO-polled host needs the level ack (as can_top_pio).
            DutChoice::Model if matches!(cfg.host, HostBfm::Pio(_)) => AnyDut::Other(Box::new(
                ModelDut::with_level_ack().with_phase_origin(cfg.model_dut_phase_origin),
            )),
            DutChoice::Model => AnyDut::Other(Box::new(
                ModelDut::new().with_phase_origin(cfg.model_dut_phase_origin),
            )),
            DutChoice::Echo => AnyDut::Other(Box::new(EchoModel::new())),
            DutChoice::Custom(c) => AnyDut::Other((c.make)()),
        }};
        if let Some(p) = &cfg.dut_trace {
            dut.trace_open(p)?;
        }
        let host = HostAgent::new(
            HostSetup {
                bfm: cfg.host,
                op_timeout_cycles: cfg.op_timeout_cycles,
                monitor_ack_timeout: cfg.monitor_ack_timeout,
                reset_cycles: cfg.reset_cycles,
                profile: profile.as_ref(),
                external: matches!(cfg.dut, DutChoice::External(_)),
            },
            &dut,
        )
        .map_err(TbError::Config)?;
        let bus = BusAgent::new(
            &cfg.nodes,
            cfg.faults.drain(..).collect(),
            cfg.dut_rx_faults.drain(..).collect(),
            cfg.rx,
            cfg.tx_on_bus,
        )
        .with_raw_nodes(std::mem::take(&mut cfg.raw_nodes))
        .with_faults_seen(cfg.bus_faults_seen.drain(..).collect());
        let wave = match &cfg.vcd {
            Some(p) => Some(Wave::create(p)?),
            None => None,
        };
        let dut_name = match &cfg.dut {
            DutChoice::Rtl if i8051 => "rtl (can_top_8051)".to_string(),
            DutChoice::Rtl if rtl_wrapper.is_some() => format!("rtl ({})", rtl_wrapper.unwrap_or_default()),
            DutChoice::Rtl => "rtl".to_string(),
            DutChoice::RtlAvalon => "rtl (can_avalon)".to_string(),
            DutChoice::Bundled(t) => t.clone(),
            // "<profile> (<dir>)": waiver `dut` globs name the profile.
            DutChoice::External(c) => match &cfg.profile {
                Some(p) => format!("{} ({})", p.name, c.dir.display()),
                None => c.dir.display().to_string(),
            },
            DutChoice::Model => "model".to_string(),
            DutChoice::Echo => "echo model".to_string(),
            DutChoice::Custom(c) => c.name.clone(),
        };
        let waivers = Session::new(
            std::mem::take(&mut cfg.waivers),
            // A profile that extends others: waivers for its family apply too.
            match &cfg.profile {
                Some(p) => DutInfo { name: dut_name.clone(), revision: cfg.dut_revision.clone(), family: Vec::new() }
                    .in_family(&p.name, &p.ancestors),
                None => DutInfo { name: dut_name.clone(), revision: cfg.dut_revision.clone(), family: Vec::new() },
            },
            cfg.collect,
        );
        let mut record = RunRecord::new(&cfg.scenario, &dut_name);
        record.host_bus = host.host_bus();
        record.timing = diagnose::Timing {
            can_clock_hz: cfg.can_hz as f64,
            host_clock_hz: cfg.host_hz as f64,
            btr0: cfg.btr0,
            btr1: cfg.btr1,
        };
        record.wiring = diagnose::Wiring {
            rx: cfg.rx,
            tx_on_bus: cfg.tx_on_bus,
            nodes: cfg
                .nodes
                .iter()
                .map(|n| diagnose::BusNode {
                    name: n.name.clone(),
                    timing: record.timing,
                    acknowledges: true,
                })
                .collect(),
            self_test: false,
            listen_only: false,
        };
        // When the reference takes a host access: as the DUT's profile
        // declares it, or as the bench knows our tops.
        let dut_kind = match &cfg.dut {
            DutChoice::Model => DutKind::Model,
            DutChoice::Rtl => DutKind::Rtl,
            DutChoice::External(_) => DutKind::External,
            _ => DutKind::Other,
        };
        let host_kind = match cfg.host {
            HostBfm::Wishbone => HostKind::Wishbone,
            HostBfm::Avalon { wiring: AvalonWiring::Seed000, .. } => HostKind::AvalonSeed000,
            HostBfm::Avalon { .. } => HostKind::Avalon,
            HostBfm::Pio(_) => HostKind::Pio,
            HostBfm::I8051(_) => HostKind::I8051,
            HostBfm::Motorola(_) => HostKind::Motorola,
            HostBfm::Axi4Lite(_) => HostKind::Axi4Lite,
            HostBfm::Apb(_) => HostKind::Apb,
            HostBfm::Regport(_) => HostKind::Regport,
        };
        let reference = ReferenceAgent::new(
            cfg.lockstep.map(|(r, _)| r),
            profile.as_ref(),
            RefTiming::for_dut(dut_kind, host_kind, profile.as_ref()),
        );
        let mut tb = Testbench {
            kernel,
            dut,
            dut_name,
            host,
            dut_pins: crate::dut::CanPins::default(),
            clkout_levels: 0,
            reference,
            checks: ComparatorAgent::new(cfg.lockstep.map(|(_, c)| c), waivers),
            bus,
            can_clocks: 0,
            tracing: trace,
            obs: Observer::new(cfg.btr0, cfg.btr1, record, wave, cfg.keep_bits),
            batching: true,
            batch_levels: Vec::new(),
            batch_out: Vec::new(),
            batch_times: Vec::new(),
            last_access_clock: None,

            block: std::collections::VecDeque::new(),
        };
        tb.host.hold_reset(&mut tb.dut);
        tb.dut.set_rx(RECESSIVE);
        tb.dut_pins = tb.dut.can();
        while tb.host.in_reset() {
            tb.tick();
        }
        Ok(tb)
    }

    /// Lets `run_can_cycles` and `wait_irq` make the instants in which only
    /// the clocks and the DUT's own tx drive its inputs in batches inside
    /// the Verilated model (on by default). The same instants and the same
    /// record either way; off, every instant goes through Rust (to check
    /// that, or to measure the difference).
    pub fn set_batching(&mut self, on: bool) {
        self.batching = on;
    }

    /// The run's bus log so far: frames completed on the bus and the error
    /// frames the DUT's Linux driver would raise (see [`crate::candump`]).
    pub fn bus_log(&self) -> &[crate::candump::LogEntry] {
        self.obs.bus_log()
    }

    /// The DUT's description.
    pub fn dut_name(&self) -> String {
        self.dut.name()
    }

    /// The kernel (time, clocks).
    pub fn kernel(&self) -> &Kernel {
        &self.kernel
    }

    /// The raw nodes on the wire (`TbConfig::raw_nodes`), for their verdicts.
    pub fn raw_nodes(&self) -> &[crate::agents::raw::RawNode] {
        self.bus.raw_nodes()
    }

    /// The golden-model nodes.
    pub fn bus(&self) -> &Bus {
        self.bus.bus()
    }

    /// Mutable access to the model nodes (to queue frames, change config).
    pub fn bus_mut(&mut self) -> &mut Bus {
        self.bus.bus_mut()
    }

    /// The comparator, if lockstep.
    pub fn comparator(&self) -> Option<&Comparator> {
        self.checks.comparator()
    }

    /// The scenario's `received` count of model node `node` missed: waived
    /// only if a waiver hit earlier in this run lists it as a consequence
    /// (`Session::waive_received_consequence`); returns that waiver's id.
    pub fn waive_received_consequence(&mut self, node: &str, want: u32, got: Option<u32>) -> Option<String> {
        let scenario = self.obs.record.scenario.clone();
        self.checks.waivers().waive_received_consequence(&scenario, node, want, got)
    }

    /// Waived divergences, failures and stale waivers so far. In collect
    /// mode the run goes on after a failure: check `passed()` here.
    /// An `adopt-dut-tec`/`-rec` still waiting for a TXERR/RXERR read is
    /// noted: the model has not taken the DUT's counter yet.
    pub fn waiver_report(&self) -> WaiverReport {
        self.checks.waiver_report()
    }

    /// Hands each new divergence to the comparator agent's waiver and
    /// resync policy.
    fn handle_divergences(&mut self) {
        let now = Now {
            t_ps: self.kernel.now_ps(),
            can_hz: self.kernel.can().freq_hz(),
            clocks_per_bit: self.obs.clocks_per_bit(),
        };
        self.checks.handle_divergences(now, &mut self.reference, self.dut_pins.tx, &mut self.obs.record);
    }

    /// Protocol violations seen so far.
    pub fn violations(&self) -> &[diagnose::Violation] {
        &self.obs.record.violations
    }

    /// Bits sampled by the bit clock so far.
    pub fn bits(&self) -> u64 {
        self.obs.bits()
    }

    /// Simulated time so far, in picoseconds (the clock divergences are stamped with).
    pub fn now_ps(&self) -> u64 {
        self.kernel.now_ps()
    }

    /// Host cycles so far.
    pub fn host_cycles(&self) -> u64 {
        self.host.cycles()
    }

    /// CAN clock cycles so far.
    pub fn can_cycles(&self) -> u64 {
        self.can_clocks
    }

    /// The DUT's CAN-side pins now.
    pub fn pins(&self) -> crate::dut::CanPins {
        self.dut_pins
    }

    /// One kernel instant.
    #[inline]
    fn tick(&mut self) {
        let t = self.kernel.advance();
        if t.can_rise {
            let rx = self.can_rise_rx();
            self.dut.set_rx(rx);
        }
        let pins = self
            .dut
            .eval_pins(self.kernel.host().level(), self.kernel.can().level());
        self.host.on_tick(&t, &self.dut);
        self.after_eval(t, pins);
    }

    /// At a CAN rising edge, before the DUT's eval: the bus level and the
    /// DUT's rx from it (the bus agent keeps both for `can_edge`).
    #[inline]
    fn can_rise_rx(&mut self) -> bool {
        let (obs, clock) = (&self.obs, self.can_clocks);
        self.bus.can_rise(self.dut_pins.tx, || obs.bus_context(clock))
    }

    /// The rest of an instant once the DUT was evaluated: its pins `pins`
    /// after the eval, the host edge, the CAN edge, the traces.
    #[inline]
    fn after_eval(&mut self, t: Tick, pins: CanPins) {
        self.dut_pins = pins;
        if matches!(self.dut, AnyDut::Verilated(_)) {
            self.clkout_levels |= 1 << pins.clkout as u8;
        }
        if t.host_rise {
            self.host_edge();
        }
        if t.can_rise {
            self.can_edge(t.t_ps, pins);
        }
        if self.tracing {
            self.dut.trace_dump(t.t_ps);
        }
        if self.obs.waving() {
            self.dump_wave(t.t_ps);
        }
    }

    /// How the DUT's rx is driven if the next instants can run as one
    /// batch in the Verilated model (`Some(None)`: its own tx, looped
    /// back; `Some(Some(level))`: tied), or `None` if they cannot: then
    /// something besides the clocks and its own tx would drive its inputs
    /// (a host access or reset, model nodes or faults on the bus), or an
    /// instant needs the DUT between evals (its VCD or ours).
    fn batch_rx(&self) -> Option<Option<bool>> {
        if !self.batching
            || !matches!(self.dut, AnyDut::Verilated(_))
            || self.host.in_reset()
            || self.tracing
            || self.obs.waving()
            || self.reference.awaiting_dut_sof()
        {
            return None;
        }
        // The master starts nothing and drives idle wires (only `op` queues).
        if !self.host.idle() {
            return None;
        }
        // Nothing but the DUT's own tx on the bus (no nodes, no faults).
        self.bus.loopback_rx()
    }

    /// Makes the next instants, up to the one with the `can_rises`-th CAN
    /// rising edge (at most [`BATCH`]), in one call into the Verilated
    /// model, then replays each through [`Testbench::after_eval`] with the
    /// pins it had: the same instants, in the same order, with the same
    /// DUT outputs as [`Testbench::tick`] would make. The model stops early
    /// after an instant that changed its Wishbone outputs (the host edge
    /// after it sees them) or, with `stop_on_irq`, that shows an interrupt
    /// pending. False (nothing done) when a batch cannot run now.
    fn run_batch(&mut self, can_rises: u64, stop_on_irq: bool) -> Result<bool, TbError> {
        let Some(rx) = self.batch_rx() else {
            return Ok(false);
        };
        if can_rises == 0 {
            return Ok(false);
        }
        // The instants ahead: clock levels (and which clocks rose) for the
        // model, and their times.
        let mut k = self.kernel.clone();
        let mut levels = std::mem::take(&mut self.batch_levels);
        let mut out = std::mem::take(&mut self.batch_out);
        let mut times = std::mem::take(&mut self.batch_times);
        if levels.len() != BATCH {
            levels.resize(BATCH, 0);
            out.resize(BATCH, 0);
            times.resize(BATCH, 0);
        }
        let n = k.plan(&mut levels[..BATCH], &mut times[..BATCH], can_rises);
        let AnyDut::Verilated(d) = &mut self.dut else {
            unreachable!("batch_rx checked the DUT");
        };
        let active_high = d.polarity();
        let made = d
            .run_batch(&levels[..n], &mut out[..n], rx, stop_on_irq)
            .unwrap_or(0);
        let mut result = Ok(made > 0);
        // The master stays idle (only `op` starts anything) and, but for the
        // last instant, the DUT's Wishbone outputs stay as they are now: once
        // the monitor has seen these idle wires, a host edge is a no-op but
        // for its count (see `host_edge`).
        let s0 = self.dut.wb();
        let quiet_wires = !(s0.ack || s0.err || s0.rty);
        let mut quiet = quiet_wires && self.host.monitor_saw(s0);
        // Instants made and replayed: all of them unless a divergence stops the run.
        let mut replayed = made;
        // An instant without a rising edge only changes the pins: `after_eval`
        // (without the traces, see `batch_rx`) for the others.
        let (lv, ot, tm) = (&levels[..made], &out[..made], &times[..made]);
        // The DUT's tx before the first instant (for the others: the
        // instant before's, in `ot`).
        let tx0 = self.dut_pins.tx;
        // Levels of clkout_o since the last CAN edge: those carried in, and
        // the instants from `since` on, gathered only when an edge takes them.
        let (mut carried, mut since) = (self.clkout_levels, 0usize);
        let gather = |from: usize, to: usize| ot[from..to].iter().fold(0u8, |a, &o| a | 1 << (o >> 3 & 1));
        // A quiet stretch (see `quiet_clocks_ahead`).
        let mut ahead = Stretch::default();
        // Only a lockstep run with the golden model has quiet stretches:
        // without one, not even asked.
        let stretches = matches!(self.reference.model, Some(AnyRef::Model(_)));
        let mut i = 0;
        while i < made {
            if ahead.left > 0 {
                let (next, last_rise) = self.quiet_run(lv, ot, i, quiet, &mut ahead);
                if let Some(r) = last_rise {
                    (carried, since) = (0, r + 1);
                }
                i = next;
            }
            let l = lv[i];
            if l & 0b1100 == 0 {
                i += 1;
                continue;
            }
            let o = ot[i];
            let last = i + 1 == made;
            if l & 4 != 0 {
                // `can_rise_rx` without model nodes or faults (see
                // `batch_rx`), with the DUT's tx of the instant before.
                let prev_tx = if i == 0 { tx0 } else { ot[i - 1] & 1 != 0 };
                self.bus.replay_rise(prev_tx, rx);
            }
            if last && let AnyDut::Verilated(d) = &mut self.dut {
                // The host edge of the last instant may see new outputs.
                d.sync_outputs();
            }
            if l & 8 != 0 {
                if quiet && !last {
                    self.host.quiet_edge();
                } else {
                    self.host_edge();
                    quiet = quiet_wires && self.host.monitor_saw(s0);
                    // Not promised anything about a host edge taken in full.
                    ahead.left = 0;
                }
            }
            if l & 4 != 0 {
                let pins = VerilatedDut::batch_pins(o, active_high);
                self.clkout_levels = carried | gather(since, i + 1);
                (carried, since) = (0, i + 1);
                if ahead.left > 0 && o & 7 == ahead.out && self.bus.level() == ahead.level {
                    ahead.left -= 1;
                    if !self.quiet_can_edge(tm[i], pins, &ahead.view) {
                        ahead.left = 0;
                    }
                } else {
                    self.can_edge(tm[i], pins);
                    if stretches {
                        ahead = self.quiet_clocks_ahead(pins);
                        ahead.out = o & 7;
                    }
                }
            }
            if self.checks.stopped()
                && let Err(e) = self.check_stopped()
            {
                result = Err(e);
                replayed = i + 1;
                break;
            }
            i += 1;
        }
        self.clkout_levels = carried | gather(since, replayed);
        if replayed > 0 {
            self.dut_pins = VerilatedDut::batch_pins(out[replayed - 1], active_high);
        }
        if let AnyDut::Verilated(d) = &mut self.dut {
            // For the instants after this batch (the last one may not have been an edge).
            d.sync_outputs();
        }
        // The kernel at the last instant replayed.
        if replayed == n {
            self.kernel = k;
        } else {
            for _ in 0..replayed {
                self.kernel.advance();
            }
        }
        self.batch_levels = levels;
        self.batch_out = out;
        self.batch_times = times;
        result
    }

    fn dump_wave(&mut self, t_ps: u64) {
        let p = self.dut.can();
        let (cyc, stb, we, adr, dat_i, dat_o, ack) = self.host.wave_pins(&self.dut);
        let (model_tx, model_field) = match &self.reference.model {
            Some(r) => (r.pins().tx, r.field()),
            None => (true, None),
        };
        let s = WaveSample {
            host_clk: self.kernel.host().level(),
            can_clk: self.kernel.can().level(),
            rst: self.host.in_reset(),
            cyc,
            stb,
            we,
            adr,
            dat_i,
            dat_o,
            ack,
            rx: self.bus.dut_rx(),
            tx: p.tx,
            irq_n: p.irq_n,
            bus_on: p.bus_on,
            clkout: p.clkout,
            bus: self.bus.level(),
            model_tx,
            model_rx: self.bus.dut_rx(),
            // The observer's bit clock and decoder fill these in.
            sample: false,
            field: None,
            model_field,
        };
        self.obs.dump_wave(t_ps, s);
    }

    /// A host rising edge, after the DUT's eval: the host agent steps; the
    /// reference takes its hardware reset when the DUT's reset ends.
    #[inline]
    fn host_edge(&mut self) {
        let timing = self.reference.declared_timing();
        if self.host.edge(&mut self.dut, timing, &mut self.obs.record.violations)
            && let Some(r) = &mut self.reference.model
        {
            r.hard_reset();
        }
    }

    /// A CAN rising edge, after the DUT's eval: `pins` are its pins now
    /// (`dut_pins`, passed in registers).
    fn can_edge(&mut self, t_ps: u64, pins: CanPins) {
        self.can_clocks += 1;
        self.host.on_can_edge();
        let level = self.bus.level();
        let sample = self.obs.clock(level);
        // A frame held for the DUT's SOF, then everything read from the
        // reference this clock, in one call.
        let view = self.reference.can_edge(self.bus.dut_rx(), pins.tx);
        let bit = self.obs.bits();
        if sample {
            let frames = self.obs.frame();
            self.obs.sample_point(t_ps, level, self.bus.seen_level(), bit, pins, self.bus.dut_rx(), view, !self.checks.stopped());
            if self.obs.frame() != frames {
                // A new frame: a register-read waiver's episode ends with the last one.
                self.checks.waivers().frame_start(t_ps);
            }
            if !pins.tx && self.bus.dut_rx() {
                // The DUT drove dominant and read recessive: an error flag it starts is a new one.
                self.checks.dut_bit_error(bit);
            }
        }
        if view.is_some_and(|v| v.events)
            && let Some(r) = &mut self.reference.model
        {
            self.obs.reference_events(t_ps, bit, r);
        }
        if self.clkout_levels != 0 {
            self.checks.clkout_instants(std::mem::take(&mut self.clkout_levels));
        }
        if let Some(v) = &view {
            let (obs, r) = (&self.obs, &self.reference.model);
            let clkout = || r.as_ref().map_or(crate::clkout::ClkoutSetting::Unchecked, |r| r.clkout_setting());
            if self.checks.can_clock(|| obs.stamp(t_ps, bit, v.field), sample, v, &pins, clkout) {
                self.handle_divergences();
            }
        }
    }

    /// After a CAN edge taken in full (`can_edge`, the DUT's pins `pins`;
    /// work added to `can_edge` goes into `quiet_can_edge` too, or ends the
    /// stretch here):
    /// how many of the next CAN edges, while the DUT's tx, irq and bus-off
    /// pins and the bus level stay as they are now, can take
    /// [`Testbench::quiet_can_edge`], and the reference's view on them.
    /// Only in lockstep with the golden model: on none of them does the
    /// reference do more than count (`ModelRef::counting_clocks`, so its
    /// view stays), none is a sample point of the bench's bit clock
    /// (`Observer::clocks_before_sample`), no frame waits for the DUT's SOF,
    /// and the comparator does no more than its short path with these
    /// inputs (`ComparatorAgent::quiet_ahead`: also while a sample point
    /// waits in its tx window, until it is judged).
    fn quiet_clocks_ahead(&self, pins: CanPins) -> Stretch {
        let none = Stretch::default();
        let Some(AnyRef::Model(m)) = &self.reference.model else { return none };
        if self.reference.awaiting_dut_sof() {
            return none;
        }
        let rx = self.bus.dut_rx();
        let n = m.counting_clocks(rx).min(self.obs.clocks_before_sample(self.bus.level()));
        if n == 0 {
            return none;
        }
        let view = m.view_now();
        let n = n.min(self.checks.quiet_ahead(&view, &pins));
        if n == 0 {
            return none;
        }
        Stretch {
            left: n,
            view,
            pins,
            level: self.bus.level(),
            rx,
            // The model's CDR and sleep stay as they are while it only counts.
            clkout: crate::types::Reference::clkout_setting(m),
            ..none
        }
    }

    /// The instants of a batch (levels `lv`, pins `ot`) from `from` on
    /// that continue the quiet stretch `s`, taken in one go: up to the
    /// first that is not a quiet host edge (as `run_batch` takes it), not a
    /// CAN edge of the stretch (pins, bus level, edges left), or a CAN edge
    /// whose CLKOUT check would not take its short path; never the batch's
    /// last instant. For the CAN edges that is what
    /// [`Testbench::quiet_can_edge`] does on each, only the CLKOUT check
    /// per edge, the rest for all of them at once (`quiet_edges_done`).
    /// Returns the first instant not taken and the last CAN edge taken.
    fn quiet_run(&mut self, lv: &[u8], ot: &[u8], from: usize, quiet_host: bool, s: &mut Stretch) -> (usize, Option<usize>) {
        let (mut j, mut clocks, mut host, mut last_rise) = (from, 0u32, 0u32, None);
        let Some((clkout, half_period)) = self.checks.quiet_clkout(s.clkout) else {
            return (from, None);
        };
        while j + 1 < lv.len() {
            let l = lv[j];
            if l & 0b1100 != 0 {
                if l & 8 != 0 && !quiet_host {
                    break;
                }
                if l & 4 != 0 {
                    let o = ot[j];
                    if s.left == 0
                        || j == 0
                        || o & 7 != s.out
                        || self.bus.replay_level(ot[j - 1] & 1 != 0) != s.level
                        || !clkout.settled_next(half_period, o & 8 != 0)
                    {
                        break;
                    }
                    s.left -= 1;
                    clocks += 1;
                    last_rise = Some(j);
                }
                host += u32::from(l >> 3 & 1);
            }
            j += 1;
        }
        self.host.quiet_edges(host);
        self.quiet_edges_done(clocks, s);
        (j, last_rise)
    }

    /// `n` CAN edges of the stretch `s` whose CLKOUT check was done
    /// (finding nothing): what [`Testbench::quiet_can_edge`] does on them
    /// besides that, in one go. Each agent's state is its own, so doing each
    /// agent's part of the edges together is doing the edges one by one.
    /// The bus keeps the level and rx it had (replayed rises of the stretch
    /// set the same).
    #[inline]
    fn quiet_edges_done(&mut self, n: u32, s: &Stretch) {
        if n == 0 {
            return;
        }
        self.can_clocks += u64::from(n);
        self.host.on_can_edges(n);
        self.obs.quiet_clocks(n);
        let Some(AnyRef::Model(m)) = &mut self.reference.model else {
            unreachable!("quiet_clocks_ahead checked the reference");
        };
        m.counting_clocks_run(n, s.rx);
        let field = s.view.field.or(self.obs.field());
        self.checks.quiet_clocks(n, field, self.obs.bits(), &s.view, &s.pins);
    }

    /// A CAN edge promised by [`Testbench::quiet_clocks_ahead`] (`v`: the
    /// reference's view then): what [`Testbench::can_edge`] does on it, in
    /// the same order, without what cannot happen there (a sample point,
    /// the reference's quantum work and events, the comparator's long
    /// path). False when a CLKOUT finding ended the stretch (handled as
    /// `can_edge` does).
    #[inline]
    fn quiet_can_edge(&mut self, t_ps: u64, pins: CanPins, v: &RefView) -> bool {
        self.can_clocks += 1;
        self.host.on_can_edge();
        let sample = self.obs.clock(self.bus.level());
        debug_assert!(!sample, "a promised clock is no sample point");
        let rx = self.bus.dut_rx();
        let Some(AnyRef::Model(m)) = &mut self.reference.model else {
            unreachable!("quiet_clocks_ahead checked the reference");
        };
        m.counting_clock(rx);
        if self.clkout_levels != 0 {
            self.checks.clkout_instants(std::mem::take(&mut self.clkout_levels));
        }
        let bit = self.obs.bits();
        let field = v.field.or(self.obs.field());
        let (obs, r) = (&self.obs, &self.reference.model);
        let clkout = || r.as_ref().map_or(crate::clkout::ClkoutSetting::Unchecked, |r| r.clkout_setting());
        if self.checks.quiet_clock(|| obs.stamp(t_ps, bit, v.field), field, bit, v, &pins, clkout) {
            self.handle_divergences();
            return false;
        }
        true
    }

    fn check_stopped(&self) -> Result<(), TbError> {
        match &self.obs.record.divergence {
            Some(d) if self.checks.stopped() => Err(TbError::Diverged(format!(
                "{:?} at {} ps (bit {:?}, field {:?}): expected {}, saw {}; {}",
                d.kind, d.time_ps, d.bit, d.field, d.expected, d.seen, d.context
            ))),
            _ => Ok(()),
        }
    }

    /// Runs `n` host clock cycles.
    pub fn run_host_cycles(&mut self, n: u64) -> Result<(), TbError> {
        let end = self.host.cycles() + n;
        while self.host.cycles() < end {
            self.tick();
            self.check_stopped()?;
        }
        Ok(())
    }

    /// Runs `n` CAN clock cycles.
    pub fn run_can_cycles(&mut self, n: u64) -> Result<(), TbError> {
        let end = self.can_clocks + n;
        while self.can_clocks < end {
            if !self.run_batch(end - self.can_clocks, false)? {
                self.tick();
                self.check_stopped()?;
            }
        }
        Ok(())
    }

    /// Runs `n` bit times (sample points of the bit clock).
    pub fn run_bits(&mut self, n: u64) -> Result<(), TbError> {
        let end = self.obs.bits() + n;
        while self.obs.bits() < end {
            self.tick();
            self.check_stopped()?;
        }
        self.obs.record.bits_simulated = self.obs.bits();
        Ok(())
    }

    /// Runs until `done` holds, at most `max_bits` bit times.
    pub fn run_until(
        &mut self,
        what: &str,
        max_bits: u64,
        mut done: impl FnMut(&Testbench) -> bool,
    ) -> Result<u64, TbError> {
        let start = self.obs.bits();
        let max_clocks = (max_bits + 1) * self.obs.clocks_per_bit() as u64;
        let end = self.can_clocks + max_clocks;
        while !done(self) {
            if self.can_clocks >= end {
                return Err(TbError::Timeout {
                    what: what.into(),
                    bits: max_bits,
                });
            }
            self.tick();
            self.check_stopped()?;
        }
        Ok(self.obs.bits() - start)
    }

    /// Waits for `irq_on` to go low (interrupt pending). The same instants
    /// as `run_until` with that condition, in batches when it can.
    pub fn wait_irq(&mut self, max_bits: u64) -> Result<u64, TbError> {
        let start = self.obs.bits();
        let max_clocks = (max_bits + 1) * self.obs.clocks_per_bit() as u64;
        let end = self.can_clocks + max_clocks;
        while self.dut_pins.irq_n {
            if self.can_clocks >= end {
                return Err(TbError::Timeout {
                    what: "irq_on low (interrupt)".into(),
                    bits: max_bits,
                });
            }
            if !self.run_batch(end - self.can_clocks, true)? {
                self.tick();
                self.check_stopped()?;
            }
        }
        Ok(self.obs.bits() - start)
    }

    /// Polls SR through the host BFM until `SR & mask == value`.
    pub fn wait_sr(&mut self, mask: u8, value: u8, max_bits: u64) -> Result<u8, TbError> {
        let start = self.obs.bits();
        loop {
            let sr = self.read(SR_ADDR)?;
            if sr & mask == value {
                return Ok(sr);
            }
            if self.obs.bits() - start > max_bits {
                if self.obs.record.stuck.is_none() && mask & diagnose::sr::TBS != 0 {
                    // A transmission that never completed: the diagnoser's case.
                    let (requested_ps, requested_bit) = self.obs.last_tr.unwrap_or((0, start));
                    self.obs.record.stuck = Some(diagnose::StuckTransfer {
                        requested_ps,
                        requested_bit,
                        waited_bits: max_bits,
                        sr,
                        attempts: self.obs.frame(),
                    });
                }
                return Err(TbError::Timeout {
                    what: format!("SR & 0x{mask:02X} == 0x{value:02X} (last SR 0x{sr:02X})"),
                    bits: max_bits,
                });
            }
            self.run_bits(1)?;
        }
    }

    /// Queues `accesses` `(write, addr, data)` as one Wishbone block cycle:
    /// the next `write`/`read`/`expect` calls must do them in this order,
    /// and each next one is on the wires at the edge that samples the
    /// previous ack (cyc and stb held). False, and nothing queued, when the
    /// host is not the Wishbone master: the accesses are then single ones.
    pub fn begin_block(&mut self, accesses: &[(bool, u8, u8)]) -> Result<bool, TbError> {
        if !self.block.is_empty() {
            return Err(TbError::Config("a block cycle began while another one has accesses left".into()));
        }
        let Some(handles) = self.host.start_block(accesses) else {
            return Ok(false);
        };
        self.block = accesses.iter().zip(handles).map(|(&(w, a, d), h)| (w, a, d, h)).collect();
        Ok(true)
    }

    fn op(&mut self, write: bool, addr: u8, data: u8) -> Result<OpResult, TbError> {
        let queued = match self.block.front() {
            None => None,
            Some(&(w, a, d, h)) if (w, a, d) == (write, addr, data) => {
                self.block.pop_front();
                Some(h)
            }
            Some(&(w, a, d, _)) => {
                self.block.clear();
                self.host.abandon_block();
                return Err(TbError::Config(format!(
                    "block cycle: the next access queued is a {} at 0x{a:02X} (data 0x{d:02X}), not this {} at 0x{addr:02X}",
                    if w { "write" } else { "read" },
                    if write { "write" } else { "read" }
                )));
            }
        };
        let r = self.op_queued(write, addr, data, queued);
        if r.is_err() && !self.block.is_empty() {
            // A failed run does not do the rest of its block behind the
            // reference's back (e.g. while the record reads SR).
            self.block.clear();
            self.host.abandon_block();
        }
        r
    }

    /// One access; `queued`: its handle when it was queued already (a block).
    fn op_queued(&mut self, write: bool, addr: u8, data: u8, queued: Option<OpHandle>) -> Result<OpResult, TbError> {
        self.check_stopped()?;
        let t0 = self.kernel.now_ps();
        let (mode, reset_mode) = self
            .reference
            .model
            .as_ref()
            .and_then(|r| r.mode())
            .unwrap_or_default();
        let reg = self
            .reference
            .model
            .as_ref()
            .and_then(|r| r.reg_name(addr, write));
        let h: OpHandle = queued.unwrap_or_else(|| self.host.start(write, addr, data));
        let bound = self.host.op_bound();
        let start_cycle = self.host.cycles();
        let viol_before = self.obs.record.violations.len();
        // The reference takes the access when the DUT's CAN side does, if
        // the bench knows when that is (see `RefTiming`); else at the ack.
        let timing = self.reference.timing();
        let due_edges = self.reference.due_edges(write, addr);
        let mut launched = false;
        let mut i8051_wr_seen = false;
        let mut acks_seen = 0u32;
        let mut can_edges = 0u32;
        // Times the core performed the access again (for the record: acks_seen).
        let mut repeats = 0u32;
        let mut taken: Option<(Option<diagnose::WriteOutcome>, u8)> = None;
        // A core with a request/acknowledge handshake (`busy-after-ack`)
        // sees a request still held once the handshake is idle again as a
        // new one (Wishbone: stb held after ack is the next transfer), and
        // performs the access again: a GPIO-polled master that misses the
        // one-clock ack does that. The reference performs it as often.
        let mut again = (!self.host.native_avalon() && !self.host.is_i8051() && self.host.has_holdoff())
            .then_some(Again::default());
        let res = loop {
            if let Some(r) = self.host.poll(h) {
                break r;
            }
            if self.host.cycles() - start_cycle > bound {
                break Err(BfmError::Stalled {
                    cycles: self.host.cycles() - start_cycle,
                });
            }
            let c = self.host.cycles();
            while self.host.cycles() == c {
                if let (Some(a), Some(_)) = (&mut again, &taken)
                    && timing != RefTiming::AtAck
                {
                    let presented = self.host.wb_presented();
                    let (cc, ready_before) = (self.can_clocks, self.host.ready());
                    self.tick();
                    let ready_now = self.host.ready();
                    if a.observe(presented, ready_before, ready_now, self.can_clocks != cc, due_edges)
                        && let Some(refm) = &mut self.reference.model
                    {
                        repeats += 1;
                        taken = Some(if write {
                            (refm.write(addr, data), 0)
                        } else {
                            self.checks.reference_read_taken();
                            (None, refm.read(addr))
                        });
                    }
                    continue;
                }
                if timing == RefTiming::AtAck || taken.is_some() {
                    self.tick();
                    continue;
                }
                let presented = self.host.presented();
                let cc = self.can_clocks;
                // A CAN edge counts for the access only if the core could
                // see the request at it (its hold-off after the last ack).
                let ready_before = self.host.ready();
                self.tick();
                if launched {
                    can_edges += (self.can_clocks != cc && ready_before) as u32;
                } else if self.host.is_i8051() {
                    // No host clock in the DUT: it sees the pins from the
                    // host edge that sets them. A read launches there with
                    // RD, a write with the release of WR (or its rise).
                    let launch = self.host.i8051_launch(write, &mut i8051_wr_seen);
                    launched = self.host.cycles() != c && launch;
                } else if self.host.count_from_wires() {
                    // The host edge that puts cyc & stb on the wires: the
                    // core's synchroniser sees them at the next CAN edge.
                    launched = self.host.cycles() != c && self.host.presented();
                } else {
                    // The first host edge at which the DUT sees cyc & stb.
                    launched = self.host.cycles() != c && presented;
                }
                let ready_now = self.host.ready();
                if launched && can_edges >= due_edges && (due_edges > 0 || ready_now) {
                    self.last_access_clock = Some(self.can_clocks);
                    if let Some(refm) = &mut self.reference.model {
                        taken = Some(if write {
                            (refm.write(addr, data), 0)
                        } else {
                            self.checks.reference_read_taken();
                            (None, refm.read(addr))
                        });
                    }
                }
            }
            // For the diagnosis of a failed access: did the DUT answer at all?
            let answered = self.host.answered(&self.dut);
            acks_seen += answered as u32;
        };
        // The master let go while the core was already taking the access
        // once more (its profile's `latch`): performed all the same.
        let committed = self.host.latch_edges().unwrap_or(due_edges).max(1);
        if let Some(a) = &again
            && taken.is_some()
            && a.committed(committed)
            && let Some(refm) = &mut self.reference.model
        {
            repeats += 1;
            if write {
                refm.write(addr, data);
            } else {
                refm.read(addr);
            }
        }
        let mut rec = HostOp {
            time_ps: t0,
            bfm: self.host.host_bus(),
            access: if write {
                RecAccess::Write
            } else {
                RecAccess::Read
            },
            addr,
            data,
            reg: reg.clone(),
            mode,
            reset_mode,
            acks_seen,
            repeats,
            ..HostOp::default()
        };
        match res {
            Ok(r) => {
                rec.cycles = r.cycles as u32;
                rec.data = r.data;
                let stamp = Stamp {
                    t_ps: self.kernel.now_ps(),
                    bit: self.obs.bits(),
                    field: self.obs.field(),
                    frame: None,
                };
                if taken.is_none() {
                    self.last_access_clock = Some(self.can_clocks);
                }
                if let Some(refm) = &mut self.reference.model {
                    if write {
                        rec.outcome = match taken {
                            Some((o, _)) => o,
                            None => refm.write(addr, data),
                        };
                    } else {
                        // A pending adopt-dut-tec/-rec takes the DUT's counter here.
                        let adopt = self.checks.adopt_at_read(reg.as_deref(), r.data, refm, stamp.t_ps);
                        let mv = match taken {
                            _ if adopt => r.data,
                            Some((_, v)) => v,
                            None => refm.read(addr),
                        };
                        rec.model_data = Some(mv);
                        if self.checks.read(stamp, addr, r.data, mv, reg.clone()) {
                            self.handle_divergences();
                        }
                    }
                }
                if write && addr == 1 && data & 0x11 != 0 {
                    // CMR.TR (bit 0) or CMR.SRR (bit 4) in both views.
                    self.obs.last_tr = Some((t0, self.obs.bits()));
                }
                if write
                    && (addr == 6 || addr == 7)
                    && rec.outcome.as_ref().is_none_or(|o| !o.is_ignored())
                {
                    self.obs.set_btr(addr, data);
                }
                self.obs.record.host_ops.push(rec);
                self.check_stopped()?;
                Ok(r)
            }
            Err(e) => {
                let monitor: Vec<String> = self.obs.record.violations[viol_before..]
                    .iter()
                    .map(|v| format!("cycle {}: {} ({})", v.cycle, v.message, v.rule))
                    .collect();
                let monitor = if monitor.is_empty() {
                    String::new()
                } else {
                    format!("; the protocol monitor saw: {}", monitor.join("; "))
                };
                rec.error = Some(e.to_string());
                self.obs.record.host_ops.push(rec);
                let err = TbError::Host {
                    op: if write { "write" } else { "read" },
                    addr,
                    error: e,
                    monitor,
                };
                self.obs.record.error = Some(err.to_string());
                Err(err)
            }
        }
    }

    /// The CAN clock count (as [`Testbench::can_cycles`]) after which the
    /// reference took the last host access: tests that place an access
    /// against a clock of the bus (an abort against the clock a frame
    /// starts) read where it landed.
    pub fn last_access_clock(&self) -> Option<u64> {
        self.last_access_clock
    }

    /// The field the reference is in after the last CAN clock, if it knows.
    pub fn reference_field(&self) -> Option<can_proto::Field> {
        self.reference.model.as_ref().and_then(|r| r.field())
    }

    /// Host register write through the BFM.
    pub fn write(&mut self, addr: u8, data: u8) -> Result<OpResult, TbError> {
        self.op(true, addr, data)
    }

    /// Host register read through the BFM (compared with the reference in lockstep).
    pub fn read(&mut self, addr: u8) -> Result<u8, TbError> {
        self.op(false, addr, 0).map(|r| r.data)
    }

    /// Reads `addr` and records whether `value & mask == expected`.
    pub fn expect(
        &mut self,
        step: usize,
        what: &str,
        addr: u8,
        mask: u8,
        expected: u8,
    ) -> Result<bool, TbError> {
        let waived_before = self.checks.waivers().waived_count();
        let v = self.read(addr)?;
        let mut passed = v & mask == expected & mask;
        let mut seen = format!("0x{:02X}", v & mask);
        // A missed SR/IR read may still be within the comparator's
        // look-ahead window: decide it first (host idle for those CAN
        // clocks), so a waived divergence of this very read is known here.
        // Only on a miss: a met expectation changes no timing. Not inside
        // a block cycle (its next access is on the wires already): the
        // miss is then judged without the look-ahead, never waived by it.
        if !passed && self.block.is_empty() {
            let n = self.checks.open_read_clocks();
            if n > 0 {
                self.run_can_cycles(n as u64)?;
            }
        }
        // A miss the comparator let through only by its status tolerance,
        // where the model's value meets the expectation, is a difference
        // after all (see `Comparator::hold_tolerated_read`).
        if !passed && self.checks.hold_tolerated_read(addr, v, mask, expected) {
            self.handle_divergences();
        }
        // A miss that is a waived deviation of this read, or a listed
        // consequence of one waived earlier.
        if !passed
            && let Some(why) = self.checks.waive_missed_expectation(
                waived_before,
                &self.obs.record.scenario,
                step,
                what,
                mask,
                expected,
                v,
            )
        {
            passed = true;
            seen.push_str(&why);
        }
        self.obs.record.expectations.push(Expectation {
            step,
            what: what.into(),
            expected: format!("0x{:02X} (mask 0x{mask:02X})", expected & mask),
            seen,
            passed,
        });
        Ok(passed)
    }

    /// The run record for the diagnoser (final registers by peeking the
    /// reference; the DUT's SR is read through the BFM when it can be).
    ///
    /// First [`Testbench::settle`]s the comparator, so that the last reads
    /// of a run are compared too.
    pub fn record(&mut self) -> RunRecord {
        if let Err(e) = self.settle()
            && !matches!(e, TbError::Diverged(_))
            && self.obs.record.error.is_none()
        {
            self.obs.record.error = Some(e.to_string());
        }
        let mut r = self.obs.record.clone();
        r.bits_simulated = self.obs.bits();
        r.dut = self.dut_name.clone();
        if let Some(refm) = &self.reference.model {
            let (tec, rec) = refm.counters().unwrap_or((0, 0));
            r.final_model = Some(FinalRegs {
                sr: refm.peek(SR_ADDR),
                ir: refm.peek(IR_ADDR),
                tec,
                rec,
                ecc: None,
                alc: None,
                counters_from_model: false,
            });
            if let Some((mode, _)) = refm.mode() {
                r.mode = mode;
            }
        }
        let _ = self.obs.flush();
        r
    }

    /// Reads the DUT's status at the end of a run through the BFM (SR; in
    /// PeliCAN also RXERR, TXERR, ECC and ALC, whose reads re-arm capture).
    /// Stored in the record in PeliCAN only: BasicCAN cannot read the error
    /// counters, and the record has no "unknown" for them. IR is not read:
    /// reading it clears it.
    pub fn capture_final(&mut self) -> Result<FinalRegs, TbError> {
        let peli = self
            .reference
            .model
            .as_ref()
            .and_then(|r| r.mode())
            .map(|(m, _)| m == diagnose::CanMode::PeliCan)
            .unwrap_or(false);
        let sr = self.read(SR_ADDR)?;
        let mut f = FinalRegs {
            sr,
            ..FinalRegs::default()
        };
        if peli {
            f.rec = self.read(14)? as u16;
            f.tec = self.read(15)? as u16;
            f.ecc = Some(self.read(12)?);
            f.alc = Some(self.read(11)?);
            if sr & diagnose::sr::BS != 0 {
                f.tec = 256;
            }
        }
        if peli {
            self.obs.record.final_dut = Some(f);
        }
        Ok(f)
    }

    /// The comparator's tolerances in words (for reports), if lockstep.
    pub fn tolerances(&self) -> Option<String> {
        self.checks.tolerances()
    }

    /// Runs the CAN clocks (host idle) that decide the comparisons still
    /// open ([`Comparator::open_clocks`]: an SR read within its look-ahead
    /// window, a pin mismatch within its tolerance, the tx window), so a
    /// run never ends with a read the comparator has not judged. Called by
    /// [`Testbench::record`]; a no-op when nothing is open or the
    /// comparison has stopped.
    pub fn settle(&mut self) -> Result<(), TbError> {
        let n = self.checks.open_clocks();
        if n > 0 {
            self.run_can_cycles(n as u64)?;
            self.obs.record.bits_simulated = self.obs.bits();
        }
        Ok(())
    }

    /// Flushes the VCD files.
    pub fn flush(&mut self) -> Result<(), TbError> {
        self.obs.flush()?;
        Ok(())
    }
}
