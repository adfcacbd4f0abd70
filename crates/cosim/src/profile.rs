//! Core profiles: the implementation freedoms the SJA1000 datasheet and
//! CAN 2.0B leave open, declared per core in a file (`tb/profiles/*.toml`)
//! instead of assumed by the reference. A *freedom* is a profile entry; a
//! *deviation* from the datasheet is a waiver (the `waivers` crate).
//!
//! ```toml
//! name = "opencores-can"                 # DUT name "<name> (<dir>)" for external cores
//! description = "what the core is"
//! phase-origin = "hardware-reset"        # or "reset-mode-exit": where the bit timing's
//!                                        # prescaler and bit counter start from
//! segment-lag = 2                        # optional, hardware-reset only (default 0): CAN
//!                                        #   clocks from the end of a quantum of the core's
//!                                        #   prescaler (the model's) to its segment counters
//!                                        #   acting on it; a BTR write in reset mode that
//!                                        #   lands within it redoes that quantum, and a
//!                                        #   request in bus idle landing within it after a
//!                                        #   sample point is taken at that sample point
//! [access.wishbone]                      # when a host access takes effect, per host bus
//! takes-effect = "can-edges"             # or "at-ack" (alone)
//! read = 3                               # after the n-th CAN (core) clock rising edge
//! write = 3                              #   strictly after the host edge that first
//! command = 3                            #   presents the access (CMR writes: `command`)
//! [access.avalon]                        # same keys
//! [access.pio]                           # same keys
//! [access.i8051]                         # optional: the 8051 bus (`--host i8051`), edges counted
//!                                        #   from the host edge raising RD or WR (default: 1/1/1)
//! inout-drive = "cs_can_i & rd_i"        # optional: the top has `inout [7:0] port_0_io`; the
//!                                        #   kit wraps it in a shell (cosim::i8051_inout_shell)
//!                                        #   and takes this as the core's output enable
//! busy-after-ack = [3, 3, 2]             # optional, any bus: after an ack the core sees no
//!                                        #   new request for this many CAN, then host, then CAN
//!                                        #   edges (a handshake returning to idle); the edge
//!                                        #   counts above start at the first edge it can see
//! latch = 1                              # optional, any bus: CAN edges after which the core
//!                                        #   has committed to the access; a request dropped
//!                                        #   later is no abandoned transfer for the bus monitor
//!                                        #   (default: when it takes effect)
//! count-from = "wires"                   # optional, any bus: the edge counts start at the
//!                                        #   first CAN edge after cyc & stb appear on the wires
//!                                        #   (a core that synchronises them straight into its
//!                                        #   CAN clock); default "host-edge": after the first
//!                                        #   host edge presenting them (a core that registers
//!                                        #   the request in the host clock first, as ours)
//! [tolerances]                           # CAN clocks, printed in every report
//! tx-edge = 4                            # tx not compared this close to a model tx edge
//! sof = 40                               # a SOF from bus idle may lag this much
//! status = 48                            # SR/IR reads: the model held the value this recently
//! pins = 48                              # irq/bus-off pins may differ this long
//! [ports]                                # optional: only the ports that differ from can_top's
//! irq = { name = "irq_o", active = "high" }   # active level: irq = pending, reset = in reset,
//! bus-off = { name = "bo", active = "high" }  #   bus-off = while bus-off (can_top: low)
//! can-clock = "clk"                      # other roles: host-clock, reset, dat-i, dat-o, cyc,
//!                                        #   stb, we, adr, ack, rx, tx, clkout (names only)
//! [vhdl]                                 # optional: a core with .vhd/.vhdl sources (GHDL)
//! standard = "08"                        # "93", "93c" (GHDL's default) or "08"
//! files = ["pkg.vhd", "top.vhd"]         # optional analysis order (default: GHDL's
//!                                        #   --elab-order of every .vhd/.vhdl in the directory)
//! ghdl-args = ["-fsynopsys"]             # optional extra GHDL options
//! ```
//!
//! Unknown keys are rejected; every error reads `file:line: key: message`.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::holdoff::BusyAfterAck;
use toml::Spanned;

pub use can_engine::PhaseOrigin;

use crate::compare::CompareConfig;

/// A profile file could not be found, read or understood.
#[derive(Debug, thiserror::Error)]
pub enum ProfileError {
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// File name.
        file: String,
        /// Cause.
        source: std::io::Error,
    },
    /// A key is missing, unknown, or has a bad value.
    #[error("{file}:{line}: {key}: {message}")]
    Invalid {
        /// File name.
        file: String,
        /// 1-based line.
        line: usize,
        /// The key at fault.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A bare name that is no shipped profile.
    #[error("no profile named `{name}` in {dir}; shipped profiles: {known}")]
    Unknown {
        /// The name asked for.
        name: String,
        /// Where it was looked for.
        dir: String,
        /// The profiles there.
        known: String,
    },
}

/// When the DUT takes a host access, for the reference to take it then.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AccessTiming {
    /// Unknown or at the handshake: when the host BFM sees the ack.
    AtAck,
    /// After the n-th CAN rising edge strictly after the host edge that
    /// first presents the access: reads, writes, CMR writes.
    CanEdges {
        /// Read data captured.
        read: u32,
        /// Register written.
        write: u32,
        /// Command (CMR) taken.
        command: u32,
    },
}

impl AccessTiming {
    /// CAN edges for an access (`None` at the ack).
    pub fn edges(&self, write: bool, addr: u8) -> Option<u32> {
        match *self {
            AccessTiming::AtAck => None,
            AccessTiming::CanEdges { read, write: w, command } => Some(if !write {
                read
            } else if addr == 1 {
                command
            } else {
                w
            }),
        }
    }

    fn describe(&self) -> String {
        match self {
            AccessTiming::AtAck => "at the ack".into(),
            AccessTiming::CanEdges { read, write, command } => {
                format!("read/write/command after CAN edge {read}/{write}/{command}")
            }
        }
    }
}

/// The per-bus `latch` entries of a profile: CAN edges after which the
/// core has committed to an access on the wires (it will perform it even if
/// the master lets go before the ack). None: when the access takes effect.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Latch {
    /// Wishbone.
    pub wishbone: Option<u32>,
    /// Avalon (through a Wishbone bridge).
    pub avalon: Option<u32>,
    /// PIO.
    pub pio: Option<u32>,
}

/// The per-bus `count-from = "wires"` entries of a profile: the access's
/// CAN edges are counted from the instant cyc & stb appear on the wires,
/// not from the next host edge (false, the default).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CountFromWires {
    /// Wishbone.
    pub wishbone: bool,
    /// Avalon (through a Wishbone bridge).
    pub avalon: bool,
    /// PIO.
    pub pio: bool,
}

/// The per-bus `busy-after-ack` entries of a profile (see
/// [`crate::holdoff`]). None: a new request is seen at once.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Holdoff {
    /// Wishbone.
    pub wishbone: Option<BusyAfterAck>,
    /// Avalon (through a Wishbone bridge).
    pub avalon: Option<BusyAfterAck>,
    /// PIO.
    pub pio: Option<BusyAfterAck>,
}

/// A port of the DUT's top: its name, and for the polarity-bearing roles
/// (reset, irq, bus-off) whether it is active high.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pin {
    /// Port name in the top.
    pub name: String,
    /// Active high (see [`PortMap`] for what "active" means per role).
    pub active_high: bool,
}

impl Pin {
    fn new(name: &str, active_high: bool) -> Pin {
        Pin { name: name.into(), active_high }
    }
}

/// The DUT top's ports by role; defaults are `can_top`'s Wishbone list.
/// Active levels: `reset` active = in reset, `irq` active = interrupt
/// pending (can_top's `irq_on`: low), `bus_off` active = node bus-off
/// (can_top's `bus_off_on`: low while bus-off).
#[derive(Clone, Debug, PartialEq, Eq)]
#[allow(missing_docs)]
pub struct PortMap {
    pub host_clock: Pin,
    pub reset: Pin,
    pub dat_i: Pin,
    pub dat_o: Pin,
    pub cyc: Pin,
    pub stb: Pin,
    pub we: Pin,
    pub adr: Pin,
    pub ack: Pin,
    pub can_clock: Pin,
    pub rx: Pin,
    pub tx: Pin,
    pub irq: Pin,
    pub bus_off: Pin,
    pub clkout: Pin,
    /// `[ports.axi4-lite]`: the AXI4-Lite slave's ports (default: `can_axi4lite`'s).
    pub axi4lite: BusPorts,
    /// `[ports.apb]`: the APB completer's ports (default: `can_apb`'s).
    pub apb: BusPorts,
    /// `[ports.regport]`: the register port's (default: `can_regport`'s).
    pub regport: BusPorts,
    /// `[ports.motorola]`: the Motorola bus's (default: `can_top_mcu`'s).
    pub motorola: BusPorts,
}

impl Default for PortMap {
    fn default() -> Self {
        PortMap {
            host_clock: Pin::new("wb_clk_i", true),
            reset: Pin::new("wb_rst_i", true),
            dat_i: Pin::new("wb_dat_i", true),
            dat_o: Pin::new("wb_dat_o", true),
            cyc: Pin::new("wb_cyc_i", true),
            stb: Pin::new("wb_stb_i", true),
            we: Pin::new("wb_we_i", true),
            adr: Pin::new("wb_adr_i", true),
            ack: Pin::new("wb_ack_o", true),
            can_clock: Pin::new("clk_i", true),
            rx: Pin::new("rx_i", true),
            tx: Pin::new("tx_o", true),
            irq: Pin::new("irq_on", false),
            bus_off: Pin::new("bus_off_on", false),
            clkout: Pin::new("clkout_o", true),
            axi4lite: BusPorts::default_for(PortBus::Axi4Lite),
            apb: BusPorts::default_for(PortBus::Apb),
            regport: BusPorts::default_for(PortBus::Regport),
            motorola: BusPorts::default_for(PortBus::Motorola),
        }
    }
}

/// A host bus whose ports a profile names by role under `[ports.<bus>]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PortBus {
    /// `[ports.axi4-lite]`.
    Axi4Lite,
    /// `[ports.apb]`.
    Apb,
    /// `[ports.regport]`.
    Regport,
    /// `[ports.motorola]`.
    Motorola,
}

/// One role of a bus's port list: its key, our wrapper's port, its active
/// level there, whether a profile may give it another (`active`), and
/// whether a top may lack it.
struct Role {
    key: &'static str,
    name: &'static str,
    high: bool,
    polar: bool,
    optional: bool,
}

const fn role(key: &'static str, name: &'static str) -> Role {
    Role { key, name, high: true, polar: false, optional: false }
}
const fn polar(key: &'static str, name: &'static str, high: bool) -> Role {
    Role { key, name, high, polar: true, optional: false }
}

const AXI_ROLES: &[Role] = &[
    role("clock", "s_axi_aclk"),
    polar("reset", "s_axi_aresetn", false),
    role("awvalid", "s_axi_awvalid"),
    role("awready", "s_axi_awready"),
    role("awaddr", "s_axi_awaddr"),
    role("awprot", "s_axi_awprot"),
    role("wvalid", "s_axi_wvalid"),
    role("wready", "s_axi_wready"),
    role("wdata", "s_axi_wdata"),
    role("wstrb", "s_axi_wstrb"),
    role("bvalid", "s_axi_bvalid"),
    role("bready", "s_axi_bready"),
    role("bresp", "s_axi_bresp"),
    role("arvalid", "s_axi_arvalid"),
    role("arready", "s_axi_arready"),
    role("araddr", "s_axi_araddr"),
    role("arprot", "s_axi_arprot"),
    role("rvalid", "s_axi_rvalid"),
    role("rready", "s_axi_rready"),
    role("rdata", "s_axi_rdata"),
    role("rresp", "s_axi_rresp"),
];

const APB_ROLES: &[Role] = &[
    role("clock", "pclk"),
    polar("reset", "presetn", false),
    role("psel", "psel"),
    role("penable", "penable"),
    role("pwrite", "pwrite"),
    role("paddr", "paddr"),
    role("pwdata", "pwdata"),
    // APB3 tops have neither.
    Role { optional: true, ..role("pstrb", "pstrb") },
    Role { optional: true, ..role("pprot", "pprot") },
    role("prdata", "prdata"),
    role("pready", "pready"),
    role("pslverr", "pslverr"),
];

const REGPORT_ROLES: &[Role] = &[
    polar("reset", "rst_i", true),
    polar("wr", "wr_i", true),
    polar("rd", "rd_i", true),
    // One address for both strobes, or a write and a read address.
    Role { optional: true, ..role("adr", "adr_i") },
    Role { optional: true, ..role("wr-adr", "wr_adr_i") },
    Role { optional: true, ..role("rd-adr", "rd_adr_i") },
    role("wdat", "wdat_i"),
    role("rdat", "rdat_o"),
];

const MOTOROLA_ROLES: &[Role] = &[
    polar("reset", "rst_i", true),
    // Active = Motorola mode selected (the chip's MODE pin low); a top
    // without the strap is Motorola only.
    Role { optional: true, ..polar("mode", "mode_i", false) },
    polar("as", "ale_as_i", true),
    polar("cs", "cs_can_i", true),
    polar("e", "rd_e_i", true),
    // Active = read.
    polar("rw", "wr_rw_i", true),
    role("ad-i", "port_0_i"),
    role("ad-o", "port_0_o"),
    // Active = the core drives the port.
    polar("ad-oe", "port_0_oe", true),
];

impl PortBus {
    fn roles(self) -> &'static [Role] {
        match self {
            PortBus::Axi4Lite => AXI_ROLES,
            PortBus::Apb => APB_ROLES,
            PortBus::Regport => REGPORT_ROLES,
            PortBus::Motorola => MOTOROLA_ROLES,
        }
    }

    /// The table's key under `[ports]`.
    pub fn key(self) -> &'static str {
        match self {
            PortBus::Axi4Lite => "axi4-lite",
            PortBus::Apb => "apb",
            PortBus::Regport => "regport",
            PortBus::Motorola => "motorola",
        }
    }
}

/// The ports of one of the buses of [`PortBus`] by role, as
/// `[ports.<bus>]` names them; a role not named keeps our wrapper's port.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BusPorts {
    bus: PortBus,
    /// Parallel to the bus's roles.
    pins: Vec<Pin>,
    /// Roles the profile named (an optional role named must exist).
    named: Vec<bool>,
}

impl BusPorts {
    /// Our wrapper's ports of `bus`.
    pub fn default_for(bus: PortBus) -> BusPorts {
        let r = bus.roles();
        BusPorts { bus, pins: r.iter().map(|r| Pin::new(r.name, r.high)).collect(), named: vec![false; r.len()] }
    }

    fn index(&self, role: &str) -> usize {
        self.bus.roles().iter().position(|r| r.key == role).unwrap_or_else(|| panic!("{:?} has no role `{role}`", self.bus))
    }

    /// The port of `role` (one of the bus's role keys).
    pub fn pin(&self, role: &str) -> &Pin {
        &self.pins[self.index(role)]
    }

    /// The top must have the port of `role`: a role every top of the bus
    /// has, or an optional one the profile named.
    pub fn required(&self, role: &str) -> bool {
        let i = self.index(role);
        !self.bus.roles()[i].optional || self.named[i]
    }

    /// The role keys of the bus, in order.
    pub fn roles(&self) -> Vec<&'static str> {
        self.bus.roles().iter().map(|r| r.key).collect()
    }

    /// The bus these ports are of.
    pub fn bus(&self) -> PortBus {
        self.bus
    }

    /// Names the port of `role` as a profile's `[ports.<bus>]` would (an
    /// optional role named becomes required). Err: the bus has no such role.
    pub fn set(&mut self, role: &str, pin: Pin) -> Result<(), String> {
        let i = self.bus.roles().iter().position(|r| r.key == role).ok_or_else(|| format!("[ports.{}] has no role `{role}` (roles: {})", self.bus.key(), self.roles().join(", ")))?;
        self.pins[i] = pin;
        self.named[i] = true;
        Ok(())
    }

    /// Whether a profile named the port of `role`.
    pub fn named(&self, role: &str) -> bool {
        self.named[self.index(role)]
    }

    /// Whether `role` carries a polarity (`active`) in a profile.
    pub fn polar(&self, role: &str) -> bool {
        self.bus.roles()[self.index(role)].polar
    }

    /// Whether a top of the bus may lack the port of `role`.
    pub fn optional(&self, role: &str) -> bool {
        self.bus.roles()[self.index(role)].optional
    }

    fn describe(&self, out: &mut Vec<String>) {
        for ((r, p), q) in self.bus.roles().iter().zip(&self.pins).zip(BusPorts::default_for(self.bus).pins) {
            if *p != q {
                let pol = if p.active_high != q.active_high { format!(" active {}", if p.active_high { "high" } else { "low" }) } else { String::new() };
                out.push(format!("{}.{} = {}{pol}", self.bus.key(), r.key, p.name));
            }
        }
    }
}

impl PortMap {
    /// The entries that differ from `can_top`'s, in words (empty: none).
    pub fn describe(&self) -> String {
        let d = PortMap::default();
        let mut v = Vec::new();
        for ((role, p), q) in self.roles().iter().zip(d.roles().iter().map(|r| r.1)) {
            if *p != q {
                let pol = if p.active_high != q.active_high {
                    format!(" active {}", if p.active_high { "high" } else { "low" })
                } else {
                    String::new()
                };
                v.push(format!("{role} = {}{pol}", p.name));
            }
        }
        for b in [&self.axi4lite, &self.apb, &self.regport, &self.motorola] {
            b.describe(&mut v);
        }
        v.join(", ")
    }

    fn roles(&self) -> [(&'static str, &Pin); 15] {
        [
            ("host-clock", &self.host_clock),
            ("reset", &self.reset),
            ("dat-i", &self.dat_i),
            ("dat-o", &self.dat_o),
            ("cyc", &self.cyc),
            ("stb", &self.stb),
            ("we", &self.we),
            ("adr", &self.adr),
            ("ack", &self.ack),
            ("can-clock", &self.can_clock),
            ("rx", &self.rx),
            ("tx", &self.tx),
            ("irq", &self.irq),
            ("bus-off", &self.bus_off),
            ("clkout", &self.clkout),
        ]
    }
}

/// Where register `n` sits on a bus wider than a byte: at byte address
/// `n * stride`, in byte lane `byte_lane` of the data bus (Linux's
/// sja1000 platform binding: `reg-io-width`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegLayout {
    /// Bytes between registers: 1, 2 or 4.
    pub stride: u32,
    /// Byte lane of the data bus that carries the register (0 to 3).
    pub byte_lane: u32,
}

impl RegLayout {
    /// One register per 32-bit word, data in bits 7:0 (AXI4-Lite and APB).
    pub const WORD: RegLayout = RegLayout { stride: 4, byte_lane: 0 };
}

/// `[access.regport]`: the plain register port's timing; what is not given
/// is `bfm::RegportConfig::default()` (our `can_regport`'s).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RegportAccess {
    /// When an access takes effect, counted from the clock edge that
    /// presents the strobe (None: as `wishbone`).
    pub timing: Option<AccessTiming>,
    /// Strobe length, clocks (`strobe`).
    pub strobe: Option<u32>,
    /// Read data valid this many clocks after the read strobe
    /// (`read-latency`, 0 = combinational).
    pub read_latency: Option<u32>,
    /// Idle clocks after every access (`gap`).
    pub gap: Option<u32>,
    /// `addresses = "one"` (true) or `"separate"` (false); None: one when
    /// the top has the `adr` role's port, else separate.
    pub one_address: Option<bool>,
}

impl RegportAccess {
    /// The master's options (the timeout is the bench's).
    pub fn config(&self) -> bfm::RegportConfig {
        let d = bfm::RegportConfig::default();
        bfm::RegportConfig {
            strobe: self.strobe.unwrap_or(d.strobe),
            read_latency: self.read_latency.unwrap_or(d.read_latency),
            gap: self.gap.unwrap_or(d.gap),
            separate_addr: self.one_address.map_or(d.separate_addr, |one| !one),
            ..d
        }
    }

    fn describe(&self) -> Option<String> {
        if *self == RegportAccess::default() {
            return None;
        }
        let c = self.config();
        Some(format!(
            "register port: {}, strobes {} clocks, read data {} clocks after the strobe, {} idle clocks{}",
            self.timing.map_or("as wishbone".to_string(), |t| t.describe()),
            c.strobe,
            c.read_latency,
            c.gap,
            match self.one_address {
                None => "",
                Some(true) => ", one address",
                Some(false) => ", separate read and write addresses",
            }
        ))
    }
}

/// `[access.motorola]`: the Motorola bus's timing. Each phase given (ns)
/// replaces the bench's default for it (`cosim::i8051_timing_for_rtl`,
/// the kit's own numbers, not the data sheet's).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MotorolaAccess {
    /// When an access takes effect, counted from the host edge raising E
    /// (None: as `[access.i8051]`).
    pub timing: Option<AccessTiming>,
    /// AS width, address hold, read float, write data set-up, E of a read,
    /// E of a write, data hold, recovery: ns, in [`MOTOROLA_PHASES`] order.
    pub phases_ns: [Option<u32>; 8],
}

/// The keys of the Motorola phases under `[access.motorola]`.
pub const MOTOROLA_PHASES: [&str; 8] =
    ["as-ns", "addr-hold-ns", "read-float-ns", "data-setup-ns", "e-read-ns", "e-write-ns", "data-hold-ns", "recovery-ns"];

impl MotorolaAccess {
    /// `base` (host cycles) with every phase the profile gives in ns
    /// rounded up to cycles of `host_hz` (at least one).
    pub fn cycles(&self, base: bfm::I8051Timing, host_hz: u64) -> bfm::I8051Timing {
        let c = |ns: Option<u32>, d: u32| ns.map_or(d, |ns| ((ns as u64 * host_hz).div_ceil(1_000_000_000)).max(1) as u32);
        let p = self.phases_ns;
        bfm::I8051Timing {
            ale: c(p[0], base.ale),
            addr_hold: c(p[1], base.addr_hold),
            read_float: c(p[2], base.read_float),
            data_setup: c(p[3], base.data_setup),
            rd: c(p[4], base.rd),
            wr: c(p[5], base.wr),
            data_hold: c(p[6], base.data_hold),
            recovery: c(p[7], base.recovery),
        }
    }

    fn describe(&self) -> Option<String> {
        if *self == MotorolaAccess::default() {
            return None;
        }
        let phases: Vec<String> = MOTOROLA_PHASES.iter().zip(self.phases_ns).filter_map(|(k, v)| Some(format!("{k} {}", v?))).collect();
        Some(format!(
            "Motorola bus: {}{}",
            self.timing.map_or("as the 8051 bus".to_string(), |t| t.describe()),
            if phases.is_empty() { String::new() } else { format!(", {}", phases.join(", ")) }
        ))
    }
}

/// A core's declared freedoms.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Profile {
    /// Name (an external core co-simulated with it is "<name> (<dir>)").
    pub name: String,
    /// The profiles it extends (`extends`), nearest first: with `name`,
    /// its family, whose waivers apply to the DUT too.
    pub ancestors: Vec<String>,
    /// What the core is.
    pub description: String,
    /// The file it came from.
    pub file: Option<PathBuf>,
    /// Where the bit timing's phase starts from.
    pub phase_origin: PhaseOrigin,
    /// CAN clocks by which the core's segment and quantum counters act
    /// after the end of a quantum of its prescaler (`segment-lag`, with a
    /// hardware-reset phase origin only; 0 otherwise). The model acts at
    /// the end of the quantum itself, so a BTR write landing less than
    /// `segment_lag` clocks after a quantum's end still decides that
    /// quantum on the core: the reference's model redoes the quantum with
    /// the new lengths, in reset mode (`Sja1000::set_segment_lag`; at BRP 0,
    /// 2 clocks a quantum, it decides which segment the bit is in). Its
    /// sample point comes as late: a transmission request made in bus idle
    /// less than `segment_lag` clocks after the model's sample point is
    /// taken at it (`Engine::request_tx`).
    pub segment_lag: u32,
    /// `ts-in-suspend = "clear"`: SR.TS reads 0 during suspend
    /// transmission (the default `"set"`: 1, the node is still the
    /// transmitter). The datasheet's TS, "transmitting a message", says
    /// nothing of those 8 bits.
    pub ts_clear_in_suspend: bool,
    /// `ecc-after-read = "cleared"`: a read of ECC clears it (reads 0 until
    /// the next capture); the default `"kept"`: it keeps the last code. The
    /// datasheet fixes ECC until the host has read it once and re-arms the
    /// capture then; what a second read returns it does not say.
    pub ecc_clear_on_read: bool,
    /// `edge-sampling = "clock"`: the core's bit timing logic sees the bus at
    /// every CAN clock, so a pulse shorter than a time quantum can be an
    /// edge to it; the model (and the default `"quantum"`) looks once per
    /// quantum. Neither CAN 2.0B nor the datasheet says which. The random
    /// campaign then makes its glitches whole quanta, which both see.
    pub edges_every_clock: bool,
    /// When a Wishbone access takes effect.
    pub wishbone: AccessTiming,
    /// When an Avalon-MM access takes effect.
    pub avalon: AccessTiming,
    /// When a PIO (bit-banged Wishbone) access takes effect.
    pub pio: AccessTiming,
    /// When an 8051-bus access takes effect (`[access.i8051]`; None: the
    /// bench's default for an external 8051 core, the 1st CAN edge of the
    /// strobe).
    pub i8051: Option<AccessTiming>,
    /// The 8051 top's `port_0_io` is an `inout` driven when this Verilog
    /// expression of its inputs holds (`[access.i8051] inout-drive`).
    pub i8051_inout_drive: Option<String>,
    /// When an AXI4-Lite access takes effect (`[access.axi4-lite]`; None:
    /// as `wishbone`), counted from the first host edge with AWVALID and
    /// WVALID (a write) or ARVALID (a read) on the wires.
    pub axi4lite: Option<AccessTiming>,
    /// When an APB access takes effect (`[access.apb]`; None: as
    /// `wishbone`), counted from the first host edge of the access phase.
    pub apb: Option<AccessTiming>,
    /// Register stride and byte lane on AXI4-Lite (`stride`, `byte-lane`
    /// under `[access.axi4-lite]`; default 4 and 0).
    pub axi4lite_layout: RegLayout,
    /// Register stride and byte lane on APB (default 4 and 0).
    pub apb_layout: RegLayout,
    /// The register port's timing (`[access.regport]`).
    pub regport: RegportAccess,
    /// The Motorola bus's timing (`[access.motorola]`).
    pub motorola: MotorolaAccess,
    /// When the core has committed to an access, per bus (for the host
    /// bus monitor: a request dropped later is not abandoned).
    pub latch: Latch,
    /// How long the core takes no new request after an ack, per bus.
    pub holdoff: Holdoff,
    /// Where the access's CAN edges are counted from, per bus.
    pub count_from_wires: CountFromWires,
    /// The comparator's tolerances for this core.
    pub tolerances: CompareConfig,
    /// Port names and polarities.
    pub ports: PortMap,
    /// How its VHDL sources go through GHDL (`[vhdl]`; default: VHDL-93c,
    /// GHDL's order).
    pub vhdl: crate::vhdl::VhdlOptions,
}

/// Our RTL's profile, shipped as `tb/profiles/rtl.toml` (built in).
const RTL_TOML: &str = include_str!("../../../tb/profiles/rtl.toml");

/// The directory of the shipped profiles (`tb/profiles` of the project).
pub fn shipped_dir() -> PathBuf {
    let local = Path::new("tb/profiles");
    if local.is_dir() {
        return local.to_path_buf();
    }
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tb/profiles")
}

/// Names of the shipped profiles, sorted.
pub fn shipped_names() -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(shipped_dir())
        .map(|d| {
            d.filter_map(|e| e.ok())
                .filter_map(|e| {
                    let p = e.path();
                    (p.extension()? == "toml").then(|| p.file_stem()?.to_str().map(str::to_string))?
                })
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

impl Profile {
    /// Our RTL's profile (`tb/profiles/rtl.toml`, compiled in).
    pub fn rtl() -> Profile {
        Profile::parse(RTL_TOML, "tb/profiles/rtl.toml").expect("the shipped rtl.toml parses (tested)")
    }

    /// A profile by bare name (looked up in `tb/profiles/`) or by file path.
    pub fn find(name_or_file: &str) -> Result<Profile, ProfileError> {
        let p = Path::new(name_or_file);
        if name_or_file.ends_with(".toml") || p.components().count() > 1 {
            return Profile::load(p);
        }
        let dir = shipped_dir();
        let f = dir.join(format!("{name_or_file}.toml"));
        if f.is_file() {
            return Profile::load(&f);
        }
        Err(ProfileError::Unknown {
            name: name_or_file.into(),
            dir: dir.display().to_string(),
            known: shipped_names().join(", "),
        })
    }

    /// Reads a profile file (and the profiles it extends).
    pub fn load(path: impl AsRef<Path>) -> Result<Profile, ProfileError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| ProfileError::Io { file: file.clone(), source })?;
        let mut p = Profile::parse_at(&text, &file, Some(path))?;
        p.file = Some(path.to_path_buf());
        Ok(p)
    }

    /// Parses profile text; `file` names it in errors. An `extends` path
    /// is taken relative to the working directory (see [`Profile::load`]
    /// for one relative to the file).
    pub fn parse(text: &str, file: &str) -> Result<Profile, ProfileError> {
        Profile::parse_at(text, file, None)
    }

    /// Parses profile text read from `path`, following `extends`.
    fn parse_at(text: &str, file: &str, path: Option<&Path>) -> Result<Profile, ProfileError> {
        let Some(chain) = resolve_extends(text, file, path, &mut Vec::new())? else { return Profile::parse_one(text, file) };
        let merged = toml::to_string(&chain.table).expect("a TOML table serialises");
        let mut p = Profile::parse_one(&merged, file).map_err(|e| chain.locate(e))?;
        p.ancestors = chain.ancestors;
        Ok(p)
    }

    /// Parses the text of one profile that extends none.
    fn parse_one(text: &str, file: &str) -> Result<Profile, ProfileError> {
        let raw: RawProfile = toml::from_str(text).map_err(|e| from_toml(file, text, &e))?;
        let bad = |span: std::ops::Range<usize>, key: &str, message: String| ProfileError::Invalid {
            file: file.into(),
            line: line_of(text, span.start),
            key: key.into(),
            message,
        };
        let name = raw.name.get_ref().trim().to_string();
        if name.is_empty() {
            return Err(bad(raw.name.span(), "name", "must not be empty".into()));
        }
        let access = |a: &RawAccess, key: &str| -> Result<AccessTiming, ProfileError> {
            let nums = [&a.read, &a.write, &a.command];
            match a.takes_effect.get_ref() {
                TakesEffect::AtAck => {
                    if let Some(n) = nums.iter().find_map(|n| n.as_ref()) {
                        return Err(bad(n.span(), key, "edge counts make no sense with takes-effect = \"at-ack\"".into()));
                    }
                    Ok(AccessTiming::AtAck)
                }
                TakesEffect::CanEdges => {
                    let get = |n: &Option<Spanned<u32>>, k: &str| {
                        n.as_ref().map(|v| *v.get_ref()).ok_or_else(|| {
                            bad(a.takes_effect.span(), key, format!("takes-effect = \"can-edges\" needs `{k}` (CAN edges after the access starts)"))
                        })
                    };
                    let (read, write, command) = (get(&a.read, "read")?, get(&a.write, "write")?, get(&a.command, "command")?);
                    for n in nums.into_iter().flatten() {
                        if *n.get_ref() > 64 {
                            return Err(bad(n.span(), key, format!("{} CAN edges: at most 64", n.get_ref())));
                        }
                    }
                    Ok(AccessTiming::CanEdges { read, write, command })
                }
            }
        };
        let busy = |a: &RawAccess, key: &str| -> Result<Option<BusyAfterAck>, ProfileError> {
            let Some(v) = &a.busy_after_ack else { return Ok(None) };
            let n = v.get_ref();
            if n.len() != 3 || n.iter().any(|&e| e > 64) {
                return Err(bad(
                    v.span(),
                    key,
                    "busy-after-ack needs [CAN edges, host edges, CAN edges], each at most 64".into(),
                ));
            }
            Ok(Some(BusyAfterAck { can: n[0], host: n[1], can_again: n[2] }))
        };
        let t = &raw.tolerances;
        for (k, v) in [("tx-edge", &t.tx_edge), ("sof", &t.sof), ("status", &t.status), ("pins", &t.pins)] {
            if *v.get_ref() > 1_000 {
                return Err(bad(v.span(), k, format!("{} CAN clocks: at most 1000", v.get_ref())));
            }
        }
        let mut ports = PortMap::default();
        if let Some(rp) = &raw.ports {
            // (serde's untagged enums cannot carry spans: the line is the key's.)
            let set = |pin: &mut Pin, raw: &Option<RawPin>, key: &str, polar: bool| -> Result<(), ProfileError> {
                match raw {
                    None => {}
                    Some(RawPin::Name(n)) => pin.name = n.clone(),
                    Some(RawPin::Full { name, active }) => {
                        if !polar {
                            return Err(ProfileError::Invalid {
                                file: file.into(),
                                line: key_line(text, key),
                                key: key.into(),
                                message: "only reset, irq and bus-off have a polarity (`active`)".into(),
                            });
                        }
                        pin.name = name.clone();
                        pin.active_high = *active == Active::High;
                    }
                }
                Ok(())
            };
            set(&mut ports.host_clock, &rp.host_clock, "host-clock", false)?;
            set(&mut ports.reset, &rp.reset, "reset", true)?;
            set(&mut ports.dat_i, &rp.dat_i, "dat-i", false)?;
            set(&mut ports.dat_o, &rp.dat_o, "dat-o", false)?;
            set(&mut ports.cyc, &rp.cyc, "cyc", false)?;
            set(&mut ports.stb, &rp.stb, "stb", false)?;
            set(&mut ports.we, &rp.we, "we", false)?;
            set(&mut ports.adr, &rp.adr, "adr", false)?;
            set(&mut ports.ack, &rp.ack, "ack", false)?;
            set(&mut ports.can_clock, &rp.can_clock, "can-clock", false)?;
            set(&mut ports.rx, &rp.rx, "rx", false)?;
            set(&mut ports.tx, &rp.tx, "tx", false)?;
            set(&mut ports.irq, &rp.irq, "irq", true)?;
            set(&mut ports.bus_off, &rp.bus_off, "bus-off", true)?;
            set(&mut ports.clkout, &rp.clkout, "clkout", false)?;
            for (bus, raw_bus) in [
                (PortBus::Axi4Lite, &rp.axi4lite),
                (PortBus::Apb, &rp.apb),
                (PortBus::Regport, &rp.regport),
                (PortBus::Motorola, &rp.motorola),
            ] {
                let Some(raw_bus) = raw_bus else { continue };
                let table = format!("ports.{}", bus.key());
                let target = match bus {
                    PortBus::Axi4Lite => &mut ports.axi4lite,
                    PortBus::Apb => &mut ports.apb,
                    PortBus::Regport => &mut ports.regport,
                    PortBus::Motorola => &mut ports.motorola,
                };
                for (k, v) in raw_bus {
                    let here = |message: String| ProfileError::Invalid { file: file.into(), line: table_key_line(text, &table, k), key: k.clone(), message };
                    let roles = bus.roles();
                    let Some(i) = roles.iter().position(|r| r.key == k) else {
                        let known: Vec<String> = roles.iter().map(|r| format!("`{}`", r.key)).collect();
                        return Err(here(format!("unknown field `{k}` of [{table}], expected one of {}", known.join(", "))));
                    };
                    let (name, high) = match v {
                        RawPin::Name(n) => (n.clone(), target.pins[i].active_high),
                        RawPin::Full { name, active } => {
                            if !roles[i].polar {
                                let polar: Vec<&str> = roles.iter().filter(|r| r.polar).map(|r| r.key).collect();
                                return Err(here(format!("only {} have a polarity (`active`) on this bus", polar.join(", "))));
                            }
                            (name.clone(), *active == Active::High)
                        }
                    };
                    if name.trim().is_empty() {
                        return Err(here("the port name must not be empty".into()));
                    }
                    target.pins[i] = Pin { name: name.trim().to_string(), active_high: high };
                    target.named[i] = true;
                }
            }
        }
        for (a, key) in [(&raw.access.wishbone, "access.wishbone"), (&raw.access.avalon, "access.avalon"), (&raw.access.pio, "access.pio")] {
            if let Some(d) = &a.inout_drive {
                return Err(bad(d.span(), key, "inout-drive belongs to [access.i8051] (the 8051 bus's shared port)".into()));
            }
        }
        let i8051 = match &raw.access.i8051 {
            None => None,
            Some(a) => {
                if a.latch.is_some() || a.busy_after_ack.is_some() {
                    return Err(bad(a.takes_effect.span(), "access.i8051", "latch and busy-after-ack are not used on the 8051 bus (no handshake)".into()));
                }
                if let Some(c) = &a.count_from {
                    return Err(bad(c.span(), "access.i8051", "count-from is not used on the 8051 bus (its edges count from the host edge raising RD or WR)".into()));
                }
                Some(access(a, "access.i8051")?)
            }
        };
        let i8051_inout_drive = match raw.access.i8051.as_ref().and_then(|a| a.inout_drive.as_ref()) {
            Some(d) if d.get_ref().trim().is_empty() => return Err(bad(d.span(), "inout-drive", "must not be empty".into())),
            Some(d) => Some(d.get_ref().trim().to_string()),
            None => None,
        };
        let segment_lag = match &raw.segment_lag {
            None => 0,
            Some(l) if !matches!(raw.phase_origin, OriginName::HardwareReset) => {
                return Err(bad(l.span(), "segment-lag", format!("{}: only with phase-origin = \"hardware-reset\" (a bit timing that stands still in reset mode takes BTR writes while stopped)", l.get_ref())));
            }
            Some(l) if *l.get_ref() > 8 => {
                return Err(bad(l.span(), "segment-lag", format!("{}: at most 8 CAN clocks", l.get_ref())));
            }
            Some(l) => *l.get_ref(),
        };
        let mut vhdl = crate::vhdl::VhdlOptions::default();
        if let Some(v) = &raw.vhdl {
            if let Some(st) = &v.standard {
                vhdl.standard = crate::vhdl::VhdlStandard::from_name(st.get_ref().trim())
                    .ok_or_else(|| bad(st.span(), "standard", format!("`{}`: expected \"93\", \"93c\" or \"08\"", st.get_ref())))?;
            }
            vhdl.files = v.files.iter().map(PathBuf::from).collect();
            vhdl.ghdl_args = v.ghdl_args.clone();
        }
        let mut bus_timing = [None, None];
        let mut layouts = [RegLayout::WORD; 2];
        for (i, (a, key)) in [(&raw.access.axi4lite, "access.axi4-lite"), (&raw.access.apb, "access.apb")].into_iter().enumerate() {
            let Some(a) = a else { continue };
            if let Some(d) = &a.inout_drive {
                return Err(bad(d.span(), key, "inout-drive belongs to [access.i8051] (the 8051 bus's shared port)".into()));
            }
            bus_timing[i] = Some(access(a, key)?);
            if let Some(st) = &a.stride {
                if ![1, 2, 4].contains(st.get_ref()) {
                    return Err(bad(st.span(), key, format!("stride {}: 1, 2 or 4 bytes between registers", st.get_ref())));
                }
                layouts[i].stride = *st.get_ref();
            }
            if let Some(l) = &a.byte_lane {
                if *l.get_ref() > 3 {
                    return Err(bad(l.span(), key, format!("byte-lane {}: 0 to 3 on a 32-bit data bus", l.get_ref())));
                }
                layouts[i].byte_lane = *l.get_ref();
            }
        }
        // [access.regport] and [access.motorola]: takes-effect is optional.
        let timing_of = |te: &Option<Spanned<TakesEffect>>, nums: [&Option<Spanned<u32>>; 3], key: &str| -> Result<Option<AccessTiming>, ProfileError> {
            let Some(te) = te else {
                if let Some(n) = nums.iter().find_map(|n| n.as_ref()) {
                    return Err(bad(n.span(), key, "read, write and command need takes-effect".into()));
                }
                return Ok(None);
            };
            let [read, write, command] = nums.map(|n| n.clone());
            let a = RawAccess { takes_effect: te.clone(), read, write, command, latch: None, busy_after_ack: None, count_from: None, inout_drive: None, stride: None, byte_lane: None };
            access(&a, key).map(Some)
        };
        let mut regport = RegportAccess::default();
        if let Some(r) = &raw.access.regport {
            let key = "access.regport";
            regport.timing = timing_of(&r.takes_effect, [&r.read, &r.write, &r.command], key)?;
            for (v, name, min, max, slot) in [
                (&r.strobe, "strobe", 1, 64, &mut regport.strobe),
                (&r.read_latency, "read-latency", 0, 256, &mut regport.read_latency),
                (&r.gap, "gap", 0, 256, &mut regport.gap),
            ] {
                if let Some(v) = v {
                    let n = *v.get_ref();
                    if !(min..=max).contains(&n) {
                        return Err(bad(v.span(), key, format!("{name} {n}: {min} to {max} clocks")));
                    }
                    *slot = Some(n);
                }
            }
            if let Some(a) = &r.addresses {
                let one = *a.get_ref() == Addresses::One;
                let named = |k: &str| ports.regport.named[ports.regport.index(k)];
                if one && (named("wr-adr") || named("rd-adr")) || !one && named("adr") {
                    return Err(bad(a.span(), key, format!("addresses = \"{}\" but [ports.regport] names {}", if one { "one" } else { "separate" }, if one { "wr-adr/rd-adr" } else { "adr" })));
                }
                regport.one_address = Some(one);
            }
        }
        if ports.regport.named[ports.regport.index("adr")] && (ports.regport.named[ports.regport.index("wr-adr")] || ports.regport.named[ports.regport.index("rd-adr")]) {
            return Err(ProfileError::Invalid {
                file: file.into(),
                line: table_key_line(text, "ports.regport", "adr"),
                key: "adr".into(),
                message: "one address (adr) or a write and a read address (wr-adr, rd-adr), not both".into(),
            });
        }
        let mut motorola = MotorolaAccess::default();
        if let Some(m) = &raw.access.motorola {
            let key = "access.motorola";
            motorola.timing = timing_of(&m.takes_effect, [&m.read, &m.write, &m.command], key)?;
            let given = [&m.as_ns, &m.addr_hold_ns, &m.read_float_ns, &m.data_setup_ns, &m.e_read_ns, &m.e_write_ns, &m.data_hold_ns, &m.recovery_ns];
            for (i, v) in given.into_iter().enumerate() {
                if let Some(v) = v {
                    let n = *v.get_ref();
                    if n > 1_000_000 {
                        return Err(bad(v.span(), key, format!("{} {n}: at most 1000000 ns", MOTOROLA_PHASES[i])));
                    }
                    motorola.phases_ns[i] = Some(n);
                }
            }
        }
        for (a, key) in [(&raw.access.wishbone, "access.wishbone"), (&raw.access.avalon, "access.avalon"), (&raw.access.pio, "access.pio")] {
            if let Some(st) = a.stride.as_ref().map(|s| s.span()).or(a.byte_lane.as_ref().map(|s| s.span())) {
                return Err(bad(st, key, "stride and byte-lane belong to [access.axi4-lite] and [access.apb] (an 8-bit bus has one register per address)".into()));
            }
        }
        Ok(Profile {
            axi4lite: bus_timing[0],
            apb: bus_timing[1],
            axi4lite_layout: layouts[0],
            apb_layout: layouts[1],
            regport,
            motorola,
            i8051,
            i8051_inout_drive,
            vhdl,
            name,
            ancestors: Vec::new(),
            description: raw.description.get_ref().trim().to_string(),
            file: None,
            phase_origin: match raw.phase_origin {
                OriginName::HardwareReset => PhaseOrigin::HardwareReset,
                OriginName::ResetModeExit => PhaseOrigin::ResetModeExit,
            },
            segment_lag,
            ts_clear_in_suspend: matches!(raw.ts_in_suspend, Some(TsInSuspend::Clear)),
            ecc_clear_on_read: matches!(raw.ecc_after_read, Some(EccAfterRead::Cleared)),
            edges_every_clock: matches!(raw.edge_sampling, Some(EdgeSampling::Clock)),
            latch: Latch {
                wishbone: raw.access.wishbone.latch.as_ref().map(|v| *v.get_ref()),
                avalon: raw.access.avalon.latch.as_ref().map(|v| *v.get_ref()),
                pio: raw.access.pio.latch.as_ref().map(|v| *v.get_ref()),
            },
            count_from_wires: CountFromWires {
                wishbone: raw.access.wishbone.count_from.as_ref().is_some_and(|c| *c.get_ref() == CountFrom::Wires),
                avalon: raw.access.avalon.count_from.as_ref().is_some_and(|c| *c.get_ref() == CountFrom::Wires),
                pio: raw.access.pio.count_from.as_ref().is_some_and(|c| *c.get_ref() == CountFrom::Wires),
            },
            holdoff: Holdoff {
                wishbone: busy(&raw.access.wishbone, "access.wishbone")?,
                avalon: busy(&raw.access.avalon, "access.avalon")?,
                pio: busy(&raw.access.pio, "access.pio")?,
            },
            wishbone: access(&raw.access.wishbone, "access.wishbone")?,
            avalon: access(&raw.access.avalon, "access.avalon")?,
            pio: access(&raw.access.pio, "access.pio")?,
            tolerances: CompareConfig {
                tx_edge_tolerance: *t.tx_edge.get_ref(),
                sof_tolerance: *t.sof.get_ref(),
                status_tolerance: *t.status.get_ref(),
                pin_tolerance: *t.pins.get_ref(),
                ..CompareConfig::default()
            },
            ports,
        })
    }

    /// The profile in one paragraph, for report headers.
    pub fn describe(&self) -> String {
        let origin = match self.phase_origin {
            PhaseOrigin::HardwareReset => "hardware reset",
            PhaseOrigin::ResetModeExit => "reset-mode exit",
        };
        let ports = self.ports.describe();
        let busy = |b: Option<BusyAfterAck>, wires: bool| {
            let w = if wires { " counted from the wires" } else { "" };
            match b {
                None => w.to_string(),
                Some(b) => format!("{w} (no new request until {}/{}/{} CAN/host/CAN edges after an ack)", b.can, b.host, b.can_again),
            }
        };
        let lag = match self.segment_lag {
            0 => String::new(),
            n => format!(" (its segments act {n} CAN clocks after each quantum: a BTR write in reset mode landing within them redoes that quantum)"),
        };
        let lag = if self.ts_clear_in_suspend { format!("{lag}; SR.TS 0 in suspend transmission") } else { lag };
        let lag = if self.ecc_clear_on_read { format!("{lag}; ECC cleared by a read") } else { lag };
        let lag = if self.edges_every_clock { format!("{lag}; edges seen at every CAN clock") } else { lag };
        format!(
            "profile {}{}{}: bit timing phase from the {origin}{lag}; host access takes effect: wishbone {}{}, avalon {}{}, pio {}{}; ports {}",
            self.name,
            self.file.as_ref().map(|f| format!(" ({})", f.display())).unwrap_or_default(),
            if self.ancestors.is_empty() { String::new() } else { format!(", extends {}", self.ancestors.join(" < ")) },
            self.wishbone.describe(),
            busy(self.holdoff.wishbone, self.count_from_wires.wishbone),
            self.avalon.describe(),
            busy(self.holdoff.avalon, self.count_from_wires.avalon),
            self.pio.describe(),
            busy(self.holdoff.pio, self.count_from_wires.pio),
            if ports.is_empty() { "as can_top".to_string() } else { ports },
        ) + &match (&self.i8051, &self.i8051_inout_drive) {
            (None, None) => String::new(),
            (t, d) => format!(
                "; 8051 bus: {}{}",
                t.map_or("the 1st CAN edge of the strobe (default)".to_string(), |t| t.describe()),
                d.as_ref().map(|d| format!(", inout port_0_io driven when {d}")).unwrap_or_default()
            ),
        } + &[self.regport.describe(), self.motorola.describe()].into_iter().flatten().map(|d| format!("; {d}")).collect::<String>()
            + &if self.vhdl == crate::vhdl::VhdlOptions::default() { String::new() } else { format!("; VHDL: {}", self.vhdl.describe()) }
    }

    /// Does a top with these ports look like the opencores `can_top`?
    /// (for the hint when an external core comes without a profile)
    pub fn looks_like_opencores(verilog_dir: &Path, top: &str) -> bool {
        let Ok(d) = std::fs::read_dir(verilog_dir) else { return false };
        let names: Vec<String> = d.filter_map(|e| e.ok()).filter_map(|e| e.file_name().to_str().map(str::to_string)).collect();
        top == "can_top" && ["can_bsp.v", "can_btl.v", "can_registers.v"].iter().all(|f| names.iter().any(|n| n == f))
    }
}

/// What to tell a user who points the kit at an external core without a
/// profile: what a profile declares, the shipped ones, and a hint when the
/// directory looks like the opencores core.
pub fn missing_profile_message(dir: &Path, top: &str) -> String {
    let hint = if Profile::looks_like_opencores(dir, top) {
        " This looks like the opencores core (can_top with can_bsp.v, can_btl.v, can_registers.v): try --profile opencores-can."
    } else {
        ""
    };
    format!(
        "external core {} has no profile: without one the reference would assume when it takes host accesses \
         and where its bit timing starts, and could report the kit's guess as the core's fault. \
         Give --profile NAME|FILE declaring phase-origin (hardware-reset | reset-mode-exit), \
         [access.wishbone], [access.avalon], [access.pio] (takes-effect = at-ack | can-edges with read/write/command), \
         [tolerances] (tx-edge, sof, status, pins) and [ports] where its top differs from can_top \
         (format: the cosim::profile docs). Shipped profiles in {}: {}.{hint}",
        dir.display(),
        shipped_dir().display(),
        shipped_names().join(", ")
    )
}

/// A profile that `extends` another, merged over its ancestors.
struct Chain {
    /// The merged keys (no `extends`).
    table: toml::Table,
    /// The profiles extended, nearest first.
    ancestors: Vec<String>,
    /// (file, text) of the profile and each ancestor, for error lines.
    sources: Vec<(String, String)>,
}

impl Chain {
    /// An error in the merged text, placed in the file that writes its key
    /// (the profile first, then its ancestors).
    fn locate(&self, e: ProfileError) -> ProfileError {
        let ProfileError::Invalid { key, message, .. } = e else { return e };
        let leaf = key.rsplit('.').next().unwrap_or(&key).to_string();
        let found = self.sources.iter().find_map(|(file, text)| {
            text.lines()
                .position(|l| {
                    let l = l.trim_start();
                    l.trim_end() == format!("[{key}]") || l.strip_prefix(leaf.as_str()).is_some_and(|r| r.trim_start().starts_with('='))
                })
                .map(|i| (file.clone(), i + 1))
        });
        let (file, line) = found.unwrap_or_else(|| (self.sources[0].0.clone(), 1));
        ProfileError::Invalid { file, line, key, message }
    }
}

/// `extends = "NAME"` or `extends = "FILE"`: the parent's keys (its own
/// ancestors' first), the child's over them; tables merge key by key, any
/// other value replaces the parent's. `None`: the profile extends none.
/// `seen` holds the files being resolved, to report a cycle.
fn resolve_extends(text: &str, file: &str, path: Option<&Path>, seen: &mut Vec<PathBuf>) -> Result<Option<Chain>, ProfileError> {
    let mut table: toml::Table = toml::from_str(text).map_err(|e| from_toml(file, text, &e))?;
    let Some(ext) = table.remove("extends") else { return Ok(None) };
    let line = key_line(text, "extends");
    let bad = |message: String| ProfileError::Invalid { file: file.into(), line, key: "extends".into(), message };
    let parent = match ext.as_str().map(str::trim) {
        Some(s) if !s.is_empty() => s.to_string(),
        _ => return Err(bad("must be a profile name (tb/profiles/NAME.toml) or a .toml path".into())),
    };
    if !table.get("name").is_some_and(|n| n.as_str().is_some_and(|n| !n.trim().is_empty())) {
        return Err(ProfileError::Invalid {
            file: file.into(),
            line: 1,
            key: "name".into(),
            message: format!("a profile that extends `{parent}` needs its own name (its DUT is named after it)"),
        });
    }
    // A name as `--profile` takes it; a path relative to this file.
    let pp = Path::new(&parent);
    let parent_path = if parent.ends_with(".toml") || pp.components().count() > 1 {
        match path.and_then(Path::parent) {
            Some(dir) if pp.is_relative() => dir.join(pp),
            _ => pp.to_path_buf(),
        }
    } else {
        let f = shipped_dir().join(format!("{parent}.toml"));
        if !f.is_file() {
            return Err(bad(format!(
                "no profile named `{parent}` in {}; shipped profiles: {}",
                shipped_dir().display(),
                shipped_names().join(", ")
            )));
        }
        f
    };
    let key = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    if let Some(me) = path {
        if seen.is_empty() {
            seen.push(key(me));
        }
    }
    let pkey = key(&parent_path);
    if let Some(i) = seen.iter().position(|s| *s == pkey) {
        let names: Vec<String> = seen[i..].iter().chain([&pkey]).map(|p| p.display().to_string()).collect();
        return Err(bad(format!("`extends` makes a cycle: {}", names.join(" extends "))));
    }
    seen.push(pkey);
    let pfile = parent_path.display().to_string();
    let ptext = std::fs::read_to_string(&parent_path).map_err(|source| ProfileError::Io { file: pfile.clone(), source })?;
    let (mut merged, mut ancestors, mut sources) = match resolve_extends(&ptext, &pfile, Some(&parent_path), seen)? {
        Some(c) => (c.table, c.ancestors, c.sources),
        None => (toml::from_str(&ptext).map_err(|e| from_toml(&pfile, &ptext, &e))?, Vec::new(), vec![(pfile.clone(), ptext.clone())]),
    };
    let pname = merged.get("name").and_then(|n| n.as_str()).map(|n| n.trim().to_string()).unwrap_or_else(|| parent.clone());
    ancestors.insert(0, pname);
    merge_tables(&mut merged, table);
    sources.insert(0, (file.to_string(), text.to_string()));
    Ok(Some(Chain { table: merged, ancestors, sources }))
}

/// `over`'s keys into `base`: tables merge key by key, other values replace.
fn merge_tables(base: &mut toml::Table, over: toml::Table) {
    for (k, v) in over {
        match (base.get_mut(&k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge_tables(b, o),
            (_, v) => {
                base.insert(k, v);
            }
        }
    }
}

/// A core profile (`tb/profiles/NAME.toml`, or any file given to `--profile`).
/// Unknown keys are rejected; every error reads `file:line: key: message`.
#[derive(Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawProfile {
    /// The profile this one extends: a shipped profile's name (`tb/profiles/NAME.toml`,
    /// as `--profile NAME` finds it) or a `.toml` path relative to this file. Only the
    /// keys that differ are written: tables merge key by key, any other value replaces
    /// the parent's. The profile's *family* is its name and its ancestors' names; a
    /// waiver whose `dut` glob names any member of the family applies to its DUT, and
    /// the report says which member it matched through. A cycle is an error. Default:
    /// none (every required key written here).
    #[allow(dead_code)] // taken out before the rest is read (`resolve_extends`)
    extends: Option<String>,
    /// Name; an external core co-simulated with it is named `"<name> (<dir>)"` in
    /// reports, which waiver `dut` globs match. Required, also with `extends`.
    #[schemars(with = "String")]
    name: Spanned<String>,
    /// What the core is, one line for report headers. Required (inherited with `extends`).
    #[schemars(with = "String")]
    description: Spanned<String>,
    /// Where the bit timing's prescaler and bit counter start from:
    /// `"hardware-reset"` (they run from the hardware reset on, also in reset mode)
    /// or `"reset-mode-exit"` (they stand still in reset mode and start when it is left).
    phase_origin: OriginName,
    /// CAN clocks from the end of a quantum of the core's prescaler to its segment
    /// counters acting on it; a BTR write in reset mode landing within them redoes that
    /// quantum, and a transmission request made in bus idle within them after a sample
    /// point is taken at that sample point. At most 8; only with
    /// `phase-origin = "hardware-reset"`. Default: 0.
    #[schemars(with = "Option<u32>")]
    segment_lag: Option<Spanned<u32>>,
    /// SR.TS during suspend transmission (an error-passive transmitter's 8 recessive bits
    /// after intermission): `"set"` (the default: 1, still the transmitter) or `"clear"`
    /// (0, sending nothing). The datasheet's TS ("transmitting a message") leaves it open.
    ts_in_suspend: Option<TsInSuspend>,
    /// ECC after the host has read it, until the next bus error: `"kept"` (the default:
    /// the last code) or `"cleared"` (0). The datasheet re-arms the capture at the read
    /// and leaves the value open.
    ecc_after_read: Option<EccAfterRead>,
    /// How often the core's bit timing logic looks at the bus for edges: `"quantum"` (the
    /// default, as the model: once per time quantum) or `"clock"` (at every CAN clock, so a
    /// pulse shorter than a quantum can be an edge). Neither CAN 2.0B nor the datasheet says;
    /// with `"clock"` the random campaign makes its glitches whole quanta.
    edge_sampling: Option<EdgeSampling>,
    /// When a host access takes effect in the core, per host bus.
    access: RawAccessSet,
    /// The comparator's tolerances for this core, in CAN clocks (printed in every report).
    tolerances: RawTolerances,
    /// The top's ports by role, only those that differ from `can_top`'s Wishbone list.
    /// Default: `can_top`'s names and polarities.
    ports: Option<RawPorts>,
    /// How a core with `.vhd`/`.vhdl` sources goes through GHDL.
    /// Default: VHDL-93c, GHDL's `--elab-order` of every VHDL file in the directory.
    vhdl: Option<RawVhdl>,
}

/// `[vhdl]`: a core with VHDL sources (GHDL).
#[derive(Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawVhdl {
    /// Language revision: `"93"`, `"93c"` (GHDL's relaxed VHDL-93) or `"08"`. Default: `"93c"`.
    #[schemars(with = "Option<String>")]
    standard: Option<Spanned<String>>,
    /// VHDL files in analysis order, relative to the core's directory.
    /// Default: every `.vhd`/`.vhdl` there, in GHDL's `--elab-order`.
    #[serde(default)]
    files: Vec<String>,
    /// Extra GHDL options for analysis and synthesis (`["-fsynopsys"]`). Default: none.
    #[serde(default)]
    ghdl_args: Vec<String>,
}

#[derive(Deserialize, Clone, Copy, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
enum OriginName {
    HardwareReset,
    ResetModeExit,
}

#[derive(Deserialize, Clone, Copy, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
enum TsInSuspend {
    Set,
    Clear,
}

#[derive(Deserialize, Clone, Copy, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
enum EccAfterRead {
    Kept,
    Cleared,
}

/// `edge-sampling`: how often the core looks at the bus for edges.
#[derive(Deserialize, Clone, Copy, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
enum EdgeSampling {
    Quantum,
    Clock,
}

/// `[access]`: one table per host bus.
#[derive(Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
struct RawAccessSet {
    /// Wishbone (`--host wishbone`, the default). Required.
    wishbone: RawAccess,
    /// Avalon-MM (`--host avalon`, through a Wishbone bridge). Required.
    avalon: RawAccess,
    /// PIO, bit-banged Wishbone (`--host pio`). Required.
    pio: RawAccess,
    /// The 8051 bus (`--host i8051`): edges counted from the host edge raising RD or WR;
    /// `latch`, `busy-after-ack` and `count-from` are refused here.
    /// Default: the 1st CAN edge of the strobe for read, write and command.
    i8051: Option<RawAccess>,
    /// AXI4-Lite (`--host axi4-lite`): edges counted from the first host edge with
    /// AWVALID and WVALID, or ARVALID; also `stride` and `byte-lane`. Default: as wishbone.
    #[serde(rename = "axi4-lite")]
    axi4lite: Option<RawAccess>,
    /// APB (`--host apb`): edges counted from the first host edge of the access phase;
    /// also `stride` and `byte-lane`. Default: as wishbone.
    apb: Option<RawAccess>,
    /// The plain register port (`--host regport`): strobe length, read latency, idle
    /// clocks, one or separate addresses; edges counted from the clock edge presenting
    /// the strobe. Default: our `can_regport`'s, timing as wishbone.
    regport: Option<RawRegportAccess>,
    /// The Motorola bus (`--host motorola`): its phases in ns; edges counted from the
    /// host edge raising E. Default: the kit's phases (not the data sheet's), timing as
    /// `[access.i8051]`.
    motorola: Option<RawMotorolaAccess>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
enum Addresses {
    One,
    Separate,
}

/// `[access.regport]`: the plain register port. Every key is optional.
#[derive(Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawRegportAccess {
    /// As under `[access.wishbone]`, counted from the clock edge that presents the
    /// strobe. Default: the wishbone timing (our `can_regport` is `can_top` behind a
    /// combinational request).
    #[schemars(with = "Option<TakesEffect>")]
    takes_effect: Option<Spanned<TakesEffect>>,
    /// CAN edges until read data is captured (with `takes-effect = "can-edges"`).
    #[schemars(with = "Option<u32>")]
    read: Option<Spanned<u32>>,
    /// CAN edges until a register is written.
    #[schemars(with = "Option<u32>")]
    write: Option<Spanned<u32>>,
    /// CAN edges until a command (CMR write) is taken.
    #[schemars(with = "Option<u32>")]
    command: Option<Spanned<u32>>,
    /// Write and read strobes last this many clocks (1 to 64). Default 1.
    #[schemars(with = "Option<u32>")]
    strobe: Option<Spanned<u32>>,
    /// Read data is valid this many clocks after the read strobe rises and stays so
    /// until the next strobe (0 = combinational, in the strobe's own clock; at most
    /// 256). Default 14 (our `can_regport`, measured).
    #[schemars(with = "Option<u32>")]
    read_latency: Option<Spanned<u32>>,
    /// Idle clocks after every access (at most 256). Default 14.
    #[schemars(with = "Option<u32>")]
    gap: Option<Spanned<u32>>,
    /// `"one"`: one address port for both strobes (`[ports.regport] adr`);
    /// `"separate"`: a write and a read address (`wr-adr`, `rd-adr`). Default: one
    /// when the top has the `adr` port, else separate.
    #[schemars(with = "Option<Addresses>")]
    addresses: Option<Spanned<Addresses>>,
}

/// `[access.motorola]`: the Motorola bus. Every key is optional; a phase not given
/// keeps the kit's default (`bfm::MotorolaAcTiming`, E stretched to 18 CAN clocks
/// and recovery to 6 for `can_top_mcu`). Phases are minimums in ns, rounded up to
/// whole host cycles (at most 1000000).
#[derive(Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawMotorolaAccess {
    /// As under `[access.i8051]`, counted from the host edge raising E. Default: the
    /// `[access.i8051]` timing.
    #[schemars(with = "Option<TakesEffect>")]
    takes_effect: Option<Spanned<TakesEffect>>,
    /// CAN edges until read data is captured (with `takes-effect = "can-edges"`).
    #[schemars(with = "Option<u32>")]
    read: Option<Spanned<u32>>,
    /// CAN edges until a register is written.
    #[schemars(with = "Option<u32>")]
    write: Option<Spanned<u32>>,
    /// CAN edges until a command (CMR write) is taken.
    #[schemars(with = "Option<u32>")]
    command: Option<Spanned<u32>>,
    /// AS pulse width (the address set up meanwhile).
    #[schemars(with = "Option<u32>")]
    as_ns: Option<Spanned<u32>>,
    /// Address held after AS falls.
    #[schemars(with = "Option<u32>")]
    addr_hold_ns: Option<Spanned<u32>>,
    /// Read: the port released before E rises.
    #[schemars(with = "Option<u32>")]
    read_float_ns: Option<Spanned<u32>>,
    /// Write: data and R/W set up before E rises.
    #[schemars(with = "Option<u32>")]
    data_setup_ns: Option<Spanned<u32>>,
    /// E pulse width of a read.
    #[schemars(with = "Option<u32>")]
    e_read_ns: Option<Spanned<u32>>,
    /// E pulse width of a write.
    #[schemars(with = "Option<u32>")]
    e_write_ns: Option<Spanned<u32>>,
    /// Write: data, R/W and CS held after E falls.
    #[schemars(with = "Option<u32>")]
    data_hold_ns: Option<Spanned<u32>>,
    /// Idle time after an access.
    #[schemars(with = "Option<u32>")]
    recovery_ns: Option<Spanned<u32>>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
enum CountFrom {
    HostEdge,
    Wires,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
enum TakesEffect {
    AtAck,
    CanEdges,
}

/// `[access.BUS]`: when an access on this bus takes effect in the core.
#[derive(Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawAccess {
    /// `"at-ack"`: when the host sees the ack (no edge counts then); `"can-edges"`:
    /// after the `read`/`write`/`command`-th CAN clock rising edge strictly after the
    /// host edge that first presents the access. Required.
    #[schemars(with = "TakesEffect")]
    takes_effect: Spanned<TakesEffect>,
    /// CAN edges after which the core has committed to the access: a request dropped
    /// later is no abandoned transfer for the bus monitor. Default: when it takes effect.
    #[schemars(with = "Option<u32>")]
    latch: Option<Spanned<u32>>,
    /// `[CAN, host, CAN]` edges after an ack during which the core sees no new request
    /// (a handshake returning to idle); each at most 64. Default: a new request is seen at once.
    #[schemars(with = "Option<Vec<u32>>")]
    busy_after_ack: Option<Spanned<Vec<u32>>>,
    /// Where the edge counts start: `"host-edge"` (after the first host edge presenting
    /// cyc & stb: a core that registers the request in the host clock) or `"wires"` (at
    /// the first CAN edge after they appear on the wires). Default: `"host-edge"`.
    #[schemars(with = "Option<CountFrom>")]
    count_from: Option<Spanned<CountFrom>>,
    /// `[access.i8051]` only: the top has `inout [7:0] port_0_io`, wrapped in a shell that
    /// drives it while this Verilog expression of its inputs holds (`"cs_can_i & rd_i"`).
    /// Default: separate input and output ports.
    #[schemars(with = "Option<String>")]
    inout_drive: Option<Spanned<String>>,
    /// `[access.axi4-lite]` and `[access.apb]` only: bytes between registers (1, 2 or 4;
    /// register n at byte n * stride). Default 4.
    #[schemars(with = "Option<u32>")]
    stride: Option<Spanned<u32>>,
    /// `[access.axi4-lite]` and `[access.apb]` only: the byte lane of the 32-bit data
    /// bus that carries the register (0 to 3). Default 0.
    #[schemars(with = "Option<u32>")]
    byte_lane: Option<Spanned<u32>>,
    /// CAN edges until read data is captured (at most 64). Required with `"can-edges"`.
    #[schemars(with = "Option<u32>")]
    read: Option<Spanned<u32>>,
    /// CAN edges until a register is written (at most 64). Required with `"can-edges"`.
    #[schemars(with = "Option<u32>")]
    write: Option<Spanned<u32>>,
    /// CAN edges until a command (CMR write) is taken (at most 64). Required with `"can-edges"`.
    #[schemars(with = "Option<u32>")]
    command: Option<Spanned<u32>>,
}

/// `[tolerances]`: how far the core may be from the model, in CAN clocks (each at most 1000).
#[derive(Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawTolerances {
    /// tx is not compared this close to a model tx edge. Required.
    #[schemars(with = "u32")]
    tx_edge: Spanned<u32>,
    /// A start of frame from bus idle may lag the model's this much. Required.
    #[schemars(with = "u32")]
    sof: Spanned<u32>,
    /// SR, IR and (PeliCAN) RXERR, TXERR, RMC reads: a value the model held this recently is accepted. Required.
    #[schemars(with = "u32")]
    status: Spanned<u32>,
    /// The irq and bus-off pins may differ from the model's this long. Required.
    #[schemars(with = "u32")]
    pins: Spanned<u32>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
enum Active {
    High,
    Low,
}

/// A port: its name (`"clk"`), or for reset, irq and bus-off also its active level
/// (`{ name = "irq_o", active = "high" }`).
#[derive(Deserialize, schemars::JsonSchema)]
#[serde(untagged)]
enum RawPin {
    Name(String),
    Full { name: String, active: Active },
}

/// `[ports]`: the top's port for each role, only where it differs from `can_top`'s.
/// Active levels: reset active = in reset, irq active = interrupt pending,
/// bus-off active = while bus-off.
#[derive(Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
struct RawPorts {
    /// Host clock. Default: `wb_clk_i`.
    host_clock: Option<RawPin>,
    /// Reset. Default: `wb_rst_i`, active high.
    reset: Option<RawPin>,
    /// Write data, 8 bits. Default: `wb_dat_i`.
    dat_i: Option<RawPin>,
    /// Read data, 8 bits. Default: `wb_dat_o`.
    dat_o: Option<RawPin>,
    /// Wishbone cycle. Default: `wb_cyc_i`.
    cyc: Option<RawPin>,
    /// Wishbone strobe. Default: `wb_stb_i`.
    stb: Option<RawPin>,
    /// Write enable. Default: `wb_we_i`.
    we: Option<RawPin>,
    /// Address, 8 bits. Default: `wb_adr_i`.
    adr: Option<RawPin>,
    /// Acknowledge. Default: `wb_ack_o`.
    ack: Option<RawPin>,
    /// CAN clock. Default: `clk_i`.
    can_clock: Option<RawPin>,
    /// CAN receive. Default: `rx_i`.
    rx: Option<RawPin>,
    /// CAN transmit. Default: `tx_o`.
    tx: Option<RawPin>,
    /// Interrupt. Default: `irq_on`, active low.
    irq: Option<RawPin>,
    /// Bus-off indication. Default: `bus_off_on`, active low (high while on the bus).
    bus_off: Option<RawPin>,
    /// Clock output. Default: `clkout_o`.
    clkout: Option<RawPin>,
    /// `[ports.axi4-lite]`: the AXI4-Lite slave's ports by role, only those that
    /// differ from `can_axi4lite`'s: `clock` (`s_axi_aclk`), `reset` (`s_axi_aresetn`,
    /// active low; the only role with `active`), and `awvalid`, `awready`, `awaddr`,
    /// `awprot`, `wvalid`, `wready`, `wdata`, `wstrb`, `bvalid`, `bready`, `bresp`,
    /// `arvalid`, `arready`, `araddr`, `arprot`, `rvalid`, `rready`, `rdata`, `rresp`
    /// (default `s_axi_<role>`). The CAN-side roles above apply on every bus.
    #[serde(rename = "axi4-lite")]
    axi4lite: Option<std::collections::BTreeMap<String, RawPin>>,
    /// `[ports.apb]`: the APB completer's ports by role: `clock` (`pclk`), `reset`
    /// (`presetn`, active low; the only role with `active`), `psel`, `penable`, `pwrite`,
    /// `paddr`, `pwdata`, `pstrb`, `pprot` (APB4; bound when the top has them),
    /// `prdata`, `pready`, `pslverr` (default: the role's name).
    apb: Option<std::collections::BTreeMap<String, RawPin>>,
    /// `[ports.regport]`: the plain register port's ports by role: `reset` (`rst_i`),
    /// `wr` (`wr_i`), `rd` (`rd_i`) (these three with `active`, default high), `adr`
    /// (`adr_i`, one address) or `wr-adr` (`wr_adr_i`) and `rd-adr` (`rd_adr_i`),
    /// `wdat` (`wdat_i`), `rdat` (`rdat_o`). Its clock is `can-clock`.
    regport: Option<std::collections::BTreeMap<String, RawPin>>,
    /// `[ports.motorola]`: the Motorola bus's ports by role: `reset` (`rst_i`), `mode`
    /// (`mode_i`, active = Motorola mode selected, default low; bound when the top has
    /// it), `as` (`ale_as_i`), `cs` (`cs_can_i`), `e` (`rd_e_i`), `rw` (`wr_rw_i`,
    /// active = read, default high), `ad-i` (`port_0_i`), `ad-o` (`port_0_o`), `ad-oe`
    /// (`port_0_oe`, active = the core drives the port). All but the port's data take
    /// `active`. Its clock is `can-clock`.
    motorola: Option<std::collections::BTreeMap<String, RawPin>>,
}

/// The JSON schema of a profile file, for the generated reference
/// (`cancosim gen reference`): doc comments are the descriptions.
pub fn file_schema() -> schemars::Schema {
    schemars::schema_for!(RawProfile)
}

/// A profile of a fork of the opencores core with renamed ports, for the
/// reference (tested to load).
pub const EXAMPLE_FORK: &str = r#"# A fork of the opencores core: same timing, its own port names.
extends = "opencores-can"      # every key of tb/profiles/opencores-can.toml, and its waivers
name = "my-can"                # its DUT is "my-can (<dir>)"
description = "opencores can_top fork with a renamed top and ports"

[ports]                        # only what differs; the rest is inherited
can-clock = "clk"
tx = "can_tx"
rx = "can_rx"
irq = { name = "irq_o", active = "high" }
"#;

/// 1-based line of the last `key = ...` in `src` (1 if none).
fn key_line(src: &str, key: &str) -> usize {
    src.lines()
        .enumerate()
        .filter(|(_, l)| l.trim_start().strip_prefix(key).is_some_and(|r| r.trim_start().starts_with('=')))
        .map(|(i, _)| i + 1)
        .last()
        .unwrap_or(1)
}

/// 1-based line of `key = ...` inside `[table]` (else as [`key_line`]).
fn table_key_line(src: &str, table: &str, key: &str) -> usize {
    let header = format!("[{table}]");
    let lines: Vec<&str> = src.lines().collect();
    if let Some(h) = lines.iter().position(|l| l.trim() == header) {
        for (i, l) in lines.iter().enumerate().skip(h + 1) {
            let t = l.trim_start();
            if t.starts_with('[') {
                break;
            }
            let k = t.split('=').next().unwrap_or("").trim().trim_matches('"');
            if t.contains('=') && k == key {
                return i + 1;
            }
        }
    }
    key_line(src, key)
}

fn line_of(src: &str, at: usize) -> usize {
    src[..at.min(src.len())].bytes().filter(|b| *b == b'\n').count() + 1
}

/// A toml error as `file:line: key: message`: the key the message quotes
/// (missing/unknown field), else the key written on that line or the table
/// it is in.
fn from_toml(file: &str, src: &str, e: &toml::de::Error) -> ProfileError {
    let message = e.message().trim().to_string();
    let span = e.span().unwrap_or(0..0);
    let line = line_of(src, span.start);
    let quoted = (message.starts_with("missing field") || message.starts_with("unknown field"))
        .then(|| message.split('`').nth(1).map(str::to_string))
        .flatten();
    let key = quoted
        .or_else(|| {
            src.lines().take(line).collect::<Vec<_>>().iter().rev().find_map(|t| {
                let t = t.trim();
                if let Some(h) = t.strip_prefix('[').and_then(|t| t.strip_suffix(']')) {
                    return Some(h.trim().to_string());
                }
                let (k, _) = t.split_once('=')?;
                let k = k.trim();
                (!k.is_empty() && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')).then(|| k.to_string())
            })
        })
        .unwrap_or_else(|| "profile".into());
    ProfileError::Invalid { file: file.into(), line, key, message }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// rtl.toml is exactly what the bench assumed for our RTL before
    /// profiles existed: the can_wb_cdc timing on every bus, the phase
    /// from reset-mode exit, the default tolerances, can_top's ports.
    #[test]
    fn rtl_profile_is_the_old_default() {
        let p = Profile::rtl();
        let cdc = AccessTiming::CanEdges { read: 3, write: 4, command: 4 };
        assert_eq!((p.wishbone, p.avalon, p.pio), (cdc, cdc, cdc));
        assert_eq!(p.phase_origin, PhaseOrigin::ResetModeExit);
        assert_eq!(p.tolerances, CompareConfig::default());
        assert_eq!(p.ports, PortMap::default());
    }

    #[test]
    fn every_shipped_profile_parses() {
        let names = shipped_names();
        assert!(names.contains(&"rtl".to_string()) && names.contains(&"opencores-can".to_string()), "{names:?}");
        for n in names {
            Profile::find(&n).unwrap_or_else(|e| panic!("{e}"));
        }
        let oc = Profile::find("opencores-can").unwrap();
        assert_eq!(oc.name, "opencores-can");
        assert_eq!(oc.phase_origin, PhaseOrigin::HardwareReset);
        let hold = Some(BusyAfterAck { can: 3, host: 3, can_again: 2 });
        assert_eq!(oc.holdoff, Holdoff { wishbone: hold, avalon: hold, pio: hold });
        assert_eq!(Profile::rtl().holdoff, Holdoff::default(), "our RTL takes a new request at once");
    }

    #[test]
    fn count_from_wires_is_per_bus_printed_and_refused_on_the_8051_bus() {
        let p = Profile::parse(&GOOD.replace("[access.pio]\n", "[access.pio]\ncount-from = \"wires\"\n"), "p.toml").unwrap();
        assert_eq!(p.count_from_wires, CountFromWires { wishbone: false, avalon: false, pio: true });
        assert!(p.describe().contains(" counted from the wires"), "{}", p.describe());
        let p = Profile::parse(&GOOD.replace("[access.pio]\n", "[access.pio]\ncount-from = \"host-edge\"\n"), "p.toml").unwrap();
        assert_eq!(p.count_from_wires, CountFromWires::default());
        assert!(!p.describe().contains("wires"));
        let e = err(&GOOD.replace("[access.pio]\n", "[access.pio]\ncount-from = \"wire\"\n"));
        assert!(e.starts_with("p.toml:"), "{e}");
        let e = err(&GOOD.replace("[tolerances]", "[access.i8051]\ntakes-effect = \"at-ack\"\ncount-from = \"wires\"\n[tolerances]"));
        assert!(e.contains("access.i8051: count-from is not used"), "{e}");
    }

    #[test]
    fn busy_after_ack_needs_three_counts() {
        let ok = Profile::parse(&GOOD.replace("[access.pio]\n", "[access.pio]\nbusy-after-ack = [3, 3, 2]\n"), "p.toml").unwrap();
        assert_eq!(ok.holdoff.pio, Some(BusyAfterAck { can: 3, host: 3, can_again: 2 }));
        assert_eq!(ok.holdoff.wishbone, None);
        let e = err(&GOOD.replace("[access.pio]\n", "[access.pio]\nbusy-after-ack = [3, 3]\n"));
        assert!(e.starts_with("p.toml:9: access.pio: busy-after-ack needs"), "{e}");
        let e = err(&GOOD.replace("[access.pio]\n", "[access.pio]\nbusy-after-ack = [3, 300, 2]\n"));
        assert!(e.contains("at most 64"), "{e}");
    }

    fn err(text: &str) -> String {
        Profile::parse(text, "p.toml").unwrap_err().to_string()
    }

    const GOOD: &str = "name = \"x\"\ndescription = \"d\"\nphase-origin = \"hardware-reset\"\n\
        [access.wishbone]\ntakes-effect = \"at-ack\"\n[access.avalon]\ntakes-effect = \"at-ack\"\n\
        [access.pio]\ntakes-effect = \"can-edges\"\nread = 3\nwrite = 3\ncommand = 3\n\
        [tolerances]\ntx-edge = 4\nsof = 40\nstatus = 48\npins = 48\n";

    #[test]
    fn bad_profiles_name_file_line_and_key() {
        assert!(Profile::parse(GOOD, "p.toml").is_ok());
        assert_eq!(err(&GOOD.replace("sof = 40", "sof = 40\nsofa = 1")), "p.toml:16: sofa: unknown field `sofa`, expected one of `tx-edge`, `sof`, `status`, `pins`");
        let e = err(&GOOD.replace("hardware-reset", "power-on"));
        assert!(e.starts_with("p.toml:3: phase-origin: unknown variant `power-on`"), "{e}");
        let e = err(&GOOD.replace("read = 3\n", ""));
        assert!(e.starts_with("p.toml:9: access.pio: ") && e.contains("needs `read`"), "{e}");
        let e = err(&GOOD.replace("[access.avalon]\ntakes-effect = \"at-ack\"", "[access.avalon]\ntakes-effect = \"at-ack\"\nread = 2"));
        assert!(e.starts_with("p.toml:8: access.avalon: "), "{e}");
        let e = err(&GOOD.replace("pins = 48\n", ""));
        assert!(e.starts_with("p.toml:13: pins: missing field `pins`"), "{e}");
        let e = err(&format!("{GOOD}[ports]\ntx = {{ name = \"t\", active = \"low\" }}\n"));
        assert!(e.starts_with("p.toml:19: tx: only reset, irq and bus-off"), "{e}");
        let e = err(&format!("{GOOD}[ports]\nirq = {{ name = \"i\", active = \"sideways\" }}\n"));
        assert!(e.starts_with("p.toml:19: irq: "), "{e}");
    }

    #[test]
    fn i8051_access_and_inout_drive() {
        assert_eq!((Profile::parse(GOOD, "p").unwrap().i8051, Profile::parse(GOOD, "p").unwrap().i8051_inout_drive), (None, None));
        let p = Profile::parse(&GOOD.replace("[tolerances]", "[access.i8051]\ntakes-effect = \"can-edges\"\nread = 1\nwrite = 1\ncommand = 0\ninout-drive = \"cs_can_i & rd_i\"\n[tolerances]"), "p").unwrap();
        assert_eq!(p.i8051, Some(AccessTiming::CanEdges { read: 1, write: 1, command: 0 }));
        assert_eq!(p.i8051_inout_drive.as_deref(), Some("cs_can_i & rd_i"));
        assert!(p.describe().contains("8051 bus: read/write/command after CAN edge 1/1/0, inout port_0_io driven when cs_can_i & rd_i"), "{}", p.describe());
        let e = err(&GOOD.replace("[access.avalon]\n", "[access.avalon]\ninout-drive = \"x\"\n"));
        assert!(e.starts_with("p.toml:7: access.avalon: inout-drive belongs to [access.i8051]"), "{e}");
        let e = err(&GOOD.replace("[tolerances]", "[access.i8051]\ntakes-effect = \"at-ack\"\nlatch = 1\n[tolerances]"));
        assert!(e.contains("access.i8051: latch and busy-after-ack"), "{e}");
    }

    #[test]
    fn vhdl_table_sets_standard_files_and_args() {
        assert_eq!(Profile::parse(GOOD, "p.toml").unwrap().vhdl, crate::vhdl::VhdlOptions::default());
        let p = Profile::parse(&format!("{GOOD}[vhdl]\nstandard = \"08\"\nfiles = [\"a.vhd\", \"b.vhd\"]\nghdl-args = [\"-fsynopsys\"]\n"), "p").unwrap();
        assert_eq!(p.vhdl.standard, crate::vhdl::VhdlStandard::V08);
        assert_eq!(p.vhdl.files, vec![PathBuf::from("a.vhd"), PathBuf::from("b.vhd")]);
        assert_eq!(p.vhdl.ghdl_args, vec!["-fsynopsys".to_string()]);
        let e = err(&format!("{GOOD}[vhdl]\nstandard = \"2019\"\n"));
        assert!(e.starts_with("p.toml:19: standard: `2019`: expected"), "{e}");
        let e = err(&format!("{GOOD}[vhdl]\nstd = \"08\"\n"));
        assert!(e.starts_with("p.toml:19: std: unknown field"), "{e}");
    }

    #[test]
    fn ts_in_suspend_is_set_unless_declared_clear() {
        assert!(!Profile::rtl().ts_clear_in_suspend);
        assert!(!Profile::parse(GOOD, "p.toml").unwrap().ts_clear_in_suspend);
        let oc = Profile::find("opencores-can").unwrap();
        assert!(oc.ts_clear_in_suspend && oc.describe().contains("SR.TS 0 in suspend transmission"), "{}", oc.describe());
        let p = |v: &str| Profile::parse(&GOOD.replacen("\n[", &format!("\nts-in-suspend = {v:?}\n["), 1), "p.toml");
        assert!(!p("set").unwrap().ts_clear_in_suspend);
        assert!(p("clear").unwrap().ts_clear_in_suspend);
        assert!(p("sometimes").is_err());
    }

    #[test]
    fn ecc_is_kept_after_a_read_unless_declared_cleared() {
        assert!(!Profile::rtl().ecc_clear_on_read);
        assert!(!Profile::parse(GOOD, "p.toml").unwrap().ecc_clear_on_read);
        let oc = Profile::find("opencores-can").unwrap();
        assert!(oc.ecc_clear_on_read && oc.describe().contains("ECC cleared by a read"), "{}", oc.describe());
        let p = |v: &str| Profile::parse(&GOOD.replacen("\n[", &format!("\necc-after-read = {v:?}\n["), 1), "p.toml");
        assert!(!p("kept").unwrap().ecc_clear_on_read);
        assert!(p("cleared").unwrap().ecc_clear_on_read);
        let e = |v: &str| Profile::parse(&GOOD.replacen("\n[", &format!("\nedge-sampling = {v:?}\n["), 1), "p.toml");
        assert!(!Profile::rtl().edges_every_clock && !e("quantum").unwrap().edges_every_clock);
        assert!(e("clock").unwrap().edges_every_clock);
        assert!(e("clock").unwrap().describe().contains("edges seen at every CAN clock"));
        assert!(e("sometimes").is_err(), "an unknown value is rejected");
        assert!(p("zero").is_err());
    }

    #[test]
    fn segment_lag_is_for_a_running_bit_timing_only() {
        assert_eq!(Profile::parse(GOOD, "p.toml").unwrap().segment_lag, 0);
        assert_eq!(Profile::rtl().segment_lag, 0);
        assert_eq!(Profile::find("opencores-can").unwrap().segment_lag, 2);
        let p = Profile::parse(&GOOD.replace("phase-origin = \"hardware-reset\"\n", "phase-origin = \"hardware-reset\"\nsegment-lag = 2\n"), "p").unwrap();
        assert_eq!(p.segment_lag, 2);
        assert!(p.describe().contains("a BTR write in reset mode landing within them redoes that quantum"), "{}", p.describe());
        let e = err(&GOOD.replace("phase-origin = \"hardware-reset\"\n", "phase-origin = \"reset-mode-exit\"\nsegment-lag = 2\n"));
        assert!(e.starts_with("p.toml:4: segment-lag: 2: only with phase-origin = \"hardware-reset\""), "{e}");
        let e = err(&GOOD.replace("phase-origin = \"hardware-reset\"\n", "phase-origin = \"hardware-reset\"\nsegment-lag = 9\n"));
        assert!(e.starts_with("p.toml:4: segment-lag: 9: at most 8"), "{e}");
        let e = err(&GOOD.replace("phase-origin = \"hardware-reset\"\n", "phase-origin = \"hardware-reset\"\nsegment-lag = -1\n"));
        assert!(e.starts_with("p.toml:4: segment-lag: "), "{e}");
    }

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let f = dir.join(name);
        std::fs::write(&f, text).unwrap();
        f
    }

    #[test]
    fn a_fork_extends_a_shipped_profile_with_only_its_own_ports() {
        let d = tempfile::tempdir().unwrap();
        let f = write(
            d.path(),
            "fork.toml",
            "extends = \"opencores-can\"\nname = \"my-fork\"\n[ports]\ncan-clock = \"clk\"\ntx = \"can_tx\"\n[tolerances]\nsof = 3\n",
        );
        let fork = Profile::load(&f).unwrap();
        let oc = Profile::find("opencores-can").unwrap();
        assert_eq!(fork.name, "my-fork");
        assert_eq!(fork.ancestors, vec!["opencores-can".to_string()]);
        assert_eq!((fork.ports.can_clock.name.as_str(), fork.ports.tx.name.as_str()), ("clk", "can_tx"));
        assert_eq!(fork.ports.irq, oc.ports.irq, "a port it does not name stays the parent's");
        // Nested tables merge key by key: [tolerances] keeps the parent's other three.
        assert_eq!(fork.tolerances, CompareConfig { sof_tolerance: 3, ..oc.tolerances.clone() });
        // Everything else is the parent's.
        let same = Profile {
            name: oc.name.clone(),
            ancestors: Vec::new(),
            file: oc.file.clone(),
            ports: oc.ports.clone(),
            tolerances: oc.tolerances.clone(),
            ..fork.clone()
        };
        assert_eq!(same, oc);
        assert!(fork.describe().contains("profile my-fork (") && fork.describe().contains(", extends opencores-can:"), "{}", fork.describe());
    }

    #[test]
    fn extends_follows_a_chain_of_files_relative_to_each() {
        let d = tempfile::tempdir().unwrap();
        std::fs::create_dir(d.path().join("base")).unwrap();
        write(&d.path().join("base"), "mid.toml", "extends = \"rtl\"\nname = \"mid\"\n[access.pio]\nwrite = 5\n");
        let f = write(d.path(), "leaf.toml", "extends = \"base/mid.toml\"\nname = \"leaf\"\ndescription = \"a leaf\"\n");
        let leaf = Profile::load(&f).unwrap();
        assert_eq!(leaf.ancestors, vec!["mid".to_string(), "rtl".to_string()]);
        assert_eq!(leaf.description, "a leaf");
        assert_eq!(leaf.pio, AccessTiming::CanEdges { read: 3, write: 5, command: 4 });
        assert_eq!(leaf.wishbone, Profile::rtl().wishbone);
    }

    #[test]
    fn an_extends_cycle_is_an_error_naming_the_files() {
        let d = tempfile::tempdir().unwrap();
        write(d.path(), "a.toml", "extends = \"b.toml\"\nname = \"a\"\n");
        write(d.path(), "b.toml", "extends = \"a.toml\"\nname = \"b\"\n");
        let e = Profile::load(d.path().join("a.toml")).unwrap_err().to_string();
        assert!(e.contains("b.toml:1: extends: `extends` makes a cycle: ") && e.contains("a.toml extends ") && e.ends_with("a.toml"), "{e}");
        write(d.path(), "self.toml", "extends = \"self.toml\"\nname = \"s\"\n");
        let e = Profile::load(d.path().join("self.toml")).unwrap_err().to_string();
        assert!(e.contains("makes a cycle"), "{e}");
    }

    #[test]
    fn bad_extends_say_where_and_why() {
        let d = tempfile::tempdir().unwrap();
        let e = Profile::load(write(d.path(), "x.toml", "name = \"x\"\nextends = \"no-such-core\"\n")).unwrap_err().to_string();
        assert!(e.contains("x.toml:2: extends: no profile named `no-such-core`") && e.contains("opencores-can"), "{e}");
        let e = Profile::load(write(d.path(), "y.toml", "extends = \"rtl\"\n")).unwrap_err().to_string();
        assert!(e.contains("y.toml:1: name: a profile that extends `rtl` needs its own name"), "{e}");
        // A bad value is reported in the file that writes it, an unknown key too.
        let e = Profile::load(write(d.path(), "z.toml", "extends = \"rtl\"\nname = \"z\"\n\n[tolerances]\nsof = 5000\n")).unwrap_err().to_string();
        assert!(e.contains("z.toml:5: sof: 5000 CAN clocks: at most 1000"), "{e}");
        let e = Profile::load(write(d.path(), "w.toml", "extends = \"rtl\"\nname = \"w\"\nsofa = 1\n")).unwrap_err().to_string();
        assert!(e.contains("w.toml:3: sofa: unknown field"), "{e}");
    }

    #[test]
    fn the_reference_example_loads_and_renames_only_ports() {
        let p = Profile::parse(EXAMPLE_FORK, "example").unwrap();
        assert_eq!((p.name.as_str(), p.ancestors.as_slice()), ("my-can", ["opencores-can".to_string()].as_slice()));
        assert_eq!(p.ports.describe(), "can-clock = clk, rx = can_rx, tx = can_tx, irq = irq_o active high");
        let s = file_schema().as_value().to_string();
        assert!(s.contains("\"extends\"") && s.contains("family"), "the schema documents extends and families");
    }

    #[test]
    fn bus_port_tables_bind_roles_with_levels_and_refuse_unknown_ones() {
        let p = Profile::parse(
            &format!("{GOOD}[ports]\ncan-clock = \"clk\"\n[ports.regport]\nwr = {{ name = \"we_n\", active = \"low\" }}\nadr = \"addr\"\n[ports.apb]\nclock = \"PCLK\"\n"),
            "p",
        )
        .unwrap();
        assert_eq!(*p.ports.regport.pin("wr"), Pin::new("we_n", false));
        assert_eq!(p.ports.regport.pin("rd").name, "rd_i", "a role not named keeps can_regport's port");
        assert!(p.ports.regport.required("adr") && !p.ports.regport.required("wr-adr"));
        assert_eq!(p.ports.apb.pin("clock").name, "PCLK");
        assert_eq!(*p.ports.apb.pin("reset"), Pin::new("presetn", false));
        assert_eq!(p.ports.describe(), "can-clock = clk, apb.clock = PCLK, regport.wr = we_n active low, regport.adr = addr");
        let e = err(&format!("{GOOD}[ports.regport]\nwrr = \"x\"\n"));
        assert!(e.starts_with("p.toml:19: wrr: unknown field `wrr` of [ports.regport], expected one of `reset`, `wr`"), "{e}");
        let e = err(&format!("{GOOD}[ports]\nreset = \"r\"\n[ports.axi4-lite]\nreset = \"a\"\nawvalid = {{ name = \"v\", active = \"low\" }}\n"));
        assert!(e.starts_with("p.toml:22: awvalid: only reset have a polarity"), "{e}");
        let e = err(&format!("{GOOD}[ports.regport]\nadr = \"a\"\nwr-adr = \"w\"\n"));
        assert!(e.starts_with("p.toml:19: adr: one address (adr) or a write and a read address"), "{e}");
        let e = err(&format!("{GOOD}[ports.motorola]\nad-o = \"\"\n"));
        assert!(e.starts_with("p.toml:19: ad-o: the port name must not be empty"), "{e}");
    }

    #[test]
    fn regport_and_motorola_access_tables_set_the_bus_timing() {
        let p = Profile::parse(GOOD, "p").unwrap();
        assert_eq!(p.regport.config(), bfm::RegportConfig::default(), "no table: can_regport's");
        let base = crate::i8051_timing_for_rtl(24_000_000, 24_000_000);
        assert_eq!(p.motorola.cycles(base, 24_000_000), base, "no table: the bench's phases");
        let p = Profile::parse(
            &GOOD.replace(
                "[tolerances]",
                "[access.regport]\nstrobe = 2\nread-latency = 0\ngap = 3\naddresses = \"one\"\ntakes-effect = \"can-edges\"\nread = 1\nwrite = 2\ncommand = 2\n\
                 [access.motorola]\ne-read-ns = 1000\nrecovery-ns = 1\n[tolerances]",
            ),
            "p",
        )
        .unwrap();
        let c = p.regport.config();
        assert_eq!((c.strobe, c.read_latency, c.gap, c.separate_addr), (2, 0, 3, false));
        assert_eq!(p.regport.timing, Some(AccessTiming::CanEdges { read: 1, write: 2, command: 2 }));
        let t = p.motorola.cycles(base, 24_000_000);
        assert_eq!((t.rd, t.recovery, t.wr, t.ale), (24, 1, base.wr, base.ale), "1000 ns at 24 MHz: 24 cycles; the rest kept");
        assert!(p.describe().contains("register port: read/write/command after CAN edge 1/2/2, strobes 2 clocks, read data 0 clocks after the strobe, 3 idle clocks, one address"), "{}", p.describe());
        assert!(p.describe().contains("Motorola bus: as the 8051 bus, e-read-ns 1000, recovery-ns 1"), "{}", p.describe());
        let e = err(&GOOD.replace("[tolerances]", "[access.regport]\nstrobe = 0\n[tolerances]"));
        assert!(e.starts_with("p.toml:14: access.regport: strobe 0: 1 to 64 clocks"), "{e}");
        let e = err(&GOOD.replace("[tolerances]", "[access.regport]\nlatency = 3\n[tolerances]"));
        assert!(e.starts_with("p.toml:14: latency: unknown field `latency`"), "{e}");
        let e = err(&GOOD.replace("[tolerances]", "[access.motorola]\nread = 3\n[tolerances]"));
        assert!(e.starts_with("p.toml:14: access.motorola: read, write and command need takes-effect"), "{e}");
        let e = err(&GOOD.replace("[tolerances]", "[access.motorola]\nas = 3\n[tolerances]"));
        assert!(e.starts_with("p.toml:14: as: unknown field `as`"), "{e}");
        let e = err(&format!("{}[ports.regport]\nadr = \"a\"\n", GOOD.replace("[tolerances]", "[access.regport]\naddresses = \"separate\"\n[tolerances]")));
        assert!(e.starts_with("p.toml:14: access.regport: addresses = \"separate\" but [ports.regport] names adr"), "{e}");
    }

    #[test]
    fn the_fork_fixture_profiles_load() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tb/fixtures/fork");
        for f in ["regport", "regport-wrong-latency", "apb", "axi4-lite", "motorola"] {
            Profile::load(dir.join(format!("{f}.toml"))).unwrap_or_else(|e| panic!("{e}"));
        }
        let wrong = Profile::load(dir.join("regport-wrong-latency.toml")).unwrap();
        let right = Profile::load(dir.join("regport.toml")).unwrap();
        assert_eq!((right.regport.config().read_latency, wrong.regport.config().read_latency), (22, 14));
        assert_eq!(Profile { name: right.name.clone(), ancestors: right.ancestors.clone(), file: right.file.clone(), description: right.description.clone(), regport: right.regport, ..wrong.clone() }, right, "the two differ in the read latency only");
    }

    #[test]
    fn ports_map_names_and_polarities() {
        let p = Profile::parse(&format!("{GOOD}[ports]\nirq = {{ name = \"irq_o\", active = \"high\" }}\ncan-clock = \"clk\"\n"), "p").unwrap();
        assert_eq!(p.ports.irq, Pin::new("irq_o", true));
        assert_eq!(p.ports.can_clock.name, "clk");
        assert_eq!(p.ports.describe(), "can-clock = clk, irq = irq_o active high");
    }
}
