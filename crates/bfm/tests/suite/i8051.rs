//! Intel-mode (8051) multiplexed bus: master against the RAM target under
//! the monitor; every monitor rule shown to fire on a broken master or slave
//! and to stay silent on clean traffic.

use crate::common;

use bfm::{
    BfmError, HostBusTarget, HostMaster, I8051Config, I8051Master, I8051Monitor,
    I8051MonitorConfig, I8051Out, I8051Polarity, I8051Ram, I8051SlaveOut, I8051Timing, OpKind,
    Rule, Violation, cycle_pause,
};
use common::{Bench, Watch};

impl Watch<I8051Out, I8051SlaveOut> for I8051Monitor {
    fn watch(&mut self, cycle: u64, m: &I8051Out, s: &I8051SlaveOut) -> Vec<Violation> {
        self.observe(cycle, m, s)
    }
}

fn rules(v: &[Violation]) -> Vec<Rule> {
    let mut r: Vec<Rule> = v.iter().map(|x| x.rule).collect();
    r.dedup();
    r
}

fn bench(
    pol: I8051Polarity,
    master_t: I8051Timing,
    monitor_t: I8051Timing,
    read_latency: u32,
) -> Bench<I8051Master, I8051Ram, I8051Monitor> {
    let master = I8051Master::new(
        "host",
        I8051Config {
            polarity: pol,
            timing: master_t,
            ..I8051Config::default()
        },
    );
    let ram = I8051Ram::new("ram", pol, read_latency);
    let mon = I8051Monitor::new("mon", I8051MonitorConfig::for_timing(pol, &monitor_t));
    Bench::new(master, ram, mon)
}

#[test]
fn writes_then_reads_both_polarities_with_and_without_pauses() {
    for pol in [I8051Polarity::SJA1000, I8051Polarity::ACTIVE_HIGH] {
        for paused in [false, true] {
            let t = I8051Timing::default();
            let mut b = bench(pol, t, t, 3);
            if paused {
                b.master.set_pause(Some(cycle_pause()));
            }
            let data: Vec<(u8, u8)> = (0..40u32)
                .map(|i| ((i * 37 % 256) as u8, (i * 101 + 7) as u8))
                .collect();
            for &(a, d) in &data {
                let h = b.master.start_write(a, d);
                let r = b.wait(h).unwrap();
                assert_eq!((r.kind, r.addr, r.data), (OpKind::Write, a, d));
                if !paused {
                    assert_eq!(r.cycles, b.master.access_cycles(OpKind::Write));
                }
            }
            assert_eq!(b.target.writes(), data.len() as u64);
            for &(a, d) in &data {
                assert_eq!(b.target.mem()[a as usize], d, "{pol:?} address {a}");
                let h = b.master.start_read(a);
                let r = b.wait(h).unwrap();
                assert_eq!(r.data, d, "{pol:?} paused {paused} read 0x{a:02X}");
                if !paused {
                    assert_eq!(r.cycles, b.master.access_cycles(OpKind::Read));
                }
            }
            assert!(b.violations.is_empty(), "{:?}", b.violations);
        }
    }
}

#[test]
fn idle_wires_follow_the_polarity() {
    let sja = I8051Master::new(
        "h",
        I8051Config {
            polarity: I8051Polarity::SJA1000,
            ..I8051Config::default()
        },
    );
    let o = sja.outputs();
    // /CS /RD /WR idle high, ALE idle low, port released.
    assert_eq!(
        (o.ale, o.cs, o.rd, o.wr, o.ad_oe),
        (false, true, true, true, false)
    );
    let hi = I8051Master::new("h", I8051Config::default());
    let o = hi.outputs();
    assert_eq!(
        (o.ale, o.cs, o.rd, o.wr, o.ad_oe),
        (false, false, false, false, false)
    );
}

#[test]
fn pins_of_one_write_cycle_by_cycle() {
    let t = I8051Timing {
        ale: 2,
        addr_hold: 1,
        read_float: 1,
        data_setup: 1,
        rd: 3,
        wr: 2,
        data_hold: 1,
        recovery: 1,
    };
    let mut b = bench(I8051Polarity::SJA1000, t, t, 0);
    b.master.start_write(0x12, 0xA5);
    let mut seen = Vec::new();
    for _ in 0..10 {
        let m = b.master.outputs();
        seen.push((m.ale, m.cs, m.rd, m.wr, m.ad_oe.then_some(m.ad)));
        b.step();
    }
    // Raw levels (/CS /RD /WR active low): idle, ALE x2, hold, set-up, WR x2, hold, recovery, idle.
    let a = Some(0x12);
    let d = Some(0xA5);
    assert_eq!(
        seen,
        vec![
            (false, true, true, true, None),
            (true, false, true, true, a),
            (true, false, true, true, a),
            (false, false, true, true, a),
            (false, false, true, true, d),
            (false, false, true, false, d),
            (false, false, true, false, d),
            (false, false, true, true, d),
            (false, true, true, true, None),
            (false, true, true, true, None),
        ]
    );
    assert_eq!(b.target.mem()[0x12], 0xA5);
    assert!(b.violations.is_empty(), "{:?}", b.violations);
}

#[test]
fn read_data_must_arrive_within_the_rd_strobe() {
    let t = I8051Timing {
        rd: 5,
        ..I8051Timing::default()
    };
    // The RAM's registered data is on the wires from RD cycle latency + 2;
    // the master samples the last (5th) RD cycle: in time up to latency 3.
    for (latency, expect) in [(0, 0x5A), (3, 0x5A), (4, 0xFF), (9, 0xFF)] {
        let mut b = bench(I8051Polarity::ACTIVE_HIGH, t, t, latency);
        b.target.mem_mut()[0x33] = 0x5A;
        let h = b.master.start_read(0x33);
        let r = b.wait(h).unwrap();
        assert_eq!(
            r.data, expect,
            "latency {latency}: pull-ups read when too late"
        );
    }
}

#[test]
fn too_short_ale_rd_wr_are_flagged() {
    let need = I8051Timing::default();
    for (what, short, rule_msg) in [
        (
            "ALE",
            I8051Timing {
                ale: need.ale - 1,
                ..need
            },
            "ALE asserted",
        ),
        (
            "RD",
            I8051Timing {
                rd: need.rd - 1,
                ..need
            },
            "RD asserted",
        ),
        (
            "WR",
            I8051Timing {
                wr: need.wr - 1,
                data_setup: need.data_setup + 1,
                ..need
            },
            "WR asserted",
        ),
    ] {
        let mut b = bench(I8051Polarity::SJA1000, short, need, 1);
        let h = b.master.start_write(1, 2);
        b.wait(h).unwrap();
        let h = b.master.start_read(1);
        b.wait(h).unwrap();
        b.steps(4);
        let hits: Vec<&Violation> = b
            .violations
            .iter()
            .filter(|v| v.rule == Rule::StrobeTooShort)
            .collect();
        assert!(!hits.is_empty(), "{what}: {:?}", b.violations);
        assert!(
            hits.iter().all(|v| v.message.starts_with(rule_msg)),
            "{what}: {hits:?}"
        );
    }
}

#[test]
fn data_and_address_not_held_are_flagged() {
    let need = I8051Timing {
        addr_hold: 3,
        data_hold: 3,
        ..I8051Timing::default()
    };
    let cases = [
        (
            "address hold",
            I8051Timing {
                addr_hold: 2,
                read_float: need.read_float + 1,
                ..need
            },
        ),
        (
            "data hold",
            I8051Timing {
                data_hold: 2,
                recovery: need.recovery + 1,
                ..need
            },
        ),
        (
            "data set-up",
            I8051Timing {
                data_setup: need.data_setup - 1,
                addr_hold: need.addr_hold + 1,
                ..need
            },
        ),
    ];
    for (what, t) in cases {
        let mut b = bench(I8051Polarity::SJA1000, t, need, 1);
        let h = b.master.start_write(0x40, 0x04);
        b.wait(h).unwrap();
        let h = b.master.start_read(0x40);
        assert_eq!(b.wait(h).unwrap().data, 0x04, "{what}: the RAM still works");
        assert_eq!(
            rules(&b.violations),
            vec![Rule::DataNotHeld],
            "{what}: {:?}",
            b.violations
        );
    }
    // The same master against its own minimums is clean.
    let mut b = bench(I8051Polarity::SJA1000, need, need, 1);
    let h = b.master.start_write(0x40, 0x04);
    b.wait(h).unwrap();
    assert!(b.violations.is_empty());
}

#[test]
fn slow_float_gives_contention_and_drive_outside_rd() {
    let t = I8051Timing {
        recovery: 1,
        ..I8051Timing::default()
    };
    let mut b = bench(I8051Polarity::ACTIVE_HIGH, t, t, 1);
    // The slave keeps driving 3 cycles after RD: into the next ALE phase.
    b.target.float_delay = 3;
    b.target.mem_mut()[7] = 0x70;
    let h = b.master.start_read(7);
    assert_eq!(b.wait(h).unwrap().data, 0x70);
    let h = b.master.start_write(8, 0x80);
    b.wait(h).unwrap();
    let r = rules(&b.violations);
    assert!(r.contains(&Rule::ReadOutsideStrobe), "{:?}", b.violations);
    assert!(r.contains(&Rule::PortContention), "{:?}", b.violations);
    let c = b
        .violations
        .iter()
        .find(|v| v.rule == Rule::PortContention)
        .unwrap();
    assert!(c.message.contains("master drives 0x08"), "{c}");
    // A float within the allowed time is no violation.
    let mut b = bench(
        I8051Polarity::ACTIVE_HIGH,
        I8051Timing::default(),
        I8051Timing::default(),
        1,
    );
    b.target.float_delay = 2; // the default recovery covers it
    let h = b.master.start_read(7);
    b.wait(h).unwrap();
    let h = b.master.start_write(8, 0x80);
    b.wait(h).unwrap();
    assert!(b.violations.is_empty(), "{:?}", b.violations);
}

#[test]
fn rd_and_wr_together_and_stray_drive_from_hand_made_wires() {
    let pol = I8051Polarity::ACTIVE_HIGH;
    let mut mon = I8051Monitor::new(
        "mon",
        I8051MonitorConfig::for_timing(pol, &I8051Timing::default()),
    );
    let mut both = pol.drive(false, true, true, true);
    both.ad_oe = false;
    let v = mon.observe(0, &both, &I8051SlaveOut::default());
    assert_eq!(rules(&v), vec![Rule::ReadAndWrite]);
    // A slave driving with no RD at all.
    let mut mon = I8051Monitor::new(
        "mon",
        I8051MonitorConfig::for_timing(pol, &I8051Timing::default()),
    );
    let idle = pol.drive(false, false, false, false);
    let drive = I8051SlaveOut {
        ad: 0x11,
        ad_oe: true,
    };
    assert!(
        mon.observe(0, &idle, &drive).is_empty(),
        "seen only from the next cycle"
    );
    let v = mon.observe(1, &idle, &I8051SlaveOut::default());
    assert_eq!(rules(&v), vec![Rule::ReadOutsideStrobe]);
    assert!(v[0].message.contains("no RD ever"), "{}", v[0]);
}

#[test]
fn reset_flushes_and_holds() {
    let t = I8051Timing::default();
    let mut b = bench(I8051Polarity::SJA1000, t, t, 1);
    let h1 = b.master.start_write(1, 1);
    let h2 = b.master.start_read(1);
    b.steps(3);
    b.master.set_reset(true);
    assert!(matches!(
        b.master.poll(h1),
        Some(Err(BfmError::Flushed { .. }))
    ));
    assert!(matches!(
        b.master.poll(h2),
        Some(Err(BfmError::Flushed { .. }))
    ));
    let o = b.master.outputs();
    assert_eq!(o, I8051Polarity::SJA1000.drive(false, false, false, false));
    // Held in reset: a queued access waits, then times out.
    b.master.set_timeout(10);
    let h3 = b.master.start_read(2);
    b.steps(12);
    assert!(matches!(
        b.master.poll(h3),
        Some(Err(BfmError::Timeout { .. }))
    ));
    b.master.set_reset(false);
    let h4 = b.master.start_write(3, 3);
    assert!(b.wait(h4).is_ok());
    assert_eq!(b.target.mem()[3], 3);
}

#[test]
fn ram_target_alone_latches_on_ale() {
    // Drive the RAM by hand: the last ALE cycle's port value is the address.
    let pol = I8051Polarity::SJA1000;
    let mut ram = I8051Ram::new("ram", pol, 0);
    let mut m = pol.drive(true, true, false, false);
    m.ad_oe = true;
    m.ad = 9;
    ram.cycle(&m);
    m.ad = 10;
    ram.cycle(&m);
    let mut w = pol.drive(false, true, false, true);
    w.ad_oe = true;
    w.ad = 0xEE;
    ram.cycle(&w);
    ram.cycle(&pol.drive(false, true, false, false));
    assert_eq!(ram.mem()[10], 0xEE);
    assert_eq!(ram.mem()[9], 0);
}
