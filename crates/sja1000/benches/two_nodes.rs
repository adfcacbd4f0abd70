//! Simulated bit times per second: two PeliCAN nodes exchanging seeded
//! random frames back to back on the fast path (target: >= 50 M/s on one
//! core). Run: `cargo bench -p sja1000 --bench two_nodes`; criterion
//! reports the rate as "elem/s" (one element = one bit time).
//!
//! `engines_only` runs the same traffic on two bare protocol engines (no
//! registers, no host), to show how the time splits between the engine
//! and the controller model.

use can_engine::{Engine, Event, Options};
use can_proto::timing::BusTiming;
use criterion::{Criterion, Throughput, criterion_group};
use rand::{SeedableRng, rngs::StdRng};
use sja1000::workload::{random_frame, two_node_exchange};

const BITS: u64 = 200_000;

fn engines_only(seed: u64, bits: u64) -> u64 {
    let mut rng = StdRng::seed_from_u64(seed);
    let t = BusTiming::from_btr(0x41, 0x25);
    let mut e = [
        Engine::new(t, Options::default()),
        Engine::new(t, Options::default()),
    ];
    for x in &mut e {
        x.set_reset_mode(false);
        x.request_tx(random_frame(&mut rng), false, false);
    }
    let mut done = 0;
    for _ in 0..bits {
        let level = e[0].tx() & e[1].tx();
        for x in &mut e {
            x.sample_bit(level);
            if x.has_events() {
                let mut again = false;
                for ev in x.take_events() {
                    if ev == Event::TxComplete {
                        again = true;
                        done += 1;
                    }
                }
                if again {
                    x.request_tx(random_frame(&mut rng), false, false);
                }
            }
        }
    }
    done
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("two_nodes");
    g.throughput(Throughput::Elements(BITS));
    g.sample_size(20);
    g.bench_function("random_frames_fast_path", |b| {
        let mut seed = 0;
        b.iter(|| {
            seed += 1;
            let st = two_node_exchange(seed, BITS);
            assert_eq!(st.bit_times, BITS);
            st
        })
    });
    g.bench_function("engines_only", |b| {
        let mut seed = 0;
        b.iter(|| {
            seed += 1;
            engines_only(seed, BITS)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);

/// Criterion times wall clock; on a loaded machine also report on-CPU rate.
fn cpu_report() {
    let r = sja1000::workload::bench_two_nodes(42, 20_000_000);
    println!(
        "two_nodes on-CPU: {} bit times, {} frames received: {:.1} M bit-times/s wall, {} on-CPU",
        r.stats.bit_times,
        r.stats.frames_received,
        r.bits_per_sec_wall() / 1e6,
        r.bits_per_sec_cpu()
            .map_or("n/a".into(), |v| format!("{:.1} M bit-times/s", v / 1e6)),
    );
}

/// The same for two bare engines (the engine's share of the time).
fn cpu_report_engines() {
    let bits = 20_000_000;
    let c0 = sja1000::workload::thread_cpu_time();
    let done = engines_only(42, bits);
    if let (Some(a), Some(b)) = (c0, sja1000::workload::thread_cpu_time()) {
        let s = (b - a).as_secs_f64();
        println!(
            "engines_only on-CPU: {bits} bit times, {done} frames: {:.1} M bit-times/s",
            bits as f64 / s / 1e6
        );
    }
}

fn main() {
    benches();
    cpu_report();
    cpu_report_engines();
    Criterion::default().configure_from_args().final_summary();
}
