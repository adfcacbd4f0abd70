//! Run a Verilog top from Rust through Verilator 5, with no knowledge of
//! what the design is: build it from sources, defines and include
//! directories into a cached shared library ([`ExternalCore`]), or link it
//! into the executable from a build script ([`shimgen`],
//! [`Model::from_table`]); instantiate it, drive and read its ports by
//! name, evaluate, step a clock, dump a VCD. See the README for an example.
#![warn(missing_docs)]

mod model;
pub mod shimgen;

pub use model::{BridgeError, CompiledCore, ExternalCore, Model, Port, PortInfo, VTable};
pub use shimgen::PortDir;
