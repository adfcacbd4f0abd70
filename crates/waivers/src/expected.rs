//! Strict expected failures: a scenario that fails on a DUT for
//! a documented deviation the golden model will not imitate, and that no
//! waiver should swallow, is declared with its exact failure SIGNATURE.
//!
//! ```toml
//! [[expected-failure]]
//! id = "basic-gts-transmits"             # unique among expected failures
//! scenario = "basic-sleep-wakeup"        # the scenario's `name`
//! dut = ["opencores-can (*)"]            # DUT name globs, as for waivers
//! host = "wishbone"                      # optional: the run's host (its own or --host):
//!                                        # wishbone, avalon, avalon-begintransfer, pio, pio-edge, i8051;
//!                                        # a list of them is accepted; absent: any host
//! revisions = ["r3.."]                   # optional, as for waivers
//! deviation = "D6"                       # row of docs/opencores-deviations.md
//! clause = "datasheet §6.3.4, Table 4 (BasicCAN CMR.4 GTS)"
//! reason = "in plain words: why the scenario fails and why this is not waived"
//! signature = [
//!   "divergence tx-bit at bit 17 (frame 1, BusIdle): model 1, DUT 0",
//!   "divergence register-read IR at bit 66 (Intermission): model 0xF0, DUT 0xE2",
//!   "expectation step 14: IR & 0xFF expected 0xF0 (mask 0xFF), seen 0xE2",
//!   "verdict category: expected Pass, diagnosed DutDeviatesFromModel",
//! ]
//! ```
//!
//! The signature is the SET of distinct lines the run shows, judged in
//! collect mode (the whole scenario, not its first divergence), one per:
//!
//! - `divergence ...`: an unwaived divergence ([`signature_line`]): kind,
//!   register (register reads), bit time, frame and CAN field the model was
//!   in, the model's and the DUT's value. Later repeats the comparator does
//!   not list again are not lines.
//! - `expectation step N: ...`: a scenario expectation that failed and that
//!   no waiver took (what, expected, seen, as the run record has them).
//! - `verdict ...`: each way the outcome missed the scenario's `[expect]`
//!   (diagnosis category, frame counts, the number of unwaived divergences).
//!
//! With `place = "step"` an entry places each divergence by the scenario
//! step it happened in, not by its bit time, so one entry holds for every
//! host: a slower host moves every read and every bus event it starts by
//! some bits, never to another step. A register read is then `divergence
//! register-read SR in step 12: model 0x3C, DUT 0x0C` (the read's value
//! pins it down inside the step); a tx bit or a pin keeps the frame and the
//! field it fell in, `divergence tx-bit in step 9 (frame 1, BaseId): model
//! 1, DUT 0`. Before the first step it is `before the steps`, after the last
//! `after the steps`. What `place = "step"` gives up: a divergence that moves
//! inside one step (for a bus event, inside one field of one frame) keeps its
//! line. Default `place = "bit"`: the lines above.
//!
//! Order does not matter; whitespace runs count as one space. The runner
//! (`cancosim regress`) counts a scenario an expected failure only if its
//! lines are exactly these: a pass is an UNEXPECTED PASS (the entry is stale)
//! and any missing or extra line is a failure, printed as a diff. Write a
//! signature with `cancosim regress --record-expected-failures FILE`, which
//! prints entries to paste; nothing rewrites a waiver file by itself.

use std::collections::BTreeSet;

use diagnose::{Divergence, DivergenceKind};
use serde::{Deserialize, Serialize};
use toml::Spanned;

use crate::file::{DutGlob, KindName, RevRange, WaiverError};
use crate::dut::DutInfo;

/// The hosts an entry may name (as `cancosim --host` and `[host] bfm` spell them).
pub const HOSTS: &[&str] = &["wishbone", "avalon", "avalon-begintransfer", "pio", "pio-edge", "i8051", "axi4-lite", "apb", "apb3", "motorola", "regport"];

/// The kinds of signature line, by their first word.
pub const LINE_KINDS: &[&str] = &["divergence", "expectation", "verdict"];

/// One host or several (`host = "wishbone"` or `host = ["wishbone", "avalon"]`).
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(untagged)]
pub(crate) enum OneOrMany {
    One(String),
    Many(Vec<String>),
}

/// `[[expected-failure]]`: a scenario that fails on a DUT for a documented deviation
/// the model will not imitate, with the exact set of lines its failure shows.
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub(crate) struct RawExpectedFailure {
    /// Unique id among the file's expected failures. Required.
    #[schemars(with = "String")]
    pub id: Spanned<String>,
    /// The scenario's `name`. Required.
    #[schemars(with = "String")]
    pub scenario: Spanned<String>,
    /// DUT name globs, as for waivers (matched through the DUT's profile family too). Required.
    #[schemars(with = "Vec<String>")]
    pub dut: Spanned<Vec<DutGlob>>,
    /// Revision ranges, as for waivers. Default: any revision.
    #[serde(default)]
    #[schemars(with = "Vec<String>")]
    pub revisions: Vec<RevRange>,
    /// The run's host bus (its own or `--host`): `wishbone`, `avalon`,
    /// `avalon-begintransfer`, `pio`, `pio-edge`, `i8051`, or a list of them. Default: any host.
    #[schemars(with = "Option<OneOrMany>")]
    pub host: Option<Spanned<OneOrMany>>,
    /// The deviation's row in the deviations table (`"D6"`). Required, not empty.
    #[schemars(with = "String")]
    pub deviation: Spanned<String>,
    /// The datasheet or CAN 2.0B clause the deviation breaks. Required, not empty.
    #[schemars(with = "String")]
    pub clause: Spanned<String>,
    /// Why the scenario fails and why this is not waived, in plain words. Required, not empty.
    #[schemars(with = "String")]
    pub reason: Spanned<String>,
    /// The set of lines the run shows (`divergence ...`, `expectation step N: ...`,
    /// `verdict ...`); order does not matter. Write it with
    /// `cancosim regress --record-expected-failures FILE`. Required.
    #[schemars(with = "Vec<String>")]
    pub signature: Spanned<Vec<Spanned<String>>>,
    /// Where a divergence line places it: `bit` (its bit time, the default)
    /// or `step` (the scenario step it happened in: the same line on every
    /// host).
    #[schemars(with = "Option<String>")]
    pub place: Option<Spanned<String>>,
}

/// How a signature's divergence lines say where they happened.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Place {
    /// `at bit N (frame f, Field)`: exact, but a slower host moves it.
    #[default]
    Bit,
    /// `in step N` (register reads) or `in step N (frame f, Field)`: the same on every host.
    Step,
}

impl Place {
    /// `bit` or `step`, as the file spells it.
    pub fn as_str(self) -> &'static str {
        match self {
            Place::Bit => "bit",
            Place::Step => "step",
        }
    }
}

/// Where in a scenario's program a divergence happened (for [`Place::Step`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepAt {
    /// Before the first step (the reset sequence).
    Before,
    /// During step N (1-based, the scenario's step number).
    In(usize),
    /// After the last step (the run-out).
    After,
}

/// A validated `[[expected-failure]]` entry.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExpectedFailure {
    /// Unique id.
    pub id: String,
    /// Scenario name.
    pub scenario: String,
    /// DUT name globs.
    pub dut: Vec<DutGlob>,
    /// Revision ranges (empty: any).
    pub revisions: Vec<RevRange>,
    /// Hosts it is for (empty: any).
    pub hosts: Vec<String>,
    /// Deviation row, e.g. `D6`.
    pub deviation: String,
    /// The datasheet / CAN 2.0B clause the deviation breaks.
    pub clause: String,
    /// Why, in plain words.
    pub reason: String,
    /// The signature lines, normalised, in file order.
    pub signature: Vec<String>,
    /// How its divergence lines are placed.
    pub place: Place,
    /// File it comes from.
    pub file: String,
    /// Line of its `id`.
    pub line: usize,
}

/// What a run showed against an entry's signature.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SignatureDiff {
    /// Lines of the entry the run did not show.
    pub missing: Vec<String>,
    /// Lines the run showed that the entry does not have.
    pub extra: Vec<String>,
}

impl SignatureDiff {
    /// The run showed exactly the signature.
    pub fn is_exact(&self) -> bool {
        self.missing.is_empty() && self.extra.is_empty()
    }

    /// `- line` for each missing, `+ line` for each extra, one per line.
    pub fn to_text(&self) -> String {
        let mut s = String::new();
        for l in &self.missing {
            s += &format!("- {l}\n");
        }
        for l in &self.extra {
            s += &format!("+ {l}\n");
        }
        s
    }
}

/// Whitespace runs as one space, ends trimmed.
pub fn normalise(line: &str) -> String {
    line.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The signature line of an unwaived divergence: `divergence <kind>[
/// <register>] at bit <n> (frame <f>, <field>): model <v>, DUT <v>`
/// (register values in hex; a divergence without a bit gives its time).
pub fn signature_line(d: &Divergence) -> String {
    let mut s = format!("divergence {}", KindName::of(d.kind).as_str());
    if let Some(r) = &d.register {
        s += &format!(" {r}");
    }
    match d.bit {
        Some(b) => s += &format!(" at bit {b}"),
        None => s += &format!(" at {} ps", d.time_ps),
    }
    let place: Vec<String> = d.frame.map(|f| format!("frame {f}")).into_iter().chain(d.field.map(|f| format!("{f:?}"))).collect();
    if !place.is_empty() {
        s += &format!(" ({})", place.join(", "));
    }
    match d.kind {
        DivergenceKind::RegisterRead => s += &format!(": model 0x{:02X}, DUT 0x{:02X}", d.expected, d.seen),
        _ => s += &format!(": model {}, DUT {}", d.expected, d.seen),
    }
    s
}

/// [`signature_line`] placed by step ([`Place::Step`]): a register read by
/// its step alone, another kind by its step, frame and field.
pub fn signature_line_in_step(d: &Divergence, at: StepAt) -> String {
    let mut s = format!("divergence {}", KindName::of(d.kind).as_str());
    if let Some(r) = &d.register {
        s += &format!(" {r}");
    }
    s += &match at {
        StepAt::Before => " before the steps".to_string(),
        StepAt::In(n) => format!(" in step {n}"),
        StepAt::After => " after the steps".to_string(),
    };
    match d.kind {
        DivergenceKind::RegisterRead => s += &format!(": model 0x{:02X}, DUT 0x{:02X}", d.expected, d.seen),
        _ => {
            let place: Vec<String> = d.frame.map(|f| format!("frame {f}")).into_iter().chain(d.field.map(|f| format!("{f:?}"))).collect();
            if !place.is_empty() {
                s += &format!(" ({})", place.join(", "));
            }
            s += &format!(": model {}, DUT {}", d.expected, d.seen);
        }
    }
    s
}

impl ExpectedFailure {
    /// True if the entry is for this DUT (name glob, through the DUT's
    /// profile family too, and revision range).
    pub fn applies_to(&self, dut: &DutInfo) -> bool {
        dut.matched_by(&self.dut, &self.revisions).is_some()
    }

    /// True if the entry is for a run of `scenario` through `host`.
    pub fn is_for(&self, scenario: &str, host: &str) -> bool {
        self.scenario == scenario && (self.hosts.is_empty() || self.hosts.iter().any(|h| h == host))
    }

    /// The signature's lines a run did not show and the run's lines it does not have.
    pub fn diff(&self, seen: &[String]) -> SignatureDiff {
        let want: BTreeSet<String> = self.signature.iter().cloned().collect();
        let got: BTreeSet<String> = seen.iter().map(|l| normalise(l)).collect();
        SignatureDiff {
            missing: self.signature.iter().filter(|l| !got.contains(*l)).cloned().collect(),
            extra: {
                let mut e: Vec<String> = Vec::new();
                for l in seen.iter().map(|l| normalise(l)) {
                    if !want.contains(&l) && !e.contains(&l) {
                        e.push(l);
                    }
                }
                e
            },
        }
    }

    /// `file:line`.
    pub fn location(&self) -> String {
        format!("{}:{}", self.file, self.line)
    }
}

fn invalid(file: &str, line: usize, key: &str, message: impl Into<String>) -> WaiverError {
    WaiverError::Invalid { file: file.into(), line, key: key.into(), message: message.into() }
}

/// Validates one raw entry (`src` gives the lines).
pub(crate) fn validate(file: &str, src: &str, raw: RawExpectedFailure) -> Result<ExpectedFailure, WaiverError> {
    let at = |span: std::ops::Range<usize>| crate::file::line_of(src, span.start);
    let line = at(raw.id.span());
    let text = |key: &str, v: &Spanned<String>, what: &str| -> Result<String, WaiverError> {
        let t = v.get_ref().trim();
        if t.is_empty() {
            return Err(invalid(file, at(v.span()), key, format!("empty: {what}")));
        }
        Ok(t.to_string())
    };
    let id = text("id", &raw.id, "a unique name for the entry")?;
    let scenario = text("scenario", &raw.scenario, "the scenario's `name`")?;
    let deviation = text("deviation", &raw.deviation, "the deviation's row, e.g. \"D6\" (docs/opencores-deviations.md)")?;
    let clause = text("clause", &raw.clause, "the datasheet or CAN 2.0B clause the deviation breaks")?;
    let reason = text("reason", &raw.reason, "why the scenario fails, in plain words")?;
    if raw.dut.get_ref().is_empty() {
        return Err(invalid(file, at(raw.dut.span()), "dut", "at least one DUT name glob"));
    }
    let hosts = match &raw.host {
        None => Vec::new(),
        Some(h) => {
            let list = match h.get_ref() {
                OneOrMany::One(s) => vec![s.clone()],
                OneOrMany::Many(v) => v.clone(),
            };
            if list.is_empty() {
                return Err(invalid(file, at(h.span()), "host", "an empty list matches no run: leave `host` out for any host"));
            }
            for x in &list {
                if !HOSTS.contains(&x.as_str()) {
                    return Err(invalid(file, at(h.span()), "host", format!("unknown host `{x}`, expected one of {}", HOSTS.join(", "))));
                }
            }
            list
        }
    };
    if raw.signature.get_ref().is_empty() {
        return Err(invalid(
            file,
            at(raw.signature.span()),
            "signature",
            "empty: an expected failure lists the lines its run shows (cancosim regress --record-expected-failures FILE writes them)",
        ));
    }
    let place = match &raw.place {
        None => Place::Bit,
        Some(p) => match p.get_ref().as_str() {
            "bit" => Place::Bit,
            "step" => Place::Step,
            other => return Err(invalid(file, at(p.span()), "place", format!("unknown place `{other}`, expected `bit` or `step`"))),
        },
    };
    let mut signature = Vec::new();
    for l in raw.signature.get_ref() {
        let n = normalise(l.get_ref());
        let first = n.split(' ').next().unwrap_or("");
        if !LINE_KINDS.contains(&first) {
            return Err(invalid(
                file,
                at(l.span()),
                "signature",
                format!("line `{n}` must start with one of: {}", LINE_KINDS.join(", ")),
            ));
        }
        if n.split(' ').count() < 2 {
            return Err(invalid(file, at(l.span()), "signature", format!("line `{n}` says nothing after `{first}`")));
        }
        if signature.contains(&n) {
            return Err(invalid(file, at(l.span()), "signature", format!("line `{n}` given twice (the signature is a set)")));
        }
        signature.push(n);
    }
    Ok(ExpectedFailure {
        id,
        scenario,
        dut: raw.dut.into_inner(),
        revisions: raw.revisions,
        hosts,
        deviation,
        clause,
        reason,
        signature,
        place,
        file: file.into(),
        line,
    })
}

/// An entry to paste into a waiver file, as TOML text, for a run of
/// `scenario` on `dut` through `host` that showed `signature`. `like`: an
/// existing entry whose texts are kept (a re-recorded signature); without
/// it the texts are left empty, so the entry does not load until filled in.
/// `place`: how `signature`'s divergence lines are placed (written as
/// `place = "step"` when not the default).
pub fn to_toml(scenario: &str, dut: &str, host: &str, signature: &[String], place: Place, like: Option<&ExpectedFailure>) -> String {
    let q = |s: &str| toml::Value::String(s.to_string()).to_string();
    let mut s = String::from("[[expected-failure]]\n");
    match like {
        Some(e) => {
            s += &format!("id = {}\n", q(&e.id));
            s += &format!("scenario = {}\n", q(scenario));
            let globs: Vec<String> = e.dut.iter().map(|g| q(&String::from(g.clone()))).collect();
            s += &format!("dut = [{}]\n", globs.join(", "));
            if !e.revisions.is_empty() {
                let r: Vec<String> = e.revisions.iter().map(|r| q(&r.to_string())).collect();
                s += &format!("revisions = [{}]\n", r.join(", "));
            }
            s += &format!("host = {}\n", q(host));
            s += &format!("deviation = {}\n", q(&e.deviation));
            s += &format!("clause = {}\n", q(&e.clause));
            s += &format!("reason = {}\n", q(&e.reason));
        }
        None => {
            s += &format!("id = {}\n", q(&format!("{scenario}-{host}")));
            s += &format!("scenario = {}\n", q(scenario));
            // "<profile> (<dir>)": any directory of that profile's core.
            let glob = match dut.split_once(" (") {
                Some((profile, _)) if dut.ends_with(')') => format!("{profile} (*)"),
                _ => dut.to_string(),
            };
            s += &format!("dut = [{}]\n", q(&glob));
            s += &format!("host = {}\n", q(host));
            s += "# Fill in before use (an empty one is an error): the deviation's row in the\n";
            s += "# deviations table, the clause it breaks, and why this is an expected failure.\n";
            s += "deviation = \"\"\nclause = \"\"\nreason = \"\"\n";
        }
    }
    if place != Place::Bit {
        s += &format!("place = {}\n", q(place.as_str()));
    }
    s += "signature = [\n";
    for l in signature {
        s += &format!("    {},\n", q(&normalise(l)));
    }
    s += "]\n";
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::WaiverSet;

    const ENTRY: &str = r#"
[[expected-failure]]
id = "gts"
scenario = "basic-sleep-wakeup"
dut = ["opencores-can (*)"]
host = ["wishbone", "avalon"]
deviation = "D6"
clause = "datasheet Table 4"
reason = "GTS transmits"
signature = [
    "divergence tx-bit   at bit 17 (frame 1, BusIdle): model 1, DUT 0",
    "verdict category: expected Pass, diagnosed DutDeviatesFromModel",
]
"#;

    #[test]
    fn an_entry_loads_with_its_hosts_dut_and_normalised_signature() {
        let set = WaiverSet::parse(ENTRY, "w.toml").unwrap();
        let e = &set.expected_failures()[0];
        assert_eq!((e.id.as_str(), e.deviation.as_str(), e.line), ("gts", "D6", 3));
        assert_eq!(e.signature[0], "divergence tx-bit at bit 17 (frame 1, BusIdle): model 1, DUT 0");
        assert!(e.is_for("basic-sleep-wakeup", "avalon") && !e.is_for("basic-sleep-wakeup", "pio") && !e.is_for("basic-overrun-abort", "wishbone"));
        assert!(e.applies_to(&DutInfo::new("opencores-can (/x)")) && !e.applies_to(&DutInfo::new("rtl")));
        assert!(set.waivers().is_empty());
        let one = WaiverSet::parse(&ENTRY.replace("host = [\"wishbone\", \"avalon\"]", "host = \"pio\""), "w.toml").unwrap();
        assert_eq!(one.expected_failures()[0].hosts, ["pio"]);
        let any = WaiverSet::parse(&ENTRY.replace("host = [\"wishbone\", \"avalon\"]\n", ""), "w.toml").unwrap();
        assert!(any.expected_failures()[0].is_for("basic-sleep-wakeup", "i8051"));
    }

    #[test]
    fn the_diff_is_a_set_difference() {
        let e = WaiverSet::parse(ENTRY, "w.toml").unwrap().expected_failures()[0].clone();
        let seen = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let exact = e.diff(&seen(&["verdict category: expected Pass, diagnosed DutDeviatesFromModel", "divergence tx-bit at bit 17 (frame 1, BusIdle): model 1, DUT 0"]));
        assert!(exact.is_exact(), "{exact:?}");
        let d = e.diff(&seen(&["divergence tx-bit at bit 18 (frame 1, BusIdle): model 1, DUT 0", "verdict category: expected Pass, diagnosed DutDeviatesFromModel"]));
        assert_eq!(d.missing, ["divergence tx-bit at bit 17 (frame 1, BusIdle): model 1, DUT 0"]);
        assert_eq!(d.extra, ["divergence tx-bit at bit 18 (frame 1, BusIdle): model 1, DUT 0"]);
        assert_eq!(d.to_text(), "- divergence tx-bit at bit 17 (frame 1, BusIdle): model 1, DUT 0\n+ divergence tx-bit at bit 18 (frame 1, BusIdle): model 1, DUT 0\n");
        assert!(!e.diff(&[]).is_exact());
    }

    #[test]
    fn a_recorded_entry_loads_only_once_explained() {
        let sig = vec!["divergence irq at bit 3 (Eof): model 0, DUT 1".to_string(), "verdict x".to_string()];
        let fresh = to_toml("s", "opencores-can (/tmp/can)", "wishbone", &sig, Place::Bit, None);
        assert!(fresh.contains("dut = [\"opencores-can (*)\"]"), "{fresh}");
        let err = WaiverSet::parse(&fresh, "rec.toml").unwrap_err().to_string();
        assert!(err.starts_with("rec.toml:") && err.contains(": deviation: empty"), "{err}");
        let old = WaiverSet::parse(ENTRY, "w.toml").unwrap().expected_failures()[0].clone();
        let again = to_toml("basic-sleep-wakeup", "opencores-can (/x)", "avalon", &sig, Place::Bit, Some(&old));
        let e = WaiverSet::parse(&again, "w.toml").unwrap().expected_failures()[0].clone();
        assert_eq!((e.id, e.deviation, e.clause, e.reason, e.hosts, e.signature), (old.id, old.deviation, old.clause, old.reason, vec!["avalon".to_string()], sig));
    }

    #[test]
    fn signature_lines_name_kind_place_and_values() {
        let d = Divergence { kind: DivergenceKind::RegisterRead, register: Some("IR".into()), bit: Some(66), field: Some(can_proto::Field::Intermission), expected: 0xF0, seen: 0xE2, time_ps: 5, context: "not in the line".into(), ..Default::default() };
        assert_eq!(signature_line(&d), "divergence register-read IR at bit 66 (Intermission): model 0xF0, DUT 0xE2");
        let t = Divergence { kind: DivergenceKind::TxBit, bit: Some(17), frame: Some(1), field: Some(can_proto::Field::BusIdle), expected: 1, seen: 0, ..Default::default() };
        assert_eq!(signature_line(&t), "divergence tx-bit at bit 17 (frame 1, BusIdle): model 1, DUT 0");
        let p = Divergence { kind: DivergenceKind::BusOff, time_ps: 1234, expected: 0, seen: 1, ..Default::default() };
        assert_eq!(signature_line(&p), "divergence bus-off at 1234 ps: model 0, DUT 1");
    }

    #[test]
    fn a_step_placed_line_names_the_step_and_keeps_the_value_and_for_bus_events_the_field() {
        let ir = Divergence { kind: DivergenceKind::RegisterRead, register: Some("IR".into()), bit: Some(66), field: Some(can_proto::Field::Intermission), expected: 0xF0, seen: 0xE2, ..Default::default() };
        assert_eq!(signature_line_in_step(&ir, StepAt::In(14)), "divergence register-read IR in step 14: model 0xF0, DUT 0xE2");
        let tx = Divergence { kind: DivergenceKind::TxBit, bit: Some(17), frame: Some(1), field: Some(can_proto::Field::BaseId), expected: 1, seen: 0, ..Default::default() };
        assert_eq!(signature_line_in_step(&tx, StepAt::In(9)), "divergence tx-bit in step 9 (frame 1, BaseId): model 1, DUT 0");
        assert_eq!(signature_line_in_step(&tx, StepAt::After), "divergence tx-bit after the steps (frame 1, BaseId): model 1, DUT 0");
        assert_eq!(signature_line_in_step(&tx, StepAt::Before), "divergence tx-bit before the steps (frame 1, BaseId): model 1, DUT 0");
        // What it still tells apart: another step, another field or frame, another value.
        let moved = [
            signature_line_in_step(&tx, StepAt::In(10)),
            signature_line_in_step(&Divergence { field: Some(can_proto::Field::Dlc), ..tx.clone() }, StepAt::In(9)),
            signature_line_in_step(&Divergence { frame: Some(2), ..tx.clone() }, StepAt::In(9)),
            signature_line_in_step(&Divergence { expected: 0, seen: 1, ..tx.clone() }, StepAt::In(9)),
            signature_line_in_step(&Divergence { seen: 0xE3, ..ir.clone() }, StepAt::In(14)),
        ];
        for m in &moved {
            assert_ne!(m, &signature_line_in_step(&tx, StepAt::In(9)));
            assert_ne!(m, &signature_line_in_step(&ir, StepAt::In(14)));
        }
    }

    #[test]
    fn place_loads_as_bit_by_default_step_when_asked_and_rejects_anything_else() {
        let set = WaiverSet::parse(ENTRY, "w.toml").unwrap();
        assert_eq!(set.expected_failures()[0].place, Place::Bit);
        let step = ENTRY.replace("signature = [", "place = \"step\"\nsignature = [");
        assert_eq!(WaiverSet::parse(&step, "w.toml").unwrap().expected_failures()[0].place, Place::Step);
        let err = WaiverSet::parse(&ENTRY.replace("signature = [", "place = \"frame\"\nsignature = ["), "w.toml").unwrap_err().to_string();
        assert!(err.contains("place: unknown place `frame`, expected `bit` or `step`"), "{err}");
        let text = to_toml("s", "opencores-can (/x)", "i8051", &["verdict x".to_string()], Place::Step, None);
        assert!(text.contains("place = \"step\"\nsignature = ["), "{text}");
        assert!(!to_toml("s", "d", "i8051", &["verdict x".to_string()], Place::Bit, None).contains("place"));
    }

    #[test]
    fn an_id_defined_in_two_files_is_an_error() {
        let mut a = WaiverSet::parse(ENTRY, "a.toml").unwrap();
        let b = WaiverSet::parse(ENTRY, "b.toml").unwrap();
        let err = a.merge(b).unwrap_err().to_string();
        assert_eq!(err, "b.toml:3: id: expected-failure id `gts` already defined at a.toml:3");
    }
}
