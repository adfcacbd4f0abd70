//! Co-simulation of HDL CAN controllers against the golden model: a thin
//! Verilator bridge of our own ([`bridge`], see the README's design notes),
//! a simulation kernel with two independent clocks, DUTs (Verilated RTL or
//! the golden model itself), CAN bus wiring, a lockstep comparator and a
//! VCD writer.
#![warn(missing_docs)]

pub mod bridge;
pub mod shimgen;

pub use bridge::{BridgeError, CompiledCore, ExternalCore, Model, Port, PortInfo, bundled_tops};
