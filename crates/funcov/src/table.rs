//! The text report: groups with holes first, then the holes by name.

use crate::{Bin, Coverage};
use std::fmt::Write as _;

pub(crate) fn render(c: &Coverage) -> String {
    let mut s = String::new();
    let mut groups = c.summary();
    // Holes first: the groups with the lowest share of hit bins on top.
    groups.sort_by(|a, b| a.percent().total_cmp(&b.percent()).then(a.group.cmp(&b.group)));
    let w = groups.iter().map(|g| g.group.len()).max().unwrap_or(5).max(5);
    let _ = writeln!(s, "{:<w$}  {:>5} {:>5}  {:>6}", "group", "hit", "bins", "cover");
    for g in &groups {
        let _ = writeln!(s, "{:<w$}  {:>5} {:>5}  {:>5.1}%", g.group, g.hit, g.total, g.percent());
    }
    let t = c.totals();
    let _ = writeln!(s, "{:<w$}  {:>5} {:>5}  {:>5.1}%", "total", t.hit, t.total, t.percent());
    for g in groups.iter().filter(|g| g.hit < g.total) {
        let _ = writeln!(s, "holes in {} ({}): {}", g.group, g.total - g.hit, compact_holes(c, &g.group).join(", "));
    }
    // Unreachable bins: not counted, each group's with its reason.
    let mut by_reason: Vec<((&str, &str), Vec<&Bin>)> = Vec::new();
    for b in c.unreachable() {
        let key = (b.group.as_str(), b.unreachable.as_deref().unwrap_or(""));
        match by_reason.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(b),
            None => by_reason.push((key, vec![b])),
        }
    }
    let n: usize = by_reason.iter().map(|(_, v)| v.len()).sum();
    if n > 0 {
        let _ = writeln!(s, "unreachable, not counted ({n} bins):");
        for ((group, reason), bins) in &by_reason {
            let _ = writeln!(s, "  {group} ({}): {}: {reason}", bins.len(), compact(bins.iter().copied()).join(", "));
        }
    }
    let hit: Vec<String> = c.unreachable().filter(|b| b.hits > 0).map(|b| format!("{}: {} (x{})", b.group, b.name, b.hits)).collect();
    if !hit.is_empty() {
        let _ = writeln!(s, "HIT ALTHOUGH MARKED UNREACHABLE ({}; the reason or the model is wrong): {}", hit.len(), hit.join("; "));
    }
    let unlisted: Vec<String> = c.unlisted().map(|b| format!("{}: {} (x{})", b.group, b.name, b.hits)).collect();
    if !unlisted.is_empty() {
        let _ = writeln!(s, "seen outside the bin model ({}): {}", unlisted.len(), unlisted.join("; "));
    }
    s
}

/// The holes of a group by name; register bits folded per register and
/// value: `ACR0 =1 bits 7-0`, `IER =0 bits 3,1`.
pub(crate) fn compact_holes(c: &Coverage, group: &str) -> Vec<String> {
    compact(c.holes().filter(|b| b.group == group))
}

/// Bin names, register bits folded per register and value.
fn compact<'a>(bins: impl Iterator<Item = &'a Bin>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    // (register, value) -> bits, in first-seen order.
    let mut regs: Vec<((String, char), Vec<u8>)> = Vec::new();
    for b in bins {
        let parsed = b.name.split_once(" bit ").and_then(|(reg, rest)| {
            let (bit, v) = rest.split_once('=')?;
            Some((reg.to_string(), bit.parse::<u8>().ok()?, v.chars().next()?))
        });
        match parsed {
            Some((reg, bit, v)) => match regs.iter_mut().find(|(k, _)| k.0 == reg && k.1 == v) {
                Some((_, bits)) => bits.push(bit),
                None => regs.push(((reg, v), vec![bit])),
            },
            None => out.push(b.name.clone()),
        }
    }
    for ((reg, v), bits) in regs {
        let contiguous = bits.windows(2).all(|w| w[0] == w[1] + 1);
        let list = if bits.len() > 2 && contiguous {
            format!("{}-{}", bits[0], bits[bits.len() - 1])
        } else {
            bits.iter().map(|b| b.to_string()).collect::<Vec<_>>().join(",")
        };
        out.push(format!("{reg} ={v} bit{} {list}", if bits.len() > 1 { "s" } else { "" }));
    }
    out
}
