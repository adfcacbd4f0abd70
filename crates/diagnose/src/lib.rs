//! The diagnoser: turns the [`RunRecord`] of a co-simulation run (first
//! divergence, stuck transfer, host-bus violation, failed expectation) into
//! what happened, the root cause in plain words, and the fix.
//!
//! Each rule is a small function in [`rules`] that looks at the record and
//! returns a [`Finding`] or nothing; [`diagnose`] runs them in priority order,
//! keeps the first as the diagnosis and lists the others under `also`.
#![warn(missing_docs)]

pub mod named;
pub mod record;
pub mod rules;

pub use record::*;

use can_proto::Field;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// The cause category of a diagnosis; stable names, used by scenario files
/// (`expect.category = "RxNotFollowingTx"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, PartialOrd, Ord)]
pub enum Category {
    /// Nothing went wrong.
    Pass,
    /// The run itself failed (DUT did not build, simulator error, timeout).
    RunError,
    /// A host access never completed (no ack from the DUT).
    HostBusTimeout,
    /// The host-bus protocol monitor saw a violation.
    HostBusViolation,
    /// The program addressed a register of the other mode (BasicCAN vs PeliCAN).
    AddressModeConfusion,
    /// Configuration registers written outside reset mode were ignored.
    ConfigWriteOutsideReset,
    /// The TX buffer was written while locked (SR.TBS = 0) and the write ignored.
    TxBufferWriteWhileLocked,
    /// rx_i does not follow tx_o (rx tied, no transceiver loopback).
    RxNotFollowingTx,
    /// No node acknowledges and the DUT is not in self-test mode.
    NoAcknowledge,
    /// Nodes on the bus use different bit rates or sample points.
    BitTimingMismatch,
    /// The DUT deviates from the golden model (an HDL bug).
    DutDeviatesFromModel,
    /// A scenario expectation failed and no other rule explains it.
    ExpectationFailed,
    /// A transmission never completed and no rule explains why.
    StuckTransfer,
}

impl Category {
    /// Every category.
    pub const ALL: [Category; 13] = [
        Category::Pass,
        Category::RunError,
        Category::HostBusTimeout,
        Category::HostBusViolation,
        Category::AddressModeConfusion,
        Category::ConfigWriteOutsideReset,
        Category::TxBufferWriteWhileLocked,
        Category::RxNotFollowingTx,
        Category::NoAcknowledge,
        Category::BitTimingMismatch,
        Category::DutDeviatesFromModel,
        Category::ExpectationFailed,
        Category::StuckTransfer,
    ];

    /// The name as written in scenario files and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Category::Pass => "Pass",
            Category::RunError => "RunError",
            Category::HostBusTimeout => "HostBusTimeout",
            Category::HostBusViolation => "HostBusViolation",
            Category::AddressModeConfusion => "AddressModeConfusion",
            Category::ConfigWriteOutsideReset => "ConfigWriteOutsideReset",
            Category::TxBufferWriteWhileLocked => "TxBufferWriteWhileLocked",
            Category::RxNotFollowingTx => "RxNotFollowingTx",
            Category::NoAcknowledge => "NoAcknowledge",
            Category::BitTimingMismatch => "BitTimingMismatch",
            Category::DutDeviatesFromModel => "DutDeviatesFromModel",
            Category::ExpectationFailed => "ExpectationFailed",
            Category::StuckTransfer => "StuckTransfer",
        }
    }

    /// Parses a category name.
    pub fn from_name(s: &str) -> Option<Category> {
        Category::ALL.into_iter().find(|c| c.name() == s)
    }
}

impl std::fmt::Display for Category {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The key numbers behind a diagnosis.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Figures {
    /// Frame (attempt) number, from 1.
    pub frame: Option<u32>,
    /// CAN field.
    #[serde(with = "named::opt", default)]
    pub field: Option<Field>,
    /// Bit index since the start of the run.
    pub bit: Option<u64>,
    /// What the model / the rule expected.
    pub expected: Option<String>,
    /// What was seen.
    pub seen: Option<String>,
    /// DUT TEC at the end (or at the plateau).
    pub tec: Option<u16>,
    /// DUT REC at the end.
    pub rec: Option<u16>,
    /// DUT SR at the end.
    pub sr: Option<u8>,
    /// TEC after the first attempt.
    pub first_attempt_tec: Option<u16>,
    /// Transmission attempts seen.
    pub attempts: Option<u32>,
    /// Attempt during which the DUT went bus-off.
    pub bus_off_attempt: Option<u32>,
    /// Register involved.
    pub register: Option<String>,
    /// Address involved.
    pub addr: Option<u8>,
    /// The TEC-trace figures (`first_attempt_tec`, `attempts`,
    /// `bus_off_attempt`, and `tec` when no DUT read gave it) are the
    /// model's, not the DUT's: the record has no DUT trace, and only the
    /// model's attempts before the first divergence are used (in lockstep
    /// the two agreed up to there). The report says so.
    #[serde(default)]
    pub counts_from_model: bool,
    /// `tec` (and `rec`) come from the model, not from a DUT register read.
    #[serde(default)]
    pub tec_from_model: bool,
}

/// One rule's conclusion.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Finding {
    /// Category.
    pub category: Category,
    /// What happened, with the numbers.
    pub what_happened: String,
    /// The root cause in plain words.
    pub root_cause: String,
    /// What to change.
    pub fix: String,
    /// Key figures.
    pub figures: Figures,
    /// A remark that does not make the run fail on its own (listed under
    /// `also`, never the diagnosis).
    #[serde(default)]
    pub advisory: bool,
}

/// The diagnoser's report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Diagnosis {
    /// Scenario name.
    pub scenario: String,
    /// DUT name.
    pub dut: String,
    /// Primary cause.
    pub category: Category,
    /// What happened, with the numbers.
    pub what_happened: String,
    /// The root cause in plain words.
    pub root_cause: String,
    /// What to change.
    pub fix: String,
    /// Key figures.
    pub figures: Figures,
    /// Where the DUT's error counts differ from the strict CAN 2.0B counts
    /// of the model: which rule makes the difference.
    pub counts_note: Option<String>,
    /// Other findings, in priority order.
    pub also: Vec<Finding>,
    /// Known deviations of the DUT that waivers let through in this run:
    /// the run's outcome holds them, so the report names them.
    #[serde(default)]
    pub waived: Vec<WaivedDeviation>,
}

impl Diagnosis {
    /// Short report for people.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "{} on {}: {}", self.scenario, self.dut, self.category);
        if self.category == Category::Pass {
            let _ = writeln!(s, "  {}", self.what_happened);
            for a in &self.also {
                let _ = writeln!(s, "  Note ({}): {}", a.category, a.what_happened);
            }
            self.write_waived(&mut s);
            return s;
        }
        let _ = writeln!(s, "What happened: {}", self.what_happened);
        let f = &self.figures;
        let mut figs = Vec::new();
        if let Some(v) = f.frame {
            figs.push(format!("frame {v}"));
        }
        if let Some(v) = f.field {
            figs.push(format!("field {v}"));
        }
        if let Some(v) = f.bit {
            figs.push(format!("bit {v}"));
        }
        if let (Some(e), Some(g)) = (&f.expected, &f.seen) {
            figs.push(format!("expected {e}, seen {g}"));
        }
        // Figures from the model's trace are marked as the model's.
        let model = if f.counts_from_model { " (the model's)" } else { "" };
        if let Some(v) = f.first_attempt_tec {
            figs.push(format!("TEC after attempt 1 = {v}{model}"));
        }
        if let Some(v) = f.tec {
            let whose = if f.tec_from_model { " (the model's)" } else { "" };
            figs.push(format!("TEC {v}{whose}"));
        }
        if let Some(v) = f.rec {
            let whose = if f.tec_from_model { " (the model's)" } else { "" };
            figs.push(format!("REC {v}{whose}"));
        }
        if let Some(v) = f.attempts {
            figs.push(format!("{v} attempts{model}"));
        }
        if let Some(v) = f.bus_off_attempt {
            figs.push(format!("bus-off in attempt {v}{model}"));
        }
        if let Some(v) = f.sr {
            figs.push(format!("SR {}", sr::describe(v)));
        }
        if let Some(v) = &f.register {
            figs.push(format!("register {v}"));
        }
        if let Some(v) = f.addr {
            figs.push(format!("address {v} (0x{v:02X})"));
        }
        if !figs.is_empty() {
            let _ = writeln!(s, "Figures: {}", figs.join("; "));
        }
        let _ = writeln!(s, "Root cause: {}", self.root_cause);
        let _ = writeln!(s, "Fix: {}", self.fix);
        if let Some(n) = &self.counts_note {
            let _ = writeln!(s, "Counts vs CAN 2.0B: {n}");
        }
        for a in &self.also {
            let _ = writeln!(s, "Also ({}): {}", a.category, a.what_happened);
        }
        self.write_waived(&mut s);
        s
    }

    /// One line per waived deviation: what the core showed, in words.
    fn write_waived(&self, s: &mut String) {
        for w in &self.waived {
            let _ = writeln!(
                s,
                "Waived: {}; {} divergence(s){}, a known deviation of this core",
                lower_first(&w.describe()),
                w.hits,
                w.bound_text()
            );
        }
    }

    /// Report for tools.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a Diagnosis always serialises")
    }
}

/// Runs every rule on `r`; the first finding in priority order is the diagnosis.
pub fn diagnose(r: &RunRecord) -> Diagnosis {
    let mut findings = rules::all(r);
    let counts_note = rules::counts_note(r);
    let Some(primary) = findings.iter().position(|f| !f.advisory) else {
        return Diagnosis {
            scenario: r.scenario.clone(),
            dut: r.dut.clone(),
            category: Category::Pass,
            what_happened: format!(
                "no divergence from the golden model, no stuck transfer, no host-bus violation, {} expectation(s) held",
                r.expectations.len()
            ),
            root_cause: String::new(),
            fix: String::new(),
            figures: rules::base_figures(r),
            counts_note,
            also: findings,
            waived: r.waived.clone(),
        };
    };
    let first = findings.remove(primary);
    Diagnosis {
        scenario: r.scenario.clone(),
        dut: r.dut.clone(),
        category: first.category,
        what_happened: first.what_happened,
        root_cause: first.root_cause,
        fix: first.fix,
        figures: first.figures,
        counts_note,
        also: findings,
        waived: r.waived.clone(),
    }
}

/// `The core ...` -> `the core ...` (a summary after "Waived: ").
fn lower_first(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) if f.is_uppercase() && c.clone().next().is_some_and(char::is_lowercase) => f.to_lowercase().chain(c).collect(),
        _ => s.to_string(),
    }
}
