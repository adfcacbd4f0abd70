//! The C driver of `crates/regmap/c/` (written against the generated
//! `can_sja_regs.h` only), compiled with `cc` and run on the host against
//! the simulated core: its `IORD`/`IOWR` go through the callback stand-in
//! for `io.h` (`host_io_callback.c`) into a host that drives our RTL or
//! the golden model, with golden-model nodes on the CAN bus.
//!
//! Two wirings ([`Wiring`]):
//! - [`Direct`] (`CDriver::new`): each 8-bit register access is handed to
//!   a [`Host`]. [`BenchHost`] turns it into one BFM operation on a
//!   [`cosim::Testbench`] (Avalon into `can_avalon`, Wishbone or
//!   Avalon-over-Wishbone into `can_top` or the golden model), which clocks
//!   both clocks and the bus while the access takes, so the driver's
//!   polling loops let simulated time pass.
//! - [`ViaPio`] (`CDriver::via_pio`): each register access is bit-banged
//!   by the generated `can_sja_pio.h` accessors (compiled in
//!   `c/pio_shim.c`, ack on PIO edge capture); only the PIO register
//!   accesses reach a [`PioHost`]. [`PioBench`] models the five PIO cores
//!   on the Wishbone pins of any [`cosim::Dut`].
//!
//! The C side keeps its callbacks in globals: each call takes a
//! process-wide lock, so drivers on several test threads take turns. A
//! failed access (BFM timeout, no ack, host panic) ends the C call quickly
//! (later accesses of the call are not performed) and is returned as
//! [`CDriverError::Host`].
//!
//! Measured with the thesis timing (24 MHz CAN clock, 50 MHz host clock,
//! BTR0 = 0x41, BTR1 = 0x25), 600 reads by `can_read_errors`: a register
//! access costs 14.6 host cycles through Avalon into `can_avalon` or
//! Wishbone into `can_top` (the clock-domain crossing), 3.0 on the golden
//! model, and 35.0 host cycles (9 GPIO accesses) through the PIO header
//! into `can_top`. Holding cyc/stb until the CPU has seen the ack (the
//! thesis sequence) makes `can_top` start a second transfer of the same
//! access: a doubled CMR.RRB drops a queued frame (see the ignored test
//! `pio_header_can_top_two_frames_queued` and [`PioBench::set_ack_gate`]).
//!
//! ```no_run
//! use can_proto::CanFrame;
//! use cdriver::{BenchHost, CDriver, Config, View};
//! use cosim::{DutChoice, HostBfm};
//! let host = BenchHost::with_model_node(DutChoice::Model, HostBfm::Wishbone, View::Peli).unwrap();
//! let mut drv = CDriver::new(host);
//! drv.init(View::Peli, &Config::accept_all()).unwrap();
//! let f = CanFrame::with_dlc(CanFrame::std_id(0x123).unwrap(), false, 2, &[1, 2]).unwrap();
//! drv.transmit(&f).unwrap();
//! ```
#![warn(missing_docs)]

mod driver;
mod ffi;
pub mod sim;

pub use driver::{CAN_BASE, CDriver, CDriverError, Capture, Config, Direct, ErrorStatus, Host, Pio, PioHost, ViaPio, View, Wiring, ecc_kind, pio_reg};
pub use sim::{BenchHost, PioBench, SimHost, model_node};
