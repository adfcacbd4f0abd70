//! Two revisions of a core side by side (`cancosim regress --baseline OLD=...
//! --external NEW=...`): per scenario fixed, broken, still failing (at the
//! same first divergence or another), or still passing.

use crate::regress::{RegressReport, Status};

/// What changed for one scenario from the baseline to the new core.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Change {
    /// Failed on the baseline, passes now.
    Fixed,
    /// Passed on the baseline, fails now.
    Broken,
    /// Fails on both with the same verdict (same first divergence).
    StillFailingSame,
    /// Fails on both, differently.
    StillFailingDifferent,
    /// Passes (or is skipped) on both.
    StillPassing,
}

impl Change {
    /// In words, for the table.
    pub fn words(&self) -> &'static str {
        match self {
            Change::Fixed => "fixed",
            Change::Broken => "BROKEN",
            Change::StillFailingSame => "still failing (same first divergence)",
            Change::StillFailingDifferent => "still failing (different first divergence)",
            Change::StillPassing => "still passing",
        }
    }
}

/// One scenario's row.
#[derive(Clone, Debug)]
pub struct DiffRow {
    /// Scenario.
    pub scenario: String,
    /// What changed.
    pub change: Change,
    /// Verdict on the baseline.
    pub old: Status,
    /// Verdict on the new core.
    pub new: Status,
}

/// Classifies one scenario from its two verdicts.
pub fn classify(old: &Status, new: &Status) -> Change {
    match (old.ok(), new.ok()) {
        (true, true) => Change::StillPassing,
        (false, true) => Change::Fixed,
        (true, false) => Change::Broken,
        (false, false) if old == new => Change::StillFailingSame,
        (false, false) => Change::StillFailingDifferent,
    }
}

/// The rows for every scenario both DUT columns ran, in the report's order.
pub fn diff(report: &RegressReport, old: &str, new: &str) -> Vec<DiffRow> {
    let cell = |s: &str, d: &str| report.cells.iter().find(|c| c.scenario == s && c.dut == d);
    report
        .scenarios
        .iter()
        .filter_map(|s| {
            let (o, n) = (cell(s, old)?, cell(s, new)?);
            Some(DiffRow { scenario: s.clone(), change: classify(&o.status, &n.status), old: o.status.clone(), new: n.status.clone() })
        })
        .collect()
}

/// True if a scenario that passed on the baseline fails on the new core.
pub fn any_broken(rows: &[DiffRow]) -> bool {
    rows.iter().any(|r| r.change == Change::Broken)
}

fn status_words(s: &Status) -> String {
    match s {
        Status::Pass => "pass".into(),
        Status::Diverged(w) => format!("diverged: {w}"),
        Status::Failed(w) => format!("failed: {w}"),
        Status::Error(w) => format!("error: {}", w.lines().next().unwrap_or("")),
        Status::Skipped(_) => "skipped".into(),
        Status::ExpectedFailure { id, deviation } => format!("expected failure ({deviation}: {id})"),
        Status::UnexpectedPass { id } => format!("unexpected pass ({id})"),
        Status::WrongFailure { id, .. } => format!("failed, not as {id}"),
    }
}

/// The table: one line per scenario, then the counts.
pub fn to_text(rows: &[DiffRow], old: &str, new: &str) -> String {
    let mut t = format!("{old} -> {new}\n");
    let w = rows.iter().map(|r| r.scenario.len()).max().unwrap_or(8);
    for r in rows {
        t += &format!("{:<w$}  {}", r.scenario, r.change.words());
        if r.change != Change::StillPassing {
            t += &format!("  [{} -> {}]", status_words(&r.old), status_words(&r.new));
        }
        t += "\n";
    }
    let n = |c: Change| rows.iter().filter(|r| r.change == c).count();
    t += &format!(
        "{} fixed, {} broken, {} still failing ({} same first divergence), {} still passing\n",
        n(Change::Fixed),
        n(Change::Broken),
        n(Change::StillFailingSame) + n(Change::StillFailingDifferent),
        n(Change::StillFailingSame),
        n(Change::StillPassing)
    );
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_pair_of_verdicts_has_its_change() {
        let d = |w: &str| Status::Diverged(w.into());
        assert_eq!(classify(&Status::Pass, &Status::Pass), Change::StillPassing);
        assert_eq!(classify(&Status::Skipped("x".into()), &Status::Pass), Change::StillPassing);
        assert_eq!(classify(&d("Eof frame 2"), &Status::Pass), Change::Fixed);
        assert_eq!(classify(&Status::Pass, &d("Eof frame 2")), Change::Broken);
        assert_eq!(classify(&Status::Pass, &Status::Error("no build".into())), Change::Broken);
        assert_eq!(classify(&d("Eof frame 2"), &d("Eof frame 2")), Change::StillFailingSame);
        assert_eq!(classify(&d("Eof frame 2"), &d("Crc frame 1")), Change::StillFailingDifferent);
        assert_eq!(classify(&Status::Failed("SR".into()), &d("Crc frame 1")), Change::StillFailingDifferent);
    }
}
