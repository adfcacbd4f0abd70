//! Masters against the RAM targets: data integrity under the
//! {no pause, 1-1-1-0} x {no backpressure, 1-1-1-0} matrix, exact per-access
//! cycle costs, timeouts, reset flushing, blocking helpers.

use crate::common;

use bfm::faults::{NeverAck, StuckWaitrequest};
use bfm::{
    AckMode, AvalonMaster, AvalonMasterConfig, AvalonMonitor, AvalonMonitorConfig, AvalonRam,
    AvalonTiming, BfmError, HostBusTarget, HostMaster, OpKind, PioMaster, PioTiming, WbMasterOut,
    WbSlaveOut, WishboneMaster, WishboneMonitor, WishboneRam, blocking_read, blocking_write,
    run_op,
};
use common::{Bench, NoWatch, Watch, capture_logs, logs, matrix};
use proptest::prelude::*;

/// Avalon timings every Avalon test covers.
const AV_TIMINGS: [AvalonTiming; 4] = [
    AvalonTiming::FixedWaitStates { read: 1, write: 0 },
    AvalonTiming::FixedWaitStates { read: 3, write: 2 },
    AvalonTiming::Waitrequest,
    AvalonTiming::Pipelined,
];

fn av_cfg(timing: AvalonTiming) -> AvalonMasterConfig {
    AvalonMasterConfig {
        timing,
        begintransfer: true,
        ..Default::default()
    }
}

fn av_mon(timing: AvalonTiming) -> AvalonMonitor {
    AvalonMonitor::new(
        "avmon",
        AvalonMonitorConfig {
            timing,
            begintransfer: true,
            timeout_cycles: 100,
        },
    )
}

/// Queue every operation, then check each result against a shadow memory,
/// the final RAM contents and the monitor's silence.
fn check_traffic<M, T, W>(
    bench: &mut Bench<M, T, W>,
    ops: &[(bool, u8, u8)],
    mem: impl Fn(&T) -> [u8; 256],
    label: &str,
) -> Result<(), TestCaseError>
where
    M: HostMaster,
    T: HostBusTarget<M::Out, M::In>,
    W: Watch<M::Out, M::In>,
{
    let mut shadow = [0u8; 256];
    let handles: Vec<_> = ops
        .iter()
        .map(|&(write, a, d)| {
            if write {
                bench.master.start_write(a, d)
            } else {
                bench.master.start_read(a)
            }
        })
        .collect();
    for (&(write, a, d), h) in ops.iter().zip(handles) {
        let r = bench
            .wait(h)
            .map_err(|e| TestCaseError::fail(format!("{label}: {e}")))?;
        prop_assert_eq!(r.addr, a, "{}", label);
        if write {
            prop_assert_eq!(r.kind, OpKind::Write);
            shadow[a as usize] = d;
        } else {
            prop_assert_eq!(r.kind, OpKind::Read);
            prop_assert_eq!(r.data, shadow[a as usize], "{}: read 0x{:02X}", label, a);
        }
        prop_assert!(r.cycles >= 1);
    }
    prop_assert_eq!(mem(&bench.target), shadow, "{}", label);
    prop_assert!(
        bench.violations.is_empty(),
        "{}: {:?}",
        label,
        bench.violations
    );
    prop_assert_eq!(bench.master.in_flight(), 0);
    Ok(())
}

/// Few distinct addresses so reads hit earlier writes.
fn ops_strategy() -> impl Strategy<Value = Vec<(bool, u8, u8)>> {
    prop::collection::vec((any::<bool>(), 0u8..8, any::<u8>()), 1..40)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn wishbone_random_traffic(ops in ops_strategy()) {
        for (label, mp, tp) in matrix() {
            let mut m = WishboneMaster::new("wb");
            m.set_pause(mp);
            let mut ram = WishboneRam::new("ram");
            ram.set_backpressure(tp);
            let mut b = Bench::new(m, ram, WishboneMonitor::new("wbmon", 100));
            check_traffic(&mut b, &ops, |r| *r.mem(), &label)?;
        }
    }

    #[test]
    fn avalon_random_traffic(ops in ops_strategy()) {
        for timing in AV_TIMINGS {
            for (label, mp, tp) in matrix() {
                let label = format!("{timing:?}, {label}");
                let mut m = AvalonMaster::new("av", av_cfg(timing));
                m.set_pause(mp);
                let mut ram = AvalonRam::new("ram", timing);
                ram.set_backpressure(tp);
                let mut b = Bench::new(m, ram, av_mon(timing));
                check_traffic(&mut b, &ops, |r| *r.mem(), &label)?;
            }
        }
    }

    #[test]
    fn pio_random_traffic(ops in prop::collection::vec((any::<bool>(), 0u8..8, any::<u8>()), 1..12)) {
        for (label, mp, tp) in matrix() {
            let mut m = PioMaster::new("pio", PioTiming::default());
            m.set_pause(mp);
            // A polling CPU needs a level ack (see `pio_polling_misses_pulse_acks`).
            let mut ram = WishboneRam::new("ram").with_ack_mode(AckMode::Level);
            ram.set_backpressure(tp);
            let mut b = Bench::new(m, ram, NoWatch);
            check_traffic(&mut b, &ops, |r| *r.mem(), &label)?;
        }
    }
}

/// Cycles of one read and one write started on an idle bus, and the mean
/// cost per access over 64 back-to-back alternating accesses.
fn measure<M, T>(mut master: M, mut target: T) -> (u64, u64, f64)
where
    M: HostMaster,
    T: HostBusTarget<M::Out, M::In>,
{
    let w = blocking_write(&mut master, &mut target, 0x10, 0xA5).expect("write");
    let r = blocking_read(&mut master, &mut target, 0x10).expect("read");
    assert_eq!(r.data, 0xA5);
    let mut b = Bench::new(master, target, NoWatch);
    b.steps(4);
    let start = b.cycle;
    let hs: Vec<_> = (0..32u8)
        .flat_map(|i| [b.master.start_write(i, i ^ 0x5A), b.master.start_read(i)])
        .collect();
    let mut last = None;
    for h in hs {
        last = Some(b.wait(h).expect("back-to-back access"));
    }
    assert_eq!(last.unwrap().data, 31 ^ 0x5A);
    // `wait` stops at the cycle the last result is available.
    let per = (b.cycle - start) as f64 / 64.0;
    (r.cycles, w.cycles, per)
}

/// The figures: host cycles per register access for each BFM
/// against the RAM targets, asserted exactly.
#[test]
fn cycle_cost_per_access() {
    // (name, measured (read, write, back-to-back), expected (read, write))
    type Row = (&'static str, (u64, u64, f64), (u64, u64));
    let rows: Vec<Row> = vec![
        (
            "Wishbone classic (registered ack)",
            measure(WishboneMaster::new("wb"), WishboneRam::new("ram")),
            (2, 2),
        ),
        (
            "Avalon fixed wait states (read 1, write 0)",
            measure(
                AvalonMaster::new(
                    "av",
                    av_cfg(AvalonTiming::FixedWaitStates { read: 1, write: 0 }),
                ),
                AvalonRam::new("ram", AvalonTiming::FixedWaitStates { read: 1, write: 0 }),
            ),
            (2, 1),
        ),
        (
            "Avalon waitrequest (registered)",
            measure(
                AvalonMaster::new("av", av_cfg(AvalonTiming::Waitrequest)),
                AvalonRam::new("ram", AvalonTiming::Waitrequest),
            ),
            (2, 2),
        ),
        (
            "Avalon waitrequest + readdatavalid",
            measure(
                AvalonMaster::new("av", av_cfg(AvalonTiming::Pipelined)),
                AvalonRam::new("ram", AvalonTiming::Pipelined),
            ),
            (3, 2),
        ),
        (
            "PIO (Nios II/f, IOWR 3, IORD 5), pulse ack",
            measure(
                PioMaster::new("pio", PioTiming::default()),
                WishboneRam::new("ram"),
            ),
            (27, 25),
        ),
        (
            "PIO (Nios II/f, IOWR 3, IORD 5), level ack",
            measure(
                PioMaster::new("pio", PioTiming::default()),
                WishboneRam::new("ram").with_ack_mode(AckMode::Level),
            ),
            (22, 20),
        ),
    ];
    println!(
        "{:<44} {:>6} {:>6} {:>14}",
        "BFM vs RAM target", "read", "write", "back-to-back"
    );
    for (name, (r, w, per), _) in &rows {
        println!("{name:<44} {r:>6} {w:>6} {per:>14.2}");
    }
    for (name, (r, w, _), (er, ew)) in rows {
        assert_eq!((r, w), (er, ew), "{name}: (read, write) host cycles");
    }
}

/// Every timeout fires with the operation, address and cycle count, and the
/// queue goes on.
#[test]
fn wishbone_timeout_on_never_ack() {
    let mut m = WishboneMaster::new("wb").with_timeout(50);
    let mut t = NeverAck(WishboneRam::new("ram"));
    let e = blocking_read(&mut m, &mut t, 0x33).unwrap_err();
    assert_eq!(
        e,
        BfmError::Timeout {
            op: OpKind::Read,
            addr: 0x33,
            cycles: 50
        }
    );
    assert!(
        !m.outputs().cyc && !m.outputs().stb,
        "cycle abandoned after the timeout"
    );
    let e = blocking_write(&mut m, &mut t, 0x01, 0x02).unwrap_err();
    assert!(matches!(
        e,
        BfmError::Timeout {
            op: OpKind::Write,
            addr: 0x01,
            ..
        }
    ));
}

#[test]
fn avalon_timeout_on_stuck_waitrequest() {
    for timing in [AvalonTiming::Waitrequest, AvalonTiming::Pipelined] {
        let mut m = AvalonMaster::new(
            "av",
            AvalonMasterConfig {
                timeout_cycles: 40,
                ..av_cfg(timing)
            },
        );
        let mut t = StuckWaitrequest(AvalonRam::new("ram", timing));
        let e = blocking_write(&mut m, &mut t, 0x07, 1).unwrap_err();
        assert_eq!(
            e,
            BfmError::Timeout {
                op: OpKind::Write,
                addr: 0x07,
                cycles: 40
            }
        );
    }
    // Pipelined read accepted but its data never comes.
    let timing = AvalonTiming::Pipelined;
    let mut m = AvalonMaster::new(
        "av",
        AvalonMasterConfig {
            timeout_cycles: 30,
            ..av_cfg(timing)
        },
    );
    let mut ram = AvalonRam::new("ram", timing);
    let h = m.start_read(0x02);
    let e = run_op(&mut m, h, |p| {
        let mut s = ram.cycle(p);
        s.readdatavalid = false;
        s
    })
    .unwrap_err();
    assert_eq!(
        e,
        BfmError::Timeout {
            op: OpKind::Read,
            addr: 0x02,
            cycles: 30
        }
    );
}

#[test]
fn pio_timeout_drops_control_word() {
    let mut m = PioMaster::new("pio", PioTiming::default());
    m.set_timeout(200);
    let mut t = NeverAck(WishboneRam::new("ram"));
    let e = blocking_write(&mut m, &mut t, 0x04, 0x99).unwrap_err();
    assert_eq!(
        e,
        BfmError::Timeout {
            op: OpKind::Write,
            addr: 0x04,
            cycles: 200
        }
    );
    assert_eq!(m.ctl(), 0, "control PIO cleared after the timeout");
}

/// A pause generator that never lets go cannot hang an operation either.
#[test]
fn endless_pause_times_out() {
    let mut m = WishboneMaster::new("wb").with_timeout(20);
    m.set_pause(Some(Box::new(std::iter::repeat(true))));
    let mut ram = WishboneRam::new("ram");
    let e = blocking_read(&mut m, &mut ram, 9).unwrap_err();
    assert_eq!(
        e,
        BfmError::Timeout {
            op: OpKind::Read,
            addr: 9,
            cycles: 20
        }
    );
    assert_eq!(ram.accesses(), 0);
}

/// Reset flushes the in-flight operation and every queued one: each is
/// logged as a warning and completes with `Flushed`; pins go idle; the
/// master works again afterwards.
fn reset_flushes<M, T>(mut m: M, mut t: T, busy: impl Fn(&M::Out) -> bool)
where
    M: HostMaster,
    T: HostBusTarget<M::Out, M::In>,
{
    capture_logs();
    let hs = [
        m.start_write(1, 0x11),
        m.start_read(1),
        m.start_write(2, 0x22),
        m.start_read(3),
    ];
    // One edge: the first operation starts and is on the pins.
    for _ in 0..1 {
        let o = m.outputs();
        let s = t.cycle(&o);
        m.on_edge(&s);
    }
    assert!(busy(&m.outputs()), "first access on the pins");
    m.reset();
    assert!(!busy(&m.outputs()), "pins idle after reset");
    assert_eq!(m.in_flight(), 0);
    for (h, (kind, addr)) in hs.iter().zip([
        (OpKind::Write, 1),
        (OpKind::Read, 1),
        (OpKind::Write, 2),
        (OpKind::Read, 3),
    ]) {
        assert_eq!(m.poll(*h), Some(Err(BfmError::Flushed { op: kind, addr })));
    }
    let warnings: Vec<_> = logs()
        .into_iter()
        .filter(|(l, s)| *l == log::Level::Warn && s.contains("flushed"))
        .collect();
    assert_eq!(warnings.len(), 4, "{warnings:?}");
    // Redeemed handles are gone: a clear error, not a hang.
    assert_eq!(m.poll(hs[0]), Some(Err(BfmError::UnknownHandle(hs[0]))));
    let w = blocking_write(&mut m, &mut t, 5, 0x55).expect("works after reset");
    assert_eq!(w.data, 0x55);
    assert_eq!(blocking_read(&mut m, &mut t, 5).expect("read").data, 0x55);
}

#[test]
fn reset_flushes_wishbone() {
    reset_flushes(
        WishboneMaster::new("wb"),
        WishboneRam::new("ram"),
        |o: &WbMasterOut| o.cyc,
    );
}

#[test]
fn reset_flushes_avalon() {
    for timing in AV_TIMINGS {
        reset_flushes(
            AvalonMaster::new("av", av_cfg(timing)),
            AvalonRam::new("ram", timing),
            |o: &bfm::AvMasterOut| o.chipselect,
        );
    }
}

#[test]
fn reset_flushes_pio() {
    // In flight = the address IOWR has not even landed; check via in_flight.
    capture_logs();
    let mut m = PioMaster::new("pio", PioTiming::default());
    let mut t = NeverAck(WishboneRam::new("ram"));
    let hs = [m.start_write(1, 0x11), m.start_read(1)];
    for _ in 0..14 {
        let o = m.outputs();
        let s = t.cycle(&o);
        m.on_edge(&s);
    }
    assert_eq!(m.ctl(), 0x07, "write waiting for ack with cyc|stb|we");
    m.reset();
    assert_eq!(m.ctl(), 0);
    for h in hs {
        assert!(matches!(m.poll(h), Some(Err(BfmError::Flushed { .. }))));
    }
    assert_eq!(
        logs()
            .iter()
            .filter(|(l, s)| *l == log::Level::Warn && s.contains("flushed"))
            .count(),
        2
    );
}

/// Construction logs the role's widths and options.
#[test]
fn roles_log_their_setup() {
    capture_logs();
    let _ = WishboneMaster::new("wb0");
    let _ = AvalonMaster::new("av0", AvalonMasterConfig::default());
    let _ = PioMaster::new("pio0", PioTiming::default());
    let l = logs();
    let has = |name: &str, what: &str| {
        l.iter()
            .any(|(_, s)| s.starts_with(name) && s.contains(what))
    };
    assert!(has("wb0", "adr 8 bits"), "{l:?}");
    assert!(has("av0", "begintransfer absent"), "{l:?}");
    assert!(has("pio0", "IOWR 3 cycles, IORD 5 cycles"), "{l:?}");
}

/// err ends an access with a bus error; rty makes the master retry.
#[test]
fn wishbone_err_and_rty() {
    let mut m = WishboneMaster::new("wb");
    let mut ram = WishboneRam::new("ram");
    let h = m.start_write(3, 4);
    let e = run_op(&mut m, h, |p| {
        let mut s = ram.cycle(p);
        s.err = s.ack;
        s.ack = false;
        s
    })
    .unwrap_err();
    assert_eq!(
        e,
        BfmError::BusError {
            op: OpKind::Write,
            addr: 3
        }
    );

    // First answer is rty, then normal acks.
    let mut retries = 0;
    let h = m.start_read(3);
    let r = run_op(&mut m, h, |p| {
        let mut s = ram.cycle(p);
        if s.ack && retries == 0 {
            retries += 1;
            s.ack = false;
            s.rty = true;
        }
        s
    })
    .expect("retried read");
    assert_eq!(retries, 1);
    assert_eq!(r.data, 4, "the write landed before err was forced");
    assert!(r.cycles >= 4, "retry costs extra cycles: {}", r.cycles);
}

/// The PIO master drives the thesis's control words in order.
#[test]
fn pio_control_word_sequence() {
    let mut m = PioMaster::new(
        "pio",
        PioTiming {
            iowr_cycles: 1,
            iord_cycles: 1,
            ..PioTiming::default()
        },
    );
    let mut ram = WishboneRam::new("ram");
    let mut seen = vec![m.ctl()];
    let h = m.start_write(0x1F, 0x00);
    let h2 = m.start_read(0x1F);
    let mut trace = Vec::new();
    for _ in 0..40 {
        let o = m.outputs();
        trace.push(o);
        let s = ram.cycle(&o);
        m.on_edge(&s);
        if *seen.last().unwrap() != m.ctl() {
            seen.push(m.ctl());
        }
    }
    assert!(m.poll(h).unwrap().is_ok() && m.poll(h2).unwrap().is_ok());
    assert_eq!(seen, vec![0x00, 0x01, 0x07, 0x00, 0x06, 0x00]);
    // Address and data were set before the strobe rose.
    let first_stb = trace.iter().find(|o| o.stb).unwrap();
    assert_eq!(
        (first_stb.adr, first_stb.dat, first_stb.we, first_stb.cyc),
        (0x1F, 0x00, true, true)
    );
    let _: WbSlaveOut = Default::default();

    // The reset pulse: ctl 0x08 held, then 0.
    let h = m.start_dut_reset(10);
    let mut rst_cycles = 0;
    for _ in 0..30 {
        let o = m.outputs();
        let s = ram.cycle(&o);
        m.on_edge(&s);
        rst_cycles += m.rst() as u32;
    }
    assert!(m.poll(h).unwrap().is_ok());
    assert_eq!(
        rst_cycles, 11,
        "rst held for the busy loop plus the clearing IOWR"
    );
    assert!(!m.rst());
}

/// A CPU polling `ack` through a GPIO samples it once per IORD; a slave
/// whose `ack` is a one-cycle pulse (like `can_top`'s) can be missed. Here
/// the CPU's idle pattern and the slave's stall pattern (both 1-1-1-0) lock
/// in phase and every pulse falls between two samples: the model times out
/// where the C code would spin forever. With a level ack it completes.
#[test]
fn pio_polling_misses_pulse_acks() {
    let run = |mode: AckMode| {
        let mut m = PioMaster::new("pio", PioTiming::default());
        m.set_timeout(2000);
        m.set_pause(Some(bfm::cycle_pause()));
        let mut ram = WishboneRam::new("ram").with_ack_mode(mode);
        ram.set_backpressure(Some(bfm::cycle_pause()));
        let r = blocking_read(&mut m, &mut ram, 0);
        (r, ram.accesses())
    };
    let (r, accesses) = run(AckMode::Pulse);
    assert_eq!(
        r,
        Err(BfmError::Timeout {
            op: OpKind::Read,
            addr: 0,
            cycles: 2000
        })
    );
    assert!(
        accesses > 100,
        "the held strobe re-triggered the access {accesses} times"
    );
    let (r, accesses) = run(AckMode::Level);
    assert!(r.is_ok(), "{r:?}");
    assert_eq!(accesses, 1);
}

/// With a pulse ack and no pauses the PIO write completes, but the held
/// strobe makes the slave perform it several times: harmless on RAM, not on
/// a register with side effects (CMR).
#[test]
fn pio_write_repeats_on_pulse_ack_slave() {
    let mut m = PioMaster::new("pio", PioTiming::default());
    let mut ram = WishboneRam::new("ram");
    blocking_write(&mut m, &mut ram, 1, 0x42).expect("write");
    assert!(ram.accesses() >= 2, "accesses {}", ram.accesses());
    let mut ram = WishboneRam::new("ram").with_ack_mode(AckMode::Level);
    blocking_write(&mut m, &mut ram, 1, 0x42).expect("write");
    assert_eq!(ram.accesses(), 1);
}

/// Random wait insertion on both sides (seeded), for every master.
#[test]
fn random_waits_every_master() {
    let ops: Vec<(bool, u8, u8)> = (0..60u8)
        .map(|i| (i % 3 != 1, i % 7, i.wrapping_mul(37)))
        .collect();
    for seed in 0..8u64 {
        let label = format!("seed {seed}");
        let mut m = WishboneMaster::new("wb");
        m.set_pause(Some(bfm::random_pause(seed, 1, 3)));
        let mut ram = WishboneRam::new("ram");
        ram.set_backpressure(Some(bfm::random_pause(seed + 100, 1, 2)));
        let mut b = Bench::new(m, ram, WishboneMonitor::new("wbmon", 100));
        check_traffic(&mut b, &ops, |r| *r.mem(), &label).unwrap();
        for timing in AV_TIMINGS {
            let mut m = AvalonMaster::new("av", av_cfg(timing));
            m.set_pause(Some(bfm::random_pause(seed, 1, 3)));
            let mut ram = AvalonRam::new("ram", timing);
            ram.set_backpressure(Some(bfm::random_pause(seed + 100, 1, 2)));
            let mut b = Bench::new(m, ram, av_mon(timing));
            check_traffic(&mut b, &ops, |r| *r.mem(), &label).unwrap();
        }
        let mut m = PioMaster::new("pio", PioTiming::default());
        m.set_pause(Some(bfm::random_pause(seed, 1, 3)));
        let mut ram = WishboneRam::new("ram").with_ack_mode(AckMode::Level);
        ram.set_backpressure(Some(bfm::random_pause(seed + 100, 1, 2)));
        let mut b = Bench::new(m, ram, NoWatch);
        check_traffic(&mut b, &ops, |r| *r.mem(), &label).unwrap();
    }
}

#[test]
fn random_pause_is_seeded() {
    let a: Vec<bool> = bfm::random_pause(7, 1, 4).take(4000).collect();
    let b: Vec<bool> = bfm::random_pause(7, 1, 4).take(4000).collect();
    let c: Vec<bool> = bfm::random_pause(8, 1, 4).take(4000).collect();
    assert_eq!(a, b);
    assert_ne!(a, c);
    let n = a.iter().filter(|x| **x).count();
    assert!((850..1150).contains(&n), "{n} pauses in 4000 at 1/4");
}

/// The reset line: assertion flushes once; while held nothing starts;
/// after release queued work runs.
#[test]
fn reset_pin_holds_and_flushes() {
    capture_logs();
    let mut m = WishboneMaster::new("wb");
    let mut ram = WishboneRam::new("ram");
    let before = m.start_write(1, 1);
    m.set_reset(true);
    assert!(matches!(
        m.poll(before),
        Some(Err(BfmError::Flushed { .. }))
    ));
    let during = m.start_write(2, 0x22);
    for _ in 0..10 {
        m.set_reset(true);
        let o = m.outputs();
        assert!(!o.cyc, "nothing starts while reset is held");
        let s = ram.cycle(&o);
        m.on_edge(&s);
    }
    assert_eq!(m.poll(during), None);
    m.set_reset(false);
    let r = run_op(&mut m, during, |o| ram.cycle(o)).expect("runs after release");
    assert_eq!(r.cycles, 12, "10 cycles held in reset + 2 for the access");
    assert_eq!(ram.mem()[2], 0x22);
    assert_eq!(
        logs().iter().filter(|(_, s)| s.contains("flushed")).count(),
        1
    );
}

/// A slave with a request/acknowledge handshake like `can_top`'s: one
/// one-cycle ack pulse `delay` cycles after cyc & stb appear, then nothing
/// until the strobe has dropped (no repeat: this isolates how the program
/// sees the pulse). Returns (result, acks given, host cycles from the ack
/// to the strobe's fall).
fn pio_against_one_pulse(
    timing: PioTiming,
    delay: u32,
    read: bool,
) -> (Option<Result<bfm::OpResult, BfmError>>, u32, u32) {
    let mut m = PioMaster::new("pio", timing);
    m.set_timeout(500);
    let h = if read {
        m.start_read(0x02)
    } else {
        m.start_write(0x01, 0x04)
    };
    let (mut seen, mut acks, mut fired) = (0u32, 0u32, false);
    let mut held_after_ack = 0u32;
    let mut s = WbSlaveOut::default();
    for _ in 0..1000 {
        let o = m.outputs();
        let req = o.cyc && o.stb;
        held_after_ack += (req && fired) as u32;
        seen = if req { seen + 1 } else { 0 };
        fired &= req;
        s = WbSlaveOut {
            ack: req && !fired && seen == delay,
            dat: 0x5A,
            ..s
        };
        if s.ack {
            fired = true;
            acks += 1;
        }
        m.on_edge(&s);
        if let Some(r) = m.poll(h) {
            return (Some(r), acks, held_after_ack);
        }
    }
    (None, acks, held_after_ack)
}

/// The thesis's level poll (one `IORD` of the data register per 5 cycles)
/// misses a one-cycle ack that falls between two samples and spins until
/// its timeout; the same program polling the ack PIO's edge capture
/// register sees the pulse whatever its phase, once, and reads the data.
#[test]
fn pio_edge_capture_sees_a_one_cycle_ack_the_level_poll_misses() {
    let edge = PioTiming {
        ack_input: bfm::PioAckInput::EdgeCapture,
        ..PioTiming::default()
    };
    let mut level_missed = 0;
    for delay in 1..=10 {
        for read in [false, true] {
            let (r, acks, _) = pio_against_one_pulse(PioTiming::default(), delay, read);
            if matches!(r, Some(Err(BfmError::Timeout { .. }))) {
                level_missed += 1;
            }
            assert_eq!(acks, 1);
            let (r, acks, held) = pio_against_one_pulse(edge, delay, read);
            let r = r.expect("finished").expect("edge capture saw the pulse");
            assert_eq!(acks, 1);
            // Capture latency (2) + at most one poll (5) + the IOWR that
            // drops the strobe (3): the data is read after that.
            assert!(held <= 10, "cyc/stb held {held} cycles after the ack (read {read})");
            if read {
                assert_eq!(r.data, 0x5A);
            }
        }
    }
    assert!(
        level_missed >= 10,
        "the level poll missed only {level_missed} of 20 pulses"
    );
}

/// Edge capture is cleared before the strobe rises: an ack pulse from
/// before the access (a stale capture) does not complete it.
#[test]
fn pio_edge_capture_ignores_an_ack_before_the_strobe() {
    let mut m = PioMaster::new(
        "pio",
        PioTiming {
            ack_input: bfm::PioAckInput::EdgeCapture,
            ..PioTiming::default()
        },
    );
    m.set_timeout(300);
    // A stray ack pulse while the bus is idle.
    m.on_edge(&WbSlaveOut {
        ack: true,
        ..Default::default()
    });
    for _ in 0..5 {
        m.on_edge(&WbSlaveOut::default());
    }
    let h = m.start_write(0x01, 0x04);
    let mut r = None;
    for _ in 0..400 {
        m.on_edge(&WbSlaveOut::default());
        if let Some(x) = m.poll(h) {
            r = Some(x);
            break;
        }
    }
    assert!(matches!(r, Some(Err(BfmError::Timeout { .. }))), "{r:?}");
}
