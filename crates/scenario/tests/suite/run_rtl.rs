//! Shipped scenarios on our RTL (Verilated), and a deliberately broken copy
//! of it caught with the right field named.

use can_proto::Field;
use diagnose::{Category, DivergenceKind};
use scenario::{DutSpec, HostBfm, RunOptions, RunOutcome, Scenario, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn load(name: &str) -> Scenario {
    Scenario::load(root().join("tb").join(format!("{name}.toml"))).unwrap()
}

fn on_rtl(s: &Scenario) -> RunOutcome {
    let o = run(s, &RunOptions { dut: Some(DutSpec::rtl()), ..Default::default() });
    eprintln!("{}\nmismatches {:?}\nwall {:?}", o.diagnosis.to_text(), o.mismatches, o.wall);
    o
}

/// The shipped scenario with the host on plain Wishbone (see the ignored
/// PIO tests below for the scenarios exactly as shipped).
fn wishbone(name: &str) -> Scenario {
    let mut s = load(name);
    s.host = HostBfm::Wishbone;
    s
}

#[test]
fn rtl_de2_thesis_wiring_is_diagnosed() {
    let o = on_rtl(&wishbone("de2-thesis"));
    assert!(o.passed, "{:?}", o.mismatches);
    assert_eq!(o.diagnosis.category, Category::RxNotFollowingTx);
    assert_eq!(o.diagnosis.figures.field, Some(Field::Sof));
    assert_eq!(o.diagnosis.figures.first_attempt_tec, Some(136));
    assert_eq!(o.diagnosis.figures.bus_off_attempt, Some(16));
    assert!(o.record.divergence.is_none(), "RTL and model agree bit for bit: {:?}", o.record.divergence);
}

#[test]
fn rtl_de2_loopback_no_ack() {
    let o = on_rtl(&wishbone("de2-loopback-no-ack"));
    assert!(o.passed, "{:?}", o.mismatches);
    assert_eq!(o.diagnosis.figures.tec, Some(128));
}

#[test]
fn rtl_de2_with_ack_node_and_parking_pass() {
    for n in ["de2-with-ack-node", "parking-10-nodes"] {
        let o = on_rtl(&wishbone(n));
        assert!(o.passed, "{n}: {:?}", o.mismatches);
        assert_eq!(o.diagnosis.category, Category::Pass);
    }
}

#[test]
fn rtl_avalon_scenarios_as_shipped() {
    let o = on_rtl(&load("de2-avalon-wrapper"));
    assert!(o.passed, "{:?}", o.mismatches);
    let o = on_rtl(&load("de2-avalon-begintransfer"));
    assert!(o.passed, "{:?}", o.mismatches);
    assert_eq!(o.diagnosis.category, Category::HostBusViolation);
}

#[test]
fn rtl_de2_pelican_selftest() {
    let o = on_rtl(&wishbone("de2-pelican-selftest"));
    assert!(o.passed, "{:?}", o.mismatches);
}

#[test]
fn rtl_pio_scenarios_as_shipped() {
    for n in ["de2-thesis", "de2-loopback-no-ack", "de2-with-ack-node"] {
        let o = on_rtl(&load(n));
        assert!(o.passed, "{n}: {:?}", o.mismatches);
    }
}

/// A copy of rtl/ with the CRC polynomial off by one bit: the comparator
/// must stop at the CRC sequence of frame 1 and the diagnoser name it.
#[test]
fn broken_crc_rtl_is_caught_in_the_crc_field() {
    let dir = std::env::temp_dir().join(format!("diag-broken-crc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for e in std::fs::read_dir(root().join("rtl")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "v" || x == "vh") {
            let text = std::fs::read_to_string(&p).unwrap();
            let text = if p.file_name().unwrap() == "can_bsp.v" {
                assert!(text.contains("15'h4599"), "the mutation point moved");
                text.replace("15'h4599", "15'h4598")
            } else {
                text
            };
            std::fs::write(dir.join(p.file_name().unwrap()), text).unwrap();
        }
    }
    let s = wishbone("de2-with-ack-node");
    let o = run(&s, &RunOptions { dut: Some(DutSpec::external("broken-crc", &dir, "can_top")), ..Default::default() });
    eprintln!("{}\n{:?}", o.diagnosis.to_text(), o.record.divergence);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(!o.passed);
    assert_eq!(o.diagnosis.category, Category::DutDeviatesFromModel, "{}", o.diagnosis.to_text());
    let d = o.record.divergence.expect("a divergence");
    assert_eq!(d.kind, DivergenceKind::TxBit);
    assert_eq!(o.diagnosis.figures.field, Some(Field::Crc));
    assert_eq!(o.diagnosis.figures.frame, Some(1));
    assert!(o.diagnosis.what_happened.contains("CRC sequence"));
}
