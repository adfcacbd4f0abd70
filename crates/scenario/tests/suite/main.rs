//! The scenario crate's integration tests, one module per file, in one test
//! binary: one link instead of one per file, and the files' tests run in
//! parallel with each other.

#[path = "../common/mod.rs"]
mod common;
#[path = "../upstream_common/mod.rs"]
mod upstream_common;
mod abort_race;
mod accounting;
mod acf_walk;
mod bad_input;
mod block_step;
mod candump_replay;
mod clkout_fosc;
mod conformance;
mod coverage;
mod fifo_btl_holes;
mod funcov;
mod fuzz_parse;
mod host_axi_apb;
mod host_fork;
mod host_i8051;
mod host_motorola;
mod host_override;
mod host_regport;
mod mutation_holes;
mod mutations;
mod parse;
mod raw_node;
mod registers;
mod regress;
mod regs_aliasing_and_sleep_refusal;
mod run_model;
mod run_rtl;
mod segment_lag;
mod setup_verdict_reads;
mod suspend_sof;
mod upstream;
mod upstream_8051;
mod upstream_lists;
mod upstream_pio;
mod upstream_resync;
mod waivers;
mod xfail;
