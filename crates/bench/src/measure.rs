//! Time and memory measurements. The machine may be shared, so the figure
//! that counts is CPU time of the thread (in-process workloads) or of the
//! child process (external simulators), with wall time reported beside it.
//! Peak RSS of a child: the VmHWM of its own address space, sampled from
//! `/proc/<pid>/status` every 2 ms while it runs (or what it reports
//! itself); `wait4`'s `ru_maxrss` is not used because it counts the
//! parent's RSS at spawn (the child starts as a copy of the bench process,
//! and the peak of the address space it left at exec is kept). For in-process
//! workloads the process's peak (VmHWM) is reset through
//! `/proc/self/clear_refs` before the workload and read after it, so it
//! includes what the process already held (code, libraries, allocator).

use std::io::Read;
use std::process::{Command, Stdio};
use std::time::Instant;

use crate::BenchError;

/// Time and memory of one measured piece of work.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Cost {
    /// CPU seconds (user + system) of the thread or child.
    pub cpu_s: f64,
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// Peak resident set size, KiB.
    pub max_rss_kib: u64,
}

fn thread_cpu_s() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: valid pointer to a timespec; CLOCK_THREAD_CPUTIME_ID is always available on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn status_kib(status: &str, key: &str) -> Option<u64> {
    let line = status.lines().find(|l| l.starts_with(key))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn vm_hwm_kib() -> Option<u64> {
    status_kib(
        &std::fs::read_to_string("/proc/self/status").ok()?,
        "VmHWM:",
    )
}

/// Resets the process's peak RSS to its current RSS (Linux >= 4.0).
fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Runs `f` on this thread and measures it.
pub fn in_process<T, E>(f: impl FnOnce() -> Result<T, E>) -> Result<(T, Cost), E> {
    let reset = reset_peak_rss();
    let c0 = thread_cpu_s();
    let t0 = Instant::now();
    let v = f()?;
    let wall_s = t0.elapsed().as_secs_f64();
    let cpu_s = thread_cpu_s() - c0;
    // Without the reset the peak is since process start: an upper bound.
    let _ = reset;
    Ok((
        v,
        Cost {
            cpu_s,
            wall_s,
            max_rss_kib: vm_hwm_kib().unwrap_or(0),
        },
    ))
}

/// What a child printed and what it cost.
#[derive(Clone, Debug)]
pub struct ChildRun {
    /// Its standard output.
    pub stdout: String,
    /// Its standard error.
    pub stderr: String,
    /// Exit code (None: killed by a signal).
    pub code: Option<i32>,
    /// Its cost, from `wait4`'s rusage.
    pub cost: Cost,
}

/// Runs `cmd` to completion and measures it with `wait4`.
pub fn child(what: &str, cmd: &mut Command) -> Result<ChildRun, BenchError> {
    let t0 = Instant::now();
    let mut ch = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| BenchError::Spawn {
            what: what.into(),
            error: e,
        })?;
    let mut out = ch.stdout.take().expect("piped");
    let mut err = ch.stderr.take().expect("piped");
    let err_reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err.read_to_string(&mut s);
        s
    });
    let pid = ch.id() as libc::pid_t;
    let running = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
    let sampler = {
        let running = running.clone();
        std::thread::spawn(move || {
            let path = format!("/proc/{pid}/status");
            let mut peak = 0u64;
            while running.load(std::sync::atomic::Ordering::Relaxed) {
                // The first samples may still be of the pre-exec copy of this process: skip
                // until the child's command line is no longer ours.
                if let Some(kib) = std::fs::read_to_string(&path)
                    .ok()
                    .and_then(|s| status_kib(&s, "VmHWM:"))
                {
                    let exe = std::fs::read_link(format!("/proc/{pid}/exe")).ok();
                    if exe.is_some() && exe != std::env::current_exe().ok() {
                        peak = peak.max(kib);
                    }
                }
                std::thread::sleep(std::time::Duration::from_millis(2));
            }
            peak
        })
    };
    let mut stdout = String::new();
    let _ = out.read_to_string(&mut stdout);
    let stderr = err_reader.join().unwrap_or_default();
    running.store(false, std::sync::atomic::Ordering::Relaxed);
    let sampled = sampler.join().unwrap_or(0);
    let mut status: libc::c_int = 0;
    // SAFETY: zeroed rusage is a valid value; pid is our own un-reaped child.
    let mut ru: libc::rusage = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut ru) };
    let wall_s = t0.elapsed().as_secs_f64();
    if r != pid {
        return Err(BenchError::Spawn {
            what: what.into(),
            error: std::io::Error::last_os_error(),
        });
    }
    let code = if libc::WIFEXITED(status) {
        Some(libc::WEXITSTATUS(status))
    } else {
        None
    };
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    let reported = bench_line(&stdout, "maxrss_kb").unwrap_or(0);
    let cost = Cost {
        cpu_s: tv(ru.ru_utime) + tv(ru.ru_stime),
        wall_s,
        max_rss_kib: reported.max(sampled),
    };
    Ok(ChildRun {
        stdout,
        stderr,
        code,
        cost,
    })
}

/// The `key=value` fields of the `BENCH ...` line a harness prints.
pub fn bench_line(stdout: &str, key: &str) -> Option<u64> {
    let line = stdout.lines().rev().find(|l| l.starts_with("BENCH "))?;
    line.split_whitespace()
        .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('=')?.parse().ok())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bench_line_fields_are_found_by_name() {
        let s = "noise\nBENCH frames=3 cycles=15021 errors=0\n";
        assert_eq!(bench_line(s, "cycles"), Some(15021));
        assert_eq!(bench_line(s, "frames"), Some(3));
        assert_eq!(bench_line(s, "missing"), None);
        assert_eq!(bench_line("no line", "frames"), None);
    }

    #[test]
    fn a_child_is_measured_and_its_exit_code_kept() {
        let r = child(
            "sh",
            Command::new("sh").args(["-c", "sleep 0.05; echo BENCH x=1; exit 3"]),
        )
        .unwrap();
        assert_eq!(r.code, Some(3));
        assert_eq!(bench_line(&r.stdout, "x"), Some(1));
        assert!(r.cost.wall_s > 0.0);
        // A shell's own peak, not this test process's.
        assert!(
            r.cost.max_rss_kib > 0 && r.cost.max_rss_kib < 16 << 10,
            "{} KiB",
            r.cost.max_rss_kib
        );
    }

    #[test]
    fn in_process_cost_counts_cpu_and_peak_memory() {
        let ((), c) = in_process(|| {
            let v = vec![1u8; 8 << 20];
            let mut s = 0u64;
            for _ in 0..4 {
                s = s.wrapping_add(v.iter().map(|&b| b as u64).sum::<u64>());
            }
            std::hint::black_box(s);
            Ok::<(), ()>(())
        })
        .unwrap();
        assert!(c.cpu_s > 0.0);
        assert!(
            c.max_rss_kib >= 8 << 10,
            "8 MiB touched, peak {} KiB",
            c.max_rss_kib
        );
    }
}
