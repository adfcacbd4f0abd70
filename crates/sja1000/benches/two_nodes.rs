//! Simulated bit times per second: two PeliCAN nodes exchanging seeded
//! random frames back to back on the fast path (target: >= 50 M/s on one
//! core). Run: `cargo bench -p sja1000 --bench two_nodes`; criterion
//! reports the rate as "elem/s" (one element = one bit time).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use sja1000::workload::two_node_exchange;

const BITS: u64 = 200_000;

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
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
