//! The suspend-transmission scenarios see the bit
//! they are about, on the golden model (the model and our RTL pass them as
//! shipped: tests/conformance.rs runs the whole list on both):
//!
//! - tx-8.5.9-passive-no-identifier-at-eighth-suspend-bit: the raw node's
//!   start of frame in the 8th suspend bit (42) makes the DUT a receiver;
//!   one bit later (43, the DUT's own SOF bit) the DUT meets it in
//!   arbitration (ALI), and with the DUT error active (no suspend) its own
//!   frame is on the wire from bit 35: both fail;
//! - tx-8.5.14-passive-recovery-time: rival (a raw node) starts in bit 57,
//!   the DUT's retransmission SOF 31 bits after the error; a bit earlier (56,
//!   the 8th suspend bit) the DUT is a receiver (no ALI), a bit later (58)
//!   the DUT's identifier runs one bit ahead of rival's and it loses at ID.25
//!   (ALC 3, not 0x0A): both fail.
//!
//! tx-8.5.8's new premise (bus integration before TXERR 128) is checked on
//! the opencores core only, where D14 turned the old one into an error-active
//! DUT: its strict expected failure (D27) records the suspend it now sees.

use scenario::{DutSpec, RunOptions, Scenario, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs `file` (in tb/conformance) on the model with each `from` replaced by
/// its `to` (each must occur once): true if the scenario still passes.
fn passes_with(file: &str, edits: &[(&str, &str)]) -> bool {
    let path = root().join("tb/conformance").join(file);
    let mut text = std::fs::read_to_string(&path).unwrap();
    for (from, to) in edits {
        assert_eq!(text.matches(from).count(), 1, "{file}: the mutation point `{from}` moved");
        text = text.replacen(from, to, 1);
    }
    let s = Scenario::parse(&text, &path).unwrap();
    let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
    eprintln!("{file} {edits:?}: passed {} {:?}", o.passed, o.mismatches);
    o.passed
}

const EIGHTH: &str = "tx-8.5.9-passive-no-identifier-at-eighth-suspend-bit.toml";
const RECOVERY: &str = "tx-8.5.14-passive-recovery-time.toml";

#[test]
fn a_sof_in_the_eighth_suspend_bit_is_judged_at_that_bit() {
    assert!(passes_with(EIGHTH, &[]));
    let at = |bit: u32| format!("frame = 1\nbit_in_frame = {bit}\nfields = {{ id = 0x0A4");
    let shipped = at(42);
    assert!(!passes_with(EIGHTH, &[(&shipped, &at(43))]), "a SOF in the DUT's own SOF bit is arbitration, not reception");
    assert!(passes_with(EIGHTH, &[(&shipped, &at(41))]), "the 7th suspend bit is reception too");
    assert!(!passes_with(EIGHTH, &[("{ write = \"TXERR\", value = 0x80,", "{ write = \"TXERR\", value = 0,")]), "an error-active DUT has no suspend");
}

#[test]
fn the_recovery_race_is_won_in_the_bit_31_bits_after_the_error_only() {
    assert!(passes_with(RECOVERY, &[]));
    let at = |bit: u32| format!("frame = 2\nbit_in_frame = {bit}\nfields");
    let shipped = at(57);
    assert!(!passes_with(RECOVERY, &[(&shipped, &at(56))]), "rival in the 8th suspend bit: the DUT receives, no ALI");
    assert!(!passes_with(RECOVERY, &[(&shipped, &at(58))]), "rival a bit after the DUT's SOF: ALC 3, not 0x0A");
}
