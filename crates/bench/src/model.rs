//! The golden model alone: node-count scaling on random traffic, and the
//! self-test loopback workload on one model node (the traffic the
//! Verilated RTL runs, for the model-vs-RTL ratio).

use rand::SeedableRng;
use rand::rngs::StdRng;
use sja1000::{Bus, Sja1000, workload};

use crate::BenchError;
use crate::workload::{IRQ_TIMEOUT_BITS, SelfTestHost, SelfTestOutcome};

/// One node count of the scaling workload: every node sends seeded random
/// frames back to back for `bit_times` bit times (fast per-bit path,
/// accounting off). Returns bit times simulated and frames received.
pub fn exchange(nodes: usize, seed: u64, bit_times: u64) -> (u64, u64) {
    let mut bus = workload::pelican_bus(nodes);
    bus.set_accounting(false);
    let mut rng = StdRng::seed_from_u64(seed);
    let st = workload::exchange(&mut bus, &mut rng, bit_times);
    (st.bit_times, st.frames_received)
}

/// A lone model node played through direct register calls; host accesses
/// take no simulated time.
pub struct ModelHost {
    bus: Bus,
}

impl ModelHost {
    /// A node just out of hardware reset on an empty bus.
    pub fn new() -> Self {
        let mut bus = Bus::new();
        bus.set_accounting(false);
        bus.add_node(Sja1000::new());
        ModelHost { bus }
    }

    /// Bit times simulated so far.
    pub fn bit_times(&self) -> u64 {
        self.bus.bit_times()
    }
}

impl Default for ModelHost {
    fn default() -> Self {
        Self::new()
    }
}

impl SelfTestHost for ModelHost {
    type Error = BenchError;
    fn write(&mut self, addr: u8, data: u8) -> Result<(), BenchError> {
        self.bus.node_mut(0).write(addr, data);
        Ok(())
    }
    fn read(&mut self, addr: u8) -> Result<u8, BenchError> {
        Ok(self.bus.node_mut(0).read(addr))
    }
    fn idle_bits(&mut self, bits: u64) -> Result<(), BenchError> {
        self.bus.run_bits(bits);
        Ok(())
    }
    fn wait_irq(&mut self) -> Result<(), BenchError> {
        if self.bus.run_until(IRQ_TIMEOUT_BITS, |b| b.node(0).irq()) {
            Ok(())
        } else {
            Err(BenchError::Run {
                what: "golden model self test".into(),
                detail: format!("no interrupt within {IRQ_TIMEOUT_BITS} bit times"),
            })
        }
    }
}

/// The self-test workload on the model; returns the outcome and the bit times.
pub fn selftest(frames: u64, seed: u64) -> Result<(SelfTestOutcome, u64), BenchError> {
    let mut h = ModelHost::new();
    let out = crate::workload::run(&mut h, frames, seed)?;
    Ok((out, h.bit_times()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_model_passes_its_own_self_test_workload() {
        let (out, bits) = selftest(20, 3).unwrap();
        assert_eq!(
            out,
            SelfTestOutcome {
                frames: 20,
                errors: 0
            }
        );
        // A standard 8-byte frame is at least 108 bits before stuffing, plus intermission.
        assert!(bits > 20 * 108, "{bits} bit times for 20 frames");
    }

    #[test]
    fn two_nodes_exchange_frames() {
        let (bits, received) = exchange(2, 1, 20_000);
        assert_eq!(bits, 20_000);
        assert!(received > 50, "{received} frames received in 20k bit times");
    }
}
