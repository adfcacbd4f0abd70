//! `consequences`: scenario expectations that follow from a waived
//! deviation on reads where DUT and model agree. Waived only when listed
//! and only after the waiver was hit in the same run; what each still catches.

use diagnose::{Divergence, DivergenceKind};
use waivers::{Action, CollectMode, DutInfo, Session, WaiverError, WaiverSet};

const NO_SLEEP: &str = r#"
[[waiver]]
id = "no-sleep"
kind = "register-read"
register = "MOD"
address = 0
bits = [4]
dut = ["opencores-can*"]
explanation = "no sleep mode"
resync = ["none"]
consequences = ["sleepy:step 21", "sleepy:received by acker"]
"#;

fn session() -> Session {
    Session::new(WaiverSet::parse(NO_SLEEP, "c.toml").unwrap(), DutInfo::new("opencores-can (/x)"), CollectMode::Collect)
}

fn mod_read() -> Divergence {
    Divergence { kind: DivergenceKind::RegisterRead, bit: Some(15), register: Some("MOD".into()), expected: 0x10, seen: 0x00, ..Divergence::default() }
}

#[test]
fn a_listed_consequence_after_the_waiver_was_hit_is_waived_and_listed() {
    let mut s = session();
    assert!(matches!(s.divergence(mod_read()), Action::Resync(_)));
    assert_eq!(s.waive_consequence("sleepy", 21, "IR", 0xFF, 0x10, 0x01).as_deref(), Some("no-sleep"));
    assert_eq!(s.waive_received_consequence("sleepy", "acker", 3, Some(2)).as_deref(), Some("no-sleep"));
    // Still caught: an unlisted step, the same step of another scenario, another node.
    assert_eq!(s.waive_consequence("sleepy", 22, "MOD", 0x1F, 0x00, 0x10), None);
    assert_eq!(s.waive_consequence("other", 21, "IR", 0xFF, 0x10, 0x01), None);
    assert_eq!(s.waive_received_consequence("sleepy", "talker", 3, Some(2)), None);
    // A met expectation is no consequence of anything.
    assert_eq!(s.waive_consequence("sleepy", 21, "IR", 0xFF, 0x10, 0x10), None);
    let (report, _) = s.finish();
    assert!(report.passed());
    assert_eq!(report.waived_expectations.len(), 2);
    let e = &report.waived_expectations[0];
    assert!(e.consequence && e.step == 21 && e.seen == 0x01 && e.model == 0x01 && e.waiver_id == "no-sleep", "{e:?}");
    let text = report.to_text();
    assert!(text.contains("WAIVED [no-sleep] expectation of step 21: IR") && text.contains("a listed consequence of waiver no-sleep"), "{text}");
    assert!(text.contains("frames received by acker: expected 3"), "{text}");
    let junit = report.to_junit("s");
    assert!(junit.contains("a listed consequence of waiver no-sleep"), "{junit}");
}

#[test]
fn a_listed_consequence_without_the_waiver_hit_still_fails() {
    let mut s = session();
    assert_eq!(s.waive_consequence("sleepy", 21, "IR", 0xFF, 0x10, 0x01), None);
    assert_eq!(s.waive_received_consequence("sleepy", "acker", 3, Some(2)), None);
    // A hit of the waiver AFTER the expectation does not waive it retroactively.
    assert!(matches!(s.divergence(mod_read()), Action::Resync(_)));
    let (report, _) = s.finish();
    assert!(report.waived_expectations.is_empty(), "{}", report.to_text());
}

#[test]
fn malformed_consequences_are_rejected_with_file_line_key() {
    let err = |src: &str| match WaiverSet::parse(src, "c.toml") {
        Err(WaiverError::Invalid { file, line, key, message }) => (file, line, key, message),
        other => panic!("expected an error, got {other:?}"),
    };
    let src = NO_SLEEP.trim_start();
    for bad in ["sleepy:21", "sleepy", "sleepy:step 0", ":step 3", "sleepy:received acker"] {
        let (file, line, key, msg) = err(&src.replace("sleepy:step 21", bad));
        assert_eq!((file.as_str(), line, key.as_str()), ("c.toml", 10, "consequences"), "{bad}: {msg}");
    }
    let (_, line, key, msg) = err(&src.replace("\"sleepy:received by acker\"", "\"sleepy:step 21\""));
    assert_eq!((line, key.as_str()), (10, "consequences"));
    assert!(msg.contains("twice"), "{msg}");
    let (_, _, key, msg) = err(&src.replace("consequences = [\"sleepy:step 21\", \"sleepy:received by acker\"]", "consequences = []"));
    assert_eq!(key, "consequences", "{msg}");
}

const EARLY_RELEASE: &str = r#"
[[waiver]]
id = "early-release"
kind = "register-read"
register = "SR"
address = 2
bits = [2, 3]
dut = ["opencores-can*"]
explanation = "TBS and TCS released at the start of the last attempt"
resync = ["none"]
consequences = ["sat:step 53"]
"#;

fn sr_read(bit: u64, model: u32, dut: u32) -> Divergence {
    Divergence { kind: DivergenceKind::RegisterRead, bit: Some(bit), register: Some("SR".into()), expected: model, seen: dut, ..Divergence::default() }
}

fn early_release_session() -> Session {
    Session::new(WaiverSet::parse(EARLY_RELEASE, "c.toml").unwrap(), DutInfo::new("opencores-can (/x)"), CollectMode::Collect)
}

#[test]
fn a_listed_consequence_on_a_waived_read_the_model_also_misses_is_waived_with_the_models_value() {
    let mut s = early_release_session();
    // The deviation, first seen on an earlier SR poll (the one that ended the host's wait).
    assert!(matches!(s.divergence(sr_read(373, 0x20, 0x2C)), Action::Resync(_)));
    // The scenario's read, a frame early: diverges (waived) and the model misses too.
    let before = s.waived_count();
    assert!(matches!(s.divergence(sr_read(403, 0x20, 0x2C)), Action::Resync(_)));
    // Not the read's own deviation: the model's 0x20 misses 0x04 as well.
    assert_eq!(s.waive_expectation(before, 53, "SR", 0x3C, 0x04, 0x2C), None);
    assert_eq!(s.waive_consequence_on_waived_read(before, "sat", 53, "SR", 0x3C, 0x04, 0x2C).as_deref(), Some("early-release"));
    let (report, _) = s.finish();
    let e = &report.waived_expectations[0];
    assert!(e.consequence && e.step == 53 && e.seen == 0x2C && e.model == 0x20, "{e:?}");
    assert!(report.to_text().contains("DUT 0x2C (model 0x20) (a listed consequence of waiver early-release"), "{}", report.to_text());
}

#[test]
fn a_consequence_on_a_waived_read_still_catches_what_it_does_not_name() {
    // Waiver hit only by this very read (not before it): no consequence.
    let mut s = early_release_session();
    let before = s.waived_count();
    assert!(matches!(s.divergence(sr_read(403, 0x20, 0x2C)), Action::Resync(_)));
    assert_eq!(s.waive_consequence_on_waived_read(before, "sat", 53, "SR", 0x3C, 0x04, 0x2C), None);
    // Hit before; but an unlisted step, another scenario, a read that did not
    // diverge, a read whose value is not the waived one, a model that meets
    // the expectation (that is the read's own deviation) all still fail.
    let before = s.waived_count();
    assert!(matches!(s.divergence(sr_read(404, 0x20, 0x2C)), Action::Resync(_)));
    assert_eq!(s.waive_consequence_on_waived_read(before, "sat", 54, "SR", 0x3C, 0x04, 0x2C), None);
    assert_eq!(s.waive_consequence_on_waived_read(before, "other", 53, "SR", 0x3C, 0x04, 0x2C), None);
    assert_eq!(s.waive_consequence_on_waived_read(s.waived_count(), "sat", 53, "SR", 0x3C, 0x04, 0x2C), None);
    assert_eq!(s.waive_consequence_on_waived_read(before, "sat", 53, "SR", 0x3C, 0x04, 0x28), None);
    assert_eq!(s.waive_consequence_on_waived_read(before, "sat", 53, "SR", 0x3C, 0x20, 0x2C), None);
    // A met expectation is no consequence of anything.
    assert_eq!(s.waive_consequence_on_waived_read(before, "sat", 53, "SR", 0x3C, 0x2C, 0x2C), None);
    let (report, _) = s.finish();
    assert!(report.waived_expectations.is_empty(), "{}", report.to_text());
}
