//! A loaded waiver file and the matching of divergences against it.

use std::collections::HashSet;
use std::path::Path;

use diagnose::{Divergence, DivergenceKind};
use serde::{Deserialize, Serialize};

use crate::dut::{DutInfo, DutMatch};
use crate::expected::{ExpectedFailure, RawExpectedFailure};
use crate::file::{
    self, BitPattern, Consequence, DutGlob, FrameRange, KindName, Lateness, RawWaiver, ResyncSpec, RevRange, WaiverError,
};

/// What the comparator can see of the DUT at the divergence, beyond the
/// divergence itself. Used for the `dut-tec`/`dut-rec` bounds and to fill
/// in the values to adopt; leave unknown what you cannot observe.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Observed {
    /// The DUT's transmit error counter (TXERR), if readable.
    pub dut_tec: Option<u16>,
    /// The DUT's receive error counter (RXERR), if readable.
    pub dut_rec: Option<u16>,
    /// Simulation time when the comparator reports the divergence (ps); with
    /// `bit_time_ps` and `can_clock_ps` it lets a `late-by` bound be checked.
    pub now_ps: Option<u64>,
    /// Nominal bit time of the run (ps).
    pub bit_time_ps: Option<u64>,
    /// CAN clock period of the run (ps).
    pub can_clock_ps: Option<u64>,
    /// The model's PeliCAN mode register (MOD) at the divergence; `None` in
    /// BasicCAN or when not observed (`model-mod-bits`).
    pub model_mod: Option<u8>,
    /// The model's IR at the divergence, read without clearing it; `None`:
    /// not observed (`model-ir-bits`).
    pub model_ir: Option<u8>,
    /// irq: `Some(true)` when the pins have not agreed since this pin's
    /// previous report (the same difference reported again), `Some(false)`
    /// when they have; `None`: not observed (then reports at most two CAN
    /// clocks apart are taken as one difference). For `until-read`.
    pub pin_continues: Option<bool>,
    /// Messages the reference (the model) lost to an RX FIFO overrun since
    /// its FIFO was last emptied (reset mode, hardware reset); `None`: not
    /// observed. For `after = "data-overrun"`.
    pub model_lost_messages: Option<u32>,
    /// The model's mode at the divergence: `Some(true)` BasicCAN,
    /// `Some(false)` PeliCAN; `None`: not observed. For `model-mode`.
    pub model_basic: Option<bool>,
    /// `Some(true)` when the host aborted (CMR.AT) the model's last
    /// transmission request; `None`: not observed. For `after-abort`.
    pub model_aborted: Option<bool>,
    /// The frame information byte of the message at the head of the
    /// model's RX FIFO (PeliCAN, operating mode); `None`: not observed. For
    /// `model-rx-frame`.
    pub model_rx_frame_info: Option<u8>,
    /// The last bit whose tx the comparator compared and found equal on
    /// both sides; `None`: not observed. It ends a tx-bit `late-bits`
    /// episode (the deviation had stopped).
    pub tx_agreed_bit: Option<u64>,
    /// The last bit at whose sample point the DUT drove dominant and its
    /// rx read recessive: a bit error the DUT detects itself (CAN 2.0B §7: a
    /// new error flag starts at the next bit); `None`: not observed. A
    /// tx-bit `late-bits` episode restarts after it.
    pub dut_bit_error_bit: Option<u64>,
}

impl Observed {
    /// The comparator's clock: report time, bit time and CAN clock period.
    pub fn timed(now_ps: u64, bit_time_ps: u64, can_clock_ps: u64) -> Self {
        Observed {
            now_ps: Some(now_ps),
            bit_time_ps: Some(bit_time_ps),
            can_clock_ps: Some(can_clock_ps),
            ..Default::default()
        }
    }
}

/// A re-synchronisation step for the comparator, in the order given.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Resync {
    /// Set the model's TEC to the DUT's. `Some(v)`: the value (from the
    /// diverging TXERR read, else [`Observed::dut_tec`], else the waiver's
    /// single-value `dut-tec`); `None`: the comparator must find the DUT's
    /// TEC itself (e.g. at its next TXERR read).
    AdoptTec(Option<u8>),
    /// Set the model's REC to the DUT's (same convention as `AdoptTec`).
    AdoptRec(Option<u8>),
    /// Write `value` (what the DUT returned) into the model's register at `addr`.
    AdoptRegister {
        /// Register address in the view in force.
        addr: u8,
        /// The DUT's value.
        value: u8,
    },
    /// The model leaves sleep without a wake-up interrupt (`model-skips-sleep`).
    ModelSkipsSleep,
    /// The model waits one more bus-free sequence after its bus-on and
    /// starts the frame it holds with the DUT's start of frame
    /// (`model-waits-bus-free-after-bus-on`).
    ModelWaitsBusFreeAfterBusOn,
    /// Compare nothing for this many bit times, counting the diverging bit
    /// as the first (`SkipBits(1)`: compare again from the next bit); the
    /// adopt steps of the same verdict apply when comparison resumes.
    SkipBits(u32),
}

/// The outcome of checking one divergence.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// A waiver covers it: record it as waived, apply `resync`, go on.
    Waived {
        /// The waiver's `id`.
        waiver_id: String,
        /// Steps to apply, in order (empty for `resync = ["none"]`).
        resync: Vec<Resync>,
    },
    /// No waiver covers it.
    Failure,
}

/// One waiver, validated.
#[derive(Clone, Debug)]
pub struct Waiver {
    /// Unique id (a rule name such as `tec-after-error-passive`).
    pub id: String,
    /// Divergence kind it covers.
    pub kind: DivergenceKind,
    /// Why the deviation is accepted.
    pub explanation: String,
    /// The datasheet or CAN 2.0B clause the deviation breaks (`clause`), for reports.
    pub clause: Option<String>,
    /// File it comes from.
    pub file: String,
    /// Line of the `id` key in the file.
    pub line: usize,
    /// DUT name globs.
    pub dut: Vec<DutGlob>,
    /// Revision ranges (empty: any revision, known or not).
    pub revisions: Vec<RevRange>,
    /// Fields the model may be in (tx-bit; irq / bus-off: when the pin
    /// difference started; empty: any).
    pub fields: Vec<can_proto::Field>,
    /// Register name (register-read), compared case-insensitively.
    pub register: Option<String>,
    /// Register address, needed by `adopt-dut-register`.
    pub address: Option<u8>,
    /// Register bits allowed to differ (register-read; `None`: any).
    pub bits: Option<u8>,
    /// Allowed model values.
    pub expected: Option<Vec<u32>>,
    /// Allowed DUT values.
    pub seen: Option<Vec<u32>>,
    /// Allowed DUT TEC values, checked against [`Observed::dut_tec`]; when
    /// the TEC was not observed a single value is taken as the measured TEC
    /// (and is what `adopt-dut-tec` adopts), several values do not match.
    pub dut_tec: Option<Vec<u16>>,
    /// Allowed DUT REC values (as `dut_tec`, with [`Observed::dut_rec`]).
    pub dut_rec: Option<Vec<u16>>,
    /// Frame numbers it applies to.
    pub frames: Option<FrameRange>,
    /// Text the divergence context must contain.
    pub context: Option<String>,
    /// The deviation may last at most this many bit times (see
    /// [`WaiverSet::check`]).
    pub late_bits: Option<u32>,
    /// irq / bus-off: the DUT's pin may lag the model by at most this long
    /// (see [`WaiverSet::check_observed`]).
    pub late_by: Option<Lateness>,
    /// irq: one pin difference (episode) lasts at most until the host's
    /// next read of this register (`until-read = "IR"`); `max-hits` then
    /// counts episodes (see [`WaiverSet::check_observed`]).
    pub until_read: Option<String>,
    /// Applies only once the reference has lost at least this many messages
    /// to an RX FIFO overrun since its FIFO was last emptied
    /// (`after = "data-overrun"`: 1; [`Observed::model_lost_messages`]).
    pub after_lost: Option<u32>,
    /// register-read: the model's value must have this pattern.
    pub expected_bits: Option<BitPattern>,
    /// register-read: the DUT's value must have this pattern.
    pub seen_bits: Option<BitPattern>,
    /// register-read: the DUT's value must be the model's plus this.
    pub seen_offset: Option<i64>,
    /// The model's PeliCAN MOD must have this pattern ([`Observed::model_mod`]).
    pub model_mod_bits: Option<BitPattern>,
    /// The model's IR must have this pattern ([`Observed::model_ir`]).
    pub model_ir_bits: Option<BitPattern>,
    /// Only after a divergence this other waiver took, starting no earlier.
    pub after_waiver: Option<String>,
    /// When this waiver last took a divergence (its `time_ps`), for `after-waiver`.
    last_hit_ps: Option<u64>,
    /// Applies only while the model is in this mode: `Some(true)` BasicCAN
    /// (`model-mode = "basic"`), `Some(false)` PeliCAN.
    pub model_basic: Option<bool>,
    /// register-read: applies only while the model's RX FIFO head is an
    /// extended (`Some(true)`) or standard frame (`model-rx-frame`).
    pub model_rx_extended: Option<bool>,
    /// Applies only while the host's last word on the model's transmission
    /// request was an abort (CMR.AT since the last TR/SRR; `after-abort`).
    pub after_abort: bool,
    /// At most this many divergences are waived.
    pub max_hits: Option<u32>,
    /// Re-synchronisation allowed.
    pub resync: Vec<ResyncSpec>,
    /// Scenario expectations that follow from this deviation (waived only
    /// after this waiver was hit in the same run; `Session::waive_consequence`).
    pub consequences: Vec<Consequence>,
    /// Divergences waived so far.
    pub hits: u32,
    /// Episodes so far (`until-read`; with `late-by`, the differences).
    pub episodes: u32,
    episode: Option<Episode>,
    late: Option<LateEpisode>,
    read_episode: Option<ReadEpisode>,
    /// Completion times (ps) of the host's recent reads of `until_read`.
    reads: Vec<u64>,
    /// register-read with `late-bits`: completion times (ps) of the host's
    /// recent reads of `register`; one between two hits ended the episode
    /// (that read agreed, or another entry took it).
    own_reads: Vec<u64>,
    /// The last report refused because it outlasted a read: (its start, the read), ps.
    outlasted: Option<(u64, u64)>,
}

/// The pin difference an `until-read` waiver is following: when it began
/// (its first report's `time_ps`) and when it was last reported.
#[derive(Clone, Copy, Debug)]
struct ReadEpisode {
    start_ps: u64,
    last_report_ps: u64,
}

/// Reads of an `until-read` register kept while no episode is open: a
/// new episode begins at most a pin tolerance before its first report, far
/// fewer reads than this fit in it.
const RECENT_READS: usize = 64;

/// The current run of hits of one waiver, for the `late-bits` bound.
#[derive(Clone, Copy, Debug)]
struct Episode {
    first_bit: u64,
    /// The last hit's bit.
    last_bit: u64,
    covered_to: u64,
    /// Time of the last hit (ps).
    last_ps: u64,
}

/// The pin difference a `late-by` waiver is following: when it started
/// (its first report's `time_ps`) and when it was last reported.
#[derive(Clone, Copy, Debug)]
struct LateEpisode {
    start_ps: u64,
    last_report_ps: u64,
}

impl Waiver {
    /// The deviation in plain words: the first sentence of the explanation,
    /// without a leading table tag such as `D1.` (docs/opencores-deviations.md).
    pub fn summary(&self) -> String {
        summary_of(&self.explanation)
    }

    /// What a report says of this waiver after `hits` divergences.
    pub fn deviation(&self, hits: u32) -> diagnose::WaivedDeviation {
        diagnose::WaivedDeviation {
            waiver_id: self.id.clone(),
            summary: self.summary(),
            clause: self.clause.clone(),
            hits,
            episodes: if self.until_read.is_some() { self.episodes } else { 0 },
            bound: self.bound(),
            via: None,
        }
    }

    /// The bounds that follow the run, in words for reports (`until-read`,
    /// `after`).
    pub fn bound(&self) -> Option<String> {
        let read = self.until_read.as_ref().map(|r| {
            let max = self.max_hits.map(|m| format!(", at most {m} (max-hits)")).unwrap_or_default();
            format!("each episode until the host's next read of {r} (until-read = \"{r}\"){max}")
        });
        let after = self.after_lost.map(|n| {
            let (lost, key) = if n == 1 {
                ("a message".to_string(), "data-overrun".to_string())
            } else {
                (format!("{n} messages"), format!("{n} data-overruns"))
            };
            format!("only after the model lost {lost} to an RX FIFO overrun (after = \"{key}\")")
        });
        let mode = self.model_basic.map(|b| format!("only while the model is in {} mode (model-mode = \"{}\")", mode_name(b), mode_key(b)));
        let abort = self.after_abort.then(|| "only after the host aborted the model's last transmission request (after-abort)".to_string());
        let rx = self.model_rx_extended.map(|e| {
            let f = if e { "extended" } else { "standard" };
            format!("only while the model's RX buffer holds a {f} frame (model-rx-frame = \"{f}\")")
        });
        let parts: Vec<String> = [read, after, mode, abort, rx].into_iter().flatten().collect();
        (!parts.is_empty()).then(|| parts.join(", "))
    }

    /// True if the waiver is for this DUT (name glob, through the DUT's
    /// profile family too, and revision range).
    pub fn applies_to(&self, dut: &DutInfo) -> bool {
        self.matched_by(dut).is_some()
    }

    /// How the waiver's `dut` globs and `revisions` take this DUT: by its
    /// own name or through a member of its profile family (`None`: not for it).
    pub fn matched_by<'a>(&self, dut: &'a DutInfo) -> Option<DutMatch<'a>> {
        dut.matched_by(&self.dut, &self.revisions)
    }

    /// Why the waiver does not cover `d` (bounds included, the `late-bits`
    /// and `max-hits` history excluded), or `None` if it does.
    pub fn mismatch(&self, d: &Divergence, dut: &DutInfo, obs: &Observed) -> Option<String> {
        if d.kind != self.kind {
            return Some("another kind".into());
        }
        if !self.applies_to(dut) {
            return Some(format!("not for {}", dut.label()));
        }
        if !self.fields.is_empty() {
            match d.field {
                Some(f) if self.fields.contains(&f) => {}
                f => return Some(format!("field {f:?} not in {:?}", self.fields)),
            }
        }
        if let Some(r) = &self.register
            && !d.register.as_deref().is_some_and(|x| x.eq_ignore_ascii_case(r))
        {
            return Some(format!("register {:?} is not {r}", d.register));
        }
        if let Some(mask) = self.bits {
            let diff = d.expected ^ d.seen;
            if diff & !(mask as u32) != 0 {
                return Some(format!("bits 0x{diff:02X} differ, only 0x{mask:02X} allowed"));
            }
        }
        for (name, pat, v) in [("model", self.expected_bits, d.expected), ("DUT", self.seen_bits, d.seen)] {
            if let Some(p) = pat
                && !p.matches(v)
            {
                return Some(format!("{name} value 0x{v:02X} does not have the pattern {}", String::from(p)));
            }
        }
        if let Some(off) = self.seen_offset
            && d.seen as i64 - d.expected as i64 != off
        {
            return Some(format!("DUT value {} is not the model's {} {off:+}", d.seen, d.expected));
        }
        // `model-mod-bits`, `model-ir-bits`: a register of the model as observed.
        for (pattern, value, name, unseen) in [
            (self.model_mod_bits, obs.model_mod, "MOD", "MOD (PeliCAN)"),
            (self.model_ir_bits, obs.model_ir, "IR", "IR"),
        ] {
            match (pattern, value) {
                (None, _) => {}
                (Some(p), Some(m)) if p.matches(m as u32) => {}
                (Some(p), Some(m)) => {
                    return Some(format!("the model's {name} 0x{m:02X} does not have the pattern {}", String::from(p)));
                }
                (Some(_), None) => return Some(format!("the model's {unseen} was not observed")),
            }
        }
        if let Some(want) = self.model_basic {
            match obs.model_basic {
                Some(b) if b == want => {}
                Some(b) => return Some(format!("the model is in {} mode, model-mode needs {}", mode_name(b), mode_name(want))),
                None => return Some("model-mode needs the model's mode, not observed".into()),
            }
        }
        if let Some(want) = self.model_rx_extended {
            let name = |e: bool| if e { "an extended" } else { "a standard" };
            match obs.model_rx_frame_info {
                Some(fi) if (fi & 0x80 != 0) == want => {}
                Some(_) => return Some(format!("the model's RX buffer does not hold {} frame (model-rx-frame)", name(want))),
                None => return Some("model-rx-frame needs the model's RX frame information, not observed".into()),
            }
        }
        if self.after_abort {
            match obs.model_aborted {
                Some(true) => {}
                Some(false) => return Some("the host did not abort the model's last transmission request (after-abort)".into()),
                None => return Some("after-abort needs the model's abort state, not observed".into()),
            }
        }
        if self.late_by.is_some() && (obs.now_ps.is_none() || obs.bit_time_ps.is_none() || obs.can_clock_ps.is_none())
        {
            return Some("late-by needs the comparator's clock (report time, bit time, CAN clock), not given".into());
        }
        if let Some(n) = self.after_lost {
            match obs.model_lost_messages {
                Some(lost) if lost >= n => {}
                Some(lost) => {
                    return Some(format!(
                        "the model lost {lost} message(s) to an RX FIFO overrun since its FIFO was last emptied, after needs {n}"
                    ));
                }
                None => return Some("after needs the model's lost messages, not observed".into()),
            }
        }
        if self.until_read.is_some() && obs.can_clock_ps.is_none() {
            return Some("until-read needs the comparator's clock (CAN clock period), not given".into());
        }
        if let Some(v) = &self.expected
            && !v.contains(&d.expected)
        {
            return Some(format!("expected value {} not in {v:?}", d.expected));
        }
        if let Some(v) = &self.seen
            && !v.contains(&d.seen)
        {
            return Some(format!("DUT value {} not in the allowed {v:?}", d.seen));
        }
        for (name, allowed, got) in [("TEC", &self.dut_tec, obs.dut_tec), ("REC", &self.dut_rec, obs.dut_rec)] {
            if let Some(v) = allowed {
                match got {
                    Some(x) if v.contains(&x) => {}
                    Some(x) => return Some(format!("DUT {name} {x} not in the allowed {v:?}")),
                    // A single value states the measured counter: assumed.
                    None if v.len() == 1 => {}
                    None => {
                        return Some(format!(
                            "DUT {name} bound {v:?} but the comparator did not observe the DUT's {name}"
                        ));
                    }
                }
            }
        }
        if let Some(fr) = self.frames {
            match d.frame {
                Some(n) if fr.contains(n) => {}
                n => return Some(format!("frame {n:?} outside {}", String::from(fr))),
            }
        }
        if let Some(c) = &self.context
            && !d.context.contains(c.as_str())
        {
            return Some(format!("context does not contain `{c}`"));
        }
        None
    }

    /// Same field and register as `d`, where the waiver names them.
    fn same_place(&self, d: &Divergence) -> bool {
        (self.fields.is_empty() || d.field.is_some_and(|f| self.fields.contains(&f)))
            && self.register.as_ref().is_none_or(|r| d.register.as_deref().is_some_and(|x| x.eq_ignore_ascii_case(r)))
    }

    fn skip(&self) -> u64 {
        self.resync.iter().map(|r| if let ResyncSpec::SkipBits(n) = r { *n as u64 } else { 0 }).max().unwrap_or(0)
    }

    fn resolve(&self, d: &Divergence, obs: &Observed) -> Vec<Resync> {
        let read_of = |name: &str| {
            (d.kind == DivergenceKind::RegisterRead
                && d.register.as_deref().is_some_and(|r| r.eq_ignore_ascii_case(name)))
            .then(|| u8::try_from(d.seen).ok())
            .flatten()
        };
        self.resync
            .iter()
            .filter_map(|r| match r {
                ResyncSpec::None => None,
                ResyncSpec::AdoptDutTec => Some(Resync::AdoptTec(
                    read_of("TXERR").or(obs.dut_tec.and_then(|t| u8::try_from(t).ok())).or(single(&self.dut_tec)),
                )),
                ResyncSpec::AdoptDutRec => Some(Resync::AdoptRec(
                    read_of("RXERR").or(obs.dut_rec.and_then(|t| u8::try_from(t).ok())).or(single(&self.dut_rec)),
                )),
                ResyncSpec::AdoptDutRegister => Some(Resync::AdoptRegister {
                    addr: self.address.expect("validated at load: adopt-dut-register has an address"),
                    value: d.seen as u8,
                }),
                ResyncSpec::ModelSkipsSleep => Some(Resync::ModelSkipsSleep),
                ResyncSpec::ModelWaitsBusFreeAfterBusOn => Some(Resync::ModelWaitsBusFreeAfterBusOn),
                ResyncSpec::SkipBits(n) => Some(Resync::SkipBits(*n)),
            })
            .collect()
    }
}

/// The verdict of an `until-read` waiver on a divergence it matches (see
/// [`WaiverSet::check_observed`]); `None`: not waived by it.
fn until_read_verdict(w: &mut Waiver, d: &Divergence, obs: &Observed) -> Option<Verdict> {
    let clk = obs.can_clock_ps?;
    let now = obs.now_ps.unwrap_or(d.time_ps).max(d.time_ps);
    let same = |e: &ReadEpisode| match obs.pin_continues {
        Some(c) => c && d.time_ps >= e.start_ps,
        None => d.time_ps >= e.start_ps && d.time_ps <= e.last_report_ps + 2 * clk,
    };
    match &mut w.read_episode {
        Some(e) if same(e) => {
            // The same difference, reported again.
            e.last_report_ps = now;
            let start = e.start_ps;
            if let Some(&read) = w.reads.iter().find(|&&r| r >= start)
                && d.time_ps > read
            {
                w.outlasted = Some((d.time_ps, read));
                return None;
            }
        }
        _ => {
            // A new difference: one more episode.
            if w.max_hits.is_some_and(|m| w.episodes >= m) {
                return None;
            }
            w.read_episode = Some(ReadEpisode { start_ps: d.time_ps, last_report_ps: now });
            w.reads.retain(|&r| r >= d.time_ps);
            w.episodes += 1;
        }
    }
    w.hits += 1;
    Some(Verdict::Waived { waiver_id: w.id.clone(), resync: w.resolve(d, obs) })
}

/// The one value of a single-value counter bound.
fn single(v: &Option<Vec<u16>>) -> Option<u8> {
    match v.as_deref() {
        Some([x]) => u8::try_from(*x).ok(),
        _ => None,
    }
}

/// A waiver file (`tb/waivers/*.toml`, `--waivers FILE`, a scenario's `[run] waivers`):
/// known deviations of a DUT, each accepted only within its bounds. Unknown keys are
/// rejected; every error reads `file:line: key: message`.
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawFile {
    /// The waivers, checked in file order: the first that covers a divergence takes it. Default: none.
    #[serde(default)]
    pub waiver: Vec<RawWaiver>,
    /// Strict expected failures of whole scenarios ([`crate::expected`]). Default: none.
    #[serde(default, rename = "expected-failure")]
    pub expected_failure: Vec<RawExpectedFailure>,
    /// Triggers of known deviations the random campaign keeps out of its plans ([`crate::avoid`]). Default: none.
    #[serde(default)]
    pub avoid: Vec<crate::avoid::RawAvoid>,
}

/// The JSON schema of a waiver file, for the generated reference
/// (`cancosim gen reference`): doc comments are the descriptions.
pub fn file_schema() -> schemars::Schema {
    schemars::schema_for!(RawFile)
}

/// A waiver file for the reference (tested to load).
pub const EXAMPLE: &str = r#"# Waivers for the opencores core; a fork whose profile says
# extends = "opencores-can" gets them too (matched via its family).
[[waiver]]
id = "tec-after-error-passive"
kind = "tx-bit"
fields = ["PassiveErrorFlag"]
dut = ["opencores-can (*)"]
explanation = "The core sends one more recessive bit after a passive error flag. Accepted: the next frame is unaffected."
clause = "CAN 2.0B §7.1"
late-bits = 1
resync = ["skip-bits 1"]
"#;

/// The waivers of one file, with their hit counts.
#[derive(Clone, Debug, Default)]
pub struct WaiverSet {
    /// File name (for messages).
    pub name: String,
    waivers: Vec<Waiver>,
    expected_failures: Vec<ExpectedFailure>,
    avoids: Vec<crate::avoid::Avoid>,
    /// Recent starts of frame on the bus (ps): one between two hits of a
    /// register-read `late-bits` waiver ends its episode.
    frame_starts: Vec<u64>,
}

impl WaiverSet {
    /// An empty set: every divergence is a failure.
    pub fn empty() -> Self {
        WaiverSet::default()
    }

    /// Reads and validates a waiver file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, WaiverError> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let src = std::fs::read_to_string(path).map_err(|source| WaiverError::Io { file: name.clone(), source })?;
        Self::parse(&src, &name)
    }

    /// Reads several files into one set (`--waivers a.toml --waivers b.toml`);
    /// an id defined twice is an error naming both places.
    pub fn load_all<P: AsRef<Path>>(paths: &[P]) -> Result<Self, WaiverError> {
        let mut set = WaiverSet::empty();
        for p in paths {
            set.merge(Self::load(p)?)?;
        }
        Ok(set)
    }

    /// Parses waiver-file text; `name` is the file name used in errors.
    pub fn parse(src: &str, name: &str) -> Result<Self, WaiverError> {
        let raw: RawFile = toml::from_str(src).map_err(|e| file::from_toml(name, src, &e))?;
        let mut ids = HashSet::new();
        let mut waivers = Vec::with_capacity(raw.waiver.len());
        for w in raw.waiver {
            let line = file::line_of(src, w.id.span().start);
            if !ids.insert(w.id.get_ref().clone()) {
                return Err(invalid(name, line, "id", format!("duplicate waiver id `{}`", w.id.get_ref())));
            }
            waivers.push(validate(name, src, w)?);
        }
        for w in &waivers {
            if let Some(a) = &w.after_waiver
                && (a == &w.id || !ids.contains(a))
            {
                return Err(invalid(name, w.line, "after-waiver", format!("`{a}` is not another waiver of this file")));
            }
        }
        let mut expected_failures: Vec<ExpectedFailure> = Vec::with_capacity(raw.expected_failure.len());
        for x in raw.expected_failure {
            let e = crate::expected::validate(name, src, x)?;
            if let Some(old) = expected_failures.iter().find(|o| o.id == e.id) {
                return Err(invalid(name, e.line, "id", format!("duplicate expected-failure id `{}` (first at line {})", e.id, old.line)));
            }
            expected_failures.push(e);
        }
        let mut avoids: Vec<crate::avoid::Avoid> = Vec::with_capacity(raw.avoid.len());
        for a in raw.avoid {
            let a = crate::avoid::validate(name, src, a)?;
            if let Some(old) = avoids.iter().find(|o| o.id == a.id) {
                return Err(invalid(name, a.line, "id", format!("duplicate avoid id `{}` (first at line {})", a.id, old.line)));
            }
            avoids.push(a);
        }
        Ok(WaiverSet { name: name.into(), waivers, expected_failures, avoids, frame_starts: Vec::new() })
    }

    /// Adds the waivers of another file after these (`--waivers a --waivers b`).
    pub fn merge(&mut self, other: WaiverSet) -> Result<(), WaiverError> {
        for w in other.waivers {
            if let Some(old) = self.get(&w.id) {
                return Err(invalid(
                    &w.file,
                    w.line,
                    "id",
                    format!("waiver id `{}` already defined at {}:{}", w.id, old.file, old.line),
                ));
            }
            self.waivers.push(w);
        }
        for e in other.expected_failures {
            if let Some(old) = self.expected_failures.iter().find(|o| o.id == e.id) {
                return Err(invalid(
                    &e.file,
                    e.line,
                    "id",
                    format!("expected-failure id `{}` already defined at {}", e.id, old.location()),
                ));
            }
            self.expected_failures.push(e);
        }
        for a in other.avoids {
            if let Some(old) = self.avoids.iter().find(|o| o.id == a.id) {
                return Err(invalid(&a.file, a.line, "id", format!("avoid id `{}` already defined at {}:{}", a.id, old.file, old.line)));
            }
            self.avoids.push(a);
        }
        if self.name.is_empty() {
            self.name = other.name;
        } else if !other.name.is_empty() {
            self.name = format!("{}, {}", self.name, other.name);
        }
        Ok(())
    }

    /// The `[[expected-failure]]` entries, in file order.
    pub fn expected_failures(&self) -> &[ExpectedFailure] {
        &self.expected_failures
    }

    /// The `[[avoid]]` entries for this DUT: triggers the random campaign
    /// keeps out of its plans on it.
    pub fn avoids_for(&self, dut: &DutInfo) -> Vec<&crate::avoid::Avoid> {
        self.avoids.iter().filter(|a| a.applies_to(dut)).collect()
    }

    /// The waivers, in file order.
    pub fn waivers(&self) -> &[Waiver] {
        &self.waivers
    }

    /// The waiver with this id.
    pub fn get(&self, id: &str) -> Option<&Waiver> {
        self.waivers.iter().find(|w| w.id == id)
    }

    /// [`WaiverSet::check_observed`] with nothing observed beyond the divergence.
    pub fn check(&mut self, d: &Divergence, dut: &DutInfo) -> Verdict {
        self.check_observed(d, dut, &Observed::default())
    }

    /// Checks a divergence against the waivers in file order; the first
    /// that covers it counts a hit and gives the verdict.
    ///
    /// `late-bits = N` bounds how long one deviation may last: hits of a
    /// waiver at most max(N, its `skip-bits`) + 1 bits apart form one
    /// episode, and a hit that would make the episode span more than N bit
    /// times is not waived (nor is the rest of that episode). For a tx-bit
    /// waiver, a bit compared equal between two hits ([`Observed::tx_agreed_bit`])
    /// ends the episode, and a bit error the DUT detects in it
    /// ([`Observed::dut_bit_error_bit`]) restarts the count at the next bit.
    /// `max-hits` bounds the total.
    ///
    /// `until-read = "IR"` bounds a pin difference by the event that ends
    /// it: reports of one lasting difference (the pins did not agree in
    /// between, [`Observed::pin_continues`]; not observed: each report
    /// starting at most two CAN clocks after the previous one) form one
    /// episode, waived while
    /// the run each report measures began no later than the completion of
    /// the host's first read of IR since the episode began
    /// ([`WaiverSet::host_read`]); later, the pin outlasted that read by more
    /// than the comparator's pin tolerance and it is not waived. `max-hits`
    /// counts episodes.
    pub fn check_observed(&mut self, d: &Divergence, dut: &DutInfo, obs: &Observed) -> Verdict {
        let bit = d.bit.unwrap_or(0);
        // `after-waiver`: when each waiver last took a divergence.
        let last_hits: Vec<Option<u64>> = self.waivers.iter().map(|w| w.last_hit_ps).collect();
        let ids: Vec<String> = self.waivers.iter().map(|w| w.id.clone()).collect();
        let after_ok = |w: &Waiver| match &w.after_waiver {
            None => true,
            Some(id) => ids.iter().position(|i| i == id).and_then(|k| last_hits[k]).is_some_and(|t| d.time_ps >= t),
        };
        for w in &mut self.waivers {
            if w.mismatch(d, dut, obs).is_some() || !after_ok(w) {
                continue;
            }
            if w.until_read.is_some() {
                match until_read_verdict(w, d, obs) {
                    Some(v) => return v,
                    None => continue,
                }
            }
            let timed = w.late_by.is_some() && obs.now_ps.is_some() && obs.bit_time_ps.is_some() && obs.can_clock_ps.is_some();
            // With `late-by` observed, max-hits counts differences (episodes),
            // below; otherwise reports.
            if !timed && w.max_hits.is_some_and(|m| w.hits >= m) {
                continue;
            }
            if let (Some(by), Some(now), Some(bit_ps), Some(clk_ps)) =
                (w.late_by, obs.now_ps, obs.bit_time_ps, obs.can_clock_ps)
            {
                // The comparator reports a lasting pin difference again and
                // again, each report's run starting where the last report
                // was taken: those reports are one difference, measured from
                // its first start to now. Their number grows with the bit
                // time, so max-hits counts differences, not reports.
                let (start, new) = match w.late {
                    Some(e) if d.time_ps >= e.start_ps && d.time_ps <= e.last_report_ps + 2 * clk_ps => (e.start_ps, false),
                    _ => (d.time_ps, true),
                };
                if new {
                    if w.max_hits.is_some_and(|m| w.episodes >= m) {
                        continue;
                    }
                    w.episodes += 1;
                }
                w.late = Some(LateEpisode { start_ps: start, last_report_ps: now.max(d.time_ps) });
                if now.saturating_sub(start) > by.ps(bit_ps, clk_ps) {
                    continue;
                }
            }
            if let Some(late) = w.late_bits {
                let reach = w.skip().max(late as u64);
                // A read of the register between two hits that was not one
                // of them showed the DUT agreeing: the deviation had ended.
                // So did a start of frame: each frame's difference is an episode of its own.
                let read_between = |e: &Episode| {
                    w.own_reads.iter().chain(&self.frame_starts).any(|&t| t > e.last_ps && t < d.time_ps)
                };
                // A tx bit compared equal between two hits showed the DUT
                // agreeing: the deviation had ended, as with a read.
                let tx_agreed_between = |e: &Episode| {
                    d.kind == DivergenceKind::TxBit && obs.tx_agreed_bit.is_some_and(|b| b > e.last_bit && b < bit)
                };
                match w.episode {
                    Some(e) if bit >= e.first_bit && bit <= e.covered_to + 1 && !read_between(&e) && !tx_agreed_between(&e) => {
                        // Same deviation still going on: it stays one episode
                        // (even once rejected), so it cannot restart the count,
                        // unless the DUT detected a bit error of its own in it:
                        // its new error flag counts from the next bit.
                        let first_bit = match obs.dut_bit_error_bit {
                            Some(b) if d.kind == DivergenceKind::TxBit && b >= e.first_bit && b < bit => b + 1,
                            _ => e.first_bit,
                        };
                        w.episode = Some(Episode { first_bit, last_bit: bit, covered_to: bit + reach, last_ps: d.time_ps });
                        if bit - first_bit + 1 > late as u64 {
                            continue;
                        }
                    }
                    _ => w.episode = Some(Episode { first_bit: bit, last_bit: bit, covered_to: bit + reach, last_ps: d.time_ps }),
                }
                w.own_reads.retain(|&t| t >= d.time_ps);
            }
            w.hits += 1;
            w.last_hit_ps = Some(d.time_ps);
            return Verdict::Waived { waiver_id: w.id.clone(), resync: w.resolve(d, obs) };
        }
        Verdict::Failure
    }

    /// For a divergence no waiver covers: each waiver of the same kind,
    /// field and register for this DUT and why it did not apply (a bound, the episode, max-hits),
    /// so a near miss is reported rather than hidden.
    pub fn near_misses(&self, d: &Divergence, dut: &DutInfo, obs: &Observed) -> Vec<String> {
        self.waivers
            .iter()
            .filter(|w| w.kind == d.kind && w.applies_to(dut) && w.same_place(d))
            .map(|w| match w.mismatch(d, dut, obs) {
                Some(why) => format!("waiver `{}` ({}:{}) does not apply: {why}", w.id, w.file, w.line),
                None if w.after_waiver.as_ref().is_some_and(|a| !self.get(a).and_then(|o| o.last_hit_ps).is_some_and(|t| d.time_ps >= t)) => format!(
                    "waiver `{}` ({}:{}) does not apply: the difference does not follow a divergence `{}` took (after-waiver)",
                    w.id,
                    w.file,
                    w.line,
                    w.after_waiver.as_deref().unwrap_or("")
                ),
                None if w.until_read.is_some() => {
                    let reg = w.until_read.as_deref().unwrap_or("");
                    match w.outlasted {
                        Some((start, read)) if start == d.time_ps => format!(
                            "waiver `{}` ({}:{}) does not apply: the pin still differed after the host's read of {reg} that completed at {read} ps (until-read = \"{reg}\")",
                            w.id, w.file, w.line
                        ),
                        _ => format!(
                            "waiver `{}` ({}:{}) already used its max-hits = {} episode(s) (until-read = \"{reg}\")",
                            w.id, w.file, w.line, w.episodes
                        ),
                    }
                }
                None if w.late_by.is_some() && w.max_hits.is_some_and(|m| w.episodes >= m) => format!(
                    "waiver `{}` ({}:{}) already used its max-hits = {} difference(s) (late-by: reports of one lasting difference count once)",
                    w.id, w.file, w.line, w.episodes
                ),
                None if w.max_hits.is_some_and(|m| w.hits >= m) => {
                    format!("waiver `{}` ({}:{}) already used its max-hits = {}", w.id, w.file, w.line, w.hits)
                }
                None => match w.late_by {
                    Some(by) => format!(
                        "waiver `{}` ({}:{}) does not apply: the DUT's pin lags longer than late-by = \"{}\"",
                        w.id,
                        w.file,
                        w.line,
                        String::from(by)
                    ),
                    None => format!(
                        "waiver `{}` ({}:{}) does not apply: the deviation lasts longer than late-bits = {}",
                        w.id,
                        w.file,
                        w.line,
                        w.late_bits.unwrap_or(0)
                    ),
                },
            })
            .collect()
    }

    /// Waivers that never matched (stale).
    pub fn stale(&self) -> Vec<&Waiver> {
        self.waivers.iter().filter(|w| w.hits == 0).collect()
    }

    /// Hit count of a waiver.
    pub fn hits(&self, id: &str) -> Option<u32> {
        self.get(id).map(|w| w.hits)
    }

    /// Forgets hit counts and episodes (a new run with the same file).
    pub fn reset_hits(&mut self) {
        for w in &mut self.waivers {
            w.hits = 0;
            w.episodes = 0;
            w.episode = None;
            w.late = None;
            w.read_episode = None;
            w.reads.clear();
            w.own_reads.clear();
            w.outlasted = None;
            w.last_hit_ps = None;
        }
        self.frame_starts.clear();
    }

    /// A start of frame on the bus at `t_ps` (simulated time): between two
    /// hits of a register-read waiver with `late-bits` it ends the episode
    /// (a difference of one frame's tail, such as D2's, ends with it).
    pub fn frame_start(&mut self, t_ps: u64) {
        if self.frame_starts.len() >= RECENT_READS {
            self.frame_starts.remove(0);
        }
        self.frame_starts.push(t_ps);
    }

    /// The host's read of `register` completed at `t_ps` (simulated time):
    /// it ends the open episode of every `until-read` waiver on that
    /// register, and of every register-read waiver with `late-bits` on it
    /// unless the read is the episode's next hit (an agreeing read between
    /// two hits shows the deviation had ended).
    pub fn host_read(&mut self, register: &str, t_ps: u64) {
        for w in &mut self.waivers {
            if w.kind == DivergenceKind::RegisterRead
                && w.late_bits.is_some()
                && w.register.as_deref().is_some_and(|r| r.eq_ignore_ascii_case(register))
            {
                if w.own_reads.len() >= RECENT_READS {
                    w.own_reads.remove(0);
                }
                w.own_reads.push(t_ps);
            }
            if w.until_read.as_deref().is_some_and(|r| r.eq_ignore_ascii_case(register)) {
                if w.read_episode.is_none() && w.reads.len() >= RECENT_READS {
                    w.reads.remove(0);
                }
                w.reads.push(t_ps);
            }
        }
    }
}

/// A mode in reports: BasicCAN or PeliCAN.
fn mode_name(basic: bool) -> &'static str {
    if basic { "BasicCAN" } else { "PeliCAN" }
}

/// A mode as the `model-mode` key spells it.
fn mode_key(basic: bool) -> &'static str {
    if basic { "basic" } else { "pelican" }
}

pub(crate) fn invalid(file: &str, line: usize, key: &str, message: String) -> WaiverError {
    WaiverError::Invalid { file: file.into(), line, key: key.into(), message }
}

/// Checks the keys against each other (the per-key checks ran in serde).
fn validate(name: &str, src: &str, w: RawWaiver) -> Result<Waiver, WaiverError> {
    let at = |span: std::ops::Range<usize>| file::line_of(src, span.start);
    let id_line = at(w.id.span());
    let id = w.id.into_inner();
    let bad_id = id.is_empty() || !id.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.');
    if bad_id {
        return Err(invalid(name, id_line, "id", format!("`{id}`: use letters, digits, `-`, `_`, `.`")));
    }
    let explanation_line = at(w.explanation.span());
    let explanation = w.explanation.into_inner();
    let e = explanation.trim();
    if e.len() < 10 || e.starts_with("TODO") {
        return Err(invalid(
            name,
            explanation_line,
            "explanation",
            format!("waiver `{id}` needs a real explanation of why the deviation is accepted"),
        ));
    }
    if w.dut.get_ref().is_empty() {
        return Err(invalid(name, at(w.dut.span()), "dut", format!("waiver `{id}` names no DUT")));
    }
    let kind = w.kind.kind();
    if let Some(r) = &w.register
        && w.kind != KindName::RegisterRead
    {
        return Err(invalid(
            name,
            at(r.span()),
            "register",
            format!("`register` is for kind register-read, not {}", w.kind.as_str()),
        ));
    }
    let mut bits = None;
    if let Some(b) = &w.bits {
        if w.kind != KindName::RegisterRead {
            return Err(invalid(
                name,
                at(b.span()),
                "bits",
                format!("`bits` is for kind register-read, not {}", w.kind.as_str()),
            ));
        }
        let mut mask = 0u8;
        for &n in b.get_ref() {
            if n > 7 {
                return Err(invalid(name, at(b.span()), "bits", format!("register bit {n} out of 0..=7")));
            }
            mask |= 1 << n;
        }
        bits = Some(mask);
    }
    let resync_line = at(w.resync.span());
    let resync = w.resync.into_inner();
    if resync.is_empty() {
        return Err(invalid(name, resync_line, "resync", "say what the comparator may do: e.g. [\"none\"]".into()));
    }
    if resync.len() > 1 && resync.contains(&ResyncSpec::None) {
        return Err(invalid(name, resync_line, "resync", "`none` cannot be combined with other steps".into()));
    }
    if resync.contains(&ResyncSpec::AdoptDutRegister) && (w.kind != KindName::RegisterRead || w.address.is_none()) {
        return Err(invalid(
            name,
            resync_line,
            "resync",
            "adopt-dut-register needs kind = \"register-read\" and the register's `address`".into(),
        ));
    }
    if resync.contains(&ResyncSpec::ModelSkipsSleep) {
        let mod_read = w.kind == KindName::RegisterRead
            && (w.address == Some(0) || w.register.as_ref().is_some_and(|r| r.get_ref().eq_ignore_ascii_case("MOD")));
        if !mod_read {
            return Err(invalid(
                name,
                resync_line,
                "resync",
                "model-skips-sleep needs kind = \"register-read\" of MOD (register = \"MOD\" or address = 0)".into(),
            ));
        }
    }
    if resync.contains(&ResyncSpec::ModelWaitsBusFreeAfterBusOn) {
        let sr_read = w.kind == KindName::RegisterRead
            && (w.address == Some(2) || w.register.as_ref().is_some_and(|r| r.get_ref().eq_ignore_ascii_case("SR")));
        if !sr_read || w.max_hits.is_none() {
            return Err(invalid(
                name,
                resync_line,
                "resync",
                "model-waits-bus-free-after-bus-on needs kind = \"register-read\" of SR (register = \"SR\" or address = 2) and a `max-hits`".into(),
            ));
        }
    }
    if let Some(l) = &w.late_bits
        && *l.get_ref() == 0
    {
        return Err(invalid(name, at(l.span()), "late-bits", "late-bits = 0 would never waive anything".into()));
    }
    let late_by = match &w.late_by {
        Some(l) if !matches!(w.kind, KindName::Irq | KindName::BusOff) => {
            return Err(invalid(
                name,
                at(l.span()),
                "late-by",
                format!("`late-by` is for kinds irq and bus-off, not {}", w.kind.as_str()),
            ));
        }
        l => l.as_ref().map(|l| *l.get_ref()),
    };
    let until_read = match &w.until_read {
        Some(u) if w.kind != KindName::Irq => {
            return Err(invalid(
                name,
                at(u.span()),
                "until-read",
                format!("`until-read` is for kind irq (a read of IR clears an interrupt), not {}", w.kind.as_str()),
            ));
        }
        Some(u) if !u.get_ref().eq_ignore_ascii_case("IR") => {
            return Err(invalid(
                name,
                at(u.span()),
                "until-read",
                format!("`{}`: only \"IR\" ends a pin difference (its read clears the interrupt flags, datasheet Table 15)", u.get_ref()),
            ));
        }
        Some(u) if w.late_by.is_some() || w.late_bits.is_some() => {
            return Err(invalid(
                name,
                at(u.span()),
                "until-read",
                "one bound on how long a difference lasts: `until-read`, or `late-by` / `late-bits`, not both".into(),
            ));
        }
        Some(u) if w.max_hits.is_none() => {
            return Err(invalid(name, at(u.span()), "until-read", "needs a `max-hits` (the number of episodes)".into()));
        }
        Some(_) => Some("IR".to_string()),
        None => None,
    };
    let after_lost = match &w.after {
        Some(a) => Some(file::parse_after(a.get_ref()).map_err(|m| invalid(name, at(a.span()), "after", m))?),
        None => None,
    };
    let model_basic = match &w.model_mode {
        Some(m) => match m.get_ref().trim() {
            "basic" => Some(true),
            "pelican" => Some(false),
            other => {
                return Err(invalid(name, at(m.span()), "model-mode", format!("`{other}`: expected \"basic\" or \"pelican\"")));
            }
        },
        None => None,
    };
    let model_rx_extended = match &w.model_rx_frame {
        Some(m) if w.kind != KindName::RegisterRead => {
            return Err(invalid(name, at(m.span()), "model-rx-frame", format!("`model-rx-frame` is for kind register-read, not {}", w.kind.as_str())));
        }
        Some(m) => match m.get_ref().trim() {
            "extended" => Some(true),
            "standard" => Some(false),
            other => {
                return Err(invalid(name, at(m.span()), "model-rx-frame", format!("`{other}`: expected \"extended\" or \"standard\"")));
            }
        },
        None => None,
    };
    let mut patterns = [None, None];
    for (slot, key, p) in [(0, "expected-bits", &w.expected_bits), (1, "seen-bits", &w.seen_bits)] {
        if let Some(p) = p {
            if w.kind != KindName::RegisterRead {
                return Err(invalid(
                    name,
                    at(p.span()),
                    key,
                    format!("`{key}` is for kind register-read, not {}", w.kind.as_str()),
                ));
            }
            patterns[slot] = Some(*p.get_ref());
        }
    }
    let [expected_bits, seen_bits] = patterns;
    if let (Some(e), Some(s), Some(p)) = (expected_bits, seen_bits, &w.seen_bits)
        && e.care == 0xFF
        && s.care == 0xFF
        && e.value == s.value
    {
        return Err(invalid(
            name,
            at(p.span()),
            "seen-bits",
            "both patterns give the same value: no divergence can match".into(),
        ));
    }
    let seen_offset = match &w.seen_offset {
        Some(o) if w.kind != KindName::RegisterRead => {
            return Err(invalid(
                name,
                at(o.span()),
                "seen-offset",
                format!("`seen-offset` is for kind register-read, not {}", w.kind.as_str()),
            ));
        }
        Some(o) if *o.get_ref() == 0 || o.get_ref().abs() > 255 => {
            return Err(invalid(name, at(o.span()), "seen-offset", "an offset is 1..=255 or -255..=-1".into()));
        }
        o => o.as_ref().map(|o| *o.get_ref()),
    };
    if let Some(m) = &w.max_hits
        && *m.get_ref() == 0
    {
        return Err(invalid(name, at(m.span()), "max-hits", "max-hits = 0 would never waive anything".into()));
    }
    let consequences = match w.consequences {
        Some(c) => {
            let line = at(c.span());
            let c = c.into_inner();
            if c.is_empty() {
                return Err(invalid(name, line, "consequences", "an empty list: leave the key out".into()));
            }
            if let Some(d) = c.iter().enumerate().find(|(i, x)| c[..*i].contains(x)) {
                return Err(invalid(name, line, "consequences", format!("`{}` is listed twice", String::from(d.1.clone()))));
            }
            c
        }
        None => Vec::new(),
    };
    Ok(Waiver {
        id,
        kind,
        explanation,
        clause: w.clause.filter(|c| !c.trim().is_empty()),
        file: name.into(),
        line: id_line,
        dut: w.dut.into_inner(),
        revisions: w.revisions,
        fields: w.fields.map(|f| f.into_inner().into_iter().map(|f| f.0).collect()).unwrap_or_default(),
        register: w.register.map(|r| r.into_inner()),
        address: w.address,
        bits,
        expected: w.expected,
        seen: w.seen,
        dut_tec: w.dut_tec,
        dut_rec: w.dut_rec,
        frames: w.frames,
        context: w.context,
        late_bits: w.late_bits.map(|l| l.into_inner()),
        late_by,
        until_read,
        after_lost,
        expected_bits,
        seen_bits,
        seen_offset,
        model_mod_bits: w.model_mod_bits,
        model_ir_bits: w.model_ir_bits,
        after_waiver: w.after_waiver.map(|a| a.into_inner()),
        last_hit_ps: None,
        model_basic,
        model_rx_extended,
        after_abort: w.after_abort.unwrap_or(false),
        max_hits: w.max_hits.map(|m| m.into_inner()),
        resync,
        consequences,
        hits: 0,
        episodes: 0,
        episode: None,
        late: None,
        read_episode: None,
        reads: Vec::new(),
        own_reads: Vec::new(),
        outlasted: None,
    })
}

/// The first sentence of a waiver explanation (up to `. ` or `; ` or the
/// end of its first line), a leading table tag dropped: `D8a. ` or
/// `D3 (a remark). ` (docs/opencores-deviations.md numbers its rows so).
pub fn summary_of(explanation: &str) -> String {
    let line = explanation.trim().lines().next().unwrap_or("").trim();
    let is_tag = |t: &str| {
        t.len() <= 5
            && t.starts_with(|c: char| c.is_ascii_uppercase())
            && t[1..].starts_with(|c: char| c.is_ascii_digit())
            && t.chars().all(|c| c.is_ascii_alphanumeric())
    };
    let mut rest = line;
    if let Some(n) = rest.find(". ") {
        let head = &rest[..n];
        let tag = head.split(" (").next().unwrap_or(head);
        if is_tag(tag) && (head == tag || head.ends_with(')')) {
            rest = &rest[n + 2..];
        }
    }
    let end = [". ", "; "].iter().filter_map(|p| rest.find(p)).min().unwrap_or(rest.len());
    rest[..end].trim_end_matches('.').trim().to_string()
}

#[cfg(test)]
mod summary_tests {
    use super::{DutInfo, DutMatch, EXAMPLE, WaiverSet, file_schema, summary_of};

    #[test]
    fn the_reference_example_parses_and_covers_a_fork_via_its_family() {
        let set = WaiverSet::parse(EXAMPLE, "example").unwrap();
        let w = &set.waivers()[0];
        let fork = DutInfo::new("my-can (/src/my-can)").in_family("my-can", &["opencores-can".into()]);
        assert_eq!(w.matched_by(&fork), Some(DutMatch::Via("opencores-can")));
        assert_eq!(w.matched_by(&DutInfo::new("opencores-can (/src/can)")), Some(DutMatch::Own));
        let other = DutInfo::new("ctu (/src/ctu)").in_family("ctu", &["ctu-can-fd".into()]);
        assert!(!w.applies_to(&other), "another family's DUT");
        assert!(file_schema().as_value().to_string().contains("family"), "the schema documents families");
    }

    #[test]
    fn the_summary_is_the_first_sentence_without_the_row_tag() {
        assert_eq!(summary_of("D1. The core stores it late; CAN 2.0B §5 says. More."), "The core stores it late");
        assert_eq!(summary_of("D8b. RBSA (address 30, datasheet 6.4.17) reads 0."), "RBSA (address 30, datasheet 6.4.17) reads 0");
        assert_eq!(summary_of("D3 (a freedom, not a deviation). TS = 0 in suspend. Why."), "TS = 0 in suspend");
        assert_eq!(summary_of("D1 with D2, in one read: both late. Only that."), "D1 with D2, in one read: both late");
        assert_eq!(summary_of("bit 7 of address 4 is not implemented"), "bit 7 of address 4 is not implemented");
        assert_eq!(summary_of("SR.TS (and SR.RS) late. Next."), "SR.TS (and SR.RS) late");
        assert_eq!(summary_of("first line\nsecond line"), "first line");
    }
}
