//! APB (AMBA APB protocol specification, APB3 and APB4): master, protocol
//! monitor, RAM target and the bridge onto a Wishbone slave that our
//! `rtl/can_apb.v` also is.
//!
//! A transfer is a setup phase (PSEL high, PENABLE low, one cycle) and an
//! access phase (PENABLE high) that lasts until the slave raises PREADY;
//! PSLVERR with PREADY ends it in error. APB4 adds PSTRB (byte lanes of a
//! write; zero on a read) and PPROT. Register `n` sits at byte address
//! `n * stride`, its byte in lane `byte_lane` of the 32-bit data bus.

use crate::axi4lite::at_time;
use crate::monitor::{Rule, Violation};
use crate::op::{OpQueue, PendingOp};
use crate::{BfmError, DEFAULT_TIMEOUT_CYCLES, HostBusTarget, HostMaster, OpHandle, OpKind, OpResult, WbMasterOut, WbSlaveOut};

/// APB signals driven by the requester (master).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct ApbMasterOut {
    /// `PSEL`.
    pub psel: bool,
    /// `PENABLE`.
    pub penable: bool,
    /// `PWRITE`.
    pub pwrite: bool,
    /// `PADDR`.
    pub paddr: u32,
    /// `PWDATA` (32 bits).
    pub pwdata: u32,
    /// `PSTRB` (APB4; 0 on APB3).
    pub pstrb: u8,
    /// `PPROT` (APB4; 0 on APB3).
    pub pprot: u8,
}

/// APB signals driven by the completer (slave).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct ApbSlaveOut {
    /// `PREADY`.
    pub pready: bool,
    /// `PRDATA` (32 bits).
    pub prdata: u32,
    /// `PSLVERR`.
    pub pslverr: bool,
}

/// Options of an [`ApbMaster`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ApbConfig {
    /// APB4 (PSTRB, PPROT driven) rather than APB3.
    pub apb4: bool,
    /// Bytes between registers (1, 2 or 4).
    pub stride: u32,
    /// Byte lane of the 32-bit data bus that carries the register (0..3).
    pub byte_lane: u32,
    /// Idle cycles (PSEL low) after each transfer.
    pub idle_cycles: u32,
    /// Per-operation timeout, host cycles.
    pub timeout_cycles: u64,
    /// Host clock period in ps, for the timeout's diagnosis (0: cycles).
    pub period_ps: u64,
}

impl Default for ApbConfig {
    fn default() -> Self {
        Self { apb4: true, stride: 4, byte_lane: 0, idle_cycles: 0, timeout_cycles: DEFAULT_TIMEOUT_CYCLES, period_ps: 0 }
    }
}

#[derive(Debug, Clone, Copy)]
struct Active {
    op: PendingOp,
    /// In the access phase since this absolute cycle (None: setup phase).
    access: Option<u64>,
}

/// APB requester: one transfer at a time.
pub struct ApbMaster {
    cfg: ApbConfig,
    q: OpQueue,
    in_reset: bool,
    active: Option<Active>,
    idle_left: u32,
    prev: ApbSlaveOut,
    out: ApbMasterOut,
    now: u64,
}

impl ApbMaster {
    /// A master with the given options.
    pub fn new(name: &str, cfg: ApbConfig) -> Self {
        log::info!(
            "{name}: {} requester, 32-bit data, register n at byte n*{} in lane {}, {} idle cycles between transfers, timeout {} cycles",
            if cfg.apb4 { "APB4" } else { "APB3" },
            cfg.stride, cfg.byte_lane, cfg.idle_cycles, cfg.timeout_cycles
        );
        Self { cfg, q: OpQueue::new(name, cfg.timeout_cycles), in_reset: false, active: None, idle_left: 0, prev: ApbSlaveOut::default(), out: ApbMasterOut::default(), now: 0 }
    }

    /// The options this master was built with.
    pub fn config(&self) -> &ApbConfig {
        &self.cfg
    }

    fn drive(&mut self) {
        let c = self.cfg;
        let lane = c.byte_lane.min(3);
        self.out = match self.active {
            Some(a) => {
                let write = a.op.kind == OpKind::Write;
                ApbMasterOut {
                    psel: true,
                    penable: a.access.is_some(),
                    pwrite: write,
                    paddr: a.op.addr as u32 * c.stride,
                    pwdata: if write { (a.op.data as u32) << (8 * lane) } else { 0 },
                    pstrb: if c.apb4 && write { 1 << lane } else { 0 },
                    pprot: 0,
                }
            }
            None => ApbMasterOut::default(),
        };
    }
}

impl HostMaster for ApbMaster {
    type Out = ApbMasterOut;
    type In = ApbSlaveOut;

    fn outputs(&self) -> ApbMasterOut {
        self.out
    }

    fn on_edge(&mut self, slave: &ApbSlaveOut) {
        let s = std::mem::replace(&mut self.prev, *slave);
        self.now += 1;
        let mut ended = false;
        if let Some(mut a) = self.active.take() {
            a.op.cycles += 1;
            match a.access {
                None => {
                    a.access = Some(self.now);
                    self.active = Some(a);
                }
                Some(_) if s.pready => {
                    ended = true;
                    if s.pslverr {
                        self.q.complete(a.op.handle, Err(BfmError::ErrorResponse { op: a.op.kind, addr: a.op.addr, response: "PSLVERR" }));
                    } else {
                        let data = if a.op.kind == OpKind::Read { (s.prdata >> (8 * self.cfg.byte_lane.min(3))) as u8 } else { a.op.data };
                        self.q.finish(&a.op, data);
                    }
                }
                Some(since) if a.op.cycles >= a.op.timeout => {
                    ended = true;
                    let at = format!(
                        "APB access phase (from {}): PREADY low for {} host clocks",
                        at_time(since, self.cfg.period_ps),
                        self.now - since
                    );
                    log::warn!("{}: {} {} at 0x{:02X} stopped: {at}", self.q.name(), a.op.handle, a.op.kind, a.op.addr);
                    self.q.complete(a.op.handle, Err(BfmError::Stopped { op: a.op.kind, addr: a.op.addr, cycles: a.op.cycles, at }));
                }
                Some(_) => self.active = Some(a),
            }
        }
        if ended {
            self.idle_left = self.cfg.idle_cycles;
        }
        if self.active.is_none() && !ended {
            let paused = self.in_reset || self.idle_left > 0;
            self.idle_left = self.idle_left.saturating_sub(1);
            self.active = self.q.next(paused).map(|op| Active { op, access: None });
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
        self.q.drain_bound() + (self.cfg.idle_cycles as u64 + 1) * self.q.in_flight() as u64 + self.active.map_or(0, |a| a.op.timeout + 2)
    }
}

/// The APB completer of `rtl/can_apb.v` in front of a Wishbone slave
/// (the golden model as DUT), all combinational: the Wishbone request is
/// the access phase (`PSEL & PENABLE`), PREADY the ack, PRDATA the read
/// byte in its lane; PSLVERR low.
#[derive(Debug, Clone, Copy)]
pub struct ApbBridge {
    /// Bytes between registers.
    pub stride: u32,
    /// Byte lane of the register.
    pub byte_lane: u32,
}

impl ApbBridge {
    /// The Wishbone wires for the requester's pins.
    pub fn to_wishbone(&self, m: &ApbMasterOut) -> WbMasterOut {
        let req = m.psel && m.penable;
        WbMasterOut { cyc: req, stb: req, we: m.pwrite, adr: (m.paddr / self.stride.max(1)) as u8, dat: (m.pwdata >> (8 * self.byte_lane.min(3))) as u8 }
    }

    /// The completer's outputs for the Wishbone slave's.
    pub fn to_apb(&self, s: &WbSlaveOut) -> ApbSlaveOut {
        ApbSlaveOut { pready: s.ack, prdata: (s.dat as u32) << (8 * self.byte_lane.min(3)), pslverr: s.err }
    }
}

/// A 256-register APB RAM completer with registered outputs: PREADY after
/// `wait` access-phase cycles; `stuck` holds PREADY low for ever (a hung
/// completer).
pub struct ApbRam {
    cfg: ApbConfig,
    mem: [u8; 256],
    out: ApbSlaveOut,
    waited: u32,
    /// Access-phase wait states.
    pub wait: u32,
    /// Never raise PREADY.
    pub stuck: bool,
}

impl ApbRam {
    /// A zero-filled RAM with this register layout.
    pub fn new(cfg: ApbConfig) -> Self {
        Self { cfg, mem: [0; 256], out: ApbSlaveOut::default(), waited: 0, wait: 0, stuck: false }
    }

    /// The memory.
    pub fn mem(&self) -> &[u8; 256] {
        &self.mem
    }
}

impl HostBusTarget<ApbMasterOut, ApbSlaveOut> for ApbRam {
    fn cycle(&mut self, m: &ApbMasterOut) -> ApbSlaveOut {
        let lane = 8 * self.cfg.byte_lane.min(3);
        let mut n = ApbSlaveOut { prdata: self.out.prdata, ..Default::default() };
        // The edge ends this access phase if PREADY was already up.
        let ends = m.psel && m.penable && self.out.pready;
        if m.psel && m.penable && !ends && !self.stuck {
            if self.waited >= self.wait {
                let a = (m.paddr / self.cfg.stride.max(1)) as usize & 0xFF;
                if m.pwrite {
                    self.mem[a] = (m.pwdata >> lane) as u8;
                } else {
                    n.prdata = (self.mem[a] as u32) << lane;
                }
                n.pready = true;
                self.waited = 0;
            } else {
                self.waited += 1;
            }
        }
        self.out = n;
        n
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum MonState {
    Idle,
    /// Last cycle was a setup phase.
    Setup,
    /// Last cycle was an access phase without PREADY, since this cycle.
    Waiting(u64),
}

/// APB protocol monitor: the setup phase is one cycle and is followed by
/// the access phase; PSEL, PENABLE, PADDR, PWRITE, PWDATA (and on APB4
/// PSTRB, PPROT) held through the access phase until PREADY; PSTRB zero on
/// a read (APB4); PSLVERR flagged; PREADY low no longer than `timeout`.
pub struct ApbMonitor {
    name: String,
    apb4: bool,
    timeout: u64,
    prev_s: ApbSlaveOut,
    prev_m: ApbMasterOut,
    state: MonState,
    reported: bool,
}

impl ApbMonitor {
    /// A monitor flagging an access phase longer than `timeout` cycles.
    pub fn new(name: &str, apb4: bool, timeout: u64) -> Self {
        log::info!("{name}: {} monitor: setup then access phase, signals held until PREADY, PSLVERR, PREADY within {timeout} cycles", if apb4 { "APB4" } else { "APB3" });
        Self { name: name.to_owned(), apb4, timeout, prev_s: ApbSlaveOut::default(), prev_m: ApbMasterOut::default(), state: MonState::Idle, reported: false }
    }

    /// The monitor's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Check one cycle (see the crate docs for `m` and `s_after`).
    pub fn observe(&mut self, cycle: u64, m: &ApbMasterOut, s_after: &ApbSlaveOut) -> Vec<Violation> {
        let s = std::mem::replace(&mut self.prev_s, *s_after);
        let pm = std::mem::replace(&mut self.prev_m, *m);
        let mut v = Vec::new();
        let mut flag = |rule, message: String| v.push(Violation { cycle, rule, message });
        let same = m.paddr == pm.paddr && m.pwrite == pm.pwrite && (!m.pwrite || m.pwdata == pm.pwdata) && (!self.apb4 || (m.pstrb == pm.pstrb && m.pprot == pm.pprot));
        match self.state {
            MonState::Setup => {
                if !(m.psel && m.penable) {
                    flag(Rule::PhaseOrder, format!("the setup phase at cycle {} was not followed by an access phase (PSEL={} PENABLE={})", cycle - 1, m.psel as u8, m.penable as u8));
                } else if !same {
                    flag(Rule::ChangedWhileValid, "PADDR, PWRITE, PWDATA, PSTRB or PPROT changed between the setup and the access phase".into());
                }
            }
            MonState::Waiting(since) => {
                if !(m.psel && m.penable) {
                    flag(Rule::ValidDroppedBeforeReady, format!("PSEL or PENABLE fell before PREADY (access phase from cycle {since}): the transfer was abandoned"));
                } else if !same {
                    flag(Rule::ChangedWhileValid, format!("PADDR, PWRITE, PWDATA, PSTRB or PPROT changed in the access phase (from cycle {since}) before PREADY"));
                }
            }
            MonState::Idle => {
                if m.penable {
                    flag(Rule::PhaseOrder, format!("PENABLE high without a setup phase (PSEL={})", m.psel as u8));
                }
            }
        }
        if self.apb4 && m.psel && !m.pwrite && m.pstrb != 0 {
            flag(Rule::ChangedWhileValid, format!("PSTRB=0x{:X} on a read (APB4: all low on reads)", m.pstrb));
        }
        let access = m.psel && m.penable;
        if access && s.pready && s.pslverr {
            flag(Rule::ErrorResponse, format!("{} at PADDR 0x{:X} ended with PSLVERR", if m.pwrite { "write" } else { "read" }, m.paddr));
        }
        self.state = if m.psel && !m.penable {
            MonState::Setup
        } else if access && !s.pready {
            let since = match self.state {
                MonState::Waiting(c) => c,
                _ => cycle,
            };
            if cycle - since >= self.timeout && !self.reported {
                self.reported = true;
                flag(Rule::HandshakeStuck, format!("APB access phase: PREADY low for {} host clocks (from cycle {since})", self.timeout));
            }
            MonState::Waiting(since)
        } else {
            self.reported = false;
            MonState::Idle
        };
        v
    }
}
