//! The cosim crate's integration tests, one module per file, in one test
//! binary: one link instead of one per file, and the files' tests run in
//! parallel with each other.

#[path = "../common/mod.rs"]
mod common;
mod after_overrun;
mod axi_apb;
mod bridge;
mod candump;
mod collect_resync;
mod external;
mod i8051;
mod motorola;
mod read_compare;
mod reference_timing;
mod regport;
mod resync_sleep;
mod rtl;
mod speed;
mod testbench;
mod vhdl;
mod wb_block;
