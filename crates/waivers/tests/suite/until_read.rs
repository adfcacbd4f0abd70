//! `until-read = "IR"`: a pin waiver bounded by the event that ends the
//! deviation (the host's next read of IR), not by a count of the
//! comparator's reports, which grows with how long the host takes to read
//! IR (the 8051 bus against Wishbone). Each test shows what it still catches.

use diagnose::{Divergence, DivergenceKind};
use waivers::{Action, CollectMode, DutInfo, Observed, Session, Verdict, WaiverError, WaiverSet};

fn dut() -> DutInfo {
    DutInfo::new("opencores-can (/cores/can)")
}

const CLK: u64 = 41_667; // 24 MHz
const BIT: u64 = 40 * CLK;
const TOL: u64 = 49 * CLK; // the comparator reports a pin after 49 differing clocks

/// An irq report (DUT pending, model not) whose run began at `start_ps`.
fn irq(start_ps: u64) -> Divergence {
    Divergence {
        kind: DivergenceKind::Irq,
        time_ps: start_ps,
        bit: Some(start_ps / BIT),
        expected: 1,
        seen: 0,
        ..Divergence::default()
    }
}

fn at(now_ps: u64) -> Observed {
    Observed::timed(now_ps, BIT, CLK)
}

const EI_PIN: &str = r#"
[[waiver]]
id = "ei-pin"
kind = "irq"
dut = ["opencores-can*"]
explanation = "EI raised early on the DUT, pending until the host reads IR"
until-read = "IR"
max-hits = 1
resync = ["none"]
"#;

/// Reports `n` of one lasting difference from `t0`, each run starting
/// where the last report was taken (as the comparator restarts it).
fn reports(set: &mut WaiverSet, t0: u64, n: u64) -> Vec<Verdict> {
    (0..n).map(|k| set.check_observed(&irq(t0 + k * TOL), &dut(), &at(t0 + (k + 1) * TOL))).collect()
}

#[test]
fn one_episode_is_waived_however_long_the_host_takes_to_read_ir() {
    // A slow host: 300 reports (more than the 153 measured on Wishbone)
    // before its read of IR; all one episode.
    let mut set = WaiverSet::parse(EI_PIN, "u.toml").unwrap();
    let t0 = 1_000_000_000;
    assert!(reports(&mut set, t0, 300).iter().all(|v| matches!(v, Verdict::Waived { .. })));
    // The read completes inside the 301st report's run: that run began
    // before it, so it is still the episode (the pin tolerance after a read).
    let read = t0 + 300 * TOL + 10 * CLK;
    set.host_read("IR", read);
    assert!(matches!(set.check_observed(&irq(t0 + 300 * TOL), &dut(), &at(t0 + 301 * TOL)), Verdict::Waived { .. }));
    assert_eq!(set.hits("ei-pin"), Some(301));
    let dev = set.get("ei-pin").unwrap().deviation(301);
    assert_eq!(dev.episodes, 1);
    assert!(dev.bound_text().contains("1 episode(s), each episode until the host's next read of IR (until-read = \"IR\"), at most 1 (max-hits)"), "{}", dev.bound_text());
}

#[test]
fn a_pin_that_stays_low_after_the_ir_read_still_fails() {
    let mut set = WaiverSet::parse(EI_PIN, "u.toml").unwrap();
    let t0 = 2_000_000_000;
    assert!(reports(&mut set, t0, 5).iter().all(|v| matches!(v, Verdict::Waived { .. })));
    let read = t0 + 5 * TOL + 3 * CLK;
    set.host_read("IR", read);
    // The run that began before the read is waived; the next one began
    // after it: the pin outlasted the read by the pin tolerance.
    assert!(matches!(set.check_observed(&irq(t0 + 5 * TOL), &dut(), &at(t0 + 6 * TOL)), Verdict::Waived { .. }));
    let late = irq(t0 + 6 * TOL);
    assert_eq!(set.check_observed(&late, &dut(), &at(t0 + 7 * TOL)), Verdict::Failure);
    let notes = set.near_misses(&late, &dut(), &at(t0 + 7 * TOL));
    assert!(
        notes.iter().any(|n| n.contains(&format!("still differed after the host's read of IR that completed at {read} ps"))),
        "{notes:?}"
    );
    // Reads of other registers, or IR reads before the difference began,
    // do not end it.
    let mut set = WaiverSet::parse(EI_PIN, "u.toml").unwrap();
    set.host_read("IR", t0 - BIT);
    set.host_read("SR", t0 + 2 * TOL);
    set.host_read("TXERR", t0 + 3 * TOL);
    assert!(reports(&mut set, t0, 8).iter().all(|v| matches!(v, Verdict::Waived { .. })));
}

#[test]
fn max_hits_counts_episodes_and_a_second_difference_fails() {
    let mut set = WaiverSet::parse(EI_PIN, "u.toml").unwrap();
    let t0 = 3_000_000_000;
    assert!(reports(&mut set, t0, 4).iter().all(|v| matches!(v, Verdict::Waived { .. })));
    set.host_read("IR", t0 + 4 * TOL);
    // The pins agreed; a new difference later is a second episode.
    let t1 = t0 + 50 * BIT;
    assert_eq!(set.check_observed(&irq(t1), &dut(), &at(t1 + TOL)), Verdict::Failure);
    let notes = set.near_misses(&irq(t1), &dut(), &at(t1 + TOL));
    assert!(notes.iter().any(|n| n.contains("already used its max-hits = 1 episode(s) (until-read = \"IR\")")), "{notes:?}");
    // With max-hits = 2 it is waived, as one more episode.
    let mut set = WaiverSet::parse(&EI_PIN.replace("max-hits = 1", "max-hits = 2"), "u.toml").unwrap();
    assert!(reports(&mut set, t0, 4).iter().all(|v| matches!(v, Verdict::Waived { .. })));
    set.host_read("IR", t0 + 4 * TOL);
    assert!(matches!(set.check_observed(&irq(t1), &dut(), &at(t1 + TOL)), Verdict::Waived { .. }));
    assert_eq!(set.get("ei-pin").unwrap().episodes, 2);
    // Without the comparator's clock the episode cannot be followed: not waived.
    let mut set = WaiverSet::parse(EI_PIN, "u.toml").unwrap();
    assert_eq!(set.check(&irq(t0), &dut()), Verdict::Failure);
    let notes = set.near_misses(&irq(t0), &dut(), &Observed::default());
    assert!(notes.iter().any(|n| n.contains("until-read needs the comparator's clock")), "{notes:?}");
}

#[test]
fn in_collect_mode_the_reports_after_the_read_are_failures() {
    let mut s = Session::new(WaiverSet::parse(EI_PIN, "u.toml").unwrap(), dut(), CollectMode::Collect);
    let t0 = 7_000_000;
    let mut actions = Vec::new();
    for k in 0..6u64 {
        if k == 3 {
            s.host_read("IR", t0 + 3 * TOL - CLK);
        }
        actions.push(s.divergence_observed(irq(t0 + k * TOL), &at(t0 + (k + 1) * TOL)));
    }
    let waived = actions.iter().filter(|a| matches!(a, Action::Resync(_))).count();
    assert_eq!(waived, 3, "{actions:?}");
    assert_eq!(actions[3], Action::Continue);
    let (report, _) = s.finish();
    assert!(!report.passed());
    assert_eq!(report.deviations[0].episodes, 1);
}

fn err(src: &str) -> (usize, String, String) {
    match WaiverSet::parse(src, "bad.toml") {
        Err(WaiverError::Invalid { line, key, message, .. }) => (line, key, message),
        other => panic!("expected an error for\n{src}\ngot {other:?}"),
    }
}

#[test]
fn malformed_until_read_is_rejected_with_file_line_and_key() {
    let src = EI_PIN.trim_start();
    let (line, key, msg) = err(&src.replace("until-read = \"IR\"", "until-read = \"SR\""));
    assert_eq!((line, key.as_str()), (6, "until-read"), "{msg}");
    assert!(msg.contains("only \"IR\""), "{msg}");
    let (line, key, msg) = err(&src.replace("kind = \"irq\"", "kind = \"bus-off\""));
    assert_eq!((line, key.as_str()), (6, "until-read"), "{msg}");
    assert!(msg.contains("for kind irq"), "{msg}");
    let (line, key, msg) = err(&src.replace("max-hits = 1\n", ""));
    assert_eq!((line, key.as_str()), (6, "until-read"), "{msg}");
    assert!(msg.contains("max-hits"), "{msg}");
    let (line, key, msg) = err(&src.replace("max-hits = 1", "max-hits = 1\nlate-by = \"2 bits\""));
    assert_eq!((line, key.as_str()), (6, "until-read"), "{msg}");
    assert!(msg.contains("not both"), "{msg}");
    let (line, key, msg) = err(&src.replace("until-read = \"IR\"", "until-read = 3"));
    assert_eq!((line, key.as_str()), (6, "until-read"), "{msg}");
}
