#![warn(missing_docs)]
// The README's example runs as a doc test.
#![doc = include_str!("../README.md")]

mod model;
pub mod shimgen;
pub mod vhdl;

pub use model::{BridgeError, CompiledCore, ExternalCore, Model, Port, PortInfo, VTable};
pub use shimgen::PortDir;
