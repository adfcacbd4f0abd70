//! The golden model in the two roles the kernel needs: a DUT with the
//! `can_top` Wishbone pins ([`ModelDut`], so everything runs without
//! Verilator and the comparator can be checked against the model itself),
//! and the reference that shadows a DUT ([`ModelRef`]).

use bfm::{WbMasterOut, WbSlaveOut};
use can_engine::ErrorKind;
use can_proto::Field;
use diagnose::{CanMode, EventKind, WriteOutcome as RecOutcome};
use regmap::{Access, Mode, Target};
use sja1000::{NodeEvent, Sja1000, WriteOutcome};

use crate::compare::{IR_ADDR, PELI_STATUS_ADDRS, RefView, Reference, SR_ADDR};
use crate::dut::{CanPins, Dut};

/// The model's write verdict as record data.
pub fn outcome_record(o: WriteOutcome) -> RecOutcome {
    match o {
        WriteOutcome::Applied => RecOutcome::Applied,
        WriteOutcome::IgnoredNotInResetMode { .. } => RecOutcome::IgnoredNotInResetMode,
        WriteOutcome::IgnoredTxBufferLocked { .. } => RecOutcome::IgnoredTxBufferLocked,
        WriteOutcome::IgnoredReadOnly { .. } | WriteOutcome::IgnoredReserved => {
            RecOutcome::IgnoredReadOnly
        }
        other => RecOutcome::Other(format!("{other:?}")),
    }
}

/// Register name at `addr` for the model's view and mode.
pub fn reg_name(m: &Sja1000, addr: u8, write: bool) -> Option<String> {
    let access = if write { Access::Write } else { Access::Read };
    let v = regmap::lookup(m.mode(), m.opmode(), access, addr)?;
    match v.target {
        Target::Register(r) => Some(if r.len > 1 {
            format!("{}[{}]", r.name, addr - r.addr)
        } else {
            r.name.to_string()
        }),
        _ => None,
    }
}

fn can_mode(m: &Sja1000) -> CanMode {
    match m.mode() {
        Mode::BasicCan => CanMode::BasicCan,
        Mode::PeliCan => CanMode::PeliCan,
    }
}

fn pins_of(m: &Sja1000) -> CanPins {
    CanPins {
        tx: m.tx(),
        irq_n: !m.irq(),
        bus_on: !m.bus_off(),
        clkout: m.clkout(),
    }
}

/// The golden model as a Wishbone slave with `can_top`'s pins: `ack` is
/// registered, one host cycle after `cyc & stb`, as in the fixtures. With
/// [`ModelDut::with_level_ack`] it behaves like `rtl/can_top_pio.v`: ack
/// stays high while `cyc & stb` do, and the next access needs them to
/// fall first (a GPIO-polled host holds them over many cycles).
#[derive(Debug)]
pub struct ModelDut {
    m: Sja1000,
    rst: bool,
    wb_in: WbMasterOut,
    ack: bool,
    level_ack: bool,
    /// Level-ack mode: the held request has been served.
    served: bool,
    dat_o: u8,
    rx: bool,
    host_clk: bool,
    can_clk: bool,
    /// Write verdicts of the accesses so far (for the record).
    pub outcomes: Vec<(u8, u8, WriteOutcome)>,
}

impl Default for ModelDut {
    fn default() -> Self {
        ModelDut::new()
    }
}

impl ModelDut {
    /// A model just after a hardware reset.
    pub fn new() -> ModelDut {
        ModelDut {
            m: Sja1000::new(),
            rst: false,
            wb_in: WbMasterOut::default(),
            ack: false,
            level_ack: false,
            served: false,
            dat_o: 0,
            rx: true,
            host_clk: false,
            can_clk: false,
            outcomes: Vec::new(),
        }
    }

    /// A model whose ack is a level held with the request (for PIO hosts).
    pub fn with_level_ack() -> ModelDut {
        ModelDut { level_ack: true, ..ModelDut::new() }
    }

    /// A model whose bit timing starts from `origin` (a stand-in for a
    /// core with that freedom).
    pub fn with_phase_origin(mut self, origin: crate::profile::PhaseOrigin) -> ModelDut {
        self.m.set_phase_origin(origin);
        self
    }

    /// The model inside.
    pub fn model(&self) -> &Sja1000 {
        &self.m
    }
}

impl Dut for ModelDut {
    fn name(&self) -> String {
        "golden model (sja1000) as a Wishbone slave".into()
    }
    fn set_reset(&mut self, on: bool) {
        self.rst = on;
    }
    fn set_wb(&mut self, m: &WbMasterOut) {
        self.wb_in = *m;
    }
    fn wb(&self) -> WbSlaveOut {
        WbSlaveOut {
            ack: self.ack,
            dat: self.dat_o,
            err: false,
            rty: false,
        }
    }
    fn set_rx(&mut self, rx: bool) {
        self.rx = rx;
    }
    fn can(&self) -> CanPins {
        pins_of(&self.m)
    }
    fn eval(&mut self, host_clk: bool, can_clk: bool) {
        let host_rise = host_clk && !self.host_clk;
        let can_rise = can_clk && !self.can_clk;
        self.host_clk = host_clk;
        self.can_clk = can_clk;
        if can_rise {
            if self.rst {
                self.m.hard_reset();
            } else {
                self.m.clock(self.rx);
            }
        }
        if host_rise {
            if self.rst {
                self.m.hard_reset();
                self.ack = false;
                self.served = false;
                self.dat_o = 0;
            } else {
                let w = self.wb_in;
                let req = w.cyc && w.stb;
                let go = if self.level_ack { req && !self.served } else { req && !self.ack };
                if go {
                    if w.we {
                        let o = self.m.write(w.adr, w.dat);
                        self.outcomes.push((w.adr, w.dat, o));
                    } else {
                        self.dat_o = self.m.read(w.adr);
                    }
                }
                if self.level_ack {
                    self.served = req;
                    self.ack = req;
                } else {
                    self.ack = go;
                }
            }
        }
    }
}

/// The golden model as the reference of a lockstep run.
///
/// [`Reference::step`] answers from a cache of what the comparator looks
/// at (pins, field, SR, IR, journal): between two time-quantum boundaries
/// a CAN clock only counts (and moves CLKOUT), so the cache is recomputed
/// at each boundary and after every host access, reset or adoption, and
/// is always what the uncached methods would return.
#[derive(Debug)]
pub struct ModelRef {
    m: Sja1000,
    view: RefView,
    /// Something other than a clock changed the model: recompute `view`.
    stale: bool,
}

impl Default for ModelRef {
    fn default() -> Self {
        ModelRef::new()
    }
}

impl ModelRef {
    /// A model just after a hardware reset, with its journal on.
    pub fn new() -> ModelRef {
        let mut m = Sja1000::new();
        m.set_journal(true);
        ModelRef {
            m,
            view: RefView::default(),
            stale: true,
        }
    }

    /// [`ModelRef::new`] with the bit timing's phase starting from `origin`
    /// (the DUT's profile says where).
    pub fn with_phase_origin(origin: crate::profile::PhaseOrigin) -> ModelRef {
        let mut r = ModelRef::new();
        r.m.set_phase_origin(origin);
        r
    }

    /// With the DUT's declared segment lag (profile `segment-lag`): a BTR
    /// write in reset mode landing that many CAN clocks or fewer after a
    /// quantum's end redoes the quantum, as the DUT's segment logic does.
    pub fn with_segment_lag(mut self, lag: u32) -> ModelRef {
        self.m.set_segment_lag(lag);
        self
    }

    /// With the DUT's declared SR.TS in suspend transmission (profile
    /// `ts-in-suspend`; `true`: "clear").
    pub fn with_ts_clear_in_suspend(mut self, on: bool) -> ModelRef {
        self.m.set_ts_clear_in_suspend(on);
        self
    }

    /// With the DUT's declared ECC after a read (profile `ecc-after-read`;
    /// `true`: "cleared").
    pub fn with_ecc_clear_on_read(mut self, on: bool) -> ModelRef {
        self.m.set_ecc_clear_on_read(on);
        self
    }

    /// How many of the next CAN clocks, with the bus staying at `rx`, only
    /// count in the model: its quanta end quietly if at all
    /// ([`can_engine::Engine::quiet_clocks`]), with no host access or resync
    /// since the view was read (`stale`) and no event waiting. On such a
    /// clock `step` clocks the model and returns the view it returned
    /// last, with only CLKOUT moved ([`ModelRef::counting_clock`]).
    #[inline]
    pub fn counting_clocks(&self, rx: bool) -> u32 {
        if self.stale || self.view.events || self.m.engine().has_events() {
            return 0;
        }
        self.m.engine().quiet_clocks(rx)
    }

    /// One of the [`ModelRef::counting_clocks`] (with its `rx`): what `step`
    /// does on it (the model's clock; the view stays as it is), without
    /// building the view.
    #[inline]
    pub fn counting_clock(&mut self, rx: bool) {
        debug_assert!(!self.stale && self.m.engine().quiet_clocks(rx) > 0);
        self.m.clock(rx);
    }

    /// `n` of the [`ModelRef::counting_clocks`] (with its `rx`) in a row:
    /// `counting_clock` `n` times.
    #[inline]
    pub fn counting_clocks_run(&mut self, n: u32, rx: bool) {
        debug_assert!(!self.stale && n <= self.m.engine().quiet_clocks(rx));
        self.m.quiet_clocks_run(n, rx);
    }

    /// The view `step` returned last, with tx and CLKOUT as they are now.
    #[inline]
    pub fn view_now(&self) -> RefView {
        RefView {
            pins: CanPins { tx: self.m.tx(), clkout: self.m.clkout(), ..self.view.pins },
            ..self.view
        }
    }

    /// Recomputes the cached view from the model (its `tx` and `clkout`
    /// are read afresh by `step` at every clock).
    fn observe(&mut self) {
        self.view = RefView {
            pins: pins_of(&self.m),
            field: Some(self.m.engine().field()),
            sr: self.m.peek(SR_ADDR),
            ir: self.m.peek(IR_ADDR),
            peli: peli_status_of(&self.m),
            events: self.m.journal_pending(),
        };
        self.stale = false;
    }

    /// The model inside.
    pub fn model(&self) -> &Sja1000 {
        &self.m
    }
}

/// RXERR, TXERR and RMC for the comparator's status window, in the
/// PeliCAN view only.
fn peli_status_of(m: &Sja1000) -> Option<[u8; 3]> {
    (m.mode() == Mode::PeliCan).then(|| PELI_STATUS_ADDRS.map(|a| m.peek(a)))
}

fn error_kind(ecc: u8) -> ErrorKind {
    // ECC bits 7:6: 00 bit, 01 form, 10 stuff, 11 other (CRC/ACK).
    match ecc >> 6 {
        0 => ErrorKind::Bit,
        1 => ErrorKind::Form,
        2 => ErrorKind::Stuff,
        _ => {
            // Only the ACK slot is an ACK error; "other" at the ACK
            // delimiter is the CRC error, flagged after the delimiter.
            if ecc & 0x1f == 0x19 {
                ErrorKind::Ack
            } else {
                ErrorKind::Crc
            }
        }
    }
}

impl Reference for ModelRef {
    fn name(&self) -> String {
        "golden model (sja1000)".into()
    }
    fn hard_reset(&mut self) {
        self.stale = true;
        self.m.hard_reset();
        self.m.set_journal(true);
    }
    fn write(&mut self, addr: u8, data: u8) -> Option<RecOutcome> {
        self.stale = true;
        Some(outcome_record(self.m.write(addr, data)))
    }
    fn read(&mut self, addr: u8) -> u8 {
        // Reads have side effects (IR, the receive buffer's status).
        self.stale = true;
        self.m.read(addr)
    }
    fn peek(&self, addr: u8) -> u8 {
        self.m.peek(addr)
    }
    #[inline]
    fn clock(&mut self, rx: bool) {
        self.stale = true;
        self.m.clock(rx);
    }
    #[inline]
    fn step(&mut self, rx: bool) -> RefView {
        // `Engine::clock` does nothing but count unless this clock ends a
        // time quantum (`clocks_to_next_tq() == 1`). At a quantum's end
        // the bit stream processor (and so the field, the status and the
        // events the controller turns into flags and interrupts) runs only
        // at a sample point or a wake-up (`activity()` counts them); otherwise the
        // quantum may only start a bit, which moves tx. Host accesses set
        // `stale`. CLKOUT moves on its own.
        let engine = self.m.engine();
        let boundary = engine.clocks_to_next_tq() <= 1;
        let bits = engine.activity();
        self.m.clock(rx);
        if self.stale || (boundary && self.m.engine().activity() != bits) {
            self.observe();
        }
        // tx and CLKOUT read afresh, the rest from the cache. Not stored
        // back: writing two bytes of the cache and reading it whole at the
        // next clock would cost a store-forwarding stall per clock.
        let v = self.view;
        RefView {
            pins: CanPins {
                tx: self.m.tx(),
                clkout: self.m.clkout(),
                ..v.pins
            },
            ..v
        }
    }
    fn adopt_counters(&mut self, tec: Option<u8>, rec: Option<u8>) -> bool {
        self.stale = true;
        self.m.adopt_counters(tec, rec);
        true
    }
    fn adopt_register(&mut self, addr: u8, value: u8) -> bool {
        self.stale = true;
        self.m.adopt_register(addr, value)
    }
    fn skip_sleep(&mut self) -> bool {
        self.stale = true;
        self.m.skip_sleep();
        true
    }
    fn wait_bus_free_after_bus_on(&mut self) -> bool {
        self.stale = true;
        self.m.wait_bus_free_after_bus_on()
    }
    fn start_held_tx_now(&mut self) -> bool {
        self.stale = true;
        self.m.start_held_tx_now()
    }
    fn pins(&self) -> CanPins {
        pins_of(&self.m)
    }
    fn field(&self) -> Option<Field> {
        Some(self.m.engine().field())
    }
    fn counters(&self) -> Option<(u16, u16)> {
        let e = self.m.engine();
        let tec = if self.m.bus_off() {
            256
        } else {
            e.tec() as u16
        };
        Some((tec, e.rec() as u16))
    }
    fn mode(&self) -> Option<(CanMode, bool)> {
        Some((can_mode(&self.m), self.m.in_reset_mode()))
    }
    fn clkout_setting(&self) -> crate::clkout::ClkoutSetting {
        // Asked every CAN clock: the stored CDR, whose low nibble is what a
        // read of address 31 shows in both views and modes (checked by
        // `clkout_setting_is_the_setting_of_the_cdr_read`), without the
        // register map's decoding.
        if self.m.is_sleeping() { crate::clkout::ClkoutSetting::Unchecked } else { crate::clkout::ClkoutSetting::from_cdr(self.m.cdr()) }
    }
    fn reg_name(&self, addr: u8, write: bool) -> Option<String> {
        reg_name(&self.m, addr, write)
    }
    fn lost_messages(&self) -> Option<u32> {
        Some(self.m.lost_messages() as u32)
    }
    fn aborted_since_request(&self) -> Option<bool> {
        Some(self.m.aborted_since_request())
    }
    fn drain_events(&mut self, out: &mut Vec<EventKind>) {
        if !self.m.journal_pending() {
            return;
        }
        self.view.events = false;
        let field = self.m.engine().field();
        for e in self.m.take_journal() {
            out.push(match e {
                NodeEvent::Sent(_) => EventKind::TxComplete,
                NodeEvent::Received { frame, own, .. } => EventKind::Received {
                    id: frame.raw_id(),
                    dlc: frame.dlc_raw(),
                    own,
                },
                NodeEvent::BusError { ecc } => EventKind::BusError {
                    kind: error_kind(ecc),
                    ecc,
                    field,
                },
                NodeEvent::ArbitrationLost { alc } => EventKind::ArbitrationLost { alc },
                NodeEvent::FaultState(s) => EventKind::FaultState(s),
                NodeEvent::ResetMode(_) | NodeEvent::Sleep(_) => continue,
            });
        }
    }
}

/// The reference of a test bench: the golden model called directly (its
/// `step` runs every CAN clock: no dynamic dispatch there), anything else
/// through [`Reference`]. Dereferences to `dyn Reference` off the hot path.
#[allow(clippy::large_enum_variant)] // inline on purpose: no indirection per edge
pub enum AnyRef {
    /// The golden model.
    Model(ModelRef),
    /// Any other reference.
    Other(Box<dyn Reference>),
}

impl std::ops::Deref for AnyRef {
    type Target = dyn Reference;
    fn deref(&self) -> &(dyn Reference + 'static) {
        match self {
            AnyRef::Model(m) => m,
            AnyRef::Other(r) => r.as_ref(),
        }
    }
}

impl std::ops::DerefMut for AnyRef {
    fn deref_mut(&mut self) -> &mut (dyn Reference + 'static) {
        match self {
            AnyRef::Model(m) => m,
            AnyRef::Other(r) => r.as_mut(),
        }
    }
}

impl AnyRef {
    /// [`Reference::step`].
    #[inline(always)]
    pub fn step(&mut self, rx: bool) -> RefView {
        match self {
            AnyRef::Model(m) => m.step(rx),
            AnyRef::Other(r) => r.step(rx),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What `step` must return: the uncached answers after a plain clock.
    fn uncached(m: &Sja1000) -> RefView {
        RefView {
            pins: pins_of(m),
            field: Some(m.engine().field()),
            sr: m.peek(SR_ADDR),
            ir: m.peek(IR_ADDR),
            peli: peli_status_of(m),
            events: m.journal_pending(),
        }
    }

    /// The cached view of `ModelRef::step` is, at every clock, what the
    /// model says uncached: self-test frames looped back with glitches on
    /// rx (errors, error frames, retransmissions), host reads and writes
    /// between clocks, bit timing changes and a hard reset.
    /// A clock promised by `counting_clocks` behaves as `step` on it:
    /// a model that takes its promised clocks through `counting_clock`
    /// shows at every clock the view of a twin that steps every clock,
    /// through self-test frames with glitches on rx, reads and writes.
    #[test]
    fn counting_clocks_are_steps_that_keep_the_view() {
        let (mut a, mut b) = (ModelRef::new(), ModelRef::new());
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut rnd = move |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        };
        let config: &[(u8, u8)] =
            &[(0, 0x01), (31, 0xC0), (0, 0x01), (6, 0x41), (7, 0x25), (20, 0xFF), (21, 0xFF), (22, 0xFF), (23, 0xFF), (4, 0xFF), (0, 0x04)];
        let both = |a: &mut ModelRef, b: &mut ModelRef, addr: u8, d: u8| {
            assert_eq!(Reference::write(a, addr, d), Reference::write(b, addr, d));
        };
        for &(addr, d) in config {
            both(&mut a, &mut b, addr, d);
        }
        let (mut left, mut promised, mut left_rx) = (0u32, 0u64, true);
        let (mut ev_a, mut ev_b) = (Vec::new(), Vec::new());
        for clk in 0..200_000u64 {
            if clk % 6_000 == 100 {
                both(&mut a, &mut b, 16, 0x08);
                for addr in 17..27 {
                    let d = rnd(256) as u8;
                    both(&mut a, &mut b, addr, d);
                }
                both(&mut a, &mut b, 1, 0x10);
                // A host access ends any promise (it made the view stale).
                assert_eq!(b.counting_clocks(true), 0);
                assert_eq!(b.counting_clocks(false), 0);
                left = 0;
            }
            if rnd(3_000) == 0 {
                let addr = [2, 3, 11, 12, 14][rnd(5) as usize];
                assert_eq!(Reference::read(&mut a, addr), Reference::read(&mut b, addr));
                left = 0;
            }
            // Now and then the rest of a promise in one go (the bench's quiet
            // stretches), the twin stepping through it with the same rx.
            if left > 1 && rnd(4) == 0 {
                let k = 1 + rnd(u64::from(left)) as u32;
                let v0 = b.view_now();
                for _ in 0..k {
                    // The view stays but for CLKOUT.
                    let va = a.step(left_rx);
                    assert_eq!(RefView { pins: CanPins { clkout: v0.pins.clkout, ..va.pins }, ..va }, v0, "clock {clk} (run of {k})");
                }
                b.counting_clocks_run(k, left_rx);
                left -= k;
                promised += u64::from(k);
                assert_eq!(a.view_now(), b.view_now(), "clock {clk}: after a run of {k}");
                assert_eq!((a.m.clkout(), a.m.tx()), (b.m.clkout(), b.m.tx()), "clock {clk}");
            }
            let rx = a.m.tx() ^ (rnd(2_500) == 0);
            // A promise holds while the bus stays at its level.
            if rx != left_rx {
                left = 0;
            }
            let va = a.step(rx);
            let vb = if left > 0 {
                left -= 1;
                promised += 1;
                b.counting_clock(rx);
                b.view_now()
            } else {
                b.step(rx)
            };
            assert_eq!(va, vb, "clock {clk}");
            if va.events {
                a.drain_events(&mut ev_a);
                b.drain_events(&mut ev_b);
                assert_eq!(ev_a, ev_b, "clock {clk}");
                ev_a.clear();
                ev_b.clear();
            }
            if left == 0 {
                // The level of the next clock, as far as the bench knows: this one's.
                left_rx = rx;
                left = b.counting_clocks(rx);
            }
        }
        // 4 clocks per quantum, and quanta that end quietly: most clocks
        // are counting ones.
        assert!(promised > 150_000, "clocks taken as counting: {promised}");
    }

    /// The per-clock CLKOUT setting reads the stored CDR instead of
    /// decoding a register read: the same setting as from the read, for
    /// every CDR value, in both views, in reset and operating mode.
    #[test]
    fn clkout_setting_is_the_setting_of_the_cdr_read() {
        use crate::clkout::ClkoutSetting;
        let mut checked = 0;
        for v in 0..=255u8 {
            let mut r = ModelRef::new();
            // Reset mode (the default after a hardware reset): every bit writable.
            Reference::write(&mut r, 31, v);
            assert_eq!(r.clkout_setting(), ClkoutSetting::from_cdr(r.peek(31)), "CDR 0x{v:02X} in reset mode");
            // Operating mode (MOD.RM / CR.RR is bit 0 at address 0 in both views):
            // only CD.2..0 writable.
            Reference::write(&mut r, 0, 0x00);
            Reference::write(&mut r, 31, v ^ 0x05);
            assert_eq!(r.clkout_setting(), ClkoutSetting::from_cdr(r.peek(31)), "CDR 0x{v:02X} ^ 5 in operating mode");
            checked += 2;
        }
        assert_eq!(checked, 512);
        // The setting still follows the value: a clock-off CDR is Off.
        let mut r = ModelRef::new();
        Reference::write(&mut r, 31, 0x88);
        assert_eq!(r.clkout_setting(), ClkoutSetting::Off);
    }

    #[test]
    fn step_view_is_always_the_uncached_view() {
        let mut r = ModelRef::new();
        let mut plain = Sja1000::new();
        plain.set_journal(true);
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let mut rnd = move |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        };
        let config: &[(u8, u8)] = &[
            (0, 0x01),
            (31, 0xC8),
            (0, 0x01),
            (6, 0x41),
            (7, 0x25),
            (20, 0xFF),
            (21, 0xFF),
            (22, 0xFF),
            (23, 0xFF),
            (4, 0xFF),
            (0, 0x04),
        ];
        let both_write = |r: &mut ModelRef, p: &mut Sja1000, a: u8, d: u8| {
            assert_eq!(Reference::write(r, a, d), Some(outcome_record(p.write(a, d))));
        };
        for &(a, d) in config {
            both_write(&mut r, &mut plain, a, d);
        }
        let (mut ev_a, mut ev_b) = (Vec::new(), Vec::new());
        let mut events = 0;
        for clk in 0..400_000u64 {
            if clk % 6_000 == 100 {
                // A frame with self reception.
                both_write(&mut r, &mut plain, 16, 0x08);
                for a in 17..27 {
                    let d = rnd(256) as u8;
                    both_write(&mut r, &mut plain, a, d);
                }
                both_write(&mut r, &mut plain, 1, 0x10);
            }
            if rnd(3_000) == 0 {
                let a = [2, 3, 11, 12, 14, 15, 29][rnd(7) as usize];
                assert_eq!(Reference::read(&mut r, a), plain.read(a));
            }
            if rnd(40_000) == 0 {
                both_write(&mut r, &mut plain, 1, 0x04);
            }
            if clk == 200_000 {
                Reference::hard_reset(&mut r);
                plain.hard_reset();
                plain.set_journal(true);
                for &(a, d) in config {
                    both_write(&mut r, &mut plain, a, d);
                }
                // Another bit timing: 3 clocks per quantum.
                both_write(&mut r, &mut plain, 0, 0x01);
                both_write(&mut r, &mut plain, 6, 0x02);
                both_write(&mut r, &mut plain, 0, 0x04);
            }
            let rx = plain.tx() ^ (rnd(2_500) == 0);
            let v = r.step(rx);
            plain.clock(rx);
            assert_eq!(v, uncached(&plain), "clock {clk}");
            if v.events {
                r.drain_events(&mut ev_a);
                // The same journal, translated the same way.
                let mut twin = ModelRef {
                    m: std::mem::replace(&mut plain, Sja1000::new()),
                    view: RefView::default(),
                    stale: true,
                };
                twin.drain_events(&mut ev_b);
                plain = twin.m;
                assert_eq!(ev_a, ev_b, "clock {clk}");
                events += ev_a.len();
                ev_a.clear();
                ev_b.clear();
            }
        }
        assert!(events > 50, "the run made events ({events})");
    }

    /// One host clock period with the request wires `w`; returns ack.
    fn host_cycle(d: &mut ModelDut, w: WbMasterOut) -> bool {
        d.set_wb(&w);
        d.eval(false, false);
        d.eval(true, false);
        d.wb().ack
    }

    /// A request held for many cycles (a GPIO-polled host) is served once
    /// by the level-ack model, and the ack stays up until the request falls;
    /// the classic model serves it again every other cycle.
    #[test]
    fn level_ack_serves_a_held_request_once() {
        // CMR.RRB in reset mode is harmless; count writes through outcomes.
        let w = WbMasterOut { cyc: true, stb: true, we: true, adr: 4, dat: 0x5A };
        let mut level = ModelDut::with_level_ack();
        let acks: Vec<bool> = (0..8).map(|_| host_cycle(&mut level, w)).collect();
        assert_eq!(acks, vec![true; 8], "ack held with the request");
        assert_eq!(level.outcomes.len(), 1, "served once: {:?}", level.outcomes);
        assert!(!host_cycle(&mut level, WbMasterOut::default()), "ack falls with the request");
        assert!(host_cycle(&mut level, w));
        assert_eq!(level.outcomes.len(), 2, "a new request is served again");
        let mut classic = ModelDut::new();
        for _ in 0..8 {
            host_cycle(&mut classic, w);
        }
        assert_eq!(classic.outcomes.len(), 4, "classic one-cycle ack repeats the access");
    }

    #[test]
    fn ecc_other_at_ack_delimiter_is_a_crc_error() {
        assert_eq!(error_kind(0xD9), ErrorKind::Ack);
        assert_eq!(error_kind(0xDB), ErrorKind::Crc);
        assert_eq!(error_kind(0xC8), ErrorKind::Crc);
        assert_eq!(error_kind(0x1B), ErrorKind::Bit);
    }
}
