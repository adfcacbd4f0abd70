//! Intel-mode (8051) multiplexed host bus, as the SJA1000 chip and the
//! opencores `can_top` built without `CAN_WISHBONE_IF` take it: the master
//! drives the register address on the shared port (`AD7..AD0`, the core's
//! `port_0`) while ALE is asserted, the slave latches it, then one RD or WR
//! strobe with chip select moves the data over the same port.
//!
//! There is no acknowledge: an access takes a fixed number of host cycles
//! ([`I8051Timing`]) and the slave must answer within the RD strobe.
//! Pin records carry wire levels; [`I8051Polarity`] says which level asserts
//! each control pin (the chip's /CS, /RD, /WR are active low, the opencores
//! core's `cs_can_i`, `rd_i`, `wr_i` active high; ALE is active high on both).

use crate::op::{OpQueue, Pause, PendingOp, step_pause};
use crate::{BfmError, HostBusTarget, HostMaster, OpHandle, OpKind, OpResult, Rule, Violation};

/// Default per-operation timeout, host cycles: an access never waits for
/// the slave, so only time spent queued (in reset) counts.
pub const DEFAULT_I8051_TIMEOUT_CYCLES: u64 = 1000;

/// What the master drives during one host cycle (wire levels).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct I8051Out {
    /// ALE pin level.
    pub ale: bool,
    /// Chip-select pin level.
    pub cs: bool,
    /// RD pin level.
    pub rd: bool,
    /// WR pin level.
    pub wr: bool,
    /// What the master drives on the port (meaningful with `ad_oe`).
    pub ad: u8,
    /// The master drives the port.
    pub ad_oe: bool,
}

/// What the slave drives on the shared port during one host cycle.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct I8051SlaveOut {
    /// Value on the slave's port drivers (meaningful with `ad_oe`).
    pub ad: u8,
    /// The slave drives the port.
    pub ad_oe: bool,
}

/// The level of the shared port: the master's value if it drives, else the
/// slave's, else the pull-ups (0xFF). With both driving, the master's value
/// is taken (the monitor reports the contention).
pub fn port_level(m: &I8051Out, s: &I8051SlaveOut) -> u8 {
    if m.ad_oe {
        m.ad
    } else if s.ad_oe {
        s.ad
    } else {
        0xFF
    }
}

/// Which level asserts each control pin (`true` = active low).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct I8051Polarity {
    /// ALE asserted low (false on every Intel-mode part we know of).
    pub ale_low: bool,
    /// Chip select asserted low.
    pub cs_low: bool,
    /// RD asserted low.
    pub rd_low: bool,
    /// WR asserted low.
    pub wr_low: bool,
}

impl I8051Polarity {
    /// The SJA1000 chip: ALE high, /CS, /RD, /WR low.
    pub const SJA1000: I8051Polarity = I8051Polarity {
        ale_low: false,
        cs_low: true,
        rd_low: true,
        wr_low: true,
    };
    /// The opencores `can_top` 8051 build and our `can_top_8051`: all high.
    pub const ACTIVE_HIGH: I8051Polarity = I8051Polarity {
        ale_low: false,
        cs_low: false,
        rd_low: false,
        wr_low: false,
    };

    /// ALE asserted on these wires.
    pub fn ale(&self, m: &I8051Out) -> bool {
        m.ale != self.ale_low
    }
    /// Chip select asserted.
    pub fn cs(&self, m: &I8051Out) -> bool {
        m.cs != self.cs_low
    }
    /// RD asserted (chip select not considered).
    pub fn rd(&self, m: &I8051Out) -> bool {
        m.rd != self.rd_low
    }
    /// WR asserted (chip select not considered).
    pub fn wr(&self, m: &I8051Out) -> bool {
        m.wr != self.wr_low
    }
    /// The wires with every control pin at the given assertion.
    pub fn drive(&self, ale: bool, cs: bool, rd: bool, wr: bool) -> I8051Out {
        I8051Out {
            ale: ale != self.ale_low,
            cs: cs != self.cs_low,
            rd: rd != self.rd_low,
            wr: wr != self.wr_low,
            ad: 0,
            ad_oe: false,
        }
    }
    fn describe(&self) -> String {
        let p = |low: bool, n: &str| if low { format!("/{n}") } else { n.to_string() };
        format!(
            "{} {} {} {}",
            p(self.ale_low, "ALE"),
            p(self.cs_low, "CS"),
            p(self.rd_low, "RD"),
            p(self.wr_low, "WR")
        )
    }
}

/// One access in host cycles (each at least 1). The phases, in order:
/// ALE asserted with the address on the port (`ale`), ALE released with the
/// address still driven (`addr_hold`), the port turned around (`read_float`:
/// released before RD; `data_setup`: write data driven before WR), the
/// strobe (`rd`/`wr`), the write data held after WR (`data_hold`), and idle
/// wires before the next access (`recovery`). Chip select is asserted from
/// ALE to the end of `data_hold`.
///
/// Defaults at a 50 MHz host clock (20 ns), after the SJA1000 datasheet
/// (2000 Jan 04) AC characteristics, Intel mode, as far as we could read
/// them (see `docs/ARCHITECTURE.md`, "8051 host bus"): every chip minimum
/// (ALE width, address set-up and hold around ALE, data set-up and hold
/// around WR, RD and WR pulse widths of a few tens of ns) is met with
/// margin by a classic 12 MHz 80C51 `MOVX` cycle, which these defaults
/// follow (ALE 120 ns, address hold 40 ns, ALE-to-strobe 200 ns, data
/// hold 40 ns). The RD strobe is stretched to 760 ns (38 cycles), WR is
/// 400 ns: our `can_top_8051` answers a read through its clock-domain
/// crossing only from the 31st RD cycle at 50/24 MHz (measured by
/// `cosim/tests/suite/i8051.rs`), where the chip answers within tens of ns.
/// Recovery is 260 ns (13 cycles, 6 CAN clocks at 24 MHz) so that a write,
/// which the wrapper performs after WR is released, is done before the
/// next access's RD (an 80C51 spends at least that long between two
/// `MOVX`). `cosim::i8051_timing_for_rtl` scales both to other clocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct I8051Timing {
    /// Cycles with ALE asserted and the address driven.
    pub ale: u32,
    /// Cycles the address stays on the port after ALE falls.
    pub addr_hold: u32,
    /// Read: cycles with the port released before RD.
    pub read_float: u32,
    /// Write: cycles with the data driven before WR.
    pub data_setup: u32,
    /// RD strobe width; the master samples the port at its last cycle.
    pub rd: u32,
    /// WR strobe width.
    pub wr: u32,
    /// Write: cycles the data stays driven (and CS asserted) after WR.
    pub data_hold: u32,
    /// Idle cycles after an access.
    pub recovery: u32,
}

impl Default for I8051Timing {
    fn default() -> Self {
        I8051Timing {
            ale: 6,
            addr_hold: 2,
            read_float: 8,
            data_setup: 8,
            rd: 38,
            wr: 20,
            data_hold: 2,
            recovery: 13,
        }
    }
}

/// Options of an [`I8051Master`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct I8051Config {
    /// Pin polarities.
    pub polarity: I8051Polarity,
    /// Cycle counts.
    pub timing: I8051Timing,
    /// Per-operation timeout (time spent queued), host cycles.
    pub timeout_cycles: u64,
}

impl Default for I8051Config {
    fn default() -> Self {
        I8051Config {
            polarity: I8051Polarity::ACTIVE_HIGH,
            timing: I8051Timing::default(),
            timeout_cycles: DEFAULT_I8051_TIMEOUT_CYCLES,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Ale,
    AddrHold,
    Turn,
    Strobe,
    DataHold,
    Recovery,
}

struct Active {
    op: PendingOp,
    phase: Phase,
    left: u32,
    data: u8,
}

/// Intel-mode multiplexed bus master: one access at a time, fixed length.
pub struct I8051Master {
    cfg: I8051Config,
    q: OpQueue,
    pause: Option<Pause>,
    in_reset: bool,
    active: Option<Active>,
    prev: I8051SlaveOut,
    out: I8051Out,
}

impl I8051Master {
    /// A master with the given options and no pause generator.
    pub fn new(name: &str, cfg: I8051Config) -> Self {
        let t = cfg.timing;
        log::info!(
            "{name}: Intel-mode (8051) multiplexed bus master, port 8 bits, pins {}, \
             ALE {} cycles, address hold {}, read float {}, write data set-up {}, RD {} cycles, \
             WR {} cycles, data hold {}, recovery {}, timeout {} cycles",
            cfg.polarity.describe(),
            t.ale,
            t.addr_hold,
            t.read_float,
            t.data_setup,
            t.rd,
            t.wr,
            t.data_hold,
            t.recovery,
            cfg.timeout_cycles
        );
        let mut m = I8051Master {
            cfg,
            q: OpQueue::new(name, cfg.timeout_cycles),
            pause: None,
            in_reset: false,
            active: None,
            prev: I8051SlaveOut::default(),
            out: I8051Out::default(),
        };
        m.drive();
        m
    }

    /// Install (or remove) the idle-inserting pause generator (delays the
    /// start of an access only: a started access has fixed timing).
    pub fn set_pause(&mut self, pause: Option<Pause>) {
        log::info!(
            "{}: idle insertion {}",
            self.q.name(),
            if pause.is_some() { "on" } else { "off" }
        );
        self.pause = pause;
    }

    /// The options this master was built with.
    pub fn config(&self) -> &I8051Config {
        &self.cfg
    }

    /// A write access is on the wires (from its ALE to its recovery).
    pub(crate) fn active_write(&self) -> bool {
        self.active.as_ref().is_some_and(|a| a.op.kind != OpKind::Read && a.phase != Phase::Recovery)
    }

    /// Host cycles one access takes on the wires, recovery included.
    pub fn access_cycles(&self, kind: OpKind) -> u64 {
        let t = self.cfg.timing;
        let c = |v: u32| v.max(1) as u64;
        let common = c(t.ale) + c(t.addr_hold) + c(t.recovery);
        match kind {
            OpKind::Read => common + c(t.read_float) + c(t.rd),
            _ => common + c(t.data_setup) + c(t.wr) + c(t.data_hold),
        }
    }

    fn len(&self, phase: Phase, kind: OpKind) -> u32 {
        let t = self.cfg.timing;
        let read = kind == OpKind::Read;
        match phase {
            Phase::Ale => t.ale,
            Phase::AddrHold => t.addr_hold,
            Phase::Turn if read => t.read_float,
            Phase::Turn => t.data_setup,
            Phase::Strobe if read => t.rd,
            Phase::Strobe => t.wr,
            Phase::DataHold => t.data_hold,
            Phase::Recovery => t.recovery,
        }
        .max(1)
    }

    fn next_phase(phase: Phase, kind: OpKind) -> Option<Phase> {
        Some(match phase {
            Phase::Ale => Phase::AddrHold,
            Phase::AddrHold => Phase::Turn,
            Phase::Turn => Phase::Strobe,
            Phase::Strobe if kind == OpKind::Read => Phase::Recovery,
            Phase::Strobe => Phase::DataHold,
            Phase::DataHold => Phase::Recovery,
            Phase::Recovery => return None,
        })
    }

    fn drive(&mut self) {
        let p = self.cfg.polarity;
        self.out = match &self.active {
            None => p.drive(false, false, false, false),
            Some(a) => {
                let read = a.op.kind == OpKind::Read;
                let (ale, cs, strobe, ad_oe, ad) = match a.phase {
                    Phase::Ale => (true, true, false, true, a.op.addr),
                    Phase::AddrHold => (false, true, false, true, a.op.addr),
                    Phase::Turn => (false, true, false, !read, a.op.data),
                    Phase::Strobe => (false, true, true, !read, a.op.data),
                    Phase::DataHold => (false, true, false, true, a.op.data),
                    Phase::Recovery => (false, false, false, false, 0),
                };
                let mut o = p.drive(ale, cs, strobe && read, strobe && !read);
                o.ad_oe = ad_oe;
                o.ad = if ad_oe { ad } else { 0 };
                o
            }
        };
    }
}

impl HostMaster for I8051Master {
    type Out = I8051Out;
    type In = I8051SlaveOut;

    fn outputs(&self) -> I8051Out {
        self.out
    }

    fn on_edge(&mut self, slave: &I8051SlaveOut) {
        // What was on the wires during the cycle this edge ends.
        let sample = std::mem::replace(&mut self.prev, *slave);
        let paused = step_pause(&mut self.pause) || self.in_reset;
        if let Some(mut a) = self.active.take() {
            a.op.cycles += 1;
            a.left -= 1;
            if a.left == 0 {
                if a.phase == Phase::Strobe && a.op.kind == OpKind::Read {
                    // The last RD cycle: the port as the slave drove it
                    // (pull-ups if it did not).
                    a.data = port_level(&self.out, &sample);
                }
                match Self::next_phase(a.phase, a.op.kind) {
                    Some(next) => {
                        a.left = self.len(next, a.op.kind);
                        a.phase = next;
                        self.active = Some(a);
                    }
                    None => self.q.finish(&a.op, a.data),
                }
            } else {
                self.active = Some(a);
            }
        }
        if self.active.is_none()
            && let Some(op) = self.q.next(paused)
        {
            let data = if op.kind == OpKind::Write { op.data } else { 0 };
            self.active = Some(Active {
                left: self.len(Phase::Ale, op.kind),
                op,
                phase: Phase::Ale,
                data,
            });
        }
        self.drive();
    }

    fn start_write(&mut self, addr: u8, data: u8) -> OpHandle {
        self.q.push(OpKind::Write, addr, data)
    }

    fn start_read(&mut self, addr: u8) -> OpHandle {
        self.q.push(OpKind::Read, addr, 0)
    }

    fn poll(&mut self, handle: OpHandle) -> Option<Result<OpResult, BfmError>> {
        self.q.poll(handle)
    }

    fn reset(&mut self) {
        log::info!("{}: reset", self.q.name());
        let active = self.active.take().map(|a| a.op);
        self.q.flush(active);
        self.drive();
    }

    fn set_reset(&mut self, asserted: bool) {
        if crate::op::reset_pin_edge(self.q.name(), &mut self.in_reset, asserted) {
            self.reset();
        }
    }

    fn set_timeout(&mut self, cycles: u64) {
        log::info!("{}: per-operation timeout {cycles} cycles", self.q.name());
        self.q.timeout = cycles;
    }

    fn in_flight(&self) -> usize {
        self.q.in_flight()
    }

    fn drain_bound(&self) -> u64 {
        let per = self
            .access_cycles(OpKind::Write)
            .max(self.access_cycles(OpKind::Read));
        self.q.drain_bound() + (self.q.in_flight() as u64 + 1) * per
    }
}

/// A 256-byte RAM on the multiplexed bus, registered like a synchronous
/// slave: it latches the port at every cycle ALE is asserted (the last one
/// wins), answers RD with CS after `read_latency` cycles (its registered
/// data is on the wires from the strobe's cycle `read_latency + 2` until
/// the cycle after RD is released), and stores the port as it was in the
/// last WR cycle when WR is released.
pub struct I8051Ram {
    name: String,
    pol: I8051Polarity,
    read_latency: u32,
    mem: [u8; 256],
    addr: u8,
    rd_cycles: u32,
    wr_data: Option<u8>,
    out: I8051SlaveOut,
    /// Extra cycles the port stays driven after RD is released (a slow
    /// float: for the monitor tests).
    pub float_delay: u32,
    float_left: u32,
    writes: u64,
}

impl I8051Ram {
    /// A zero-filled RAM answering reads `read_latency` cycles after RD.
    pub fn new(name: &str, pol: I8051Polarity, read_latency: u32) -> Self {
        log::info!(
            "{name}: 8051-bus RAM target, 256 x 8 bits, pins {}, read data after {read_latency} cycles, registered",
            pol.describe()
        );
        I8051Ram {
            name: name.to_owned(),
            pol,
            read_latency,
            mem: [0; 256],
            addr: 0,
            rd_cycles: 0,
            wr_data: None,
            out: I8051SlaveOut::default(),
            float_delay: 0,
            float_left: 0,
            writes: 0,
        }
    }

    /// The memory contents.
    pub fn mem(&self) -> &[u8; 256] {
        &self.mem
    }

    /// The memory contents, writable (to preload).
    pub fn mem_mut(&mut self) -> &mut [u8; 256] {
        &mut self.mem
    }

    /// Writes stored so far.
    pub fn writes(&self) -> u64 {
        self.writes
    }

    /// The target's name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl HostBusTarget<I8051Out, I8051SlaveOut> for I8051Ram {
    fn cycle(&mut self, m: &I8051Out) -> I8051SlaveOut {
        let p = self.pol;
        let wire = port_level(m, &self.out);
        let cs = p.cs(m);
        if p.ale(m) {
            self.addr = wire;
        }
        if cs && p.wr(m) {
            self.wr_data = Some(wire);
        } else if let Some(d) = self.wr_data.take() {
            self.mem[self.addr as usize] = d;
            self.writes += 1;
        }
        let mut next = I8051SlaveOut::default();
        if cs && p.rd(m) {
            self.rd_cycles += 1;
            if self.rd_cycles > self.read_latency {
                next = I8051SlaveOut {
                    ad: self.mem[self.addr as usize],
                    ad_oe: true,
                };
                self.float_left = self.float_delay;
            }
        } else {
            self.rd_cycles = 0;
            if self.out.ad_oe && self.float_left > 0 {
                self.float_left -= 1;
                next = self.out;
            }
        }
        self.out = next;
        next
    }
}

/// Minimum widths the slave needs and the monitor checks, host cycles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct I8051MonitorConfig {
    /// Pin polarities.
    pub polarity: I8051Polarity,
    /// Minimum ALE width.
    pub min_ale: u32,
    /// Minimum cycles the address stays on the port after ALE falls.
    pub min_addr_hold: u32,
    /// Minimum RD width (with CS).
    pub min_rd: u32,
    /// Minimum WR width (with CS).
    pub min_wr: u32,
    /// Write data stable before WR is released, cycles.
    pub min_data_setup: u32,
    /// Write data still driven after WR is released, cycles.
    pub min_data_hold: u32,
    /// Cycles the slave may keep driving after RD is released (float time).
    pub read_float: u32,
}

impl I8051MonitorConfig {
    /// The checks a master with `t` passes exactly (each minimum equal to
    /// the master's own value), so shortening any phase is caught.
    pub fn for_timing(polarity: I8051Polarity, t: &I8051Timing) -> Self {
        I8051MonitorConfig {
            polarity,
            min_ale: t.ale.max(1),
            min_addr_hold: t.addr_hold.max(1),
            min_rd: t.rd.max(1),
            min_wr: t.wr.max(1),
            min_data_setup: (t.data_setup + t.wr).max(1),
            min_data_hold: t.data_hold.max(1),
            read_float: t.recovery.max(1),
        }
    }
}

/// Passive checker of the multiplexed bus.
pub struct I8051Monitor {
    name: String,
    cfg: I8051MonitorConfig,
    prev_s: I8051SlaveOut,
    prev_m: I8051Out,
    ale_run: u64,
    /// Cycles since ALE fell while the master still drives the address.
    addr_hold_run: u64,
    addr: Option<u8>,
    checking_addr_hold: bool,
    rd_run: u64,
    wr_run: u64,
    /// Write data of the current WR strobe: value and cycles stable.
    wr_data: Option<(u8, u64)>,
    /// After WR release: (data, cycles to check still).
    hold_check: Option<(u8, u64)>,
    since_rd: u64,
}

impl I8051Monitor {
    /// A monitor with the given minimums.
    pub fn new(name: &str, cfg: I8051MonitorConfig) -> Self {
        log::info!(
            "{name}: 8051-bus monitor, pins {}, checks ALE >= {} cycles, address hold >= {}, \
             RD >= {}, WR >= {}, write data set-up >= {} and hold >= {}, port contention, \
             slave driving outside RD (float {} cycles)",
            cfg.polarity.describe(),
            cfg.min_ale,
            cfg.min_addr_hold,
            cfg.min_rd,
            cfg.min_wr,
            cfg.min_data_setup,
            cfg.min_data_hold,
            cfg.read_float
        );
        I8051Monitor {
            name: name.to_owned(),
            cfg,
            prev_s: I8051SlaveOut::default(),
            // Before the first cycle the wires are idle.
            prev_m: cfg.polarity.drive(false, false, false, false),
            ale_run: 0,
            addr_hold_run: 0,
            addr: None,
            checking_addr_hold: false,
            rd_run: 0,
            wr_run: 0,
            wr_data: None,
            hold_check: None,
            since_rd: u64::MAX,
        }
    }

    /// Check one cycle: `m` = master pins during `cycle`, `s_after` = slave
    /// outputs after that cycle's edge.
    pub fn observe(&mut self, cycle: u64, m: &I8051Out, s_after: &I8051SlaveOut) -> Vec<Violation> {
        let s = std::mem::replace(&mut self.prev_s, *s_after);
        let pm = std::mem::replace(&mut self.prev_m, *m);
        let p = self.cfg.polarity;
        let c = self.cfg;
        let mut v = Vec::new();
        let mut flag = |rule, message: String| {
            v.push(Violation {
                cycle,
                rule,
                message,
            });
        };
        let (ale, cs, rd, wr) = (p.ale(m), p.cs(m), p.rd(m), p.wr(m));
        let (prd, pwr) = (p.rd(&pm) && p.cs(&pm), p.wr(&pm) && p.cs(&pm));
        if m.ad_oe && s.ad_oe {
            flag(
                Rule::PortContention,
                format!(
                    "master drives 0x{:02X} and slave drives 0x{:02X} on the port together",
                    m.ad, s.ad
                ),
            );
        }
        if rd && wr && cs {
            flag(
                Rule::ReadAndWrite,
                "RD and WR asserted together with CS".to_owned(),
            );
        }
        // ALE width, then the address held after it falls.
        if ale {
            self.ale_run += 1;
            self.addr = m.ad_oe.then_some(m.ad);
            self.checking_addr_hold = false;
        } else if self.ale_run > 0 {
            if self.ale_run < c.min_ale as u64 {
                flag(
                    Rule::StrobeTooShort,
                    format!(
                        "ALE asserted {} cycles (minimum {})",
                        self.ale_run, c.min_ale
                    ),
                );
            }
            self.ale_run = 0;
            self.addr_hold_run = 0;
            self.checking_addr_hold = true;
        }
        if self.checking_addr_hold && !ale {
            let held = m.ad_oe && Some(m.ad) == self.addr;
            if held {
                self.addr_hold_run += 1;
                if self.addr_hold_run >= c.min_addr_hold as u64 {
                    self.checking_addr_hold = false;
                }
            } else {
                flag(
                    Rule::DataNotHeld,
                    format!(
                        "address {} held {} cycles after ALE fell (minimum {}); the port now {}",
                        self.addr
                            .map_or("(not driven)".to_owned(), |a| format!("0x{a:02X}")),
                        self.addr_hold_run,
                        c.min_addr_hold,
                        if m.ad_oe {
                            format!("carries 0x{:02X}", m.ad)
                        } else {
                            "is released".to_owned()
                        }
                    ),
                );
                self.checking_addr_hold = false;
            }
        }
        // Strobe widths (with CS).
        let rd_now = rd && cs;
        let wr_now = wr && cs;
        if rd_now {
            self.rd_run += 1;
            self.since_rd = 0;
        } else {
            if prd && self.rd_run < c.min_rd as u64 {
                flag(
                    Rule::StrobeTooShort,
                    format!("RD asserted {} cycles (minimum {})", self.rd_run, c.min_rd),
                );
            }
            self.rd_run = 0;
            self.since_rd = self.since_rd.saturating_add(1);
        }
        // Write data: stable from min_data_setup cycles before WR is
        // released until min_data_hold cycles after.
        if wr_now {
            self.wr_run += 1;
            let d = m.ad_oe.then_some(m.ad);
            self.wr_data = match (self.wr_data, d) {
                (Some((old, n)), Some(new)) if old == new => Some((old, n + 1)),
                (_, Some(new)) => Some((new, 1)),
                (_, None) => None,
            };
        } else if pwr {
            if self.wr_run < c.min_wr as u64 {
                flag(
                    Rule::StrobeTooShort,
                    format!("WR asserted {} cycles (minimum {})", self.wr_run, c.min_wr),
                );
            }
            match self.wr_data {
                None => flag(
                    Rule::DataNotHeld,
                    "WR released while the master did not drive the port".to_owned(),
                ),
                Some((d, n)) => {
                    if n < c.min_data_setup as u64 {
                        flag(
                            Rule::DataNotHeld,
                            format!(
                                "write data 0x{d:02X} stable {n} cycles before WR was released (minimum {})",
                                c.min_data_setup
                            ),
                        );
                    }
                    self.hold_check = Some((d, c.min_data_hold as u64));
                }
            }
            self.wr_run = 0;
            self.wr_data = None;
        }
        // Count data stable before the strobe too (set-up includes it).
        if !wr_now && !pwr && cs && m.ad_oe && !ale {
            self.wr_data = match self.wr_data {
                Some((old, n)) if old == m.ad => Some((old, n + 1)),
                _ => Some((m.ad, 1)),
            };
        } else if !wr_now && !cs {
            self.wr_data = None;
        }
        if !wr_now && let Some((d, left)) = self.hold_check {
            self.hold_check = None;
            if !(m.ad_oe && m.ad == d) {
                flag(
                    Rule::DataNotHeld,
                    format!(
                        "write data 0x{d:02X} not held {} cycles after WR was released (the port {})",
                        c.min_data_hold,
                        if m.ad_oe {
                            format!("carries 0x{:02X}", m.ad)
                        } else {
                            "is released".to_owned()
                        }
                    ),
                );
            } else if left > 1 {
                self.hold_check = Some((d, left - 1));
            }
        }
        // The slave may drive only during RD with CS (and its float time).
        if s.ad_oe && !rd_now && self.since_rd > c.read_float as u64 {
            flag(
                Rule::ReadOutsideStrobe,
                format!(
                    "slave drives 0x{:02X} on the port {} cycles after the last RD (float limit {})",
                    s.ad,
                    if self.since_rd == u64::MAX {
                        "with no RD ever".to_owned()
                    } else {
                        self.since_rd.to_string()
                    },
                    c.read_float
                ),
            );
        }
        for x in &v {
            log::warn!("{}: {x}", self.name);
        }
        v
    }
}
