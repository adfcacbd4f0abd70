//! The CLKOUT check: `clkout_o`'s period and enable against the clock
//! divider the reference holds (SJA1000 datasheet, clock divider register
//! CDR: CD.2..0 = 0..6 give fosc / (2 (CD + 1)), CD = 7 gives fosc, CDR.3
//! switches CLKOUT off). The phase is not compared: the DUT takes a CDR
//! write some CAN edges after the model (its profile's access timing), so
//! each side's divider restarts at its own clock; the half period (clocks
//! between two toggles) and whether it toggles at all are compared.

/// What `clkout_o` must do, from the reference's CDR.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClkoutSetting {
    /// Toggles every `half_period` CAN clocks (CD = 0..6: CD + 1).
    Divide {
        /// CAN clocks between two toggles.
        half_period: u32,
    },
    /// `clkout_o` is `clk_i` itself (CD = 7). Read once per CAN clock, a
    /// pin that is the clock reads 0 or 1 from one clock to the next
    /// (measured on our RTL), so its level at the rising edge is no check.
    /// When the bench also gives the levels the pin had at every instant
    /// it evaluated the DUT (both clock edges: [`ClkoutCheck::instants`],
    /// a Verilated DUT), the pin must be seen low and high within every
    /// [`FOSC_WINDOW`] CAN clocks: a CLKOUT held at one level is caught,
    /// its phase and duty cycle are not checked.
    Fosc,
    /// CDR.3 (clock off): no toggle.
    Off,
    /// Not checked: sleep mode, where the datasheet lets CLKOUT run on for
    /// at least 15 bit times before it goes low, and the first clocks
    /// after waking.
    Unchecked,
}

impl ClkoutSetting {
    /// The setting of CDR value `cdr` (awake).
    pub fn from_cdr(cdr: u8) -> ClkoutSetting {
        if cdr & 0x08 != 0 {
            ClkoutSetting::Off
        } else if cdr & 0x07 == 0x07 {
            ClkoutSetting::Fosc
        } else {
            ClkoutSetting::Divide { half_period: u32::from(cdr & 0x07) + 1 }
        }
    }
}

/// CAN clocks around a change of setting in which the DUT is not held to
/// either setting: its CDR write may land a few CAN edges before or after
/// the model's (the profile's access timing), and the toggle under way may
/// end early or late. A difference is reported only once it has stood
/// this long without the model's setting changing.
pub const SETTLE_CLOCKS: u32 = 32;

/// With CD = 7 (fosc), CAN clocks within which `clkout_o` must be seen at
/// both levels (it is the clock: both levels every clock; the window only
/// leaves room for an instant the bench did not evaluate).
pub const FOSC_WINDOW: u32 = 4;

/// A difference the check found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ClkoutMismatch {
    /// Expected: the half period in CAN clocks (0: no toggle).
    pub expected: u32,
    /// Seen on the DUT, in the same unit.
    pub seen: u32,
    /// In words, for the report.
    pub what: String,
}

/// Watches `clkout_o` clock by clock. After a mismatch it stays quiet until
/// the setting changes (a lasting difference is reported once).
#[derive(Clone, Debug)]
pub struct ClkoutCheck {
    setting: ClkoutSetting,
    /// CAN clocks since the setting last changed (saturating).
    since_change: u32,
    last_level: Option<bool>,
    /// CAN clocks since the last toggle seen after the settle time.
    since_toggle: Option<u32>,
    /// A difference found, and the CAN clocks it has stood.
    pending: Option<(ClkoutMismatch, u32)>,
    reported: bool,
    /// Levels of clkout_o seen at the DUT's instants since the last CAN
    /// clock (bit 0: low, bit 1: high), when the bench gives them.
    instant_levels: u8,
    /// The bench gives the levels at every instant (kept across settings).
    sub_clock: bool,
    /// Fosc: levels seen since both were last seen, and for how many clocks.
    fosc_seen: u8,
    fosc_run: u32,
}

impl Default for ClkoutCheck {
    fn default() -> Self {
        ClkoutCheck {
            setting: ClkoutSetting::Unchecked,
            since_change: 0,
            last_level: None,
            since_toggle: None,
            pending: None,
            reported: false,
            instant_levels: 0,
            sub_clock: false,
            fosc_seen: 0,
            fosc_run: 0,
        }
    }
}

impl ClkoutCheck {
    /// One CAN clock: the reference's setting now, the DUT's `clkout_o`.
    #[inline]
    pub fn clock(&mut self, setting: ClkoutSetting, dut_level: bool) -> Option<ClkoutMismatch> {
        if self.settled(setting) {
            self.settled_divide(setting, dut_level);
            return None;
        }
        self.clock_general(setting, dut_level)
    }

    /// The clocks ahead with the reference's `setting` take the short path
    /// of [`ClkoutCheck::clock`] while nothing is found
    /// ([`ClkoutCheck::settled_next`]): the divider's half period if so.
    #[inline]
    pub fn settled_half_period(&self, setting: ClkoutSetting) -> Option<u32> {
        match setting {
            ClkoutSetting::Divide { half_period } if self.settled(setting) => Some(half_period),
            _ => None,
        }
    }

    /// After [`ClkoutCheck::settled_half_period`] gave `half_period` for the
    /// setting, on one of the clocks ahead with it: [`ClkoutCheck::instants`]
    /// (any levels) then [`ClkoutCheck::clock`], if that clock takes the
    /// short path, which reports nothing; true if it did (false: nothing
    /// done, something was found). Of what the short path's condition
    /// reads, only `pending` changes on the way.
    #[inline]
    pub fn settled_next(&mut self, half_period: u32, dut_level: bool) -> bool {
        if self.pending.is_some() {
            return false;
        }
        // What `instants` leaves once the short path has dropped the levels.
        self.sub_clock = true;
        self.settled_divide(ClkoutSetting::Divide { half_period }, dut_level);
        true
    }

    /// Most clocks: a divider setting that has settled, with nothing found
    /// yet. `clock_general` then does exactly what `settled_divide` does: no
    /// reset (same setting), the instants dropped (only `Fosc` reads them),
    /// past the settle time (`since_change` only grows), no finding ageing,
    /// and the divider check, whose finding starts ageing.
    #[inline]
    fn settled(&self, setting: ClkoutSetting) -> bool {
        matches!(setting, ClkoutSetting::Divide { .. })
            && setting == self.setting
            && !self.reported
            && self.pending.is_none()
            && self.since_change > SETTLE_CLOCKS
    }

    #[inline(always)]
    fn settled_divide(&mut self, setting: ClkoutSetting, dut_level: bool) {
        let ClkoutSetting::Divide { half_period } = setting else { return };
        self.instant_levels = 0;
        let toggled = self.last_level.is_some_and(|l| l != dut_level);
        self.last_level = Some(dut_level);
        self.since_change = self.since_change.saturating_add(1);
        if let Some(m) = self.divide(half_period, toggled) {
            self.pending = Some((m, 0));
        }
    }

    /// [`ClkoutCheck::clock`] in full.
    #[inline(never)]
    fn clock_general(&mut self, setting: ClkoutSetting, dut_level: bool) -> Option<ClkoutMismatch> {
        let instants = std::mem::take(&mut self.instant_levels);
        if setting != self.setting {
            *self = ClkoutCheck { setting, sub_clock: self.sub_clock, ..ClkoutCheck::default() };
        }
        let toggled = self.last_level.is_some_and(|l| l != dut_level);
        self.last_level = Some(dut_level);
        self.since_change = self.since_change.saturating_add(1);
        if self.reported || self.since_change <= SETTLE_CLOCKS {
            return None;
        }
        if let Some((m, age)) = &mut self.pending {
            *age += 1;
            if *age < SETTLE_CLOCKS {
                return None;
            }
            self.reported = true;
            let mut m = m.clone();
            m.what = format!("{} ({SETTLE_CLOCKS} CAN clocks before this report)", m.what);
            return Some(m);
        }
        let found = match setting {
            ClkoutSetting::Unchecked => None,
            ClkoutSetting::Fosc => self.fosc(instants),
            ClkoutSetting::Off => toggled.then(|| ClkoutMismatch {
                expected: 0,
                seen: 1,
                what: "clkout_o toggles while CDR.3 (clock off) is set".into(),
            }),
            ClkoutSetting::Divide { half_period } => self.divide(half_period, toggled),
        };
        // `pending` is None here (see above): only a finding is stored, so a
        // clock that finds nothing writes nothing.
        if let Some(m) = found {
            self.pending = Some((m, 0));
        }
        None
    }

    /// The levels `clkout_o` had at the DUT's instants since the last CAN
    /// clock (bit 0: seen low, bit 1: seen high), given before [`Self::clock`]
    /// by a bench that evaluates the DUT at both CAN clock edges.
    #[inline]
    pub fn instants(&mut self, levels: u8) {
        self.sub_clock = true;
        self.instant_levels |= levels;
    }

    fn fosc(&mut self, instants: u8) -> Option<ClkoutMismatch> {
        if !self.sub_clock {
            return None;
        }
        self.fosc_seen |= instants;
        if self.fosc_seen == 0b11 {
            self.fosc_seen = 0;
            self.fosc_run = 0;
            return None;
        }
        self.fosc_run += 1;
        (self.fosc_run > FOSC_WINDOW).then(|| {
            let level = if self.fosc_seen & 0b10 != 0 { "high" } else { "low" };
            ClkoutMismatch {
                expected: 1,
                seen: 0,
                what: format!("clkout_o stayed {level} for {} CAN clocks, read at both clock edges; CDR.2..0 = 7 gives fosc (CLKOUT is the clock)", self.fosc_run),
            }
        })
    }

    #[inline(always)]
    fn divide(&mut self, half_period: u32, toggled: bool) -> Option<ClkoutMismatch> {
        let run = self.since_toggle.map_or(self.since_change - SETTLE_CLOCKS, |n| n + 1);
        if toggled {
            let measured = self.since_toggle.is_some();
            self.since_toggle = Some(0);
            if measured && run != half_period {
                return Some(divide_mismatch(half_period, run, true));
            }
        } else {
            self.since_toggle = self.since_toggle.map(|n| n + 1);
            if run > half_period {
                return Some(divide_mismatch(half_period, run, false));
            }
        }
        None
    }
}

/// The finding of [`ClkoutCheck::divide`]: a toggle after `run` CAN
/// clocks (`toggled`), or none for `run` clocks. Out of line: the check's
/// per-clock path stays small.
#[cold]
#[inline(never)]
fn divide_mismatch(half_period: u32, run: u32, toggled: bool) -> ClkoutMismatch {
    let cd = half_period - 1;
    if toggled {
        ClkoutMismatch {
            expected: half_period,
            seen: run,
            what: format!("clkout_o toggled after {run} CAN clocks; CDR.2..0 = {cd} gives a toggle every {half_period}"),
        }
    } else {
        ClkoutMismatch {
            expected: half_period,
            seen: 0,
            what: format!("clkout_o did not toggle for {run} CAN clocks; CDR.2..0 = {cd} gives a toggle every {half_period}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `levels` (one per CAN clock) under `setting`; the first mismatch.
    fn run(setting: ClkoutSetting, levels: impl IntoIterator<Item = bool>) -> Option<ClkoutMismatch> {
        let mut c = ClkoutCheck::default();
        levels.into_iter().find_map(|l| c.clock(setting, l))
    }

    /// A divider toggling every `h` clocks, `n` clocks, from phase `phase`.
    fn divider(h: u32, n: u32, phase: u32) -> impl Iterator<Item = bool> {
        (0..n).map(move |t| ((t + phase) / h) % 2 == 1)
    }

    #[test]
    fn settings_from_cdr() {
        assert_eq!(ClkoutSetting::from_cdr(0x00), ClkoutSetting::Divide { half_period: 1 });
        assert_eq!(ClkoutSetting::from_cdr(0x86), ClkoutSetting::Divide { half_period: 7 });
        assert_eq!(ClkoutSetting::from_cdr(0x07), ClkoutSetting::Fosc);
        assert_eq!(ClkoutSetting::from_cdr(0x0F), ClkoutSetting::Off);
        assert_eq!(ClkoutSetting::from_cdr(0x8B), ClkoutSetting::Off);
    }

    #[test]
    fn the_right_period_at_any_phase_passes() {
        for cd in 0..7u32 {
            for phase in 0..2 * (cd + 1) {
                assert_eq!(run(ClkoutSetting::Divide { half_period: cd + 1 }, divider(cd + 1, 400, phase)), None, "CD {cd} phase {phase}");
            }
        }
    }

    #[test]
    fn a_wrong_period_or_a_stopped_divider_is_found() {
        let m = run(ClkoutSetting::Divide { half_period: 3 }, divider(2, 400, 0)).expect("fosc/4 for fosc/6");
        assert_eq!((m.expected, m.seen), (3, 2), "{m:?}");
        let m = run(ClkoutSetting::Divide { half_period: 2 }, divider(3, 400, 0)).expect("fosc/6 for fosc/4");
        assert_eq!(m.expected, 2, "{m:?}");
        let m = run(ClkoutSetting::Divide { half_period: 4 }, std::iter::repeat_n(false, 400)).expect("stuck low");
        assert_eq!((m.expected, m.seen), (4, 0), "{m:?}");
        // one late toggle among right ones: half periods 3, 3, 4, 2, 3 ...
        let mut levels: Vec<bool> = divider(3, 150, 0).collect();
        levels[60] = !levels[60];
        assert!(run(ClkoutSetting::Divide { half_period: 3 }, levels).is_some());
    }

    #[test]
    fn off_means_no_toggle_after_the_settle_time() {
        // the divider may finish its toggle within the settle time
        let mut levels: Vec<bool> = divider(1, 10, 0).collect();
        levels.extend(std::iter::repeat_n(false, 300));
        assert_eq!(run(ClkoutSetting::Off, levels.clone()), None);
        levels[200] = true;
        assert!(run(ClkoutSetting::Off, levels).is_some());
    }

    #[test]
    fn fosc_and_unchecked_check_nothing() {
        assert_eq!(run(ClkoutSetting::Fosc, divider(1, 100, 0)), None);
        assert_eq!(run(ClkoutSetting::Fosc, std::iter::repeat_n(false, 100)), None);
        assert_eq!(run(ClkoutSetting::Unchecked, divider(1, 100, 0).map(|_| false)), None);
    }

    /// With the levels at both clock edges, CD = 7 means both levels every
    /// few clocks: the clock passes, a pin held low or high is reported.
    #[test]
    fn fosc_read_at_both_edges_must_follow_the_clock() {
        let fosc = |held: Option<bool>| {
            let mut c = ClkoutCheck::default();
            (0..200).find_map(|_| {
                let (lo, hi) = held.map_or((false, true), |h| (h, h));
                c.instants(1 << lo as u8);
                c.instants(1 << hi as u8);
                c.clock(ClkoutSetting::Fosc, hi)
            })
        };
        assert_eq!(fosc(None), None);
        let m = fosc(Some(false)).expect("CLKOUT held low");
        assert!(m.what.contains("stayed low"), "{m:?}");
        assert!(fosc(Some(true)).expect("CLKOUT held high").what.contains("stayed high"));
        // an instant missed now and then (one level per clock) still passes
        let mut c = ClkoutCheck::default();
        assert_eq!((0..200).find_map(|t| { c.instants(1 << (t % 2)); c.clock(ClkoutSetting::Fosc, t % 2 == 1) }), None);
    }

    #[test]
    fn a_setting_change_restarts_the_measurement_and_a_mismatch_is_reported_once() {
        let mut c = ClkoutCheck::default();
        let mut found = 0;
        for l in divider(1, 100, 0) {
            found += c.clock(ClkoutSetting::Divide { half_period: 1 }, l).is_some() as u32;
        }
        for l in divider(5, 200, 3) {
            found += c.clock(ClkoutSetting::Divide { half_period: 5 }, l).is_some() as u32;
        }
        assert_eq!(found, 0, "each setting's own period, across the change");
        for _ in 0..200 {
            found += c.clock(ClkoutSetting::Divide { half_period: 5 }, false).is_some() as u32;
        }
        assert_eq!(found, 1, "a stopped divider, reported once");
    }

    /// The DUT may take a CDR write a few clocks before the model: a
    /// difference followed by the model's change within the settle time is
    /// not reported.
    #[test]
    fn a_dut_that_changes_first_is_not_reported() {
        let mut c = ClkoutCheck::default();
        let mut found = 0;
        let half2: Vec<bool> = divider(2, 200, 0).collect();
        for &l in &half2 {
            found += c.clock(ClkoutSetting::Divide { half_period: 2 }, l).is_some() as u32;
        }
        // the DUT is already at half period 5 for 10 clocks, then the model follows
        let mut level = *half2.last().unwrap();
        for t in 0..10 {
            if t % 5 == 0 {
                level = !level;
            }
            found += c.clock(ClkoutSetting::Divide { half_period: 2 }, level).is_some() as u32;
        }
        for l in divider(5, 200, 1) {
            found += c.clock(ClkoutSetting::Divide { half_period: 5 }, l).is_some() as u32;
        }
        assert_eq!(found, 0);
    }
}
