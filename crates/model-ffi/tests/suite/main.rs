//! The model-ffi crate's integration tests, one module per file, in one test
//! binary: one link instead of one per file, and the files' tests run in
//! parallel with each other.

mod shadow;
mod sv_bench;
