//! AXI4-Lite: master, protocol monitor, RAM target and the bridge onto a
//! Wishbone slave that our `rtl/can_axi4lite.v` also is.
//!
//! The five channels (AW, W, B, AR, R) each have their own VALID/READY; a
//! transfer on a channel happens at a rising edge with VALID and READY both
//! high. The master asserts AWVALID and WVALID after their own delays, in
//! either order (AMBA AXI: a master must not wait for READY before VALID),
//! and takes the response with BREADY/RREADY after their delays.
//!
//! Register `n` sits at byte address `n * stride`, its byte in lane
//! `byte_lane` of the 32-bit data bus (WSTRB has that lane's bit only).

use crate::monitor::{Rule, Violation};
use crate::op::{OpQueue, PendingOp};
use crate::{BfmError, DEFAULT_TIMEOUT_CYCLES, HostBusTarget, HostMaster, OpHandle, OpKind, OpResult, WbMasterOut, WbSlaveOut};

/// AXI4-Lite signals driven by the master.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct AxiMasterOut {
    /// `AWVALID`.
    pub awvalid: bool,
    /// `AWADDR`.
    pub awaddr: u32,
    /// `AWPROT`.
    pub awprot: u8,
    /// `WVALID`.
    pub wvalid: bool,
    /// `WDATA` (32 bits).
    pub wdata: u32,
    /// `WSTRB`.
    pub wstrb: u8,
    /// `BREADY`.
    pub bready: bool,
    /// `ARVALID`.
    pub arvalid: bool,
    /// `ARADDR`.
    pub araddr: u32,
    /// `ARPROT`.
    pub arprot: u8,
    /// `RREADY`.
    pub rready: bool,
}

/// AXI4-Lite signals driven by the slave.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct AxiSlaveOut {
    /// `AWREADY`.
    pub awready: bool,
    /// `WREADY`.
    pub wready: bool,
    /// `BVALID`.
    pub bvalid: bool,
    /// `BRESP` (0 OKAY, 1 EXOKAY, 2 SLVERR, 3 DECERR).
    pub bresp: u8,
    /// `ARREADY`.
    pub arready: bool,
    /// `RVALID`.
    pub rvalid: bool,
    /// `RDATA` (32 bits).
    pub rdata: u32,
    /// `RRESP`.
    pub rresp: u8,
}

/// The name of an AXI response code.
pub fn resp_name(code: u8) -> &'static str {
    match code & 3 {
        0 => "OKAY",
        1 => "EXOKAY",
        2 => "SLVERR",
        _ => "DECERR",
    }
}

/// A time for a diagnosis: host cycle `cycle` at `period_ps` per cycle
/// ("1.20 us", "340 ns"), or the cycle number without a period.
pub(crate) fn at_time(cycle: u64, period_ps: u64) -> String {
    if period_ps == 0 {
        return format!("cycle {cycle}");
    }
    let ns = cycle as f64 * period_ps as f64 / 1000.0;
    if ns < 1000.0 { format!("{ns:.0} ns") } else { format!("{:.2} us", ns / 1000.0) }
}

/// Options of an [`Axi4LiteMaster`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Axi4LiteConfig {
    /// Bytes between registers (1, 2 or 4).
    pub stride: u32,
    /// Byte lane of the 32-bit data bus that carries the register (0..3).
    pub byte_lane: u32,
    /// Cycles from the start of a write to AWVALID.
    pub aw_delay: u32,
    /// Cycles from the start of a write to WVALID.
    pub w_delay: u32,
    /// Cycles from the start of a read to ARVALID.
    pub ar_delay: u32,
    /// Cycles after the request's last handshake before BREADY/RREADY.
    pub ready_delay: u32,
    /// Per-operation timeout, host cycles.
    pub timeout_cycles: u64,
    /// Host clock period in ps, for the timeout's diagnosis (0: cycles).
    pub period_ps: u64,
}

impl Default for Axi4LiteConfig {
    fn default() -> Self {
        Self { stride: 4, byte_lane: 0, aw_delay: 0, w_delay: 0, ar_delay: 0, ready_delay: 0, timeout_cycles: DEFAULT_TIMEOUT_CYCLES, period_ps: 0 }
    }
}

impl Axi4LiteConfig {
    /// The byte address of register `reg`.
    pub fn addr(&self, reg: u8) -> u32 {
        reg as u32 * self.stride
    }
}

#[derive(Debug, Clone, Copy)]
struct Active {
    op: PendingOp,
    /// Edges since the start.
    t: u32,
    /// Absolute cycle of each handshake.
    aw: Option<u64>,
    w: Option<u64>,
    ar: Option<u64>,
}

impl Active {
    fn request_done(&self) -> Option<u64> {
        if self.op.kind == OpKind::Write {
            Some(self.aw?.max(self.w?))
        } else {
            self.ar
        }
    }
}

/// AXI4-Lite master: one access at a time, 32-bit data.
pub struct Axi4LiteMaster {
    cfg: Axi4LiteConfig,
    q: OpQueue,
    in_reset: bool,
    active: Option<Active>,
    prev: AxiSlaveOut,
    out: AxiMasterOut,
    now: u64,
}

impl Axi4LiteMaster {
    /// A master with the given options.
    pub fn new(name: &str, cfg: Axi4LiteConfig) -> Self {
        log::info!(
            "{name}: AXI4-Lite master, 32-bit data, register n at byte n*{} in lane {}, delays AW {} W {} AR {} ready {}, timeout {} cycles",
            cfg.stride, cfg.byte_lane, cfg.aw_delay, cfg.w_delay, cfg.ar_delay, cfg.ready_delay, cfg.timeout_cycles
        );
        Self { cfg, q: OpQueue::new(name, cfg.timeout_cycles), in_reset: false, active: None, prev: AxiSlaveOut::default(), out: AxiMasterOut::default(), now: 0 }
    }

    /// The options this master was built with.
    pub fn config(&self) -> &Axi4LiteConfig {
        &self.cfg
    }

    fn drive(&mut self) {
        let c = self.cfg;
        let lane = 8 * c.byte_lane.min(3);
        self.out = match self.active {
            Some(a) if a.op.kind == OpKind::Write => AxiMasterOut {
                awvalid: a.aw.is_none() && a.t >= c.aw_delay,
                awaddr: c.addr(a.op.addr),
                wvalid: a.w.is_none() && a.t >= c.w_delay,
                wdata: (a.op.data as u32) << lane,
                wstrb: 1 << c.byte_lane.min(3),
                bready: a.request_done().is_some_and(|d| self.now >= d + c.ready_delay as u64),
                ..Default::default()
            },
            Some(a) => AxiMasterOut {
                arvalid: a.ar.is_none() && a.t >= c.ar_delay,
                araddr: c.addr(a.op.addr),
                rready: a.request_done().is_some_and(|d| self.now >= d + c.ready_delay as u64),
                ..Default::default()
            },
            None => AxiMasterOut::default(),
        };
    }

    /// Where an access that timed out stopped, in words.
    fn stuck_at(&self, a: &Active) -> String {
        let p = self.cfg.period_ps;
        let t = |c: u64| at_time(c, p);
        if a.op.kind == OpKind::Write {
            match (a.aw, a.w) {
                (None, None) => "neither AW nor W ever ready".into(),
                (Some(x), None) => format!("AW accepted at {}, W never ready", t(x)),
                (None, Some(x)) => format!("W accepted at {}, AW never ready", t(x)),
                (Some(x), Some(y)) => format!("AW accepted at {}, W at {}, BVALID never raised", t(x), t(y)),
            }
        } else {
            match a.ar {
                None => "AR never ready".into(),
                Some(x) => format!("AR accepted at {}, RVALID never raised", t(x)),
            }
        }
    }
}

impl HostMaster for Axi4LiteMaster {
    type Out = AxiMasterOut;
    type In = AxiSlaveOut;

    fn outputs(&self) -> AxiMasterOut {
        self.out
    }

    fn on_edge(&mut self, slave: &AxiSlaveOut) {
        let s = std::mem::replace(&mut self.prev, *slave);
        let o = self.out;
        self.now += 1;
        let now = self.now;
        let mut aborted = false;
        if let Some(mut a) = self.active.take() {
            a.op.cycles += 1;
            a.t += 1;
            let mut done = false;
            if a.op.kind == OpKind::Write {
                if o.awvalid && s.awready {
                    a.aw = Some(now);
                }
                if o.wvalid && s.wready {
                    a.w = Some(now);
                }
                if o.bready && s.bvalid {
                    done = true;
                    if s.bresp & 2 != 0 {
                        self.q.complete(a.op.handle, Err(BfmError::ErrorResponse { op: a.op.kind, addr: a.op.addr, response: resp_name(s.bresp) }));
                    } else {
                        self.q.finish(&a.op, a.op.data);
                    }
                }
            } else {
                if o.arvalid && s.arready {
                    a.ar = Some(now);
                }
                if o.rready && s.rvalid {
                    done = true;
                    if s.rresp & 2 != 0 {
                        self.q.complete(a.op.handle, Err(BfmError::ErrorResponse { op: a.op.kind, addr: a.op.addr, response: resp_name(s.rresp) }));
                    } else {
                        self.q.finish(&a.op, (s.rdata >> (8 * self.cfg.byte_lane.min(3))) as u8);
                    }
                }
            }
            if !done {
                if a.op.cycles >= a.op.timeout {
                    let at = self.stuck_at(&a);
                    log::warn!("{}: {} {} at 0x{:02X} stopped: {at}", self.q.name(), a.op.handle, a.op.kind, a.op.addr);
                    self.q.complete(a.op.handle, Err(BfmError::Stopped { op: a.op.kind, addr: a.op.addr, cycles: a.op.cycles, at }));
                    aborted = true;
                } else {
                    self.active = Some(a);
                }
            }
        }
        if self.active.is_none() && !aborted {
            self.active = self.q.next(self.in_reset).map(|op| Active { op, t: 0, aw: None, w: None, ar: None });
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
        self.q.drain_bound() + self.active.map_or(0, |a| a.op.timeout + 2)
    }
}

/// The AXI4-Lite slave logic of `rtl/can_axi4lite.v` in front of a
/// Wishbone slave (the golden model as DUT): the Wishbone request is
/// `AWVALID & WVALID` (a write) or `ARVALID` (a read), combinationally,
/// while no response is pending; `AWREADY`/`WREADY`/`ARREADY` are the
/// Wishbone ack; `BVALID`/`RVALID` (with the read byte) are registered
/// from it and held until `BREADY`/`RREADY`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Axi4LiteBridge {
    /// Register stride and byte lane.
    pub stride: u32,
    /// Byte lane.
    pub byte_lane: u32,
    /// An access is in progress: Some(true) a write, Some(false) a read.
    cur: Option<bool>,
    bvalid: bool,
    rvalid: bool,
    rdata: u8,
}

impl Axi4LiteBridge {
    /// A bridge for this register layout.
    pub fn new(stride: u32, byte_lane: u32) -> Self {
        Self { stride: stride.max(1), byte_lane: byte_lane.min(3), ..Default::default() }
    }

    fn select(&self, m: &AxiMasterOut) -> Option<bool> {
        let wr_ok = m.awvalid && m.wvalid && !self.bvalid;
        let rd_ok = m.arvalid && !self.rvalid;
        match self.cur {
            Some(w) => Some(w),
            None if wr_ok => Some(true),
            None if rd_ok => Some(false),
            None => None,
        }
    }

    /// The Wishbone wires for the master's pins (combinational).
    pub fn to_wishbone(&self, m: &AxiMasterOut) -> WbMasterOut {
        let lane = 8 * self.byte_lane;
        match self.select(m) {
            Some(true) => WbMasterOut { cyc: true, stb: true, we: true, adr: (m.awaddr / self.stride) as u8, dat: (m.wdata >> lane) as u8 },
            Some(false) => WbMasterOut { cyc: true, stb: true, we: false, adr: (m.araddr / self.stride) as u8, dat: 0 },
            None => WbMasterOut::default(),
        }
    }

    /// The AXI slave outputs given the Wishbone slave's (after an edge).
    pub fn to_axi(&self, m: &AxiMasterOut, s: &WbSlaveOut) -> AxiSlaveOut {
        let sel = self.select(m);
        AxiSlaveOut {
            awready: s.ack && sel == Some(true),
            wready: s.ack && sel == Some(true),
            bvalid: self.bvalid,
            bresp: 0,
            arready: s.ack && sel == Some(false),
            rvalid: self.rvalid,
            rdata: (self.rdata as u32) << (8 * self.byte_lane),
            rresp: 0,
        }
    }

    /// The bridge's registers at a rising edge: `m` and `s` are the wires
    /// during the cycle that ends (`s` the Wishbone slave's outputs then).
    pub fn clock(&mut self, m: &AxiMasterOut, s: &WbSlaveOut) {
        let sel = self.select(m);
        if self.bvalid && m.bready {
            self.bvalid = false;
        }
        if self.rvalid && m.rready {
            self.rvalid = false;
        }
        match sel {
            Some(w) if s.ack => {
                self.cur = None;
                if w {
                    self.bvalid = true;
                } else {
                    self.rvalid = true;
                    self.rdata = s.dat;
                }
            }
            Some(w) => self.cur = Some(w),
            None => {}
        }
    }
}

/// A 256-register AXI4-Lite RAM slave with registered outputs (a target
/// to test the master and monitor): AW and W are accepted each on its own
/// (one cycle of READY), the B response follows once both are in; AR gets
/// R one cycle later. `never_bvalid` plants a slave that takes a write and
/// never answers it.
pub struct Axi4LiteRam {
    cfg: Axi4LiteConfig,
    mem: [u8; 256],
    out: AxiSlaveOut,
    aw: Option<u32>,
    w: Option<u32>,
    /// Never raise BVALID (a hung slave).
    pub never_bvalid: bool,
}

impl Axi4LiteRam {
    /// A zero-filled RAM with this register layout.
    pub fn new(cfg: Axi4LiteConfig) -> Self {
        Self { cfg, mem: [0; 256], out: AxiSlaveOut::default(), aw: None, w: None, never_bvalid: false }
    }

    /// The memory.
    pub fn mem(&self) -> &[u8; 256] {
        &self.mem
    }
}

impl HostBusTarget<AxiMasterOut, AxiSlaveOut> for Axi4LiteRam {
    fn cycle(&mut self, m: &AxiMasterOut) -> AxiSlaveOut {
        let o = self.out;
        let mut n = AxiSlaveOut { bvalid: o.bvalid && !m.bready, rvalid: o.rvalid && !m.rready, rdata: o.rdata, ..Default::default() };
        if m.awvalid && o.awready {
            self.aw = Some(m.awaddr);
        }
        if m.wvalid && o.wready {
            self.w = Some(m.wdata);
        }
        if let (Some(a), Some(d)) = (self.aw, self.w)
            && !n.bvalid
        {
            self.mem[(a / self.cfg.stride) as usize & 0xFF] = (d >> (8 * self.cfg.byte_lane)) as u8;
            self.aw = None;
            self.w = None;
            n.bvalid = !self.never_bvalid;
        }
        if m.arvalid && o.arready {
            n.rvalid = true;
            n.rdata = (self.mem[(m.araddr / self.cfg.stride) as usize & 0xFF] as u32) << (8 * self.cfg.byte_lane);
        }
        n.awready = m.awvalid && !o.awready && self.aw.is_none();
        n.wready = m.wvalid && !o.wready && self.w.is_none();
        n.arready = m.arvalid && !o.arready && !n.rvalid;
        self.out = n;
        n
    }
}

#[derive(Debug, Clone, Copy, Default)]
struct Chan {
    /// Cycle VALID rose while READY was low (a transfer waiting).
    since: Option<u64>,
    reported: bool,
}

/// AXI4-Lite protocol monitor (AMBA AXI and ACE specification, A3.2 and
/// B1): on every channel VALID, once high, stays high until the handshake,
/// and the payload is stable while VALID waits; a B or R response only for
/// an accepted request, one per request; responses OKAY; no channel waits
/// more than `timeout` cycles.
pub struct Axi4LiteMonitor {
    name: String,
    timeout: u64,
    prev_s: AxiSlaveOut,
    prev_m: AxiMasterOut,
    /// The previous cycle ended without a handshake on the channel:
    /// (aw, w, b, ar, r).
    waiting: [Chan; 5],
    writes_open: i64,
    wdata_open: i64,
    reads_open: i64,
    /// BRESP, RDATA, RRESP on the wires last cycle.
    last_resp: (u8, u32, u8),
}

impl Axi4LiteMonitor {
    /// A monitor flagging a channel that waits more than `timeout` cycles.
    pub fn new(name: &str, timeout: u64) -> Self {
        log::info!("{name}: AXI4-Lite monitor: VALID held until READY, payload stable, one response per request, OKAY, handshake within {timeout} cycles");
        Self { name: name.to_owned(), timeout, prev_s: AxiSlaveOut::default(), prev_m: AxiMasterOut::default(), waiting: [Chan::default(); 5], writes_open: 0, wdata_open: 0, reads_open: 0, last_resp: (0, 0, 0) }
    }

    /// The monitor's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Check one cycle (see the crate docs for `m` and `s_after`).
    pub fn observe(&mut self, cycle: u64, m: &AxiMasterOut, s_after: &AxiSlaveOut) -> Vec<Violation> {
        let s = std::mem::replace(&mut self.prev_s, *s_after);
        let pm = std::mem::replace(&mut self.prev_m, *m);
        let mut v = Vec::new();
        let names = ["AW", "W", "B", "AR", "R"];
        let valid = [m.awvalid, m.wvalid, s.bvalid, m.arvalid, s.rvalid];
        let ready = [s.awready, s.wready, m.bready, s.arready, m.rready];
        let payload_same = [
            m.awaddr == pm.awaddr && m.awprot == pm.awprot,
            m.wdata == pm.wdata && m.wstrb == pm.wstrb,
            true,
            m.araddr == pm.araddr && m.arprot == pm.arprot,
            true,
        ];
        let timeout = self.timeout;
        let (b_waited, r_waited) = (self.waiting[2].since.is_some(), self.waiting[4].since.is_some());
        for i in 0..5 {
            let ch = &mut self.waiting[i];
            if let Some(since) = ch.since {
                // VALID was high without READY last cycle.
                if !valid[i] {
                    let who = if i == 2 || i == 4 { "slave" } else { "master" };
                    v.push(Violation { cycle, rule: Rule::ValidDroppedBeforeReady, message: format!("{}VALID fell before {}READY (raised at cycle {since}): the {who} withdrew a transfer", names[i], names[i]) });
                } else if !payload_same[i] {
                    v.push(Violation { cycle, rule: Rule::ChangedWhileValid, message: format!("the {} payload changed while {}VALID waited for {}READY", names[i], names[i], names[i]) });
                }
            }
            if valid[i] && !ready[i] {
                let since = *ch.since.get_or_insert(cycle);
                if cycle - since >= timeout && !ch.reported {
                    ch.reported = true;
                    v.push(Violation { cycle, rule: Rule::HandshakeStuck, message: format!("{}VALID high since cycle {since} without {}READY for {timeout} cycles", names[i], names[i]) });
                }
            } else {
                *ch = Chan::default();
            }
        }
        // The slave's payloads (B, R) stable while their VALID waits.
        let (bresp, rdata, rresp) = self.last_resp;
        if b_waited && s.bvalid && s.bresp != bresp {
            v.push(Violation { cycle, rule: Rule::ChangedWhileValid, message: "BRESP changed while BVALID waited for BREADY".into() });
        }
        if r_waited && s.rvalid && (s.rdata != rdata || s.rresp != rresp) {
            v.push(Violation { cycle, rule: Rule::ChangedWhileValid, message: "RDATA or RRESP changed while RVALID waited for RREADY".into() });
        }
        // Responses: one per accepted request, and OKAY.
        if s.bvalid && (self.writes_open <= 0 || self.wdata_open <= 0) {
            v.push(Violation { cycle, rule: Rule::ResponseWithoutRequest, message: "BVALID with no write whose AW and W were both accepted".into() });
        }
        if s.rvalid && self.reads_open <= 0 {
            v.push(Violation { cycle, rule: Rule::ResponseWithoutRequest, message: "RVALID with no read accepted on AR".into() });
        }
        if s.bvalid && m.bready {
            self.writes_open -= 1;
            self.wdata_open -= 1;
            if s.bresp != 0 {
                v.push(Violation { cycle, rule: Rule::ErrorResponse, message: format!("write answered {} (BRESP={})", resp_name(s.bresp), s.bresp) });
            }
        }
        if s.rvalid && m.rready {
            self.reads_open -= 1;
            if s.rresp != 0 {
                v.push(Violation { cycle, rule: Rule::ErrorResponse, message: format!("read answered {} (RRESP={})", resp_name(s.rresp), s.rresp) });
            }
        }
        // A request accepted now is answered in a later cycle at the earliest.
        if m.awvalid && s.awready {
            self.writes_open += 1;
        }
        if m.wvalid && s.wready {
            self.wdata_open += 1;
        }
        if m.arvalid && s.arready {
            self.reads_open += 1;
        }
        self.last_resp = (s.bresp, s.rdata, s.rresp);
        v
    }
}
