//! The golden model in the two roles the kernel needs: a DUT with the
//! `can_top` Wishbone pins ([`ModelDut`], so everything runs without
//! Verilator and the comparator can be checked against the model itself),
//! and the reference that shadows a DUT ([`ModelRef`]).

use bfm::{AvMasterOut, AvSlaveOut, WbMasterOut, WbSlaveOut};
use can_engine::ErrorKind;
use can_proto::Field;
use diagnose::{CanMode, EventKind, WriteOutcome as RecOutcome};
use regmap::{Access, Mode, Target};
use sja1000::{NodeEvent, Sja1000, WriteOutcome};

use crate::compare::Reference;
use crate::dut::{CanPins, Dut, HostPort};

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
/// registered, one host cycle after `cyc & stb`, as in the fixtures.
#[derive(Debug)]
pub struct ModelDut {
    m: Sja1000,
    rst: bool,
    wb_in: WbMasterOut,
    ack: bool,
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
            dat_o: 0,
            rx: true,
            host_clk: false,
            can_clk: false,
            outcomes: Vec::new(),
        }
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
    fn host_port(&self) -> HostPort {
        HostPort::Wishbone
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
    fn set_av(&mut self, _m: &AvMasterOut) {}
    fn av(&self) -> AvSlaveOut {
        AvSlaveOut::default()
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
                self.dat_o = 0;
            } else {
                let w = self.wb_in;
                let go = w.cyc && w.stb && !self.ack;
                if go {
                    if w.we {
                        let o = self.m.write(w.adr, w.dat);
                        self.outcomes.push((w.adr, w.dat, o));
                    } else {
                        self.dat_o = self.m.read(w.adr);
                    }
                }
                self.ack = go;
            }
        }
    }
}

/// The golden model as the reference of a lockstep run.
#[derive(Debug)]
pub struct ModelRef {
    m: Sja1000,
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
        ModelRef { m }
    }

    /// The model inside.
    pub fn model(&self) -> &Sja1000 {
        &self.m
    }
}

fn error_kind(ecc: u8) -> ErrorKind {
    // ECC bits 7:6: 00 bit, 01 form, 10 stuff, 11 other (CRC/ACK).
    match ecc >> 6 {
        0 => ErrorKind::Bit,
        1 => ErrorKind::Form,
        2 => ErrorKind::Stuff,
        _ => {
            if ecc & 0x1f == 0x19 || ecc & 0x1f == 0x1b {
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
        self.m.hard_reset();
        self.m.set_journal(true);
    }
    fn write(&mut self, addr: u8, data: u8) -> Option<RecOutcome> {
        Some(outcome_record(self.m.write(addr, data)))
    }
    fn read(&mut self, addr: u8) -> u8 {
        self.m.read(addr)
    }
    fn peek(&self, addr: u8) -> u8 {
        self.m.peek(addr)
    }
    #[inline]
    fn clock(&mut self, rx: bool) {
        self.m.clock(rx);
    }
    fn adopt_counters(&mut self, tec: Option<u8>, rec: Option<u8>) -> bool {
        self.m.adopt_counters(tec, rec);
        true
    }
    fn adopt_register(&mut self, addr: u8, value: u8) -> bool {
        self.m.adopt_register(addr, value)
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
    fn reg_name(&self, addr: u8, write: bool) -> Option<String> {
        reg_name(&self.m, addr, write)
    }
    fn drain_events(&mut self, out: &mut Vec<EventKind>) {
        if !self.m.journal_pending() {
            return;
        }
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
