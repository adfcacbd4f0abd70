//! What `parse.rs` does not already cover: bad values in
//! `[[node]]` tables (DLC > 8 in node traffic, IDs out of range, BTR with
//! no valid bit timing, clocks), reads at out-of-range addresses, what
//! DLC 9..15 means when sent on purpose, and "loses nothing": a bad
//! scenario in a regression list does not stop the others from running
//! and being reported.

use can_proto::FrameTrait;
use scenario::regress::{Status, regress_inputs};
use scenario::{Action, DutSpec, RegressOptions, Scenario, ScenarioError};
use std::path::PathBuf;

const GOOD: &str = "purpose = \"t\"\nverifies = [\"x\"]\n[clocks]\nhost_mhz = 50.0\ncan_mhz = 24.0\n[host]\nbfm = \"wishbone\"\n[[step]]\nwrite = \"CR\"\nvalue = 1\n";

fn err(text: &str) -> ScenarioError {
    Scenario::parse(text, "tb/bad.toml").expect_err("must be rejected")
}

/// A `[[node]]` (lines 11..) with `send` as given.
fn node(btr: &str, send: &str) -> String {
    format!("{GOOD}[[node]]\nname = \"n\"\n{btr}\nsend = [ {send} ]\n")
}

const BTR: &str = "btr0 = 0x41\nbtr1 = 0x25";

#[test]
fn dlc_over_8_in_node_traffic() {
    let e = err(&node(BTR, "{ id = 0x10, data = [1,2,3,4,5,6,7,8], dlc = 12 }"));
    assert_eq!(e.key(), "node[1].send[1].dlc", "{e}");
    assert!(e.to_string().starts_with("tb/bad.toml:15:"), "{e}");
    assert!(e.to_string().contains("DLC 12 > 8"), "{e}");
    let e = err(&node(BTR, "{ id = 0x10, data = [1,2,3,4,5,6,7,8,9] }"));
    assert_eq!(e.key(), "node[1].send[1].data", "{e}");
    let e = err(&node(BTR, "{ id = 0x10, dlc = 16, raw_dlc = true, data = [1,2,3,4,5,6,7,8] }"));
    assert!(e.to_string().contains("4-bit field"), "{e}");
}

/// DLC 9..15 on purpose (`raw_dlc`): the CAN rule, 8 data bytes, and the
/// raw DLC kept in the TX buffer so the wire carries it.
#[test]
fn raw_dlc_means_eight_bytes_and_is_kept_on_the_wire() {
    let s = Scenario::parse(&node(BTR, "{ id = 0x10, data = [1,2,3,4,5,6,7,8], dlc = 15, raw_dlc = true }"), "x").unwrap();
    let f = s.nodes[0].traffic[0].frame;
    assert_eq!((f.dlc_raw(), f.data().len()), (15, 8));
    let s = Scenario::parse(&format!("{GOOD}[[step]]\nload_tx = {{ id = 0x123, data = [1,2,3,4,5,6,7,8], dlc = 9, raw_dlc = true }}\n"), "x").unwrap();
    let writes: Vec<(u8, u8)> = s
        .steps
        .iter()
        .filter_map(|st| match st.action {
            Action::Write { addr, value, .. } => Some((addr, value)),
            _ => None,
        })
        .collect();
    // BasicCAN TXID2 = ID.2-0 | RTR | DLC: DLC 9, then eight data bytes
    assert!(writes.contains(&(11u8, (((0x123u16 & 7) as u8) << 5) | 9)), "{writes:?}");
    assert_eq!(writes.iter().filter(|(a, _)| (12..20).contains(a)).count(), 8, "{writes:?}");
    // with dlc 9 and fewer than 8 bytes the frame is inconsistent
    let e = err(&format!("{GOOD}[[step]]\nload_tx = {{ id = 0x123, data = [1], dlc = 9, raw_dlc = true }}\n"));
    assert!(e.to_string().contains("needs 8 data byte(s), 1 given"), "{e}");
}

#[test]
fn ids_out_of_range_in_node_traffic_and_load_tx() {
    let e = err(&node(BTR, "{ id = 0x1FFFFFFF }"));
    assert!(e.to_string().contains("out of range for a standard frame"), "{e}");
    assert!(e.to_string().contains("extended = true"), "says how to fix it: {e}");
    let e = err(&node(BTR, "{ id = 0x20000000, extended = true }"));
    assert!(e.to_string().contains("extended frame (0..=0x1FFFFFFF)"), "{e}");
    let e = err(&format!("{GOOD}[[step]]\nload_tx = {{ id = -1 }}\n"));
    assert_eq!(e.key(), "step[2].load_tx.id", "{e}");
    assert!(!e.to_string().contains("FFFFFFFF"), "a negative ID is shown as written: {e}");
    // the limits themselves are accepted
    Scenario::parse(&node(BTR, "{ id = 0x7FF }, { id = 0x1FFFFFFF, extended = true }, { id = 0 }"), "x").unwrap();
}

#[test]
fn node_timing_with_no_valid_bit_timing() {
    // BTR0 = 0, BTR1 = 0x12: 5 tq of one clock at 24 MHz = 4.8 Mbit/s
    let e = err(&node("btr0 = 0\nbtr1 = 0x12", "{ id = 1 }"));
    assert_eq!(e.key(), "node[1].btr1", "{e}");
    assert!(e.to_string().contains("no valid bit timing"), "{e}");
    assert_eq!(e.line(), 14, "{e}");
    let e = err(&node("btr0 = 256\nbtr1 = 0x25", "{ id = 1 }"));
    assert_eq!(e.key(), "node[1].btr0", "{e}");
    let e = err(&node(&format!("{BTR}\ncan_mhz = 0.0"), "{ id = 1 }"));
    assert_eq!(e.key(), "node[1].can_mhz", "{e}");
    let e = err(&node(&format!("{BTR}\ncan_mhz = nan"), "{ id = 1 }"));
    assert_eq!(e.key(), "node[1].can_mhz", "{e}");
    // a bit rate no BTR can reach at this clock
    let e = err(&GOOD.replace("can_mhz = 24.0", "can_mhz = 1.0\nbit_rate = 1000000"));
    assert_eq!(e.key(), "clocks.bit_rate", "{e}");
    let e = err(&GOOD.replace("can_mhz = 24.0", "can_mhz = 24.0\nbit_rate = 0"));
    assert_eq!(e.key(), "clocks.bit_rate", "{e}");
    for v in ["-1.0", "inf", "1e9"] {
        let e = err(&GOOD.replace("host_mhz = 50.0", &format!("host_mhz = {v}")));
        assert_eq!(e.key(), "clocks.host_mhz", "{v}: {e}");
    }
}

#[test]
fn reads_at_out_of_range_addresses() {
    let e = err(&format!("{GOOD}[[step]]\nread = 32\n"));
    assert!(e.to_string().contains("address 32 is out of range"), "{e}");
    assert_eq!(e.line(), 12, "{e}");
    let e = err(&format!("{GOOD}[[step]]\nread = 300\n"));
    assert!(e.key().starts_with("step[2]"), "{e}");
    let e = err(&format!("{GOOD}[[step]]\nread = -1\n"));
    assert!(e.key().starts_with("step[2]"), "{e}");
    let e = err(&format!("{GOOD}[[step]]\nread = \"TXDATA+9\"\n"));
    assert!(e.key().starts_with("step[2]"), "{e}");
    // in PeliCAN the map ends at 127
    let peli = format!("{GOOD}[[step]]\nwrite = \"CDR\"\nvalue = 0x80\n");
    Scenario::parse(&format!("{peli}[[step]]\nread = 127\n"), "x").unwrap();
    let e = err(&format!("{peli}[[step]]\nread = 128\n"));
    assert!(e.to_string().contains("PeliCAN"), "{e}");
}

/// Per test and per process: two `cargo test` runs may share a target dir.
fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("scenario-bad-input").join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A list with a good scenario, a scenario with an unknown key, a missing
/// file and another good scenario: both good ones run and are reported,
/// the bad ones are error rows naming file, line and key, and the
/// regression fails.
#[test]
fn a_bad_scenario_in_a_list_does_not_stop_the_others() {
    let dir = scratch("list");
    std::fs::write(dir.join("first.toml"), GOOD).unwrap();
    std::fs::write(dir.join("typo.toml"), GOOD.replace("value = 1", "value = 1\nvaleu = 2")).unwrap();
    std::fs::write(dir.join("last.toml"), GOOD).unwrap();
    std::fs::write(dir.join("all.list"), "first.toml\ntypo.toml\ngone.toml  # deleted\nlast.toml\n").unwrap();
    let duts = vec![DutSpec::model()];
    let rep = regress_inputs(&[dir.join("all.list")], &duts, &RegressOptions { jobs: 1, ..Default::default() }).unwrap();
    let table = rep.to_table();
    assert_eq!(rep.scenarios, ["first", "last", "typo", "gone"], "{table}");
    assert_eq!(rep.cells.len(), 4, "{table}");
    for name in ["first", "last"] {
        let c = rep.cells.iter().find(|c| c.scenario == name).unwrap();
        assert!(!matches!(c.status, Status::Error(_)), "{name} ran: {:?}", c.status);
    }
    let typo = rep.cells.iter().find(|c| c.scenario == "typo").unwrap();
    match &typo.status {
        Status::Error(m) => {
            assert!(m.contains("typo.toml:11:") && m.contains("valeu"), "{m}");
        }
        s => panic!("typo: {s:?}"),
    }
    let gone = rep.cells.iter().find(|c| c.scenario == "gone").unwrap();
    assert!(matches!(&gone.status, Status::Error(m) if m.contains("gone.toml")), "{:?}", gone.status);
    // The user's input, not the core: exit 2 (neither 1 "failed" nor 125
    // "does not build", which git bisect would read as bad / skip).
    assert_eq!(rep.unloadable, ["typo", "gone"]);
    assert_eq!(rep.exit_code(), scenario::regress::EXIT_BAD_INPUT);
    assert!(table.contains("typo") && table.contains("gone") && table.contains("first"), "{table}");
    let junit = rep.to_junit();
    assert!(junit.contains("valeu") && junit.contains("gone.toml"), "{junit}");
    // scenario files given one by one behave the same
    let rep = regress_inputs(&[dir.join("typo.toml"), dir.join("first.toml")], &duts, &RegressOptions { jobs: 1, ..Default::default() }).unwrap();
    assert_eq!(rep.cells.len(), 2);
    // only an unreadable list is an error
    assert!(regress_inputs(&[dir.join("nope.list")], &duts, &RegressOptions::default()).is_err());
}

/// Found by `fuzz_parse`: a value of the wrong type that is an array
/// (`host_mhz = []`) gave an error naming the key `` (empty).
#[test]
fn wrong_type_errors_name_their_key() {
    let e = err(&GOOD.replace("host_mhz = 50.0", "host_mhz = []"));
    assert_eq!((e.line(), e.key()), (4, "host_mhz"), "{e}");
    let e = err(&format!("{GOOD}[[step]]\nload_tx = {{ id = [] }}\n"));
    assert_eq!(e.key(), "id", "{e}");
    let e = err(&GOOD.replace("value = 1", "value = { a = 1 }"));
    assert_eq!(e.key(), "value", "{e}");
}

/// A glitch's pulse is placed on the DUT's bit grid in CAN clocks
/// (`offset_clocks`/`width_clocks`) or in its time quanta (`offset_tq`/
/// `width_tq`; BTR0 = 0x41, BTR1 = 0x25: 10 quanta of 4 clocks, 40 clocks):
/// only on a glitch given by frame + bit_in_frame, on `dut-rx`, one pair,
/// both keys, at least 1 wide, inside the bit; each mistake is a one-line
/// error naming the key.
#[test]
fn glitch_pulse_keys_are_checked() {
    let with = |fault: &str| format!("{GOOD}[[step]]\nwrite = \"BTR0\"\nvalue = 0x41\n[[step]]\nwrite = \"BTR1\"\nvalue = 0x25\n[[fault]]\n{fault}\n");
    let ok = "kind = \"glitch\"\nframe = 1\nbit_in_frame = 25\noffset_clocks = 0\nwidth_clocks = 24\ntarget = \"dut-rx\"";
    assert_eq!(Scenario::parse(&with(ok), "tb/ok.toml").unwrap().faults[0].pulse_clocks, Some((0, 24)));
    let tq = "kind = \"glitch\"\nframe = 1\nbit_in_frame = 3\noffset_tq = 9\nwidth_tq = 1\ntarget = \"dut-rx\"";
    assert_eq!(Scenario::parse(&with(tq), "tb/ok.toml").unwrap().faults[0].pulse_clocks, Some((36, 4)), "quanta are 4 CAN clocks");
    for (bad, key, says) in [
        (ok.replace("kind = \"glitch\"", "kind = \"flip\""), "offset_clocks", "no glitch"),
        (ok.replace("target = \"dut-rx\"", "target = \"bus\""), "offset_clocks", "dut-rx"),
        (ok.replace("width_clocks = 24", ""), "offset_clocks", "together"),
        (ok.replace("width_clocks = 24", "width_clocks = 0"), "offset_clocks", "at least 1"),
        (ok.replace("offset_clocks = 0", "offset_clocks = -3"), "offset_clocks", "at least 1"),
        (ok.replace("offset_clocks = 0", "offset_clocks = 30").replace("width_clocks = 24", "width_clocks = 11"), "offset_clocks", "bit of 40 CAN clocks"),
        (ok.replace("frame = 1\nbit_in_frame = 25", "at_bit = 100"), "offset_clocks", "frame + bit_in_frame"),
        (tq.replace("width_tq = 1", ""), "offset_tq", "together"),
        (tq.replace("width_tq = 1", "width_tq = 2"), "offset_tq", "10 quanta"),
        (tq.replace("offset_tq = 9", "offset_tq = -1"), "offset_tq", "10 quanta"),
        (format!("{tq}\noffset_clocks = 0\nwidth_clocks = 4"), "offset_tq", "not both"),
    ] {
        let e = err(&with(&bad));
        assert_eq!(e.key(), format!("fault[1].{key}"), "{e}");
        assert!(e.to_string().starts_with("tb/bad.toml:"), "{e}");
        assert!(e.to_string().contains(says), "{bad}: {e}");
    }
}

/// `grid = "sof"` counts a placed glitch on the nominal grid from its
/// frame's SOF edge: only on a placed glitch, only "sof" or "bench"; each
/// mistake is a one-line error naming the key.
#[test]
fn glitch_grid_key_is_checked() {
    let with = |fault: &str| format!("{GOOD}[[step]]\nwrite = \"BTR0\"\nvalue = 0x41\n[[step]]\nwrite = \"BTR1\"\nvalue = 0x25\n[[fault]]\n{fault}\n");
    let ok = "kind = \"glitch\"\nframe = 1\nbit_in_frame = 46\noffset_tq = 5\nwidth_tq = 5\ntarget = \"dut-rx\"\ngrid = \"sof\"";
    assert!(Scenario::parse(&with(ok), "tb/ok.toml").unwrap().faults[0].pulse_on_sof_grid);
    let bench = Scenario::parse(&with(&ok.replace("\"sof\"", "\"bench\"")), "tb/ok.toml").unwrap();
    assert!(!bench.faults[0].pulse_on_sof_grid);
    let plain = Scenario::parse(&with(&ok.replace("\ngrid = \"sof\"", "")), "tb/ok.toml").unwrap();
    assert!(!plain.faults[0].pulse_on_sof_grid, "the bench's grid by default");
    for (bad, says) in [
        (ok.replace("\"sof\"", "\"peer\""), "use \"sof\""),
        (ok.replace("offset_tq = 5\nwidth_tq = 5\n", ""), "places a glitch's pulse"),
    ] {
        let e = err(&with(&bad));
        assert_eq!(e.key(), "fault[1].grid", "{e}");
        assert!(e.to_string().starts_with("tb/bad.toml:") && e.to_string().contains(says), "{bad}: {e}");
    }
}

/// `level` makes a placed glitch force a level instead of inverting the
/// wire's: only on a placed glitch, only "dominant" or "recessive"; each
/// mistake is a one-line error naming the key.
#[test]
fn glitch_level_key_is_checked() {
    let with = |fault: &str| format!("{GOOD}[[step]]\nwrite = \"BTR0\"\nvalue = 0x41\n[[step]]\nwrite = \"BTR1\"\nvalue = 0x25\n[[fault]]\n{fault}\n");
    let ok = "kind = \"glitch\"\nframe = 1\nbit_in_frame = 45\noffset_clocks = 32\nwidth_clocks = 8\ntarget = \"dut-rx\"\nlevel = \"dominant\"";
    let f = &Scenario::parse(&with(ok), "tb/ok.toml").unwrap().faults[0];
    assert_eq!((f.pulse_clocks, f.pulse_level), (Some((32, 8)), Some(can_proto::DOMINANT)));
    let rec = Scenario::parse(&with(&ok.replace("\"dominant\"", "\"recessive\"")), "tb/ok.toml").unwrap();
    assert_eq!(rec.faults[0].pulse_level, Some(!can_proto::DOMINANT));
    let plain = Scenario::parse(&with(&ok.replace("\nlevel = \"dominant\"", "")), "tb/ok.toml").unwrap();
    assert_eq!(plain.faults[0].pulse_level, None, "no level: the pulse inverts");
    for (bad, says) in [
        (ok.replace("\"dominant\"", "\"low\""), "use \"dominant\" or \"recessive\""),
        (ok.replace("offset_clocks = 32\nwidth_clocks = 8\n", ""), "placed glitch"),
    ] {
        let e = err(&with(&bad));
        assert_eq!(e.key(), "fault[1].level", "{e}");
        assert!(e.to_string().starts_with("tb/bad.toml:") && e.to_string().contains(says), "{bad}: {e}");
    }
}
