//! Devices under test: anything with the `can_top` pins (or the Avalon
//! wrapper's), stepped by the kernel. Implemented by Verilated tops
//! ([`VerilatedDut`]), by the golden model wrapped as a Wishbone slave
//! (`ModelDut`, in [`crate::model`]), and by [`EchoModel`], a Rust twin of
//! the `cosim_echo` fixture so the kernel and comparator run without
//! Verilator.

use std::path::Path;

use bfm::{AvMasterOut, AvSlaveOut, I8051Out, I8051SlaveOut, WbMasterOut, WbSlaveOut};

use crate::bridge::{BatchPins, BridgeError, Model, Port};

/// Which host interface a DUT has natively.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HostPort {
    /// The opencores `can_top` Wishbone port list.
    Wishbone,
    /// Our `can_avalon` wrapper (address, chipselect, read, write, ...).
    Avalon,
    /// The 8051 multiplexed bus (`rst_i ale_i cs_can_i rd_i wr_i`, all
    /// active high, and the shared port: `port_0_i`/`port_0_o`/`port_0_oe`
    /// as on our `can_top_8051`). Sampled by `clk_i`: no host clock port.
    I8051,
}

/// The CAN-side outputs of a DUT.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CanPins {
    /// `tx_o`: `true` = recessive.
    pub tx: bool,
    /// `irq_on`: active low (`false` = interrupt pending).
    pub irq_n: bool,
    /// `bus_off_on`: `true` while on the bus, `false` while bus-off.
    pub bus_on: bool,
    /// `clkout_o`.
    pub clkout: bool,
}

/// A device the kernel can step. Inputs set with `set_*` take effect at the
/// next [`Dut::eval`]; outputs read after it.
pub trait Dut {
    /// What it is, for reports.
    fn name(&self) -> String;
    /// Native host interface (default: Wishbone).
    fn host_port(&self) -> HostPort {
        HostPort::Wishbone
    }
    /// Host-side reset (`wb_rst_i` / `reset`), active high.
    fn set_reset(&mut self, on: bool);
    /// Wishbone pins (ignored by an Avalon DUT).
    fn set_wb(&mut self, m: &WbMasterOut);
    /// Wishbone slave outputs (default for an Avalon DUT).
    fn wb(&self) -> WbSlaveOut;
    /// Avalon pins (ignored by a Wishbone DUT, the default).
    fn set_av(&mut self, _m: &AvMasterOut) {}
    /// Avalon slave outputs (idle for a Wishbone DUT, the default).
    fn av(&self) -> AvSlaveOut {
        AvSlaveOut::default()
    }
    /// 8051-bus pins (ignored by other DUTs, the default).
    fn set_i8051(&mut self, _m: &I8051Out) {}
    /// 8051-bus slave outputs (port not driven for other DUTs, the default).
    fn i8051(&self) -> I8051SlaveOut {
        I8051SlaveOut::default()
    }
    /// `rx_i`: `true` = recessive.
    fn set_rx(&mut self, rx: bool);
    /// CAN-side outputs.
    fn can(&self) -> CanPins;
    /// New clock levels (host clock `wb_clk_i`, CAN clock `clk_i`); the DUT
    /// reacts to their rising edges.
    fn eval(&mut self, host_clk: bool, can_clk: bool);
    /// Start a VCD of the DUT's internals (Verilated DUTs only).
    fn trace_open(&mut self, path: &Path) -> Result<(), BridgeError> {
        Err(BridgeError::Trace {
            path: path.display().to_string(),
            reason: format!("{} has no internal trace", self.name()),
        })
    }
    /// Dump the internal trace at `t_ps` (no-op without a trace).
    fn trace_dump(&mut self, _t_ps: u64) {}
}

struct WbPorts {
    clk: Port,
    rst: Port,
    dat_i: Port,
    dat_o: Port,
    cyc: Port,
    stb: Port,
    we: Port,
    adr: Port,
    ack: Port,
}

struct AvPorts {
    clk: Port,
    reset: Port,
    address: Port,
    chipselect: Port,
    read: Port,
    write: Port,
    writedata: Port,
    readdata: Port,
    waitrequest: Port,
}

struct I8051Ports {
    rst: Port,
    ale: Port,
    cs: Port,
    rd: Port,
    wr: Port,
    port_i: Port,
    port_o: Port,
    port_oe: Port,
}

enum HostPorts {
    Wb(WbPorts),
    Av(AvPorts),
    I8051(I8051Ports),
}

/// A Verilated top with the `can_top` Wishbone port list or the
/// `can_avalon` port list.
pub struct VerilatedDut {
    m: Model,
    host: HostPorts,
    can_clk: Port,
    rx: Port,
    tx: Port,
    irq: Port,
    /// The Avalon wrapper's `irq` is active high; `can_top`'s `irq_on` low.
    irq_active_high: bool,
    bus_off_on: Port,
    clkout: Port,
    /// Outputs read once after each eval: `can()`/`wb()`/`av()` are called
    /// several times per tick and must not go back to the ports each time.
    out: OutCache,
    /// Last values written to the host inputs, to write only changes.
    wb_in: Option<WbMasterOut>,
}

/// The DUT's outputs as of the last eval.
#[derive(Clone, Copy, Debug, Default)]
struct OutCache {
    can: CanPins,
    wb: WbSlaveOut,
    av: AvSlaveOut,
    i8051: I8051SlaveOut,
}

impl VerilatedDut {
    /// Reads every output pin into the cache (after each eval); returns
    /// the CAN-side pins (from registers: the caller need not read back
    /// the cache it just wrote, byte by byte).
    #[inline]
    fn refresh(&mut self) -> CanPins {
        let m = &self.m;
        // Every port was bound from this model with a width of 1 or 8 (see
        // `new`); `model()` could have swapped the model: `eval` checks.
        debug_assert!(m.owns(self.tx));
        // SAFETY: ports of `m`, 8 bits or fewer (checked above and at bind).
        let get = |p: Port| unsafe { m.get_u8_unchecked(p) };
        let irq = get(self.irq) != 0;
        let can = CanPins {
            tx: get(self.tx) != 0,
            irq_n: if self.irq_active_high { !irq } else { irq },
            bus_on: get(self.bus_off_on) != 0,
            clkout: get(self.clkout) != 0,
        };
        self.out.can = can;
        match &self.host {
            HostPorts::Wb(w) => {
                self.out.wb = WbSlaveOut {
                    ack: get(w.ack) != 0,
                    dat: get(w.dat_o),
                    err: false,
                    rty: false,
                }
            }
            HostPorts::Av(a) => {
                self.out.av = AvSlaveOut {
                    readdata: get(a.readdata),
                    waitrequest: get(a.waitrequest) != 0,
                    readdatavalid: false,
                }
            }
            HostPorts::I8051(p) => {
                self.out.i8051 = I8051SlaveOut {
                    ad: get(p.port_o),
                    ad_oe: get(p.port_oe) != 0,
                }
            }
        }
        can
    }

    /// Makes `levels.len()` instants in one call while only the clocks
    /// and `rx` drive the inputs, `rx` taking at each CAN rising edge the
    /// level given, or (`None`) the DUT's own `tx` (see `bridge::Batch` for the encodings); returns how many were
    /// made: it stops after an instant that changed the Wishbone outputs,
    /// or, with `stop_on_irq`, that shows an interrupt pending. `None` for
    /// a DUT without the Wishbone port list. The output cache is left as it
    /// was before the call: [`VerilatedDut::sync_outputs`] brings it up to date.
    pub(crate) fn run_batch(
        &mut self,
        levels: &[u8],
        out: &mut [u8],
        rx: Option<bool>,
        stop_on_irq: bool,
    ) -> Option<usize> {
        let HostPorts::Wb(w) = &self.host else {
            return None;
        };
        assert!(out.len() >= levels.len());
        let pins = BatchPins {
            host_clk: w.clk,
            can_clk: self.can_clk,
            rx: self.rx,
            tx: self.tx,
            irq: self.irq,
            bus_off: self.bus_off_on,
            clkout: self.clkout,
            ack: w.ack,
            dat: w.dat_o,
        };
        assert!(
            self.m.owns(w.clk) && self.m.owns(self.tx),
            "VerilatedDut: the model was replaced"
        );
        // An interrupt pending is `irq_n` low.
        let stop = stop_on_irq.then_some(self.irq_active_high);
        // SAFETY: every port above was bound from this model in `new` with
        // a width of 1 or 8; `out` is long enough (asserted).
        Some(unsafe { self.m.run_batch(&pins, levels, out, rx, stop) })
    }

    /// The CAN-side pins of one `out` byte of [`VerilatedDut::run_batch`]
    /// (`irq_active_high`: [`VerilatedDut::irq_active_high`]).
    #[inline]
    pub(crate) fn batch_pins(o: u8, irq_active_high: bool) -> CanPins {
        let irq = o & 2 != 0;
        CanPins {
            tx: o & 1 != 0,
            irq_n: if irq_active_high { !irq } else { irq },
            bus_on: o & 4 != 0,
            clkout: o & 8 != 0,
        }
    }

    /// The top's interrupt output is active high (`can_avalon`'s `irq`).
    pub(crate) fn irq_active_high(&self) -> bool {
        self.irq_active_high
    }

    /// Reads every output into the cache (after a batch).
    pub(crate) fn sync_outputs(&mut self) {
        let _ = self.refresh();
    }

    /// [`Dut::eval`], returning the CAN-side pins after it.
    #[inline]
    pub fn eval_pins(&mut self, host_clk: bool, can_clk: bool) -> CanPins {
        let hc = match &self.host {
            HostPorts::Wb(w) => Some(w.clk),
            HostPorts::Av(a) => Some(a.clk),
            // The 8051 bus has no clock: clk_i samples it.
            HostPorts::I8051(_) => None,
        };
        let cc = self.can_clk;
        assert!(self.m.owns(cc), "VerilatedDut: the model was replaced");
        // SAFETY: both clocks are 1-bit ports of this model (bound in `new`).
        unsafe {
            if let Some(hc) = hc {
                self.m.set_bit_unchecked(hc, host_clk);
            }
            self.m.set_bit_unchecked(cc, can_clk);
        }
        self.m.eval();
        self.refresh()
    }

    /// Binds a model with the given host port list. Missing ports or wrong
    /// widths are reported in one paragraph listing the ports it has.
    pub fn new(m: Model, kind: HostPort) -> Result<VerilatedDut, BridgeError> {
        // The CAN-side pins differ only in name (and irq polarity) between
        // the two tops: (can clock, rx, tx, irq, bus_off_on, clkout).
        let (host, can_names, irq_active_high, k) = match kind {
            HostPort::Wishbone => {
                let k = "can_top Wishbone";
                let p = |n: &str, w: u32| m.port(n, Some(w), k);
                let host = HostPorts::Wb(WbPorts {
                    clk: p("wb_clk_i", 1)?,
                    rst: p("wb_rst_i", 1)?,
                    dat_i: p("wb_dat_i", 8)?,
                    dat_o: p("wb_dat_o", 8)?,
                    cyc: p("wb_cyc_i", 1)?,
                    stb: p("wb_stb_i", 1)?,
                    we: p("wb_we_i", 1)?,
                    adr: p("wb_adr_i", 8)?,
                    ack: p("wb_ack_o", 1)?,
                });
                (
                    host,
                    ["clk_i", "rx_i", "tx_o", "irq_on", "bus_off_on", "clkout_o"],
                    false,
                    k,
                )
            }
            HostPort::Avalon => {
                let k = "can_avalon";
                let p = |n: &str, w: u32| m.port(n, Some(w), k);
                let host = HostPorts::Av(AvPorts {
                    clk: p("clk", 1)?,
                    reset: p("reset", 1)?,
                    address: p("address", 8)?,
                    chipselect: p("chipselect", 1)?,
                    read: p("read", 1)?,
                    write: p("write", 1)?,
                    writedata: p("writedata", 8)?,
                    readdata: p("readdata", 8)?,
                    waitrequest: p("waitrequest", 1)?,
                });
                (
                    host,
                    ["can_clk", "rx", "tx", "irq", "bus_off_on", "clkout"],
                    true,
                    k,
                )
            }
            HostPort::I8051 => {
                let k = "8051 bus (can_top_8051)";
                let p = |n: &str, w: u32| m.port(n, Some(w), k);
                let host = HostPorts::I8051(I8051Ports {
                    rst: p("rst_i", 1)?,
                    ale: p("ale_i", 1)?,
                    cs: p("cs_can_i", 1)?,
                    rd: p("rd_i", 1)?,
                    wr: p("wr_i", 1)?,
                    port_i: p("port_0_i", 8)?,
                    port_o: p("port_0_o", 8)?,
                    port_oe: p("port_0_oe", 1)?,
                });
                (
                    host,
                    ["clk_i", "rx_i", "tx_o", "irq_on", "bus_off_on", "clkout_o"],
                    false,
                    k,
                )
            }
        };
        let p = |i: usize| m.port(can_names[i], Some(1), k);
        Ok(VerilatedDut::cached(VerilatedDut {
            host,
            can_clk: p(0)?,
            rx: p(1)?,
            tx: p(2)?,
            irq: p(3)?,
            irq_active_high,
            bus_off_on: p(4)?,
            clkout: p(5)?,
            out: OutCache::default(),
            wb_in: None,
            m,
        }))
    }

    fn cached(mut d: VerilatedDut) -> VerilatedDut {
        let _ = d.refresh();
        d
    }

    /// A bundled top (`can_top`, `can_avalon` or a fixture).
    pub fn bundled(top: &str, kind: HostPort, trace: bool) -> Result<VerilatedDut, BridgeError> {
        VerilatedDut::new(Model::bundled(top, trace)?, kind)
    }

    /// The underlying model (for extra ports). Inputs set through it are
    /// seen at the next eval, as are outputs; the input cache is dropped so
    /// the next `set_wb` writes every pin.
    pub fn model(&mut self) -> &mut Model {
        self.wb_in = None;
        &mut self.m
    }
}

impl Dut for VerilatedDut {
    fn name(&self) -> String {
        format!("Verilated `{}`", self.m.top())
    }
    fn host_port(&self) -> HostPort {
        match self.host {
            HostPorts::Wb(_) => HostPort::Wishbone,
            HostPorts::Av(_) => HostPort::Avalon,
            HostPorts::I8051(_) => HostPort::I8051,
        }
    }
    fn set_reset(&mut self, on: bool) {
        let p = match &self.host {
            HostPorts::Wb(w) => w.rst,
            HostPorts::Av(a) => a.reset,
            HostPorts::I8051(p) => p.rst,
        };
        self.m.set(p, on as u64);
    }
    #[inline]
    fn set_wb(&mut self, x: &WbMasterOut) {
        if self.wb_in == Some(*x) {
            return;
        }
        self.wb_in = Some(*x);
        if let HostPorts::Wb(w) = &self.host {
            let (cyc, stb, we, adr, dat) = (w.cyc, w.stb, w.we, w.adr, w.dat_i);
            self.m.set(cyc, x.cyc as u64);
            self.m.set(stb, x.stb as u64);
            self.m.set(we, x.we as u64);
            self.m.set(adr, x.adr as u64);
            self.m.set(dat, x.dat as u64);
        }
    }
    #[inline]
    fn wb(&self) -> WbSlaveOut {
        self.out.wb
    }
    fn set_av(&mut self, x: &AvMasterOut) {
        if let HostPorts::Av(a) = &self.host {
            let (ad, cs, rd, wr, wd) = (a.address, a.chipselect, a.read, a.write, a.writedata);
            self.m.set(ad, x.address as u64);
            self.m.set(cs, x.chipselect as u64);
            self.m.set(rd, x.read as u64);
            self.m.set(wr, x.write as u64);
            self.m.set(wd, x.writedata as u64);
        }
    }
    fn av(&self) -> AvSlaveOut {
        self.out.av
    }
    fn set_i8051(&mut self, x: &I8051Out) {
        if let HostPorts::I8051(p) = &self.host {
            let (ale, cs, rd, wr, pi) = (p.ale, p.cs, p.rd, p.wr, p.port_i);
            self.m.set(ale, x.ale as u64);
            self.m.set(cs, x.cs as u64);
            self.m.set(rd, x.rd as u64);
            self.m.set(wr, x.wr as u64);
            // An undriven port reads as the pull-ups.
            self.m.set(pi, if x.ad_oe { x.ad } else { 0xFF } as u64);
        }
    }
    fn i8051(&self) -> I8051SlaveOut {
        self.out.i8051
    }
    #[inline]
    fn set_rx(&mut self, rx: bool) {
        let p = self.rx;
        assert!(self.m.owns(p), "VerilatedDut: the model was replaced");
        // SAFETY: `rx_i`/`rx` is a 1-bit port of this model (bound in `new`).
        unsafe { self.m.set_bit_unchecked(p, rx) }
    }
    #[inline]
    fn can(&self) -> CanPins {
        self.out.can
    }
    #[inline]
    fn eval(&mut self, host_clk: bool, can_clk: bool) {
        let _ = self.eval_pins(host_clk, can_clk);
    }
    fn trace_open(&mut self, path: &Path) -> Result<(), BridgeError> {
        self.m.trace_open(path)
    }
    fn trace_dump(&mut self, t_ps: u64) {
        self.m.trace_dump(t_ps);
    }
}

/// The DUT of a test bench: a Verilated top called directly (the hot
/// path: no dynamic dispatch per edge), anything else through [`Dut`].
/// Dereferences to `dyn Dut` for everything off the hot path.
#[allow(clippy::large_enum_variant)] // inline on purpose: no indirection per edge
pub enum AnyDut {
    /// A Verilated top.
    Verilated(VerilatedDut),
    /// Any other implementation.
    Other(Box<dyn Dut>),
}

impl std::ops::Deref for AnyDut {
    type Target = dyn Dut;
    fn deref(&self) -> &(dyn Dut + 'static) {
        match self {
            AnyDut::Verilated(d) => d,
            AnyDut::Other(d) => d.as_ref(),
        }
    }
}

impl std::ops::DerefMut for AnyDut {
    fn deref_mut(&mut self) -> &mut (dyn Dut + 'static) {
        match self {
            AnyDut::Verilated(d) => d,
            AnyDut::Other(d) => d.as_mut(),
        }
    }
}

impl AnyDut {
    /// [`Dut::eval`] then [`Dut::can`].
    #[inline(always)]
    pub fn eval_pins(&mut self, host_clk: bool, can_clk: bool) -> CanPins {
        match self {
            AnyDut::Verilated(d) => d.eval_pins(host_clk, can_clk),
            AnyDut::Other(d) => {
                d.eval(host_clk, can_clk);
                d.can()
            }
        }
    }

    /// [`Dut::set_rx`].
    #[inline(always)]
    pub fn set_rx(&mut self, rx: bool) {
        match self {
            AnyDut::Verilated(d) => d.set_rx(rx),
            AnyDut::Other(d) => d.set_rx(rx),
        }
    }

    /// [`Dut::wb`].
    #[inline(always)]
    pub fn wb(&self) -> WbSlaveOut {
        match self {
            AnyDut::Verilated(d) => d.wb(),
            AnyDut::Other(d) => d.wb(),
        }
    }

    /// [`Dut::set_wb`].
    #[inline(always)]
    pub fn set_wb(&mut self, m: &WbMasterOut) {
        match self {
            AnyDut::Verilated(d) => d.set_wb(m),
            AnyDut::Other(d) => d.set_wb(m),
        }
    }
}

/// Rust twin of the `tb/fixtures/cosim_echo.v` fixture (same register map,
/// same one-cycle registered `ack`), so everything above the bridge can be
/// exercised, and compared against the Verilated fixture, without Verilator.
#[derive(Clone, Debug, Default)]
pub struct EchoModel {
    mem: [u8; 32],
    ack: bool,
    dat_o: u8,
    rx_q: bool,
    clkdiv: bool,
    rst: bool,
    wb_in: WbMasterOut,
    rx: bool,
    host_clk: bool,
    can_clk: bool,
}

impl EchoModel {
    /// A fresh instance (state as Verilator's zero initialisation).
    pub fn new() -> EchoModel {
        EchoModel::default()
    }
}

impl Dut for EchoModel {
    fn name(&self) -> String {
        "Rust echo model".into()
    }
    fn set_reset(&mut self, on: bool) {
        self.rst = on;
    }
    fn set_wb(&mut self, m: &WbMasterOut) {
        self.wb_in = *m;
    }
    fn wb(&self) -> WbSlaveOut {
        WbSlaveOut {
            ack: self.ack,
            dat: self.dat_o,
            err: false,
            rty: false,
        }
    }
    fn set_rx(&mut self, rx: bool) {
        self.rx = rx;
    }
    fn can(&self) -> CanPins {
        CanPins {
            tx: if self.mem[0] & 2 != 0 {
                self.rx_q
            } else {
                self.mem[0] & 1 != 0
            },
            irq_n: self.mem[1] & 1 == 0,
            bus_on: self.mem[1] & 2 == 0,
            clkout: self.clkdiv,
        }
    }
    fn eval(&mut self, host_clk: bool, can_clk: bool) {
        let host_rise = host_clk && !self.host_clk;
        let can_rise = can_clk && !self.can_clk;
        self.host_clk = host_clk;
        self.can_clk = can_clk;
        if host_rise {
            if self.rst {
                self.mem = [0; 32];
                self.mem[0] = 1;
                self.ack = false;
                self.dat_o = 0;
            } else {
                let m = self.wb_in;
                let go = m.cyc && m.stb && !self.ack;
                let a = (m.adr & 0x1f) as usize;
                if go {
                    if m.we {
                        if a != 0x1f {
                            self.mem[a] = m.dat;
                        }
                    } else {
                        self.dat_o = if a == 0x1f {
                            self.rx as u8
                        } else {
                            self.mem[a]
                        };
                    }
                }
                self.ack = go;
            }
        }
        if can_rise {
            self.rx_q = self.rx;
            self.clkdiv = !self.clkdiv;
        }
    }
}

impl crate::compare::Reference for EchoModel {
    fn name(&self) -> String {
        "Rust echo model".into()
    }
    fn hard_reset(&mut self) {
        *self = EchoModel {
            mem: [0; 32],
            ..EchoModel::default()
        };
        self.mem[0] = 1;
    }
    fn write(&mut self, addr: u8, data: u8) -> Option<diagnose::WriteOutcome> {
        let a = (addr & 0x1f) as usize;
        if a == 0x1f {
            return Some(diagnose::WriteOutcome::IgnoredReadOnly);
        }
        self.mem[a] = data;
        Some(diagnose::WriteOutcome::Applied)
    }
    fn read(&mut self, addr: u8) -> u8 {
        self.peek(addr)
    }
    fn peek(&self, addr: u8) -> u8 {
        let a = (addr & 0x1f) as usize;
        if a == 0x1f {
            self.rx as u8
        } else {
            self.mem[a]
        }
    }
    fn clock(&mut self, rx: bool) {
        self.rx = rx;
        self.rx_q = rx;
        self.clkdiv = !self.clkdiv;
    }
    fn pins(&self) -> CanPins {
        Dut::can(self)
    }
    fn adopt_register(&mut self, addr: u8, value: u8) -> bool {
        let a = (addr & 0x1f) as usize;
        if a != 0x1f {
            self.mem[a] = value;
        }
        a != 0x1f
    }
}
