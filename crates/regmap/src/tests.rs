//! Table consistency and data sheet fact checks.
use super::*;
use std::collections::HashSet;

// ---- structure of the tables ------------------------------------------------

#[test]
fn address_table_covers_every_address_exactly_once() {
    for mode in Mode::ALL {
        let mut next: u16 = 0;
        for row in address_table(mode) {
            assert_eq!(row.first as u16, next, "{mode}: gap or overlap at {next}");
            assert!(row.last >= row.first, "{mode}: row {}..{} reversed", row.first, row.last);
            next = row.last as u16 + 1;
        }
        assert_eq!(next, mode.addr_limit(), "{mode}: table does not end at the limit");
    }
}

#[test]
fn views_point_inside_their_register_and_every_register_is_reachable() {
    for mode in Mode::ALL {
        let mut reached: HashSet<&str> = HashSet::new();
        for row in address_table(mode) {
            for op in OpMode::ALL {
                for acc in Access::ALL {
                    let v = row.view(op, acc);
                    if let Some(r) = v.register() {
                        assert_eq!(r.mode, mode, "{mode}: view reaches a {} register", r.mode);
                        assert!(
                            r.contains(row.first) && r.contains(row.last),
                            "{mode} {}..{} {op} {acc:?} reaches {} outside {}..{}",
                            row.first, row.last, r.name, r.addr, r.addr as u16 + r.len as u16
                        );
                        reached.insert(r.name);
                    }
                    match (acc, v.target) {
                        (Access::Write, Target::Constant(_)) => panic!("{mode} {}: a write cannot return a constant", row.first),
                        (Access::Read, Target::Nothing) => panic!("{mode} {}: a read must return something", row.first),
                        (Access::Read, Target::Register(_)) => assert_eq!(v.write_mask, 0xFF),
                        _ => {}
                    }
                }
            }
        }
        // Every byte of every register is reached by some view.
        for r in registers(mode) {
            assert!(reached.contains(r.name), "{mode}: {} is unreachable", r.name);
            for a in r.addr..r.addr + r.len {
                let hit = OpMode::ALL.iter().any(|&op| {
                    Access::ALL.iter().any(|&acc| {
                        lookup(mode, op, acc, a).and_then(RegisterView::register).is_some_and(|x| std::ptr::eq(x, *r))
                    })
                });
                assert!(hit, "{mode}: byte {a} of {} is unreachable", r.name);
            }
        }
    }
}

#[test]
fn registers_are_sorted_named_once_and_fields_fit() {
    for mode in Mode::ALL {
        let regs = registers(mode);
        let mut names = HashSet::new();
        for w in regs.windows(2) {
            assert!(w[0].addr <= w[1].addr, "{mode}: {} after {}", w[1].name, w[0].name);
        }
        for r in regs {
            assert!(names.insert(r.name), "{mode}: {} twice", r.name);
            assert!(r.len >= 1);
            assert!((r.addr as u16 + r.len as u16) <= mode.addr_limit());
            let mut used = 0u8;
            let mut fnames = HashSet::new();
            for f in r.fields {
                assert!(f.width >= 1 && f.lsb + f.width <= 8, "{}.{} does not fit", r.name, f.name);
                assert_eq!(used & f.mask(), 0, "{}.{} overlaps", r.name, f.name);
                used |= f.mask();
                assert!(fnames.insert(f.name), "{}.{} twice", r.name, f.name);
                assert!(!f.meaning.is_empty());
            }
            if !r.fields.is_empty() {
                assert_eq!(r.len, 1, "{}: fields on a multi-byte window", r.name);
            }
        }
    }
}

// ---- typed constants agree with the table ----------------------------------

/// Pairs each generated constant with its table entry by name, for every
/// register and field of both views: the typed constants and the tables come
/// from one macro invocation, and this proves the expansion wires them up.
#[test]
fn typed_constants_match_the_table() {
    macro_rules! check_regs {
        ($m:ident, $mode:expr, [$($r:ident),*]) => {$(
            let r = register($mode, stringify!($r)).unwrap();
            assert_eq!($m::$r, r.addr, "{}", stringify!($r));
            assert_eq!($m::len::$r, r.len, "{}", stringify!($r));
        )*};
    }
    macro_rules! check_fields {
        ($m:ident, $mode:expr, $r:ident / $l:ident, [$($f:ident),*]) => {
            let r = register($mode, stringify!($r)).unwrap();
            assert_eq!(r.fields.len(), [$(stringify!($f)),*].len(), "{}: field count", stringify!($r));
            $(
                let f = r.field(stringify!($f)).unwrap();
                assert_eq!($m::$l::$f, f.mask(), "{}.{}", stringify!($r), stringify!($f));
                assert_eq!($m::$l::lsb::$f, f.lsb, "{}.{}", stringify!($r), stringify!($f));
            )*
        };
    }
    use Mode::*;
    check_regs!(peli, PeliCan, [MOD, CMR, SR, IR, IER, BTR0, BTR1, OCR, TEST, ALC, ECC, EWLR, RXERR, TXERR,
        RXFI, TXFI, RXB, TXB, ACR0, ACR1, ACR2, ACR3, AMR0, AMR1, AMR2, AMR3, RMC, RBSA, CDR, RXFIFO, TXBUF, RAMFREE]);
    assert_eq!(registers(PeliCan).len(), 32);
    check_regs!(basic, BasicCan, [CR, CMR, SR, IR, ACR, AMR, BTR0, BTR1, OCR, TEST, TXID1, TXID2, TXDATA,
        RXID1, RXID2, RXDATA, CDR]);
    assert_eq!(registers(BasicCan).len(), 17);
    check_fields!(peli, PeliCan, MOD / r#mod, [RM, LOM, STM, AFM, SM]);
    check_fields!(peli, PeliCan, CMR / cmr, [TR, AT, RRB, CDO, SRR]);
    check_fields!(peli, PeliCan, SR / sr, [RBS, DOS, TBS, TCS, RS, TS, ES, BS]);
    check_fields!(peli, PeliCan, IR / ir, [RI, TI, EI, DOI, WUI, EPI, ALI, BEI]);
    check_fields!(peli, PeliCan, IER / ier, [RIE, TIE, EIE, DOIE, WUIE, EPIE, ALIE, BEIE]);
    check_fields!(peli, PeliCan, BTR0 / btr0, [BRP, SJW]);
    check_fields!(peli, PeliCan, BTR1 / btr1, [TSEG1, TSEG2, SAM]);
    check_fields!(peli, PeliCan, OCR / ocr, [OCMODE, OCPOL0, OCTN0, OCTP0, OCPOL1, OCTN1, OCTP1]);
    check_fields!(peli, PeliCan, ALC / alc, [BITNO]);
    check_fields!(peli, PeliCan, ECC / ecc, [SEG, DIR, ERRC]);
    check_fields!(peli, PeliCan, RXFI / rxfi, [DLC, RTR, FF]);
    check_fields!(peli, PeliCan, TXFI / txfi, [DLC, RTR, FF]);
    check_fields!(peli, PeliCan, RMC / rmc, [RMC]);
    check_fields!(peli, PeliCan, RBSA / rbsa, [RBSA]);
    check_fields!(peli, PeliCan, CDR / cdr, [CD, CLKOFF, RXINTEN, CBP, CANMODE]);
    check_fields!(basic, BasicCan, CR / cr, [RR, RIE, TIE, EIE, OIE]);
    check_fields!(basic, BasicCan, CMR / cmr, [TR, AT, RRB, CDO, GTS]);
    check_fields!(basic, BasicCan, SR / sr, [RBS, DOS, TBS, TCS, RS, TS, ES, BS]);
    check_fields!(basic, BasicCan, IR / ir, [RI, TI, EI, DOI, WUI]);
    check_fields!(basic, BasicCan, BTR0 / btr0, [BRP, SJW]);
    check_fields!(basic, BasicCan, BTR1 / btr1, [TSEG1, TSEG2, SAM]);
    check_fields!(basic, BasicCan, OCR / ocr, [OCMODE, OCPOL0, OCTN0, OCTP0, OCPOL1, OCTN1, OCTP1]);
    check_fields!(basic, BasicCan, TXID1 / txid1, [ID]);
    check_fields!(basic, BasicCan, TXID2 / txid2, [DLC, RTR, ID]);
    check_fields!(basic, BasicCan, RXID2 / rxid2, [DLC, RTR, ID]);
    check_fields!(basic, BasicCan, CDR / cdr, [CD, CLKOFF, RXINTEN, CBP, CANMODE]);
}

// ---- data sheet facts (typed in from the data sheet, independently of the table) ----

#[test]
fn peli_addresses_match_the_data_sheet() {
    let expect: &[(&str, u8)] = &[
        ("MOD", 0), ("CMR", 1), ("SR", 2), ("IR", 3), ("IER", 4), ("BTR0", 6), ("BTR1", 7), ("OCR", 8),
        ("TEST", 9), ("ALC", 11), ("ECC", 12), ("EWLR", 13), ("RXERR", 14), ("TXERR", 15), ("ACR0", 16),
        ("ACR3", 19), ("AMR0", 20), ("AMR3", 23), ("RMC", 29), ("RBSA", 30), ("CDR", 31), ("RXFIFO", 32),
        ("TXBUF", 96),
    ];
    for &(name, addr) in expect {
        assert_eq!(register(Mode::PeliCan, name).unwrap().addr, addr, "{name}");
    }
}

#[test]
fn basic_addresses_match_the_data_sheet() {
    let expect: &[(&str, u8)] = &[
        ("CR", 0), ("CMR", 1), ("SR", 2), ("IR", 3), ("ACR", 4), ("AMR", 5), ("BTR0", 6), ("BTR1", 7),
        ("OCR", 8), ("TEST", 9), ("TXID1", 10), ("TXID2", 11), ("TXDATA", 12), ("RXID1", 20), ("RXID2", 21),
        ("RXDATA", 22), ("CDR", 31),
    ];
    for &(name, addr) in expect {
        assert_eq!(register(Mode::BasicCan, name).unwrap().addr, addr, "{name}");
    }
}

#[test]
fn bit_masks_match_the_data_sheet() {
    assert_eq!(peli::sr::TBS, 0x04);
    assert_eq!(peli::sr::BS, 0x80);
    assert_eq!(peli::ir::BEI, 0x80);
    assert_eq!(peli::ir::ALI, 0x40);
    assert_eq!(peli::cmr::SRR, 0x10);
    assert_eq!(basic::cmr::GTS, 0x10);
    assert_eq!(peli::r#mod::SM, 0x10);
    assert_eq!(peli::btr0::SJW, 0xC0);
    assert_eq!(peli::btr0::BRP, 0x3F);
    assert_eq!(peli::btr1::TSEG2, 0x70);
    assert_eq!(peli::ecc::ERRC, 0xC0);
    assert_eq!(peli::ecc::DIR, 0x20);
    assert_eq!(peli::rxfi::FF, 0x80);
    assert_eq!(peli::rxfi::RTR, 0x40);
    assert_eq!(basic::txid2::RTR, 0x10);
    assert_eq!(basic::txid2::ID, 0xE0);
    assert_eq!(peli::cdr::CANMODE, 0x80);
    assert_eq!(peli::cdr::CLKOFF, 0x08);
    assert_eq!(basic::cr::OIE, 0x10);
}

#[test]
fn reset_values_match_the_data_sheet() {
    let hw = |m, n| register(m, n).unwrap().reset_hw.apply(0);
    // PeliCAN Table 6.
    assert_eq!(hw(Mode::PeliCan, "MOD"), 0x01);
    assert_eq!(hw(Mode::PeliCan, "SR"), 0x3C);
    assert_eq!(hw(Mode::PeliCan, "IR"), 0x00);
    assert_eq!(hw(Mode::PeliCan, "EWLR"), 96);
    assert_eq!(hw(Mode::PeliCan, "RMC"), 0);
    assert_eq!(hw(Mode::PeliCan, "CDR"), 0);
    // BasicCAN Table 2.
    assert_eq!(register(Mode::BasicCan, "CR").unwrap().reset_hw.apply(0), 0x21);
    assert_eq!(register(Mode::BasicCan, "CR").unwrap().reset_hw.apply(0xFF), 0x7F);
    assert_eq!(hw(Mode::BasicCan, "SR"), 0x0C);
    assert_eq!(hw(Mode::BasicCan, "IR"), 0xE0);
    // Entering reset mode keeps the "x" bits: SR.BS/ES/TCS, MOD.LOM/STM/AFM.
    let sr = register(Mode::PeliCan, "SR").unwrap();
    assert_eq!(sr.reset_rm.apply(0xC8), 0xFC);
    assert_eq!(sr.reset_rm.apply(0x0B), 0x3C); // TCS kept, DOS and RBS cleared
    let m = register(Mode::PeliCan, "MOD").unwrap();
    assert_eq!(m.reset_rm.apply(0x1E), 0x0F);
}

#[test]
fn reset_notation_round_trips() {
    for s in ["0x1xxxx1", "00111100", "xxxxxxxx", "01100000"] {
        assert_eq!(ResetValue::parse(s).notation(), s);
    }
    let r = ResetValue::parse("0x1x_xxx1");
    assert_eq!(r.defined, 0xA1);
    assert_eq!(r.value, 0x21);
}

// ---- what an access means ----------------------------------------------------

#[test]
fn peli_address_16_has_three_meanings() {
    use Access::*;
    use OpMode::*;
    let name = |op, acc| lookup(Mode::PeliCan, op, acc, 16).unwrap().register().unwrap().name;
    assert_eq!(name(Operating, Read), "RXFI");
    assert_eq!(name(Operating, Write), "TXFI");
    assert_eq!(name(Reset, Read), "ACR0");
    assert_eq!(name(Reset, Write), "ACR0");
    assert_eq!(lookup(Mode::PeliCan, Reset, Read, 24).unwrap().constant(), Some(0x00));
    let v = lookup(Mode::PeliCan, Operating, Read, 28).unwrap();
    assert_eq!(v.register().unwrap().name, "RXB");
    assert_eq!(v.index(28), Some(11));
    assert_eq!(v.index(16), None);
}

#[test]
fn basic_configuration_reads_ff_in_operating_mode() {
    for a in [basic::ACR, basic::AMR, basic::BTR0, basic::BTR1, basic::OCR] {
        let v = lookup(Mode::BasicCan, OpMode::Operating, Access::Read, a).unwrap();
        assert_eq!(v.constant(), Some(0xFF), "address {a}");
        let w = lookup(Mode::BasicCan, OpMode::Operating, Access::Write, a).unwrap();
        assert_eq!(w.target, Target::Nothing, "address {a}");
        let r = lookup(Mode::BasicCan, OpMode::Reset, Access::Read, a).unwrap();
        assert_eq!(r.register().unwrap().addr, a);
        assert!(r.register().unwrap().reset_mode_only_write());
    }
    // PeliCAN keeps them readable.
    let v = lookup(Mode::PeliCan, OpMode::Operating, Access::Read, peli::BTR0).unwrap();
    assert_eq!(v.register().unwrap().name, "BTR0");
}

#[test]
fn command_register_reads_constant() {
    for op in OpMode::ALL {
        assert_eq!(lookup(Mode::BasicCan, op, Access::Read, 1).unwrap().constant(), Some(0xFF));
        assert_eq!(lookup(Mode::PeliCan, op, Access::Read, 1).unwrap().constant(), Some(0x00));
        assert_eq!(lookup(Mode::PeliCan, op, Access::Write, 1).unwrap().register().unwrap().name, "CMR");
    }
}

#[test]
fn basic_tx_buffer_is_operating_mode_only() {
    let v = lookup(Mode::BasicCan, OpMode::Reset, Access::Read, basic::TXID1).unwrap();
    assert_eq!(v.constant(), Some(0xFF));
    let v = lookup(Mode::BasicCan, OpMode::Operating, Access::Write, 19).unwrap();
    assert_eq!(v.register().unwrap().name, "TXDATA");
}

#[test]
fn write_masks_follow_the_access_rules() {
    let wm = |m, op, a| lookup(m, op, Access::Write, a).unwrap().write_mask;
    assert_eq!(wm(Mode::PeliCan, OpMode::Operating, peli::MOD), peli::r#mod::RM | peli::r#mod::SM);
    assert_eq!(wm(Mode::PeliCan, OpMode::Reset, peli::MOD) & peli::r#mod::SM, 0);
    assert_eq!(wm(Mode::PeliCan, OpMode::Operating, peli::CDR) & peli::cdr::CANMODE, 0);
    assert_ne!(wm(Mode::PeliCan, OpMode::Reset, peli::CDR) & peli::cdr::CANMODE, 0);
    assert!(register(Mode::PeliCan, "BTR0").unwrap().reset_mode_only_write());
    assert!(register(Mode::PeliCan, "ACR0").unwrap().reset_mode_only_write());
    assert!(!register(Mode::PeliCan, "IER").unwrap().reset_mode_only_write());
    assert!(!register(Mode::PeliCan, "SR").unwrap().reset_mode_only_write());
}

#[test]
fn out_of_range_is_a_clear_error() {
    assert!(lookup(Mode::BasicCan, OpMode::Operating, Access::Read, 32).is_none());
    assert!(lookup(Mode::PeliCan, OpMode::Operating, Access::Read, 127).is_some());
    let e = decode(Mode::PeliCan, OpMode::Reset, Access::Write, 200).unwrap_err();
    assert_eq!(e, RegError::OutOfRange { addr: 200, mode: Mode::PeliCan });
    assert!(e.to_string().contains("0xC8"), "{e}");
    let e = register(Mode::BasicCan, "IER").unwrap_err();
    assert!(matches!(e, RegError::UnknownRegister { .. }), "{e}");
    let e = field(Mode::PeliCan, "SR", "XYZ").unwrap_err();
    assert!(e.to_string().contains("SR"), "{e}");
}

#[test]
fn field_lookup_and_bit_ops() {
    let f = field(Mode::PeliCan, "sr", "tbs").unwrap();
    assert_eq!((f.lsb, f.width), (2, 1));
    let b = field(Mode::PeliCan, "BTR0", "BRP").unwrap();
    assert_eq!(b.get(0xC5), 5);
    assert_eq!(b.set(0xC5, 0x3F), 0xFF);
    assert_eq!(b.set(0xC5, 0x40), 0xC0);
}

#[test]
fn mode_from_cdr() {
    assert_eq!(Mode::from_cdr(0x80), Mode::PeliCan);
    assert_eq!(Mode::from_cdr(0x7F), Mode::BasicCan);
}

// ---- the thesis's hand-typed addresses (seed 000 annexe 4), decoded ----------

/// What the thesis's PeliCAN initialisation really wrote, decoded through
/// the map (reset mode, PeliCAN view). It typed BTR0 at 0x05 and BTR1 at
/// 0x06: the BTR0 value 0x41 went to a reserved address and the BTR1 value
/// 0x25 landed in BTR0, so BTR1 kept its undefined reset value. Its
/// "acceptance filter" 0x14..0x17 is AMR0..AMR3 (writing FFh there accepts
/// everything, which hid the mistake).
#[test]
fn thesis_pelican_init_addresses_hit_other_registers() {
    let w = |a| decode(Mode::PeliCan, OpMode::Reset, Access::Write, a).unwrap();
    assert_eq!(w(0x05).target, Target::Nothing, "pelican_timing0 0x05 is reserved");
    assert_eq!(w(0x06).register().unwrap().name, "BTR0", "pelican_timing1 0x06 is BTR0");
    for (a, n) in [(0x14, "AMR0"), (0x15, "AMR1"), (0x16, "AMR2"), (0x17, "AMR3")] {
        assert_eq!(w(a).register().unwrap().name, n);
    }
    assert_eq!(w(0x04).register().unwrap().name, "IER", "its 'interrupt' 0x04 is IER in PeliCAN");
    // The same 0x04 in BasicCAN is the acceptance code register.
    let b = decode(Mode::BasicCan, OpMode::Reset, Access::Write, 0x04).unwrap();
    assert_eq!(b.register().unwrap().name, "ACR");
    // Its TX_INFO 0x10, read in operating mode, is the RX frame information.
    let r = decode(Mode::PeliCan, OpMode::Operating, Access::Read, 0x10).unwrap();
    assert_eq!(r.register().unwrap().name, "RXFI");
    // BasicCAN timing at 0x06/0x07 was right.
    assert_eq!(decode(Mode::BasicCan, OpMode::Reset, Access::Write, 0x06).unwrap().register().unwrap().name, "BTR0");
}
