//! The co-simulation of our RTL (`can_top`, Verilated into the `cosim`
//! crate) with the Wishbone BFM and, in lockstep, the golden model and the
//! comparator, on the self-test loopback workload. Both clocks run at
//! 24 MHz so the simulated design work matches the one-clock raw harness.

use cosim::{CompareConfig, DutChoice, HostBfm, ReferenceChoice, TbConfig, Testbench};
use diagnose::RxWiring;

use crate::BenchError;
use crate::workload::{CLOCKS_PER_BIT, IRQ_TIMEOUT_BITS, SelfTestHost, SelfTestOutcome};

/// The CAN and host clock of the bench, Hz.
pub const CLOCK_HZ: u64 = 24_000_000;
/// The DE2's host clock (`wb_clk_i`), Hz, for the two-clock row.
pub const DE2_HOST_HZ: u64 = 50_000_000;

/// The test bench as a [`SelfTestHost`].
pub struct CosimHost {
    tb: Testbench,
}

impl CosimHost {
    /// Builds the bench: our RTL, Wishbone BFM, `rx_i` = `tx_o` (no other
    /// node), with or without the lockstep golden model + comparator.
    pub fn new(lockstep: bool) -> Result<Self, BenchError> {
        Self::with_host_clock(lockstep, CLOCK_HZ)
    }

    /// As [`CosimHost::new`] with the host clock at `host_hz` (the DE2
    /// runs `wb_clk_i` at 50 MHz).
    pub fn with_host_clock(lockstep: bool, host_hz: u64) -> Result<Self, BenchError> {
        let cfg = TbConfig {
            scenario: "bench self-test loopback".into(),
            dut: DutChoice::Rtl,
            host: HostBfm::Wishbone,
            host_hz,
            can_hz: CLOCK_HZ,
            rx: RxWiring::Bus,
            tx_on_bus: true,
            lockstep: lockstep.then(|| (ReferenceChoice::Model, CompareConfig::default())),
            keep_bits: 0,
            ..TbConfig::default()
        };
        Ok(CosimHost {
            tb: Testbench::new(cfg)?,
        })
    }

    /// Turns the test bench's batches off or on ([`Testbench::set_batching`]).
    pub fn set_batching(&mut self, on: bool) {
        self.tb.set_batching(on);
    }

    /// The run record so far (for comparing two runs).
    pub fn record(&mut self) -> diagnose::RunRecord {
        self.tb.record()
    }

    /// The lockstep comparator, if any (for comparing two runs).
    pub fn comparator(&self) -> Option<&cosim::Comparator> {
        self.tb.comparator()
    }

    /// Host clock cycles simulated so far.
    pub fn host_cycles(&self) -> u64 {
        self.tb.host_cycles()
    }

    /// CAN clock cycles simulated so far.
    pub fn cycles(&self) -> u64 {
        self.tb.can_cycles()
    }
}

impl SelfTestHost for CosimHost {
    type Error = BenchError;
    fn write(&mut self, addr: u8, data: u8) -> Result<(), BenchError> {
        self.tb.write(addr, data)?;
        Ok(())
    }
    fn read(&mut self, addr: u8) -> Result<u8, BenchError> {
        Ok(self.tb.read(addr)?)
    }
    fn idle_bits(&mut self, bits: u64) -> Result<(), BenchError> {
        Ok(self.tb.run_can_cycles(bits * CLOCKS_PER_BIT)?)
    }
    fn wait_irq(&mut self) -> Result<(), BenchError> {
        self.tb.wait_irq(IRQ_TIMEOUT_BITS)?;
        Ok(())
    }
}

/// The self-test workload in co-simulation; returns the outcome and the CAN clock cycles.
pub fn selftest(
    frames: u64,
    seed: u64,
    lockstep: bool,
    host_hz: u64,
) -> Result<(SelfTestOutcome, u64), BenchError> {
    selftest_batching(frames, seed, lockstep, host_hz, true)
}

/// As [`selftest`], with the test bench's batches on or off.
pub fn selftest_batching(
    frames: u64,
    seed: u64,
    lockstep: bool,
    host_hz: u64,
    batching: bool,
) -> Result<(SelfTestOutcome, u64), BenchError> {
    let mut h = CosimHost::with_host_clock(lockstep, host_hz)?;
    h.set_batching(batching);
    let out = crate::workload::run(&mut h, frames, seed)?;
    Ok((out, h.cycles()))
}
