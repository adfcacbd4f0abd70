//! Golden model of the NXP SJA1000 stand-alone CAN controller, BasicCAN and
//! PeliCAN views, and a multi-node wired-AND CAN bus to run it on.
//!
//! - [`Sja1000`]: the register file (decoded through the one register map,
//!   [`regmap`]), commands, status, interrupts, the 64-byte RX FIFO, the TX
//!   buffer, acceptance filters, sleep and CLKOUT, around the protocol
//!   engine [`can_engine::Engine`].
//! - [`filter`]: the acceptance filters as pure functions.
//! - [`Bus`]: N nodes on one bus, propagation delays, fault injectors, a
//!   fast per-bit path, and the accounting check that nothing was lost.
//! - [`workload`]: seeded random traffic, shared by the benchmark and the CLI.
//!
//! Source of the semantics: the SJA1000 data sheet (Philips, 2000 Jan 04)
//! and the CAN 2.0B specification.
//!
//! ```
//! use can_proto::{CanFrame, FrameTrait};
//! use regmap::peli;
//! use sja1000::host::{self, Config};
//! use sja1000::{Bus, Sja1000};
//!
//! let mut bus = Bus::new();
//! for _ in 0..2 {
//!     let mut node = Sja1000::new(); // hardware reset: BasicCAN, reset mode
//!     host::configure(&mut node, &Config::pelican()); // PeliCAN, accept all, operating
//!     bus.add_node(node);
//! }
//! let frame = CanFrame::new(CanFrame::std_id(0x123).unwrap(), &[1, 2, 3]).unwrap();
//! host::transmit(bus.node_mut(0), &frame, peli::cmr::TR).unwrap();
//! bus.run_bits(200);
//! assert_eq!(host::receive(bus.node_mut(1)), Some(frame));
//! assert_eq!(bus.node_mut(0).read(peli::SR) & peli::sr::TCS, peli::sr::TCS);
//! bus.check_accounting().unwrap();
//! ```
#![warn(missing_docs)]

pub mod bus;
mod controller;
pub mod fifo;
pub mod filter;
pub mod host;
pub mod workload;

pub use bus::*;
pub use can_engine::{Engine, Event, FaultState};
pub use controller::{NodeEvent, ResetKind, RxOutcome, Sja1000, WriteOutcome};
pub use regmap::{Mode, OpMode, RegError};
