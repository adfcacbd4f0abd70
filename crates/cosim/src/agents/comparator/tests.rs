//! The comparator's tests across its checkers: tolerances, collect mode,
//! waivers, and the differential test against [`super::before`].

use super::*;

fn pins(tx: bool) -> CanPins {
    CanPins {
        tx,
        irq_n: true,
        bus_on: true,
        clkout: false,
    }
}

fn run(cfg: CompareConfig, ref_tx: &[bool], dut_tx: &[bool], samples: &[usize]) -> Comparator {
    run_in(cfg, ref_tx, dut_tx, samples, None)
}

fn run_in(
    cfg: CompareConfig,
    ref_tx: &[bool],
    dut_tx: &[bool],
    samples: &[usize],
    field: Option<Field>,
) -> Comparator {
    let mut c = Comparator::new(cfg);
    for k in 0..ref_tx.len() {
        let s = Stamp {
            t_ps: k as u64,
            bit: k as u64,
            field,
            ..Stamp::default()
        };
        c.can_clock(
            s,
            samples.contains(&k),
            &pins(ref_tx[k]),
            &pins(dut_tx[k]),
            0,
            0,
            None,
        );
    }
    c
}

#[test]
fn tx_edges_within_tolerance_are_not_compared_but_sample_points_are() {
    let cfg = CompareConfig {
        tx_edge_tolerance: 2,
        ..CompareConfig::default()
    };
    // Model edge at clock 10, DUT edge at 12 (late by 2): sample at 11 is
    // inside the window, sample at 20 is stable and equal.
    let r: Vec<bool> = (0..30).map(|k| k < 10).collect();
    let d: Vec<bool> = (0..30).map(|k| k < 12).collect();
    let c = run(cfg, &r, &d, &[11, 20]);
    assert!(c.divergence().is_none());
    assert_eq!(c.compared_bits, 1);
    // Late by 5 with a sample at 14: a divergence at 14.
    let d: Vec<bool> = (0..30).map(|k| k < 15).collect();
    let c = run(cfg, &r, &d, &[14, 20]);
    let dv = c.divergence().expect("divergence");
    assert_eq!(dv.kind, DivergenceKind::TxBit);
    assert_eq!(dv.time_ps, 14);
    assert_eq!((dv.expected, dv.seen), (0, 1));
    assert!(
        dv.context.contains("not within 2 CAN clocks"),
        "tolerance printed: {}",
        dv.context
    );
}

/// The last bit compared equal is what ends a tx-bit waiver's episode: a
/// sample point skipped in the edge window or one that differs is not one.
#[test]
fn the_last_tx_bit_compared_equal_is_kept_for_the_waivers() {
    let cfg = CompareConfig {
        tx_edge_tolerance: 2,
        ..CompareConfig::default()
    };
    // Equal at 5; the model's edge at 10, the DUT's at 11: the sample at 11
    // is in the window (not compared); differing from 20 on.
    let r: Vec<bool> = (0..30).map(|k| k < 10).collect();
    let d: Vec<bool> = (0..30).map(|k| k < 11 || k >= 20).collect();
    let c = run(cfg, &r, &d, &[5, 11]);
    assert_eq!(c.tx_agreed_bit(), Some(5), "the sample in the edge window is not an agreement");
    let c = run(cfg, &r, &d, &[5, 15, 22]);
    assert_eq!(c.tx_agreed_bit(), Some(15));
    assert!(c.divergence().is_some_and(|dv| dv.bit == Some(22)), "22 differs, and is no agreement");
}

#[test]
fn a_start_of_frame_from_bus_idle_may_lag_within_the_sof_tolerance() {
    let cfg = CompareConfig {
        tx_edge_tolerance: 2,
        sof_tolerance: 20,
        ..CompareConfig::default()
    };
    // Model SOF at clock 10, DUT SOF at 22 (12 clocks later), sample at 15.
    let r: Vec<bool> = (0..40).map(|k| k < 10).collect();
    let d: Vec<bool> = (0..40).map(|k| k < 22).collect();
    let c = run_in(cfg, &r, &d, &[15, 30], Some(Field::BusIdle));
    assert!(c.divergence().is_none(), "{:?}", c.divergence());
    assert_eq!(
        c.compared_bits, 1,
        "the sample after the DUT's SOF is compared"
    );
    // The same lag inside a frame (not from bus idle) is a divergence.
    let c = run_in(cfg, &r, &d, &[15, 30], Some(Field::Data));
    assert_eq!(c.divergence().map(|d| d.time_ps), Some(15));
    // A DUT that never starts is caught once the grace expires.
    let d: Vec<bool> = vec![true; 40];
    let c = run_in(cfg, &r, &d, &[15, 35], Some(Field::BusIdle));
    assert_eq!(c.divergence().map(|d| d.time_ps), Some(35));
}

#[test]
fn an_ir_read_is_not_matched_by_the_value_the_reference_read_left_behind() {
    // The reference takes a read when the DUT's CAN side does,
    // before the ack; reading IR clears DOI, so for the clocks up to the
    // ack the model's IR is 0x01. A DUT that never raised DOI returned
    // 0x01 and the window took it (pelican-fifo-overrun steps 23, 38).
    let mut c = Comparator::new(CompareConfig { status_tolerance: 40, ..CompareConfig::default() });
    let p = pins(true);
    for _ in 0..50 {
        c.can_clock(Stamp::default(), false, &p, &p, 0, 0x09, None);
    }
    c.reference_read_taken();
    for _ in 0..4 {
        c.can_clock(Stamp::default(), false, &p, &p, 0, 0x01, None);
    }
    c.read(Stamp::default(), IR_ADDR, 0x01, 0x09, None);
    let d = c.divergence().expect("IR 0x01 only after the read cleared DOI");
    assert_eq!((d.register.as_deref(), d.expected, d.seen), (Some("IR"), 0x09, 0x01));
    // A value the model held before the read is still within the window.
    let mut c = Comparator::new(CompareConfig { status_tolerance: 40, ..CompareConfig::default() });
    for ir in [0x01, 0x01, 0x09, 0x09] {
        c.can_clock(Stamp::default(), false, &p, &p, 0, ir, None);
    }
    c.reference_read_taken();
    c.can_clock(Stamp::default(), false, &p, &p, 0, 0x01, None);
    c.read(Stamp::default(), IR_ADDR, 0x01, 0x09, None);
    assert!(c.divergence().is_none(), "IR 0x01 two clocks before the read");
    assert_eq!(c.tolerated_reads, 1);
    // Without an early take (reference at the ack) nothing changes.
    let mut c = Comparator::new(CompareConfig { status_tolerance: 40, ..CompareConfig::default() });
    for ir in [0x01, 0x09] {
        c.can_clock(Stamp::default(), false, &p, &p, 0, ir, None);
    }
    c.read(Stamp::default(), IR_ADDR, 0x01, 0x09, None);
    assert!(c.divergence().is_none());
}

#[test]
fn a_tolerated_read_that_misses_an_expectation_the_model_meets_is_a_divergence() {
    // pelican-fifo-overrun step 70: SR 0x0F (DOS, RBS) 20 clocks after
    // the release of the last message, where the model reads 0x0E and
    // the scenario expects RBS = 0, DOS = 1 (mask 0x03).
    let setup = || {
        let mut c = Comparator::new(CompareConfig { status_tolerance: 40, ..CompareConfig::default() });
        let p = pins(true);
        for k in 0..60 {
            c.can_clock(Stamp::default(), false, &p, &p, if k < 40 { 0x0F } else { 0x0E }, 0, None);
        }
        c.read(Stamp { t_ps: 9, ..Stamp::default() }, SR_ADDR, 0x0F, 0x0E, None);
        assert!(c.divergence().is_none(), "the window accepts it");
        c
    };
    let mut c = setup();
    assert!(c.hold_tolerated_read(SR_ADDR, 0x0F, 0x03, 0x02));
    let d = c.divergence().expect("held to the expectation");
    assert_eq!((d.time_ps, d.register.as_deref(), d.expected, d.seen), (9, Some("SR"), 0x0E, 0x0F));
    assert!(d.context.contains("expectation"), "{}", d.context);
    assert_eq!(c.tolerated_reads, 0);
    // An expectation the model misses too: the scenario's problem, not a divergence.
    let mut c = setup();
    assert!(!c.hold_tolerated_read(SR_ADDR, 0x0F, 0x03, 0x00));
    assert!(c.divergence().is_none());
    // An expectation the DUT meets: nothing to hold.
    let mut c = setup();
    assert!(!c.hold_tolerated_read(SR_ADDR, 0x0F, 0x0C, 0x0C));
    // Only the last read: a later exact read forgets it.
    let mut c = setup();
    c.read(Stamp::default(), 4, 0, 0, None);
    assert!(!c.hold_tolerated_read(SR_ADDR, 0x0F, 0x03, 0x02));
    assert!(c.divergence().is_none());
}

#[test]
fn status_reads_use_the_window_other_reads_are_exact() {
    let mut c = Comparator::new(CompareConfig {
        status_tolerance: 3,
        ..CompareConfig::default()
    });
    let p = pins(true);
    for sr in [0x0C, 0x0C, 0x3C] {
        c.can_clock(Stamp::default(), false, &p, &p, sr, 0, None);
    }
    c.read(Stamp::default(), SR_ADDR, 0x0C, 0x3C, None);
    assert!(
        c.divergence().is_none(),
        "SR 0x0C was the model's value 1 clock ago"
    );
    assert_eq!(c.tolerated_reads, 1);
    // SR value the model takes 2 clocks after the read: accepted too.
    c.read(Stamp::default(), SR_ADDR, 0x1C, 0x3C, None);
    assert_eq!(c.pending_reads(), 1);
    c.can_clock(Stamp::default(), false, &p, &p, 0x3C, 0, None);
    c.can_clock(Stamp::default(), false, &p, &p, 0x1C, 0, None);
    assert_eq!(c.pending_reads(), 0);
    assert!(c.divergence().is_none());
    // SR value never taken: divergence once the window closes.
    c.read(
        Stamp {
            t_ps: 77,
            ..Stamp::default()
        },
        SR_ADDR,
        0xFF,
        0x1C,
        None,
    );
    for _ in 0..5 {
        c.can_clock(Stamp::default(), false, &p, &p, 0x1C, 0, None);
    }
    let d = c.divergence().expect("SR 0xFF never held");
    assert_eq!(
        (d.kind, d.time_ps, d.register.as_deref()),
        (DivergenceKind::RegisterRead, 77, Some("SR"))
    );
    // Another register: exact.
    let mut c = Comparator::new(CompareConfig::default());
    c.read(Stamp::default(), 6, 0x41, 0x41, Some("BTR0".into()));
    assert!(c.divergence().is_none());
    c.read(Stamp::default(), 6, 0x40, 0x41, Some("BTR0".into()));
    assert_eq!(c.divergence().unwrap().register.as_deref(), Some("BTR0"));
}

/// Reference tx all recessive with a sample point every 10 clocks (bit
/// k at clock 10k + 5); the DUT drives dominant at the given bits.
fn run_bits(
    c: &mut Comparator,
    bits: std::ops::Range<u64>,
    dominant: &[u64],
    mut on_div: impl FnMut(&mut Comparator, Divergence),
) {
    for bit in bits {
        for k in 0..10u64 {
            let s = Stamp {
                t_ps: bit * 10 + k,
                bit,
                ..Stamp::default()
            };
            let dut_tx = !(dominant.contains(&bit) && k >= 2);
            c.can_clock(s, k == 5, &pins(true), &pins(dut_tx), 0, 0, None);
            while let Some(d) = c.take_divergence() {
                on_div(c, d);
            }
        }
    }
}

#[test]
fn resume_goes_on_after_a_divergence_and_skip_bits_are_not_compared() {
    let mut c = Comparator::new(CompareConfig {
        tx_edge_tolerance: 2,
        ..CompareConfig::default()
    });
    let mut seen = vec![];
    // Without resume: halted at the first one, as before.
    run_bits(&mut c, 0..20, &[3, 4, 12], |_, d| seen.push(d.bit.unwrap()));
    assert_eq!(seen, [3]);
    assert!(c.halted());
    assert_eq!(c.divergence().unwrap().bit, Some(3));
    // Resume after each (a waiver with skip-bits 2): bit 4 is skipped, 12 reported.
    let mut c = Comparator::new(CompareConfig {
        tx_edge_tolerance: 2,
        ..CompareConfig::default()
    });
    let mut seen = vec![];
    run_bits(&mut c, 0..20, &[3, 4, 12], |c, d| {
        seen.push(d.bit.unwrap());
        c.resume(d.bit.map(|b| b + 2), false);
    });
    assert_eq!(seen, [3, 12]);
    assert_eq!(
        c.divergence().unwrap().bit,
        Some(3),
        "divergence() stays the first"
    );
    // Resume without skipping, not latched (waived): every bit reported.
    let mut c = Comparator::new(CompareConfig {
        tx_edge_tolerance: 2,
        ..CompareConfig::default()
    });
    let mut seen = vec![];
    run_bits(&mut c, 0..20, &[3, 4, 12], |c, d| {
        seen.push(d.bit.unwrap());
        c.resume(None, false);
    });
    assert_eq!(seen, [3, 4, 12]);
    // Collect mode latches: a lasting deviation counts once until tx agrees again.
    let mut c = Comparator::new(CompareConfig {
        tx_edge_tolerance: 2,
        ..CompareConfig::default()
    });
    let mut seen = vec![];
    run_bits(&mut c, 0..20, &[3, 4, 5, 12], |c, d| {
        seen.push(d.bit.unwrap());
        c.resume(None, true);
    });
    assert_eq!(seen, [3, 12]);
}

#[test]
fn a_waiver_session_drives_the_comparator() {
    use waivers::{Action, CollectMode, DutInfo, Resync, Session, WaiverSet};
    let set = WaiverSet::parse(
        r#"
[[waiver]]
id = "late-flag"
kind = "tx-bit"
dut = ["fixture"]
late-bits = 1
explanation = "one dominant bit late, accepted for this test"
resync = ["skip-bits 1"]
"#,
        "t.toml",
    )
    .unwrap();
    for (mode, dominant, waived, failures) in [
        (CollectMode::StopAtFirst, vec![3], 1, 0),
        (CollectMode::StopAtFirst, vec![3, 4], 1, 1),
        (CollectMode::Collect, vec![3, 4, 5, 15], 2, 1),
    ] {
        let mut s = Session::new(set.clone(), DutInfo::new("fixture"), mode);
        let mut c = Comparator::new(CompareConfig {
            tx_edge_tolerance: 2,
            ..CompareConfig::default()
        });
        run_bits(&mut c, 0..20, &dominant, |c, d| {
            let bit = d.bit.unwrap();
            match s.divergence(d) {
                Action::Resync(steps) => {
                    let skip = steps
                        .iter()
                        .map(|r| {
                            if let Resync::SkipBits(n) = r {
                                *n as u64
                            } else {
                                0
                            }
                        })
                        .max();
                    c.resume(skip.map(|n| bit + n), false);
                }
                Action::Continue => c.resume(None, true),
                Action::Stop => {}
            }
        });
        let (r, _) = s.finish();
        assert_eq!(
            (r.waived.len(), r.failures.len()),
            (waived, failures),
            "{mode:?} {dominant:?}: {}",
            r.to_text()
        );
    }
}

#[test]
fn irq_may_differ_briefly_but_not_longer_than_the_tolerance() {
    let mut c = Comparator::new(CompareConfig {
        pin_tolerance: 3,
        ..CompareConfig::default()
    });
    let r = CanPins {
        irq_n: false,
        ..pins(true)
    };
    let d = pins(true);
    for k in 0..3 {
        c.can_clock(
            Stamp {
                t_ps: k,
                ..Stamp::default()
            },
            false,
            &r,
            &d,
            0,
            0,
            None,
        );
    }
    assert!(c.divergence().is_none());
    c.can_clock(Stamp::default(), false, &r, &r, 0, 0, None);
    for k in 10..14 {
        c.can_clock(
            Stamp {
                t_ps: k,
                ..Stamp::default()
            },
            false,
            &r,
            &d,
            0,
            0,
            None,
        );
    }
    let dv = c.divergence().expect("irq divergence");
    assert_eq!((dv.kind, dv.time_ps), (DivergenceKind::Irq, 10));
}

/// Collect mode lists each tx difference once: the first mismatch of a
/// frame is listed; later mismatches of that frame are its cascade
/// (counted); the same difference (field, levels) in a later frame is
/// a repeat (counted, and the rest of its frame its cascade); a difference in
/// another field is listed; a waived one (not latched) never is
/// deduplicated.
#[test]
fn collect_mode_lists_each_tx_difference_once() {
    // Ten bits per frame; the DUT is dominant at these bits, in these fields.
    let plan: [(u64, Field); 7] = [
        (3, Field::Data),
        (4, Field::Data),
        (13, Field::Data),
        (15, Field::Crc),
        (24, Field::Crc),
        (33, Field::AckSlot),
        (45, Field::Crc),
    ];
    for latch in [true, false] {
        let mut c = Comparator::new(CompareConfig { tx_edge_tolerance: 2, ..CompareConfig::default() });
        let mut listed = vec![];
        for bit in 0..50u64 {
            let field = plan.iter().find(|p| p.0 == bit).map(|p| p.1).or(Some(Field::Data));
            for k in 0..10u64 {
                let s = Stamp { t_ps: bit * 10 + k, bit, field, frame: Some(bit as u32 / 10 + 1) };
                let dominant = plan.iter().any(|p| p.0 == bit) && k >= 2;
                c.can_clock(s, k == 5, &pins(true), &pins(!dominant), 0, 0, None);
                while let Some(d) = c.take_divergence() {
                    listed.push((d.bit.unwrap(), d.field));
                    c.resume(None, latch);
                }
            }
        }
        if latch {
            assert_eq!(listed, [(3, Some(Field::Data)), (24, Some(Field::Crc)), (33, Some(Field::AckSlot))]);
            assert_eq!(
                (c.repeated, c.cascade),
                (2, 2),
                "bits 13 and 45 repeat; bit 4 is bit 3's cascade, bit 15 bit 13's"
            );
            assert_eq!(c.repeats().len(), 2, "{:?}", c.repeats());
            assert!(c.repeats()[0].starts_with("tx in data field (model recessive, DUT dominant): 1 more"), "{:?}", c.repeats());
        } else {
            assert_eq!(listed.len(), plan.len(), "waived: every bit is handed on");
            assert_eq!((c.repeated, c.cascade), (0, 0));
        }
    }
}

/// Differential test against the declared tolerance: on
/// random status sequences with random reads, interleaved with tx and
/// irq divergences at random clocks, a read diverges exactly when its
/// DUT value differs from the model's at the read and from every value
/// the model's SR held in the clocks [P - 1 - tol, P + tol] around it
/// (IR: [P - 1 - tol, P - 1]; other registers: none), P being the
/// clocks before the read. The run ends with `open_clocks()` clocks, as
/// the test bench's settle does, so the last reads are judged too.
#[test]
fn a_read_diverges_exactly_when_the_model_never_held_the_value_in_the_window() {
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut rnd = move |n: u64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed % n
    };
    let values = [0x0Cu8, 0x1C, 0x3C, 0x0D, 0x00, 0x04];
    let (mut bad_total, mut good_total) = (0, 0);
    for st_tol in [0u32, 1, 3, 48] {
        let cfg = CompareConfig {
            tx_edge_tolerance: 1,
            status_tolerance: st_tol,
            pin_tolerance: 2,
            ..CompareConfig::default()
        };
        let mut c = Comparator::new(cfg);
        let clocks = 40_000usize;
        let total = clocks + 200;
        let mut sr = vec![0u8; total];
        let mut ir = vec![0u8; total];
        for k in 1..total {
            sr[k] = if rnd(4) == 0 { values[rnd(6) as usize] } else { sr[k - 1] };
            ir[k] = if rnd(6) == 0 { values[rnd(6) as usize] } else { ir[k - 1] };
        }
        // (read id, address, P, DUT value, model value)
        let mut reads: Vec<(u64, u8, usize, u8, u8)> = Vec::new();
        let mut flagged = std::collections::BTreeSet::new();
        let mut clk = 0usize;
        let step = |c: &mut Comparator, clk: usize, rnd: &mut dyn FnMut(u64) -> u64| {
            let sample = clk % 10 == 5;
            // The DUT's tx is wrong at some sample points, its irq now and then.
            let dut_tx = !(sample && rnd(7) == 0);
            let irq_bad = clk % 97 < 5 && rnd(3) == 0;
            let r = pins(true);
            let d = CanPins { tx: dut_tx, irq_n: !irq_bad, ..pins(true) };
            let stamp = Stamp { t_ps: clk as u64, bit: clk as u64 / 10, frame: Some(clk as u32 / 200), ..Stamp::default() };
            c.can_clock(stamp, sample, &r, &d, sr[clk], ir[clk], None);
        };
        let drain = |c: &mut Comparator, flagged: &mut std::collections::BTreeSet<u64>| {
            while let Some(d) = c.take_divergence() {
                let read = d.kind == DivergenceKind::RegisterRead;
                if read {
                    assert!(flagged.insert(d.time_ps), "one divergence per read");
                }
                c.resume(None, !read);
            }
        };
        while clk < clocks {
            step(&mut c, clk, &mut rnd);
            clk += 1;
            drain(&mut c, &mut flagged);
            if rnd(5) == 0 {
                let addr = [SR_ADDR, IR_ADDR, 6][rnd(3) as usize];
                let model = match addr {
                    SR_ADDR => sr[clk - 1],
                    IR_ADDR => ir[clk - 1],
                    _ => values[rnd(6) as usize],
                };
                let dut = if rnd(3) == 0 { model } else { values[rnd(6) as usize] };
                let id = 1_000_000 + reads.len() as u64;
                let stamp = Stamp { t_ps: id, ..Stamp::default() };
                c.read(stamp, addr, dut, model, None);
                reads.push((id, addr, clk, dut, model));
                drain(&mut c, &mut flagged);
            }
        }
        let open = c.open_clocks() as usize;
        assert!(open <= (st_tol.max(2) + 3) as usize, "open {open}");
        for _ in 0..open {
            step(&mut c, clk, &mut rnd);
            clk += 1;
            drain(&mut c, &mut flagged);
        }
        assert_eq!(c.pending_reads(), 0, "every read judged");
        let tol = st_tol as usize;
        for &(id, addr, p, dut, model) in &reads {
            let held = |h: &[u8], lo: usize, hi: usize| (lo..=hi).any(|k| h[k] == dut);
            let back = p.saturating_sub(1 + tol);
            let ok = dut == model
                || match addr {
                    SR_ADDR => held(&sr, back, if tol > 0 { p + tol } else { p - 1 }),
                    IR_ADDR => held(&ir, back, p - 1),
                    _ => false,
                };
            assert_eq!(
                flagged.contains(&id),
                !ok,
                "tol {st_tol}: read {id} of {addr} at P = {p}: DUT 0x{dut:02X}, model 0x{model:02X}"
            );
            if ok { good_total += 1 } else { bad_total += 1 }
        }
    }
    assert!(bad_total > 1000 && good_total > 1000, "{bad_total} / {good_total}");
}

/// The comparator reaches exactly the verdicts of the one it replaced
/// (`before::OldComparator`) on random pin, status and read sequences,
/// with halts, resumes, skips and latches, for several tolerances.
/// A run of clocks promised by `quiet_ahead` not yet given to the
/// comparator: how many, their field and bit, and the inputs held.
type QuietRun = (u32, Option<Field>, u64, Option<(CanPins, CanPins, u8, u8)>);

/// Gives the comparator the clocks of `run` in one go.
fn take_run(c: &mut Comparator, run: &mut QuietRun) {
    if run.0 > 0 {
        let (r, d, ..) = run.3.expect("a run holds its inputs");
        c.quiet_clocks(run.0, run.1, run.2, &r, &d);
        run.0 = 0;
    }
}

#[test]
fn same_verdicts_as_the_per_clock_deque_comparator() {
    let mut seed = 0x9E37_79B9_7F4A_7C15u64;
    let mut rnd = move |n: u64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed % n
    };
    let fields = [
        None,
        Some(Field::BusIdle),
        Some(Field::Sof),
        Some(Field::Data),
        Some(Field::Intermission),
        Some(Field::Crc),
        Some(Field::SuspendTransmission),
    ];
    let statuses = [0x0C, 0x1C, 0x3C, 0x0D, 0x00];
    let mut divergences = 0;
    // Busy sequences (something changes nearly every clock) and calm
    // ones (long stretches where nothing does, as on a real bus).
    for (calm, (tx_tol, sof_tol, st_tol, pin_tol)) in [
        (4, 40, 48, 48),
        (0, 0, 0, 0),
        (1, 3, 2, 1),
        (2, 20, 3, 3),
        (3, 100, 70, 5),
        (8, 63, 1, 60),
    ]
    .into_iter()
    .flat_map(|c| [(1, c), (25, c)])
    {
        let cfg = CompareConfig {
            tx_edge_tolerance: tx_tol,
            status_tolerance: st_tol,
            pin_tolerance: pin_tol,
            compare_irq: rnd(4) != 0,
            compare_bus_off: rnd(4) != 0,
            sof_tolerance: sof_tol,
            compare_clkout: true,
        };
        let mut new = Comparator::new(cfg);
        let mut old = before::OldComparator::new(cfg);
        // A third one takes the clocks `quiet_ahead` promised (inputs held,
        // no sample point) in runs by the short path, as the test bench's
        // quiet stretches do: the same verdicts.
        let mut bulk = Comparator::new(cfg);
        let (mut left, mut run, mut promised): (u32, QuietRun, u64) = (0, (0, None, 0, None), 0);
        let mut ref_tx_hist = vec![true; 64];
        let (mut lag, mut field, mut phase) = (0usize, None, 5u64);
        let (mut rp, mut dp) = (pins(true), pins(true));
        let (mut sr, mut ir) = (0x0C, 0);
        for clk in 0..60_000u64 {
            // Reference tx in runs; the DUT follows it late by `lag`, with glitches.
            let last = *ref_tx_hist.last().unwrap();
            ref_tx_hist.push(if rnd(12 * calm) == 0 { !last } else { last });
            if rnd(400) == 0 {
                lag = [0, 1, 2, 5, 12, 30, 45][rnd(7) as usize];
            }
            let n = ref_tx_hist.len();
            rp.tx = ref_tx_hist[n - 1];
            dp.tx = ref_tx_hist[n - 1 - lag] ^ (rnd(300 * calm) == 0);
            if rnd(60) == 0 {
                field = fields[rnd(fields.len() as u64) as usize];
            }
            if rnd(50 * calm) == 0 {
                rp.irq_n = !rp.irq_n;
            }
            if rnd(50 * calm) == 0 {
                rp.bus_on = !rp.bus_on;
            }
            if rnd(7 * calm) == 0 {
                dp.irq_n = rp.irq_n ^ (rnd(9) == 0);
                dp.bus_on = rp.bus_on ^ (rnd(9) == 0);
            }
            if rnd(20 * calm) == 0 {
                sr = statuses[rnd(5) as usize];
            }
            if rnd(30 * calm) == 0 {
                ir = statuses[rnd(5) as usize];
            }
            if rnd(500) == 0 {
                phase = rnd(10);
            }
            let stamp = Stamp {
                t_ps: clk,
                bit: clk / 10,
                field,
                frame: Some((clk / 1000) as u32),
            };
            // Calm: a sample point every 40 clocks, as at 40 clocks per bit.
            let sample = clk % (10 * calm.min(4)) == phase;
            new.can_clock(stamp, sample, &rp, &dp, sr, ir, None);
            old.can_clock(stamp, sample, &rp, &dp, sr, ir);
            // A run's clocks share their field and bit (no sample point
            // among them on the bench).
            if (run.1, run.2) != (field, stamp.bit) {
                take_run(&mut bulk, &mut run);
            }
            if left > 0 && !sample && run.3 == Some((rp, dp, sr, ir)) {
                left -= 1;
                promised += 1;
                (run.0, run.1, run.2) = (run.0 + 1, field, stamp.bit);
                if rnd(8) == 0 {
                    take_run(&mut bulk, &mut run);
                }
            } else {
                take_run(&mut bulk, &mut run);
                bulk.can_clock(stamp, sample, &rp, &dp, sr, ir, None);
                left = bulk.quiet_ahead(&rp, &dp, sr, ir, None);
                run.3 = Some((rp, dp, sr, ir));
            }
            if rnd(90 * calm) == 0 {
                let addr = [SR_ADDR, IR_ADDR, 6][rnd(3) as usize];
                let dut = statuses[rnd(5) as usize];
                let model = if rnd(2) == 0 {
                    sr
                } else {
                    statuses[rnd(5) as usize]
                };
                new.read(stamp, addr, dut, model, None);
                old.read(stamp, addr, dut, model, None);
                take_run(&mut bulk, &mut run);
                bulk.read(stamp, addr, dut, model, None);
                left = 0;
            }
            loop {
                let (a, b) = (new.take_divergence(), old.take_divergence());
                assert_eq!(a, b, "clock {clk}, config {cfg:?}");
                assert_eq!(a, bulk.take_divergence(), "clock {clk}, config {cfg:?}: quiet runs");
                if a.is_none() {
                    break;
                }
                divergences += 1;
            }
            assert_eq!(new.halted(), old.halted(), "clock {clk}");
            assert_eq!(new.halted(), bulk.halted(), "clock {clk}: quiet runs");
            if new.halted() && rnd(3) != 0 {
                let skip = (rnd(2) == 0).then(|| clk / 10 + rnd(5));
                let latch = rnd(2) == 0;
                new.resume(skip, latch);
                old.resume(skip, latch);
                take_run(&mut bulk, &mut run);
                bulk.resume(skip, latch);
                left = 0;
            }
        }
        take_run(&mut bulk, &mut run);
        assert_eq!(new.divergence(), old.divergence());
        assert_eq!(new.divergence(), bulk.divergence());
        assert_eq!(
            (new.compared_bits, new.compared_reads, new.tolerated_reads, new.pending_reads(), new.repeated, new.cascade),
            (bulk.compared_bits, bulk.compared_reads, bulk.tolerated_reads, bulk.pending_reads(), bulk.repeated, bulk.cascade),
            "{cfg:?}: quiet runs"
        );
        if calm > 1 {
            assert!(promised > 1_000, "{cfg:?}: clocks taken in quiet runs: {promised}");
        }
        assert_eq!(
            (
                new.compared_bits,
                new.compared_reads,
                new.tolerated_reads,
                new.pending_reads()
            ),
            (
                old.compared_bits,
                old.compared_reads,
                old.tolerated_reads,
                old.pending_reads()
            ),
            "{cfg:?}"
        );
        assert!(
            new.compared_bits > 100,
            "{cfg:?}: too few bits compared to mean anything"
        );
    }
    assert!(
        divergences > 100,
        "the sequences exercise divergences ({divergences})"
    );
}
