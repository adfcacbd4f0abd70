//! The sja1000 crate's integration tests, one module per file, in one test
//! binary: one link instead of one per file, and the files' tests run in
//! parallel with each other.

#[path = "../common/mod.rs"]
mod common;
mod bus;
mod fuzz;
mod fuzz_host;
mod interrupts;
mod node_clock;
mod registers;
mod sleep_request;
