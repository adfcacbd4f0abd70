//! Bins no run can hit on an SJA1000, each with the reason: they are not
//! holes and not in the totals, and the table prints them with the reason,
//! so nothing is dropped silently. A run that hits one anyway is printed as
//! a contradiction (the reason, the model or the bin is wrong).

use crate::Bin;

/// A bin of `group`: the register bin `reg bit n=v`.
enum Which {
    Bit(&'static str, u8, bool),
}

const RM_IS_THE_MODE: &str = "MOD.RM / CR.RR is the mode: it reads 1 in reset mode and 0 in operating mode";
const RESET_EMPTIES_FIFO: &str =
    "entering reset mode empties the RX FIFO and clears the overrun (datasheet Tables 2 and 6, reset-mode values RBS = DOS = 0, RMC = 0); reset mode receives nothing";
const RESET_TBS: &str = "TBS reads 1 in reset mode (reset-mode value): reset mode takes no transmission request";
const RESET_IR: &str = "RI, TI, DOI and WUI are 0 on entering reset mode (reset-mode values) and reset mode neither receives, transmits, overruns nor wakes up";
const PELI_RESET_TS_RS: &str = "PeliCAN reset mode sets TS and RS (reset-mode value xx11_x100: waiting for bus-free)";
const BASIC_RESET_TS_RS: &str = "BasicCAN reset mode clears TS and RS (datasheet Table 2, reset-mode value xx00_x100), also when bus-off set it";
const RESET_SM: &str = "entering reset mode clears MOD.SM, and SM cannot be set in reset mode (datasheet, MOD)";
const VIEW_IS_CDR7: &str = "CDR.7 selects the register view: a read in the PeliCAN view sees 1, in the BasicCAN view 0";

fn entries() -> Vec<(String, Which, &'static str)> {
    use Which::*;
    let mut v = Vec::new();
    for (view, rm_reg) in [("BasicCAN", "CR"), ("PeliCAN", "MOD")] {
        let g = |op: &str, a: &str| format!("registers {view} {op} {a}");
        v.push((g("reset", "read"), Bit(rm_reg, 0, false), RM_IS_THE_MODE));
        v.push((g("operating", "read"), Bit(rm_reg, 0, true), RM_IS_THE_MODE));
        v.push((g("reset", "read"), Bit("SR", 0, true), RESET_EMPTIES_FIFO));
        v.push((g("reset", "read"), Bit("SR", 1, true), RESET_EMPTIES_FIFO));
        v.push((g("reset", "read"), Bit("SR", 2, false), RESET_TBS));
        for bit in [0, 1, 3, 4] {
            v.push((g("reset", "read"), Bit("IR", bit, true), RESET_IR));
        }
        let peli = view == "PeliCAN";
        for op in ["reset", "operating"] {
            v.push((g(op, "read"), Bit("CDR", 7, !peli), VIEW_IS_CDR7));
        }
    }
    v.push(("registers BasicCAN reset read".to_string(), Which::Bit("SR", 4, true), BASIC_RESET_TS_RS));
    v.push(("registers BasicCAN reset read".to_string(), Which::Bit("SR", 5, true), BASIC_RESET_TS_RS));
    let g = |op: &str, a: &str| format!("registers PeliCAN {op} {a}");
    v.push((g("reset", "read"), Which::Bit("SR", 4, false), PELI_RESET_TS_RS));
    v.push((g("reset", "read"), Which::Bit("SR", 5, false), PELI_RESET_TS_RS));
    v.push((g("reset", "read"), Which::Bit("MOD", 4, true), RESET_SM));
    for bit in 0..5 {
        v.push((g("reset", "read"), Which::Bit("RMC", bit, true), RESET_EMPTIES_FIFO));
    }
    v
}

fn matches(b: &Bin, group: &str, w: &Which) -> bool {
    let Which::Bit(reg, bit, value) = w;
    b.group == group && b.name == crate::bins::register_bit(reg, *bit, *value)
}

/// Marks the unreachable bins; returns the entries that named no bin (a
/// typo or a changed register map), which a test keeps empty.
pub(crate) fn mark(bins: &mut [Bin]) -> Vec<String> {
    let mut unmatched = Vec::new();
    for (group, which, reason) in entries() {
        let mut n = 0;
        for b in bins.iter_mut().filter(|b| matches(b, &group, &which)) {
            b.unreachable = Some(reason.to_string());
            n += 1;
        }
        if n == 0 {
            let Which::Bit(r, bit, v) = which;
            unmatched.push(format!("{group}: {}", crate::bins::register_bit(r, bit, v)));
        }
    }
    unmatched
}
