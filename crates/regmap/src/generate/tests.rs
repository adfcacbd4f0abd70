//! Generator tests that need no external tool (the C, Tcl and Verilog
//! tools run in `tests/c_generated.rs`).
use super::*;
use crate::{register, registers, Mode};

#[test]
fn regenerating_gives_identical_output() {
    for spacing in [Spacing::Byte, Spacing::Word] {
        let opts = GenOptions { header: HeaderOptions { spacing, ..Default::default() }, ..Default::default() };
        let a = all_files(&opts);
        let b = all_files(&opts);
        assert_eq!(a, b);
        assert_eq!(a.len(), 6);
        for (name, text) in &a {
            assert!(text.contains("Do not edit"), "{name} lacks the stamp");
            assert!(!text.contains("\r"), "{name} has CR");
        }
    }
    // And through the file system.
    let d1 = tempfile::tempdir().unwrap();
    let d2 = tempfile::tempdir().unwrap();
    let p1 = write_all(d1.path(), &GenOptions::default()).unwrap();
    let p2 = write_all(d2.path(), &GenOptions::default()).unwrap();
    for (a, b) in p1.iter().zip(&p2) {
        assert_eq!(a.file_name(), b.file_name());
        assert_eq!(std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    }
    let names: Vec<_> = p1.iter().map(|p| p.file_name().unwrap().to_string_lossy().into_owned()).collect();
    assert_eq!(
        names,
        ["can_sja_regs.h", "can_sja_pio.h", "can_sja_8051.h", "can_avalon_hw.tcl", "sja1000_registers.md", "sja1000_regs.vh"]
    );
}

#[test]
fn i8051_header_respects_access_rules() {
    let h = i8051_header(&HeaderOptions::default());
    // Write-only CMR has no RD_, read-only SR has no WR_.
    assert!(h.contains("#define WR_CAN_SJA_PELI_CMR(data) CAN_SJA_WR(CAN_SJA_PELI_CMR_REG, data)"));
    assert!(!h.contains("RD_CAN_SJA_PELI_CMR("));
    assert!(h.contains("#define RD_CAN_SJA_PELI_SR() CAN_SJA_RD(CAN_SJA_PELI_SR_REG)"));
    assert!(!h.contains("WR_CAN_SJA_PELI_SR("));
    assert!(h.contains("volatile CAN_SJA_XDATA unsigned char *"));
    let c = i8051_header(&HeaderOptions::new("CAN0", Spacing::Byte).unwrap());
    assert!(c.contains("#ifndef CAN0_BASE") && !c.contains("CAN_SJA_"));
}

#[test]
fn header_names_views_apart_and_marks_access_rules() {
    let h = nios_header(&HeaderOptions::default());
    // Distinct names for the same address in the two views.
    assert!(h.contains("#define CAN_SJA_PELI_IER_REG 4\n"));
    assert!(h.contains("#define CAN_SJA_BASIC_ACR_REG 4\n"));
    // Write-only CMR has no IORD, read-only SR has no IOWR.
    assert!(h.contains("#define IOWR_CAN_SJA_PELI_CMR(base, data) IOWR_8DIRECT(base, CAN_SJA_PELI_CMR_REG, data)"));
    assert!(!h.contains("IORD_CAN_SJA_PELI_CMR("));
    assert!(!h.contains("IOWR_CAN_SJA_PELI_SR("));
    assert!(h.contains("#define IORD_CAN_SJA_PELI_RXFIFO(base, i) IORD_8DIRECT(base, CAN_SJA_PELI_RXFIFO_REG + (i))"));
    // Reset-mode-only registers are marked in their comment block.
    for (mode, name) in [(Mode::PeliCan, "ACR0"), (Mode::PeliCan, "AMR3"), (Mode::BasicCan, "ACR")] {
        let r = register(mode, name).unwrap();
        let at = h.find(&format!(" * {}: {}", r.name, r.title)).unwrap_or_else(|| panic!("{name} comment"));
        let block = &h[at..at + 200];
        assert!(block.contains("RESET MODE ONLY"), "{name}: {block}");
    }
    let at = h.find(" * IER: interrupt enable register").unwrap();
    assert!(!h[at..at + 120].contains("RESET MODE ONLY"));
    assert!(h.contains("#include <io.h>"));
    assert!(h.contains("Register spacing: BYTE"));
    let w = nios_header(&HeaderOptions { spacing: Spacing::Word, ..Default::default() });
    assert!(w.contains("Register spacing: WORD"));
    assert!(w.contains("#define IORD_CAN_SJA_PELI_SR(base) (IORD(base, CAN_SJA_PELI_SR_REG) & 0xFF)"));
    assert!(w.contains("#define IOWR_CAN_SJA_PELI_MOD(base, data) IOWR(base, CAN_SJA_PELI_MOD_REG, ((data) & 0xFF))"));
    assert!(w.contains("__IO_CALC_ADDRESS_NATIVE"));
}

#[test]
fn stride_and_lane_move_every_access_and_address() {
    let h = nios_header(&HeaderOptions::new("CAN_SJA", Spacing::Half).unwrap().with_lane(1).unwrap());
    assert!(h.contains("Register spacing: HALF"));
    assert!(h.contains("#define CAN_SJA_SPACING (2)") && h.contains("#define CAN_SJA_LANE (1)"));
    assert!(h.contains("#define IORD_CAN_SJA_PELI_SR(base) ((IORD_16DIRECT(base, (CAN_SJA_PELI_SR_REG) * 2) >> 8) & 0xFF)"), "{h}");
    assert!(h.contains("#define IOWR_CAN_SJA_PELI_TXB(base, i, data) IOWR_16DIRECT(base, (CAN_SJA_PELI_TXB_REG + (i)) * 2, (((data) & 0xFF) << 8))"));
    assert!(h.contains("#define IOADDR_CAN_SJA_PELI_SR(base) __IO_CALC_ADDRESS_DYNAMIC(base, (CAN_SJA_PELI_SR_REG) * 2 + 1)"));
    let w3 = nios_header(&HeaderOptions::new("CAN_SJA", Spacing::Word).unwrap().with_lane(3).unwrap());
    assert!(w3.contains("#define IORD_CAN_SJA_PELI_IR(base) ((IORD(base, CAN_SJA_PELI_IR_REG) >> 24) & 0xFF)"));
    // The field constants stay bits of the register, whatever the lane.
    assert!(w3.contains("#define CAN_SJA_PELI_SR_TBS_MSK (0x04)") && w3.contains("#define CAN_SJA_PELI_SR_TBS_OFST (2)"));
    let o = HeaderOptions::new("CAN_SJA", Spacing::Word).unwrap().with_lane(2).unwrap();
    assert_eq!((o.offset(0), o.offset(3)), (2, 14));
    // A lane outside the stride, a stride that is not 1, 2 or 4.
    assert_eq!(
        HeaderOptions::new("CAN_SJA", Spacing::Half).unwrap().with_lane(2).unwrap_err().to_string(),
        "byte lane 2 is outside a register of 2 byte(s): lanes 0..1"
    );
    assert!(HeaderOptions::default().with_lane(1).is_err());
    assert_eq!(Spacing::from_stride(3).unwrap_err().to_string(), "register stride 3 is not 1, 2 or 4 bytes");
    assert_eq!(Spacing::from_stride(2).unwrap(), Spacing::Half);
}

#[test]
fn prefix_is_configurable() {
    let o = HeaderOptions { prefix: "CAN0".into(), spacing: Spacing::Byte, lane: 0 };
    assert_eq!(o.regs_file(), "can0_regs.h");
    let h = nios_header(&o);
    assert!(h.contains("#define CAN0_PELI_SR_REG 2"));
    assert!(!h.contains("CAN_SJA_"));
    let p = pio_header(&o);
    assert!(p.contains("static inline int can0_pio_write_reg("));
    assert!(p.contains("#include \"can0_regs.h\""));
}

#[test]
fn markdown_lists_every_address_and_register() {
    let md = markdown();
    for mode in Mode::ALL {
        for r in registers(mode) {
            assert!(md.contains(&format!("### {} {}: {}", mode.tag(), r.name, r.title)), "{mode} {}", r.name);
        }
    }
    assert!(md.contains("| 16 | RXFI | TXFI | ACR0 | ACR0 |"), "PeliCAN address 16 row");
    assert!(md.contains("| 4 | reads FFH | - | ACR | ACR |"), "BasicCAN address 4 row");
    assert!(md.contains("| 1 | reads FFH | CMR (mask 0x1F) | reads FFH | CMR (mask 0x1F) |"));
    assert!(md.contains("| 7 | SAM | 0x80 |"));
}

/// The RTL's hand-typed `rtl/sja1000_addr.vh` (written before the generated
/// include existed) must agree with the map until it is replaced by the
/// generated `sja1000_regs.vh`. Names there that are not register names of
/// this map are mapped explicitly below.
#[test]
fn rtl_address_include_agrees_with_the_map() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../rtl/sja1000_addr.vh");
    let Ok(text) = std::fs::read_to_string(&path) else {
        // Nothing to compare: the RTL includes the generated file instead.
        return;
    };
    let reg = |m, n| register(m, n).unwrap();
    let mut checked = 0;
    for line in text.lines() {
        let Some(rest) = line.trim().strip_prefix("localparam [7:0] ") else { continue };
        let (name, val) = rest.split_once('=').unwrap();
        let name = name.trim();
        let val = val.split(';').next().unwrap().trim();
        let v: u16 = val.strip_prefix("8'd").map(|d| d.parse().unwrap()).unwrap_or_else(|| panic!("{line}"));
        let (mode, short) = match name.split_once('_') {
            Some(("BC", s)) => (Mode::BasicCan, s),
            Some(("PC", s)) => (Mode::PeliCan, s),
            _ => panic!("unexpected name {name}"),
        };
        let expect: u16 = match (mode, short) {
            (Mode::BasicCan, "TXB") => reg(mode, "TXID1").addr as u16,
            (Mode::BasicCan, "RXB") => reg(mode, "RXID1").addr as u16,
            (Mode::BasicCan, "TXB_LEN") => 2 + reg(mode, "TXDATA").len as u16,
            (Mode::BasicCan, "RXB_LEN") => 2 + reg(mode, "RXDATA").len as u16,
            (Mode::PeliCan, "TXB") => reg(mode, "TXFI").addr as u16,
            (Mode::PeliCan, "RXB") => reg(mode, "RXFI").addr as u16,
            (Mode::PeliCan, "BUF_LEN") => 1 + reg(mode, "RXB").len as u16,
            (Mode::PeliCan, "TXRAM") => reg(mode, "TXBUF").addr as u16,
            (Mode::PeliCan, "TXRAM_LEN") => reg(mode, "TXBUF").len as u16,
            (_, s) if s.ends_with("_LEN") => reg(mode, s.trim_end_matches("_LEN")).len as u16,
            (_, s) => reg(mode, s).addr as u16,
        };
        assert_eq!(v, expect, "rtl/sja1000_addr.vh: {name} = {v}, the map says {expect}");
        checked += 1;
    }
    assert!(checked >= 30, "only {checked} localparams found in {}", path.display());
}

#[test]
fn options_from_command_line_text() {
    assert_eq!("Byte".parse::<Spacing>(), Ok(Spacing::Byte));
    assert_eq!("word".parse::<Spacing>(), Ok(Spacing::Word));
    let e = "dword".parse::<Spacing>().unwrap_err();
    assert!(e.to_string().contains("dword"), "{e}");
    assert!(HeaderOptions::new("CAN0", Spacing::Byte).is_ok());
    for bad in ["", "can", "0CAN", "CAN-0", "CAN SJA"] {
        assert_eq!(HeaderOptions::new(bad, Spacing::Byte), Err(GenError::BadPrefix(bad.to_string())), "{bad:?}");
    }
}
