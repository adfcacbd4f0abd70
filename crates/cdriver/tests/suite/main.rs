//! The cdriver crate's integration tests, one module per file, in one test
//! binary: one link instead of one per file, and the files' tests run in
//! parallel with each other.

#[path = "../common/mod.rs"]
mod common;
mod api;
mod model;
mod rtl;
