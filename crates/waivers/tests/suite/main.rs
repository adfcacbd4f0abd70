//! The waivers crate's integration tests, one module per file, in one test
//! binary: one link instead of one per file, and the files' tests run in
//! parallel with each other.

mod after_overrun;
mod bus_on_resync;
mod conformance_upstream;
mod consequences;
mod expected_failures_upstream;
mod file_and_report;
mod lockstep;
mod narrow_bounds;
mod registers_upstream;
mod until_read;
