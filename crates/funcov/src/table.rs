//! The text report: groups with holes first, then the holes by name.

use crate::Coverage;
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
        let holes: Vec<&str> = c.holes().filter(|b| b.group == g.group).map(|b| b.name.as_str()).collect();
        let _ = writeln!(s, "holes in {} ({}): {}", g.group, holes.len(), holes.join(", "));
    }
    let unlisted: Vec<String> = c.unlisted().map(|b| format!("{}: {} (x{})", b.group, b.name, b.hits)).collect();
    if !unlisted.is_empty() {
        let _ = writeln!(s, "seen outside the bin model ({}): {}", unlisted.len(), unlisted.join("; "));
    }
    s
}
