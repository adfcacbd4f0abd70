//! Protocol monitors: each rule is caught when a broken master or target
//! breaks it, at the right cycle, and clean traffic raises nothing.

use crate::common;

use bfm::faults::{DoubleAck, NeverAck, SpuriousAck, SpuriousReaddatavalid, StuckWaitrequest};
use bfm::wiring::{AvalonOverWishbone, Wiring};
use bfm::{
    AvMasterOut, AvSlaveOut, AvalonMaster, AvalonMasterConfig, AvalonMonitor, AvalonMonitorConfig,
    AvalonRam, AvalonTiming, HostBusTarget, HostMaster, Rule, Violation, WbMasterOut, WbSlaveOut,
    WishboneMaster, WishboneMonitor, WishboneRam,
};
use common::{Bench, matrix};

fn rules(v: &[Violation]) -> Vec<(u64, Rule)> {
    v.iter().map(|x| (x.cycle, x.rule)).collect()
}

fn wb(cyc: bool, stb: bool, we: bool, adr: u8, dat: u8) -> WbMasterOut {
    WbMasterOut {
        cyc,
        stb,
        we,
        adr,
        dat,
    }
}

const IDLE: WbMasterOut = WbMasterOut {
    cyc: false,
    stb: false,
    we: false,
    adr: 0,
    dat: 0,
};
const NO_ACK: WbSlaveOut = WbSlaveOut {
    ack: false,
    dat: 0,
    err: false,
    rty: false,
};

/// Feed a crafted trace: (master pins during cycle k, slave outputs after edge k).
fn feed_wb(trace: &[(WbMasterOut, WbSlaveOut)]) -> Vec<Violation> {
    let mut mon = WishboneMonitor::new("wbmon", 100);
    trace
        .iter()
        .enumerate()
        .flat_map(|(k, (m, s))| mon.observe(k as u64, m, s))
        .collect()
}

// ---- Wishbone ----------------------------------------------------------

#[test]
fn wb_stb_without_cyc() {
    let v = feed_wb(&[
        (IDLE, NO_ACK),
        (wb(false, true, false, 3, 0), NO_ACK),
        (IDLE, NO_ACK),
    ]);
    assert_eq!(rules(&v), vec![(1, Rule::StbWithoutCyc)]);
    assert!(
        v[0].to_string().starts_with("cycle 1: stb without cyc:"),
        "{}",
        v[0]
    );
}

#[test]
fn wb_changed_while_waiting() {
    let req = wb(true, true, true, 0x10, 0xAA);
    let v = feed_wb(&[
        (req, NO_ACK),
        (req, NO_ACK),
        (wb(true, true, true, 0x10, 0xAB), NO_ACK),
        (wb(true, true, false, 0x11, 0), NO_ACK),
    ]);
    assert_eq!(
        rules(&v),
        vec![
            (2, Rule::ChangedWhileWaiting),
            (3, Rule::ChangedWhileWaiting)
        ]
    );
    assert!(v[0].message.contains("dat 0xAA->0xAB"), "{}", v[0]);
    assert!(
        v[1].message.contains("adr 0x10->0x11") && v[1].message.contains("we 1->0"),
        "{}",
        v[1]
    );
}

#[test]
fn wb_stb_and_cyc_dropped_before_ack() {
    let req = wb(true, true, false, 1, 0);
    let v = feed_wb(&[
        (req, NO_ACK),
        (wb(true, false, false, 1, 0), NO_ACK),
        (req, NO_ACK),
        (IDLE, NO_ACK),
    ]);
    assert_eq!(
        rules(&v),
        vec![
            (1, Rule::StbDroppedBeforeAck),
            (3, Rule::CycDroppedBeforeAck)
        ]
    );
}

/// Seed 000's Platform Designer wiring: wb_cyc_i on begintransfer, a
/// one-cycle pulse. The Wishbone side sees cyc fall before ack.
#[test]
fn wb_seed000_begintransfer_as_cyc() {
    let cfg = AvalonMasterConfig {
        timing: AvalonTiming::FixedWaitStates { read: 1, write: 0 },
        begintransfer: true,
        ..Default::default()
    };
    for wiring in [Wiring::Seed000, Wiring::Bridge] {
        let cfg = if wiring == Wiring::Bridge {
            AvalonMasterConfig {
                timing: AvalonTiming::Waitrequest,
                ..cfg
            }
        } else {
            cfg
        };
        let mut m = AvalonMaster::new("nios", cfg);
        let mut t = AvalonOverWishbone::new(WishboneRam::new("can_top"), wiring);
        let mut mon = WishboneMonitor::new("wbmon", 100);
        let mut v = Vec::new();
        let h = m.start_read(0x02);
        for k in 0..8 {
            let o = m.outputs();
            let s = t.cycle(&o);
            m.on_edge(&s);
            let (wm, ws) = t.last_wishbone();
            v.extend(mon.observe(k, &wm, &ws));
        }
        assert!(m.poll(h).unwrap().is_ok());
        match wiring {
            Wiring::Seed000 => {
                // Transfer on the wires at cycle 1; cyc gone at cycle 2 while
                // stb (chipselect) stays high and the registered ack arrives.
                assert!(rules(&v).contains(&(2, Rule::CycDroppedBeforeAck)), "{v:?}");
                assert!(rules(&v).contains(&(2, Rule::StbWithoutCyc)), "{v:?}");
                let cyc = v
                    .iter()
                    .find(|x| x.rule == Rule::CycDroppedBeforeAck)
                    .unwrap();
                assert!(
                    cyc.message.contains("read at 0x02 started at cycle 1"),
                    "{cyc}"
                );
            }
            Wiring::Bridge => assert!(v.is_empty(), "{v:?}"),
        }
    }
}

/// Seed 000's wiring loses a write when the slave is not ready in the
/// first cycle: cyc is gone by the time it could act.
#[test]
fn wb_seed000_write_lost_on_slow_slave() {
    let cfg = AvalonMasterConfig {
        timing: AvalonTiming::FixedWaitStates { read: 1, write: 1 },
        begintransfer: true,
        ..Default::default()
    };
    let mut m = AvalonMaster::new("nios", cfg);
    let mut ram = WishboneRam::new("can_top");
    // Not ready in the one cycle where cyc (begintransfer) is high.
    ram.set_backpressure(Some(Box::new([false, true].into_iter())));
    let mut t = AvalonOverWishbone::new(ram, Wiring::Seed000);
    bfm::blocking_write(&mut m, &mut t, 0x05, 0x77).expect("fixed wait states always complete");
    assert_eq!(t.inner().mem()[5], 0, "the write never reached the slave");
}

#[test]
fn wb_ack_without_request() {
    // A slave that acks on its own while the bus is idle.
    let mut b = Bench::new(
        WishboneMaster::new("wb"),
        SpuriousAck::new(WishboneRam::new("ram"), 5),
        WishboneMonitor::new("wbmon", 100),
    );
    b.steps(12);
    // s after edges 4 and 9 carry ack; the wires show them in cycles 5 and 10.
    assert_eq!(
        rules(&b.violations),
        vec![(5, Rule::AckWithoutRequest), (10, Rule::AckWithoutRequest)]
    );
    assert!(
        b.violations[0]
            .message
            .contains("wb_ack_o=1 while cyc=0 stb=0"),
        "{}",
        b.violations[0]
    );

    // A slave that acks twice: the second ack finds no request.
    let mut b = Bench::new(
        WishboneMaster::new("wb"),
        DoubleAck::new(WishboneRam::new("ram")),
        WishboneMonitor::new("wbmon", 100),
    );
    let h = b.master.start_write(1, 2);
    b.wait(h).unwrap();
    b.steps(3);
    assert_eq!(rules(&b.violations), vec![(3, Rule::AckWithoutRequest)]);
}

#[test]
fn wb_no_ack_within_limit() {
    let mut b = Bench::new(
        WishboneMaster::new("wb").with_timeout(40),
        NeverAck(WishboneRam::new("ram")),
        WishboneMonitor::new("wbmon", 10),
    );
    let h = b.master.start_read(0x21);
    assert!(b.wait(h).is_err());
    b.steps(2);
    // On the wires from cycle 1; more than 10 cycles at cycle 11, once; the
    // master's timeout then abandons it (cycle 41).
    assert_eq!(
        rules(&b.violations),
        vec![(11, Rule::NoAck), (41, Rule::CycDroppedBeforeAck)]
    );
    assert!(
        b.violations[0]
            .message
            .contains("read at 0x21 started at cycle 1"),
        "{}",
        b.violations[0]
    );
}

/// Clean traffic raises nothing, for every master under the full matrix.
#[test]
fn wb_clean_traffic_is_silent() {
    for (label, mp, tp) in matrix() {
        let mut m = WishboneMaster::new("wb");
        m.set_pause(mp);
        let mut ram = WishboneRam::new("ram");
        ram.set_backpressure(tp);
        let mut b = Bench::new(m, ram, WishboneMonitor::new("wbmon", 8));
        let hs: Vec<_> = (0..20u8)
            .map(|i| {
                if i % 3 == 0 {
                    b.master.start_read(i)
                } else {
                    b.master.start_write(i, i)
                }
            })
            .collect();
        for h in hs {
            b.wait(h).unwrap();
        }
        b.steps(5);
        assert!(b.violations.is_empty(), "{label}: {:?}", b.violations);
    }
}

// ---- Avalon-MM ---------------------------------------------------------

fn av(read: bool, write: bool, address: u8, writedata: u8) -> AvMasterOut {
    AvMasterOut {
        address,
        chipselect: read || write,
        read,
        write,
        writedata,
        begintransfer: false,
        byteenable: 1,
    }
}

const AV_IDLE: AvMasterOut = AvMasterOut {
    address: 0,
    chipselect: false,
    read: false,
    write: false,
    writedata: 0,
    begintransfer: false,
    byteenable: 0,
};
const WAIT: AvSlaveOut = AvSlaveOut {
    readdata: 0,
    waitrequest: true,
    readdatavalid: false,
};
const GO: AvSlaveOut = AvSlaveOut {
    readdata: 0,
    waitrequest: false,
    readdatavalid: false,
};

fn feed_av(
    timing: AvalonTiming,
    begintransfer: bool,
    trace: &[(AvMasterOut, AvSlaveOut)],
) -> Vec<Violation> {
    let mut mon = AvalonMonitor::new(
        "avmon",
        AvalonMonitorConfig {
            timing,
            begintransfer,
            timeout_cycles: 100,
        },
    );
    trace
        .iter()
        .enumerate()
        .flat_map(|(k, (m, s))| mon.observe(k as u64, m, s))
        .collect()
}

#[test]
fn av_read_and_write_together() {
    let v = feed_av(
        AvalonTiming::Waitrequest,
        false,
        &[(AV_IDLE, GO), (av(true, true, 4, 0), GO), (AV_IDLE, WAIT)],
    );
    assert_eq!(rules(&v), vec![(1, Rule::ReadAndWrite)]);
}

#[test]
fn av_changed_or_withdrawn_while_waitrequest() {
    let v = feed_av(
        AvalonTiming::Waitrequest,
        false,
        &[
            (AV_IDLE, WAIT),
            (av(false, true, 4, 1), WAIT),
            (av(false, true, 4, 2), WAIT),
            (av(false, true, 5, 2), WAIT),
            (AV_IDLE, WAIT),
        ],
    );
    assert_eq!(
        rules(&v),
        vec![
            (2, Rule::ChangedWhileWaitrequest),
            (3, Rule::ChangedWhileWaitrequest),
            (4, Rule::WithdrawnWhileWaitrequest)
        ]
    );
    assert!(v[0].message.contains("writedata 0x01->0x02"), "{}", v[0]);
    assert!(v[1].message.contains("address 0x04->0x05"), "{}", v[1]);
    // Accepted (waitrequest low on the wires) then changed: legal.
    let v = feed_av(
        AvalonTiming::Waitrequest,
        false,
        &[
            (AV_IDLE, GO),
            (av(false, true, 4, 1), WAIT),
            (av(false, true, 5, 1), GO),
        ],
    );
    assert!(v.is_empty(), "{v:?}");
}

#[test]
fn av_fixed_wait_states_request_too_short() {
    let timing = AvalonTiming::FixedWaitStates { read: 2, write: 0 };
    let r = av(true, false, 9, 0);
    let v = feed_av(
        timing,
        false,
        &[
            (r, GO),
            (r, GO),
            (AV_IDLE, GO),
            (r, GO),
            (r, GO),
            (r, GO),
            (AV_IDLE, GO),
        ],
    );
    assert_eq!(rules(&v), vec![(2, Rule::WithdrawnWhileWaitrequest)]);
    assert!(v[0].message.contains("fixed wait states"), "{}", v[0]);
}

#[test]
fn av_readdatavalid_without_read() {
    let timing = AvalonTiming::Pipelined;
    let mut b = Bench::new(
        AvalonMaster::new(
            "av",
            AvalonMasterConfig {
                timing,
                ..Default::default()
            },
        ),
        SpuriousReaddatavalid::new(AvalonRam::new("ram", timing), 4),
        AvalonMonitor::new(
            "avmon",
            AvalonMonitorConfig {
                timing,
                begintransfer: false,
                timeout_cycles: 100,
            },
        ),
    );
    b.steps(9);
    assert_eq!(
        rules(&b.violations),
        vec![
            (4, Rule::ReaddatavalidWithoutRead),
            (8, Rule::ReaddatavalidWithoutRead)
        ]
    );
}

#[test]
fn av_waitrequest_stuck() {
    let timing = AvalonTiming::Waitrequest;
    let mut b = Bench::new(
        AvalonMaster::new(
            "av",
            AvalonMasterConfig {
                timing,
                timeout_cycles: 30,
                ..Default::default()
            },
        ),
        StuckWaitrequest(AvalonRam::new("ram", timing)),
        AvalonMonitor::new(
            "avmon",
            AvalonMonitorConfig {
                timing,
                begintransfer: false,
                timeout_cycles: 10,
            },
        ),
    );
    let h = b.master.start_write(0x0C, 3);
    assert!(b.wait(h).is_err());
    b.steps(2);
    assert_eq!(
        rules(&b.violations),
        vec![
            (11, Rule::WaitrequestStuck),
            (31, Rule::WithdrawnWhileWaitrequest)
        ]
    );
}

#[test]
fn av_no_readdatavalid() {
    let timing = AvalonTiming::Pipelined;
    let mut m = AvalonMaster::new(
        "av",
        AvalonMasterConfig {
            timing,
            timeout_cycles: 50,
            ..Default::default()
        },
    );
    let mut ram = AvalonRam::new("ram", timing);
    let mut mon = AvalonMonitor::new(
        "avmon",
        AvalonMonitorConfig {
            timing,
            begintransfer: false,
            timeout_cycles: 10,
        },
    );
    let h = m.start_read(1);
    let mut v = Vec::new();
    for k in 0..60 {
        let o = m.outputs();
        let mut s = ram.cycle(&o);
        s.readdatavalid = false;
        m.on_edge(&s);
        v.extend(mon.observe(k, &o, &s));
    }
    assert!(m.poll(h).unwrap().is_err());
    // Read accepted at cycle 2 (waitrequest low on the wires); cycles 3..=13
    // are the 11 cycles without data that exceed the limit of 10.
    assert_eq!(rules(&v), vec![(13, Rule::NoReaddatavalid)]);
}

#[test]
fn av_begintransfer_checked() {
    let timing = AvalonTiming::Waitrequest;
    let r = av(true, false, 1, 0);
    let rb = AvMasterOut {
        begintransfer: true,
        ..r
    };
    // Slave outputs given at cycle k are on the wires at cycle k + 1.
    // Transfer 1 (cycles 1-3) keeps begintransfer in its second cycle;
    // transfer 2 (cycles 5-7) starts without it.
    let v = feed_av(
        timing,
        true,
        &[
            (AV_IDLE, WAIT),
            (rb, WAIT),
            (rb, GO),
            (r, WAIT),
            (AV_IDLE, WAIT),
            (r, WAIT),
            (r, GO),
            (r, WAIT),
            (AV_IDLE, WAIT),
        ],
    );
    assert_eq!(
        rules(&v),
        vec![
            (2, Rule::BegintransferMisplaced),
            (5, Rule::BegintransferMisplaced)
        ]
    );
    assert!(v[0].message.contains("outside the first cycle"), "{}", v[0]);
    assert!(v[1].message.contains("without begintransfer"), "{}", v[1]);
}

#[test]
fn av_clean_traffic_is_silent() {
    for timing in [
        AvalonTiming::FixedWaitStates { read: 1, write: 0 },
        AvalonTiming::Waitrequest,
        AvalonTiming::Pipelined,
    ] {
        for (label, mp, tp) in matrix() {
            let mut m = AvalonMaster::new(
                "av",
                AvalonMasterConfig {
                    timing,
                    begintransfer: true,
                    ..Default::default()
                },
            );
            m.set_pause(mp);
            let mut ram = AvalonRam::new("ram", timing);
            ram.set_backpressure(tp);
            let mut b = Bench::new(
                m,
                ram,
                AvalonMonitor::new(
                    "avmon",
                    AvalonMonitorConfig {
                        timing,
                        begintransfer: true,
                        timeout_cycles: 8,
                    },
                ),
            );
            let hs: Vec<_> = (0..20u8)
                .map(|i| {
                    if i % 3 == 0 {
                        b.master.start_read(i)
                    } else {
                        b.master.start_write(i, i)
                    }
                })
                .collect();
            for h in hs {
                b.wait(h).unwrap();
            }
            b.steps(5);
            assert!(
                b.violations.is_empty(),
                "{timing:?}, {label}: {:?}",
                b.violations
            );
        }
    }
}

// ---- PIO ----------------------------------------------------------------

/// What the Wishbone monitor says about PIO bit-banging, a fact the
/// diagnoser needs: even against a slave that holds `ack` until `stb`
/// falls, the registered `ack` outlives the control word by one cycle, so
/// each access ends with one "ack without request" right after `ctl=0x00`.
#[test]
fn pio_against_level_ack_slave_leaves_one_late_ack_per_access() {
    let mut b = Bench::new(
        bfm::PioMaster::new("pio", bfm::PioTiming::default()),
        WishboneRam::new("ram").with_ack_mode(bfm::AckMode::Level),
        WishboneMonitor::new("wbmon", 100),
    );
    let w = b.master.start_write(1, 2);
    let w = b.wait(w).unwrap();
    let r = b.master.start_read(1);
    let r = b.wait(r).unwrap();
    b.steps(5);
    assert_eq!(r.data, 2);
    // The write is activated at edge 0 and ends at edge 20: pins idle from
    // cycle 21, where the last ack is still on the wires. The read is queued
    // then, activated at edge 21 and ends 22 edges later.
    let end_w = w.cycles + 1;
    let end_r = end_w + 1 + r.cycles;
    assert_eq!(
        rules(&b.violations),
        vec![
            (end_w, Rule::AckWithoutRequest),
            (end_r, Rule::AckWithoutRequest)
        ]
    );
}

/// A request the slave has already latched (the bench knows when its core
/// does, from the core's profile) and the master then drops before the
/// ack is no abandoned transfer; the same drop before the latch point is.
#[test]
fn drop_after_the_latch_point_is_not_abandoned() {
    let req = wb(true, true, true, 0x10, 0x5A);
    let run = |latched_at: Option<u64>| {
        let mut m = WishboneMonitor::new("mon", 100);
        let mut all = Vec::new();
        for cycle in 0..6u64 {
            m.set_latched(latched_at.is_some_and(|l| cycle >= l));
            let pins = if cycle < 4 { req } else { IDLE };
            all.extend(m.observe(cycle, &pins, &NO_ACK));
        }
        rules(&all)
    };
    assert_eq!(run(None), vec![(4, Rule::CycDroppedBeforeAck)], "never latched: abandoned");
    assert_eq!(run(Some(5)), vec![(4, Rule::CycDroppedBeforeAck)], "latched only after the drop: abandoned");
    assert_eq!(run(Some(2)), vec![], "latched at cycle 2, dropped at 4: the slave has it");
}
