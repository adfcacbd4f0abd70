//! A plain register port, as forks of the core expose it: a write strobe
//! and a read strobe of a given length, one address or separate read and
//! write addresses, write data in, read data out, valid a given number of
//! clocks after the read strobe (0 = combinational). No acknowledge: the
//! host times everything. The port runs on one clock with the core (the
//! kit drives it on the CAN clock).

use crate::op::{OpQueue, PendingOp};
use crate::{BfmError, HostMaster, OpHandle, OpKind, OpResult, Rule, Violation};

/// Options of a [`RegportMaster`] (cycles of the port's clock).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RegportConfig {
    /// Strobe length (at least 1).
    pub strobe: u32,
    /// Read data valid this many clocks after the read strobe rises
    /// (0 = combinational: in the strobe's first cycle); it must stay
    /// valid until the master samples it, at clock `read_latency`.
    pub read_latency: u32,
    /// Separate read and write addresses (`rd_adr`, `wr_adr`); with one
    /// address both carry the access's address.
    pub separate_addr: bool,
    /// Idle clocks after each access (a write completes meanwhile).
    pub gap: u32,
    /// Per-operation timeout (time spent queued), clocks.
    pub timeout_cycles: u64,
}

impl Default for RegportConfig {
    /// Our `can_regport` on `can_top`: a one-clock strobe, read data 14
    /// clocks after it and 14 idle clocks after each access (measured: the
    /// core's acknowledge through its clock-domain crossing at one clock
    /// comes 10 clocks after the strobe, 14 for the first access after
    /// reset; a write needs 12 idle clocks before the next strobe).
    fn default() -> Self {
        RegportConfig { strobe: 1, read_latency: 14, separate_addr: true, gap: 14, timeout_cycles: 1000 }
    }
}

/// What the master drives during one clock.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct RegportOut {
    /// Write strobe.
    pub wr: bool,
    /// Read strobe.
    pub rd: bool,
    /// Write address (with one address: the address).
    pub wr_adr: u8,
    /// Read address (with one address: the same as `wr_adr`).
    pub rd_adr: u8,
    /// Write data.
    pub wdat: u8,
}

/// What the port drives.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct RegportIn {
    /// Read data.
    pub rdat: u8,
}

struct Active {
    op: PendingOp,
    /// Clocks since the access started.
    n: u32,
    data: u8,
}

/// Register-port master: one access at a time, fixed length.
pub struct RegportMaster {
    cfg: RegportConfig,
    q: OpQueue,
    in_reset: bool,
    active: Option<Active>,
    out: RegportOut,
}

impl RegportMaster {
    /// A master with these options.
    pub fn new(name: &str, cfg: RegportConfig) -> Self {
        let cfg = RegportConfig { strobe: cfg.strobe.max(1), ..cfg };
        log::info!(
            "{name}: register-port master, strobes {} clocks, read data {} clocks after the strobe{}, {} address(es), {} idle clocks, timeout {} clocks",
            cfg.strobe,
            cfg.read_latency,
            if cfg.read_latency == 0 { " (combinational)" } else { "" },
            if cfg.separate_addr { "separate read and write" } else { "one" },
            cfg.gap,
            cfg.timeout_cycles
        );
        RegportMaster { cfg, q: OpQueue::new(name, cfg.timeout_cycles), in_reset: false, active: None, out: RegportOut::default() }
    }

    /// The options.
    pub fn config(&self) -> &RegportConfig {
        &self.cfg
    }

    /// Clocks one access takes, gap included.
    pub fn access_cycles(&self, kind: OpKind) -> u64 {
        let c = self.cfg;
        let busy = if kind == OpKind::Read { c.strobe.max(c.read_latency + 1) } else { c.strobe };
        (busy + c.gap) as u64
    }

    fn drive(&mut self) {
        let c = self.cfg;
        let mut o = RegportOut { wr_adr: self.out.wr_adr, rd_adr: self.out.rd_adr, wdat: self.out.wdat, ..RegportOut::default() };
        if let Some(a) = &self.active {
            let strobe = a.n < c.strobe;
            let read = a.op.kind == OpKind::Read;
            if read {
                o.rd = strobe;
                o.rd_adr = a.op.addr;
                if !c.separate_addr {
                    o.wr_adr = a.op.addr;
                }
            } else {
                o.wr = strobe;
                o.wr_adr = a.op.addr;
                o.wdat = a.op.data;
                if !c.separate_addr {
                    o.rd_adr = a.op.addr;
                }
            }
        }
        self.out = o;
    }
}

impl HostMaster for RegportMaster {
    type Out = RegportOut;
    type In = RegportIn;

    fn outputs(&self) -> RegportOut {
        self.out
    }

    fn on_edge(&mut self, slave: &RegportIn) {
        let c = self.cfg;
        if let Some(mut a) = self.active.take() {
            a.op.cycles += 1;
            // `slave` is the port after this edge with this clock's pins
            // still applied: at clock n it is the data `n` clocks after the
            // strobe for a registered port, and for a combinational one
            // (latency 0) the data of the strobe's own clock.
            if a.op.kind == OpKind::Read && a.n == c.read_latency.saturating_sub(1) {
                a.data = slave.rdat;
            }
            a.n += 1;
            let total = self.access_cycles(a.op.kind) as u32;
            if a.n >= total {
                self.q.finish(&a.op, a.data);
            } else {
                self.active = Some(a);
            }
        }
        if self.active.is_none()
            && let Some(op) = self.q.next(self.in_reset)
        {
            let data = if op.kind == OpKind::Write { op.data } else { 0 };
            self.active = Some(Active { op, n: 0, data });
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
        self.q.timeout = cycles;
    }
    fn in_flight(&self) -> usize {
        self.q.in_flight()
    }
    fn drain_bound(&self) -> u64 {
        let per = self.access_cycles(OpKind::Read).max(self.access_cycles(OpKind::Write));
        self.q.drain_bound() + (self.q.in_flight() as u64 + 1) * per
    }
}

/// Passive checker of the register port: read and write strobes never
/// together, each strobe exactly the configured length, and the read data
/// stable from the clock it is due until the next strobe (a port whose
/// data comes later than its latency is named there).
pub struct RegportMonitor {
    name: String,
    cfg: RegportConfig,
    rd_run: u32,
    wr_run: u32,
    /// Clocks since the read strobe rose, and the data seen when due.
    since_rd: Option<(u32, Option<u8>)>,
    adr: u8,
}

impl RegportMonitor {
    /// A monitor for a master with `cfg`.
    pub fn new(name: &str, cfg: RegportConfig) -> Self {
        log::info!("{name}: register-port monitor: strobes of {} clocks, never both, read data steady from its due clock", cfg.strobe.max(1));
        RegportMonitor { name: name.to_owned(), cfg: RegportConfig { strobe: cfg.strobe.max(1), ..cfg }, rd_run: 0, wr_run: 0, since_rd: None, adr: 0 }
    }

    /// Check one clock: `m` = master pins during `cycle`, `s_after` = the
    /// port after that clock's edge.
    pub fn observe(&mut self, cycle: u64, m: &RegportOut, s_after: &RegportIn) -> Vec<Violation> {
        let c = self.cfg;
        let mut v = Vec::new();
        let mut flag = |rule, message: String| v.push(Violation { cycle, rule, message });
        if m.rd && m.wr {
            flag(Rule::ReadAndWrite, "read and write strobes high together".to_owned());
        }
        for (now, run, what) in [(m.rd, &mut self.rd_run, "read"), (m.wr, &mut self.wr_run, "write")] {
            if now {
                *run += 1;
            } else if *run > 0 {
                if *run != c.strobe {
                    flag(Rule::StrobeTooShort, format!("{what} strobe high {} clocks (the port takes {})", run, c.strobe));
                }
                *run = 0;
            }
        }
        if m.wr && self.wr_run == 1 {
            self.since_rd = None;
        }
        if m.rd && self.rd_run == 1 {
            self.since_rd = Some((0, None));
            self.adr = m.rd_adr;
        }
        if let Some((n, seen)) = self.since_rd.as_mut() {
            let due = c.read_latency.saturating_sub(1);
            if *n >= due {
                match *seen {
                    None => *seen = Some(s_after.rdat),
                    Some(d) if d != s_after.rdat => {
                        flag(
                            Rule::ChangedWhileValid,
                            format!(
                                "read data of register 0x{:02X} changed from 0x{d:02X} to 0x{:02X} {} clocks after the strobe, later than its read latency of {}",
                                self.adr,
                                s_after.rdat,
                                *n + 1,
                                c.read_latency
                            ),
                        );
                        *seen = Some(s_after.rdat);
                    }
                    _ => {}
                }
            }
            // Watched until the next strobe: the data is the port's until then.
            *n += 1;
        }
        for x in &v {
            log::warn!("{}: {x}", self.name);
        }
        v
    }
}

/// The logic of `can_regport` in Rust, onto a Wishbone slave (the golden
/// model as DUT): the Wishbone request combinational from a strobe, held
/// by a register until the acknowledge; the read byte registered from it
/// and held until the next read.
#[derive(Debug, Clone, Copy, Default)]
pub struct RegportBridge {
    /// The access held after its strobe: (write, address, data).
    busy: Option<(bool, u8, u8)>,
    rdat: u8,
}

impl RegportBridge {
    fn request(&self, m: &RegportOut) -> Option<(bool, u8, u8)> {
        self.busy.or(if m.wr {
            Some((true, m.wr_adr, m.wdat))
        } else if m.rd {
            Some((false, m.rd_adr, 0))
        } else {
            None
        })
    }
    /// The Wishbone wires for the master's pins (combinational).
    pub fn to_wishbone(&self, m: &RegportOut) -> crate::WbMasterOut {
        match self.request(m) {
            Some((we, adr, dat)) => crate::WbMasterOut { cyc: true, stb: true, we, adr, dat },
            None => crate::WbMasterOut::default(),
        }
    }
    /// The port's read data.
    pub fn to_port(&self) -> RegportIn {
        RegportIn { rdat: self.rdat }
    }
    /// The registers at a rising edge: `m`, `s` the wires of the clock
    /// that ends.
    pub fn clock(&mut self, m: &RegportOut, s: &crate::WbSlaveOut) {
        match self.request(m) {
            Some((we, ..)) if s.ack => {
                self.busy = None;
                if !we {
                    self.rdat = s.dat;
                }
            }
            r => self.busy = r,
        }
    }
}
