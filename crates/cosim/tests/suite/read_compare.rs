//! Every register read the host makes in a
//! lockstep run is compared, up to the last one, in collect mode too, and
//! after an earlier divergence. The DUT is the golden model behind a
//! wrapper with one deliberate deviation (the opencores core's: an abort
//! sets SR.TCS), so no Verilator build and no third-party core is needed.

use crate::common;
use common::AlteredModel;
use std::sync::Arc;

use cosim::waivers::CollectMode;
use cosim::{
    CompareConfig, CustomDut, Dut, DutChoice, HostBfm, ReferenceChoice, TbConfig,
    Testbench,
};
use diagnose::DivergenceKind;

const SR: u8 = 2;
const CMR: u8 = 1;

fn bench(collect: CollectMode) -> Testbench {
    bench_with(collect, cosim::waivers::WaiverSet::default())
}

fn bench_with(collect: CollectMode, waivers: cosim::waivers::WaiverSet) -> Testbench {
    let make: Arc<dyn Fn() -> Box<dyn Dut> + Send + Sync> = Arc::new(|| {
        // after CMR.AT, SR reads show TCS (bit 3) for the rest of the run
        Box::new(AlteredModel::new("golden model, SR.TCS set by an abort").on_read(|adr, d, writes| {
            let aborted = writes.iter().any(|&(a, v)| a == CMR && v & 0x02 != 0);
            if adr == SR && aborted { d | 0x08 } else { d }
        }))
    });
    Testbench::new(TbConfig {
        scenario: "tcs-after-abort".into(),
        dut: DutChoice::Custom(CustomDut {
            name: "tcs-after-abort".into(),
            make,
        }),
        host: HostBfm::Wishbone,
        lockstep: Some((ReferenceChoice::Model, CompareConfig::default())),
        collect,
        waivers,
        ..TbConfig::default()
    })
    .expect("test bench")
}

/// PeliCAN, listen-only (a transmission request stays pending, nothing on
/// the bus), one frame loaded and requested.
fn listen_only_with_a_pending_request(tb: &mut Testbench) {
    for (a, d) in [
        (0u8, 0x01u8), // reset mode
        (31, 0x80),    // PeliCAN
        (6, 0x41),
        (7, 0x25),
        (0, 0x02), // operating mode, listen only
        (16, 0x01),
        (17, 0x0A),
        (18, 0xA0),
        (19, 0x5A),
        (CMR, 0x01), // TR: stays pending
    ] {
        tb.write(a, d).unwrap();
    }
    tb.run_bits(20).unwrap();
}

/// The hole: the last SR read of a run differs from the model (DUT 0x0C,
/// model 0x04), and the run ends within the SR look-ahead window. Before
/// the fix the read stayed pending for ever and the run passed.
#[test]
fn the_last_read_of_a_run_is_compared() {
    let mut tb = bench(CollectMode::StopAtFirst);
    listen_only_with_a_pending_request(&mut tb);
    assert_eq!(tb.read(SR).unwrap() & 0x0C, 0x00, "TBS = 0, TCS = 0: pending");
    tb.write(CMR, 0x02).unwrap();
    tb.run_bits(2).unwrap();
    // The last host access of the run.
    let sr = tb.read(SR).unwrap();
    assert_eq!(sr & 0x0C, 0x0C, "the wrapper's deviation: TCS after an abort");
    let d = tb
        .record()
        .divergence
        .expect("the last SR read differs from the model: a divergence");
    assert_eq!(d.kind, DivergenceKind::RegisterRead);
    assert_eq!(d.register.as_deref(), Some("SR"));
    assert_eq!((d.seen, d.expected), (sr as u32, (sr & !0x08) as u32));
    let r = tb.waiver_report();
    assert!(!r.passed(), "{}", r.to_text());
}

/// Collect mode, after an earlier divergence: a read difference is listed
/// once; the same difference again (same register, same DUT and model
/// values) is a counted repeat, also after reads that agreed; a different
/// difference on the same register is listed: reads are compared afresh,
/// never latched. After each listed read the model adopts what it can of
/// the DUT's value (here SR.TCS), so the read right after
/// the first agrees; the last read, after the model's abort cleared its
/// TCS again, is the same difference as the first: a repeat.
#[test]
fn collect_mode_lists_each_distinct_read_difference_once() {
    let mut tb = bench(CollectMode::Collect);
    listen_only_with_a_pending_request(&mut tb);
    tb.write(CMR, 0x02).unwrap();
    tb.run_bits(2).unwrap();
    assert_eq!(tb.read(SR).unwrap() & 0x0C, 0x0C, "listed: DUT 0x0C, model 0x04");
    assert_eq!(tb.read(SR).unwrap() & 0x0C, 0x0C, "the same state again: the model adopted TCS");
    assert_eq!(tb.read(4).unwrap(), 0x00, "IER agrees");
    tb.run_bits(3).unwrap();
    // A new request: the model's SR 0x00 (TBS = 0), the DUT's 0x08: another difference.
    tb.write(CMR, 0x01).unwrap();
    tb.run_bits(20).unwrap();
    assert_eq!(tb.read(SR).unwrap() & 0x0C, 0x08);
    tb.write(CMR, 0x02).unwrap();
    tb.run_bits(2).unwrap();
    // The first difference once more, as the last access of the run.
    assert_eq!(tb.read(SR).unwrap() & 0x0C, 0x0C);
    let rec = tb.record();
    let r = tb.waiver_report();
    let listed: Vec<(DivergenceKind, Option<&str>, u32, u32)> =
        r.failures.iter().map(|d| (d.kind, d.register.as_deref(), d.seen, d.expected)).collect();
    assert_eq!(
        listed,
        [
            (DivergenceKind::RegisterRead, Some("SR"), 0x0C, 0x04),
            (DivergenceKind::RegisterRead, Some("SR"), 0x08, 0x00),
        ],
        "{}",
        r.to_text()
    );
    assert_eq!(tb.comparator().unwrap().repeated, 1, "the last read (the second agreed after the adoption)");
    assert!(
        r.notes.iter().any(|n| n.contains("read of SR (DUT 0x0C, model 0x04): 1 more time(s)")),
        "the repeats are reported: {}",
        r.to_text()
    );
    assert_eq!(rec.divergence.map(|d| d.time_ps), Some(r.failures[0].time_ps), "the record keeps the first");
}

/// `adopt-dut-register` on SR: after the waived read (DUT 0x0C, model 0x04)
/// the model takes TCS, so the same state read again is no new hit; a later
/// different SR (a new request: DUT 0x08, model 0x00) is still reported.
/// With `none` the second read is a second hit, beyond `max-hits = 1`.
#[test]
fn an_adopted_sr_flag_keeps_the_next_real_difference_reported() {
    let waiver = |resync: &str| {
        cosim::waivers::WaiverSet::parse(
            &format!(
                r#"
[[waiver]]
id = "tcs-set-by-abort"
kind = "register-read"
register = "SR"
address = 2
bits = [3]
seen = [0x0C]
max-hits = 1
dut = ["tcs-after-abort"]
explanation = "TCS set by an abort (test wrapper)"
resync = ["{resync}"]
"#
            ),
            "t.toml",
        )
        .unwrap()
    };
    let play = |resync: &str| {
        let mut tb = bench_with(CollectMode::Collect, waiver(resync));
        listen_only_with_a_pending_request(&mut tb);
        tb.write(CMR, 0x02).unwrap();
        tb.run_bits(2).unwrap();
        assert_eq!(tb.read(SR).unwrap() & 0x0C, 0x0C);
        assert_eq!(tb.read(SR).unwrap() & 0x0C, 0x0C);
        tb.run_bits(3).unwrap();
        tb.write(CMR, 0x01).unwrap();
        tb.run_bits(20).unwrap();
        let v = tb.read(SR).unwrap();
        tb.run_bits(5).unwrap();
        assert_eq!(v & 0x0C, 0x08);
        tb.waiver_report()
    };
    let r = play("adopt-dut-register");
    let failures: Vec<(u32, u32)> = r.failures.iter().map(|d| (d.seen, d.expected)).collect();
    assert_eq!(r.waived.len(), 1, "{}", r.to_text());
    assert_eq!(failures, [(0x08, 0x00)], "only the new difference: {}", r.to_text());
    assert!(!r.notes.iter().any(|n| n.contains("could not be applied")), "{}", r.to_text());
    let r = play("none");
    let failures: Vec<(u32, u32)> = r.failures.iter().map(|d| (d.seen, d.expected)).collect();
    assert_eq!(failures, [(0x0C, 0x04), (0x08, 0x00)], "second hit beyond max-hits: {}", r.to_text());
}

/// A failed expectation on an SR read whose divergence is waived counts as
/// waived even when the read is still inside the comparator's look-ahead
/// window (pelican-listen-only's TCS read failed before: the waiver was
/// applied only after the expectation had been judged).
#[test]
fn an_expectation_on_a_waived_sr_read_in_its_look_ahead_window_is_waived() {
    let set = cosim::waivers::WaiverSet::parse(
        r#"
[[waiver]]
id = "tcs-set-by-abort"
kind = "register-read"
register = "SR"
bits = [3]
max-hits = 1
dut = ["tcs-after-abort"]
explanation = "TCS set by an abort (test wrapper)"
resync = ["none"]
"#,
        "t.toml",
    )
    .unwrap();
    let mut tb = bench_with(CollectMode::Collect, set);
    listen_only_with_a_pending_request(&mut tb);
    tb.write(CMR, 0x02).unwrap();
    tb.run_bits(2).unwrap();
    let met = tb.expect(7, "SR: TBS, not TCS", SR, 0x0C, 0x04).unwrap();
    let r = tb.waiver_report();
    assert!(met, "the read's own waived deviation: {}", r.to_text());
    assert_eq!(r.waived_expectations.len(), 1, "{}", r.to_text());
    assert_eq!(r.waived_expectations[0].waiver_id, "tcs-set-by-abort");
    // The same read again is beyond max-hits: a failure, and its
    // expectation is not waived.
    assert!(!tb.expect(8, "SR: TBS, not TCS", SR, 0x0C, 0x04).unwrap());
    let r = tb.waiver_report();
    assert_eq!((r.waived_expectations.len(), r.failures.len()), (1, 1), "{}", r.to_text());
}
