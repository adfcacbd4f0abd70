//! The lockstep test bench's agents, one job each. The
//! [`crate::Testbench`] owns one of each, wires them to the DUT and steps
//! time; it keeps no state of a role itself.
//!
//! - [`host`]: the host BFM, its wiring to the DUT's register bus, the
//!   protocol monitors and the reset sequence;
//! - [`bus`]: the wired-AND CAN bus, the golden-model nodes on it, the
//!   fault injectors and the DUT's rx wiring;
//! - [`reference`]: the model the DUT is compared with, and the DUT's
//!   declared timing (when a host access takes effect; the bit timing's
//!   phase origin);
//! - [`comparator`]: one checker per kind (tx bits, register reads, the
//!   irq/bus-off pins) with their tolerances, and the waiver and resync
//!   policy that decides what a divergence does to the run;
//! - [`raw`]: a bit-level sender (the lower tester) that the bus agent
//!   wires onto the bus with the DUT and the model nodes;
//! - [`observer`]: the bit clock, the field decoder, our VCD, the run
//!   record and the bus log: it watches and writes down, never drives.

pub mod bus;
pub mod comparator;
pub mod host;
pub mod observer;
pub mod raw;
pub mod reference;
