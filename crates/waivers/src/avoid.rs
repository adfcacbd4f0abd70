//! `[[avoid]]` tables: a known deviation whose trigger the random campaign
//! (`cancosim campaign`) keeps out of its plans on the DUTs named. For a
//! deviation whose consequences no waiver can bound (the core joins a frame
//! in flight and every later bit is another difference), the honest
//! alternative to stopping every campaign at it. Each entry names its
//! deviation and clause; the campaign's report lists what it left out.
//!
//! ```toml
//! [[avoid]]
//! id = "no-bus-free-wait-after-software-reset"
//! trigger = "software-reset-mode"
//! deviation = "D29"
//! clause = "datasheet Table 3 note 4"
//! dut = ["opencores-can (*)"]
//! explanation = "The core is idle at once after a reset mode the host left ..."
//! ```

use serde::Deserialize;
use toml::Spanned;

use crate::dut::DutInfo;
use crate::file::DutGlob;

/// The triggers a campaign knows how to keep out of its plans: the name
/// used in `trigger = "..."`, and what leaving it out removes.
pub const CAMPAIGN_TRIGGERS: &[(&str, &str)] = &[
    (
        "extended-frames-in-basiccan",
        "while the DUT runs in BasicCAN mode, the model nodes send standard frames only",
    ),
    (
        "software-reset-mode",
        "after its configuration the host never enters reset mode again (no reset-mode toggles, so no TXERR/RXERR/EWLR writes while the bus runs)",
    ),
    ("sleep-mode", "the host never requests sleep (PeliCAN MOD.SM, BasicCAN CMR.GTS)"),
    (
        "command-right-after-request",
        "the host waits 2 bit times after each transmission request before its next operation (no other CMR write right after TR)",
    ),
    (
        "error-in-received-data",
        "faults are placed in the first 19 wire bits of a frame (start of frame, identifier, control) and on the bus, where the sender sees them too, so an error is flagged before a receiver has taken a data byte; faults later in a frame (data, CRC, ACK, end of frame) and flips or stuck bits on the DUT's rx alone are not made (glitches stay on its rx)",
    ),
    (
        "self-reception-retransmitted",
        "every self-reception request is single shot (CMR 0x12 for 0x10), so a self-received frame is never retransmitted",
    ),
    (
        "rx-fifo-overrun",
        "the frames the DUT's filter takes (its own self-reception frames included) fit its 64-byte RX FIFO together, later ones are not sent, so no message is lost to an overrun however late the host drains",
    ),
    (
        "stuff-error-in-own-arbitration",
        "the DUT's identifiers have no recessive stuff bit in their arbitration field (an identifier bit before each is made recessive), so no error flag or fault can make one read dominant",
    ),
    (
        "one-quantum-tseg1",
        "TSEG1 is at least two time quanta (a run drawn with BTR1.TSEG1 = 0 gets 1; nothing else of it changes)",
    ),
    (
        "one-quantum-sjw",
        "SJW is at least two time quanta (a run drawn with BTR0.SJW = 0 gets 1 where TSEG1 and TSEG2 allow it; nothing else of it changes)",
    ),
    (
        "early-edge-beyond-sjw",
        "no glitch has an edge in phase segment 2 more than SJW before the end of the bit (a negative phase error beyond SJW); glitches elsewhere in the bit stay",
    ),
    (
        "resync-without-edge",
        "no glitch's leading edge falls where it would put the DUT a whole TSEG1 early (the quantum TSEG1 + 1 before the bit's end, within SJW), so no later edge comes in its sample quantum, nor, with triple sampling, where it would lengthen phase segment 1 by TSEG2 (SJW at least TSEG2), so no third look lands on the next bit's edge; glitches elsewhere in the bit stay",
    ),
    (
        "abort-in-flight",
        "the host writes CMR.AT on its own only in the program's closing abort, 200 bit times after its last operation; single-shot requests (TR with AT) stay",
    ),
];

/// What leaving `trigger` out removes from the plans (None: unknown trigger).
pub fn trigger_meaning(trigger: &str) -> Option<&'static str> {
    CAMPAIGN_TRIGGERS.iter().find(|(t, _)| *t == trigger).map(|(_, m)| *m)
}

/// One `[[avoid]]` table as written.
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawAvoid {
    /// Unique id among the file's avoid entries. Required.
    #[schemars(with = "String")]
    pub id: Spanned<String>,
    /// What the campaign leaves out of its plans: `extended-frames-in-basiccan`,
    /// `software-reset-mode`, `sleep-mode`, `command-right-after-request`, `error-in-received-data`,
    /// `self-reception-retransmitted`, `rx-fifo-overrun`, `stuff-error-in-own-arbitration`, `one-quantum-tseg1`,
    /// `one-quantum-sjw`, `early-edge-beyond-sjw`, `resync-without-edge` or `abort-in-flight`. Required.
    #[schemars(with = "String")]
    pub trigger: Spanned<String>,
    /// The deviation's row in the deviations table (`"D29"`). Required, not empty.
    pub deviation: String,
    /// The datasheet or CAN 2.0B clause the deviation breaks. Required, not empty.
    pub clause: String,
    /// DUT name globs, as for waivers (matched through the DUT's profile family too). Required.
    #[schemars(with = "Vec<String>")]
    pub dut: Vec<DutGlob>,
    /// Why no waiver can bound the deviation, in plain words. Required, not empty.
    pub explanation: String,
}

/// A validated `[[avoid]]` entry.
#[derive(Clone, Debug, PartialEq)]
pub struct Avoid {
    /// Id.
    pub id: String,
    /// One of [`CAMPAIGN_TRIGGERS`].
    pub trigger: String,
    /// Deviation row.
    pub deviation: String,
    /// Clause broken.
    pub clause: String,
    /// DUT globs.
    pub dut: Vec<DutGlob>,
    /// Why.
    pub explanation: String,
    /// File and line, for reports.
    pub file: String,
    /// Line of the entry's `id`.
    pub line: usize,
}

impl Avoid {
    /// True if the entry is for this DUT (its name or its profile family).
    pub fn applies_to(&self, dut: &DutInfo) -> bool {
        dut.matched_by(&self.dut, &[]).is_some()
    }

    /// One line for reports: what is left out, on which grounds.
    pub fn describe(&self) -> String {
        format!(
            "{} ({}, {}): {}; {}:{}",
            self.trigger,
            self.deviation,
            self.clause,
            trigger_meaning(&self.trigger).unwrap_or("?"),
            self.file,
            self.line
        )
    }
}

pub(crate) fn validate(name: &str, src: &str, raw: RawAvoid) -> Result<Avoid, crate::WaiverError> {
    let line = crate::file::line_of(src, raw.id.span().start);
    let bad = |key: &str, msg: String| crate::set::invalid(name, line, key, msg);
    let trigger = raw.trigger.get_ref().clone();
    if trigger_meaning(&trigger).is_none() {
        let known: Vec<&str> = CAMPAIGN_TRIGGERS.iter().map(|(t, _)| *t).collect();
        return Err(bad("trigger", format!("unknown trigger `{trigger}` (known: {})", known.join(", "))));
    }
    for (key, v) in [("deviation", &raw.deviation), ("clause", &raw.clause), ("explanation", &raw.explanation)] {
        if v.trim().is_empty() {
            return Err(bad(key, "must not be empty".into()));
        }
    }
    if raw.dut.is_empty() {
        return Err(bad("dut", "at least one DUT glob".into()));
    }
    Ok(Avoid {
        id: raw.id.get_ref().clone(),
        trigger,
        deviation: raw.deviation,
        clause: raw.clause,
        dut: raw.dut,
        explanation: raw.explanation,
        file: name.into(),
        line,
    })
}

#[cfg(test)]
mod tests {
    use crate::{DutInfo, WaiverSet};

    const FILE: &str = r#"
[[avoid]]
id = "no-bus-free-wait"
trigger = "software-reset-mode"
deviation = "D29"
clause = "datasheet Table 3 note 4"
dut = ["opencores-can (*)"]
explanation = "The core joins a frame in flight."
"#;

    #[test]
    fn an_avoid_entry_applies_to_its_core_and_its_forks_only() {
        let set = WaiverSet::parse(FILE, "f.toml").unwrap();
        let up = DutInfo::new("opencores-can (/src/can)");
        let fork = DutInfo::new("fork (/d)").in_family("fork", &["opencores-can".into()]);
        assert_eq!(set.avoids_for(&up).len(), 1);
        assert_eq!(set.avoids_for(&fork).len(), 1, "a fork of the core inherits it");
        assert!(set.avoids_for(&DutInfo::new("rtl")).is_empty(), "our RTL keeps every trigger");
        assert!(set.avoids_for(&up)[0].describe().contains("D29"));
    }

    #[test]
    fn an_unknown_trigger_or_an_empty_reason_is_an_error_with_its_line() {
        let e = WaiverSet::parse(&FILE.replace("software-reset-mode", "everything"), "f.toml").unwrap_err().to_string();
        assert!(e.contains("f.toml:3") && e.contains("unknown trigger `everything`"), "{e}");
        let e = WaiverSet::parse(&FILE.replace("The core joins a frame in flight.", " "), "f.toml").unwrap_err().to_string();
        assert!(e.contains("explanation") && e.contains("must not be empty"), "{e}");
    }
}
