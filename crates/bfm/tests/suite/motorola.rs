//! Motorola-mode multiplexed bus: the master against a RAM target (the
//! 8051 RAM behind the decoding `can_top_mcu` does: RD = E with R/W high,
//! WR = E with R/W low) under the monitor; each rule of its own shown to
//! fire, and clean traffic to pass.

use bfm::{
    HostBusTarget, HostMaster, I8051Polarity, I8051Ram, I8051SlaveOut, I8051Timing, MotorolaMaster,
    MotorolaMonitor, MotorolaOut, Rule, Violation,
};

/// Runs `n` cycles: master pins (through `tamper`) into the RAM (unless it
/// is `dead`), the monitor on the wires. Returns violations and the pins.
fn run(
    m: &mut MotorolaMaster,
    ram: &mut I8051Ram,
    mon: &mut MotorolaMonitor,
    n: u64,
    dead: bool,
    mut tamper: impl FnMut(u64, &mut MotorolaOut),
) -> (Vec<Violation>, Vec<MotorolaOut>) {
    let (mut v, mut seen) = (Vec::new(), Vec::new());
    for c in 0..n {
        let mut o = m.outputs();
        tamper(c, &mut o);
        let s = if dead { I8051SlaveOut::default() } else { ram.cycle(&o.intel_view()) };
        m.on_edge(&s);
        v.extend(mon.observe(c, &o, &s));
        seen.push(o);
    }
    (v, seen)
}

fn setup(t: I8051Timing) -> (MotorolaMaster, I8051Ram, MotorolaMonitor) {
    (MotorolaMaster::new("host", t, 1000), I8051Ram::new("ram", I8051Polarity::ACTIVE_HIGH, 2), MotorolaMonitor::new("mon", &t))
}

#[test]
fn a_write_then_a_read_back_with_rw_steady_around_e_and_no_violation() {
    let t = I8051Timing::default();
    let (mut m, mut ram, mut mon) = setup(t);
    let w = m.start_write(0x1F, 0xA5);
    let r = m.start_read(0x1F);
    let (v, seen) = run(&mut m, &mut ram, &mut mon, 300, false, |_, _| {});
    assert!(v.is_empty(), "{v:?}");
    assert_eq!(ram.mem()[0x1F], 0xA5);
    assert!(m.poll(w).unwrap().is_ok());
    assert_eq!(m.poll(r).unwrap().unwrap().data, 0xA5);
    // R/W is low for the write from AS to the end of its data hold (never
    // across E's edges), high for the read and when idle.
    let e_low_rw: Vec<bool> = seen.iter().filter(|o| o.e).map(|o| o.rw).collect();
    assert_eq!(e_low_rw.len() as u32, t.wr + t.rd);
    assert!(e_low_rw[..t.wr as usize].iter().all(|rw| !rw) && e_low_rw[t.wr as usize..].iter().all(|rw| *rw));
    let first_e = seen.iter().position(|o| o.e).unwrap();
    assert!(!seen[first_e - 1].rw, "R/W set before E rises");
    assert!(seen.last().unwrap().rw && !seen.last().unwrap().cs, "idle: R/W high, deselected");
}

#[test]
fn a_slave_that_never_answers_a_read_is_named_in_one_sentence() {
    let t = I8051Timing::default();
    let (mut m, mut ram, mut mon) = setup(t);
    let r = m.start_read(0x02);
    let (v, _) = run(&mut m, &mut ram, &mut mon, 120, true, |_, _| {});
    assert_eq!(m.poll(r).unwrap().unwrap().data, 0xFF, "pull-ups");
    let nr: Vec<&Violation> = v.iter().filter(|x| x.rule == Rule::NoReadData).collect();
    assert_eq!(nr.len(), 1, "{v:?}");
    assert_eq!(
        nr[0].message,
        format!("read of register 0x02: E high for {} host cycles and the slave never drove AD (the master read the pull-ups, 0xFF)", t.rd)
    );
}

#[test]
fn rw_changing_while_e_is_high_and_a_short_e_are_caught() {
    let t = I8051Timing::default();
    let (mut m, mut ram, mut mon) = setup(t);
    m.start_write(0x04, 0x11);
    let mut e_cycles = 0;
    // R/W flips to read for one cycle in the middle of the write's E.
    let (v, _) = run(&mut m, &mut ram, &mut mon, 100, false, |_, o| {
        if o.e {
            e_cycles += 1;
            if e_cycles == 5 {
                o.rw = true;
            }
        }
    });
    assert!(v.iter().any(|x| x.message == "R/W changed to read (high) while E was high"), "{v:?}");
    assert!(v.iter().any(|x| x.rule == Rule::StrobeTooShort), "the write's E cut in two: {v:?}");
    // A master with a shorter E than the monitor's minimum.
    let short = I8051Timing { rd: t.rd - 1, ..t };
    let (mut m, mut ram, _) = setup(short);
    let mut mon = MotorolaMonitor::new("mon", &t);
    m.start_read(0x04);
    let (v, _) = run(&mut m, &mut ram, &mut mon, 100, false, |_, _| {});
    assert!(v.iter().any(|x| x.rule == Rule::StrobeTooShort && x.message.contains(&format!("E (read) asserted {} cycles (minimum {})", t.rd - 1, t.rd))), "{v:?}");
}
