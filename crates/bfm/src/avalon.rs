//! Avalon-MM master (slave side as a Nios II data master and the interconnect
//! drive it) and RAM target.

use std::collections::VecDeque;

use crate::op::{OpQueue, Pause, PendingOp, step_pause};
use crate::{
    AvMasterOut, AvSlaveOut, BfmError, DEFAULT_TIMEOUT_CYCLES, HostBusTarget, HostMaster, OpHandle,
    OpKind, OpResult,
};

/// How a transfer's end is decided, as a Platform Designer component
/// declares it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AvalonTiming {
    /// No `waitrequest`: the request is held `read + 1` (reads) or
    /// `write + 1` (writes) cycles and `readdata` is sampled at the end.
    /// A slave with registered `readdata` needs `read >= 1`.
    FixedWaitStates {
        /// Read wait states.
        read: u32,
        /// Write wait states.
        write: u32,
    },
    /// The request is held until `waitrequest` is sampled low; `readdata` is
    /// sampled with it.
    Waitrequest,
    /// `waitrequest` ends the command phase; read data comes later with
    /// `readdatavalid` (pipelined read, variable latency, one outstanding).
    Pipelined,
}

/// Options of an [`AvalonMaster`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AvalonMasterConfig {
    /// Transfer timing.
    pub timing: AvalonTiming,
    /// Drive `begintransfer` in the first cycle of each transfer.
    pub begintransfer: bool,
    /// Per-operation timeout, in host cycles.
    pub timeout_cycles: u64,
}

impl Default for AvalonMasterConfig {
    fn default() -> Self {
        Self {
            timing: AvalonTiming::Waitrequest,
            begintransfer: false,
            timeout_cycles: DEFAULT_TIMEOUT_CYCLES,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Request on the pins; `driven` cycles so far.
    Command { driven: u32 },
    /// Pipelined read accepted, waiting for `readdatavalid`.
    Data,
}

/// Avalon-MM single-access master: one transfer at a time, byteenable 0x1.
pub struct AvalonMaster {
    cfg: AvalonMasterConfig,
    q: OpQueue,
    pause: Option<Pause>,
    in_reset: bool,
    active: Option<(PendingOp, Phase)>,
    prev: AvSlaveOut,
    out: AvMasterOut,
}

impl AvalonMaster {
    /// A master with the given options and no pause generator.
    pub fn new(name: &str, cfg: AvalonMasterConfig) -> Self {
        let timing = match cfg.timing {
            AvalonTiming::FixedWaitStates { read, write } => {
                format!(
                    "fixed wait states (read {read}, write {write}), no waitrequest, no readdatavalid"
                )
            }
            AvalonTiming::Waitrequest => "waitrequest, no readdatavalid".to_owned(),
            AvalonTiming::Pipelined => "waitrequest + readdatavalid (pipelined reads)".to_owned(),
        };
        log::info!(
            "{name}: Avalon-MM master, address 8 bits, data 8 bits, byteenable 1 bit, {timing}, \
             begintransfer {}, chipselect used, timeout {} cycles",
            if cfg.begintransfer {
                "driven"
            } else {
                "absent"
            },
            cfg.timeout_cycles
        );
        Self {
            cfg,
            q: OpQueue::new(name, cfg.timeout_cycles),
            pause: None,
            in_reset: false,
            active: None,
            prev: AvSlaveOut::default(),
            out: AvMasterOut::default(),
        }
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

    /// The options this master was built with.
    pub fn config(&self) -> &AvalonMasterConfig {
        &self.cfg
    }

    fn drive(&mut self) {
        self.out = match self.active {
            Some((op, Phase::Command { driven })) => AvMasterOut {
                address: op.addr,
                chipselect: true,
                read: op.kind == OpKind::Read,
                write: op.kind == OpKind::Write,
                writedata: if op.kind == OpKind::Write { op.data } else { 0 },
                begintransfer: self.cfg.begintransfer && driven == 0,
                byteenable: 0x1,
            },
            _ => AvMasterOut::default(),
        };
    }
}

impl HostMaster for AvalonMaster {
    type Out = AvMasterOut;
    type In = AvSlaveOut;

    fn outputs(&self) -> AvMasterOut {
        self.out
    }

    fn on_edge(&mut self, slave: &AvSlaveOut) {
        let sample = std::mem::replace(&mut self.prev, *slave);
        // Held in reset: start nothing (queued operations wait, and time out).
        let paused = step_pause(&mut self.pause) || self.in_reset;
        let mut aborted = false;
        if let Some((mut op, phase)) = self.active.take() {
            op.cycles += 1;
            let mut next = None;
            match phase {
                Phase::Command { driven } => {
                    let driven = driven + 1;
                    let accepted = match self.cfg.timing {
                        AvalonTiming::FixedWaitStates { read, write } => {
                            let wait = if op.kind == OpKind::Read { read } else { write };
                            driven > wait
                        }
                        AvalonTiming::Waitrequest | AvalonTiming::Pipelined => !sample.waitrequest,
                    };
                    if !accepted {
                        next = Some((op, Phase::Command { driven }));
                    } else if op.kind == OpKind::Read && self.cfg.timing == AvalonTiming::Pipelined
                    {
                        next = Some((op, Phase::Data));
                    } else {
                        let data = if op.kind == OpKind::Read {
                            sample.readdata
                        } else {
                            op.data
                        };
                        self.q.finish(&op, data);
                    }
                }
                Phase::Data => {
                    if sample.readdatavalid {
                        self.q.finish(&op, sample.readdata);
                    } else {
                        next = Some((op, Phase::Data));
                    }
                }
            }
            if let Some((op, _)) = next
                && op.cycles >= op.timeout
            {
                self.q.time_out(&op);
                next = None;
                aborted = true;
            }
            self.active = next;
        }
        // After an abandoned transfer, idle one cycle before the next.
        if self.active.is_none() && !aborted {
            self.active = self
                .q
                .next(paused)
                .map(|op| (op, Phase::Command { driven: 0 }));
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
        let active = self.active.take().map(|(op, _)| op);
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
        self.q.drain_bound() + self.active.map_or(0, |(op, _)| op.timeout + 2)
    }
}

/// A 256-byte Avalon-MM RAM slave with registered outputs.
///
/// - [`AvalonTiming::FixedWaitStates`]: `readdata <= mem[address]` every
///   cycle a read is requested, writes land every cycle a write is requested
///   (idempotent); the wait-state numbers are the master's business.
/// - [`AvalonTiming::Waitrequest`]: `waitrequest` is high by default and
///   drops for one cycle when a request is accepted, with `readdata`.
/// - [`AvalonTiming::Pipelined`]: as above, and read data returns at least one
///   cycle later with `readdatavalid`.
///
/// The backpressure generator holds `waitrequest` (and delays
/// `readdatavalid`) while it yields true; it has no effect with fixed wait
/// states, where the slave cannot stall.
pub struct AvalonRam {
    name: String,
    timing: AvalonTiming,
    mem: [u8; 256],
    backpressure: Option<Pause>,
    out: AvSlaveOut,
    read_queue: VecDeque<u8>,
    accesses: u64,
}

impl AvalonRam {
    /// A zero-filled RAM with the given timing.
    pub fn new(name: &str, timing: AvalonTiming) -> Self {
        log::info!("{name}: Avalon-MM RAM target, 256 x 8 bits, {timing:?}, registered outputs");
        Self {
            name: name.to_owned(),
            timing,
            mem: [0; 256],
            backpressure: None,
            out: AvSlaveOut {
                waitrequest: !matches!(timing, AvalonTiming::FixedWaitStates { .. }),
                ..Default::default()
            },
            read_queue: VecDeque::new(),
            accesses: 0,
        }
    }

    /// Install (or remove) the waitrequest/readdatavalid backpressure generator.
    pub fn set_backpressure(&mut self, pause: Option<Pause>) {
        log::info!(
            "{}: backpressure {}",
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

    /// Requests accepted so far (waitrequest modes only).
    pub fn accesses(&self) -> u64 {
        self.accesses
    }
}

impl HostBusTarget<AvMasterOut, AvSlaveOut> for AvalonRam {
    fn cycle(&mut self, m: &AvMasterOut) -> AvSlaveOut {
        let stall = step_pause(&mut self.backpressure);
        let mut next = AvSlaveOut {
            readdata: self.out.readdata,
            ..Default::default()
        };
        let a = m.address as usize;
        match self.timing {
            AvalonTiming::FixedWaitStates { .. } => {
                if m.chipselect && m.write {
                    self.mem[a] = m.writedata;
                }
                if m.chipselect && m.read {
                    next.readdata = self.mem[a];
                }
            }
            AvalonTiming::Waitrequest | AvalonTiming::Pipelined => {
                // Data of reads accepted at earlier edges first.
                if !stall && let Some(d) = self.read_queue.pop_front() {
                    next.readdata = d;
                    next.readdatavalid = true;
                }
                // A request on the wires while waitrequest was low has just
                // been accepted at this edge: do not take it twice.
                if self.out.waitrequest && m.request() && !stall {
                    self.accesses += 1;
                    if m.write {
                        self.mem[a] = m.writedata;
                    } else if self.timing == AvalonTiming::Pipelined {
                        self.read_queue.push_back(self.mem[a]);
                    } else {
                        next.readdata = self.mem[a];
                    }
                    next.waitrequest = false;
                } else {
                    next.waitrequest = true;
                }
            }
        }
        self.out = next;
        next
    }
}
