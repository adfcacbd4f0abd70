//! Operations, results, errors, pause generators and the queue every master
//! shares.

use std::collections::VecDeque;
use std::fmt;

/// Default per-operation timeout of the Wishbone and Avalon masters, in host
/// cycles. The opencores core acks after a few cycles of clock-domain
/// synchronisation; 1000 cycles is far beyond any legal wait.
pub const DEFAULT_TIMEOUT_CYCLES: u64 = 1000;

/// A pause generator, stepped once per host clock cycle; `true` inserts an
/// idle cycle (masters) or a backpressure cycle (targets). An exhausted
/// iterator means "no more pauses".
pub type Pause = Box<dyn Iterator<Item = bool> + Send>;

/// The 1-1-1-0 pattern of cocotbext-axi's `cycle_pause`: three paused cycles,
/// one free, forever.
pub fn cycle_pause() -> Pause {
    Box::new([true, true, true, false].into_iter().cycle())
}

/// Random idle/backpressure insertion: each cycle pauses with probability
/// `numerator / denominator`, from a seeded Xoshiro256++ (portable and
/// reproducible: the same seed gives the same pattern everywhere).
pub fn random_pause(seed: u64, numerator: u32, denominator: u32) -> Pause {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed);
    let (n, d) = (numerator.min(denominator.max(1)), denominator.max(1));
    Box::new(std::iter::repeat_with(move || rng.random_ratio(n, d)))
}

/// Direction of a register access.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum OpKind {
    /// Register read.
    Read,
    /// Register write.
    Write,
    /// PIO only: pulse the DUT reset line (`wb_rst_i`) through the control PIO.
    ResetPulse,
}

impl fmt::Display for OpKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            OpKind::Read => "read",
            OpKind::Write => "write",
            OpKind::ResetPulse => "reset pulse",
        })
    }
}

/// Ticket for a queued operation; redeem it with `HostMaster::poll`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct OpHandle(pub u64);

impl fmt::Display for OpHandle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "op#{}", self.0)
    }
}

/// A completed access: a plain record, like cocotbext-axi's `AxiLiteReadResp`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct OpResult {
    /// Read or write.
    pub kind: OpKind,
    /// Register address.
    pub addr: u8,
    /// Data read, or data written.
    pub data: u8,
    /// Host clock cycles from the cycle the operation reached the head of the
    /// queue (with the master free) to the edge at which it completed,
    /// inclusive. Idle cycles inserted by the master's pause generator count.
    pub cycles: u64,
}

/// Why an operation did not complete normally.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BfmError {
    /// The target never ended the transfer.
    #[error("{op} at 0x{addr:02X} timed out after {cycles} host cycles without an acknowledge")]
    Timeout {
        /// Read or write.
        op: OpKind,
        /// Register address.
        addr: u8,
        /// Cycles waited.
        cycles: u64,
    },
    /// The target stopped answering part-way through a multi-phase
    /// transfer (AXI4-Lite, APB): `at` says where.
    #[error("{op} at 0x{addr:02X} timed out after {cycles} host cycles: {at}")]
    Stopped {
        /// Read or write.
        op: OpKind,
        /// Register address.
        addr: u8,
        /// Cycles waited.
        cycles: u64,
        /// Where it stopped ("AW accepted at 1.20 us, W never ready").
        at: String,
    },
    /// The target answered with an error response (AXI SLVERR/DECERR,
    /// APB PSLVERR).
    #[error("{op} at 0x{addr:02X} answered {response}")]
    ErrorResponse {
        /// Read or write.
        op: OpKind,
        /// Register address.
        addr: u8,
        /// The response's name.
        response: &'static str,
    },
    /// The master was reset while the operation was queued or in flight.
    #[error("{op} at 0x{addr:02X} flushed by a master reset")]
    Flushed {
        /// Read or write.
        op: OpKind,
        /// Register address.
        addr: u8,
    },
    /// The slave ended the transfer with `err`.
    #[error("{op} at 0x{addr:02X} ended with a bus error (err)")]
    BusError {
        /// Read or write.
        op: OpKind,
        /// Register address.
        addr: u8,
    },
    /// The handle is not queued, not in flight and has no stored result
    /// (already redeemed, or from another master).
    #[error("{0} is unknown to this master (already polled, or from another master)")]
    UnknownHandle(OpHandle),
    /// A blocking helper stepped longer than every queued timeout allows.
    #[error("blocking access gave up after {cycles} host cycles")]
    Stalled {
        /// Cycles stepped.
        cycles: u64,
    },
    /// An earlier transfer of the same Wishbone block cycle did not end with
    /// an ack (timeout or err): the master gave up the block, and this
    /// transfer was never put on the wires.
    #[error("{op} at 0x{addr:02X} not done: an earlier transfer of its block cycle failed")]
    BlockAbandoned {
        /// Read or write.
        op: OpKind,
        /// Register address.
        addr: u8,
    },
}

/// One queued operation.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PendingOp {
    pub handle: OpHandle,
    pub kind: OpKind,
    pub addr: u8,
    pub data: u8,
    pub timeout: u64,
    /// Operation-specific argument (the PIO reset pulse's hold time).
    pub extra: u64,
    /// Cycles spent so far (waiting at the head of the queue, then in flight).
    pub cycles: u64,
}

/// The queue of operations and the store of finished results shared by all
/// masters.
pub(crate) struct OpQueue {
    name: String,
    next_id: u64,
    pub timeout: u64,
    pending: VecDeque<PendingOp>,
    // A handful of entries at most: a Vec beats hashing on the per-cycle path.
    in_flight: Vec<OpHandle>,
    done: Vec<(OpHandle, Result<OpResult, BfmError>)>,
}

impl OpQueue {
    pub fn new(name: &str, timeout: u64) -> Self {
        Self {
            name: name.to_owned(),
            next_id: 0,
            timeout,
            pending: VecDeque::new(),
            in_flight: Vec::new(),
            done: Vec::new(),
        }
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    pub fn push(&mut self, kind: OpKind, addr: u8, data: u8) -> OpHandle {
        self.push_with(kind, addr, data, 0)
    }

    pub fn push_with(&mut self, kind: OpKind, addr: u8, data: u8, extra: u64) -> OpHandle {
        let handle = OpHandle(self.next_id);
        self.next_id += 1;
        self.pending.push_back(PendingOp {
            handle,
            kind,
            addr,
            data,
            timeout: self.timeout,
            extra,
            cycles: 0,
        });
        self.in_flight.push(handle);
        log::trace!(
            "{}: queued {handle} {kind} 0x{addr:02X} data 0x{data:02X}",
            self.name
        );
        handle
    }

    /// Take the head if the master may start it (`!paused`); otherwise count a
    /// waiting cycle against the head's timeout.
    pub fn next(&mut self, paused: bool) -> Option<PendingOp> {
        if !paused {
            return self.pending.pop_front();
        }
        let head = self.pending.front_mut()?;
        head.cycles += 1;
        if head.cycles >= head.timeout {
            let op = self.pending.pop_front().expect("head exists");
            self.time_out(&op);
        }
        None
    }

    pub fn time_out(&mut self, op: &PendingOp) {
        log::warn!(
            "{}: {} {} at 0x{:02X} timed out after {} cycles",
            self.name,
            op.handle,
            op.kind,
            op.addr,
            op.cycles
        );
        self.complete(
            op.handle,
            Err(BfmError::Timeout {
                op: op.kind,
                addr: op.addr,
                cycles: op.cycles,
            }),
        );
    }

    pub fn finish(&mut self, op: &PendingOp, data: u8) {
        log::debug!(
            "{}: {} {} 0x{:02X} data 0x{:02X} done in {} cycles",
            self.name,
            op.handle,
            op.kind,
            op.addr,
            data,
            op.cycles
        );
        self.complete(
            op.handle,
            Ok(OpResult {
                kind: op.kind,
                addr: op.addr,
                data,
                cycles: op.cycles,
            }),
        );
    }

    pub fn complete(&mut self, handle: OpHandle, result: Result<OpResult, BfmError>) {
        self.in_flight.retain(|h| *h != handle);
        self.done.retain(|(h, _)| *h != handle);
        self.done.push((handle, result));
    }

    pub fn poll(&mut self, handle: OpHandle) -> Option<Result<OpResult, BfmError>> {
        if let Some(i) = self.done.iter().position(|(h, _)| *h == handle) {
            return Some(self.done.swap_remove(i).1);
        }
        if self.in_flight.contains(&handle) {
            return None;
        }
        Some(Err(BfmError::UnknownHandle(handle)))
    }

    /// Flush the in-flight operation (if any) and every queued one: log each
    /// as a warning and complete it with [`BfmError::Flushed`].
    pub fn flush(&mut self, active: Option<PendingOp>) {
        let ops: Vec<PendingOp> = active.into_iter().chain(self.pending.drain(..)).collect();
        for op in ops {
            log::warn!(
                "{}: reset flushed {} {} at 0x{:02X} (data 0x{:02X})",
                self.name,
                op.handle,
                op.kind,
                op.addr,
                op.data
            );
            self.complete(
                op.handle,
                Err(BfmError::Flushed {
                    op: op.kind,
                    addr: op.addr,
                }),
            );
        }
    }

    /// Remove the queued (not yet started) operations `handles` and complete
    /// each with [`BfmError::BlockAbandoned`].
    pub fn abandon(&mut self, handles: &[OpHandle]) {
        let (gone, kept): (Vec<PendingOp>, Vec<PendingOp>) =
            self.pending.drain(..).partition(|p| handles.contains(&p.handle));
        self.pending = kept.into();
        for op in gone {
            log::warn!(
                "{}: {} {} at 0x{:02X} abandoned with its block cycle",
                self.name,
                op.handle,
                op.kind,
                op.addr
            );
            self.complete(
                op.handle,
                Err(BfmError::BlockAbandoned {
                    op: op.kind,
                    addr: op.addr,
                }),
            );
        }
    }

    /// The handle of the operation at the head of the queue.
    pub fn head(&self) -> Option<OpHandle> {
        self.pending.front().map(|p| p.handle)
    }

    /// Operations queued or in flight.
    pub fn in_flight(&self) -> usize {
        self.in_flight.len()
    }

    /// Sum of the timeouts of everything in flight: an upper bound on how long
    /// the queue can take to drain.
    pub fn drain_bound(&self) -> u64 {
        self.pending.iter().map(|p| p.timeout + 2).sum::<u64>()
    }
}

/// Step a pause generator once; an absent or exhausted one never pauses.
pub(crate) fn step_pause(p: &mut Option<Pause>) -> bool {
    p.as_mut().and_then(|it| it.next()).unwrap_or(false)
}

/// Follows a master's reset pin: logs each change and returns true when the
/// pin rises, the moment the master flushes its operations.
pub(crate) fn reset_pin_edge(name: &str, in_reset: &mut bool, asserted: bool) -> bool {
    if asserted == *in_reset {
        return false;
    }
    log::info!(
        "{name}: reset {}",
        if asserted { "asserted" } else { "released" }
    );
    *in_reset = asserted;
    asserted
}
