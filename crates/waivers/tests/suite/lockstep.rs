//! A tiny fake lockstep: a golden "model" node and a "DUT" node go through
//! the same no-acknowledge retransmissions (the DE2 loopback case) and the
//! loop compares their error-flag bits, SR and TXERR reads, the way cosim's
//! comparator does, handing each divergence to a waiver [`Session`] and
//! applying the resync steps it returns.
//!
//! The DUT deviates on purpose in two ways:
//! 1. SR.ES (error status, TEC >= 96) is set one attempt late;
//! 2. it enters error passive one bit late: on its first attempt at
//!    TEC = 128 it still drives `lag` dominant error-flag bits and counts an
//!    active error, ending at TEC = 136 (the upstream opencores deviation).

use can_proto::Field;
use diagnose::{Divergence, DivergenceKind};
use waivers::{Action, CollectMode, DutInfo, Observed, Resync, Session, WaiverReport, WaiverSet};

const ATTEMPTS: u32 = 24;
const FLAG_BITS: u64 = 2;
const SR_ES: u8 = 0x40;
/// The TEC pair (tests/data), as first shipped for the upstream core.
const UPSTREAM: &str = include_str!("../data/tec-pair.toml");
const UPSTREAM_NAME: &str = "tests/data/tec-pair.toml";

/// SR.ES one attempt late, `late-bits = 1`, no resync (the next read agrees).
const ES_WAIVER: &str = r#"
[[waiver]]
id = "es-one-attempt-late"
kind = "register-read"
register = "SR"
bits = [6]
dut = ["*opencores*"]
explanation = "SR.ES follows TEC >= 96 one attempt late; the host sees it at the next read."
resync = ["none"]
"#;

#[derive(Clone, Copy, Debug, Default)]
struct Node {
    tec: u16,
    tec_before: u16,
    was_passive: bool,
    /// Dominant flag bits sent on the first attempt at TEC >= 128 (0: strict).
    passive_lag: u32,
    /// SR.ES computed from the TEC before the last error (one attempt late).
    es_late: bool,
}

#[derive(Clone, Copy, Debug)]
struct FlagBit {
    tx: bool,
    field: Field,
}

impl Node {
    fn strict() -> Node {
        Node::default()
    }

    fn deviant(passive_lag: u32) -> Node {
        Node { passive_lag, es_late: true, ..Node::default() }
    }

    /// One acknowledge error: the error flag's first bits and the TEC rule
    /// (CAN 2.0B: +8 for a transmitter; an error-passive transmitter's ACK
    /// error with a passive flag does not count).
    fn ack_error(&mut self) -> [FlagBit; FLAG_BITS as usize] {
        self.tec_before = self.tec;
        let passive = self.tec >= 128;
        let late = passive && !self.was_passive && self.passive_lag > 0;
        let mut bits = [FlagBit { tx: true, field: Field::PassiveErrorFlag }; FLAG_BITS as usize];
        for (k, b) in bits.iter_mut().enumerate() {
            if !passive {
                *b = FlagBit { tx: false, field: Field::ActiveErrorFlag };
            } else if late && (k as u32) < self.passive_lag {
                b.tx = false;
            }
        }
        if !passive || late {
            self.tec += 8;
        }
        self.was_passive = passive;
        bits
    }

    fn sr(&self) -> u8 {
        let t = if self.es_late { self.tec_before } else { self.tec };
        0x0C | if t >= 96 { SR_ES } else { 0 }
    }
}

/// How the fake run ended.
#[derive(Debug)]
struct Outcome {
    report: WaiverReport,
    set: WaiverSet,
    completed: bool,
    model_tec: u16,
    reads_equal: u32,
}

fn opencores() -> DutInfo {
    DutInfo::new("/work/cores/opencores-can").revision("r5")
}

fn lockstep(mut model: Node, mut dut: Node, set: WaiverSet, mode: CollectMode) -> Outcome {
    let mut s = Session::new(set, opencores(), mode);
    let mut bit = 0u64;
    let mut skip = 0u32;
    let mut reads_equal = 0;
    // Applies a verdict; false means stop.
    let handle = |s: &mut Session, d: Divergence, dut: &Node, model: &mut Node, skip: &mut u32| -> bool {
        let obs = Observed { dut_tec: Some(dut.tec), dut_rec: Some(0), ..Default::default() };
        match s.divergence_observed(d, &obs) {
            Action::Resync(steps) => {
                for r in steps {
                    match r {
                        Resync::SkipBits(n) => *skip = n - 1,
                        Resync::AdoptTec(v) => model.tec = v.map(u16::from).unwrap_or(dut.tec),
                        other => panic!("the fake applies no {other:?}"),
                    }
                }
                true
            }
            Action::Continue => true,
            Action::Stop => false,
        }
    };
    for attempt in 1..=ATTEMPTS {
        let (m, d) = (model.ack_error(), dut.ack_error());
        for k in 0..FLAG_BITS as usize {
            bit += 1;
            if skip > 0 {
                skip -= 1;
                continue;
            }
            if m[k].tx != d[k].tx {
                let dv = Divergence {
                    kind: DivergenceKind::TxBit,
                    time_ps: bit * 1_666_667,
                    bit: Some(bit),
                    frame: Some(attempt),
                    field: Some(m[k].field),
                    expected: m[k].tx as u32,
                    seen: d[k].tx as u32,
                    context: format!("error flag bit {k}"),
                    ..Divergence::default()
                };
                if !handle(&mut s, dv, &dut, &mut model, &mut skip) {
                    return finish(s, false, &model, reads_equal);
                }
            }
        }
        bit += 1;
        for (reg, mv, dv) in [("SR", model.sr(), dut.sr()), ("TXERR", model.tec as u8, dut.tec as u8)] {
            if mv == dv {
                reads_equal += 1;
                continue;
            }
            let d = Divergence {
                kind: DivergenceKind::RegisterRead,
                time_ps: bit * 1_666_667,
                bit: Some(bit),
                frame: Some(attempt),
                register: Some(reg.into()),
                expected: mv as u32,
                seen: dv as u32,
                ..Divergence::default()
            };
            if !handle(&mut s, d, &dut, &mut model, &mut skip) {
                return finish(s, false, &model, reads_equal);
            }
        }
    }
    finish(s, true, &model, reads_equal)
}

fn finish(s: Session, completed: bool, model: &Node, reads_equal: u32) -> Outcome {
    let snap = s.snapshot();
    let (report, set) = s.finish();
    assert_eq!(snap, report, "a snapshot at the end is the final report");
    Outcome { report, set, completed, model_tec: model.tec, reads_equal }
}

fn upstream() -> WaiverSet {
    WaiverSet::parse(UPSTREAM, UPSTREAM_NAME).expect("the shipped waiver file loads")
}

fn es() -> WaiverSet {
    WaiverSet::parse(ES_WAIVER, "es.toml").unwrap()
}

fn both() -> WaiverSet {
    let mut set = es();
    set.merge(upstream()).unwrap();
    set
}

// ---- what done means ----

#[test]
fn the_strict_pair_never_diverges() {
    let o = lockstep(Node::strict(), Node::strict(), WaiverSet::empty(), CollectMode::StopAtFirst);
    assert!(o.completed && o.report.passed());
    assert_eq!(o.model_tec, 128, "no-ack retransmissions stop counting at error passive");
}

#[test]
fn without_waivers_the_run_stops_at_the_first_deviation() {
    let o = lockstep(Node::strict(), Node::deviant(1), WaiverSet::empty(), CollectMode::StopAtFirst);
    assert!(!o.completed);
    assert!(o.report.stopped_early);
    assert_eq!(o.report.failures.len(), 1);
    assert!(o.report.waived.is_empty());
    let d = &o.report.failures[0];
    assert_eq!((d.kind, d.register.as_deref()), (DivergenceKind::RegisterRead, Some("SR")));
    assert_eq!((d.frame, d.expected as u8 ^ d.seen as u8), (Some(12), SR_ES), "TEC reaches 96 at attempt 12");
    assert!(!o.report.to_text().contains("WAIVED"));
}

#[test]
fn with_one_waiver_the_run_stops_at_the_second_deviation() {
    let o = lockstep(Node::strict(), Node::deviant(1), es(), CollectMode::StopAtFirst);
    assert!(!o.completed);
    assert_eq!(o.report.waived.len(), 1);
    assert_eq!(o.report.waived[0].waiver_id, "es-one-attempt-late");
    assert_eq!(o.report.failures.len(), 1);
    let d = &o.report.failures[0];
    assert_eq!((d.kind, d.field, d.frame), (DivergenceKind::TxBit, Some(Field::PassiveErrorFlag), Some(17)));
    assert_eq!((d.expected, d.seen), (1, 0), "the model's passive flag is recessive, the DUT drives dominant");
}

#[test]
fn with_both_waivers_the_run_completes_and_lists_both_as_waived() {
    let o = lockstep(Node::strict(), Node::deviant(1), both(), CollectMode::StopAtFirst);
    assert!(o.completed, "{}", o.report.to_text());
    assert!(o.report.passed());
    let ids: Vec<&str> = o.report.waived.iter().map(|w| w.waiver_id.as_str()).collect();
    assert_eq!(ids, ["es-one-attempt-late", "tec-after-error-passive"]);
    // The resync took the DUT's TEC: every later TXERR read agrees.
    assert_eq!(o.model_tec, 136);
    assert_eq!(o.reads_equal, 2 * ATTEMPTS - 1, "only the late SR read differed");
    let text = o.report.to_text();
    assert!(text.contains("0 failure(s), 2 waived"), "{text}");
    assert!(text.contains("WAIVED [tec-after-error-passive] tx-bit"), "{text}");
    assert_eq!(o.set.hits("tec-after-error-passive"), Some(1));
}

#[test]
fn a_stale_waiver_is_a_warning_not_a_failure() {
    // The TXERR read-back waiver never matches once the TEC was adopted at the flag.
    let o = lockstep(Node::strict(), Node::deviant(1), both(), CollectMode::StopAtFirst);
    assert!(o.report.passed());
    assert_eq!(o.report.stale.len(), 1);
    assert_eq!(o.report.stale[0].waiver_id, "tec-136-read-back");
    assert!(o.report.stale[0].location.starts_with(UPSTREAM_NAME), "{:?}", o.report.stale[0]);
    let text = o.report.to_text();
    assert!(text.contains("WARNING stale waiver `tec-136-read-back`"), "{text}");
    assert!(text.contains("result: PASS with 1 warning(s)"), "{text}");
    assert_eq!(o.set.stale().len(), 1);
    // A DUT with no deviation leaves all three stale.
    let o = lockstep(Node::strict(), Node::strict(), both(), CollectMode::StopAtFirst);
    assert_eq!(o.report.counts().stale, 3);
}

#[test]
fn without_tec_adoption_the_read_back_waiver_resynchronises_instead() {
    let no_adopt = UPSTREAM.replacen(r#"resync = ["skip-bits 1", "adopt-dut-tec"]"#, r#"resync = ["skip-bits 1"]"#, 1);
    assert_ne!(no_adopt, UPSTREAM);
    let mut set = es();
    set.merge(WaiverSet::parse(&no_adopt, "no-adopt.toml").unwrap()).unwrap();
    let o = lockstep(Node::strict(), Node::deviant(1), set, CollectMode::StopAtFirst);
    assert!(o.completed, "{}", o.report.to_text());
    let ids: Vec<&str> = o.report.waived.iter().map(|w| w.waiver_id.as_str()).collect();
    assert_eq!(ids, ["es-one-attempt-late", "tec-after-error-passive", "tec-136-read-back"]);
    assert_eq!(o.model_tec, 136, "adopted from the TXERR read");
    assert!(o.report.stale.is_empty());
}

#[test]
fn without_any_resync_the_tec_difference_keeps_failing() {
    let no_adopt = UPSTREAM
        .replacen(r#"resync = ["skip-bits 1", "adopt-dut-tec"]"#, r#"resync = ["skip-bits 1"]"#, 1)
        .replacen(r#"resync = ["adopt-dut-tec"]"#, r#"resync = ["none"]"#, 1);
    let mut set = es();
    set.merge(WaiverSet::parse(&no_adopt, "none.toml").unwrap()).unwrap();
    let o = lockstep(Node::strict(), Node::deviant(1), set, CollectMode::Collect);
    assert!(o.completed);
    // Read-back waived once (max-hits = 1), then every later TXERR read fails.
    assert_eq!(o.report.waived.len(), 3);
    assert_eq!(o.report.failures.len(), (ATTEMPTS - 17) as usize);
    assert!(
        o.report.failures.iter().all(|d| d.register.as_deref() == Some("TXERR") && d.seen == 136 && d.expected == 128)
    );
    assert!(o.report.notes.iter().any(|n| n.contains("max-hits")), "{:?}", o.report.notes);
}

#[test]
fn collect_mode_sees_every_divergence() {
    let o = lockstep(Node::strict(), Node::deviant(1), WaiverSet::empty(), CollectMode::Collect);
    assert!(o.completed);
    assert!(!o.report.stopped_early);
    let kinds: Vec<(DivergenceKind, Option<&str>)> =
        o.report.failures.iter().map(|d| (d.kind, d.register.as_deref())).collect();
    assert_eq!(kinds[0], (DivergenceKind::RegisterRead, Some("SR")));
    assert_eq!(kinds[1], (DivergenceKind::TxBit, None));
    assert_eq!(kinds.len(), 2 + (ATTEMPTS - 16) as usize, "plus one TXERR read per attempt from 17 on");
    assert!(!o.report.passed());
}

// ---- bounds ----

#[test]
fn a_deviation_longer_than_late_bits_is_not_waived() {
    // Two dominant flag bits instead of one: the second is outside late-bits = 1.
    let o = lockstep(Node::strict(), Node::deviant(2), both(), CollectMode::StopAtFirst);
    assert!(!o.completed);
    assert_eq!(o.report.waived.len(), 2);
    let d = &o.report.failures[0];
    assert_eq!((d.kind, d.context.as_str()), (DivergenceKind::TxBit, "error flag bit 1"));
    assert!(o.report.notes.iter().any(|n| n.contains("late-bits = 1")), "{:?}", o.report.notes);
    // The read-back waiver was not reached: stale, and the warning says the run stopped early.
    assert_eq!(o.report.stale.len(), 1);
    assert!(o.report.warnings()[0].contains("stopped at a failure"), "{:?}", o.report.warnings());
}

#[test]
fn a_tec_outside_the_allowed_values_is_not_waived() {
    let tight = UPSTREAM.replacen("dut-tec = [136]", "dut-tec = [144]", 1);
    let o = lockstep(
        Node::strict(),
        Node::deviant(1),
        WaiverSet::parse(&tight, "tight.toml").unwrap(),
        CollectMode::Collect,
    );
    assert!(o.report.failures.iter().any(|d| d.kind == DivergenceKind::TxBit));
    assert!(o.report.notes.iter().any(|n| n.contains("DUT TEC 136 not in the allowed [144]")), "{:?}", o.report.notes);
}
