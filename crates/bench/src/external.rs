//! The external simulators of the same RTL and stimulus: the raw C++
//! Verilator harness (`tb/bench/harness.cpp`, built here with
//! `verilator --cc --exe --build`, -O3) and the Icarus test bench
//! (`tb/bench/bench_tb.v`). Builds are cached in the work directory under
//! a key hashed from the tool version, the flags and every source file, so
//! only the first run after an RTL change pays for them.

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use crate::BenchError;
use crate::measure::{self, ChildRun, Cost};

/// Verilator flags of the harness build (also part of the cache key).
const VERILATOR_FLAGS: &[&str] = &[
    "-O3",
    "--cc",
    "--exe",
    "--build",
    "-j",
    "2",
    "-Wno-fatal",
    "-Wno-lint",
    "-Wno-style",
    "--top-module",
    "can_top",
];
/// C++ optimisation of the harness build.
const MAKEFLAGS: &str = "OPT_FAST=-O3 OPT_SLOW=-O1";

/// A build step's outcome.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Built {
    /// The executable or compiled image.
    pub path: PathBuf,
    /// Taken from the cache.
    pub cached: bool,
    /// Seconds the build took (0 when cached).
    pub build_s: f64,
}

/// One run of an external simulator.
#[derive(Clone, Debug)]
pub struct ExternalRun {
    /// Frames sent.
    pub frames: u64,
    /// Clock cycles simulated.
    pub cycles: u64,
    /// Read-back mismatches.
    pub errors: u64,
    /// Its cost.
    pub cost: Cost,
}

/// The RTL sources (`rtl/*.v`) and include files, sorted.
fn rtl_sources(root: &Path) -> Result<(Vec<PathBuf>, Vec<PathBuf>), BenchError> {
    let dir = root.join("rtl");
    let rd = std::fs::read_dir(&dir)
        .map_err(|e| BenchError::Missing(format!("RTL directory {}: {e}", dir.display())))?;
    let mut v = Vec::new();
    let mut inc = Vec::new();
    for e in rd.flatten() {
        let p = e.path();
        match p.extension().and_then(|x| x.to_str()) {
            Some("v") => v.push(p),
            Some("vh") => inc.push(p),
            _ => {}
        }
    }
    v.sort();
    inc.sort();
    if !v
        .iter()
        .any(|p| p.file_name().is_some_and(|n| n == "can_top.v"))
    {
        return Err(BenchError::Missing(format!(
            "rtl/can_top.v not found in {}",
            dir.display()
        )));
    }
    Ok((v, inc))
}

fn tool_version(tool: &str, arg: &str) -> Result<String, BenchError> {
    let o = Command::new(tool).arg(arg).output().map_err(|e| {
        BenchError::Missing(format!(
            "`{tool}` could not be run ({e}); install it (apt-get install {tool})"
        ))
    })?;
    Ok(format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    ))
}

fn cache_key(parts: &[&str], files: &[PathBuf]) -> Result<String, BenchError> {
    let mut h = DefaultHasher::new();
    parts.hash(&mut h);
    for f in files {
        f.file_name().hash(&mut h);
        std::fs::read(f)
            .map_err(|e| BenchError::Missing(format!("{}: {e}", f.display())))?
            .hash(&mut h);
    }
    Ok(format!("{:016x}", h.finish()))
}

/// Builds `dir/product` once (the shared `buildcache` helper: a work
/// directory per build, moved into place atomically), so concurrent runs
/// (test threads, two `cancosim bench`) never see or break half a build.
fn cached_build(
    dir: &Path,
    product: &str,
    build: impl FnOnce(&Path) -> Result<(), BenchError>,
) -> Result<Built, BenchError> {
    let t0 = Instant::now();
    let entry = buildcache::build_once(dir, product, build).map_err(|e| match e {
        buildcache::Error::Build(e) => e,
        io @ buildcache::Error::Io { .. } => BenchError::Build {
            what: product.into(),
            log: io.to_string(),
        },
    })?;
    let cached = entry.origin == buildcache::Origin::Cached;
    Ok(Built {
        path: entry.product,
        cached,
        build_s: if cached { 0.0 } else { t0.elapsed().as_secs_f64() },
    })
}

fn run_tool(what: &str, cmd: &mut Command) -> Result<(), BenchError> {
    let o = cmd.output().map_err(|e| BenchError::Spawn {
        what: what.into(),
        error: e,
    })?;
    if o.status.success() {
        return Ok(());
    }
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    let tail: Vec<&str> = log.lines().rev().take(30).collect();
    Err(BenchError::Build {
        what: what.into(),
        log: tail.into_iter().rev().collect::<Vec<_>>().join("\n"),
    })
}

/// Builds (or finds in the cache) the raw C++ harness.
pub fn build_harness(root: &Path, work: &Path) -> Result<Built, BenchError> {
    let (srcs, incs) = rtl_sources(root)?;
    let harness = root.join("tb/bench/harness.cpp");
    let version = tool_version("verilator", "--version")?;
    let mut files = srcs.clone();
    files.extend(incs);
    files.push(harness.clone());
    let flags = VERILATOR_FLAGS.join(" ");
    let key = cache_key(&[&version, &flags, MAKEFLAGS], &files)?;
    let dir = work.join(format!("harness-{key}"));
    cached_build(&dir, "harness", |tmp| {
        let mut cmd = Command::new("verilator");
        cmd.args(VERILATOR_FLAGS)
            .arg(format!("-I{}", root.join("rtl").display()))
            .args(["-MAKEFLAGS", MAKEFLAGS, "-CFLAGS", "-O3"])
            .arg("-Mdir")
            .arg(tmp.join("obj"))
            .args(&srcs)
            .arg(&harness)
            .arg("-o")
            .arg(tmp.join("harness"));
        run_tool(
            "the raw C++ Verilator harness (verilator --build)",
            &mut cmd,
        )?;
        // Keep the executable, drop the object files.
        let _ = std::fs::remove_dir_all(tmp.join("obj"));
        Ok(())
    })
}

/// Compiles (or finds in the cache) the Icarus test bench.
pub fn build_icarus(root: &Path, work: &Path) -> Result<Built, BenchError> {
    let (srcs, incs) = rtl_sources(root)?;
    let tb = root.join("tb/bench/bench_tb.v");
    let version = tool_version("iverilog", "-V")?;
    let version = version.lines().next().unwrap_or("").to_string();
    let mut files = srcs.clone();
    files.extend(incs);
    files.push(tb.clone());
    let key = cache_key(&[&version, "-g2005 -s bench_tb"], &files)?;
    let dir = work.join(format!("icarus-{key}"));
    cached_build(&dir, "bench.vvp", |tmp| {
        let mut cmd = Command::new("iverilog");
        cmd.args(["-g2005", "-s", "bench_tb"])
            .arg("-I")
            .arg(root.join("rtl"))
            .arg("-o")
            .arg(tmp.join("bench.vvp"))
            .arg(&tb)
            .args(&srcs);
        run_tool("the Icarus test bench (iverilog)", &mut cmd)
    })
}

fn parse_run(what: &str, r: ChildRun, frames: u64) -> Result<ExternalRun, BenchError> {
    let field = |k: &str| measure::bench_line(&r.stdout, k);
    match (r.code, field("frames"), field("cycles"), field("errors")) {
        (Some(0), Some(f), Some(c), Some(e)) if f == frames => Ok(ExternalRun {
            frames: f,
            cycles: c,
            errors: e,
            cost: r.cost,
        }),
        _ => Err(BenchError::Run {
            what: what.into(),
            detail: format!(
                "exit {:?}; stdout: {}; stderr: {}",
                r.code,
                r.stdout.trim(),
                r.stderr.trim()
            ),
        }),
    }
}

/// Runs the harness on `frames` frames of the generator seeded with `seed`.
pub fn run_harness(exe: &Path, frames: u64, seed: u64) -> Result<ExternalRun, BenchError> {
    let what = "raw C++ Verilator harness";
    let r = measure::child(
        what,
        Command::new(exe)
            .arg(frames.to_string())
            .arg(seed.to_string()),
    )?;
    parse_run(what, r, frames)
}

/// Runs the Icarus test bench (`vvp -n`).
pub fn run_icarus(vvp: &Path, frames: u64, seed: u64) -> Result<ExternalRun, BenchError> {
    let what = "Icarus test bench (vvp)";
    let r = measure::child(
        what,
        Command::new("vvp")
            .arg("-n")
            .arg(vvp)
            .arg(format!("+frames={frames}"))
            .arg(format!("+seed={}", seed as u32)),
    )?;
    parse_run(what, r, frames)
}
