//! `after = "data-overrun"`: a waiver for a deviation that exists only once
//! a message was lost to an RX FIFO overrun (the opencores core's D8: the
//! lost message keeps an entry in its FIFO until reset mode) applies only
//! after the reference (the model) lost one, counted since its FIFO was
//! last emptied. The waiver audit found mutant 74 (a message the
//! filter must reject, stored) hidden by the two D8 waivers in a run with
//! no overrun at all (RMC model 0x02, DUT 0x03; SR model 0x0C, DUT 0x0D):
//! those reads now fail. Each test shows what is still caught.

use diagnose::{Divergence, DivergenceKind};
use waivers::{DutInfo, Observed, Verdict, WaiverError, WaiverSet};

fn dut() -> DutInfo {
    DutInfo::new("opencores-can (/cores/can)")
}

fn read(reg: &str, model: u32, seen: u32) -> Divergence {
    Divergence { kind: DivergenceKind::RegisterRead, bit: Some(640), register: Some(reg.into()), expected: model, seen, ..Divergence::default() }
}

/// The model in PeliCAN operating mode that lost `lost` messages (None: not observed).
fn lost(lost: Option<u32>) -> Observed {
    Observed { model_mod: Some(0x00), model_lost_messages: lost, ..Observed::default() }
}

fn by(set: &mut WaiverSet, d: &Divergence, obs: &Observed) -> Option<String> {
    match set.check_observed(d, &dut(), obs) {
        Verdict::Waived { waiver_id, .. } => Some(waiver_id),
        Verdict::Failure => None,
    }
}

fn shipped() -> WaiverSet {
    WaiverSet::load(concat!(env!("CARGO_MANIFEST_DIR"), "/../../tb/waivers/opencores-upstream.toml")).unwrap()
}

/// Mutant 74's reads (the waiver audit): with no message lost in the run,
/// the D8 waivers no longer take them; after a loss they still do.
#[test]
fn the_d8_waivers_take_rmc_and_rbs_only_after_the_model_lost_a_message() {
    let rmc = read("RMC", 0x02, 0x03);
    let rbs = read("SR", 0x0C, 0x0D);
    for none in [Some(0), None] {
        let mut set = shipped();
        assert_eq!(by(&mut set, &rmc, &lost(none)), None, "RMC one more, model lost {none:?}");
        assert_eq!(by(&mut set, &rbs, &lost(none)), None, "SR.RBS for no message, model lost {none:?}");
        let why = set.near_misses(&rmc, &dut(), &lost(none)).join("\n");
        assert!(why.contains("rmc-counts-lost-message") && why.contains("after"), "{why}");
    }
    let mut set = shipped();
    assert_eq!(by(&mut set, &rmc, &lost(Some(1))).as_deref(), Some("rmc-counts-lost-message"));
    assert_eq!(by(&mut set, &rbs, &lost(Some(1))).as_deref(), Some("rbs-for-lost-message-entry"));
    // Two more messages in the core's RMC needs two lost by the model.
    let two = read("RMC", 5, 7);
    let mut set = shipped();
    assert_eq!(by(&mut set, &two, &lost(Some(1))), None, "one loss cannot explain two more");
    assert_eq!(by(&mut set, &two, &lost(Some(2))).as_deref(), Some("rmc-counts-two-lost-messages"));
    // The report prints the condition with the hits.
    let mut set = shipped();
    by(&mut set, &rmc, &lost(Some(1)));
    let dev = set.get("rmc-counts-lost-message").unwrap().deviation(1);
    assert!(
        dev.bound_text().contains("only after the model lost a message to an RX FIFO overrun (after = \"data-overrun\")"),
        "{}",
        dev.bound_text()
    );
    assert!(!dev.bound_text().contains("episode"), "{}", dev.bound_text());
}

const RMC_AFTER: &str = r#"
[[waiver]]
id = "rmc-lost"
kind = "register-read"
register = "RMC"
dut = ["opencores-can*"]
explanation = "a lost message keeps an entry in the DUT's message counter"
seen-offset = 1
after = "data-overrun"
resync = ["none"]
"#;

#[test]
fn after_counts_the_models_losses_and_keeps_the_other_bounds() {
    let mut set = WaiverSet::parse(RMC_AFTER, "a.toml").unwrap();
    assert_eq!(set.get("rmc-lost").unwrap().after_lost, Some(1));
    assert_eq!(by(&mut set, &read("RMC", 1, 2), &lost(Some(0))), None);
    assert_eq!(by(&mut set, &read("RMC", 1, 2), &lost(Some(3))).as_deref(), Some("rmc-lost"));
    // The condition adds to the others: one more only, RMC only.
    assert_eq!(by(&mut set, &read("RMC", 1, 3), &lost(Some(3))), None);
    assert_eq!(by(&mut set, &read("RXERR", 1, 2), &lost(Some(3))), None);
    let two = RMC_AFTER.replace("\"data-overrun\"", "\"2 data-overruns\"");
    let mut set = WaiverSet::parse(&two, "a.toml").unwrap();
    assert_eq!(by(&mut set, &read("RMC", 1, 2), &lost(Some(1))), None);
    assert_eq!(by(&mut set, &read("RMC", 1, 2), &lost(Some(2))).as_deref(), Some("rmc-lost"));
    let text = set.get("rmc-lost").unwrap().bound().unwrap();
    assert_eq!(text, "only after the model lost 2 messages to an RX FIFO overrun (after = \"2 data-overruns\")");
}

#[test]
fn an_after_with_until_read_prints_both_bounds() {
    let src = r#"
[[waiver]]
id = "doi-pin"
kind = "irq"
dut = ["opencores-can*"]
explanation = "DOI raised late on the DUT, pending until the host reads IR"
until-read = "IR"
after = "data-overrun"
max-hits = 1
resync = ["none"]
"#;
    let mut set = WaiverSet::parse(src, "a.toml").unwrap();
    let pin = Divergence { kind: DivergenceKind::Irq, time_ps: 1_000_000, expected: 0, seen: 1, ..Divergence::default() };
    let clock = |n: Option<u32>| Observed { model_lost_messages: n, ..Observed::timed(1_000_000, 40 * 41_667, 41_667) };
    assert_eq!(by(&mut set, &pin, &clock(Some(0))), None, "no message lost yet");
    assert_eq!(by(&mut set, &pin, &clock(Some(1))).as_deref(), Some("doi-pin"));
    let dev = set.get("doi-pin").unwrap().deviation(1);
    assert!(dev.bound_text().starts_with("; 1 episode(s), each episode until the host's next read of IR"), "{}", dev.bound_text());
    assert!(dev.bound_text().ends_with(", only after the model lost a message to an RX FIFO overrun (after = \"data-overrun\")"), "{}", dev.bound_text());
}

#[test]
fn a_bad_after_names_file_line_and_key() {
    for (value, words) in [
        ("\"overrun\"", "expected \"data-overrun\" or \"<n> data-overruns\""),
        ("\"0 data-overruns\"", "leave the key out"),
        ("\"2 data-overrun\"", "expected \"data-overrun\""),
        ("\"300 data-overruns\"", "more than the model counts"),
    ] {
        let src = RMC_AFTER.replace("\"data-overrun\"", value);
        match WaiverSet::parse(&src, "bad.toml") {
            Err(WaiverError::Invalid { file, line, key, message }) => {
                assert_eq!((file.as_str(), line, key.as_str()), ("bad.toml", 9, "after"), "{value}: {message}");
                assert!(message.contains(words), "{value}: {message}");
                let one = WaiverSet::parse(&src, "bad.toml").unwrap_err().to_string();
                assert!(one.starts_with("bad.toml:9: after: ") && !one.contains('\n'), "{one}");
            }
            other => panic!("{value}: {other:?}"),
        }
    }
    // Not a string: serde's own error, still located.
    let src = RMC_AFTER.replace("\"data-overrun\"", "1");
    match WaiverSet::parse(&src, "bad.toml") {
        Err(WaiverError::Invalid { line, key, .. }) => assert_eq!((line, key.as_str()), (9, "after")),
        other => panic!("{other:?}"),
    }
}

/// D8d on SR: DOS late only while the model still holds a message (RBS):
/// once every message is released the core's lost entry is at its head
/// and its DOS is due (the opencores mutant 113, an RRB that also clears
/// DOS, read model 0x0E, DUT 0x0C after the releases).
#[test]
fn dos_late_is_waived_only_while_the_model_still_holds_a_message() {
    let mut set = shipped();
    assert_eq!(by(&mut set, &read("SR", 0x0E, 0x0C), &lost(Some(1))), None, "every message released");
    assert_eq!(by(&mut set, &read("SR", 0x0F, 0x0D), &lost(Some(1))).as_deref(), Some("dos-at-release-not-at-loss"));
}
