//! PIO master: a Nios II bit-banging the Wishbone pins through GPIO
//! registers, as in the DE2 thesis (seed 000, annexe 4, `write_reg` and
//! `read_reg`).

use std::collections::VecDeque;

use crate::op::{OpQueue, Pause, PendingOp, step_pause};
use crate::{BfmError, HostMaster, OpHandle, OpKind, OpResult, WbMasterOut, WbSlaveOut};

/// Control PIO bit 0: `wb_we_i`.
pub const CTL_WE: u8 = 0x01;
/// Control PIO bit 1: `wb_stb_i`.
pub const CTL_STB: u8 = 0x02;
/// Control PIO bit 2: `wb_cyc_i`.
pub const CTL_CYC: u8 = 0x04;
/// Control PIO bit 3: `wb_rst_i`.
pub const CTL_RST: u8 = 0x08;

/// Default per-operation timeout of the PIO master: a polled access costs
/// tens of cycles, so allow 100 times the Wishbone default.
pub const DEFAULT_PIO_TIMEOUT_CYCLES: u64 = 100_000;

/// Host-clock cost of one GPIO access by the CPU.
///
/// Defaults model a Nios II/f running on the host clock (`wb_clk_i`, 50 MHz
/// on the DE2) with uncached `IOWR`/`IORD` (`stwio`/`ldwio`) to a PIO core.
/// These are estimates from the Nios II Processor Reference Guide table
/// "Instruction Execution Performance for Nios II/f Core" (loads and stores
/// stall until their Avalon-MM transfer completes; a load result is late by
/// two cycles; a correctly predicted taken branch costs 2), not a hardware
/// measurement:
/// - `IOWR` = 3: one issue cycle + a 2-cycle Avalon write (PIO `s1` with
///   no wait state behind one registered interconnect stage);
/// - `IORD` = 5: one issue cycle + a 2-cycle Avalon read (registered PIO
///   `readdata`) + 2 late-result cycles before the `while (IORD(..) == 0)`
///   compare can use it; the loop's taken branch overlaps the next issue.
///
/// It also says how the program sees `ack` ([`PioAckInput`]): the GPIO
/// cost of an access depends on it (one more `IOWR` with edge capture).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PioTiming {
    /// Host cycles per GPIO write (`IOWR`).
    pub iowr_cycles: u32,
    /// Host cycles per GPIO read (`IORD`), polling loop included.
    pub iord_cycles: u32,
    /// How the `ack` input PIO is read: the thesis's level poll (default).
    pub ack_input: PioAckInput,
}

impl Default for PioTiming {
    fn default() -> Self {
        Self {
            iowr_cycles: 3,
            iord_cycles: 5,
            ack_input: PioAckInput::Level,
        }
    }
}

/// How the program sees the core's `ack` through its input PIO.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PioAckInput {
    /// The thesis's program: `while (IORD(BASEacknowledge, 0) == 0)` reads
    /// the PIO's data register, one sample of the wire per loop. A core
    /// whose ack is a one-clock pulse (classic Wishbone, the opencores
    /// `can_top`) is seen only when a sample lands on the pulse; the
    /// strobe stays up meanwhile and such a core performs the access again.
    #[default]
    Level,
    /// The ack PIO built with its edge capture register (Intel/Altera PIO
    /// core, "synchronously capture: rising edge"; input registered twice,
    /// the capture bit set at the clock after the rising edge is seen, and
    /// cleared by a write to the `edgecapture` register). The program
    /// clears the capture (`IOWR_ALTERA_AVALON_PIO_EDGE_CAP`) before it
    /// raises cyc/stb and polls the capture register instead of the data
    /// register: a one-clock ack pulse is never missed. A read drops
    /// cyc/stb before `IORD(BASEdata_in)`: the program relies on the core
    /// holding `wb_dat_o` from its ack to its next read (the opencores
    /// core's `data_out`, our `can_wb_cdc`, the model DUT do; a core that
    /// does not shows as a read divergence, not as a pass).
    EdgeCapture,
}

/// The GPIO output registers of the thesis wiring.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum PioReg {
    /// `BASEaddress`: drives `wb_adr_i`.
    Address,
    /// `BASEdata_out`: drives `wb_dat_i`.
    DataOut,
    /// `BASEcyc_stb_we_rst`: drives `wb_we_i`, `wb_stb_i`, `wb_cyc_i`, `wb_rst_i`.
    Control,
}

/// One step of the C driver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Step {
    /// `IOWR(reg, 0, value)`.
    Iowr(PioReg, u8),
    /// One iteration of `while (IORD(BASEacknowledge, 0) == 0) {}` (or of
    /// `IORD_ALTERA_AVALON_PIO_EDGE_CAP` with [`PioAckInput::EdgeCapture`]).
    PollAck,
    /// `IOWR_ALTERA_AVALON_PIO_EDGE_CAP(BASEacknowledge, 1)`: clears the
    /// ack's edge capture bit.
    ClearAckCapture,
    /// `donnee = IORD(BASEdata_in, 0)`.
    ReadData,
    /// A busy loop of this many host cycles (the reset pulse's delay).
    Hold(u64),
}

struct Active {
    op: PendingOp,
    steps: VecDeque<Step>,
    /// Cycles spent on the current step.
    elapsed: u64,
    data: u8,
}

/// A Nios II driving the Wishbone pins through PIO registers: address PIO,
/// data-out PIO, control PIO (`we` = bit 0, `stb` = bit 1, `cyc` = bit 2,
/// `rst` = bit 3), with `ack` and `wb_dat_o` read back through input PIOs.
///
/// - write = `IOWR adr; IOWR data; IOWR ctl=0x01; IOWR ctl=0x07;
///   poll IORD ack until 1; IOWR ctl=0x00`;
/// - read = `IOWR adr; IOWR ctl=0x00; IOWR ctl=0x06; poll IORD ack until 1;
///   IORD data; IOWR ctl=0x00`.
///
/// A GPIO write changes the pins at the edge that ends it; a GPIO read
/// samples the wires at the edge that ends it. The pause generator makes
/// the CPU do something else for a cycle before a GPIO access starts. Where
/// the C code polls forever, the model times out and drops the control
/// word to 0 at once.
pub struct PioMaster {
    timing: PioTiming,
    q: OpQueue,
    pause: Option<Pause>,
    in_reset: bool,
    active: Option<Active>,
    prev: WbSlaveOut,
    adr: u8,
    dat: u8,
    ctl: u8,
    /// Edge capture of the ack input: its two input registers and the
    /// capture bit (used with [`PioAckInput::EdgeCapture`] only).
    ack_d1: bool,
    ack_d2: bool,
    ack_captured: bool,
}

impl PioMaster {
    /// A PIO master with the given GPIO access costs.
    pub fn new(name: &str, timing: PioTiming) -> Self {
        log::info!(
            "{name}: PIO master (Nios II bit-banging Wishbone), address PIO 8 bits, data-out PIO 8 bits, \
             control PIO we=bit0 stb=bit1 cyc=bit2 rst=bit3, inputs ack + data-in 8 bits, \
             IOWR {} cycles, IORD {} cycles, ack {}, timeout {DEFAULT_PIO_TIMEOUT_CYCLES} cycles",
            timing.iowr_cycles,
            timing.iord_cycles,
            match timing.ack_input {
                PioAckInput::Level => "polled as a level (the thesis's program)",
                PioAckInput::EdgeCapture => "through the PIO's edge capture register",
            }
        );
        Self {
            timing,
            q: OpQueue::new(name, DEFAULT_PIO_TIMEOUT_CYCLES),
            pause: None,
            in_reset: false,
            active: None,
            prev: WbSlaveOut::default(),
            adr: 0,
            dat: 0,
            ctl: 0,
            ack_d1: false,
            ack_d2: false,
            ack_captured: false,
        }
    }

    /// Install (or remove) the pause generator (CPU busy elsewhere).
    pub fn set_pause(&mut self, pause: Option<Pause>) {
        log::info!(
            "{}: idle insertion {}",
            self.q.name(),
            if pause.is_some() { "on" } else { "off" }
        );
        self.pause = pause;
    }

    /// Queue the thesis's `init_can` reset pulse: `IOWR ctl=0x08`, busy-wait
    /// `hold_cycles`, `IOWR ctl=0x00`.
    pub fn start_dut_reset(&mut self, hold_cycles: u64) -> OpHandle {
        self.q.push_with(OpKind::ResetPulse, 0, 0, hold_cycles)
    }

    /// The control PIO's current value.
    pub fn ctl(&self) -> u8 {
        self.ctl
    }

    /// `wb_rst_i` as driven by control bit 3.
    pub fn rst(&self) -> bool {
        self.ctl & CTL_RST != 0
    }

    fn steps_for(&self, op: &PendingOp) -> VecDeque<Step> {
        use PioReg::*;
        use Step::*;
        let mut steps: VecDeque<Step> = match op.kind {
            OpKind::Write => [
                Iowr(Address, op.addr),
                Iowr(DataOut, op.data),
                Iowr(Control, CTL_WE),
                Iowr(Control, CTL_WE | CTL_STB | CTL_CYC),
                PollAck,
                Iowr(Control, 0),
            ]
            .into(),
            OpKind::Read => [
                Iowr(Address, op.addr),
                Iowr(Control, 0),
                Iowr(Control, CTL_STB | CTL_CYC),
                PollAck,
                ReadData,
                Iowr(Control, 0),
            ]
            .into(),
            OpKind::ResetPulse => [Iowr(Control, CTL_RST), Hold(op.extra), Iowr(Control, 0)].into(),
        };
        // Edge capture: clear the bit just before the strobe goes up, so
        // that only this access's ack can set it; and drop the strobe as
        // soon as the ack is seen, before reading the data (the thesis's
        // order holds cyc/stb for one more IORD: with the capture's two
        // clocks of latency that reaches the end of a handshake core's
        // hold-off, and the core performs the read again, its late ack
        // then landing in the next access's capture).
        if self.timing.ack_input == PioAckInput::EdgeCapture
            && let Some(i) = steps.iter().position(|s| *s == PollAck)
        {
            steps.insert(i - 1, ClearAckCapture);
            if let Some(r) = steps.iter().position(|s| *s == ReadData) {
                steps.remove(r);
                steps.push_back(ReadData);
            }
        }
        steps
    }

    fn cost(&self, step: Step) -> u64 {
        match step {
            Step::Iowr(..) | Step::ClearAckCapture => self.timing.iowr_cycles.max(1) as u64,
            Step::PollAck | Step::ReadData => self.timing.iord_cycles.max(1) as u64,
            Step::Hold(n) => n.max(1),
        }
    }
}

impl HostMaster for PioMaster {
    type Out = WbMasterOut;
    type In = WbSlaveOut;

    fn outputs(&self) -> WbMasterOut {
        WbMasterOut {
            cyc: self.ctl & CTL_CYC != 0,
            stb: self.ctl & CTL_STB != 0,
            we: self.ctl & CTL_WE != 0,
            adr: self.adr,
            dat: self.dat,
        }
    }

    fn on_edge(&mut self, slave: &WbSlaveOut) {
        let sample = std::mem::replace(&mut self.prev, *slave);
        // The ack PIO's registers at this edge: what a read ending here
        // returns is the capture bit before the edge.
        let captured_before = self.ack_captured;
        self.ack_captured |= self.ack_d1 && !self.ack_d2;
        self.ack_d2 = self.ack_d1;
        self.ack_d1 = sample.ack;
        let ack_read = match self.timing.ack_input {
            PioAckInput::Level => sample.ack,
            PioAckInput::EdgeCapture => captured_before,
        };
        // Held in reset: start nothing (queued operations wait, and time out).
        let paused = step_pause(&mut self.pause) || self.in_reset;
        let mut aborted = false;
        if let Some(mut a) = self.active.take() {
            a.op.cycles += 1;
            // A pause only delays the start of a GPIO access.
            if !(a.elapsed == 0 && paused) {
                a.elapsed += 1;
                let step = *a.steps.front().expect("active op has steps");
                if a.elapsed >= self.cost(step) {
                    a.elapsed = 0;
                    match step {
                        Step::Iowr(PioReg::Address, v) => self.adr = v,
                        Step::Iowr(PioReg::DataOut, v) => self.dat = v,
                        Step::Iowr(PioReg::Control, v) => self.ctl = v,
                        Step::PollAck => {}
                        // The write takes priority over an edge seen at the same clock.
                        Step::ClearAckCapture => self.ack_captured = false,
                        Step::ReadData => a.data = sample.dat,
                        Step::Hold(_) => {}
                    }
                    // The poll loop repeats until it reads ack = 1.
                    if step != Step::PollAck || ack_read {
                        a.steps.pop_front();
                    }
                }
            }
            if a.steps.is_empty() {
                self.q.finish(&a.op, a.data);
            } else if a.op.cycles >= a.op.timeout {
                self.ctl = 0;
                self.q.time_out(&a.op);
                aborted = true;
            } else {
                self.active = Some(a);
            }
        }
        if self.active.is_none()
            && !aborted
            && let Some(op) = self.q.next(paused)
        {
            let steps = self.steps_for(&op);
            let data = if op.kind == OpKind::Write { op.data } else { 0 };
            self.active = Some(Active {
                op,
                steps,
                elapsed: 0,
                data,
            });
        }
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

    /// Flush the queue and clear the control PIO (a CPU reset clears the
    /// PIO output registers to their reset value, 0).
    fn reset(&mut self) {
        log::info!("{}: reset", self.q.name());
        let active = self.active.take().map(|a| a.op);
        self.q.flush(active);
        self.adr = 0;
        self.dat = 0;
        self.ctl = 0;
        self.ack_captured = false;
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
        self.q.drain_bound() + self.active.as_ref().map_or(0, |a| a.op.timeout + 2)
    }
}
