//! Wishbone classic master and RAM target.

use crate::op::{OpQueue, Pause, PendingOp, step_pause};
use crate::{
    BfmError, DEFAULT_TIMEOUT_CYCLES, HostBusTarget, HostMaster, OpHandle, OpKind, OpResult,
    WbMasterOut, WbSlaveOut,
};

/// One transfer of a Wishbone block cycle (see [`WishboneMaster::start_block`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlockAccess {
    /// A write (else a read).
    pub write: bool,
    /// Register address.
    pub addr: u8,
    /// Write data (ignored for a read).
    pub data: u8,
}

impl BlockAccess {
    /// A write transfer.
    pub fn write(addr: u8, data: u8) -> Self {
        Self { write: true, addr, data }
    }

    /// A read transfer.
    pub fn read(addr: u8) -> Self {
        Self { write: false, addr, data: 0 }
    }
}

/// Wishbone classic (non-pipelined) single-access master.
///
/// Holds `cyc`/`stb` from the edge an operation starts until the edge at
/// which it samples `ack` (or `err`); a `rty` ends the attempt, idles one
/// cycle and retries. Back-to-back operations keep `cyc`/`stb` high, as
/// classic cycles allow. The pause generator inserts idle cycles before an
/// operation starts, never inside one (nor inside a block cycle).
///
/// [`WishboneMaster::start_block`] queues transfers as one block cycle
/// (Wishbone B4 §3.3 BLOCK READ / WRITE, classic): `cyc` and `stb` stay high
/// from the first transfer to the ack of the last, and each next transfer's
/// `adr`/`we`/`dat` go on the wires at the edge that samples the previous
/// `ack`; a slave that keeps `ack` high then acknowledges that next transfer
/// too, which a slave must not do before it has done it.
pub struct WishboneMaster {
    q: OpQueue,
    pause: Option<Pause>,
    in_reset: bool,
    active: Option<PendingOp>,
    retry_gap: bool,
    prev: WbSlaveOut,
    out: WbMasterOut,
    /// Queued transfers that continue the block of the one before them.
    block_rest: Vec<OpHandle>,
}

impl WishboneMaster {
    /// A master with the default timeout and no pause generator.
    pub fn new(name: &str) -> Self {
        log::info!(
            "{name}: Wishbone classic master, adr 8 bits, dat 8 bits, granularity 8, \
             cyc/stb/we/ack used, err/rty honoured, timeout {DEFAULT_TIMEOUT_CYCLES} cycles"
        );
        Self {
            q: OpQueue::new(name, DEFAULT_TIMEOUT_CYCLES),
            pause: None,
            in_reset: false,
            active: None,
            retry_gap: false,
            prev: WbSlaveOut::default(),
            out: WbMasterOut::default(),
            block_rest: Vec::new(),
        }
    }

    /// Queue `accesses` as one block cycle; one handle per transfer, in
    /// order. If a transfer ends without an ack (timeout, `err`), the rest
    /// of the block completes with [`BfmError::BlockAbandoned`] and never
    /// reaches the wires (each transfer keeps its own timeout: a slave that
    /// stops acknowledging inside a block ends in a timeout, not a hang).
    pub fn start_block(&mut self, accesses: &[BlockAccess]) -> Vec<OpHandle> {
        let handles: Vec<OpHandle> = accesses
            .iter()
            .map(|a| {
                if a.write {
                    self.q.push(OpKind::Write, a.addr, a.data)
                } else {
                    self.q.push(OpKind::Read, a.addr, 0)
                }
            })
            .collect();
        log::debug!("{}: block cycle of {} transfers queued", self.q.name(), handles.len());
        self.block_rest.extend(handles.iter().skip(1));
        handles
    }

    /// The operation on the wires now, if any.
    pub fn active(&self) -> Option<OpHandle> {
        self.active.map(|op| op.handle)
    }

    /// Give up the transfers of the current block that have not started
    /// (a transfer before them failed, or the caller stops): each completes
    /// with [`BfmError::BlockAbandoned`]. A transfer on the wires runs on.
    pub fn abandon_block(&mut self) {
        let rest = std::mem::take(&mut self.block_rest);
        self.q.abandon(&rest);
    }

    /// Set the per-operation timeout for operations queued from now on.
    pub fn with_timeout(mut self, cycles: u64) -> Self {
        self.set_timeout(cycles);
        self
    }

    /// Install (or remove) the idle-inserting pause generator.
    pub fn set_pause(&mut self, pause: Option<Pause>) {
        log::info!(
            "{}: idle insertion {}",
            self.q.name(),
            if pause.is_some() { "on" } else { "off" }
        );
        self.pause = pause;
    }

    fn drive(&mut self) {
        self.out = match (&self.active, self.retry_gap) {
            (Some(op), false) => WbMasterOut {
                cyc: true,
                stb: true,
                we: op.kind == OpKind::Write,
                adr: op.addr,
                dat: if op.kind == OpKind::Write { op.data } else { 0 },
            },
            _ => WbMasterOut::default(),
        };
    }
}

impl HostMaster for WishboneMaster {
    type Out = WbMasterOut;
    type In = WbSlaveOut;

    fn outputs(&self) -> WbMasterOut {
        self.out
    }

    fn on_edge(&mut self, slave: &WbSlaveOut) {
        // What was on the wires before this edge.
        let sample = std::mem::replace(&mut self.prev, *slave);
        // Held in reset: start nothing (queued operations wait, and time out).
        let paused = step_pause(&mut self.pause) || self.in_reset;
        let mut aborted = false;
        // The transfer that ended at this edge was acked.
        let mut acked = false;
        if let Some(mut op) = self.active.take() {
            op.cycles += 1;
            if self.retry_gap {
                self.retry_gap = false;
                self.active = Some(op);
            } else if sample.ack {
                let data = if op.kind == OpKind::Read {
                    sample.dat
                } else {
                    op.data
                };
                self.q.finish(&op, data);
                acked = true;
            } else if sample.err {
                log::warn!(
                    "{}: {} {} at 0x{:02X} ended with err",
                    self.q.name(),
                    op.handle,
                    op.kind,
                    op.addr
                );
                self.q.complete(
                    op.handle,
                    Err(BfmError::BusError {
                        op: op.kind,
                        addr: op.addr,
                    }),
                );
                self.abandon_block();
            } else if sample.rty {
                log::debug!("{}: {} retry requested by slave", self.q.name(), op.handle);
                self.retry_gap = true;
                self.active = Some(op);
            } else {
                self.active = Some(op);
            }
            if let Some(op) = self.active
                && op.cycles >= op.timeout
            {
                self.active = None;
                self.retry_gap = false;
                self.q.time_out(&op);
                self.abandon_block();
                aborted = true;
            }
        }
        // The next transfer of a block follows its ack at once: cyc and stb
        // stay high (no pause inside a block cycle).
        let continues = acked && self.q.head().is_some_and(|h| self.block_rest.contains(&h));
        // After an abandoned cycle, idle one cycle so a late ack cannot
        // complete the next operation.
        if self.active.is_none() && !aborted {
            self.active = self.q.next(if continues { self.in_reset } else { paused });
            if let Some(op) = self.active {
                self.block_rest.retain(|h| *h != op.handle);
            }
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
        let active = self.active.take();
        self.q.flush(active);
        self.block_rest.clear();
        self.retry_gap = false;
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
        self.q.drain_bound() + self.active.map_or(0, |op| op.timeout + 2)
    }
}

/// How a [`WishboneRam`] acknowledges.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AckMode {
    /// Classic registered ack, `ack <= cyc & stb & !ack & !stall`: a one-cycle
    /// pulse per transfer; a master that keeps `stb` high after `ack` starts
    /// a new transfer (as `can_top` does: its synchronised `cs` re-triggers
    /// and its `wb_ack_o` is a one-cycle pulse).
    #[default]
    Pulse,
    /// The access happens once per `cyc & stb` assertion and `ack` then stays
    /// high until `stb` falls (a four-phase handshake): what a slave needs to
    /// be polled safely through GPIO. A registered `ack` then outlives `stb`
    /// by one cycle, which a Wishbone monitor reports.
    Level,
}

/// A 256-byte Wishbone classic RAM with a registered acknowledge (one wait
/// state, see [`AckMode`]). The optional backpressure generator delays
/// `ack` while it yields true.
pub struct WishboneRam {
    name: String,
    mode: AckMode,
    /// Level mode: the current strobe has been served.
    served: bool,
    mem: [u8; 256],
    backpressure: Option<Pause>,
    out: WbSlaveOut,
    accesses: u64,
}

impl WishboneRam {
    /// A zero-filled RAM.
    pub fn new(name: &str) -> Self {
        log::info!(
            "{name}: Wishbone RAM target, 256 x 8 bits, registered ack (1 wait state), no err/rty"
        );
        Self {
            name: name.to_owned(),
            mode: AckMode::Pulse,
            served: false,
            mem: [0; 256],
            backpressure: None,
            out: WbSlaveOut::default(),
            accesses: 0,
        }
    }

    /// Choose how the RAM acknowledges (default [`AckMode::Pulse`]).
    pub fn with_ack_mode(mut self, mode: AckMode) -> Self {
        log::info!("{}: ack mode {mode:?}", self.name);
        self.mode = mode;
        self
    }

    /// Install (or remove) the ack-stalling backpressure generator.
    pub fn set_backpressure(&mut self, pause: Option<Pause>) {
        log::info!(
            "{}: ack backpressure {}",
            self.name,
            if pause.is_some() { "on" } else { "off" }
        );
        self.backpressure = pause;
    }

    /// The memory contents.
    pub fn mem(&self) -> &[u8; 256] {
        &self.mem
    }

    /// The memory contents, writable (to preload).
    pub fn mem_mut(&mut self) -> &mut [u8; 256] {
        &mut self.mem
    }

    /// Transfers acknowledged so far (a master that holds `stb` across
    /// several acks is counted once per ack).
    pub fn accesses(&self) -> u64 {
        self.accesses
    }
}

impl HostBusTarget for WishboneRam {
    fn cycle(&mut self, m: &WbMasterOut) -> WbSlaveOut {
        let stall = step_pause(&mut self.backpressure);
        let mut next = WbSlaveOut {
            dat: self.out.dat,
            ..Default::default()
        };
        if self.mode == AckMode::Level {
            if !m.request() {
                self.served = false;
            } else if self.served {
                next.ack = true;
            } else if !stall {
                self.served = true;
                next.ack = true;
                self.accesses += 1;
                if m.we {
                    self.mem[m.adr as usize] = m.dat;
                } else {
                    next.dat = self.mem[m.adr as usize];
                }
            }
        } else if m.request() && !self.out.ack && !stall {
            if m.we {
                self.mem[m.adr as usize] = m.dat;
            } else {
                next.dat = self.mem[m.adr as usize];
            }
            next.ack = true;
            self.accesses += 1;
        }
        self.out = next;
        next
    }
}
