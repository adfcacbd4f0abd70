//! [`Shadow`]: the golden model shadowing a DUT in someone else's bench.
//!
//! The bench tells it three things, each when it happens: a CAN clock
//! (the DUT's rx level and, to compare, its pins), a host access the DUT
//! has just seen presented (launch edge), and the data a read returned
//! (ack). The model takes each access at the CAN clock the core's profile
//! declares (`tb/profiles/*.toml`, `[access.wishbone]` or the host bus
//! set with [`Shadow::set_host_bus`]), the comparator is
//! the CLI's own (`cosim::Comparator` with the profile's tolerances), and a
//! divergence or a transmission that never completed becomes the
//! diagnoser's text. Times are the bench's when it anchors them
//! ([`Shadow::set_time_ps`], [`Shadow::set_period_ps`]), so the run record,
//! the bus log and the marker file ([`crate::markers`]) line up with the
//! simulator's own waveform.

use std::collections::VecDeque;

use can_proto::decode::{DecodeEvent, Decoder};
use can_proto::timing::BusTiming;
use cosim::bitclock::BitClock;
use cosim::candump::BusLog;
use cosim::compare::Stamp;
use cosim::{AccessTiming, CanPins, Comparator, ModelRef, PhaseOrigin, Profile, Reference};
use diagnose::{
    BusBit, CanMode, EngineEvent, EventKind, FinalRegs, HostBus, HostOp, RunRecord, RxWiring, Side,
    StuckTransfer, Timing, Wiring,
};

/// SR and IR addresses (both register views).
const SR: u8 = 2;
/// CMR address (both views).
const CMR: u8 = 1;
/// Bus bits kept for the diagnosis.
const KEEP_BITS: usize = 512;

/// What went wrong with a call (a C caller gets it as text).
#[derive(Debug, thiserror::Error)]
pub enum ShadowError {
    /// The profile could not be found or read.
    #[error("{0}")]
    Profile(String),
    /// The CAN clock frequency is not a positive number.
    #[error("CAN clock frequency must be positive, got {0} Hz")]
    Clock(f64),
}

/// The DUT's CAN-side pins at a clock, each optional (a pin not given is
/// not compared).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DutPins {
    /// `tx_o` (`true` = recessive).
    pub tx: Option<bool>,
    /// `irq_on` (active low).
    pub irq_n: Option<bool>,
    /// `bus_off_on` (high while on the bus).
    pub bus_on: Option<bool>,
}

/// A host access presented to the DUT, waiting for the CAN clock at which
/// the core takes it.
#[derive(Clone, Copy, Debug)]
struct Pending {
    write: bool,
    addr: u8,
    data: u8,
    /// CAN edges still to come before the model takes it.
    edges_left: u32,
    t_ps: u64,
}

/// Engine events kept with their time for the marker file (the first ones
/// say most, as in the record).
const KEEP_EVENTS: usize = 4096;

/// The golden model, the comparator and the run record of one DUT.
pub struct Shadow {
    reference: ModelRef,
    cmp: Comparator,
    timing: AccessTiming,
    /// The profile's access timing per host bus (Wishbone, Avalon-MM, PIO,
    /// AXI4-Lite, APB, register port, 8051, Motorola), and the bus in use.
    access: [AccessTiming; 8],
    host_bus: HostBus,
    profile_name: String,
    tolerances: String,
    bitclock: BitClock,
    period_ps: u64,
    clocks: u64,
    /// The bench's time at CAN clock `anchor_clock` (the clock's count
    /// after it), set by [`Shadow::set_time_ps`].
    anchor_ps: u64,
    anchor_clock: u64,
    /// The model's engine events with their time: (ps, event).
    timed_events: Vec<(u64, EventKind)>,
    pending: VecDeque<Pending>,
    /// Reads the model has taken, waiting for the DUT's data: (addr, model value).
    taken_reads: VecDeque<(u8, u8)>,
    record: RunRecord,
    events: Vec<EventKind>,
    /// The last transmission request not yet completed: (ps, bit).
    last_tr: Option<(u64, u64)>,
    /// Sample points at which the model drove dominant: how often rx read
    /// dominant and recessive then (the wiring, as the pins show it).
    tx_dom_rx_dom: u64,
    tx_dom_rx_rec: u64,
    rx_ever_dominant: bool,
    diagnosis: Option<String>,
    /// Reads and sample points compared.
    compared_reads: u64,
    /// The DUT's rx decoded at the bench's sample points, and the bus log
    /// the CLI's `--candump` writes (frames seen, the model's error frames).
    decoder: Decoder,
    bus_log: BusLog,
}

impl Shadow {
    /// A model for a DUT with `profile` (a shipped name such as `rtl` or a
    /// `.toml` path) clocked at `can_hz`.
    pub fn new(profile: &str, can_hz: f64) -> Result<Shadow, ShadowError> {
        let p = if profile.is_empty() || profile == "rtl" {
            Profile::rtl()
        } else {
            Profile::find(profile).map_err(|e| ShadowError::Profile(e.to_string()))?
        };
        Shadow::with_profile(&p, can_hz)
    }

    /// [`Shadow::new`] with a profile already read.
    pub fn with_profile(p: &Profile, can_hz: f64) -> Result<Shadow, ShadowError> {
        if !(can_hz.is_finite() && can_hz > 0.0) {
            return Err(ShadowError::Clock(can_hz));
        }
        let mut reference =
            ModelRef::with_phase_origin(p.phase_origin)
                .with_segment_lag(p.segment_lag)
                .with_ts_clear_in_suspend(p.ts_clear_in_suspend)
                .with_ecc_clear_on_read(p.ecc_clear_on_read);
        reference.hard_reset();
        let timing = Timing {
            can_clock_hz: can_hz,
            host_clock_hz: 0.0,
            btr0: 0,
            btr1: 0,
        };
        // As `cosim`'s reference takes them: a profile without
        // `[access.i8051]` acts at the first CAN edge of the strobe.
        let i8051 = p.i8051.unwrap_or(AccessTiming::CanEdges {
            read: 1,
            write: 1,
            command: 1,
        });
        let mut record = RunRecord::new("bench", &p.name).with_timing(timing);
        record.host_bus = HostBus::Wishbone;
        Ok(Shadow {
            reference,
            cmp: Comparator::new(p.tolerances),
            timing: p.wishbone,
            access: [
                p.wishbone,
                p.avalon,
                p.pio,
                p.axi4lite.unwrap_or(p.wishbone),
                p.apb.unwrap_or(p.wishbone),
                p.regport.timing.unwrap_or(p.wishbone),
                i8051,
                p.motorola.timing.unwrap_or(i8051),
            ],
            host_bus: HostBus::Wishbone,
            profile_name: p.name.clone(),
            tolerances: p.tolerances.describe(),
            bitclock: BitClock::new(BusTiming::from_btr(0, 0)),
            period_ps: (1e12 / can_hz).round() as u64,
            clocks: 0,
            anchor_ps: 0,
            anchor_clock: 0,
            timed_events: Vec::new(),
            pending: VecDeque::new(),
            taken_reads: VecDeque::new(),
            record,
            events: Vec::new(),
            last_tr: None,
            tx_dom_rx_dom: 0,
            tx_dom_rx_rec: 0,
            rx_ever_dominant: false,
            diagnosis: None,
            compared_reads: 0,
            decoder: Decoder::new(),
            bus_log: BusLog::new(),
        })
    }

    /// A model that takes every access at the call (no clock-domain
    /// crossing to mimic): for a bench that calls at the instant its core
    /// acts, or drives the model alone.
    pub fn immediate(can_hz: f64) -> Result<Shadow, ShadowError> {
        let mut p = Profile::rtl();
        p.name = "immediate".into();
        p.wishbone = AccessTiming::AtAck;
        p.avalon = AccessTiming::AtAck;
        p.pio = AccessTiming::AtAck;
        p.axi4lite = Some(AccessTiming::AtAck);
        p.apb = Some(AccessTiming::AtAck);
        p.i8051 = Some(AccessTiming::AtAck);
        p.regport.timing = Some(AccessTiming::AtAck);
        p.motorola.timing = Some(AccessTiming::AtAck);
        p.phase_origin = PhaseOrigin::ResetModeExit;
        Shadow::with_profile(&p, can_hz)
    }

    /// The test's name, as the diagnosis's first line names it ("bench" until set).
    pub fn set_test_name(&mut self, name: &str) {
        self.record.scenario = name.to_string();
    }

    /// The host bus the bench's accesses come through (default Wishbone):
    /// the model takes them at the CAN clock the profile declares for that
    /// bus (`[access.avalon]`, `[access.axi4-lite]`, `[access.apb]`,
    /// `[access.regport]`...), and the run record names the bus. AXI4-Lite,
    /// APB and the register port without one: as Wishbone (our wrappers
    /// are `can_top` behind a combinational request); Motorola without
    /// `[access.motorola]`: as the 8051 bus (`can_top_mcu` decodes it into
    /// the 8051 strobes; its bench requests a read at E rising, a write at
    /// E falling, as our RTL takes them).
    pub fn set_host_bus(&mut self, bus: HostBus) {
        self.host_bus = bus;
        self.record.host_bus = bus;
        self.timing = self.access[match bus {
            HostBus::Wishbone => 0,
            HostBus::Avalon => 1,
            HostBus::Pio => 2,
            HostBus::Axi4Lite => 3,
            HostBus::Apb => 4,
            HostBus::Regport => 5,
            HostBus::I8051 => 6,
            HostBus::Motorola => 7,
        }];
    }

    /// The host bus set by [`Shadow::set_host_bus`].
    pub fn host_bus(&self) -> HostBus {
        self.host_bus
    }

    /// The bench's time of the next CAN clock (the next [`Shadow::clock`]
    /// call), in picoseconds: later clocks are `period` apart
    /// ([`Shadow::set_period_ps`]; default from the CAN frequency). Call it
    /// again after the bench skipped clocks (a reset held). Without it, time
    /// starts at 0 with the first clock.
    pub fn set_time_ps(&mut self, t_ps: u64) {
        self.anchor_ps = t_ps;
        self.anchor_clock = self.clocks + 1;
    }

    /// The CAN clock's period in the bench (ps); 0 is refused (keeps the one
    /// from the CAN frequency). Applies from the last anchor on.
    pub fn set_period_ps(&mut self, period_ps: u64) {
        if period_ps > 0 {
            self.period_ps = period_ps;
        }
    }

    /// CAN clocks per bit of the bench's bit clock (BTR0/BTR1 as the model took them).
    pub fn clocks_per_bit(&self) -> u32 {
        self.bitclock.clocks_per_bit()
    }

    /// The CAN clock's period the times are computed with (ps).
    pub fn period_ps(&self) -> u64 {
        self.period_ps
    }

    /// The time of the last CAN clock (ps), on the bench's time line.
    pub fn now(&self) -> u64 {
        self.now_ps()
    }

    /// The model's engine events so far with their time (ps), for markers.
    pub fn timed_events(&self) -> &[(u64, EventKind)] {
        &self.timed_events
    }

    /// The bus log's entries (frames on the DUT's rx, the model's error
    /// frames), with their time.
    pub fn bus_log_entries(&self) -> &[cosim::candump::LogEntry] {
        self.bus_log.entries()
    }

    /// The profile's name.
    pub fn profile_name(&self) -> &str {
        &self.profile_name
    }

    /// The comparator's tolerances in words (as the CLI prints them).
    pub fn tolerances(&self) -> &str {
        &self.tolerances
    }

    /// CAN clocks seen so far.
    pub fn clocks(&self) -> u64 {
        self.clocks
    }

    /// Bit times (sample points of the bench's bit clock) so far.
    pub fn bits(&self) -> u64 {
        self.bitclock.bits()
    }

    /// The model's tx level after the last clock (`true` = recessive).
    pub fn tx(&self) -> bool {
        self.reference.pins().tx
    }

    /// The model's pins after the last clock.
    pub fn pins(&self) -> CanPins {
        self.reference.pins()
    }

    /// Register value as a read would return it, without a read's side effects.
    pub fn peek(&self, addr: u8) -> u8 {
        self.reference.peek(addr)
    }

    /// Register reads compared so far.
    pub fn compared_reads(&self) -> u64 {
        self.compared_reads
    }

    /// Sample points at which tx was compared.
    pub fn compared_bits(&self) -> u64 {
        self.cmp.compared_bits
    }

    /// The diagnosis, once the model and the DUT disagreed or
    /// [`Shadow::finish`] found a transfer that never completed.
    pub fn diagnosis(&self) -> Option<&str> {
        self.diagnosis.as_deref()
    }

    /// True once a diagnosis exists.
    pub fn failed(&self) -> bool {
        self.diagnosis.is_some()
    }

    /// CAN clocks the comparator still needs before every comparison made
    /// so far is judged (an SR read waiting for the model, the tx window).
    pub fn open_clocks(&self) -> u32 {
        self.cmp.open_clocks()
    }

    /// Hardware reset of the model (the DUT's reset pin).
    pub fn hard_reset(&mut self) {
        self.reference.hard_reset();
        self.pending.clear();
        self.taken_reads.clear();
        self.last_tr = None;
    }

    /// A host access the DUT has just seen presented (the host clock edge
    /// at which its bus sampled cyc & stb for the first time). The model
    /// takes it at the CAN clock the profile declares; with no declared
    /// timing, now.
    pub fn request(&mut self, write: bool, addr: u8, data: u8) {
        let edges = self.timing.edges(write, addr).unwrap_or(0);
        let p = Pending {
            write,
            addr,
            data,
            edges_left: edges,
            t_ps: self.now_ps(),
        };
        if edges == 0 {
            self.take(p);
        } else {
            self.pending.push_back(p);
        }
    }

    /// A write the model takes now, whatever the profile says.
    pub fn write(&mut self, addr: u8, data: u8) {
        let t_ps = self.now_ps();
        self.take(Pending {
            write: true,
            addr,
            data,
            edges_left: 0,
            t_ps,
        });
    }

    /// A read the model takes now; its value. The caller compares it
    /// itself: [`Shadow::compare_read`] judges the DUT's value with the
    /// status tolerance.
    pub fn read(&mut self, addr: u8) -> u8 {
        let t_ps = self.now_ps();
        self.take(Pending {
            write: false,
            addr,
            data: 0,
            edges_left: 0,
            t_ps,
        });
        self.taken_reads.pop_back().map(|(_, v)| v).unwrap_or(0)
    }

    /// The DUT's read of `addr` returned `dut` (at its ack). Compared with
    /// the model's value for the same read (taken at its declared CAN
    /// clock, or now if it has not been yet), SR/IR with the profile's
    /// status tolerance. Returns the model's value. A divergence may be
    /// found later (an SR read waits up to the tolerance for the model to
    /// take the DUT's value): see [`Shadow::failed`].
    pub fn compare_read(&mut self, addr: u8, dut: u8) -> u8 {
        let model = match self.taken_reads.iter().position(|&(a, _)| a == addr) {
            Some(i) => self.taken_reads.remove(i).map(|(_, v)| v).unwrap_or(0),
            None => {
                // Not taken yet: a read request still pending for this
                // address goes now, else the read was never announced.
                match self.pending.iter().position(|p| !p.write && p.addr == addr) {
                    Some(i) => {
                        let p = self.pending.remove(i).expect("index from position");
                        self.take(p);
                        self.taken_reads.pop_back().map(|(_, v)| v).unwrap_or(0)
                    }
                    None => self.read(addr),
                }
            }
        };
        let name = self.reference.reg_name(addr, false);
        if let Some(op) = self
            .record
            .host_ops
            .iter_mut()
            .rev()
            .find(|o| o.addr == addr && o.access == diagnose::Access::Read)
        {
            op.data = dut;
        }
        self.compared_reads += 1;
        let stamp = self.stamp();
        self.cmp.read(stamp, addr, dut, model, name);
        self.check();
        model
    }

    /// One CAN clock (rising edge of the core's clk_i): `rx` is the DUT's
    /// rx_i now; `dut` its pins, to compare (None: the model only runs).
    /// Returns the model's tx (`true` = recessive).
    pub fn clock(&mut self, rx: bool, dut: Option<DutPins>) -> bool {
        self.clocks += 1;
        let sample = self.bitclock.clock(rx);
        let view = self.reference.step(rx);
        // A pin the bench does not give is the model's own: never a difference.
        let dut = dut.map(|d| CanPins {
            tx: d.tx.unwrap_or(view.pins.tx),
            irq_n: d.irq_n.unwrap_or(view.pins.irq_n),
            bus_on: d.bus_on.unwrap_or(view.pins.bus_on),
            clkout: view.pins.clkout,
        });
        let bit = self.bitclock.bits();
        if sample {
            for e in self.decoder.push(rx) {
                if let DecodeEvent::Frame(d) = e {
                    self.bus_log.frame(self.now_ps(), d.frame);
                }
            }
            if !rx {
                self.rx_ever_dominant = true;
            }
            if !view.pins.tx {
                if rx {
                    self.tx_dom_rx_rec += 1;
                } else {
                    self.tx_dom_rx_dom += 1;
                }
            }
            let d = dut.unwrap_or(view.pins);
            self.record.push_bit(
                BusBit {
                    bit,
                    bus: rx,
                    dut_tx: d.tx,
                    model_tx: view.pins.tx,
                    dut_rx: rx,
                    field: view.field,
                    frame: None,
                },
                KEEP_BITS,
            );
        }
        if view.events {
            self.reference_events(bit);
        }
        if let Some(d) = dut {
            let stamp = Stamp {
                t_ps: self.now_ps(),
                bit,
                field: view.field,
                frame: None,
            };
            self.cmp
                .can_clock(stamp, sample, &view.pins, &d, view.sr, view.ir, view.peli);
        }
        // Accesses whose CAN edge this was.
        let mut i = 0;
        while i < self.pending.len() {
            let p = &mut self.pending[i];
            p.edges_left = p.edges_left.saturating_sub(1);
            if p.edges_left == 0 {
                let p = self.pending.remove(i).expect("index in range");
                self.take(p);
            } else {
                i += 1;
            }
        }
        self.check();
        view.pins.tx
    }

    /// The end of the test: a transmission requested and never completed
    /// (no transmit-complete event of the model since, no abort) becomes a diagnosis if nothing else did. Returns
    /// true if the run failed. Clock [`Shadow::open_clocks`] more CAN
    /// clocks before, so the last reads are judged.
    pub fn finish(&mut self) -> bool {
        if self.diagnosis.is_none()
            && let Some((requested_ps, requested_bit)) = self.last_tr
        {
            // Still pending, or dropped at bus-off (SR.TBS back to 1, no
            // transmit complete): either way the frame never went out.
            let sr = self.reference.peek(SR);
            self.record.stuck = Some(StuckTransfer {
                requested_ps,
                requested_bit,
                waited_bits: self.bits().saturating_sub(requested_bit),
                sr,
                attempts: scenario::run::tec_trace_from_events(&self.record, Side::Model).len()
                    as u32,
            });
            self.diagnose_now();
        }
        self.failed()
    }

    /// The bus log in can-utils `candump -l` format on interface `iface`,
    /// as `cancosim run --candump` writes it: every frame completed on the
    /// DUT's rx, and the error frames the Linux `sja1000` driver would raise
    /// for the DUT, from the model's events.
    pub fn candump_log(&self, iface: &str) -> String {
        cosim::candump::write_log(self.bus_log.entries(), iface)
    }

    /// The run record so far (with the wiring the pins showed).
    pub fn record(&self) -> RunRecord {
        let mut r = self.record.clone();
        r.tec_trace = scenario::run::tec_trace_from_events(&r, Side::Model);
        r.bits_simulated = self.bits();
        r.wiring = self.wiring();
        if let Some((mode, _)) = self.reference.mode() {
            r.mode = mode;
        }
        let (tec, rec) = self.reference.counters().unwrap_or((0, 0));
        r.final_model = Some(FinalRegs {
            sr: self.reference.peek(SR),
            ir: self.reference.peek(3),
            tec,
            rec,
            ..FinalRegs::default()
        });
        r
    }

    /// How rx_i is wired, as the pins showed it: a bench says nothing of its
    /// wiring, but at every sample point where the model sent dominant, rx
    /// either followed or did not. Never dominant at all: tied recessive.
    fn wiring(&self) -> Wiring {
        let mut w = Wiring::default();
        // PeliCAN MOD.STM (self-test: no acknowledge needed).
        if self
            .reference
            .mode()
            .is_some_and(|(m, _)| m == CanMode::PeliCan)
        {
            w.self_test = self.reference.peek(0) & 0x04 != 0;
            w.listen_only = self.reference.peek(0) & 0x02 != 0;
        }
        if self.tx_dom_rx_rec > 0 && self.tx_dom_rx_dom == 0 {
            if self.rx_ever_dominant {
                w.tx_on_bus = false;
            } else {
                w.rx = RxWiring::TiedRecessive;
                w.tx_on_bus = false;
            }
        }
        w
    }

    fn now_ps(&self) -> u64 {
        if self.anchor_clock == 0 {
            return self.clocks * self.period_ps;
        }
        // Before the anchored clock (an access announced ahead of it): the anchor.
        self.anchor_ps + self.clocks.saturating_sub(self.anchor_clock) * self.period_ps
    }

    fn stamp(&self) -> Stamp {
        Stamp {
            t_ps: self.now_ps(),
            bit: self.bits(),
            field: self.reference.field(),
            frame: None,
        }
    }

    /// The model takes an access.
    fn take(&mut self, p: Pending) {
        let name = self.reference.reg_name(p.addr, p.write);
        let (mode, reset_mode) = self.reference.mode().unwrap_or((CanMode::BasicCan, true));
        let mut op = if p.write {
            HostOp::write(p.addr, p.data)
        } else {
            HostOp::read(p.addr, 0)
        };
        op = op.at(p.t_ps).mode(mode, reset_mode);
        op.bfm = self.host_bus;
        if let Some(n) = &name {
            op = op.reg(n);
        }
        if p.write {
            if let Some(o) = self.reference.write(p.addr, p.data) {
                op = op.outcome(o);
            }
            // The bench's bit clock follows BTR0/BTR1 as the model took them.
            if reset_mode && (p.addr == 6 || p.addr == 7) {
                let t = &mut self.record.timing;
                if p.addr == 6 {
                    t.btr0 = p.data
                } else {
                    t.btr1 = p.data
                }
                self.bitclock
                    .set_timing(BusTiming::from_btr(t.btr0, t.btr1));
            }
            // A transmission (or self reception) request the model accepted.
            if p.addr == CMR && p.data & 0x11 != 0 && !reset_mode {
                self.last_tr = Some((p.t_ps, self.bits()));
            }
            // An abort, or reset mode, ends the request on purpose.
            if (p.addr == CMR && p.data & 0x02 != 0)
                || self.reference.mode().is_some_and(|(_, rm)| rm)
            {
                self.last_tr = None;
            }
        } else {
            self.cmp.reference_read_taken();
            let v = self.reference.read(p.addr);
            op.model_data = Some(v);
            self.taken_reads.push_back((p.addr, v));
        }
        self.record.host_ops.push(op);
    }

    /// The model's engine events into the record (the TEC per attempt is
    /// derived from them in [`Shadow::record`], as the scenario runner does).
    fn reference_events(&mut self, bit: u64) {
        self.reference.drain_events(&mut self.events);
        let counters = self.reference.counters();
        let t_ps = self.now_ps();
        for k in self.events.drain(..) {
            if matches!(k, EventKind::TxComplete) {
                self.last_tr = None;
            }
            self.bus_log.event(t_ps, &k, counters);
            if self.timed_events.len() < KEEP_EVENTS {
                self.timed_events.push((t_ps, k.clone()));
            }
            let mut e = EngineEvent::new(bit, Side::Model, k);
            if let Some((tec, rec)) = counters {
                e.tec = Some(tec);
                e.rec = Some(rec);
            }
            // Bounded: the first events say most (the diagnoser looks at the first error).
            if self.record.events.len() < 4096 {
                self.record.events.push(e);
            }
        }
        // SR.ES (error warning) for the bus log's state frames, as the CLI's
        // observer does: the model's journal has no warning event of its own.
        let es = self.reference.peek(SR) & 0x40 != 0;
        self.bus_log
            .event(t_ps, &EventKind::ErrorWarning(es), counters);
    }

    /// A divergence found: the diagnosis (the first only; the comparison
    /// stops there, as the CLI's does by default).
    fn check(&mut self) {
        if self.diagnosis.is_some() {
            return;
        }
        if let Some(d) = self.cmp.take_divergence() {
            self.record.divergence = Some(d);
            self.diagnose_now();
        }
    }

    fn diagnose_now(&mut self) {
        let r = self.record();
        let d = diagnose::diagnose(&r);
        let mut text = d.to_text();
        if text.contains("tolerances:") {
            text.push_str(&format!("Profile: {}\n", self.profile_name));
        } else {
            text.push_str(&format!(
                "Profile: {}; tolerances: {}\n",
                self.profile_name, self.tolerances
            ));
        }
        self.diagnosis = Some(text);
    }
}
