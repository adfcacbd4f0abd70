//! A device-tree node for Linux's `sja1000_platform` driver (binding
//! `nxp,sja1000`): where the registers are (base, stride as `reg-io-width`),
//! the interrupt, and the clock and output settings the driver writes into
//! OCR and CDR, derived from the register values through the register map's
//! own fields.
//!
//! What the driver does with each property (read from the binding and the
//! driver, Documentation/devicetree/bindings/net/can/nxp,sja1000.yaml and
//! drivers/net/can/sja1000/sja1000_platform.c):
//! - `reg-io-width` 1, 2 or 4: register n is read with an access of that
//!   width at base + n * width, and bits 7..0 are kept (so the data must be
//!   in byte lane 0);
//! - `nxp,external-clock-frequency`: the oscillator (the core's clock
//!   input); the CAN clock the driver computes bit timing from is half of it;
//! - `nxp,tx-output-mode`: OCR bits 1..0; `nxp,tx-output-config`: OCR bits
//!   7..2 (0x02 = TX0 pull-down);
//! - `nxp,clock-out-frequency`: absent or 0 = CLKOUT off (CDR.3); otherwise
//!   divider = oscillator / frequency, CDR.2..0 = divider / 2 - 1, or 7
//!   (CLKOUT = oscillator) for a divider of 1;
//! - `nxp,no-comparator-bypass`: present = CDR.6 (CBP) left 0; absent, the
//!   driver sets CBP.
//!
//! The driver has no property for the bit rate (it computes BTR0/BTR1 from
//! `ip link set canX type can bitrate N`) nor for CDR.5 (RXINTEN): the node
//! says them in a comment.

use super::{stamp, GenError, Spacing};
use crate::{field, registers, Mode};
use std::fmt::Write;

/// Options of [`dt_node`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DtOptions {
    /// Node name before the `@` (the unit address is `base`).
    pub name: String,
    /// Bus address of register 0 (32 bits: one address cell).
    pub base: u32,
    /// Register stride on the bus (`reg-io-width`).
    pub spacing: Spacing,
    /// Byte lane of the data in a register's stride (must be 0 for the driver).
    pub lane: u8,
    /// The `interrupts` cells, as the interrupt controller wants them.
    pub interrupts: Vec<u32>,
    /// `interrupt-parent` phandle label without `&` (none: inherited).
    pub interrupt_parent: Option<String>,
    /// The core's clock input in Hz (the SJA1000's oscillator, XTAL1).
    pub clock_hz: u32,
    /// Output control register value (OCR, address 8).
    pub ocr: u8,
    /// Clock divider register value (CDR, address 31).
    pub cdr: u8,
    /// BTR0 and BTR1 of the chosen bit timing, for the bit-rate comment.
    pub btr: Option<(u8, u8)>,
}

impl Default for DtOptions {
    /// The values of our DE2 set-up: 24 MHz, OCR 0xDA (normal mode, push-pull),
    /// CDR 0xC8 (PeliCAN, comparator bypass, CLKOUT off).
    fn default() -> Self {
        DtOptions {
            name: "can".into(),
            base: 0,
            spacing: Spacing::Byte,
            lane: 0,
            interrupts: vec![0],
            interrupt_parent: None,
            clock_hz: 24_000_000,
            ocr: 0xDA,
            cdr: 0xC8,
            btr: None,
        }
    }
}

/// Bytes of the register window: the 128 addresses of the PeliCAN address
/// allocation (0..127; the map's registers end at 111, the rest reads as
/// reserved), times the stride.
pub fn window_bytes(spacing: Spacing) -> u32 {
    let top = registers(Mode::PeliCan).iter().map(|r| r.addr as u32 + r.len as u32).max().unwrap_or(0);
    top.next_power_of_two().max(128) * spacing.stride() as u32
}

/// The CLKOUT frequency CDR selects from `clock_hz`, or `None` when CDR.3
/// (clock off) is set. Datasheet CDR.2..0: fosc / 2, / 4 ... / 14, 7 = fosc.
pub fn clkout_hz(clock_hz: u32, cdr: u8) -> Option<u32> {
    let off = field(Mode::PeliCan, "CDR", "CLKOFF").expect("CDR.CLKOFF in the map");
    let cd = field(Mode::PeliCan, "CDR", "CD").expect("CDR.CD in the map");
    if off.get(cdr) != 0 {
        return None;
    }
    Some(match cd.get(cdr) {
        7 => clock_hz,
        n => clock_hz / (2 * (n as u32 + 1)),
    })
}

/// The device-tree node text (a node to paste under its bus, not a whole tree).
pub fn dt_node(o: &DtOptions) -> Result<String, GenError> {
    let stride = o.spacing.stride();
    if o.lane >= stride {
        return Err(GenError::BadLane { lane: o.lane as u32, stride });
    }
    if o.lane != 0 {
        return Err(GenError::LaneNotForLinux { lane: o.lane, stride });
    }
    let f = |reg: &str, name: &str| field(Mode::PeliCan, reg, name).expect("field in the map");
    let mode = f("OCR", "OCMODE").get(o.ocr);
    // OCR bits 7..2: OCPOL0 (bit 2) up to OCTP1 (bit 7), as the binding numbers them from 0.
    let config = (o.ocr & !f("OCR", "OCMODE").mask()) >> f("OCR", "OCPOL0").lsb;
    let cbp = f("CDR", "CBP").get(o.cdr) != 0;
    let rxinten = f("CDR", "RXINTEN").get(o.cdr) != 0;
    let mut s = String::new();
    let _ = writeln!(s, "/*");
    let _ = writeln!(s, " * SJA1000-compatible CAN controller for Linux's sja1000 platform driver.");
    let _ = writeln!(s, " * {}", stamp());
    let _ = writeln!(s, " * From OCR 0x{:02X} and CDR 0x{:02X} at a {} Hz clock; registers every {stride} byte(s).", o.ocr, o.cdr, o.clock_hz);
    if let Some((b0, b1)) = o.btr {
        let brp = (b0 & 0x3F) as u32 + 1;
        let tseg1 = (b1 & 0x0F) as u32 + 1;
        let tseg2 = ((b1 >> 4) & 0x07) as u32 + 1;
        let quanta = 1 + tseg1 + tseg2;
        let bitrate = o.clock_hz as f64 / (2.0 * brp as f64 * quanta as f64);
        let _ = writeln!(
            s,
            " * Bit timing BTR0 0x{b0:02X} BTR1 0x{b1:02X}: {bitrate:.0} bit/s, sample point {:.1} %. The driver computes",
            100.0 * (1 + tseg1) as f64 / quanta as f64
        );
        let _ = writeln!(s, " * its own BTR0/BTR1: `ip link set canX type can bitrate {bitrate:.0}`.");
    }
    if rxinten {
        let _ = writeln!(s, " * CDR.5 (RXINTEN) is set here; the driver has no property for it and leaves it 0.");
    }
    let _ = writeln!(s, " */");
    let _ = writeln!(s, "{}@{:x} {{", o.name, o.base);
    let _ = writeln!(s, "\tcompatible = \"nxp,sja1000\";");
    let _ = writeln!(s, "\treg = <0x{:x} 0x{:x}>;", o.base, window_bytes(o.spacing));
    let _ = writeln!(s, "\treg-io-width = <{stride}>;");
    if let Some(p) = &o.interrupt_parent {
        let _ = writeln!(s, "\tinterrupt-parent = <&{p}>;");
    }
    let cells: Vec<String> = o.interrupts.iter().map(|c| c.to_string()).collect();
    let _ = writeln!(s, "\tinterrupts = <{}>;", cells.join(" "));
    let _ = writeln!(s, "\tnxp,external-clock-frequency = <{}>;", o.clock_hz);
    let _ = writeln!(s, "\tnxp,tx-output-mode = <{mode}>;");
    let _ = writeln!(s, "\tnxp,tx-output-config = <0x{config:02x}>;");
    if let Some(hz) = clkout_hz(o.clock_hz, o.cdr) {
        let _ = writeln!(s, "\tnxp,clock-out-frequency = <{hz}>;");
    }
    if !cbp {
        let _ = writeln!(s, "\tnxp,no-comparator-bypass;");
    }
    let _ = writeln!(s, "}};");
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The property value of `name` in a node, as text between `<` and `>`.
    fn prop<'a>(node: &'a str, name: &str) -> Option<&'a str> {
        let at = node.find(&format!("\t{name} = <"))?;
        let rest = &node[at + name.len() + 5..];
        Some(&rest[..rest.find('>')?])
    }

    fn num(v: &str) -> u32 {
        match v.strip_prefix("0x") {
            Some(h) => u32::from_str_radix(h, 16).unwrap(),
            None => v.parse().unwrap(),
        }
    }

    /// OCR and CDR as the driver rebuilds them from the node (its documented
    /// defaults when a property is absent), to check the node round-trips.
    fn driver_view(node: &str) -> (u8, u8, u32) {
        let osc = prop(node, "nxp,external-clock-frequency").map(num).unwrap_or(16_000_000);
        let mut ocr = prop(node, "nxp,tx-output-mode").map(num).unwrap_or(2) as u8 & 0x03;
        ocr |= ((prop(node, "nxp,tx-output-config").map(num).unwrap_or(0x02) << 2) & 0xFC) as u8;
        let mut cdr = 0u8;
        match prop(node, "nxp,clock-out-frequency").map(num) {
            Some(hz) if hz != 0 => {
                let divider = osc / hz;
                cdr |= if divider > 1 { (divider / 2 - 1) as u8 } else { 0x07 };
            }
            _ => cdr |= 0x08,
        }
        if !node.contains("nxp,no-comparator-bypass;") {
            cdr |= 0x40;
        }
        (ocr, cdr, prop(node, "reg-io-width").map(num).unwrap_or(1))
    }

    #[test]
    fn a_node_for_our_de2_settings_has_the_register_values_the_driver_writes_back() {
        let o = DtOptions { base: 0xff20_0000, interrupts: vec![0, 40, 4], interrupt_parent: Some("intc".into()), ..Default::default() };
        let n = dt_node(&o).unwrap();
        assert!(n.contains("can@ff200000 {\n\tcompatible = \"nxp,sja1000\";\n"), "{n}");
        assert_eq!(prop(&n, "reg"), Some("0xff200000 0x80"));
        assert_eq!(prop(&n, "reg-io-width"), Some("1"));
        assert_eq!(prop(&n, "interrupts"), Some("0 40 4"));
        assert_eq!(prop(&n, "interrupt-parent"), Some("&intc"));
        assert_eq!(prop(&n, "nxp,external-clock-frequency"), Some("24000000"));
        // OCR 0xDA: mode 2 (normal), config 0x36 (TX0 push-pull 0x06, TX1 pull-down 0x10, TX1 invert 0x20).
        assert_eq!(prop(&n, "nxp,tx-output-mode"), Some("2"));
        assert_eq!(prop(&n, "nxp,tx-output-config"), Some("0x36"));
        // CDR 0xC8: clock off (no property), CBP set (no no-comparator-bypass).
        assert_eq!(prop(&n, "nxp,clock-out-frequency"), None);
        assert!(!n.contains("no-comparator-bypass"));
        // PeliCAN mode (CDR.7) is the driver's own choice; the rest comes back.
        assert_eq!(driver_view(&n), (0xDA, 0x48, 1));
    }

    #[test]
    fn clkout_cbp_and_stride_follow_cdr_and_the_layout() {
        for cd in 0..8u8 {
            let o = DtOptions { cdr: 0x80 | cd, spacing: Spacing::Word, ..Default::default() };
            let n = dt_node(&o).unwrap();
            let want = if cd == 7 { 24_000_000 } else { 24_000_000 / (2 * (cd as u32 + 1)) };
            assert_eq!(prop(&n, "nxp,clock-out-frequency").map(num), Some(want), "CD {cd}");
            assert!(n.contains("\tnxp,no-comparator-bypass;\n"), "CBP 0");
            assert_eq!(prop(&n, "reg"), Some("0x0 0x200"), "128 registers at a 4-byte stride");
            assert_eq!(driver_view(&n), (0xDA, cd, 4), "CD {cd} round-trips through the driver");
        }
        let half = dt_node(&DtOptions { spacing: Spacing::Half, ..Default::default() }).unwrap();
        assert_eq!((prop(&half, "reg"), prop(&half, "reg-io-width")), (Some("0x0 0x100"), Some("2")));
        // An odd clock still gives the divider back.
        let odd = dt_node(&DtOptions { clock_hz: 16_000_001, cdr: 0x06, ..Default::default() }).unwrap();
        assert_eq!(driver_view(&odd).1, 0x06);
    }

    #[test]
    fn a_lane_the_driver_cannot_read_is_refused_with_the_reason() {
        let e = dt_node(&DtOptions { spacing: Spacing::Word, lane: 1, ..Default::default() }).unwrap_err().to_string();
        assert!(e.contains("byte lane 1 at a 4-byte stride") && e.contains("keeps bits 7..0 (lane 0)"), "{e}");
        assert!(dt_node(&DtOptions { lane: 1, ..Default::default() }).unwrap_err().to_string().contains("outside a register of 1 byte"));
    }

    #[test]
    fn the_bit_timing_and_rxinten_are_said_in_the_comment() {
        let n = dt_node(&DtOptions { btr: Some((0x00, 0x1C)), cdr: 0xE8, ..Default::default() }).unwrap();
        // 24 MHz, BRP 1, 1 + 13 + 2 = 16 quanta: 750 kbit/s, sample point 87.5 %.
        assert!(n.contains("750000 bit/s, sample point 87.5 %"), "{n}");
        assert!(n.contains("bitrate 750000"));
        assert!(n.contains("RXINTEN"));
    }
}
