//! Verilog include with the register addresses and field masks for the RTL.

use super::stamp;
use crate::{registers, Mode};
use std::fmt::Write;

/// Verilog name prefix of a view: `PC_` (PeliCAN) or `BC_` (BasicCAN).
pub(crate) fn vprefix(mode: Mode) -> &'static str {
    match mode {
        Mode::PeliCan => "PC_",
        Mode::BasicCan => "BC_",
    }
}

/// `sja1000_regs.vh`: `localparam`s to include inside a module body:
/// `PC_SR = 8'd2`, `PC_RXFIFO_LEN = 8'd64`, `PC_SR_TBS = 8'h04` (mask),
/// `PC_SR_TBS_BIT = 2` (lsb). No include guard: a guard would hide the
/// localparams from the second module that includes the file.
pub fn verilog_include() -> String {
    let mut o = String::new();
    let _ = writeln!(o, "// sja1000_regs.vh: SJA1000 register addresses and field masks.");
    let _ = writeln!(o, "// {}", stamp());
    let _ = writeln!(o, "// Include inside a module body (localparams are module-scoped).");
    let _ = writeln!(o, "// PC_* = PeliCAN view (CDR.7 = 1), BC_* = BasicCAN view (CDR.7 = 0).");
    let _ = writeln!(o, "// <REG> = address, <REG>_LEN = bytes spanned (windows), <REG>_<FIELD> = mask,");
    let _ = writeln!(o, "// <REG>_<FIELD>_BIT = lsb of the field.");
    for mode in [Mode::PeliCan, Mode::BasicCan] {
        let vp = vprefix(mode);
        let _ = writeln!(o, "\n// ---- {mode} view: addresses 0..{} ----", mode.addr_limit() - 1);
        for r in registers(mode) {
            let _ = writeln!(o, "localparam [7:0] {vp}{} = 8'd{}; // {}", r.name, r.addr, r.title);
            if r.len > 1 {
                let _ = writeln!(o, "localparam [7:0] {vp}{}_LEN = 8'd{};", r.name, r.len);
            }
            for f in r.fields {
                let _ = writeln!(o, "localparam [7:0] {vp}{}_{} = 8'h{:02X};", r.name, f.name, f.mask());
                let _ = writeln!(o, "localparam integer {vp}{}_{}_BIT = {};", r.name, f.name, f.lsb);
            }
        }
    }
    o
}
