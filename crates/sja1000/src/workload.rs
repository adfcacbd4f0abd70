//! Seeded random traffic between model nodes: the benchmark workload, also
//! exposed for the CLI's `bench` command.

use can_proto::{CanFrame, Id};
use rand::{Rng, RngExt, SeedableRng, rngs::StdRng};
use regmap::peli;

use crate::bus::Bus;
use crate::controller::Sja1000;
use crate::host::{self, Config};

/// A random frame: standard or extended, data or remote, DLC 0..=15.
pub fn random_frame(rng: &mut impl Rng) -> CanFrame {
    let id: Id = if rng.random_bool(0.5) {
        CanFrame::std_id(rng.random_range(0..0x800)).expect("11 bits")
    } else {
        CanFrame::ext_id(rng.random_range(0..0x2000_0000)).expect("29 bits")
    };
    let rtr = rng.random_bool(0.1);
    let dlc = rng.random_range(0..16u8);
    let mut data = [0u8; 8];
    rng.fill(&mut data[..]);
    let n = if rtr { 0 } else { dlc.min(8) as usize };
    CanFrame::with_dlc(id, rtr, dlc, &data[..n]).expect("valid DLC")
}

/// What an exchange did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExchangeStats {
    /// Bit times simulated.
    pub bit_times: u64,
    /// Transmissions requested.
    pub frames_requested: u64,
    /// Frames read out of RX FIFOs.
    pub frames_received: u64,
}

/// `n` PeliCAN nodes accepting every frame, RI and TI enabled, same timing.
pub fn pelican_bus(n: usize) -> Bus {
    let mut bus = Bus::new();
    for _ in 0..n {
        let mut node = Sja1000::new();
        let cfg = Config {
            interrupts: peli::ier::RIE | peli::ier::TIE,
            ..Config::pelican()
        };
        host::configure(&mut node, &cfg);
        bus.add_node(node);
    }
    bus
}

/// Every node sends random frames back to back (a new one as soon as TI
/// says the buffer is free) and reads out whatever it receives, for
/// `bit_times` bit times. The host services interrupts every 8 bit times.
pub fn exchange(bus: &mut Bus, rng: &mut impl Rng, bit_times: u64) -> ExchangeStats {
    let mut st = ExchangeStats::default();
    for i in 0..bus.len() {
        let f = random_frame(rng);
        if host::transmit(bus.node_mut(i), &f, peli::cmr::TR).is_ok() {
            st.frames_requested += 1;
        }
    }
    const CHUNK: u64 = 8;
    let mut done = 0;
    while done < bit_times {
        let n = CHUNK.min(bit_times - done);
        bus.run_bits(n);
        done += n;
        for i in 0..bus.len() {
            let node = bus.node_mut(i);
            if !node.irq() {
                continue;
            }
            let ir = node.read(peli::IR);
            while host::receive(node).is_some() {
                st.frames_received += 1;
            }
            if ir & peli::ir::TI != 0 {
                let f = random_frame(rng);
                if host::transmit(node, &f, peli::cmr::TR).is_ok() {
                    st.frames_requested += 1;
                }
            }
        }
    }
    st.bit_times = done;
    st
}

/// The benchmark workload: two nodes, seeded random frames, `bit_times`
/// bit times, accounting off (it is a speed measurement).
pub fn two_node_exchange(seed: u64, bit_times: u64) -> ExchangeStats {
    let mut bus = pelican_bus(2);
    bus.set_accounting(false);
    let mut rng = StdRng::seed_from_u64(seed);
    exchange(&mut bus, &mut rng, bit_times)
}

/// On-CPU time of the calling thread (Linux `/proc/thread-self/schedstat`),
/// `None` elsewhere. On a shared, loaded machine wall time says little;
/// this says what a core of its own would give.
pub fn thread_cpu_time() -> Option<std::time::Duration> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: u64 = s.split_whitespace().next()?.parse().ok()?;
    Some(std::time::Duration::from_nanos(ns))
}

/// A timed run of [`two_node_exchange`].
#[derive(Clone, Copy, Debug)]
pub struct BenchReport {
    /// What the run did.
    pub stats: ExchangeStats,
    /// Wall-clock time.
    pub wall: std::time::Duration,
    /// On-CPU time of the thread, if the platform tells.
    pub cpu: Option<std::time::Duration>,
}

impl BenchReport {
    /// Simulated bit times per second of wall-clock time.
    pub fn bits_per_sec_wall(&self) -> f64 {
        self.stats.bit_times as f64 / self.wall.as_secs_f64()
    }

    /// Simulated bit times per second of on-CPU time.
    pub fn bits_per_sec_cpu(&self) -> Option<f64> {
        self.cpu
            .map(|c| self.stats.bit_times as f64 / c.as_secs_f64())
    }
}

/// Runs [`two_node_exchange`] and times it (the CLI `bench` command).
pub fn bench_two_nodes(seed: u64, bit_times: u64) -> BenchReport {
    let cpu0 = thread_cpu_time();
    let t = std::time::Instant::now();
    let stats = two_node_exchange(seed, bit_times);
    let wall = t.elapsed();
    let cpu = match (cpu0, thread_cpu_time()) {
        (Some(a), Some(b)) => Some(b.saturating_sub(a)),
        _ => None,
    };
    BenchReport { stats, wall, cpu }
}
