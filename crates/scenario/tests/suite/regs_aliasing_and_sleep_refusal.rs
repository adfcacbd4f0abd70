//! The checks for can_regs mutants 45, 111 (a reset-mode write
//! that also lands at a second address) and 72 (sleep taken with an
//! interrupt pending) are live: each expected value set to what the mutant
//! reads fails on the golden model and on our RTL; so do the other sleep
//! refusals of the PeliCAN scenario (in reset mode, before bus-free).

use scenario::{DutSpec, RunOptions, Scenario, run};

#[allow(dead_code)] // only root() of the shared helpers is used here
use crate::common;
use common::root;

/// `(file under tb/, text of the check, the check as the mutant reads it)`.
const CHECKS: [(&str, &str, &str); 8] = [
    // mutant 111: the TX RAM write at 102 also lands in the free RAM at 110
    (
        "registers/peli-reset-mode-writes-alias-nothing.toml",
        "{ read = 110, expect = 0x5C },",
        "{ read = 110, expect = 0xDF },",
    ),
    // mutant 45: a write to the reserved 24..28 also lands in AMR0 (seen 00H)
    (
        "registers/peli-reset-mode-writes-alias-nothing.toml",
        "{ read = 20, expect = 0x2A, note = \"AMR0..3 kept\" },",
        "{ read = 20, expect = 0x00, note = \"AMR0..3 kept\" },",
    ),
    // mutant 72, PeliCAN: the request with WUI pending and the one with EI pending are taken
    (
        "mutation-holes/peli-sleep-refused-interrupt-pending.toml",
        "{ read = \"MOD\", expect = 0x00, mask = 0x1F, note = \"SM reads 0: still awake\" },",
        "{ read = \"MOD\", expect = 0x10, mask = 0x1F, note = \"SM reads 0: still awake\" },",
    ),
    (
        "mutation-holes/peli-sleep-refused-interrupt-pending.toml",
        "{ read = \"MOD\", expect = 0x00, mask = 0x1F, note = \"SM reads 0\" },",
        "{ read = \"MOD\", expect = 0x10, mask = 0x1F, note = \"SM reads 0\" },",
    ),
    // the other refusals of the PeliCAN family: in reset mode, and before bus-free after it
    (
        "mutation-holes/peli-sleep-refused-interrupt-pending.toml",
        "{ read = \"MOD\", expect = 0x01, mask = 0x1F },",
        "{ read = \"MOD\", expect = 0x11, mask = 0x1F },",
    ),
    (
        "mutation-holes/peli-sleep-refused-interrupt-pending.toml",
        "{ read = \"MOD\", expect = 0x00, mask = 0x1F, note = \"SM reads 0: no sleep before bus-free\" },",
        "{ read = \"MOD\", expect = 0x10, mask = 0x1F, note = \"SM reads 0: no sleep before bus-free\" },",
    ),
    // mutant 72, BasicCAN: clearing GTS after the refused request wakes a sleeping DUT (WUI)
    (
        "mutation-holes/basic-sleep-refused-interrupt-pending.toml",
        "{ read = \"IR\", expect = 0xE0, note = \"no WUI: the refused request",
        "{ read = \"IR\", expect = 0xF0, note = \"no WUI: the refused request",
    ),
    (
        "mutation-holes/basic-sleep-refused-interrupt-pending.toml",
        "{ read = \"IR\", expect = 0xE1, note = \"RI only\" },",
        "{ read = \"IR\", expect = 0xF1, note = \"RI only\" },",
    ),
];

#[test]
fn each_check_set_to_the_mutant_value_fails_on_model_and_rtl() {
    for (file, from, to) in CHECKS {
        let path = root().join("tb").join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.matches(from).count(), 1, "{file}: the check moved: {from}");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        for dut in [DutSpec::model(), DutSpec::rtl()] {
            let o = run(&s, &RunOptions { dut: Some(dut), ..Default::default() });
            assert!(!o.passed, "{file}: {to} passed");
        }
    }
}
