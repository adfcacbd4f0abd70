//! Hosts on the simulated core.
//!
//! - [`BenchHost`]: the driver's register accesses become BFM operations
//!   on a [`cosim::Testbench`] (Avalon into `can_avalon`, Wishbone or
//!   Avalon-over-Wishbone into `can_top` or the golden model). The bench
//!   clocks both clocks and the CAN bus, with its golden-model nodes, for
//!   as long as each access takes, so the driver's polling loops let
//!   simulated time pass.
//! - [`PioBench`]: five Altera-style PIO cores whose outputs drive the
//!   Wishbone pins of a [`Dut`] and whose inputs read `wb_ack_o` (with
//!   rising-edge capture) and `wb_dat_o`, for the generated
//!   `can_sja_pio.h` path ([`crate::CDriver::via_pio`]).

use bfm::{PioTiming, WbMasterOut, WbSlaveOut};
use cosim::{Dut, Kernel, TbConfig, TbError, Testbench};
use sja1000::{Bus, Sja1000};

use crate::driver::{Host, Pio, PioHost, pio_reg};

/// The thesis bit timing used by every bench here: 24 MHz CAN clock,
/// BTR0 = 0x41, BTR1 = 0x25 (40 clocks per bit).
pub const CAN_HZ: u64 = 24_000_000;
/// Host clock (`wb_clk_i`) of the DE2 system.
pub const HOST_HZ: u64 = 50_000_000;

/// A model node configured through its registers like the DUT: the given
/// view, [`sja1000::host::Config::pelican`] timing (BTR0 = 0x41,
/// BTR1 = 0x25), accepting everything.
pub fn model_node(view: crate::View) -> Sja1000 {
    let mut n = Sja1000::new();
    let cfg = match view {
        crate::View::Peli => sja1000::host::Config::pelican(),
        crate::View::Basic => sja1000::host::Config::basic(0, 0xFF),
    };
    sja1000::host::configure(&mut n, &cfg);
    n
}

/// What a test needs from a simulated host besides register accesses:
/// time, and the model nodes on the bus.
pub trait SimHost {
    /// Lets `n` CAN bit times pass (at the thesis timing, 40 CAN clocks).
    fn run_bits(&mut self, n: u64);
    /// Model node `i` on the bus.
    fn node(&mut self, i: usize) -> &mut Sja1000;
    /// The DUT's interrupt line (`true` = interrupt pending).
    fn irq(&self) -> bool;
    /// Why the last `run_bits` could not run (e.g. the lockstep comparator
    /// stopped the bench), without consuming it.
    fn stalled(&self) -> Option<&str>;
}

/// CAN clocks per bit at BTR0 = 0x41, BTR1 = 0x25.
pub const CLOCKS_PER_BIT: u64 = 40;

/// The driver's 8-bit accesses as BFM operations on a test bench.
pub struct BenchHost {
    tb: Testbench,
    error: Option<String>,
    accesses: u64,
}

impl BenchHost {
    /// Builds the bench (DUT, BFM, bus with the configured nodes) and runs
    /// its reset sequence.
    pub fn new(cfg: TbConfig) -> Result<BenchHost, TbError> {
        Ok(BenchHost { tb: Testbench::new(cfg)?, error: None, accesses: 0 })
    }

    /// A bench from `cfg` (its `nodes` are replaced) with `nodes` on the
    /// bus, already configured (e.g. by [`model_node`]).
    pub fn with_nodes(mut cfg: TbConfig, nodes: Vec<Sja1000>) -> Result<BenchHost, TbError> {
        cfg.nodes = (0..nodes.len()).map(|i| cosim::NodeConfig { name: format!("model node {i}"), init: Vec::new() }).collect();
        let mut h = BenchHost::new(cfg)?;
        for (i, n) in nodes.into_iter().enumerate() {
            *h.tb.bus_mut().node_mut(i) = n;
        }
        Ok(h)
    }

    /// The thesis clocks (50 MHz host, 24 MHz CAN) and bit timing, the
    /// given DUT and BFM, nothing on the bus yet.
    pub fn config(dut: cosim::DutChoice, host: cosim::HostBfm) -> TbConfig {
        TbConfig { scenario: "cdriver".into(), dut, host, host_hz: HOST_HZ, can_hz: CAN_HZ, ..TbConfig::default() }
    }

    /// A bench with the given DUT and BFM, the thesis clocks and timing,
    /// and one model node (`node_view`, configured by register writes) on
    /// the bus with the DUT.
    pub fn with_model_node(dut: cosim::DutChoice, host: cosim::HostBfm, node_view: crate::View) -> Result<BenchHost, TbError> {
        BenchHost::with_nodes(BenchHost::config(dut, host), vec![model_node(node_view)])
    }

    /// A bench with the given DUT and BFM and nothing else on the bus (no
    /// node to acknowledge).
    pub fn alone(dut: cosim::DutChoice, host: cosim::HostBfm) -> Result<BenchHost, TbError> {
        BenchHost::new(BenchHost::config(dut, host))
    }

    /// The test bench.
    pub fn tb(&self) -> &Testbench {
        &self.tb
    }

    /// The test bench, to run time or reach the model nodes.
    pub fn tb_mut(&mut self) -> &mut Testbench {
        &mut self.tb
    }

    /// Register accesses made by the driver so far.
    pub fn accesses(&self) -> u64 {
        self.accesses
    }

    fn fail(&mut self, e: impl std::fmt::Display) {
        if self.error.is_none() {
            self.error = Some(e.to_string());
        }
    }
}

impl SimHost for BenchHost {
    fn run_bits(&mut self, n: u64) {
        if let Err(e) = self.tb.run_can_cycles(n * CLOCKS_PER_BIT) {
            self.fail(e);
        }
    }
    fn node(&mut self, i: usize) -> &mut Sja1000 {
        self.tb.bus_mut().node_mut(i)
    }
    fn irq(&self) -> bool {
        !self.tb.pins().irq_n
    }
    fn stalled(&self) -> Option<&str> {
        self.error.as_deref()
    }
}

impl Host for BenchHost {
    fn iord8(&mut self, offset: u32) -> u8 {
        self.accesses += 1;
        match u8::try_from(offset).map_err(|_| format!("offset {offset} beyond the 8-bit address bus")).and_then(|a| self.tb.read(a).map_err(|e| e.to_string())) {
            Ok(v) => v,
            Err(e) => {
                self.fail(e);
                0xFF
            }
        }
    }
    fn iowr8(&mut self, offset: u32, v: u8) {
        self.accesses += 1;
        let r = u8::try_from(offset).map_err(|_| format!("offset {offset} beyond the 8-bit address bus")).and_then(|a| self.tb.write(a, v).map(|_| ()).map_err(|e| e.to_string()));
        if let Err(e) = r {
            self.fail(e);
        }
    }
    fn take_error(&mut self) -> Option<String> {
        self.error.take()
    }
}

/// Five PIO cores on the Wishbone pins of a DUT, the two clocks, and the
/// CAN bus with model nodes. A PIO access costs the CPU the cycles of
/// [`PioTiming`] (an output changes at the edge that ends the write, an
/// input is sampled at the edge that ends the read).
pub struct PioBench<D: Dut> {
    kernel: Kernel,
    dut: D,
    bus: Bus,
    timing: PioTiming,
    addr: u8,
    dout: u8,
    ctrl: u8,
    /// The DUT's Wishbone outputs after the last host edge.
    slave: WbSlaveOut,
    /// Edge capture register of the ack PIO (bit 0).
    ack_capture: bool,
    /// Host cycles the DUT reset is still held at start.
    reset_left: u64,
    host_cycles: u64,
    /// Rising edges of `wb_ack_o`: the Wishbone transfers the DUT made.
    acks: u64,
    /// GPIO accesses made by the CPU.
    gpio_accesses: u64,
    /// Writes to the address PIO: one per register access of the driver.
    register_accesses: u64,
    /// Glue between the control PIO and the core: after `wb_ack_o`, hold
    /// cyc/stb low until the CPU next writes the control PIO.
    ack_gate: bool,
    /// The gate is closed (an ack came since the last control write).
    gated: bool,
    error: Option<String>,
}

impl<D: Dut> PioBench<D> {
    /// A bench on `dut` with the given model nodes; holds the DUT reset for
    /// 16 host cycles and then lets 64 more pass.
    pub fn new(dut: D, nodes: Vec<Sja1000>, timing: PioTiming) -> PioBench<D> {
        let mut bus = Bus::new();
        bus.set_accounting(false);
        for n in nodes {
            bus.add_node(n);
        }
        let mut b = PioBench {
            kernel: Kernel::new(HOST_HZ, CAN_HZ).expect("constant clocks are in range"),
            dut,
            bus,
            timing,
            addr: 0,
            dout: 0,
            ctrl: 0,
            slave: WbSlaveOut::default(),
            ack_capture: false,
            reset_left: 16,
            host_cycles: 0,
            acks: 0,
            gpio_accesses: 0,
            register_accesses: 0,
            ack_gate: false,
            gated: false,
            error: None,
        };
        b.dut.set_reset(true);
        b.dut.set_rx(true);
        b.run_host_cycles(16 + 64);
        b
    }

    /// Puts (or removes) a one-shot between the control PIO and the core's
    /// `wb_cyc_i`/`wb_stb_i`: once `wb_ack_o` is seen they read low until
    /// the CPU writes the control PIO again. Without it the thesis sequence
    /// keeps cyc/stb high for the several cycles the CPU needs to notice the
    /// ack, which Wishbone reads as a new transfer of the same access.
    pub fn set_ack_gate(&mut self, on: bool) {
        self.ack_gate = on;
        self.gated = false;
    }

    /// The DUT.
    pub fn dut(&self) -> &D {
        &self.dut
    }

    /// Host cycles so far.
    pub fn host_cycles(&self) -> u64 {
        self.host_cycles
    }

    /// Wishbone transfers acknowledged by the DUT so far.
    pub fn acks(&self) -> u64 {
        self.acks
    }

    /// Register accesses of the driver so far (writes to the address PIO,
    /// which `can_sja_pio.h` makes once per access).
    pub fn register_accesses(&self) -> u64 {
        self.register_accesses
    }

    /// PIO register accesses made by the CPU so far.
    pub fn gpio_accesses(&self) -> u64 {
        self.gpio_accesses
    }

    /// Lets `n` host cycles pass with the pins as they are.
    pub fn run_host_cycles(&mut self, n: u64) {
        let end = self.host_cycles + n;
        while self.host_cycles < end {
            self.tick();
        }
    }

    fn tick(&mut self) {
        let t = self.kernel.advance();
        if t.can_rise {
            let tx = self.dut.can().tx;
            let level = if self.bus.is_empty() { tx } else { self.bus.clock_with(tx) };
            self.dut.set_rx(level);
        }
        self.dut.eval(self.kernel.host().level(), self.kernel.can().level());
        if t.host_rise {
            self.host_cycles += 1;
            let s = self.dut.wb();
            if s.ack && !self.slave.ack {
                self.acks += 1;
            }
            // The PIO core samples its input at this edge: a pulse seen
            // here sets edge capture.
            self.ack_capture |= s.ack;
            self.gated |= self.ack_gate && s.ack;
            self.slave = s;
            if self.reset_left > 0 {
                self.reset_left -= 1;
            }
            self.dut.set_reset(self.reset_left > 0 || self.ctrl & bfm::CTL_RST != 0);
            let open = !self.gated;
            self.dut.set_wb(&WbMasterOut {
                cyc: open && self.ctrl & bfm::CTL_CYC != 0,
                stb: open && self.ctrl & bfm::CTL_STB != 0,
                we: self.ctrl & bfm::CTL_WE != 0,
                adr: self.addr,
                dat: self.dout,
            });
        }
    }

    fn fail(&mut self, msg: String) {
        if self.error.is_none() {
            self.error = Some(msg);
        }
    }
}

impl<D: Dut> SimHost for PioBench<D> {
    fn run_bits(&mut self, n: u64) {
        let end = self.kernel.can().cycles() + n * CLOCKS_PER_BIT;
        while self.kernel.can().cycles() < end {
            self.tick();
        }
    }
    fn node(&mut self, i: usize) -> &mut Sja1000 {
        self.bus.node_mut(i)
    }
    fn irq(&self) -> bool {
        !self.dut.can().irq_n
    }
    fn stalled(&self) -> Option<&str> {
        self.error.as_deref()
    }
}

impl<D: Dut> PioHost for PioBench<D> {
    fn pio_read(&mut self, pio: Pio, reg: u32) -> u32 {
        self.gpio_accesses += 1;
        self.run_host_cycles(self.timing.iord_cycles.max(1) as u64);
        match (pio, reg) {
            (Pio::Ack, pio_reg::DATA) => self.slave.ack as u32,
            (Pio::Ack, pio_reg::EDGE_CAP) => self.ack_capture as u32,
            (Pio::Din, pio_reg::DATA) => self.slave.dat as u32,
            (Pio::Addr, pio_reg::DATA) => self.addr as u32,
            (Pio::Dout, pio_reg::DATA) => self.dout as u32,
            (Pio::Ctrl, pio_reg::DATA) => self.ctrl as u32,
            _ => {
                self.fail(format!("read of {pio:?} register {reg}, which this wiring does not have"));
                0xFFFF_FFFF
            }
        }
    }

    fn pio_write(&mut self, pio: Pio, reg: u32, v: u32) {
        self.gpio_accesses += 1;
        self.run_host_cycles(self.timing.iowr_cycles.max(1) as u64);
        match (pio, reg) {
            (Pio::Addr, pio_reg::DATA) => {
                self.register_accesses += 1;
                self.addr = v as u8;
            }
            (Pio::Dout, pio_reg::DATA) => self.dout = v as u8,
            (Pio::Ctrl, pio_reg::DATA) => {
                self.ctrl = v as u8;
                self.gated = false;
            }
            (Pio::Ack, pio_reg::EDGE_CAP) => {
                if v & 1 != 0 {
                    self.ack_capture = false;
                }
            }
            _ => self.fail(format!("write of 0x{v:X} to {pio:?} register {reg}, which this wiring does not have")),
        }
    }

    fn take_error(&mut self) -> Option<String> {
        self.error.take()
    }
}
