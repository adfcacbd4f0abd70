//! candump logs in and out of scenario runs: a run's log replayed as a
//! model node's traffic gives the same frames in the same order with the
//! same gaps (or gaps scaled by the capture's bit rate); bad logs are
//! refused with the scenario's file:line:key and the log's file:line.

use can_proto::CanFrame;
use cosim::candump::{LogEntry, LogKind, write_log};
use scenario::{DutSpec, RunOptions, Scenario, run};
use std::path::{Path, PathBuf};

fn tb(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tb").join(name)
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candump-replay-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// Frames and their times in µs.
fn frames(log: &[LogEntry]) -> Vec<(u64, CanFrame)> {
    log.iter()
        .filter_map(|e| match e.kind {
            LogKind::Frame(f) => Some((e.t_ps / 1_000_000, f)),
            LogKind::Error { .. } => None,
        })
        .collect()
}

/// The model DUT accepting everything at the parking network's 117.6 kbit/s
/// (16 MHz, BTR0 0x03, BTR1 0xBB), a node replaying `replay`.
fn replay_scenario(replay: &str, wait_bits: u64) -> String {
    format!(
        r#"purpose = "replay"
[clocks]
host_mhz = 50.0
can_mhz = 16.0
[dut]
kind = "model"
[[step]]
write = "CR"
value = 0x01
[[step]]
write = "ACR"
value = 0x00
[[step]]
write = "AMR"
value = 0xFF
[[step]]
write = "BTR0"
value = 0x03
[[step]]
write = "BTR1"
value = 0xBB
[[step]]
write = "CR"
value = 0x00
[[step]]
wait_bits = {wait_bits}
[[node]]
name = "player"
btr0 = 0x03
btr1 = 0xBB
acr = [0x00]
amr = [0xFF]
replay = {replay}
"#
    )
}

/// How far a replayed gap may be from the logged one: timestamps are
/// whole µs (0.1 bit here, twice), the request is rounded to a whole bit
/// time and taken at the node's next bit, and SOF waits for bus idle
/// (at most 3 bit times in all). A gap kept unscaled or a frame dropped is
/// off by 50 bit times or more.
const TOLERANCE_BITS: f64 = 3.0;
const BIT_US: f64 = 1e6 / (16e6 / 136.0); // 17 tq of 8 clocks at 16 MHz: 8.5 µs

/// The parking network's traffic (ten frames back to back) as a log.
fn parking_log() -> (PathBuf, Vec<(u64, CanFrame)>) {
    let s = Scenario::load(tb("parking-10-nodes.toml")).unwrap();
    let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
    assert!(o.passed, "{:?}", o.mismatches);
    let f = frames(&o.bus_log);
    assert_eq!(f.len(), 10, "{}", write_log(&o.bus_log, "can0"));
    let p = tmp("parking.log");
    std::fs::write(&p, write_log(&o.bus_log, "can0")).unwrap();
    (p, f)
}

fn replayed(replay: &str, wait_bits: u64) -> Vec<(u64, CanFrame)> {
    let s = Scenario::parse(&replay_scenario(replay, wait_bits), tmp("replay.toml")).unwrap();
    let o = run(&s, &RunOptions::default());
    assert!(o.passed, "{:?}\n{}", o.mismatches, o.diagnosis.to_text());
    frames(&o.bus_log)
}

fn gaps(f: &[(u64, CanFrame)]) -> Vec<f64> {
    f.windows(2).map(|w| (w[1].0 - w[0].0) as f64).collect()
}

#[test]
fn a_run_replayed_from_its_log_gives_the_same_frames_and_gaps() {
    let (log, want) = parking_log();
    // Back to back at the same bit rate, as logged.
    let got = replayed(&format!("{{ file = \"{}\", start_bit = 100 }}", log.display()), 3000);
    let ids = |f: &[(u64, CanFrame)]| f.iter().map(|x| x.1).collect::<Vec<_>>();
    assert_eq!(ids(&got), ids(&want));
    for (g, w) in gaps(&got).iter().zip(gaps(&want)) {
        eprintln!("gap {g} µs replayed, {w} µs logged");
        assert!((g - w).abs() <= TOLERANCE_BITS * BIT_US, "gap {g} µs replayed, {w} µs logged");
    }
}

#[test]
fn gaps_scale_with_the_capture_bit_rate() {
    let (log, want) = parking_log();
    // Captured at twice our rate: each gap is twice as many of our bits.
    let rate = (2.0_f64 * 16e6 / 136.0).round() as u32;
    let got = replayed(&format!("{{ file = \"{}\", bit_rate = {rate}, start_bit = 50 }}", log.display()), 6000);
    assert_eq!(got.len(), want.len());
    for (g, w) in gaps(&got).iter().zip(gaps(&want)) {
        eprintln!("gap {g} µs replayed, 2 x {w} µs expected");
        assert!((g - 2.0 * w).abs() <= TOLERANCE_BITS * BIT_US, "gap {g} µs replayed, 2 x {w} µs expected");
    }
}

#[test]
fn error_frames_are_left_out_with_a_warning_and_other_interfaces_ignored() {
    let p = tmp("mixed.log");
    std::fs::write(
        &p,
        "(0000000001.000000) can0 123#11\n(0000000001.000100) can0 20000288#0000810300000800\n(0000000001.000200) can1 456#22\n(0000000001.000850) can0 124#R\n",
    )
    .unwrap();
    let text = replay_scenario(&format!("{{ file = \"{}\", iface = \"can0\" }}", p.display()), 800);
    let s = Scenario::parse(&text, tmp("replay.toml")).unwrap();
    let t = &s.nodes[0].traffic;
    assert_eq!(t.len(), 2);
    assert_eq!(t[0].at_bit, 0);
    // 850 µs at 117.6 kbit/s = 100 bits.
    assert_eq!(t[1].at_bit, 100);
    assert!(s.warnings.iter().any(|w| w.contains("1 error frame(s)")), "{:?}", s.warnings);
    let got = replayed(&format!("{{ file = \"{}\", iface = \"can0\" }}", p.display()), 800);
    assert_eq!(got.len(), 2);
}

#[test]
fn a_bad_log_is_refused_with_both_places() {
    let p = tmp("bad.log");
    std::fs::write(&p, "(0000000001.000000) can0 123#11\n(0000000001.000100) can0 123#1\n").unwrap();
    let text = replay_scenario(&format!("{{ file = \"{}\" }}", p.display()), 100);
    let e = Scenario::parse(&text, "inline.toml").unwrap_err().to_string();
    let line = text.lines().position(|l| l.starts_with("replay")).unwrap() + 1;
    assert!(e.starts_with(&format!("inline.toml:{line}:")), "{e}");
    assert!(e.contains("node[1].replay") && e.contains("bad.log:2:") && e.contains("odd number"), "{e}");
    let e = Scenario::parse(&replay_scenario("{ file = \"/nonexistent.log\" }", 100), "inline.toml").unwrap_err().to_string();
    assert!(e.contains("cannot read candump log /nonexistent.log"), "{e}");
    std::fs::write(&p, "(0000000001.000000) can0 20000240#000000000000FF00\n").unwrap();
    let e = Scenario::parse(&text, "inline.toml").unwrap_err().to_string();
    assert!(e.contains("no data or remote frame to replay"), "{e}");
}

#[test]
fn frames_logged_at_one_instant_are_all_sent_in_order() {
    // Three frames with one timestamp (a capture with coarse timestamps):
    // the node sends them back to back; before node frames waited for a
    // free TX buffer, the second and third were dropped.
    let p = tmp("burst.log");
    std::fs::write(&p, "(0000000002.000000) can0 101#01\n(0000000002.000000) can0 102#02\n(0000000002.000000) can0 103#03\n").unwrap();
    let got = replayed(&format!("{{ file = \"{}\", start_bit = 100 }}", p.display()), 600);
    let ids: Vec<u32> = got.iter().map(|(_, f)| can_proto::FrameTrait::id(f)).map(|id| match id {
        can_proto::Id::Standard(s) => u32::from(s.as_raw()),
        can_proto::Id::Extended(e) => e.as_raw(),
    }).collect();
    assert_eq!(ids, [0x101, 0x102, 0x103]);
}
