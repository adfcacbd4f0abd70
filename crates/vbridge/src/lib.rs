//! Run a Verilog top from Rust through Verilator (moved from `cosim`; the
//! next commit makes it build on its own).
pub mod model;
pub mod shimgen;
