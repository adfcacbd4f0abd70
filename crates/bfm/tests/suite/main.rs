//! The bfm crate's integration tests, one module per file, in one test
//! binary: one link instead of one per file, and the files' tests run in
//! parallel with each other.

#[path = "../common/mod.rs"]
mod common;
mod axi_apb;
mod i8051;
mod masters;
mod monitors;
mod motorola;
mod regport;
mod wb_block;
