//! The co-simulation rows alone, repeated, for profiling and for quick
//! before/after figures of an optimisation (min of the repetitions):
//! `cargo run --release -p bench --example cosim_only -- [frames] [reps] [both|lockstep|plain] [nobatch|batch] [host Hz]`
//! (host clock: default the CAN clock's, 24 MHz; 50000000 for the DE2's two clocks).

fn main() -> Result<(), bench::BenchError> {
    let mut args = std::env::args().skip(1);
    let frames: u64 = args.next().and_then(|v| v.parse().ok()).unwrap_or(300);
    let reps: u32 = args.next().and_then(|v| v.parse().ok()).unwrap_or(5);
    let which = args.next().unwrap_or_else(|| "both".into());
    let batching = args.next().as_deref() != Some("nobatch");
    let host_hz: u64 = args.next().and_then(|v| v.parse().ok()).unwrap_or(bench::cosim_run::CLOCK_HZ);
    let rows: &[(&str, bool)] = match which.as_str() {
        "lockstep" => &[("cosim", true)],
        "plain" => &[("cosim-no-lockstep", false)],
        _ => &[("cosim", true), ("cosim-no-lockstep", false)],
    };
    for &(name, lockstep) in rows {
        let mut best = f64::MAX;
        for _ in 0..reps {
            let ((out, cycles), cost) = bench::measure::in_process(|| {
                bench::cosim_run::selftest_batching(
                    frames,
                    1,
                    lockstep,
                    host_hz,
                    batching,
                )
            })?;
            assert!(out.frames == frames && out.errors == 0, "self-test failed");
            best = best.min(cost.cpu_s * 1e9 / cycles as f64);
        }
        println!("{name:<18} {best:8.1} ns CPU per CAN cycle (min of {reps})");
    }
    Ok(())
}
