//! The mutate crate's integration tests, one module per file, in one test
//! binary: one link instead of one per file, and the files' tests run in
//! parallel with each other.

mod equiv_scripts;
mod journal_key;
mod reset_proof;
mod tiny;
mod waiver_audit;
mod widen;
