//! Markdown register reference.

use super::{stamp, Reach};
use crate::{address_table, registers, Mode, OpMode, Access, RegisterView, Target};
use std::fmt::Write;

fn cell(v: &RegisterView, addr: u8) -> String {
    match v.target {
        Target::Register(r) => {
            let mut s = if r.len > 1 { format!("{}[{}]", r.name, addr - r.addr) } else { r.name.to_string() };
            if v.write_mask != 0xFF {
                let _ = write!(s, " (mask 0x{:02X})", v.write_mask);
            }
            s
        }
        Target::Constant(c) => format!("reads {c:02X}H"),
        Target::Nothing => "-".to_string(),
    }
}

fn cell_range(v: &RegisterView, first: u8, last: u8) -> String {
    if first == last {
        return cell(v, first);
    }
    match v.target {
        Target::Register(r) if r.len > 1 => {
            format!("{}[{}..{}]", r.name, first - r.addr, last - r.addr)
        }
        _ => cell(v, first),
    }
}

/// The register reference: per view, the address allocation table (what a
/// read or write does in operating and in reset mode), then each register
/// with its reset values and fields.
pub fn markdown() -> String {
    let mut o = String::new();
    let _ = writeln!(o, "# SJA1000 register reference\n");
    let _ = writeln!(o, "<!-- {} -->\n", stamp());
    let _ = writeln!(
        o,
        "Source: SJA1000 data sheet (Philips, 2000 Jan 04), sections 6.3 to 6.5. Where seed 000 \
         annexe 1 (the DE2 thesis table) differs, the data sheet wins; the notes say where. \
         Reset values: `hw` after a hardware reset, `rm` after entering reset mode (MOD.RM / CR.RR \
         set by software or by bus-off), bit 7 first, `x` = undefined (hw) or unchanged (rm). \
         Addresses outside the view (32..255 in BasicCAN, 128..255 in PeliCAN) are not defined \
         by the data sheet and are an error in the map.\n"
    );
    for mode in [Mode::PeliCan, Mode::BasicCan] {
        let _ = writeln!(o, "## {mode} view (CDR.7 = {})\n", u8::from(mode == Mode::PeliCan));
        let _ = writeln!(o, "| address | operating read | operating write | reset read | reset write |");
        let _ = writeln!(o, "|---|---|---|---|---|");
        for row in address_table(mode) {
            let a = if row.first == row.last { row.first.to_string() } else { format!("{}..{}", row.first, row.last) };
            let c = |op, acc| cell_range(row.view(op, acc), row.first, row.last);
            let _ = writeln!(
                o,
                "| {a} | {} | {} | {} | {} |",
                c(OpMode::Operating, Access::Read),
                c(OpMode::Operating, Access::Write),
                c(OpMode::Reset, Access::Read),
                c(OpMode::Reset, Access::Write)
            );
        }
        let _ = writeln!(o);
        for r in registers(mode) {
            let reach = Reach::of(r);
            let addr = if r.len > 1 { format!("{}..{}", r.addr, r.addr as u16 + r.len as u16 - 1) } else { r.addr.to_string() };
            let _ = writeln!(o, "### {} {}: {} ({addr})\n", mode.tag(), r.name, r.title);
            let _ = writeln!(
                o,
                "{}{}. Reset: hw `{}`, rm `{}`.\n",
                if reach.reset_mode_only() { "**Reset mode only.** " } else { "" },
                reach.summary(),
                r.reset_hw.notation(),
                r.reset_rm.notation()
            );
            if !r.note.is_empty() {
                let _ = writeln!(o, "{}\n", r.note.split_whitespace().collect::<Vec<_>>().join(" "));
            }
            if !r.fields.is_empty() {
                let _ = writeln!(o, "| bits | field | mask | meaning |");
                let _ = writeln!(o, "|---|---|---|---|");
                for f in r.fields.iter().rev() {
                    let bits = if f.width == 1 { f.lsb.to_string() } else { format!("{}..{}", f.lsb + f.width - 1, f.lsb) };
                    let _ = writeln!(o, "| {bits} | {} | 0x{:02X} | {} |", f.name, f.mask(), f.meaning);
                }
                let _ = writeln!(o);
            }
        }
    }
    o
}
