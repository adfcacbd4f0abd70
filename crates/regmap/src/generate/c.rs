//! Nios II C headers in the Altera HAL style (`IORD_`/`IOWR_` macros,
//! `_MSK`/`_OFST` constants), and the PIO access variant.

use super::{stamp, HeaderOptions, Reach, Spacing};
use crate::{frame, registers, Mode, Register};
use std::fmt::Write;

/// Upper-case C identifier root of a register: `<PREFIX>_<PELI|BASIC>_<NAME>`.
pub(crate) fn reg_root(prefix: &str, reg: &Register) -> String {
    format!("{}_{}_{}", prefix, reg.mode.tag(), reg.name)
}

/// `(x >> shift) & 0xFF`, without a zero shift.
fn lane_of(x: String, shift: u32) -> String {
    if shift == 0 { format!("({x} & 0xFF)") } else { format!("(({x} >> {shift}) & 0xFF)") }
}

/// `(data & 0xFF) << shift`, without a zero shift.
fn into_lane(shift: u32) -> String {
    if shift == 0 { "((data) & 0xFF)".to_string() } else { format!("(((data) & 0xFF) << {shift})") }
}

/// A read returns the register's 8 bits only, a write puts only them on the
/// bus (the other lanes 0), whatever the stride.
fn read_expr(o: &HeaderOptions, off: &str) -> String {
    let shift = 8 * o.lane as u32;
    match o.spacing {
        Spacing::Byte => format!("IORD_8DIRECT(base, {off})"),
        Spacing::Half => lane_of(format!("IORD_16DIRECT(base, ({off}) * 2)"), shift),
        Spacing::Word => lane_of(format!("IORD(base, {off})"), shift),
    }
}

fn write_expr(o: &HeaderOptions, off: &str) -> String {
    let shift = 8 * o.lane as u32;
    match o.spacing {
        Spacing::Byte => format!("IOWR_8DIRECT(base, {off}, data)"),
        Spacing::Half => format!("IOWR_16DIRECT(base, ({off}) * 2, {})", into_lane(shift)),
        Spacing::Word => format!("IOWR(base, {off}, {})", into_lane(shift)),
    }
}

fn addr_expr(o: &HeaderOptions, off: &str) -> String {
    match (o.spacing, o.lane) {
        (Spacing::Byte, _) => format!("__IO_CALC_ADDRESS_DYNAMIC(base, {off})"),
        (Spacing::Word, 0) => format!("__IO_CALC_ADDRESS_NATIVE(base, {off})"),
        (sp, lane) => format!("__IO_CALC_ADDRESS_DYNAMIC(base, ({off}) * {} + {lane})", sp.stride()),
    }
}

/// Wraps text into ` * ` comment lines of at most ~76 columns.
pub(crate) fn comment_lines(out: &mut String, text: &str) {
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && line.len() + word.len() + 1 > 72 {
            let _ = writeln!(out, " * {line}");
            line.clear();
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        let _ = writeln!(out, " * {line}");
    }
}

fn view_title(mode: Mode) -> &'static str {
    match mode {
        Mode::PeliCan => "PeliCAN view (CDR.CANMODE = 1): addresses 0..127",
        Mode::BasicCan => "BasicCAN view (CDR.CANMODE = 0, the reset default): addresses 0..31",
    }
}

/// `<prefix>_regs.h`: per register the index (`_REG`), `IOADDR_`, `IORD_`
/// (if readable) and `IOWR_` (if writable) macros, per field `_MSK` and
/// `_OFST`; windows get an index argument and a `_LEN`.
pub fn nios_header(opts: &HeaderOptions) -> String {
    let p = opts.prefix.as_str();
    let guard = format!("__{}_REGS_H__", p);
    let mut o = String::new();
    let _ = writeln!(o, "/*");
    let _ = writeln!(o, " * {}: SJA1000-compatible CAN controller registers (BasicCAN and PeliCAN views).", opts.regs_file());
    let _ = writeln!(o, " * {}", stamp());
    let _ = writeln!(o, " *");
    let spacing = match opts.spacing {
        Spacing::Byte => {
            "Register spacing: BYTE. Register n is the byte at base + n and is accessed with \
             IORD_8DIRECT/IOWR_8DIRECT. This matches the can_avalon wrapper (8-bit data, \
             addressUnits WORDS, so one word is one byte)."
        }
        Spacing::Half => {
            "Register spacing: HALF. Register n is the 16-bit half-word at base + 2*n and is \
             accessed with IORD_16DIRECT/IOWR_16DIRECT (Linux: reg-io-width = <2>)."
        }
        Spacing::Word => {
            "Register spacing: WORD. Register n is the 32-bit word at base + 4*n and is accessed \
             with IORD/IOWR (native). Use this only with a 32-bit wide wrapper."
        }
    };
    comment_lines(&mut o, spacing);
    if opts.lane != 0 {
        comment_lines(
            &mut o,
            &format!(
                "Byte lane {lane}: the register's 8 bits are bits {hi}..{lo} of that access (the byte at \
                 base + n*{stride} + {lane}); IORD_ returns them shifted down to bits 7..0 and IOWR_ shifts \
                 them up, so the _MSK and _OFST constants are bits of the register itself.",
                lane = opts.lane,
                lo = 8 * opts.lane as u32,
                hi = 8 * opts.lane as u32 + 7,
                stride = opts.spacing.stride(),
            ),
        );
    }
    let _ = writeln!(o, " *");
    comment_lines(
        &mut o,
        &format!(
            "Names: {p}_PELI_* belong to the PeliCAN view, {p}_BASIC_* to the BasicCAN view; the \
             same address means different registers in the two views (e.g. address 4 is IER in \
             PeliCAN and ACR in BasicCAN), and in PeliCAN addresses 16..28 mean RX buffer (read), \
             TX buffer (write) in operating mode and ACR0..3/AMR0..3 in reset mode. Registers \
             marked RESET MODE ONLY are reachable only while MOD.RM (PeliCAN) or CR.RR (BasicCAN) \
             is 1. Reset values: hw = after hardware reset, rm = after entering reset mode \
             (x = undefined / unchanged)."
        ),
    );
    let _ = writeln!(o, " */");
    let _ = writeln!(o, "#ifndef {guard}\n#define {guard}\n\n#include <io.h>\n");
    let _ = writeln!(
        o,
        "/* Register spacing in bytes, and generic accessors for a computed index. */\n#define {p}_SPACING ({})",
        opts.spacing.stride()
    );
    if opts.lane != 0 {
        let _ = writeln!(o, "/* Byte lane of the data, and the byte offset of register index's data from base. */");
        let _ = writeln!(o, "#define {p}_LANE ({})", opts.lane);
        let _ = writeln!(o, "#define {p}_OFFSET(index) ((index) * {p}_SPACING + {p}_LANE)");
    } else {
        let _ = writeln!(o, "#define {p}_OFFSET(index) ((index) * {p}_SPACING)");
    }
    let _ = writeln!(o, "#define {p}_IORD(base, index) {}", read_expr(opts, "(index)"));
    let _ = writeln!(o, "#define {p}_IOWR(base, index, data) {}\n", write_expr(opts, "(index)"));

    for mode in [Mode::PeliCan, Mode::BasicCan] {
        let _ = writeln!(o, "/* ==== {} ==== */\n", view_title(mode));
        for reg in registers(mode) {
            emit_register(&mut o, p, opts, reg);
        }
        emit_frame_layout(&mut o, p, mode);
    }
    let _ = writeln!(o, "#endif /* {guard} */");
    o
}

fn emit_register(o: &mut String, p: &str, sp: &HeaderOptions, reg: &'static Register) {
    let root = reg_root(p, reg);
    let reach = Reach::of(reg);
    let _ = writeln!(o, "/*");
    let mut head = format!("{}: {} (address {}", reg.name, reg.title, reg.addr);
    if reg.len > 1 {
        let _ = write!(head, "..{}", reg.addr as u16 + reg.len as u16 - 1);
    }
    head.push_str(").");
    if reach.reset_mode_only() {
        head.push_str(" RESET MODE ONLY.");
    }
    comment_lines(o, &head);
    comment_lines(
        o,
        &format!("{}. Reset: hw {}, rm {}.", reach.summary(), reg.reset_hw.notation(), reg.reset_rm.notation()),
    );
    if !reg.note.is_empty() {
        comment_lines(o, reg.note);
    }
    let _ = writeln!(o, " */");
    let _ = writeln!(o, "#define {root}_REG {}", reg.addr);
    if reg.len > 1 {
        let _ = writeln!(o, "#define {root}_LEN {}", reg.len);
        let off = format!("{root}_REG + (i)");
        let _ = writeln!(o, "#define IOADDR_{root}(base, i) {}", addr_expr(sp, &off));
        if reach.readable() {
            let _ = writeln!(o, "#define IORD_{root}(base, i) {}", read_expr(sp, &off));
        }
        if reach.writable() {
            let _ = writeln!(o, "#define IOWR_{root}(base, i, data) {}", write_expr(sp, &off));
        }
    } else {
        let off = format!("{root}_REG");
        let _ = writeln!(o, "#define IOADDR_{root}(base) {}", addr_expr(sp, &off));
        if reach.readable() {
            let _ = writeln!(o, "#define IORD_{root}(base) {}", read_expr(sp, &off));
        }
        if reach.writable() {
            let _ = writeln!(o, "#define IOWR_{root}(base, data) {}", write_expr(sp, &off));
        }
    }
    for f in reg.fields {
        let _ = writeln!(o, "#define {root}_{}_MSK (0x{:02X}) /* {} */", f.name, f.mask(), f.meaning);
        let _ = writeln!(o, "#define {root}_{}_OFST ({})", f.name, f.lsb);
    }
    let _ = writeln!(o);
}

/// Byte offsets inside the buffer windows (no second copy: they come from
/// `regmap::frame`).
pub(crate) fn frame_layout(mode: Mode) -> Vec<(&'static str, u8, &'static str)> {
    match mode {
        Mode::PeliCan => vec![
            ("FI", frame::peli::FI, "frame information"),
            ("ID1", frame::peli::ID1, "identifier byte 1"),
            ("ID2", frame::peli::ID2, "identifier byte 2"),
            ("SFF_DATA", frame::peli::SFF_DATA, "first data byte, standard frame"),
            ("EFF_ID3", frame::peli::EFF_ID3, "identifier byte 3, extended frame"),
            ("EFF_ID4", frame::peli::EFF_ID4, "identifier byte 4, extended frame"),
            ("EFF_DATA", frame::peli::EFF_DATA, "first data byte, extended frame"),
        ],
        Mode::BasicCan => vec![
            ("ID1", frame::basic::ID1, "identifier byte 1"),
            ("ID2", frame::basic::ID2, "identifier byte 2 (ID.2..0, RTR, DLC)"),
            ("DATA", frame::basic::DATA, "first data byte"),
        ],
    }
}

fn emit_frame_layout(o: &mut String, p: &str, mode: Mode) {
    let base = match mode {
        Mode::PeliCan => "the frame information address (16)",
        Mode::BasicCan => "TX identifier 1 (10) or RX identifier 1 (20)",
    };
    let _ = writeln!(o, "/* {} buffer layout: byte offsets from {base}. */", mode);
    for (name, off, what) in frame_layout(mode) {
        let _ = writeln!(o, "#define {p}_{}_FRAME_{name}_OFST ({off}) /* {what} */", mode.tag());
    }
    if mode == Mode::PeliCan {
        let _ = writeln!(
            o,
            "#define {p}_PELI_FRAME_SFF_ID2_RTR_MSK (0x{:02X}) /* RTR copy in SFF ID2 (RX) */",
            frame::peli::SFF_ID2_RTR
        );
        let _ = writeln!(
            o,
            "#define {p}_PELI_FRAME_EFF_ID4_RTR_MSK (0x{:02X}) /* RTR copy in EFF ID4 (RX) */",
            frame::peli::EFF_ID4_RTR
        );
    }
    let _ = writeln!(o);
}

/// `<prefix>_pio.h`: register access for the thesis-style GPIO wiring (seed
/// 000 annexe 4): an address PIO, a data-out PIO, a control PIO (we = bit 0,
/// stb = bit 1, cyc = bit 2, rst = bit 3), an ack input PIO polled with a
/// timeout, and a data-in PIO.
pub fn pio_header(opts: &HeaderOptions) -> String {
    let p = opts.prefix.as_str();
    let l = p.to_lowercase();
    let guard = format!("__{}_PIO_H__", p);
    let mut o = String::new();
    let _ = writeln!(o, "/*");
    let _ = writeln!(o, " * {}: SJA1000 register access through PIO (GPIO) wiring.", opts.pio_file());
    let _ = writeln!(o, " * {}", stamp());
    let _ = writeln!(o, " *");
    comment_lines(
        &mut o,
        &format!(
            "The Wishbone port of the core is driven by five PIOs, as in the DE2 thesis (seed 000 \
             annexe 4): address out, data out, control out (we = bit 0, stb = bit 1, cyc = bit 2, \
             rst = bit 3), ack in (bit 0), data in. Define {p}_PIO_ADDR_BASE, {p}_PIO_DOUT_BASE, \
             {p}_PIO_CTRL_BASE, {p}_PIO_ACK_BASE and {p}_PIO_DIN_BASE (from system.h) before \
             including this file. Register indexes are the {p}_PELI_*_REG / {p}_BASIC_*_REG \
             constants of {}. Every wait for ack gives up after {p}_PIO_TIMEOUT polls and returns \
             -1, so a dead core cannot hang the CPU.",
            opts.regs_file()
        ),
    );
    let _ = writeln!(o, " *");
    comment_lines(
        &mut o,
        &format!(
            "The core's ack may be a single-clock pulse, which a polled level PIO can miss: give \
             the ack PIO rising-edge capture and define {p}_PIO_ACK_EDGE_CAPTURE to poll the \
             edge capture register instead of the data register."
        ),
    );
    let _ = writeln!(o, " */");
    let _ = writeln!(o, "#ifndef {guard}\n#define {guard}\n");
    let _ = writeln!(o, "#include <io.h>\n#include <altera_avalon_pio_regs.h>\n#include \"{}\"\n", opts.regs_file());
    for b in ["ADDR", "DOUT", "CTRL", "ACK", "DIN"] {
        let _ = writeln!(o, "#ifndef {p}_PIO_{b}_BASE\n#error \"define {p}_PIO_{b}_BASE (see system.h) before including {}\"\n#endif", opts.pio_file());
    }
    let _ = writeln!(o);
    let _ = writeln!(o, "/* Control PIO bits. */");
    let _ = writeln!(o, "#define {p}_PIO_CTRL_WE_MSK (0x01)");
    let _ = writeln!(o, "#define {p}_PIO_CTRL_STB_MSK (0x02)");
    let _ = writeln!(o, "#define {p}_PIO_CTRL_CYC_MSK (0x04)");
    let _ = writeln!(o, "#define {p}_PIO_CTRL_RST_MSK (0x08)");
    let _ = writeln!(o, "#define {p}_PIO_CTRL_WRITE ({p}_PIO_CTRL_CYC_MSK | {p}_PIO_CTRL_STB_MSK | {p}_PIO_CTRL_WE_MSK) /* 0x07 */");
    let _ = writeln!(o, "#define {p}_PIO_CTRL_READ ({p}_PIO_CTRL_CYC_MSK | {p}_PIO_CTRL_STB_MSK) /* 0x06 */");
    let _ = writeln!(o, "#define {p}_PIO_CTRL_RESET ({p}_PIO_CTRL_RST_MSK) /* 0x08 */");
    let _ = writeln!(o, "#define {p}_PIO_CTRL_IDLE (0x00)\n");
    let _ = writeln!(o, "#ifndef {p}_PIO_TIMEOUT\n#define {p}_PIO_TIMEOUT (100000UL)\n#endif\n");
    let _ = writeln!(o, "#ifdef {p}_PIO_ACK_EDGE_CAPTURE");
    let _ = writeln!(o, "#define {p}_PIO_ACK_SEEN() ((IORD_ALTERA_AVALON_PIO_EDGE_CAP({p}_PIO_ACK_BASE) & 1) != 0)");
    let _ = writeln!(o, "#define {p}_PIO_ACK_CLEAR() IOWR_ALTERA_AVALON_PIO_EDGE_CAP({p}_PIO_ACK_BASE, 1)");
    let _ = writeln!(o, "#else");
    let _ = writeln!(o, "#define {p}_PIO_ACK_SEEN() ((IORD_ALTERA_AVALON_PIO_DATA({p}_PIO_ACK_BASE) & 1) != 0)");
    let _ = writeln!(o, "#define {p}_PIO_ACK_CLEAR() ((void)0)");
    let _ = writeln!(o, "#endif\n");
    let _ = writeln!(
        o,
        r#"/* Waits for ack; on timeout drops the cycle and returns -1. */
static inline int {l}_pio_wait_ack(void)
{{
    unsigned long polls = 0;
    while (!{p}_PIO_ACK_SEEN()) {{
        if (++polls >= {p}_PIO_TIMEOUT) {{
            IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_CTRL_BASE, {p}_PIO_CTRL_IDLE);
            return -1;
        }}
    }}
    return 0;
}}

/* Writes one register: one Wishbone write cycle. 0 on ack, -1 on timeout. */
static inline int {l}_pio_write_reg(unsigned char reg, unsigned char data)
{{
    IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_ADDR_BASE, reg);
    IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_DOUT_BASE, data);
    {p}_PIO_ACK_CLEAR();
    /* we first, then cyc|stb|we: the thesis sequence, so traces match it */
    IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_CTRL_BASE, {p}_PIO_CTRL_WE_MSK);
    IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_CTRL_BASE, {p}_PIO_CTRL_WRITE);
    if ({l}_pio_wait_ack() != 0)
        return -1;
    IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_CTRL_BASE, {p}_PIO_CTRL_IDLE);
    return 0;
}}

/* Reads one register into *data: one Wishbone read cycle. 0 on ack, -1 on timeout. */
static inline int {l}_pio_read_reg(unsigned char reg, unsigned char *data)
{{
    IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_ADDR_BASE, reg);
    {p}_PIO_ACK_CLEAR();
    IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_CTRL_BASE, {p}_PIO_CTRL_IDLE);
    IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_CTRL_BASE, {p}_PIO_CTRL_READ);
    if ({l}_pio_wait_ack() != 0)
        return -1;
    *data = (unsigned char)(IORD_ALTERA_AVALON_PIO_DATA({p}_PIO_DIN_BASE) & 0xFF);
    IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_CTRL_BASE, {p}_PIO_CTRL_IDLE);
    return 0;
}}

/* Pulses the core's reset input for `hold` polling loops. */
static inline void {l}_pio_reset(unsigned long hold)
{{
    volatile unsigned long i;
    IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_CTRL_BASE, {p}_PIO_CTRL_RESET);
    for (i = 0; i < hold; i++) {{
    }}
    IOWR_ALTERA_AVALON_PIO_DATA({p}_PIO_CTRL_BASE, {p}_PIO_CTRL_IDLE);
}}
"#
    );
    let _ = writeln!(o, "#endif /* {guard} */");
    o
}
