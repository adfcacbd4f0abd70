//! Host bus-functional models for the SJA1000-compatible core: Wishbone
//! classic, Avalon-MM, AXI4-Lite, APB3/APB4, PIO (GPIO bit-banging) and
//! Intel-mode 8051 and Motorola-mode multiplexed-bus masters, passive protocol
//! monitors, RAM targets to test them, and fault wrappers.
//!
//! The crate knows no simulator and no async runtime: every role is a plain
//! value stepped once per host clock edge by whoever owns time (the `cosim`
//! kernel, or a test loop).
//!
//! # Stepping contract
//!
//! Each host clock cycle `k` the kernel does, in this order:
//!
//! 1. `let m = master.outputs();` the master's registered pins for cycle `k`;
//! 2. applies `m` to the DUT inputs and clocks the DUT's rising edge `E_k`;
//! 3. reads the DUT outputs after that edge, `s_k`, and calls
//!    `master.on_edge(&s_k)`;
//! 4. optionally calls `monitor.observe(k, &m, &s_k)`.
//!
//! A [`HostBusTarget`] does step 2 in one call: `s_k = target.cycle(&m)`.
//!
//! `on_edge(&s_k)` is the master's own edge `E_k`, at which a synchronous
//! master samples what was on the wires *before* that edge, i.e. `s_{k-1}`.
//! So every master keeps the previous `s` and reacts to it: the master sees
//! registered slave outputs one edge after they were produced, as a real
//! synchronous master does. With a slave that registers `ack` from `stb`, a
//! Wishbone access therefore takes 2 cycles (stb at `E_k`, ack after `E_k`,
//! sampled at `E_{k+1}`). Slave outputs that depend combinationally on the
//! master's pins in the same cycle are not modelled (the `can_top` outputs
//! are registered); in particular an Avalon `waitrequest` must be
//! registered and high whenever the slave is not accepting, idle included.
//!
//! An operation queued between cycles is taken at the next `on_edge` and
//! drives the pins from the cycle after; its [`OpResult::cycles`] counts from
//! that edge. Drive the reset line with [`HostMaster::set_reset`] every
//! cycle (or on change): assertion flushes the queue once.
//!
//! Monitors take the same pair the kernel has in hand (`m` and `s_k`) and pair
//! `m_k` with `s_{k-1}` internally, so a violation's cycle number is the cycle
//! during which the offending values were on the wires.
//!
//! ```
//! use bfm::{HostBusTarget, HostMaster, WishboneMaster, WishboneMonitor, WishboneRam};
//!
//! let mut master = WishboneMaster::new("wb");
//! let mut dut = WishboneRam::new("ram"); // the cosim crate puts a DUT here
//! let mut monitor = WishboneMonitor::new("wbmon", 100);
//! let h = master.start_write(0x1F, 0x08); // CDR: clock off
//! for cycle in 0..10 {
//!     let m = master.outputs();
//!     let s = dut.cycle(&m);
//!     master.on_edge(&s);
//!     assert!(monitor.observe(cycle, &m, &s).is_empty());
//! }
//! assert_eq!(master.poll(h).unwrap().unwrap().cycles, 2);
//! assert_eq!(dut.mem()[0x1F], 0x08);
//! ```
//!
//! # Roles
//!
//! One type per role, as cocotbext-axi does: [`WishboneMaster`],
//! [`AvalonMaster`], [`PioMaster`], [`I8051Master`]; [`WishboneMonitor`],
//! [`AvalonMonitor`], [`I8051Monitor`]; [`WishboneRam`], [`AvalonRam`],
//! [`I8051Ram`]; fault wrappers in [`faults`]; seed 000's
//! Avalon-to-Wishbone wiring in [`wiring`]. Masters queue operations
//! (`start_read`/`start_write` return an [`OpHandle`]), take an optional
//! idle-inserting [`Pause`], time out every operation, and flush their queue
//! on [`HostMaster::reset`]. Each role logs its options when constructed.

#![warn(missing_docs)]

mod apb;
mod avalon;
mod axi4lite;
pub mod faults;
mod i8051;
mod i8051_ac;
mod monitor;
mod motorola;
mod op;
mod pins;
mod pio;
mod regport;
pub mod wiring;
mod wishbone;

pub use apb::{ApbBridge, ApbConfig, ApbMaster, ApbMasterOut, ApbMonitor, ApbRam, ApbSlaveOut};
pub use axi4lite::{
    Axi4LiteBridge, Axi4LiteConfig, Axi4LiteMaster, Axi4LiteMonitor, Axi4LiteRam, AxiMasterOut,
    AxiSlaveOut, resp_name,
};
pub use avalon::{AvalonMaster, AvalonMasterConfig, AvalonRam, AvalonTiming};
pub use i8051_ac::I8051AcTiming;
pub use i8051::{
    DEFAULT_I8051_TIMEOUT_CYCLES, I8051Config, I8051Master, I8051Monitor, I8051MonitorConfig,
    I8051Out, I8051Polarity, I8051Ram, I8051SlaveOut, I8051Timing, port_level,
};
pub use motorola::{MotorolaAcTiming, MotorolaBridge, MotorolaMaster, MotorolaMonitor, MotorolaOut};
pub use monitor::{AvalonMonitor, AvalonMonitorConfig, Rule, Violation, WishboneMonitor};
pub use op::{
    BfmError, DEFAULT_TIMEOUT_CYCLES, OpHandle, OpKind, OpResult, Pause, cycle_pause, random_pause,
};
pub use pins::{AvMasterOut, AvSlaveOut, WbMasterOut, WbSlaveOut};
pub use pio::{
    CTL_CYC, CTL_RST, CTL_STB, CTL_WE, DEFAULT_PIO_TIMEOUT_CYCLES, PioAckInput, PioMaster,
    PioTiming,
};
pub use regport::{RegportBridge, RegportConfig, RegportIn, RegportMaster, RegportMonitor, RegportOut};
pub use wishbone::{AckMode, BlockAccess, WishboneMaster, WishboneRam};

/// A host-side bus master, stepped by the kernel (see the crate docs for the
/// stepping contract).
pub trait HostMaster {
    /// Pins the master drives.
    type Out: Copy;
    /// Pins the slave drives.
    type In: Copy;

    /// The master's registered pins for the coming cycle. Pure.
    fn outputs(&self) -> Self::Out;
    /// The master's clock edge; `slave` is what the slave drives after the
    /// edge the kernel just clocked.
    fn on_edge(&mut self, slave: &Self::In);
    /// Queue a register write.
    fn start_write(&mut self, addr: u8, data: u8) -> OpHandle;
    /// Queue a register read.
    fn start_read(&mut self, addr: u8) -> OpHandle;
    /// `None` while the operation is queued or in flight; its result once
    /// (the result is handed over and forgotten).
    fn poll(&mut self, handle: OpHandle) -> Option<Result<OpResult, BfmError>>;
    /// Flush every queued and in-flight operation (each is logged and
    /// completes with [`BfmError::Flushed`]) and return the pins to idle.
    fn reset(&mut self);
    /// The reset line's level, given every cycle or on change: on assertion
    /// the master [`reset`](HostMaster::reset)s once; while it is held, no
    /// operation starts (queued ones wait and count towards their timeout).
    fn set_reset(&mut self, asserted: bool);
    /// Timeout, in host cycles, given to operations queued from now on.
    fn set_timeout(&mut self, cycles: u64);
    /// Operations queued or in flight.
    fn in_flight(&self) -> usize;
    /// An upper bound, in cycles, on how long everything queued can take.
    fn drain_bound(&self) -> u64;
}

/// A slave that the kernel can clock: apply the master's pins, clock one
/// rising edge, return the slave's (registered) outputs after it. The
/// default parameters make it the Wishbone target trait the `cosim` crate
/// implements for DUTs; the Avalon RAM implements
/// `HostBusTarget<AvMasterOut, AvSlaveOut>`.
pub trait HostBusTarget<O = WbMasterOut, I = WbSlaveOut> {
    /// One host clock cycle.
    fn cycle(&mut self, m: &O) -> I;
}

/// Step `master` against `step` (one call = one host cycle, see the stepping
/// contract) until `handle` completes. Never hangs: gives up with
/// [`BfmError::Stalled`] past the master's drain bound.
pub fn run_op<M, F>(master: &mut M, handle: OpHandle, mut step: F) -> Result<OpResult, BfmError>
where
    M: HostMaster,
    F: FnMut(&M::Out) -> M::In,
{
    let bound = master.drain_bound() + 16;
    let mut cycles = 0;
    loop {
        if let Some(r) = master.poll(handle) {
            return r;
        }
        if cycles >= bound {
            return Err(BfmError::Stalled { cycles });
        }
        let m = master.outputs();
        let s = step(&m);
        master.on_edge(&s);
        cycles += 1;
    }
}

/// Blocking register read through `master` against `target`.
pub fn blocking_read<M, T>(master: &mut M, target: &mut T, addr: u8) -> Result<OpResult, BfmError>
where
    M: HostMaster,
    T: HostBusTarget<M::Out, M::In>,
{
    let h = master.start_read(addr);
    run_op(master, h, |m| target.cycle(m))
}

/// Blocking register write through `master` against `target`.
pub fn blocking_write<M, T>(
    master: &mut M,
    target: &mut T,
    addr: u8,
    data: u8,
) -> Result<OpResult, BfmError>
where
    M: HostMaster,
    T: HostBusTarget<M::Out, M::In>,
{
    let h = master.start_write(addr, data);
    run_op(master, h, |m| target.cycle(m))
}
