//! Per-case time bound for the fuzz targets: a case that
//! runs longer than its bound fails, and one that never returns (an
//! infinite loop) is reported by a watchdog thread, which names the input
//! and ends the process with a failure code instead of hanging CI.
//!
//! The same file is included (`#[path]`) by the fuzz tests of can-proto,
//! sja1000 and scenario, so the three targets behave alike.
#![allow(dead_code)]

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};
use std::thread::ThreadId;
use std::time::{Duration, Instant};

/// Case under way on each test thread: start, bound, input in words.
static RUNNING: OnceLock<Mutex<HashMap<ThreadId, (Instant, Duration, String)>>> = OnceLock::new();

fn running() -> &'static Mutex<HashMap<ThreadId, (Instant, Duration, String)>> {
    RUNNING.get_or_init(|| {
        std::thread::spawn(|| {
            loop {
                std::thread::sleep(Duration::from_millis(200));
                let map = running().lock().unwrap_or_else(|e| e.into_inner());
                for (start, limit, input) in map.values() {
                    // A panicking bound fires at `limit`; the watchdog only
                    // acts on a case that never returns.
                    if start.elapsed() > *limit * 4 + Duration::from_secs(2) {
                        eprintln!(
                            "fuzz watchdog: a case has run {:.1} s (bound {:.1} s) and never returned; input: {input}",
                            start.elapsed().as_secs_f64(),
                            limit.as_secs_f64()
                        );
                        std::process::exit(3);
                    }
                }
            }
        });
        Mutex::new(HashMap::new())
    })
}

/// Runs `f` (one fuzz case, described by `input`) and panics if it took
/// longer than `limit`.
pub fn within<T>(limit: Duration, input: impl FnOnce() -> String, f: impl FnOnce() -> T) -> T {
    let me = std::thread::current().id();
    let start = Instant::now();
    running()
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(me, (start, limit, input()));
    let out = f();
    let took = start.elapsed();
    let entry = running().lock().unwrap_or_else(|e| e.into_inner()).remove(&me);
    if took > limit {
        let input = entry.map(|e| e.2).unwrap_or_default();
        panic!(
            "fuzz case took {:.3} s, over its bound of {:.3} s; input: {input}",
            took.as_secs_f64(),
            limit.as_secs_f64()
        );
    }
    out
}

/// Cases for the large runs: `FUZZ_CASES`, else `default`.
pub fn large_cases(default: u32) -> u32 {
    std::env::var("FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}
