//! Register access rules and reset values, both views, both modes
//! (data sheet Tables 1, 2, 5 and 6, through the `regmap` tables).

use crate::common;
use common::*;

use regmap::{Access, Mode, OpMode, Target, basic, peli};
use sja1000::host::{self, Config};
use sja1000::{RegError, Sja1000, WriteOutcome};

// ---------------------------------------------------------------------------
// Reset values

/// Every single-byte register reads its hardware reset value (the bits the
/// data sheet defines), in the view it belongs to, right after power-up.
#[test]
fn hardware_reset_values_from_the_map() {
    for mode in Mode::ALL {
        let n = if mode == Mode::PeliCan {
            pelican_reset()
        } else {
            basic_reset()
        };
        for r in regmap::registers(mode) {
            if r.len != 1 || r.reset_hw.defined == 0 {
                continue;
            }
            let Some(v) = regmap::lookup(mode, OpMode::Reset, Access::Read, r.addr) else {
                continue;
            };
            if !matches!(v.target, Target::Register(x) if std::ptr::eq(x, *r)) {
                continue;
            }
            let got = n.peek(r.addr);
            let want = r.reset_hw.value;
            // CDR: we switched to PeliCAN to see this view.
            let defined = if r.name == "CDR" {
                r.reset_hw.defined & 0x7F
            } else {
                r.reset_hw.defined
            };
            assert_eq!(
                got & defined,
                want & defined,
                "{mode} {} reads {got:#04x}, reset {}",
                r.name,
                r.reset_hw.notation()
            );
        }
    }
}

/// The data sheet's numbers, spelled out (so a wrong map fails too).
#[test]
fn hardware_reset_values_spelled_out() {
    let mut b = basic_reset();
    assert_eq!(b.read(basic::CR), 0x21, "CR: RR = 1, CR.5 reads 1");
    assert_eq!(b.read(basic::CMR), 0xFF);
    assert_eq!(b.read(basic::SR), 0x0C, "SR: TBS = TCS = 1");
    assert_eq!(b.read(basic::IR), 0xE0, "IR.7..5 read 1");
    assert_eq!(b.read(basic::CDR), 0x00);
    let mut p = pelican_reset();
    assert_eq!(p.read(peli::MOD), 0x01);
    assert_eq!(p.read(peli::CMR), 0x00);
    assert_eq!(
        p.read(peli::SR),
        0x3C,
        "SR: TS = RS = 1 (waiting for bus-free), TBS = TCS = 1"
    );
    assert_eq!(p.read(peli::IR), 0x00);
    assert_eq!(p.read(peli::EWLR), 96);
    assert_eq!(p.read(peli::ALC), 0);
    assert_eq!(p.read(peli::ECC), 0);
    assert_eq!(p.read(peli::RXERR), 0);
    assert_eq!(p.read(peli::TXERR), 0);
    assert_eq!(p.read(peli::RMC), 0);
    assert_eq!(p.read(peli::RBSA), 0);
    assert_eq!(p.read(peli::CDR), 0x80);
}

/// Entering reset mode by software sets the defined bits (MOD.RM = 1,
/// SM = 0, SR.TBS = 1, DOS = RBS = 0, IR.RI/TI/DOI/WUI = 0, RMC = 0) and
/// keeps the "x" ones (LOM/STM/AFM, IER, ACR/AMR, BTR, EWLR, RBSA).
#[test]
fn reset_mode_entry_keeps_x_bits() {
    let mut n = pelican_reset();
    n.write(
        peli::MOD,
        peli::r#mod::RM | peli::r#mod::AFM | peli::r#mod::LOM,
    );
    n.write(peli::IER, 0xA5);
    n.write(peli::EWLR, 77);
    n.write(peli::ACR0 + 2, 0x12);
    n.write(peli::AMR0 + 3, 0x34);
    n.write(peli::BTR0, 0x41);
    n.write(peli::RBSA, 10);
    host::leave_reset(&mut n);
    assert!(!n.in_reset_mode());
    host::enter_reset(&mut n);
    assert_eq!(
        n.read(peli::MOD),
        peli::r#mod::RM | peli::r#mod::AFM | peli::r#mod::LOM
    );
    assert_eq!(n.read(peli::IER), 0xA5);
    assert_eq!(n.read(peli::EWLR), 77);
    assert_eq!(n.read(peli::ACR0 + 2), 0x12);
    assert_eq!(n.read(peli::AMR0 + 3), 0x34);
    assert_eq!(n.read(peli::BTR0), 0x41);
    assert_eq!(n.read(peli::RBSA), 10);
    assert_eq!(n.read(peli::RMC), 0);
    let sr = n.read(peli::SR);
    assert_eq!(
        sr & (peli::sr::TBS | peli::sr::DOS | peli::sr::RBS),
        peli::sr::TBS
    );
}

// ---------------------------------------------------------------------------
// BasicCAN access rules

/// Operating mode: ACR, AMR, BTR0, BTR1, OCR read FFH and ignore writes.
#[test]
fn basic_configuration_registers_locked_in_operating_mode() {
    let mut n = basic_reset();
    let regs = [
        (basic::ACR, 0x11),
        (basic::AMR, 0x22),
        (basic::BTR0, 0x41),
        (basic::BTR1, 0x25),
        (basic::OCR, 0x1A),
    ];
    for (a, v) in regs {
        assert_eq!(n.write(a, v), WriteOutcome::Applied);
        assert_eq!(n.read(a), v);
    }
    host::leave_reset(&mut n);
    for (a, v) in regs {
        assert_eq!(n.read(a), 0xFF, "addr {a} reads FFH in operating mode");
        assert!(
            matches!(n.write(a, !v), WriteOutcome::IgnoredNotInResetMode { .. }),
            "addr {a}"
        );
    }
    host::enter_reset(&mut n);
    for (a, v) in regs {
        assert_eq!(n.read(a), v, "addr {a} kept its value");
    }
}

/// BasicCAN TX buffer (10..19): operating mode only; reads FFH in reset mode.
#[test]
fn basic_tx_buffer_operating_mode_only() {
    let mut n = basic_reset();
    assert_eq!(n.read(basic::TXID1), 0xFF);
    assert_eq!(
        n.write(basic::TXID1, 0x12),
        WriteOutcome::IgnoredInResetMode { reg: "TXID1" }
    );
    host::leave_reset(&mut n);
    for a in basic::TXID1..basic::TXID1 + 10 {
        assert_eq!(n.write(a, a * 3), WriteOutcome::Applied);
        assert_eq!(n.read(a), a * 3);
    }
}

/// CMR reads FFH in both modes; SR and IR are read only.
#[test]
fn basic_cmr_sr_ir() {
    let mut n = basic_reset();
    host::leave_reset(&mut n);
    assert_eq!(n.read(basic::CMR), 0xFF);
    assert_eq!(
        n.write(basic::SR, 0),
        WriteOutcome::IgnoredReadOnly { reg: "SR" }
    );
    assert_eq!(
        n.write(basic::IR, 0xFF),
        WriteOutcome::IgnoredReadOnly { reg: "IR" }
    );
    assert_eq!(n.read(basic::IR), 0xE0);
}

/// CR keeps the enables and CR.6 as written, reads CR.5 = 1 and CR.7 = 0.
#[test]
fn basic_cr_bits() {
    let mut n = basic_reset();
    n.write(basic::CR, 0xFF);
    assert_eq!(n.read(basic::CR), 0x7F);
    n.write(basic::CR, basic::cr::TIE);
    assert_eq!(n.read(basic::CR), 0x20 | basic::cr::TIE);
    assert!(!n.in_reset_mode());
}

/// Addresses 32 and up do not exist in BasicCAN; 128 and up not in PeliCAN.
#[test]
fn out_of_range_addresses_are_errors() {
    let mut b = basic_reset();
    assert_eq!(
        b.try_read(32),
        Err(RegError::OutOfRange {
            addr: 32,
            mode: Mode::BasicCan
        })
    );
    assert!(b.try_write(200, 1).is_err());
    assert_eq!(b.read(32), 0);
    let mut p = pelican_reset();
    assert!(p.try_read(127).is_ok());
    assert_eq!(
        p.try_read(128),
        Err(RegError::OutOfRange {
            addr: 128,
            mode: Mode::PeliCan
        })
    );
    assert_eq!(p.write(255, 1), WriteOutcome::IgnoredReserved);
}

// ---------------------------------------------------------------------------
// PeliCAN access rules

/// 16..23: ACR0..3/AMR0..3 in reset mode; RX window (read) and TX buffer
/// (write) in operating mode; 24..28 read 00H in reset mode.
#[test]
fn pelican_acceptance_registers_and_buffer_window() {
    let mut n = pelican_reset();
    for i in 0..8 {
        assert_eq!(n.write(peli::ACR0 + i, 0x10 + i), WriteOutcome::Applied);
    }
    for i in 0..8 {
        assert_eq!(n.read(peli::ACR0 + i), 0x10 + i);
    }
    for a in 24..=28 {
        assert_eq!(n.read(a), 0);
        assert_eq!(
            n.write(a, 1),
            WriteOutcome::IgnoredInResetMode { reg: "TXB" }
        );
    }
    host::leave_reset(&mut n);
    // Writes go to the TX buffer, visible at 96..108; 16.. reads the RX window.
    for i in 0..13 {
        assert_eq!(n.write(peli::TXFI + i, 0xA0 + i), WriteOutcome::Applied);
    }
    for i in 0..13 {
        assert_eq!(n.read(peli::TXBUF + i), 0xA0 + i);
    }
    host::enter_reset(&mut n);
    for i in 0..8 {
        assert_eq!(
            n.read(peli::ACR0 + i),
            0x10 + i,
            "filter survived operating-mode writes"
        );
    }
}

/// MOD.LOM/STM/AFM are written in reset mode only; the write reports the
/// bits it could not change ("configuration written outside reset mode").
#[test]
fn pelican_mod_configuration_bits_reset_mode_only() {
    let mut n = pelican_operating(0);
    let out = n.write(peli::MOD, peli::r#mod::AFM | peli::r#mod::LOM);
    assert_eq!(
        out,
        WriteOutcome::BitsIgnoredNotInResetMode {
            reg: "MOD",
            bits: peli::r#mod::LOM
        }
    );
    // Config::pelican() sets AFM; LOM stayed 0.
    assert_eq!(n.read(peli::MOD), peli::r#mod::AFM);
}

/// SM cannot be set in reset mode.
#[test]
fn pelican_sm_not_in_reset_mode() {
    let mut n = pelican_reset();
    let out = n.write(peli::MOD, peli::r#mod::RM | peli::r#mod::SM);
    assert_eq!(
        out,
        WriteOutcome::BitsIgnoredInResetMode {
            reg: "MOD",
            bits: peli::r#mod::SM
        }
    );
    assert_eq!(n.read(peli::MOD), peli::r#mod::RM);
}

/// BTR0/1, OCR, EWLR, RXERR, TXERR, RBSA: readable always, writable in reset mode only.
#[test]
fn pelican_reset_mode_only_registers() {
    let regs = [
        peli::BTR0,
        peli::BTR1,
        peli::OCR,
        peli::EWLR,
        peli::RXERR,
        peli::TXERR,
        peli::RBSA,
    ];
    let mut n = pelican_reset();
    for (k, &a) in regs.iter().enumerate() {
        let v = 0x21 + k as u8;
        assert_eq!(n.write(a, v), WriteOutcome::Applied, "addr {a}");
        assert_eq!(n.read(a), v, "addr {a}");
    }
    // Back to sane timing before going on the bus.
    n.write(peli::BTR0, 0x41);
    n.write(peli::BTR1, 0x25);
    n.write(peli::TXERR, 0);
    n.write(peli::RXERR, 0);
    host::leave_reset(&mut n);
    for &a in &regs {
        let before = n.read(a);
        assert!(
            matches!(
                n.write(a, before ^ 0x0F),
                WriteOutcome::IgnoredNotInResetMode { .. }
            ),
            "addr {a}"
        );
        assert_eq!(n.read(a), before, "addr {a}");
    }
}

/// Datasheet, TXERR register: a write of 255 in
/// reset mode shows only in TXERR; SR.BS/ES and the interrupts wait until
/// reset mode is left; then the bus-off happens as one by errors: MOD.RM
/// reads 1 again, TXERR 127, RXERR 0, SR.BS and SR.ES set, IR.EI (enabled)
/// set, no EPI.
#[test]
fn pelican_txerr_255_bus_off_waits_for_leaving_reset_mode() {
    let mut n = pelican_reset();
    n.write(peli::IER, peli::ier::EIE | peli::ier::EPIE);
    n.write(peli::RXERR, 40);
    assert_eq!(n.write(peli::TXERR, 255), WriteOutcome::Applied);
    assert_eq!(n.read(peli::TXERR), 255);
    assert_eq!(n.read(peli::RXERR), 40);
    assert_eq!(n.read(peli::SR) & (peli::sr::BS | peli::sr::ES), 0);
    assert_eq!(n.read(peli::IR), 0, "no interrupt in reset mode");
    assert!(!n.bus_off());
    n.write(peli::MOD, 0);
    assert_eq!(n.read(peli::MOD) & peli::r#mod::RM, peli::r#mod::RM);
    assert_eq!((n.read(peli::TXERR), n.read(peli::RXERR)), (127, 0));
    let sr = n.read(peli::SR);
    assert_eq!(sr & (peli::sr::BS | peli::sr::ES), peli::sr::BS | peli::sr::ES);
    assert_eq!(n.read(peli::IR) & (peli::ir::EI | peli::ir::EPI), peli::ir::EI);
    assert!(n.bus_off());
}

/// CDR.7 (CAN mode), CBP and RXINTEN are reset-mode only; CD and clock off are not.
#[test]
fn pelican_cdr_mode_bit_locked_in_operating_mode() {
    let mut n = pelican_operating(0);
    let out = n.write(peli::CDR, 0x05);
    assert_eq!(
        out,
        WriteOutcome::BitsIgnoredNotInResetMode {
            reg: "CDR",
            bits: peli::cdr::CANMODE
        }
    );
    assert_eq!(n.mode(), Mode::PeliCan);
    assert_eq!(n.read(peli::CDR), 0x85);
}

/// CMR reads 00H; ALC, ECC, RMC, SR, IR are read only; address 5 and 10 reserved.
#[test]
fn pelican_read_only_and_reserved() {
    let mut n = pelican_operating(0);
    assert_eq!(n.read(peli::CMR), 0);
    for (a, name) in [
        (peli::SR, "SR"),
        (peli::IR, "IR"),
        (peli::ALC, "ALC"),
        (peli::ECC, "ECC"),
        (peli::RMC, "RMC"),
    ] {
        assert_eq!(
            n.write(a, 0x55),
            WriteOutcome::IgnoredReadOnly { reg: name }
        );
    }
    assert_eq!(n.write(5, 1), WriteOutcome::IgnoredReserved);
    assert_eq!(n.read(5), 0);
    assert_eq!(n.read(10), 0);
    assert_eq!(n.read(120), 0);
}

/// The RX FIFO RAM (32..95) is readable in both modes and writable in reset mode.
#[test]
fn pelican_rx_fifo_ram_access() {
    let mut n = pelican_reset();
    for i in 0..64 {
        assert_eq!(n.write(peli::RXFIFO + i, i ^ 0x5A), WriteOutcome::Applied);
    }
    host::leave_reset(&mut n);
    for i in 0..64 {
        assert_eq!(n.read(peli::RXFIFO + i), i ^ 0x5A);
    }
    assert!(matches!(
        n.write(peli::RXFIFO, 0),
        WriteOutcome::IgnoredNotInResetMode { .. }
    ));
    // The receive window shows the RAM from RBSA (0) on.
    assert_eq!(n.read(peli::RXFI), 0x5A);
    assert_eq!(n.read(peli::RXFI + 12), 12 ^ 0x5A);
}

/// The window follows RBSA, wrapping at 64.
#[test]
fn pelican_window_follows_rbsa() {
    let mut n = pelican_reset();
    for i in 0..64 {
        n.write(peli::RXFIFO + i, i);
    }
    n.write(peli::RBSA, 60);
    host::leave_reset(&mut n);
    let w: Vec<u8> = (0..13).map(|i| n.read(peli::RXFI + i)).collect();
    assert_eq!(w, [60, 61, 62, 63, 0, 1, 2, 3, 4, 5, 6, 7, 8]);
}

// ---------------------------------------------------------------------------
// TX buffer lock and commands

/// After TR the TX buffer is locked (TBS = 0): writes report it.
#[test]
fn tx_buffer_locked_while_pending() {
    let mut n = pelican_operating(0);
    let f = std_frame(0x123, &[1, 2]);
    host::transmit(&mut n, &f, peli::cmr::TR).unwrap();
    assert_eq!(n.read(peli::SR) & peli::sr::TBS, 0);
    assert_eq!(
        n.write(peli::TXFI + 3, 9),
        WriteOutcome::IgnoredTxBufferLocked { reg: "TXB" }
    );
    assert_eq!(n.read(peli::TXBUF + 3), 1, "buffer unchanged");
    // A second TR is refused too.
    assert!(matches!(
        n.write(peli::CMR, peli::cmr::TR),
        WriteOutcome::CommandIgnored { command: "TR", .. }
    ));
}

/// TR in reset mode is ignored.
#[test]
fn tr_ignored_in_reset_mode() {
    let mut n = pelican_reset();
    assert_eq!(
        n.write(peli::CMR, peli::cmr::TR),
        WriteOutcome::CommandIgnored {
            command: "TR",
            reason: "reset mode"
        }
    );
    assert_eq!(n.read(peli::SR) & peli::sr::TBS, peli::sr::TBS);
}

/// The TX buffer layouts decode to the frame the host meant (PeliCAN SFF
/// and EFF, BasicCAN), including DLC > 8 and remote frames.
#[test]
fn tx_buffer_layouts() {
    let cases = [
        std_frame(0x7FF, &[1, 2, 3, 4, 5, 6, 7, 8]),
        ext_frame(0x1ABC_DEF0, &[0xAA]),
        can_proto::CanFrame::with_dlc(can_proto::CanFrame::std_id(0x001).unwrap(), true, 5, &[])
            .unwrap(),
        can_proto::CanFrame::with_dlc(can_proto::CanFrame::ext_id(7).unwrap(), false, 12, &[9; 8])
            .unwrap(),
    ];
    for f in cases {
        let mut n = pelican_operating(0);
        host::load_tx(&mut n, &f).unwrap();
        assert_eq!(n.tx_frame(), f);
    }
    let mut b = Sja1000::new();
    host::configure(&mut b, &Config::basic(0, 0xFF));
    let f = std_frame(0x529, &[0x51]);
    host::load_tx(&mut b, &f).unwrap();
    // The DE2 thesis frame: TX buffer 0xA5, 0x21, 0x51.
    assert_eq!((b.read(10), b.read(11), b.read(12)), (0xA5, 0x21, 0x51));
    assert_eq!(b.tx_frame(), f);
}
