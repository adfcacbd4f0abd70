//! The cli crate's integration tests, one module per file, in one test
//! binary: one link instead of one per file, and the files' tests run in
//! parallel with each other.

mod bad_input;
mod bisect;
mod bittiming;
mod cache_race;
mod candump_python_can;
mod coverage;
mod doc_links;
mod expected_failures;
mod gtkw_view;
mod host_commands;
mod html_report;
mod mutate_upstream;
mod reference;
mod revdiff;
mod vhdl_input;
