//! Interrupt sources, IR read-to-clear, enables (IER / CR), CLKOUT, sleep.
//! Sources that need bus traffic are in `tests/bus.rs`.

use crate::common;
use common::*;

use regmap::{basic, peli};
use sja1000::host::{self, Config};
use sja1000::{Sja1000, WriteOutcome};

/// AT before the transmission starts releases the buffer: TBS 0 -> 1 sets
/// TI (enabled), TCS stays 0; reading IR clears TI.
#[test]
fn ti_on_abort_and_read_to_clear() {
    let mut n = pelican_operating(peli::ier::TIE);
    host::transmit(&mut n, &std_frame(0x10, &[]), peli::cmr::TR).unwrap();
    assert!(!n.irq());
    n.write(peli::CMR, peli::cmr::AT);
    let sr = n.read(peli::SR);
    assert_eq!(sr & (peli::sr::TBS | peli::sr::TCS), peli::sr::TBS);
    assert!(n.irq(), "irq_on low");
    assert_eq!(n.peek(peli::IR), peli::ir::TI, "peek has no side effect");
    assert_eq!(n.read(peli::IR), peli::ir::TI);
    assert_eq!(n.read(peli::IR), 0, "read cleared TI");
    assert!(!n.irq());
}

/// With TIE = 0 the same release raises nothing.
#[test]
fn ti_needs_its_enable() {
    let mut n = pelican_operating(0);
    host::transmit(&mut n, &std_frame(0x10, &[]), peli::cmr::TR).unwrap();
    n.write(peli::CMR, peli::cmr::AT);
    assert_eq!(n.read(peli::IR), 0);
    assert!(!n.irq());
}

/// BasicCAN: the CR.TIE enable; IR reads E0H | TI.
#[test]
fn basic_ti_uses_cr_enable() {
    let mut n = Sja1000::new();
    host::configure(
        &mut n,
        &Config {
            interrupts: basic::cr::TIE,
            ..Config::basic(0, 0xFF)
        },
    );
    host::transmit(&mut n, &std_frame(0x10, &[]), basic::cmr::TR).unwrap();
    n.write(basic::CMR, basic::cmr::AT);
    assert_eq!(n.read(basic::IR), 0xE0 | basic::ir::TI);
    assert_eq!(n.read(basic::IR), 0xE0);
}

/// Entering reset mode clears TI (reset value 0) and releases the buffer.
#[test]
fn reset_mode_clears_ti() {
    let mut n = pelican_operating(peli::ier::TIE);
    host::transmit(&mut n, &std_frame(0x10, &[]), peli::cmr::TR).unwrap();
    n.write(peli::CMR, peli::cmr::AT);
    assert!(n.irq());
    host::enter_reset(&mut n);
    assert!(!n.irq());
    assert_eq!(n.read(peli::SR) & peli::sr::TBS, peli::sr::TBS);
}

/// Runs `n` with the bus recessive until it has seen bus-free (11
/// recessive bits) after reset mode: only then can sleep be set (CMR.4 note 1).
fn integrate(n: &mut Sja1000) {
    for _ in 0..12 * n.engine().timing().clocks_per_bit() {
        n.clock(true);
    }
}

/// Sleep is refused while an interrupt is pending (data sheet MOD.4).
#[test]
fn sleep_refused_with_interrupt_pending() {
    let mut n = pelican_operating(peli::ier::TIE);
    integrate(&mut n);
    host::transmit(&mut n, &std_frame(0x10, &[]), peli::cmr::TR).unwrap();
    n.write(peli::CMR, peli::cmr::AT);
    let out = n.write(peli::MOD, peli::r#mod::SM | peli::r#mod::AFM);
    assert!(
        matches!(out, WriteOutcome::CommandIgnored { command: "SM", .. }),
        "{out:?}"
    );
    assert!(!n.is_sleeping());
    n.read(peli::IR);
    assert_eq!(
        n.write(peli::MOD, peli::r#mod::SM | peli::r#mod::AFM),
        WriteOutcome::Applied
    );
    assert!(n.is_sleeping());
    assert_eq!(n.read(peli::MOD) & peli::r#mod::SM, peli::r#mod::SM);
    // The host wakes it by clearing SM.
    n.write(peli::MOD, peli::r#mod::AFM);
    assert!(!n.is_sleeping());
}

/// BasicCAN sleep is CMR.GTS; a CMR write with GTS = 0 wakes it.
#[test]
fn basic_gts_sleep_and_wake() {
    let mut n = Sja1000::new();
    host::configure(&mut n, &Config::basic(0, 0xFF));
    // before bus-free is seen after reset mode, GTS is refused (CMR.4 note 1)
    assert!(matches!(n.write(basic::CMR, basic::cmr::GTS), WriteOutcome::CommandIgnored { command: "GTS", .. }));
    assert!(!n.is_sleeping());
    integrate(&mut n);
    n.read(basic::IR); // the refusal's WUI
    n.write(basic::CMR, basic::cmr::GTS);
    assert!(n.is_sleeping());
    n.write(basic::CMR, 0);
    assert!(!n.is_sleeping());
}

// ---------------------------------------------------------------------------
// CLKOUT

fn clkout_period(n: &mut Sja1000, clocks: usize) -> Option<usize> {
    let mut edges = vec![];
    let mut last = n.clkout();
    for t in 0..clocks {
        n.clock(true);
        let c = n.clkout();
        if c && !last {
            edges.push(t);
        }
        last = c;
    }
    if edges.len() < 3 {
        return None;
    }
    let p = edges[1] - edges[0];
    assert!(edges.windows(2).all(|w| w[1] - w[0] == p), "steady period");
    Some(p)
}

/// CDR.2..0 divides fosc by 2, 4, ... 14 (data sheet Table 47); CDR.3
/// (clock off) stops CLKOUT.
#[test]
fn clkout_divider_and_clock_off() {
    for cd in 0..7u8 {
        let mut n = pelican_reset();
        n.write(peli::CDR, peli::cdr::CANMODE | cd);
        assert_eq!(
            clkout_period(&mut n, 200),
            Some(2 * (cd as usize + 1)),
            "CD = {cd}"
        );
    }
    let mut n = pelican_reset();
    n.write(peli::CDR, peli::cdr::CANMODE | peli::cdr::CLKOFF);
    assert_eq!(clkout_period(&mut n, 200), None);
    assert!(n.clkout());
}

/// `reset(ResetMode)` does what MOD.RM does; `reset(Hardware)` restores
/// the power-on values (BasicCAN, EWLR 96, IER 0 here).
#[test]
fn reset_kinds() {
    use sja1000::ResetKind;
    let mut n = pelican_operating(peli::ier::TIE);
    n.reset(ResetKind::ResetMode);
    assert!(n.in_reset_mode());
    assert_eq!(
        n.read(peli::IER),
        peli::ier::TIE,
        "IER kept on reset-mode entry"
    );
    n.write(peli::EWLR, 5);
    n.reset(ResetKind::Hardware);
    assert_eq!(n.mode(), regmap::Mode::BasicCan);
    n.write(peli::CDR, peli::cdr::CANMODE);
    assert_eq!(n.read(peli::EWLR), 96);
    // The outcome explains itself in plain words.
    let msg = WriteOutcome::IgnoredTxBufferLocked { reg: "TXB" }.to_string();
    assert!(msg.contains("locked") && msg.contains("TBS = 0"), "{msg}");
}
