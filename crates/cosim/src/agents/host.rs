//! The host agent: the host side of the DUT's register bus. The bus
//! functional model (Wishbone, Avalon-MM natively or through a bridge
//! wiring, PIO bit-banging, the 8051 bus), the pins it applied last, the
//! protocol monitors of that bus, the reset sequence on the host clock, and
//! what the core's declared handshake says about a request on the wires
//! (when it is latched, when a new one can be seen after an ack).

use bfm::{
    ApbBridge, ApbConfig, ApbMaster, ApbMasterOut, ApbMonitor, Axi4LiteBridge, Axi4LiteConfig,
    Axi4LiteMaster, Axi4LiteMonitor, AxiMasterOut, AvMasterOut, AvalonMaster, AvalonMasterConfig, AvalonMonitor, AvalonMonitorConfig, AvalonTiming,
    BfmError, HostMaster, I8051Config, I8051Master, I8051Monitor, I8051MonitorConfig, I8051Out,
    I8051Polarity, I8051Timing, MotorolaBridge, MotorolaMaster, MotorolaMonitor, MotorolaOut, RegportBridge, RegportConfig, RegportMaster, RegportMonitor, RegportOut, OpHandle, OpResult, PioMaster, PioTiming, WbMasterOut, WbSlaveOut,
    WishboneMaster, WishboneMonitor, wiring::Wiring as AvWiring,
};
use diagnose::HostBus;

use crate::agents::reference::RefTiming;
use crate::dut::{AnyDut, HostPort};
use crate::holdoff::AckHoldoff;
use crate::kernel::Tick;
use crate::profile::Profile;

/// How the Avalon master reaches a Wishbone DUT.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AvalonWiring {
    /// The DUT has an Avalon port of its own (`can_avalon`).
    Native,
    /// Correct Avalon-to-Wishbone bridge (`waitrequest = !ack`).
    Bridge,
    /// The DE2 thesis wiring (seed 000, Tableau 3.2).
    Seed000,
}

/// The host bus-functional model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HostBfm {
    /// Wishbone classic master.
    Wishbone,
    /// Avalon-MM master.
    Avalon {
        /// Transfer timing.
        timing: AvalonTiming,
        /// How it reaches the DUT.
        wiring: AvalonWiring,
    },
    /// Nios II bit-banging the Wishbone pins through PIO registers.
    Pio(PioTiming),
    /// Intel-mode (8051) multiplexed bus master (pins active high, as on
    /// `can_top_8051` and the opencores 8051 build); drives a DUT with the
    /// [`HostPort::I8051`] port list (`DutChoice::Rtl` becomes `can_top_8051`).
    I8051(I8051Timing),
    /// AXI4-Lite master: drives a DUT with the [`HostPort::Axi4Lite`] port
    /// list natively (`DutChoice::Rtl` becomes `can_axi4lite`), a Wishbone
    /// DUT (the golden model) through [`bfm::Axi4LiteBridge`], the slave
    /// logic of `can_axi4lite` in Rust.
    Axi4Lite(Axi4LiteConfig),
    /// APB3/APB4 requester: a DUT with the [`HostPort::Apb`] port list
    /// natively (`DutChoice::Rtl` becomes `can_apb`), a Wishbone DUT
    /// through [`bfm::ApbBridge`].
    Apb(ApbConfig),
    /// Motorola-mode multiplexed bus master (AS, E, R/W, CS, active high,
    /// phases as [`I8051Timing`]'s with AS for ALE and E for RD/WR); drives
    /// a DUT with the [`HostPort::Motorola`] port list (`DutChoice::Rtl`
    /// becomes `can_top_mcu` with `mode_i` low).
    Motorola(I8051Timing),
    /// A plain register port (strobes, no acknowledge) on the CAN clock
    /// (`Testbench::new` sets the host clock to it): a DUT with the
    /// [`HostPort::Regport`] port list (`DutChoice::Rtl` becomes
    /// `can_regport`), a Wishbone DUT through [`bfm::RegportBridge`].
    Regport(RegportConfig),
}

/// 8051-bus timing for our `can_top_8051` at the given clocks: the default
/// [`I8051Timing`] with the RD strobe long enough for the wrapper's read
/// latency (about 15 CAN clocks, see `rtl/can_top_8051.v`; 18 with margin)
/// and at least 6 CAN clocks of recovery, so that a write, done after WR is
/// released (about 14 CAN clocks), is over before the next access's RD
/// (with 4 host cycles at 50/24 MHz a read waits behind the write and
/// `pelican-error-kinds` diverges: measured).
pub fn i8051_timing_for_rtl(host_hz: u64, can_hz: u64) -> I8051Timing {
    // The phases in ns (bfm::I8051AcTiming), in cycles of this host clock.
    let d = bfm::I8051AcTiming::default().cycles(host_hz);
    let host_cycles = |can_clocks: u64| (can_clocks * host_hz).div_ceil(can_hz.max(1)) as u32;
    I8051Timing {
        rd: d.rd.max(host_cycles(18)),
        recovery: d.recovery.max(host_cycles(6)),
        ..d
    }
}

enum Master {
    Wb(WishboneMaster),
    Av(AvalonMaster, AvalonWiring),
    Pio(PioMaster),
    I8051(I8051Master, I8051Monitor),
    /// The bridge (and the Wishbone outputs of the cycle that ends) when
    /// the DUT has a Wishbone port.
    Motorola(MotorolaMaster, MotorolaMonitor, Option<(MotorolaBridge, WbSlaveOut)>),
    Regport(RegportMaster, RegportMonitor, Option<(RegportBridge, WbSlaveOut)>),
    /// The bridge (and the Wishbone outputs of the cycle that ends) when
    /// the DUT has a Wishbone port.
    Axi(Axi4LiteMaster, Axi4LiteMonitor, Option<(Axi4LiteBridge, WbSlaveOut)>),
    Apb(ApbMaster, ApbMonitor, Option<ApbBridge>),
}

macro_rules! with_master {
    ($m:expr, $x:ident => $e:expr) => {
        match $m {
            Master::Wb($x) => $e,
            Master::Av($x, _) => $e,
            Master::Pio($x) => $e,
            Master::I8051($x, _) => $e,
            Master::Motorola($x, ..) => $e,
            Master::Regport($x, ..) => $e,
            Master::Axi($x, ..) => $e,
            Master::Apb($x, ..) => $e,
        }
    };
}

/// A monitor rule as the record names it: `prefix` then the rule in snake case.
fn rule_id(prefix: &str, r: bfm::Rule) -> String {
    let dbg = format!("{r:?}");
    let mut s = String::from(prefix);
    for (i, c) in dbg.chars().enumerate() {
        if c.is_ascii_uppercase() {
            if i > 0 {
                s.push('_');
            }
            s.push(c.to_ascii_lowercase());
        } else {
            s.push(c);
        }
    }
    s
}

/// The host BFM, its wiring to the DUT, its monitors and the reset sequence.
pub struct HostAgent {
    master: Master,
    host_bus: HostBus,
    /// The pins applied to the DUT last (per bus kind).
    applied_wb: WbMasterOut,
    applied_av: AvMasterOut,
    /// The 8051 pins applied last (Motorola host: its wires' Intel view).
    applied_i8051: I8051Out,
    applied_mot: MotorolaOut,
    applied_reg: RegportOut,
    applied_axi: AxiMasterOut,
    applied_apb: ApbMasterOut,
    wb_mon: WishboneMonitor,
    /// Master pins and slave outputs the Wishbone monitor saw last.
    wb_mon_seen: Option<(WbMasterOut, WbSlaveOut)>,
    av_mon: Option<AvalonMonitor>,
    host_cycle: u64,
    /// Host cycles `wb_rst_i` is still held.
    reset_left: u64,
    /// CAN edges since the Wishbone request on the wires (`req_wires`)
    /// appeared: the monitor is told when the DUT has latched it
    /// (counted only when the profile says when that is).
    req_edges: u32,
    req_wires: WbMasterOut,
    /// The profile's `latch` for the host bus in use, if it gives one.
    latch_edges: Option<u32>,
    /// The profile's `busy-after-ack` for the host bus in use: when the
    /// core can see a new request after an ack.
    holdoff: Option<AckHoldoff>,
    /// 8051 host: the DUT takes a write when WR is released (our
    /// `can_top_8051`), not when WR rises (an external core).
    i8051_write_at_release: bool,
    /// The profile's `count-from = "wires"` for the host bus in use.
    count_from_wires: bool,
}

/// The host agent's settings from the bench configuration.
#[derive(Clone, Copy, Debug)]
pub struct HostSetup<'a> {
    /// The BFM.
    pub bfm: HostBfm,
    /// Per-operation timeout, host cycles.
    pub op_timeout_cycles: u64,
    /// Ack limit of the monitors, host cycles.
    pub monitor_ack_timeout: u64,
    /// Host cycles `wb_rst_i` is held high at start.
    pub reset_cycles: u64,
    /// The DUT's profile (latch, busy-after-ack).
    pub profile: Option<&'a Profile>,
    /// The DUT is a core given by path (8051: takes a write when WR rises).
    pub external: bool,
}

impl HostAgent {
    /// The BFM `s.bfm` wired to `dut`; an error (one line) when the BFM
    /// cannot drive that DUT's port list.
    pub fn new(s: HostSetup<'_>, dut: &AnyDut) -> Result<HostAgent, String> {
        let (master, host_bus) = match s.bfm {
            HostBfm::Wishbone => (
                Master::Wb(WishboneMaster::new("host").with_timeout(s.op_timeout_cycles)),
                HostBus::Wishbone,
            ),
            HostBfm::Avalon { timing, wiring } => {
                let native = dut.host_port() == HostPort::Avalon;
                if native != (wiring == AvalonWiring::Native) {
                    return Err(format!(
                        "Avalon wiring {wiring:?} does not fit {} (its host port is {:?}); use Native for can_avalon, Bridge or Seed000 for a Wishbone DUT",
                        dut.name(),
                        dut.host_port()
                    ));
                }
                let begintransfer = wiring == AvalonWiring::Seed000;
                let m = AvalonMaster::new(
                    "host",
                    AvalonMasterConfig {
                        timing,
                        begintransfer,
                        timeout_cycles: s.op_timeout_cycles,
                    },
                );
                (Master::Av(m, wiring), HostBus::Avalon)
            }
            HostBfm::Pio(t) => {
                let mut m = PioMaster::new("host", t);
                m.set_timeout(s.op_timeout_cycles);
                (Master::Pio(m), HostBus::Pio)
            }
            HostBfm::I8051(timing) => {
                let polarity = I8051Polarity::ACTIVE_HIGH;
                let m = I8051Master::new(
                    "host",
                    I8051Config {
                        polarity,
                        timing,
                        timeout_cycles: s.op_timeout_cycles,
                    },
                );
                let mon = I8051Monitor::new(
                    "8051 monitor",
                    I8051MonitorConfig::for_timing(polarity, &timing),
                );
                (Master::I8051(m, mon), HostBus::I8051)
            }
            HostBfm::Regport(cfg) => {
                let cfg = RegportConfig { timeout_cycles: s.op_timeout_cycles, ..cfg };
                let bridge = match dut.host_port() {
                    HostPort::Regport => None,
                    HostPort::Wishbone => Some((RegportBridge::default(), WbSlaveOut::default())),
                    other => return Err(format!("{} has the {other:?} port list: the register-port host drives a register port (can_regport) or a Wishbone port", dut.name())),
                };
                (Master::Regport(RegportMaster::new("host", cfg), RegportMonitor::new("regport monitor", cfg), bridge), HostBus::Regport)
            }
            HostBfm::Motorola(timing) => {
                let bridge = match dut.host_port() {
                    HostPort::Motorola => None,
                    HostPort::Wishbone => Some((MotorolaBridge::default(), WbSlaveOut::default())),
                    other => return Err(format!("{} has the {other:?} port list: the Motorola host drives a Motorola (can_top_mcu) or a Wishbone port", dut.name())),
                };
                let m = MotorolaMaster::new("host", timing, s.op_timeout_cycles);
                (Master::Motorola(m, MotorolaMonitor::new("motorola monitor", &timing), bridge), HostBus::Motorola)
            }
            HostBfm::Axi4Lite(cfg) => {
                let cfg = Axi4LiteConfig { timeout_cycles: s.op_timeout_cycles, ..cfg };
                let bridge = match dut.host_port() {
                    HostPort::Axi4Lite => None,
                    HostPort::Wishbone => Some((Axi4LiteBridge::new(cfg.stride, cfg.byte_lane), WbSlaveOut::default())),
                    other => return Err(format!("{} has the {other:?} port list: the AXI4-Lite host drives an AXI4-Lite or a Wishbone port", dut.name())),
                };
                let mon = Axi4LiteMonitor::new("axi4-lite monitor", s.monitor_ack_timeout);
                (Master::Axi(Axi4LiteMaster::new("host", cfg), mon, bridge), HostBus::Axi4Lite)
            }
            HostBfm::Apb(cfg) => {
                let cfg = ApbConfig { timeout_cycles: s.op_timeout_cycles, ..cfg };
                let bridge = match dut.host_port() {
                    HostPort::Apb => None,
                    HostPort::Wishbone => Some(ApbBridge { stride: cfg.stride, byte_lane: cfg.byte_lane }),
                    other => return Err(format!("{} has the {other:?} port list: the APB host drives an APB or a Wishbone port", dut.name())),
                };
                let mon = ApbMonitor::new("apb monitor", cfg.apb4, s.monitor_ack_timeout);
                (Master::Apb(ApbMaster::new("host", cfg), mon, bridge), HostBus::Apb)
            }
        };
        if matches!(dut.host_port(), HostPort::Axi4Lite | HostPort::Apb) {
            let fits = matches!((&master, dut.host_port()), (Master::Axi(..), HostPort::Axi4Lite) | (Master::Apb(..), HostPort::Apb));
            if !fits {
                return Err(format!("{} has the {:?} port list: drive it with that host", dut.name(), dut.host_port()));
            }
        }
        let i8051 = matches!(s.bfm, HostBfm::I8051(_));
        if dut.host_port() == HostPort::Regport && !matches!(s.bfm, HostBfm::Regport(_)) {
            return Err(format!("{} has the register-port port list: drive it with the register-port host", dut.name()));
        }
        if dut.host_port() == HostPort::Motorola && !matches!(s.bfm, HostBfm::Motorola(_)) {
            return Err(format!("{} has the Motorola port list: drive it with the Motorola host", dut.name()));
        }
        if (dut.host_port() == HostPort::I8051) != i8051 {
            return Err(format!(
                "{} has the {:?} port list: drive {} with the 8051 host",
                dut.name(),
                dut.host_port(),
                if i8051 {
                    "only a DUT with the 8051 port list"
                } else {
                    "it only"
                }
            ));
        }
        if dut.host_port() == HostPort::Avalon && !matches!(master, Master::Av(..)) {
            return Err(format!(
                "{} has an Avalon port: drive it with the Avalon BFM (wiring Native)",
                dut.name()
            ));
        }
        let av_mon = match &master {
            Master::Av(m, _) => {
                let c = m.config();
                Some(AvalonMonitor::new(
                    "avalon monitor",
                    AvalonMonitorConfig {
                        timing: c.timing,
                        begintransfer: c.begintransfer,
                        timeout_cycles: s.monitor_ack_timeout,
                    },
                ))
            }
            _ => None,
        };
        let profile = s.profile;
        Ok(HostAgent {
            master,
            host_bus,
            applied_wb: WbMasterOut::default(),
            applied_av: AvMasterOut::default(),
            applied_i8051: I8051Polarity::ACTIVE_HIGH.drive(false, false, false, false),
            applied_mot: MotorolaOut::default(),
            applied_reg: RegportOut::default(),
            applied_axi: AxiMasterOut::default(),
            applied_apb: ApbMasterOut::default(),
            wb_mon: WishboneMonitor::new("wishbone monitor", s.monitor_ack_timeout),
            wb_mon_seen: None,
            av_mon,
            host_cycle: 0,
            reset_left: s.reset_cycles.max(1),
            req_edges: 0,
            req_wires: WbMasterOut::default(),
            latch_edges: profile.and_then(|p| match s.bfm {
                HostBfm::Wishbone => p.latch.wishbone,
                HostBfm::Avalon { .. } => p.latch.avalon,
                HostBfm::Pio(_) => p.latch.pio,
                _ => None,
            }),
            holdoff: profile
                .and_then(|p| match s.bfm {
                    HostBfm::Wishbone => p.holdoff.wishbone,
                    HostBfm::Avalon { wiring: AvalonWiring::Bridge, .. } => p.holdoff.avalon,
                    HostBfm::Pio(_) => p.holdoff.pio,
                    _ => None,
                })
                .map(AckHoldoff::new),
            i8051_write_at_release: !s.external,
            count_from_wires: profile.is_some_and(|p| match s.bfm {
                HostBfm::Wishbone => p.count_from_wires.wishbone,
                HostBfm::Avalon { wiring: AvalonWiring::Bridge, .. } => p.count_from_wires.avalon,
                HostBfm::Pio(_) => p.count_from_wires.pio,
                _ => false,
            }),
        })
    }

    /// The bus kind, for the record.
    pub fn host_bus(&self) -> HostBus {
        self.host_bus
    }

    /// Puts the DUT into reset with idle host pins (before the first tick).
    pub fn hold_reset(&self, dut: &mut AnyDut) {
        dut.set_reset(true);
        dut.set_i8051(&self.applied_i8051);
        dut.set_motorola(&self.applied_mot);
        dut.set_regport(&self.applied_reg);
    }

    /// `wb_rst_i` is still held.
    #[inline]
    pub fn in_reset(&self) -> bool {
        self.reset_left > 0
    }

    /// Host cycles so far.
    #[inline]
    pub fn cycles(&self) -> u64 {
        self.host_cycle
    }

    /// One instant after the DUT's eval: the core's handshake hold-off
    /// follows its ack.
    #[inline]
    pub fn on_tick(&mut self, t: &Tick, dut: &AnyDut) {
        if let Some(h) = &mut self.holdoff {
            h.on_tick(t, dut.wb().ack);
        }
    }

    /// A CAN rising edge: one more edge of the request on the wires.
    #[inline]
    pub fn on_can_edge(&mut self) {
        if self.wb_presented() {
            self.req_edges = self.req_edges.saturating_add(1);
        }
    }

    /// `n` CAN rising edges ([`HostAgent::on_can_edge`] `n` times).
    #[inline]
    pub fn on_can_edges(&mut self, n: u32) {
        if self.wb_presented() {
            self.req_edges = self.req_edges.saturating_add(n);
        }
    }

    /// A Wishbone request (cyc & stb) is on the DUT's wires.
    #[inline]
    pub fn wb_presented(&self) -> bool {
        self.applied_wb.cyc && self.applied_wb.stb
    }

    /// The Wishbone master starts nothing and drives idle wires (only a
    /// host operation queues anything): its edges change nothing.
    #[inline]
    pub fn idle(&self) -> bool {
        matches!(&self.master, Master::Wb(m) if m.in_flight() == 0 && self.applied_wb == WbMasterOut::default())
    }

    /// The Wishbone monitor has already seen the wires as they are, with
    /// the DUT's outputs `s`: a host edge would flag nothing and keep its
    /// state.
    #[inline]
    pub fn monitor_saw(&self, s: WbSlaveOut) -> bool {
        self.wb_mon_seen == Some((self.applied_wb, s))
    }

    /// A host edge that changes nothing but the count (see [`HostAgent::idle`]).
    #[inline]
    pub fn quiet_edge(&mut self) {
        self.host_cycle += 1;
    }

    /// `n` [`HostAgent::quiet_edge`]s.
    #[inline]
    pub fn quiet_edges(&mut self, n: u32) {
        self.host_cycle += u64::from(n);
    }

    /// A host rising edge after the DUT's eval: the reset sequence, or the
    /// monitors see the pins and the DUT's outputs, the master steps and
    /// its next pins are applied. Monitor violations go to `violations`.
    /// True at the edge that releases the reset (the reference then
    /// takes its hardware reset). `timing`: the DUT's declared access
    /// timing, for when a request counts as latched.
    pub fn edge(&mut self, dut: &mut AnyDut, timing: RefTiming, violations: &mut Vec<diagnose::Violation>) -> bool {
        let cycle = self.host_cycle;
        self.host_cycle += 1;
        if self.reset_left > 0 {
            self.reset_left -= 1;
            if self.reset_left == 0 {
                dut.set_reset(false);
                return true;
            }
            return false;
        }
        let mut viol: Vec<bfm::Violation> = Vec::new();
        let mut av_viol: Vec<bfm::Violation> = Vec::new();
        // Has the DUT latched the request on the wires (its profile says
        // after how many CAN edges)? A drop after that is no abandonment.
        let latched = match (self.latch_edges, timing) {
            (Some(n), _) => self.req_edges >= n,
            (None, RefTiming::CanEdges { read, write, command }) => {
                let w = self.req_wires;
                let due = if !w.we { read } else if w.adr == 1 { command } else { write };
                self.req_edges >= due
            }
            _ => false,
        };
        self.wb_mon.set_latched(latched);
        // A new request counts its edges afresh once the wires have let go
        // (the monitor has now seen that). A request held on after its ack
        // (a GPIO-polled master that saw the ack late) is still the access
        // the core latched, not a new one.
        if !(self.applied_wb.cyc && self.applied_wb.stb) {
            self.req_edges = 0;
        }
        let mut i8051_viol: Vec<bfm::Violation> = Vec::new();
        let mut axi_viol: Vec<bfm::Violation> = Vec::new();
        match &mut self.master {
            Master::Wb(m) => {
                let s = dut.wb();
                let idle_wires =
                    !(self.applied_wb.cyc || self.applied_wb.stb || s.ack || s.err || s.rty);
                // The monitor would flag nothing and keep its state when
                // the same idle wires come again: skip it.
                if !(idle_wires && self.wb_mon_seen == Some((self.applied_wb, s))) {
                    viol = self.wb_mon.observe(cycle, &self.applied_wb, &s);
                    self.wb_mon_seen = Some((self.applied_wb, s));
                }
                // Nothing queued or in flight and idle outputs: its edge
                // would start nothing and drive the same idle outputs.
                if !(m.in_flight() == 0 && self.applied_wb == WbMasterOut::default()) {
                    let before = m.active();
                    m.on_edge(&s);
                    // The next transfer of a block cycle replaced the one
                    // on the wires (cyc & stb held): a new request.
                    if before.is_some() && m.active().is_some_and(|h| Some(h) != before) {
                        self.req_edges = 0;
                    }
                    self.applied_wb = m.outputs();
                    dut.set_wb(&self.applied_wb);
                }
            }
            Master::Pio(m) => {
                let s = dut.wb();
                viol = self.wb_mon.observe(cycle, &self.applied_wb, &s);
                m.on_edge(&s);
                self.applied_wb = m.outputs();
                dut.set_wb(&self.applied_wb);
                dut.set_reset(m.rst());
            }
            Master::Regport(m, mon, None) => {
                let s = dut.regport();
                i8051_viol = mon.observe(cycle, &self.applied_reg, &s);
                m.on_edge(&s);
                self.applied_reg = m.outputs();
                dut.set_regport(&self.applied_reg);
            }
            Master::Regport(m, mon, Some((b, prev_wb))) => {
                let s_wb = dut.wb();
                b.clock(&self.applied_reg, prev_wb);
                *prev_wb = s_wb;
                let s = b.to_port();
                i8051_viol = mon.observe(cycle, &self.applied_reg, &s);
                m.on_edge(&s);
                self.applied_reg = m.outputs();
                self.applied_wb = b.to_wishbone(&self.applied_reg);
                dut.set_wb(&self.applied_wb);
            }
            Master::Motorola(m, mon, None) => {
                let s = dut.i8051();
                i8051_viol = mon.observe(cycle, &self.applied_mot, &s);
                m.on_edge(&s);
                self.applied_mot = m.outputs();
                self.applied_i8051 = self.applied_mot.intel_view();
                dut.set_motorola(&self.applied_mot);
            }
            Master::Motorola(m, mon, Some((b, prev_wb))) => {
                let s_wb = dut.wb();
                // The bridge's registers take the wires of the cycle that ends.
                b.clock(&self.applied_mot, prev_wb);
                *prev_wb = s_wb;
                let s = b.to_port(&self.applied_mot);
                i8051_viol = mon.observe(cycle, &self.applied_mot, &s);
                m.on_edge(&s);
                self.applied_mot = m.outputs();
                self.applied_i8051 = self.applied_mot.intel_view();
                self.applied_wb = b.to_wishbone();
                dut.set_wb(&self.applied_wb);
            }
            Master::I8051(m, mon) => {
                let s = dut.i8051();
                i8051_viol = mon.observe(cycle, &self.applied_i8051, &s);
                m.on_edge(&s);
                self.applied_i8051 = m.outputs();
                dut.set_i8051(&self.applied_i8051);
            }
            Master::Axi(m, mon, None) => {
                let s = dut.axi();
                axi_viol = mon.observe(cycle, &self.applied_axi, &s);
                m.on_edge(&s);
                self.applied_axi = m.outputs();
                dut.set_axi(&self.applied_axi);
            }
            Master::Axi(m, mon, Some((b, prev_wb))) => {
                let s_wb = dut.wb();
                // The bridge's registers take the wires of the cycle that ends.
                b.clock(&self.applied_axi, prev_wb);
                *prev_wb = s_wb;
                let s = b.to_axi(&self.applied_axi, &s_wb);
                axi_viol = mon.observe(cycle, &self.applied_axi, &s);
                m.on_edge(&s);
                self.applied_axi = m.outputs();
                self.applied_wb = b.to_wishbone(&self.applied_axi);
                dut.set_wb(&self.applied_wb);
            }
            Master::Apb(m, mon, bridge) => {
                let s = match bridge {
                    None => dut.apb(),
                    Some(b) => b.to_apb(&dut.wb()),
                };
                axi_viol = mon.observe(cycle, &self.applied_apb, &s);
                m.on_edge(&s);
                self.applied_apb = m.outputs();
                match bridge {
                    None => dut.set_apb(&self.applied_apb),
                    Some(b) => {
                        self.applied_wb = b.to_wishbone(&self.applied_apb);
                        dut.set_wb(&self.applied_wb);
                    }
                }
            }
            Master::Av(m, AvalonWiring::Native) => {
                let s = dut.av();
                if let Some(mon) = &mut self.av_mon {
                    av_viol = mon.observe(cycle, &self.applied_av, &s);
                }
                m.on_edge(&s);
                self.applied_av = m.outputs();
                dut.set_av(&self.applied_av);
            }
            Master::Av(m, w) => {
                let wiring = if *w == AvalonWiring::Seed000 {
                    AvWiring::Seed000
                } else {
                    AvWiring::Bridge
                };
                let s_wb = dut.wb();
                viol = self.wb_mon.observe(cycle, &self.applied_wb, &s_wb);
                let s = wiring.to_avalon(&s_wb);
                if let Some(mon) = &mut self.av_mon {
                    av_viol = mon.observe(cycle, &self.applied_av, &s);
                }
                m.on_edge(&s);
                self.applied_av = m.outputs();
                self.applied_wb = wiring.to_wishbone(&self.applied_av);
                dut.set_wb(&self.applied_wb);
            }
        }
        if self.applied_wb.cyc && self.applied_wb.stb {
            self.req_wires = self.applied_wb;
        }
        // Three plain loops: this runs at every host edge, mostly with
        // nothing to push (an array of the three vectors costs measurably).
        for v in viol {
            violations.push(diagnose::Violation { cycle: v.cycle, rule: rule_id("wb.", v.rule), message: v.message });
        }
        for v in av_viol {
            violations.push(diagnose::Violation { cycle: v.cycle, rule: rule_id("avalon.", v.rule), message: v.message });
        }
        for v in i8051_viol {
            let prefix = match self.master {
                Master::Motorola(..) => "motorola.",
                Master::Regport(..) => "regport.",
                _ => "i8051.",
            };
            violations.push(diagnose::Violation { cycle: v.cycle, rule: rule_id(prefix, v.rule), message: v.message });
        }
        let prefix = if matches!(self.master, Master::Apb(..)) { "apb." } else { "axi4lite." };
        for v in axi_viol {
            violations.push(diagnose::Violation { cycle: v.cycle, rule: rule_id(prefix, v.rule), message: v.message });
        }
        false
    }

    /// Queues a register access on the BFM.
    pub fn start(&mut self, write: bool, addr: u8, data: u8) -> OpHandle {
        with_master!(&mut self.master, m => if write { m.start_write(addr, data) } else { m.start_read(addr) })
    }

    /// Queues register accesses `(write, addr, data)` as one Wishbone block
    /// cycle (cyc and stb held across them, see
    /// [`bfm::WishboneMaster::start_block`]); one handle per access. `None`
    /// when the host is not the Wishbone master (other buses have no block
    /// cycle: the caller does the accesses one by one).
    pub fn start_block(&mut self, accesses: &[(bool, u8, u8)]) -> Option<Vec<OpHandle>> {
        let Master::Wb(m) = &mut self.master else { return None };
        let block: Vec<bfm::BlockAccess> = accesses
            .iter()
            .map(|&(write, addr, data)| bfm::BlockAccess { write, addr, data })
            .collect();
        Some(m.start_block(&block))
    }

    /// Gives up the accesses of the block cycle that have not started.
    pub fn abandon_block(&mut self) {
        if let Master::Wb(m) = &mut self.master {
            m.abandon_block();
        }
    }

    /// Host cycles within which the queued operations must end (the
    /// master's own bound plus a margin).
    pub fn op_bound(&self) -> u64 {
        with_master!(&self.master, m => m.drain_bound()) + 64
    }

    /// The operation's result, once it has one.
    pub fn poll(&mut self, h: OpHandle) -> Option<Result<OpResult, BfmError>> {
        with_master!(&mut self.master, m => m.poll(h))
    }

    /// The master is the Avalon one on an Avalon port.
    #[inline]
    pub fn native_avalon(&self) -> bool {
        matches!(self.master, Master::Av(_, AvalonWiring::Native))
    }

    /// The master is the 8051 one (or the Motorola one, whose wires the
    /// agent also keeps as their Intel view).
    #[inline]
    pub fn is_i8051(&self) -> bool {
        matches!(self.master, Master::I8051(..) | Master::Motorola(..))
    }

    /// The core's handshake can see a new request now (no hold-off, or it
    /// is over).
    #[inline]
    pub fn ready(&self) -> bool {
        self.holdoff.as_ref().is_none_or(|h| h.ready())
    }

    /// The profile gives a handshake hold-off (`busy-after-ack`).
    pub fn has_holdoff(&self) -> bool {
        self.holdoff.is_some()
    }

    /// The profile says the core sees cyc & stb from the wires (its CAN
    /// clock synchronises them), not from the next host edge.
    pub fn count_from_wires(&self) -> bool {
        self.count_from_wires
    }

    /// The profile's `latch` for this bus, if it gives one.
    pub fn latch_edges(&self) -> Option<u32> {
        self.latch_edges
    }

    /// A request is on the wires (Avalon: chipselect with read or write;
    /// else Wishbone cyc & stb).
    #[inline]
    pub fn presented(&self) -> bool {
        if let Master::Axi(_, _, None) = self.master {
            // can_axi4lite's request: AW and W both valid, or AR valid
            // (one access at a time: no response is waiting then).
            let a = self.applied_axi;
            return (a.awvalid && a.wvalid) || a.arvalid;
        }
        if let Master::Apb(_, _, None) = self.master {
            return self.applied_apb.psel && self.applied_apb.penable;
        }
        if let Master::Regport(_, _, None) = self.master {
            return self.applied_reg.rd || self.applied_reg.wr;
        }
        if self.native_avalon() {
            self.applied_av.chipselect && (self.applied_av.read || self.applied_av.write)
        } else {
            self.wb_presented()
        }
    }

    /// 8051 bus: the access launches at this host edge: a read with RD, a
    /// write when WR is released (our `can_top_8051`) or raised (an
    /// external core). `wr_seen` remembers WR across the calls of one
    /// access. False for other buses.
    pub fn i8051_launch(&self, write: bool, wr_seen: &mut bool) -> bool {
        let p = match &self.master {
            Master::I8051(m, _) => m.config().polarity,
            Master::Motorola(..) => I8051Polarity::ACTIVE_HIGH,
            _ => return false,
        };
        let w = &self.applied_i8051;
        let (rd, wr) = (p.cs(w) && p.rd(w), p.cs(w) && p.wr(w));
        *wr_seen |= wr;
        let write_launch = if self.i8051_write_at_release { *wr_seen && !wr } else { wr };
        if write { write_launch } else { rd }
    }

    /// Did the DUT answer this cycle (ack; Avalon: no waitrequest while
    /// selected; 8051: it drives the port)?
    pub fn answered(&self, dut: &AnyDut) -> bool {
        if let Master::Axi(_, _, None) = self.master {
            let s = dut.axi();
            return s.awready || s.wready || s.arready || s.bvalid || s.rvalid;
        }
        if let Master::Apb(_, _, None) = self.master {
            return self.applied_apb.psel && dut.apb().pready;
        }
        if let Master::Regport(_, _, None) = self.master {
            // No acknowledge: the port answers by being there.
            return self.applied_reg.rd || self.applied_reg.wr;
        }
        if self.native_avalon() {
            self.applied_av.chipselect && !dut.av().waitrequest
        } else if let Master::Motorola(_, _, Some((b, _))) = &self.master {
            b.to_port(&self.applied_mot).ad_oe
        } else if self.is_i8051() {
            dut.i8051().ad_oe
        } else {
            dut.wb().ack
        }
    }

    /// The host pins for our VCD, as Wishbone names them: (cyc, stb, we,
    /// adr, dat_i, dat_o, ack). Avalon: chipselect on cyc, read or write on
    /// stb, ack = selected without waitrequest; 8051: cyc = CS, stb = RD or
    /// WR, adr = the port while ALE is high, ack = the DUT drives the port.
    pub fn wave_pins(&self, dut: &AnyDut) -> (bool, bool, bool, u8, u8, u8, bool) {
        let (ack, dat_o) = match dut.host_port() {
            HostPort::Wishbone => {
                let s = dut.wb();
                (s.ack, s.dat)
            }
            HostPort::Avalon => {
                let s = dut.av();
                (self.applied_av.chipselect && !s.waitrequest, s.readdata)
            }
            HostPort::I8051 | HostPort::Motorola => {
                let s = dut.i8051();
                (s.ad_oe, s.ad)
            }
            HostPort::Regport => {
                let a = self.applied_reg;
                (a.rd || a.wr, dut.regport().rdat)
            }
            HostPort::Axi4Lite => {
                let s = dut.axi();
                (s.awready || s.arready, s.rdata as u8)
            }
            HostPort::Apb => {
                let s = dut.apb();
                (self.applied_apb.psel && s.pready, s.prdata as u8)
            }
        };
        let (cyc, stb, we, adr, dat_i) = match dut.host_port() {
            HostPort::Wishbone => {
                let a = self.applied_wb;
                (a.cyc, a.stb, a.we, a.adr, a.dat)
            }
            HostPort::Avalon => {
                let a = self.applied_av;
                (a.chipselect, a.read || a.write, a.write, a.address, a.writedata)
            }
            HostPort::I8051 | HostPort::Motorola => {
                let a = self.applied_i8051;
                (a.cs, a.rd || a.wr, a.wr, if a.ale { a.ad } else { 0 }, a.ad)
            }
            HostPort::Regport => {
                let a = self.applied_reg;
                (a.rd || a.wr, a.rd || a.wr, a.wr, if a.rd { a.rd_adr } else { a.wr_adr }, a.wdat)
            }
            HostPort::Axi4Lite => {
                let a = self.applied_axi;
                let adr = if a.awvalid { a.awaddr } else { a.araddr };
                (a.awvalid || a.wvalid || a.arvalid, (a.awvalid && a.wvalid) || a.arvalid, a.awvalid, (adr >> 2) as u8, a.wdata as u8)
            }
            HostPort::Apb => {
                let a = self.applied_apb;
                (a.psel, a.psel && a.penable, a.pwrite, (a.paddr >> 2) as u8, a.pwdata as u8)
            }
        };
        (cyc, stb, we, adr, dat_i, dat_o, ack)
    }
}

/// A request held past the core's ack (see `busy-after-ack`): the core sees
/// it again once its handshake is idle, and takes it after as many CAN
/// edges as a new one.
#[derive(Clone, Copy, Debug, Default)]
pub struct Again {
    /// The core acknowledged the access last taken (its hold-off started).
    acked: bool,
    /// CAN edges since then at which the core could see the request.
    edges: u32,
}

impl Again {
    /// One instant of a held request: whether the core takes it again now.
    pub fn observe(&mut self, presented: bool, ready_before: bool, ready_now: bool, can_edge: bool, due: u32) -> bool {
        if !ready_before || !ready_now {
            // Busy with the last access: its ack came, the hold-off runs.
            self.acked = true;
            self.edges = 0;
            return false;
        }
        if !self.acked {
            return false;
        }
        if !presented {
            self.edges = 0;
            return false;
        }
        self.edges += can_edge as u32;
        if self.edges >= due && (due > 0 || can_edge) {
            *self = Again::default();
            return true;
        }
        false
    }

    /// The core has seen the held request at `latch` CAN edges: it is
    /// committed to performing it.
    pub fn committed(&self, latch: u32) -> bool {
        self.acked && self.edges >= latch
    }
}

#[cfg(test)]
mod again_tests {
    use super::Again;

    /// (presented, ready_before, ready_now, can_edge) per instant.
    fn run(a: &mut Again, steps: &[(bool, bool, bool, bool)], due: u32) -> Vec<usize> {
        steps.iter().enumerate().filter(|(_, s)| a.observe(s.0, s.1, s.2, s.3, due)).map(|(i, _)| i).collect()
    }

    #[test]
    fn a_request_held_past_the_hold_off_is_taken_again_after_due_edges() {
        // Held throughout: busy (hold-off) for 2 instants, then ready; the
        // 3rd CAN edge after that takes it again.
        let held = [
            (true, true, true, true),   // before the ack: nothing
            (true, true, false, false), // the ack: hold-off starts
            (true, false, true, true),  // hold-off ends
            (true, true, true, true),
            (true, true, true, false),
            (true, true, true, true),
            (true, true, true, true),
        ];
        assert_eq!(run(&mut Again::default(), &held, 3), vec![6]);
        // A command (due 0): at the first CAN edge the core can see it.
        assert_eq!(run(&mut Again::default(), &held, 0), vec![3]);
        // Released during the hold-off (a Wishbone master): never again.
        let released = [
            (true, true, false, false),
            (false, false, true, true),
            (false, true, true, true),
            (false, true, true, true),
            (false, true, true, true),
        ];
        let mut a = Again::default();
        assert!(run(&mut a, &released, 3).is_empty());
        assert!(!a.committed(1));
        // Dropped after the core saw it at one edge: committed (latch 1).
        let mut a = Again::default();
        assert!(run(&mut a, &held[..4], 3).is_empty());
        assert!(a.committed(1) && !a.committed(2));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::Kernel;
    use crate::model::ModelDut;

    fn setup(bfm: HostBfm) -> HostSetup<'static> {
        HostSetup { bfm, op_timeout_cycles: 2_000, monitor_ack_timeout: 1_000, reset_cycles: 3, profile: None, external: false }
    }

    fn model_dut() -> AnyDut {
        AnyDut::Other(Box::new(ModelDut::new()))
    }

    /// Runs the host agent on the golden model as DUT until `h` completes;
    /// returns its result and how many host edges released the reset.
    fn run_op(host: &mut HostAgent, dut: &mut AnyDut, k: &mut Kernel, h: OpHandle) -> (OpResult, u32, Vec<diagnose::Violation>) {
        let (mut releases, mut viol) = (0, Vec::new());
        for _ in 0..10_000 {
            if let Some(r) = host.poll(h) {
                return (r.expect("the access completes"), releases, viol);
            }
            let t = k.advance();
            dut.eval_pins(k.host().level(), k.can().level());
            host.on_tick(&t, dut);
            if t.host_rise {
                releases += host.edge(dut, RefTiming::AtAck, &mut viol) as u32;
            }
        }
        panic!("the access never completed");
    }

    #[test]
    fn the_reset_sequence_then_a_write_and_a_read_back_through_wishbone() {
        let mut dut = model_dut();
        let mut host = HostAgent::new(setup(HostBfm::Wishbone), &dut).unwrap();
        assert_eq!(host.host_bus(), HostBus::Wishbone);
        host.hold_reset(&mut dut);
        assert!(host.in_reset());
        let mut k = Kernel::new(50_000_000, 24_000_000).unwrap();
        // ACR (address 4, BasicCAN) is writable in reset mode.
        let h = host.start(true, 4, 0xA5);
        let (_, releases, viol) = run_op(&mut host, &mut dut, &mut k, h);
        assert_eq!(releases, 1, "the reset is released once");
        assert!(!host.in_reset());
        let h = host.start(false, 4, 0);
        let (r, releases, viol2) = run_op(&mut host, &mut dut, &mut k, h);
        assert_eq!((r.data, releases), (0xA5, 0));
        assert!(viol.is_empty() && viol2.is_empty(), "a correct slave: no monitor violation");
        assert!(host.cycles() > 3);
        // Idle again: the master starts nothing.
        host.edge(&mut dut, RefTiming::AtAck, &mut Vec::new());
        assert!(host.idle());
    }

    #[test]
    fn a_bfm_that_cannot_drive_the_dut_port_list_is_refused() {
        let dut = model_dut();
        let e = HostAgent::new(setup(HostBfm::I8051(I8051Timing::default())), &dut).err().unwrap();
        assert!(e.contains("drive only a DUT with the 8051 port list"), "{e}");
        let native = HostBfm::Avalon { timing: AvalonTiming::Waitrequest, wiring: AvalonWiring::Native };
        let e = HostAgent::new(setup(native), &dut).err().unwrap();
        assert!(e.contains("does not fit"), "{e}");
        let bridge = HostBfm::Avalon { timing: AvalonTiming::Waitrequest, wiring: AvalonWiring::Bridge };
        assert!(HostAgent::new(setup(bridge), &dut).is_ok());
    }

    #[test]
    fn monitor_rules_are_named_in_snake_case_under_their_bus() {
        assert_eq!(rule_id("wb.", bfm::Rule::AckWithoutRequest), "wb.ack_without_request");
    }
}
