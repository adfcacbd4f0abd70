//! `[[raw-node]]`: the bit-level sender's table parses into the levels it
//! drives, bad tables give file:line:key errors, and on a run its monitor
//! and its start decide: a wire other than expected, or a start that never
//! comes, fails the scenario.

use cosim::agents::raw::RawStart;
use scenario::{DutSpec, RunOptions, Scenario, ScenarioError, run};

const HEAD: &str = r#"purpose = "raw node"
step = [
    { write = "CR", value = 1 },
    { write = "CDR", value = 0x80 },
    { write = "IER", value = 1 },
    { write = "AMR0", value = 0xFF },
    { write = "AMR1", value = 0xFF },
    { write = "AMR2", value = 0xFF },
    { write = "AMR3", value = 0xFF },
    { write = "BTR0", value = 0x41 },
    { write = "BTR1", value = 0x25 },
    { write = "MOD", value = 0 },
    { wait_bits = 12 },
    { wait_irq = true, timeout_bits = 200 },
    { read = "IR", expect = 1 },
    { read = "RXB+2", expect = 0x55 },
]

[clocks]
host_mhz = 50.0
can_mhz = 24.0

[expect]
category = "Pass"
"#;

fn parse(raw: &str) -> Result<Scenario, ScenarioError> {
    Scenario::parse(&format!("{HEAD}\n{raw}"), "raw.toml")
}

/// Line (from 1, in the whole text) where `needle` starts inside `raw`.
fn line_of(raw: &str, needle: &str) -> usize {
    let head_lines = format!("{HEAD}\n").matches('\n').count();
    let at = raw.find(needle).expect("needle in raw");
    head_lines + raw[..at].matches('\n').count() + 1
}

#[test]
fn a_raw_node_parses_into_its_start_and_levels() {
    let s = parse("[[raw-node]]\nname = \"lt\"\nframe = 2\nbit_in_frame = 57\nbits = \"0 1_0\"\nexpect_bits = \"0x1\"\n").unwrap();
    let r = &s.raw_nodes[0];
    assert_eq!(r.start, RawStart::FrameBit { frame: 2, bit: 57 });
    assert_eq!(r.bits, vec![false, true, false]);
    assert_eq!(r.expect, vec![Some(false), None, Some(true)]);
    let s = parse("[[raw-node]]\nname = \"lt\"\nidle_bits = 11\nfields = { id = 0x555, data = [0x55], r0 = 1, expect_ack = true }\n").unwrap();
    let r = &s.raw_nodes[0];
    assert_eq!(r.start, RawStart::IdleBits(11));
    let f = r.frame.as_ref().unwrap();
    assert!(f.r0);
    assert_eq!(r.bits, f.wire_bits());
    // expect_ack: any level up to the ACK slot, which must be dominant.
    let slot = f.ack_slot().unwrap();
    assert_eq!(r.expect.len(), slot + 1);
    assert!(r.expect[..slot].iter().all(Option::is_none));
    assert_eq!(r.expect[slot], Some(false));
}

#[test]
fn bad_raw_nodes_name_file_line_and_key() {
    for (raw, needle, key, words) in [
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 40\nbits = \"0 2\"\n", "bits =", "raw-node[1].bits", "`2` is not a level"),
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 40\n", "[[raw-node]]", "raw-node[1]", "either bits"),
        ("[[raw-node]]\nname = \"lt\"\nbits = \"0\"\n", "[[raw-node]]", "raw-node[1]", "where it starts"),
        ("[[raw-node]]\nname = \"lt\"\nframe = 1\nbits = \"0\"\n", "frame =", "raw-node[1].frame", "together"),
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 1\nidle_bits = 11\nbits = \"0\"\n", "[[raw-node]]", "raw-node[1]", "one start"),
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 1\nfields = { id = 0x800, data = [] }\n", "fields =", "raw-node[1].fields.id", "out of range"),
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 1\nfields = { id = 1, data = [1], r0 = 2 }\n", "fields =", "raw-node[1].fields.r0", "not a bus level"),
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 1\nfields = { id = 1, data = [1], srr = 0 }\n", "fields =", "raw-node[1].fields.srr", "extended format"),
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 1\nfields = { id = 1, data = [1], dlc = 2 }\n", "fields =", "raw-node[1].fields.data", "2 data byte(s), 1 given"),
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 1\nfields = { id = 1, data = [], flip = [99] }\n", "fields =", "raw-node[1].fields.flip", "outside the frame"),
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 1\nfields = { id = 1, data = [], until_bit = 5, expect_ack = true }\n", "fields =", "raw-node[1].fields.expect_ack", "cut"),
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 1\nfields = { id = 1, data = [], ack = 0, expect_ack = true }\n", "fields =", "raw-node[1].fields.expect_ack", "its own"),
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 1\nbits = \"0\"\nexpect_bits = \"0?\"\n", "expect_bits =", "raw-node[1].expect_bits", "`?`"),
        ("[[raw-node]]\nname = \"lt\"\nat_bit = 1\nbits = \"0\"\nspeed = 2\n", "speed", "speed", "unknown key"),
        ("[[node]]\nname = \"lt\"\nbtr0 = 0x41\nbtr1 = 0x25\n\n[[raw-node]]\nname = \"lt\"\nat_bit = 1\nbits = \"0\"\n", "name = \"lt\"\nat_bit", "raw-node[1].name", "name of its own"),
    ] {
        let e = parse(raw).expect_err(raw);
        let msg = e.to_string();
        let want_line = line_of(raw, needle);
        assert_eq!(e.line(), want_line, "{msg}");
        assert!(msg.starts_with("raw.toml:"), "{msg}");
        assert!(msg.contains(&format!("key `{key}`")), "{msg}");
        assert!(msg.contains(words), "{msg}");
    }
}

/// `offset_tq` / `offset_clocks` start the raw node inside its start bit
/// (BTR0 = 0x41, BTR1 = 0x25: 4 clocks a quantum, 40 a bit): one of them,
/// inside the bit, from a bit's start (not after idle bits); each mistake
/// is a one-line error naming the key.
#[test]
fn a_raw_node_offset_is_placed_in_quanta_or_clocks_inside_its_start_bit() {
    let at = |extra: &str| parse(&format!("[[raw-node]]\nname = \"lt\"\nframe = 1\nbit_in_frame = 42\nbits = \"0\"\n{extra}"));
    assert_eq!(at("").unwrap().raw_nodes[0].delay_clocks, 0);
    assert_eq!(at("offset_tq = 6\n").unwrap().raw_nodes[0].delay_clocks, 24, "6 quanta of 4 clocks");
    assert_eq!(at("offset_clocks = 39\n").unwrap().raw_nodes[0].delay_clocks, 39);
    for (extra, key, words) in [
        ("offset_tq = 10\n", "raw-node[1].offset_tq", "inside the start bit (10 quanta, 40 CAN clocks"),
        ("offset_tq = -1\n", "raw-node[1].offset_tq", "inside the start bit"),
        ("offset_clocks = 40\n", "raw-node[1].offset_clocks", "inside the start bit"),
        ("offset_tq = 1\noffset_clocks = 4\n", "raw-node[1].offset_tq", "not both"),
    ] {
        let e = at(extra).expect_err(extra);
        let msg = e.to_string();
        assert!(msg.starts_with("raw.toml:") && msg.contains(&format!("key `{key}`")) && msg.contains(words), "{extra}: {msg}");
    }
    let idle = parse("[[raw-node]]\nname = \"lt\"\nidle_bits = 11\nbits = \"0\"\noffset_tq = 2\n").expect_err("offset after idle bits");
    assert!(idle.to_string().contains("counts from a bit's start"), "{idle}");
}

fn model() -> RunOptions {
    RunOptions { dut: Some(DutSpec::model()), ..RunOptions::default() }
}

#[test]
fn on_a_run_the_raw_node_frame_is_received_and_its_monitor_and_start_decide() {
    // A frame with a recessive r0 from the raw node alone: the golden model
    // as DUT receives it and acknowledges (expect_ack).
    let ok = parse("[[raw-node]]\nname = \"lt\"\nat_bit = 40\nfields = { id = 0x555, data = [0x55], r0 = 1, expect_ack = true }\n").unwrap();
    let out = run(&ok, &model());
    assert!(out.passed, "{:?} {:?}", out.mismatches, out.diagnosis.what_happened);
    // The ACK slot expected recessive instead: the monitor fails the run.
    let mut bad = ok.clone();
    let slot = bad.raw_nodes[0].frame.as_ref().unwrap().ack_slot().unwrap();
    bad.raw_nodes[0].expect[slot] = Some(true);
    let out = run(&bad, &model());
    assert!(!out.passed);
    assert!(out.record.expectations.iter().any(|e| !e.passed && e.what == "raw node lt" && e.seen.contains(&format!("wire bit {slot}"))), "{:?}", out.record.expectations);
    // A second node whose start (frame 5) never comes fails a run that
    // passes otherwise: a raw node that did nothing is no silent pass.
    let never = parse("[[raw-node]]\nname = \"lt\"\nat_bit = 40\nfields = { id = 0x555, data = [0x55] }\n\n[[raw-node]]\nname = \"late\"\nframe = 5\nbit_in_frame = 0\nbits = \"0\"\n").unwrap();
    let out = run(&never, &model());
    assert!(!out.passed);
    let e = out.record.expectations.iter().find(|e| e.what == "raw node late").unwrap();
    assert!(!e.passed && e.seen.contains("never started"), "{e:?}");
}
