//! C header for 8051 firmware (SDCC): the controller on the external data
//! bus, register n at XDATA address base + n, read and written with MOVX
//! through a `volatile __xdata` pointer, as boards built around the
//! SJA1000 chip in Intel mode (or our `can_top_8051`) wire it.

use super::{stamp, HeaderOptions, Reach};
use crate::{registers, Mode, Register};
use std::fmt::Write;

use super::c::{comment_lines, frame_layout, reg_root};

fn view_title(mode: Mode) -> &'static str {
    match mode {
        Mode::PeliCan => "PeliCAN view (CDR.CANMODE = 1): addresses 0..127",
        Mode::BasicCan => "BasicCAN view (CDR.CANMODE = 0, the reset default): addresses 0..31",
    }
}

/// `<prefix>_8051.h`: `<PREFIX>_BASE` (defined by the firmware) is the
/// controller's XDATA address; per register the index (`_REG`), `RD_`
/// (if readable) and `WR_` (if writable) macros through a
/// `volatile __xdata unsigned char *`; per field `_MSK` and `_OFST`; the
/// buffer windows take an index and have a `_LEN`. Other compilers than
/// SDCC get a plain `volatile` pointer (for host-side tests).
pub fn i8051_header(opts: &HeaderOptions) -> String {
    let p = opts.prefix.as_str();
    let guard = format!("__{p}_8051_H__");
    let file = opts.i8051_file();
    let mut o = String::new();
    let _ = writeln!(o, "/*");
    let _ = writeln!(o, " * {file}: SJA1000-compatible CAN controller registers for 8051 firmware (SDCC).");
    let _ = writeln!(o, " * {}", stamp());
    let _ = writeln!(o, " *");
    comment_lines(
        &mut o,
        &format!(
            "Intel-mode bus: the controller sits in the external data space (MOVX), register n at \
             XDATA address {p}_BASE + n (CS decodes the high address byte, ALE latches the low \
             one into the controller). Define {p}_BASE before including this file. Accesses go \
             through a volatile __xdata pointer, so SDCC emits one MOVX per access and never \
             caches or reorders them. Names as in {}: {p}_PELI_* for the PeliCAN view, \
             {p}_BASIC_* for the BasicCAN view; registers marked RESET MODE ONLY are reachable \
             only while MOD.RM (PeliCAN) or CR.RR (BasicCAN) is 1.",
            opts.regs_file()
        ),
    );
    let _ = writeln!(o, " */");
    let _ = writeln!(o, "#ifndef {guard}\n#define {guard}\n");
    let _ = writeln!(
        o,
        "#ifndef {p}_BASE\n#error \"define {p}_BASE (the controller's XDATA address) before including {file}\"\n#endif\n"
    );
    let _ = writeln!(
        o,
        "#if defined(__SDCC)\n#define {p}_XDATA __xdata\n#else\n#define {p}_XDATA /* not SDCC: plain memory (host-side tests) */\n#endif\n"
    );
    let _ = writeln!(o, "/* The register file, and accessors for a computed index. */");
    let _ = writeln!(o, "#define {p}_REGS ((volatile {p}_XDATA unsigned char *)({p}_BASE))");
    let _ = writeln!(o, "#define {p}_RD(index) ({p}_REGS[(index)])");
    let _ = writeln!(o, "#define {p}_WR(index, data) ({p}_REGS[(index)] = (unsigned char)(data))\n");
    for mode in [Mode::PeliCan, Mode::BasicCan] {
        let _ = writeln!(o, "/* ==== {} ==== */\n", view_title(mode));
        for reg in registers(mode) {
            emit_register(&mut o, p, reg);
        }
        let _ = writeln!(o, "/* {mode} buffer layout: byte offsets from the window's first register. */");
        for (name, off, what) in frame_layout(mode) {
            let _ = writeln!(o, "#define {p}_{}_FRAME_{name}_OFST ({off}) /* {what} */", mode.tag());
        }
        let _ = writeln!(o);
    }
    let _ = writeln!(o, "#endif /* {guard} */");
    o
}

fn emit_register(o: &mut String, p: &str, reg: &'static Register) {
    let root = reg_root(p, reg);
    let reach = Reach::of(reg);
    let mut head = format!("{}: {} (address {}", reg.name, reg.title, reg.addr);
    if reg.len > 1 {
        let _ = write!(head, "..{}", reg.addr as u16 + reg.len as u16 - 1);
    }
    head.push_str(").");
    if reach.reset_mode_only() {
        head.push_str(" RESET MODE ONLY.");
    }
    let _ = writeln!(o, "/*");
    comment_lines(o, &head);
    comment_lines(o, &format!("{}.", reach.summary()));
    let _ = writeln!(o, " */");
    let _ = writeln!(o, "#define {root}_REG {}", reg.addr);
    if reg.len > 1 {
        let _ = writeln!(o, "#define {root}_LEN {}", reg.len);
        if reach.readable() {
            let _ = writeln!(o, "#define RD_{root}(i) {p}_RD({root}_REG + (i))");
        }
        if reach.writable() {
            let _ = writeln!(o, "#define WR_{root}(i, data) {p}_WR({root}_REG + (i), data)");
        }
    } else {
        if reach.readable() {
            let _ = writeln!(o, "#define RD_{root}() {p}_RD({root}_REG)");
        }
        if reach.writable() {
            let _ = writeln!(o, "#define WR_{root}(data) {p}_WR({root}_REG, data)");
        }
    }
    for f in reg.fields {
        let _ = writeln!(o, "#define {root}_{}_MSK (0x{:02X}) /* {} */", f.name, f.mask(), f.meaning);
        let _ = writeln!(o, "#define {root}_{}_OFST ({})", f.name, f.lsb);
    }
    let _ = writeln!(o);
}
