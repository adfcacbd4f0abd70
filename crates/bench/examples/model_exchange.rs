//! The model scaling workload alone, for a profiler:
//! `cargo build --release -p bench --example model_exchange &&
//! perf record -g target/release/examples/model_exchange 2 4000000`.

fn main() {
    let mut a = std::env::args().skip(1);
    let nodes: usize = a.next().and_then(|v| v.parse().ok()).unwrap_or(2);
    let bits: u64 = a.next().and_then(|v| v.parse().ok()).unwrap_or(4_000_000);
    let t0 = std::time::Instant::now();
    let (bit_times, frames) = bench::model::exchange(nodes, 1, bits);
    let s = t0.elapsed().as_secs_f64();
    println!(
        "{nodes} nodes: {bit_times} bit times, {frames} frames received, {s:.3} s, {:.2} M bit times/s",
        bit_times as f64 / s / 1e6
    );
}
