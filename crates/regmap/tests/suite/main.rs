//! The regmap crate's integration tests, one module per file, in one test
//! binary: one link instead of one per file, and the files' tests run in
//! parallel with each other.

mod c_8051;
mod c_ffi;
mod c_generated;
mod checked_in;
mod devicetree;
