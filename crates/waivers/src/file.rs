//! The waiver file: TOML read through serde, unknown keys rejected, every
//! error located as `file:line: key: message`. Besides `[[waiver]]` tables
//! it may hold `[[expected-failure]]` tables (strict expected failures of
//! whole scenarios, with their signature: [`crate::expected`]).
//!
//! ```toml
//! [[waiver]]
//! id = "tec-after-error-passive"
//! kind = "tx-bit"                  # tx-bit | register-read | irq | bus-off
//! fields = ["ActiveErrorFlag"]     # tx-bit, irq, bus-off: field the model was in
//! dut = ["opencores-can*"]         # DUT name globs (at least one)
//! revisions = ["r3..r7"]           # optional; inclusive ranges
//! explanation = "why this deviation is accepted"
//! late-bits = 1                    # optional bound: the deviation lasts <= 1 bit
//! dut-tec = [136]                  # optional bound on the DUT's TEC (see Waiver::dut_tec)
//! # Other keys: register = "SR", address = 2, bits = [6] (register bits that
//! # may differ), expected = [..] / seen = [..] (allowed model / DUT values),
//! # dut-rec = [..], frames = "2..5", context = "text", max-hits = N,
//! # clause = "CAN 2.0B §8" (the clause the deviation breaks, for reports;
//! # the first sentence of `explanation` is the deviation in plain words).
//! resync = ["skip-bits 1", "adopt-dut-tec"]
//! ```
//!
//! Resync steps (applied in order once the divergence is waived, so the
//! next report is the next real difference, not a consequence of this one):
//!
//! - `none`: nothing; compare on.
//! - `skip-bits N`: N bit times are not compared (the diverging one first).
//! - `adopt-dut-tec` / `adopt-dut-rec`: the model takes the DUT's counter.
//! - `adopt-dut-register`: the model takes the value the DUT returned
//!   (register-read with `address`): storage registers, TXERR/RXERR, and
//!   SR's latched flags TCS and DOS when every other SR bit already agrees
//!   (the rest of SR, IR and RMC follow the model's engine, interrupts and
//!   FIFO: not adoptable; the report notes a step the model refused).
//!   After adoption later reads agree, so a scenario expectation on them is
//!   judged against the adopted value: prefer `none` where a scenario step
//!   checks the datasheet value again.
//! - `model-skips-sleep`: for a core with no sleep mode. The model leaves
//!   sleep at once and raises no wake-up interrupt, as the DUT never slept;
//!   the frame that would have woken it is then received by both. Only on
//!   a register-read of MOD (PeliCAN address 0, the SM bit: `bits = [4]`),
//!   so a waiver cannot use it to forget anything but the sleep request.
//! - `model-waits-bus-free-after-bus-on`: for a core that waits for one
//!   more bus-free sequence (11 recessive bits) after bus-on. The model,
//!   if its bus-on was at most 3 bits ago and it has been idle since,
//!   integrates again from its bus-on (SR TS = RS = 1) and holds a frame
//!   then requested for at most 2 bits past the 11th, starting it at the
//!   DUT's start of frame. Only on a register-read of SR, with `max-hits`.
//!
//! Narrower bounds for deviations that are a bit pattern or a lateness:
//!
//! ```toml
//! # register-read only: the model's and the DUT's value, MSB first, each
//! # character 0, 1 or x (either); `_` is a separator. Here: the model
//! # reads RS = 1, TS = 0 and the DUT the other way round (the other bits
//! # may differ only where `bits` allows it, if given).
//! expected-bits = "xx01_xxxx"
//! seen-bits     = "xx10_xxxx"
//! # register-read only: the DUT's value is the model's plus this (e.g. a
//! # counter one ahead of the model's all along: TXERR 128 for 127).
//! seen-offset = 1
//! # any kind: the model's PeliCAN mode register (MOD) at the divergence
//! # must have this pattern, e.g. listen-only mode set (MOD.1). A run in
//! # BasicCAN, or one that does not give the model's MOD, never matches.
//! model-mod-bits = "xxxx_xx1x"
//! # any kind: the model's IR (its pending interrupts, read without
//! # clearing them) at the divergence must have this pattern, e.g. EPI
//! # pending (IR.5). A run that does not give the model's IR never matches.
//! model-ir-bits = "xx1x_xxxx"
//! # any kind: only for a difference that starts after a divergence the
//! # named waiver (of the same file) took in the run: a consequence of
//! # that deviation, such as a pin left parted by a waived read.
//! after-waiver = "epi-late-not-yet-in-ir-at-the-error"
//! # any kind: the model's mode (CDR.7) at the divergence must be this:
//! # "basic" (BasicCAN) or "pelican". For a deviation that exists in one
//! # mode only. A run that does not give the model's mode never matches.
//! model-mode = "basic"
//! # any kind: only while the host's last word on the model's transmission
//! # request was an abort (CMR.AT written since the last TR or SRR), for a
//! # deviation in how a core shows an aborted request. A run that does not
//! # give the model's abort state never matches.
//! after-abort = true
//! # irq and bus-off only: the DUT's pin may lag the model by at most this
//! # long, counted from the start of the difference to the clock the
//! # comparator reports it: bit times and/or CAN clocks ("1 bit",
//! # "2 bits", "16 clocks", "1 bit + 16 clocks"). Checked against the
//! # comparator's clock (`Observed::now_ps`, `bit_time_ps`,
//! # `can_clock_ps`); a run that does not give them never matches.
//! late-by = "1 bit + 16 clocks"
//! # irq only: a pin difference that the host's read of IR ends (the read
//! # clears the interrupt flag of the side that has it, datasheet Table
//! # 15). One episode runs from the start of the difference until the
//! # host's next read of IR; a report of it whose run began after that read
//! # completed (the pin still differed for more than the comparator's pin
//! # tolerance after the read) is not waived. `max-hits` then counts
//! # episodes, not the comparator's repeated reports of one difference
//! # (their number grows with how long the host takes to read IR). Not
//! # with `late-by` or `late-bits`; only "IR" is accepted.
//! until-read = "IR"
//! # any kind: the waiver applies only once the reference (the model) has
//! # lost a message to an RX FIFO overrun (SR.DOS's condition), counted
//! # since its RX FIFO was last emptied (reset mode entered, hardware
//! # reset; releases do not forget a loss). For a deviation that exists
//! # only after a lost message (a core that keeps an entry per lost
//! # message until reset mode). "2 data-overruns": two lost messages. A
//! # run whose reference does not report its losses never matches.
//! after = "data-overrun"
//! ```
//!
//! A scenario expectation (a register read with an expected value) that
//! fails on a read whose divergence a waiver covered, and that the model's
//! value meets, counts as waived by that waiver: it is listed in
//! `WaiverReport::waived_expectations`, never passed silently
//! (`Session::waive_expectation`).
//!
//! A scenario expectation on a read where DUT and model AGREE (so no
//! divergence to waive) can still follow from a waived deviation, e.g. a
//! core without sleep mode never reads SM = 1. A waiver lists such
//! expectations explicitly, each as `"<scenario>:step <n>"` (the scenario's
//! name and the 1-based step number of the expectation) or
//! `"<scenario>:received by <node>"` (the scenario's `received` count of
//! that model node):
//!
//! ```toml
//! consequences = ["pelican-sleep-wakeup:step 12", "pelican-sleep-wakeup:received by acker"]
//! ```
//!
//! A listed expectation that fails counts as waived ONLY if this waiver
//! was hit earlier in the same run; it is then listed in
//! `WaiverReport::waived_expectations` as a consequence of the waiver
//! (`Session::waive_consequence`). Otherwise, and for any expectation not
//! listed, the failure stands.
//!
//! A listed expectation may also be on a read that itself diverged (waived
//! by any waiver) where the model's value misses the expectation too: a
//! waived deviation moved the host's read to a moment the scenario did not
//! intend (e.g. a "wait for TBS" that ends a frame early). It is waived
//! only if the listing waiver was hit BEFORE that read
//! (`Session::waive_consequence_on_waived_read`), and listed with the
//! model's value.

use std::fmt;
use std::str::FromStr;

use can_proto::Field;
use diagnose::DivergenceKind;
use diagnose::named::Named;
use serde::{Deserialize, Serialize};
use toml::Spanned;

/// A waiver file could not be read or is malformed.
#[derive(Debug, thiserror::Error)]
pub enum WaiverError {
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// File name.
        file: String,
        /// Cause.
        source: std::io::Error,
    },
    /// A key is missing, unknown, or has a bad value.
    #[error("{file}:{line}: {key}: {message}")]
    Invalid {
        /// File name.
        file: String,
        /// 1-based line.
        line: usize,
        /// The key at fault (or the table, e.g. `waiver`).
        key: String,
        /// What is wrong.
        message: String,
    },
}

/// The divergence kinds a waiver can name, spelled as in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum KindName {
    /// `DivergenceKind::TxBit`.
    TxBit,
    /// `DivergenceKind::RegisterRead`.
    RegisterRead,
    /// `DivergenceKind::Irq`.
    Irq,
    /// `DivergenceKind::BusOff`.
    BusOff,
    /// `DivergenceKind::Clkout`.
    Clkout,
}

impl KindName {
    /// The comparator's kind.
    pub fn kind(self) -> DivergenceKind {
        match self {
            KindName::TxBit => DivergenceKind::TxBit,
            KindName::RegisterRead => DivergenceKind::RegisterRead,
            KindName::Irq => DivergenceKind::Irq,
            KindName::BusOff => DivergenceKind::BusOff,
            KindName::Clkout => DivergenceKind::Clkout,
        }
    }

    /// The file spelling of a comparator kind.
    pub fn of(k: DivergenceKind) -> KindName {
        match k {
            DivergenceKind::TxBit => KindName::TxBit,
            DivergenceKind::RegisterRead => KindName::RegisterRead,
            DivergenceKind::Irq => KindName::Irq,
            DivergenceKind::BusOff => KindName::BusOff,
            DivergenceKind::Clkout => KindName::Clkout,
        }
    }

    /// `tx-bit`, `register-read`, ...
    pub fn as_str(self) -> &'static str {
        match self {
            KindName::TxBit => "tx-bit",
            KindName::RegisterRead => "register-read",
            KindName::Irq => "irq",
            KindName::BusOff => "bus-off",
            KindName::Clkout => "clkout",
        }
    }
}

/// A revision such as `r5` or `v1.2`: a letter prefix and dotted numbers,
/// compared number by number.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Revision {
    prefix: String,
    numbers: Vec<u64>,
}

impl FromStr for Revision {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim();
        let digits = s.find(|c: char| c.is_ascii_digit()).ok_or_else(|| format!("revision `{s}` has no number"))?;
        let (prefix, rest) = s.split_at(digits);
        if !prefix.chars().all(|c| c.is_ascii_alphabetic()) {
            return Err(format!("revision `{s}`: expected letters then dotted numbers, e.g. `r5` or `v1.2`"));
        }
        let numbers = rest
            .split('.')
            .map(|n| n.parse::<u64>().map_err(|_| format!("revision `{s}`: `{n}` is not a number")))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Revision { prefix: prefix.to_ascii_lowercase(), numbers })
    }
}

impl fmt::Display for Revision {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n: Vec<String> = self.numbers.iter().map(u64::to_string).collect();
        write!(f, "{}{}", self.prefix, n.join("."))
    }
}

/// An inclusive revision range: `r3..r7` (both ends included, like
/// `r3..=r7`), `r3..`, `..r7` or a single `r5`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct RevRange {
    from: Option<Revision>,
    to: Option<Revision>,
}

impl RevRange {
    /// True if `rev` lies in the range (same prefix, numbers within bounds).
    pub fn contains(&self, rev: &Revision) -> bool {
        let same = |r: &Revision| r.prefix == rev.prefix;
        self.from.as_ref().is_none_or(|f| same(f) && f <= rev) && self.to.as_ref().is_none_or(|t| same(t) && rev <= t)
    }
}

impl TryFrom<String> for RevRange {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        let opt = |p: &str| if p.trim().is_empty() { Ok(None) } else { p.parse().map(Some) };
        let r = if let Some((a, b)) = s.split_once("..") {
            let b = b.strip_prefix('=').unwrap_or(b);
            RevRange { from: opt(a)?, to: opt(b)? }
        } else {
            let r: Revision = s.parse()?;
            RevRange { from: Some(r.clone()), to: Some(r) }
        };
        match (&r.from, &r.to) {
            (None, None) => Err(format!("revision range `{s}` has no bound")),
            (Some(a), Some(b)) if a.prefix != b.prefix => Err(format!("revision range `{s}` mixes prefixes")),
            (Some(a), Some(b)) if a > b => Err(format!("revision range `{s}` is empty (start after end)")),
            _ => Ok(r),
        }
    }
}

impl From<RevRange> for String {
    fn from(r: RevRange) -> String {
        r.to_string()
    }
}

impl fmt::Display for RevRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (&self.from, &self.to) {
            (Some(a), Some(b)) if a == b => write!(f, "{a}"),
            (a, b) => {
                if let Some(a) = a {
                    write!(f, "{a}")?;
                }
                f.write_str("..")?;
                if let Some(b) = b {
                    write!(f, "{b}")?;
                }
                Ok(())
            }
        }
    }
}

/// A DUT name glob (`*`, `?`, `[..]`), as the `glob` crate reads it.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct DutGlob(glob::Pattern);

impl DutGlob {
    /// True if `name` matches.
    pub fn matches(&self, name: &str) -> bool {
        self.0.matches(name)
    }
}

impl TryFrom<String> for DutGlob {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        if s.trim().is_empty() {
            return Err("empty DUT glob".into());
        }
        glob::Pattern::new(&s).map(DutGlob).map_err(|e| format!("bad DUT glob `{s}`: {e}"))
    }
}

impl From<DutGlob> for String {
    fn from(g: DutGlob) -> String {
        g.0.as_str().to_string()
    }
}

/// A CAN field named as `can_proto::Field`'s variant (`ActiveErrorFlag`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct FieldName(pub Field);

impl TryFrom<String> for FieldName {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        Field::from_name(&s).map(FieldName).ok_or_else(|| {
            let all: Vec<String> = Field::ALL.iter().map(|f| f.name()).collect();
            format!("unknown field `{s}`, expected one of {}", all.join(", "))
        })
    }
}

impl From<FieldName> for String {
    fn from(f: FieldName) -> String {
        f.0.name()
    }
}

/// An inclusive frame-number range `a..b`, `a..`, `..b` or `n`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct FrameRange {
    /// First frame (inclusive).
    pub from: u32,
    /// Last frame (inclusive).
    pub to: u32,
}

impl FrameRange {
    /// True if `n` is in the range.
    pub fn contains(&self, n: u32) -> bool {
        (self.from..=self.to).contains(&n)
    }
}

impl TryFrom<String> for FrameRange {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        let num = |p: &str, dflt: u32| {
            let p = p.trim();
            if p.is_empty() {
                Ok(dflt)
            } else {
                p.parse::<u32>().map_err(|_| format!("frame range `{s}`: `{p}` is not a number"))
            }
        };
        let (from, to) = match s.split_once("..") {
            Some((a, b)) => (num(a, 0)?, num(b.strip_prefix('=').unwrap_or(b), u32::MAX)?),
            None => {
                let n = num(&s, 0)?;
                (n, n)
            }
        };
        if from > to {
            return Err(format!("frame range `{s}` is empty"));
        }
        Ok(FrameRange { from, to })
    }
}

impl From<FrameRange> for String {
    fn from(r: FrameRange) -> String {
        match (r.from, r.to) {
            (a, b) if a == b => a.to_string(),
            (a, u32::MAX) => format!("{a}.."),
            (a, b) => format!("{a}..{b}"),
        }
    }
}

/// How late a pin may follow the model: `bits` bit times plus `clocks`
/// CAN clocks (`late-by = "1 bit + 16 clocks"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct Lateness {
    /// Whole bit times.
    pub bits: u32,
    /// CAN clocks on top.
    pub clocks: u32,
}

impl Lateness {
    /// The bound in picoseconds for this bit time and CAN clock period.
    pub fn ps(&self, bit_time_ps: u64, can_clock_ps: u64) -> u64 {
        self.bits as u64 * bit_time_ps + self.clocks as u64 * can_clock_ps
    }
}

impl TryFrom<String> for Lateness {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        let mut l = Lateness { bits: 0, clocks: 0 };
        let (mut seen_bits, mut seen_clocks) = (false, false);
        for term in s.split('+') {
            let mut w = term.split_whitespace();
            let (Some(n), Some(unit), None) = (w.next(), w.next(), w.next()) else {
                return Err(format!("`{s}`: expected e.g. \"1 bit\", \"16 clocks\" or \"1 bit + 16 clocks\""));
            };
            let n: u32 = n.parse().map_err(|_| format!("`{s}`: `{n}` is not a number"))?;
            match unit {
                "bit" | "bits" if !seen_bits => (l.bits, seen_bits) = (n, true),
                "clock" | "clocks" if !seen_clocks => (l.clocks, seen_clocks) = (n, true),
                _ => return Err(format!("`{s}`: unit `{unit}` unknown or given twice (bits, clocks)")),
            }
        }
        if l.bits == 0 && l.clocks == 0 {
            return Err(format!("`{s}`: a lateness of 0 would never waive anything"));
        }
        Ok(l)
    }
}

impl From<Lateness> for String {
    fn from(l: Lateness) -> String {
        let unit = |n: u32, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
        match (l.bits, l.clocks) {
            (b, 0) => unit(b, "bit", "bits"),
            (0, c) => unit(c, "clock", "clocks"),
            (b, c) => format!("{} + {}", unit(b, "bit", "bits"), unit(c, "clock", "clocks")),
        }
    }
}

/// An 8-bit register value pattern, MSB first: `0`, `1` or `x` (either) per
/// bit, `_` ignored (`"xx01_xxxx"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct BitPattern {
    /// Bits that must have the given value.
    pub care: u8,
    /// Their values (0 where `care` is 0).
    pub value: u8,
}

impl BitPattern {
    /// True if `v` is a byte with the pattern's 0s and 1s.
    pub fn matches(&self, v: u32) -> bool {
        v <= 0xFF && (v as u8) & self.care == self.value
    }
}

impl TryFrom<String> for BitPattern {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        let chars: Vec<char> = s.chars().filter(|c| *c != '_').collect();
        if chars.len() != 8 {
            return Err(format!("`{s}`: a pattern has 8 bits (0, 1 or x), MSB first, e.g. \"xx01_xxxx\""));
        }
        let mut p = BitPattern { care: 0, value: 0 };
        for (i, c) in chars.iter().enumerate() {
            let bit = 1u8 << (7 - i);
            match c {
                '0' => p.care |= bit,
                '1' => {
                    p.care |= bit;
                    p.value |= bit;
                }
                'x' | 'X' => {}
                _ => return Err(format!("`{s}`: `{c}` is not 0, 1 or x")),
            }
        }
        if p.care == 0 {
            return Err(format!("`{s}`: a pattern of only x bounds nothing"));
        }
        Ok(p)
    }
}

impl From<BitPattern> for String {
    fn from(p: BitPattern) -> String {
        (0..8)
            .map(|i| {
                let bit = 1u8 << (7 - i);
                match (p.care & bit != 0, p.value & bit != 0) {
                    (false, _) => 'x',
                    (true, true) => '1',
                    (true, false) => '0',
                }
            })
            .collect()
    }
}

/// `after = "data-overrun"` (1) or `"<n> data-overruns"` (n >= 1): the
/// number of messages the reference must have lost to an RX FIFO overrun
/// (since its FIFO was last emptied) before the waiver applies.
pub fn parse_after(s: &str) -> Result<u32, String> {
    let bad = || {
        format!("`{s}`: expected \"data-overrun\" or \"<n> data-overruns\" (messages the model lost to an RX FIFO overrun)")
    };
    let t = s.trim();
    if t == "data-overrun" {
        return Ok(1);
    }
    let (n, what) = t.split_once(char::is_whitespace).ok_or_else(bad)?;
    let n: u32 = n.parse().map_err(|_| bad())?;
    match (n, what.trim()) {
        (0, _) => Err(format!("`{s}`: after 0 lost messages is no condition: leave the key out")),
        (1, "data-overrun" | "data-overruns") => Ok(1),
        (n, "data-overruns") if n <= 255 => Ok(n),
        (n, "data-overruns") => Err(format!("`{s}`: {n} lost messages is more than the model counts (255)")),
        _ => Err(bad()),
    }
}

/// The re-synchronisation a waiver allows, as written in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum ResyncSpec {
    /// `none`: keep comparing, nothing adopted.
    None,
    /// `adopt-dut-tec`: the model takes the DUT's transmit error counter.
    AdoptDutTec,
    /// `adopt-dut-rec`: the model takes the DUT's receive error counter.
    AdoptDutRec,
    /// `adopt-dut-register`: the model takes the value the DUT returned for
    /// the register read that diverged (needs `address`).
    AdoptDutRegister,
    /// `model-skips-sleep`: for a core without sleep mode. The model leaves
    /// sleep at once, without a wake-up interrupt, as the DUT never entered
    /// it; later sleep requests still reach the model (and diverge again).
    ModelSkipsSleep,
    /// `model-waits-bus-free-after-bus-on`: for a core that waits for one
    /// more bus-free sequence (11 recessive bits) after bus-on before it
    /// may start a frame. The model, if it came out of bus-off at most 3
    /// bits ago and has been idle since, integrates again from its bus-on
    /// (TS = RS = 1) and holds a transmission then pending for at most 2
    /// bits past the 11th, starting it with the DUT's start of frame.
    /// Only on a register-read of SR with `max-hits`.
    ModelWaitsBusFreeAfterBusOn,
    /// `skip-bits N`: N bit times are not compared, the diverging one
    /// included (`skip-bits 1` forgives that bit only).
    SkipBits(u32),
}

impl TryFrom<String> for ResyncSpec {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        let mut w = s.split_whitespace();
        let r = match (w.next(), w.next(), w.next()) {
            (Some("none"), None, _) => ResyncSpec::None,
            (Some("adopt-dut-tec"), None, _) => ResyncSpec::AdoptDutTec,
            (Some("adopt-dut-rec"), None, _) => ResyncSpec::AdoptDutRec,
            (Some("adopt-dut-register"), None, _) => ResyncSpec::AdoptDutRegister,
            (Some("model-skips-sleep"), None, _) => ResyncSpec::ModelSkipsSleep,
            (Some("model-waits-bus-free-after-bus-on"), None, _) => ResyncSpec::ModelWaitsBusFreeAfterBusOn,
            (Some("skip-bits"), Some(n), None) => match n.parse::<u32>() {
                Ok(n) if n > 0 => ResyncSpec::SkipBits(n),
                _ => return Err(format!("`{s}`: skip-bits takes a positive number of bits")),
            },
            _ => {
                return Err(format!(
                    "unknown resync `{s}`, expected one of: none, adopt-dut-tec, adopt-dut-rec, adopt-dut-register, model-skips-sleep, model-waits-bus-free-after-bus-on, skip-bits N"
                ));
            }
        };
        Ok(r)
    }
}

impl From<ResyncSpec> for String {
    fn from(r: ResyncSpec) -> String {
        match r {
            ResyncSpec::None => "none".into(),
            ResyncSpec::AdoptDutTec => "adopt-dut-tec".into(),
            ResyncSpec::AdoptDutRec => "adopt-dut-rec".into(),
            ResyncSpec::AdoptDutRegister => "adopt-dut-register".into(),
            ResyncSpec::ModelSkipsSleep => "model-skips-sleep".into(),
            ResyncSpec::ModelWaitsBusFreeAfterBusOn => "model-waits-bus-free-after-bus-on".into(),
            ResyncSpec::SkipBits(n) => format!("skip-bits {n}"),
        }
    }
}

/// A scenario expectation that follows from a waived deviation:
/// `"<scenario>:step <n>"` or `"<scenario>:received by <node>"` (see the module doc).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct Consequence {
    /// Scenario name (as in its file's `name`).
    pub scenario: String,
    /// Which of its expectations.
    pub of: ConsequenceOf,
}

/// The expectation a [`Consequence`] names.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ConsequenceOf {
    /// The register-read expectation of this 1-based step.
    Step(usize),
    /// The scenario's `received = { node = n }` count of this model node.
    Received(String),
}

impl TryFrom<String> for Consequence {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        let bad = || {
            format!("`{s}`: a consequence is \"<scenario>:step <n>\" or \"<scenario>:received by <node>\", e.g. \"pelican-sleep-wakeup:step 12\"")
        };
        let (scenario, rest) = s.split_once(':').ok_or_else(bad)?;
        let scenario = scenario.trim();
        if scenario.is_empty() || scenario.contains(char::is_whitespace) {
            return Err(bad());
        }
        let rest = rest.trim();
        let of = if let Some(n) = rest.strip_prefix("step") {
            if !n.starts_with(char::is_whitespace) {
                return Err(bad());
            }
            let step: usize = n.trim().parse().map_err(|_| bad())?;
            if step == 0 {
                return Err(format!("`{s}`: steps are numbered from 1"));
            }
            ConsequenceOf::Step(step)
        } else if let Some(node) = rest.strip_prefix("received by ") {
            let node = node.trim();
            if node.is_empty() || node.contains(char::is_whitespace) {
                return Err(bad());
            }
            ConsequenceOf::Received(node.into())
        } else {
            return Err(bad());
        };
        Ok(Consequence { scenario: scenario.into(), of })
    }
}

impl From<Consequence> for String {
    fn from(c: Consequence) -> String {
        match c.of {
            ConsequenceOf::Step(n) => format!("{}:step {n}", c.scenario),
            ConsequenceOf::Received(node) => format!("{}:received by {node}", c.scenario),
        }
    }
}

/// `[[waiver]]`: a known deviation of a DUT from the golden model, accepted and bounded.
#[derive(Debug, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub(crate) struct RawWaiver {
    /// Unique id among the file's waivers, named in reports. Required.
    #[schemars(with = "String")]
    pub id: Spanned<String>,
    /// What differs: `"tx-bit"`, `"register-read"`, `"irq"`, `"bus-off"` or `"clkout"`. Required.
    #[schemars(with = "String")]
    pub kind: KindName,
    /// Why the deviation is accepted; its first sentence is the deviation in plain
    /// words in reports. Required.
    #[schemars(with = "String")]
    pub explanation: Spanned<String>,
    /// The datasheet or CAN 2.0B clause the deviation breaks, for reports. Default: none.
    #[serde(default)]
    pub clause: Option<String>,
    /// DUT name globs (`*`, `?`, `[..]`), at least one. An external core is named
    /// `"<profile> (<dir>)"`; a glob also matches through the DUT's profile family (the
    /// profiles its profile `extends`), so `"opencores-can (*)"` covers a fork whose
    /// profile extends `opencores-can`, and the report says "applied via family member
    /// opencores-can". Required.
    #[schemars(with = "Vec<String>")]
    pub dut: Spanned<Vec<DutGlob>>,
    /// Inclusive revision ranges (`"r3..r7"`, `"r3.."`, `"..r7"`, `"r5"`); a DUT of
    /// unknown revision never matches one. Default: any revision.
    #[serde(default)]
    #[schemars(with = "Vec<String>")]
    pub revisions: Vec<RevRange>,
    /// The CAN fields (`can_proto::Field` names, `"ActiveErrorFlag"`): the model's at
    /// the difference for tx-bit, irq and bus-off; for register-read the field on the
    /// bus, as the bus decoder labels it, when the read was made (a bound on where a
    /// deviation shows that does not depend on how often the host reads). Default:
    /// any field.
    #[serde(default)]
    #[schemars(with = "Option<Vec<String>>")]
    pub fields: Option<Spanned<Vec<FieldName>>>,
    /// register-read: the register's datasheet name (`"SR"`). Default: any register.
    #[schemars(with = "Option<String>")]
    pub register: Option<Spanned<String>>,
    /// register-read: the register's address; needed by `adopt-dut-register`. Default: any.
    pub address: Option<u8>,
    /// register-read: the bits (0..7) that may differ. Default: any bit.
    #[schemars(with = "Option<Vec<u8>>")]
    pub bits: Option<Spanned<Vec<u8>>>,
    /// Allowed model values. Default: any.
    pub expected: Option<Vec<u32>>,
    /// Allowed DUT values. Default: any.
    pub seen: Option<Vec<u32>>,
    /// Allowed DUT transmit error counts (TEC); with one value it is also what
    /// `adopt-dut-tec` adopts. Default: any.
    pub dut_tec: Option<Vec<u16>>,
    /// Allowed DUT receive error counts (REC). Default: any.
    pub dut_rec: Option<Vec<u16>>,
    /// Frame numbers the divergence may be in (`"2..5"`). Default: any frame.
    #[schemars(with = "Option<String>")]
    pub frames: Option<FrameRange>,
    /// Text the divergence's context must contain. Default: any.
    pub context: Option<String>,
    /// One deviation lasts at most this many bit times; longer, the rest is not waived. For a
    /// register read an episode ends at a read of the register that agreed or at a start of frame
    /// between two hits; for a tx bit, at a bit compared equal between two hits, and it counts
    /// again from the bit after one where the DUT drove dominant and read recessive (a bit error
    /// of its own: a new error flag). Default: unbounded.
    #[schemars(with = "Option<u32>")]
    pub late_bits: Option<Spanned<u32>>,
    /// irq and bus-off: the DUT's pin lags the model's by at most this (`"1 bit"`,
    /// `"16 clocks"`, `"1 bit + 16 clocks"`). Default: unbounded.
    #[schemars(with = "Option<String>")]
    pub late_by: Option<Spanned<Lateness>>,
    /// irq only: a pin difference the host's read of this register ends (only `"IR"`);
    /// `max-hits` then counts episodes. Not with `late-by` or `late-bits`. Default: none.
    #[schemars(with = "Option<String>")]
    pub until_read: Option<Spanned<String>>,
    /// Applies only once the model has lost a message to an RX FIFO overrun
    /// (`"data-overrun"`, `"2 data-overruns"`). Default: always.
    #[schemars(with = "Option<String>")]
    pub after: Option<Spanned<String>>,
    /// register-read: the model's value, MSB first, each character `0`, `1` or `x`
    /// (`_` separates): `"xx01_xxxx"`. Default: any.
    #[schemars(with = "Option<String>")]
    pub expected_bits: Option<Spanned<BitPattern>>,
    /// register-read: the DUT's value as a pattern, like `expected-bits`. Default: any.
    #[schemars(with = "Option<String>")]
    pub seen_bits: Option<Spanned<BitPattern>>,
    /// register-read: the DUT's value is the model's plus this. Default: any.
    #[schemars(with = "Option<i64>")]
    pub seen_offset: Option<Spanned<i64>>,
    /// The model's PeliCAN MOD at the divergence matches this pattern (`"xxxx_xx1x"`). Default: any.
    #[schemars(with = "Option<String>")]
    pub model_mod_bits: Option<BitPattern>,
    /// The model's IR at the divergence (its pending interrupt flags, read without
    /// clearing them) matches this pattern (`"xx1x_xxxx"`: EPI pending). Default: any.
    #[schemars(with = "Option<String>")]
    pub model_ir_bits: Option<BitPattern>,
    /// Only for a difference that starts after a divergence the waiver with this id took
    /// in the run (a consequence of that waived deviation). Default: none.
    #[schemars(with = "Option<String>")]
    pub after_waiver: Option<Spanned<String>>,
    /// The model's mode at the divergence: `"basic"` or `"pelican"`. Default: either.
    #[schemars(with = "Option<String>")]
    pub model_mode: Option<Spanned<String>>,
    /// register-read: the message at the head of the model's RX FIFO is of this frame
    /// format, `"extended"` or `"standard"` (PeliCAN frame information bit 7, read in
    /// operating mode). Default: either.
    #[schemars(with = "Option<String>")]
    pub model_rx_frame: Option<Spanned<String>>,
    /// Only while the host's last word on the model's transmission request was an abort
    /// (CMR.AT written since the last TR or SRR). Default: false.
    pub after_abort: Option<bool>,
    /// At most this many hits are waived (with `until-read`: episodes; with `late-by`: differences, each counted once however often it is reported). Default: unbounded.
    #[schemars(with = "Option<u32>")]
    pub max_hits: Option<Spanned<u32>>,
    /// What the bench does once the divergence is waived, in order: `"none"`,
    /// `"skip-bits N"`, `"adopt-dut-tec"`, `"adopt-dut-rec"`, `"adopt-dut-register"`,
    /// `"model-skips-sleep"`, `"model-waits-bus-free-after-bus-on"`. Required.
    #[schemars(with = "Vec<String>")]
    pub resync: Spanned<Vec<ResyncSpec>>,
    /// Scenario expectations that follow from this deviation though DUT and model agree
    /// (`"<scenario>:step <n>"`, `"<scenario>:received by <node>"`); waived only after
    /// this waiver was hit in the run. Default: none.
    #[serde(default)]
    #[schemars(with = "Option<Vec<String>>")]
    pub consequences: Option<Spanned<Vec<Consequence>>>,
}

/// Suggested entry, written by [`crate::suggest`] (same keys as the file).
#[derive(Debug, Serialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) struct OutWaiver {
    pub id: String,
    pub kind: KindName,
    pub explanation: String,
    pub dut: Vec<String>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub revisions: Vec<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fields: Option<Vec<FieldName>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub register: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub address: Option<u8>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bits: Option<Vec<u8>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub expected: Option<Vec<u32>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seen: Option<Vec<u32>>,
    pub resync: Vec<ResyncSpec>,
}

#[derive(Debug, Serialize)]
pub(crate) struct OutFile {
    pub waiver: Vec<OutWaiver>,
}

/// 1-based line of byte offset `at` in `src`.
pub(crate) fn line_of(src: &str, at: usize) -> usize {
    src[..at.min(src.len())].bytes().filter(|b| *b == b'\n').count() + 1
}

/// Turns a toml error into `file:line: key: message`: the key is the one
/// the message names (missing/unknown field), else the key written on the
/// line the error points at.
pub(crate) fn from_toml(file: &str, src: &str, e: &toml::de::Error) -> WaiverError {
    let message = e.message().trim().to_string();
    let span = e.span().unwrap_or(0..0);
    let line = line_of(src, span.start);
    let quoted = |m: &str| m.split('`').nth(1).map(str::to_string);
    let key = if message.starts_with("missing field") || message.starts_with("unknown field") {
        quoted(&message)
    } else {
        None
    }
    .or_else(|| {
        // The key on that line, or on the line that opened a multi-line
        // value (an array over several lines); a table header ends the search.
        let lines: Vec<&str> = src.lines().take(line).collect();
        for text in lines.iter().rev() {
            let t = text.trim();
            if let Some(h) = t.strip_prefix("[[").and_then(|t| t.strip_suffix("]]")) {
                return Some(h.trim().to_string());
            }
            if let Some(h) = t.strip_prefix('[').and_then(|t| t.strip_suffix(']')).filter(|h| !h.contains(['"', ','])) {
                return Some(h.trim().to_string());
            }
            if let Some((k, _)) = t.split_once('=') {
                let k = k.trim().trim_matches('"');
                if !k.is_empty() && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_') {
                    return Some(k.to_string());
                }
            }
        }
        None
    })
    .unwrap_or_else(|| "waiver".into());
    WaiverError::Invalid { file: file.into(), line, key, message }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rev(s: &str) -> Revision {
        s.parse().unwrap()
    }

    #[test]
    fn revision_ranges_are_inclusive_and_prefix_bound() {
        let r = RevRange::try_from("r3..r7".to_string()).unwrap();
        assert!(!r.contains(&rev("r2")));
        assert!(r.contains(&rev("r3")) && r.contains(&rev("r5")) && r.contains(&rev("r7")));
        assert!(!r.contains(&rev("r8")));
        assert!(!r.contains(&rev("v5")), "another prefix is another numbering");
        assert!(!r.contains(&rev("r10")) && RevRange::try_from("r3..".to_string()).unwrap().contains(&rev("r10")));
        let v = RevRange::try_from("v1.2..=v1.10".to_string()).unwrap();
        assert!(v.contains(&rev("v1.9")) && v.contains(&rev("v1.10")) && !v.contains(&rev("v1.11")));
        assert!(RevRange::try_from("..r4".to_string()).unwrap().contains(&rev("r0")));
        assert!(RevRange::try_from("r5".to_string()).unwrap().contains(&rev("R5")));
        for bad in ["..", "r7..r3", "r1..v2", "rx", "r1.a"] {
            assert!(RevRange::try_from(bad.to_string()).is_err(), "{bad} must be rejected");
        }
        assert_eq!(String::from(RevRange::try_from("r3..=r7".to_string()).unwrap()), "r3..r7");
    }

    #[test]
    fn lateness_and_bit_pattern_spelling() {
        let l = |s: &str| Lateness::try_from(s.to_string());
        assert_eq!(l("1 bit"), Ok(Lateness { bits: 1, clocks: 0 }));
        assert_eq!(l("1 bit + 16 clocks"), Ok(Lateness { bits: 1, clocks: 16 }));
        assert_eq!(l("24 clocks"), Ok(Lateness { bits: 0, clocks: 24 }));
        assert_eq!(String::from(l("2 bits+1 clock").unwrap()), "2 bits + 1 clock");
        assert_eq!(l("1 bit").unwrap().ps(1_000, 10), 1_000);
        assert_eq!(l("1 bit + 16 clocks").unwrap().ps(1_000, 10), 1_160);
        for bad in ["", "1", "bit", "1 byte", "1 bit + 2 bits", "0 bits", "0 bits + 0 clocks", "-1 bit", "1 bit 2"] {
            assert!(l(bad).is_err(), "{bad} must be rejected");
        }
        let p = |s: &str| BitPattern::try_from(s.to_string());
        let ts = p("xx10_xxxx").unwrap();
        assert_eq!(ts, BitPattern { care: 0x30, value: 0x20 });
        assert!(ts.matches(0x2C) && ts.matches(0x20) && !ts.matches(0x1C) && !ts.matches(0x3C) && !ts.matches(0x120));
        assert_eq!(String::from(ts), "xx10xxxx");
        for bad in ["xx10xxx", "xx10_xxxxx", "xx12_xxxx", "xxxx_xxxx", ""] {
            assert!(p(bad).is_err(), "{bad} must be rejected");
        }
    }

    #[test]
    fn after_spelling() {
        assert_eq!(parse_after("data-overrun"), Ok(1));
        assert_eq!(parse_after(" 1 data-overrun "), Ok(1));
        assert_eq!(parse_after("2 data-overruns"), Ok(2));
        for bad in ["", "overrun", "data-overruns", "0 data-overruns", "2 data-overrun", "x data-overruns", "2", "256 data-overruns", "-1 data-overruns"] {
            assert!(parse_after(bad).is_err(), "{bad} must be rejected");
        }
    }

    #[test]
    fn consequence_spelling() {
        let c = |s: &str| Consequence::try_from(s.to_string());
        let step = |n| ConsequenceOf::Step(n);
        assert_eq!(c("pelican-sleep-wakeup:step 12"), Ok(Consequence { scenario: "pelican-sleep-wakeup".into(), of: step(12) }));
        assert_eq!(String::from(c(" a : step  3").unwrap()), "a:step 3");
        assert_eq!(c("a:received by acker").unwrap().of, ConsequenceOf::Received("acker".into()));
        for bad in ["", "a", "a:12", "a:step", "a:step x", "a:step 0", ":step 1", "a b:step 1", "a:steps 1", "a:step1", "a:received by", "a:received acker", "a:received by a b"] {
            assert!(c(bad).is_err(), "{bad} must be rejected");
        }
    }

    #[test]
    fn resync_and_frames_spelling() {
        assert_eq!(ResyncSpec::try_from("model-skips-sleep".to_string()), Ok(ResyncSpec::ModelSkipsSleep));
        assert!(ResyncSpec::try_from("model-skips-sleep 2".to_string()).is_err());
        assert_eq!(
            ResyncSpec::try_from("model-waits-bus-free-after-bus-on".to_string()),
            Ok(ResyncSpec::ModelWaitsBusFreeAfterBusOn)
        );
        assert!(ResyncSpec::try_from("model-waits-bus-free-after-bus-on 11".to_string()).is_err());
        assert_eq!(
            String::from(ResyncSpec::ModelWaitsBusFreeAfterBusOn),
            "model-waits-bus-free-after-bus-on"
        );
        assert_eq!(ResyncSpec::try_from("skip-bits 3".to_string()), Ok(ResyncSpec::SkipBits(3)));
        assert!(ResyncSpec::try_from("skip-bits 0".to_string()).is_err());
        assert!(ResyncSpec::try_from("skip-bits".to_string()).is_err());
        assert!(ResyncSpec::try_from("adopt-tec".to_string()).is_err());
        assert_eq!(String::from(ResyncSpec::SkipBits(2)), "skip-bits 2");
        let f = FrameRange::try_from("2..4".to_string()).unwrap();
        assert!(f.contains(2) && f.contains(4) && !f.contains(5) && !f.contains(1));
        assert!(FrameRange::try_from("5..2".to_string()).is_err());
    }
}
