#![warn(missing_docs)]
// The README's example runs as a doc test.
#![doc = include_str!("../README.md")]

mod error;
mod external;
mod model;
pub mod shimgen;
pub mod vhdl;

pub use error::BridgeError;
pub use external::ExternalCore;
pub use model::{CompiledCore, Model, Port, PortInfo, VTable};
pub use shimgen::PortDir;
