//! Speed baseline: the same Verilated top in a raw C++ loop (no Rust, no
//! FFI), built with Verilator's own `--exe --build` at `-O3`, clocked the
//! way the kernel clocks it. The co-simulation's cycles/s divided by this
//! one's is the bridge's efficiency (the bench uses it too).

use std::path::PathBuf;
use std::process::Command;

use std::fmt::Write as _;

use vbridge::{BridgeError, ExternalCore};

/// Where the bundled tops' sources are (this crate's build inputs).
pub fn bundled_sources(top: &str) -> ExternalCore {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = if top.starts_with("cosim_") {
        root.join("tb/fixtures")
    } else {
        root.join("rtl")
    };
    let files = if top.starts_with("cosim_") {
        vec![dir.join(format!("{top}.v"))]
    } else {
        Vec::new()
    };
    ExternalCore {
        dir,
        top: top.into(),
        files,
        ..ExternalCore::default()
    }
}

/// Result of one baseline run.
#[derive(Clone, Copy, Debug)]
pub struct Baseline {
    /// CAN clock cycles simulated.
    pub cycles: u64,
    /// Wall time of the loop, seconds.
    pub seconds: f64,
}

impl Baseline {
    /// CAN clock cycles per second.
    pub fn cycles_per_s(&self) -> f64 {
        self.cycles as f64 / self.seconds
    }
}

/// Builds and runs the raw C++ loop for `core` with its `can_top`-style
/// clocks (`clk_i`, `wb_clk_i`, reset `wb_rst_i`): `cycles` CAN clock
/// cycles at `can_hz`, the host clock at `host_hz`.
pub fn cpp_baseline(
    core: &ExternalCore,
    cycles: u64,
    host_hz: u64,
    can_hz: u64,
) -> Result<Baseline, BridgeError> {
    // A scratch directory of this call's own (two baselines of one top may
    // run at once: test threads share the pid); removed on every return.
    let scratch = tempfile::Builder::new()
        .prefix(&format!("cosim-cpp-{}-", core.top))
        .tempdir()
        .map_err(|e| BridgeError::Io {
            context: "creating the baseline dir".into(),
            source: e,
        })?;
    let dir = scratch.path();
    let can_half = 1_000_000_000_000 / (2 * can_hz);
    let host_half = 1_000_000_000_000 / (2 * host_hz);
    let src = gen_cpp_harness(
        &core.top,
        "clk_i",
        Some("wb_clk_i"),
        Some("wb_rst_i"),
        can_half,
        host_half,
        cycles,
    );
    let harness = dir.join("harness.cpp");
    std::fs::write(&harness, src).map_err(|e| BridgeError::Io {
        context: "writing the harness".into(),
        source: e,
    })?;
    let mut sources = core.files.clone();
    if sources.is_empty() {
        sources = std::fs::read_dir(&core.dir)
            .map_err(|e| BridgeError::Io {
                context: format!("reading {}", core.dir.display()),
                source: e,
            })?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("v" | "sv")))
            .collect();
        sources.sort();
    }
    let mut cmd = Command::new("verilator");
    cmd.args([
        "--cc",
        "--exe",
        "--build",
        "--no-timing",
        "-Wno-fatal",
        "-Wno-lint",
        "-Wno-style",
        "+1364-2005ext+v",
        "-j",
        "2",
        "--top-module",
    ])
    .arg(&core.top)
    .arg("--prefix")
    .arg(format!("V{}", core.top))
    .arg("-Mdir")
    .arg(dir.join("obj"))
    .args(["-MAKEFLAGS", "OPT_FAST=-O3 OPT_SLOW=-O2 OPT_GLOBAL=-O3"])
    .arg(format!("-I{}", core.dir.display()));
    for d in &core.defines {
        cmd.arg(format!("-D{d}"));
    }
    for d in &core.include_dirs {
        cmd.arg(format!("-I{}", d.display()));
    }
    cmd.args(&sources).arg(&harness).arg("-o").arg("harness");
    let o = cmd.output().map_err(|e| BridgeError::Io {
        context: "running verilator".into(),
        source: e,
    })?;
    if !o.status.success() {
        return Err(BridgeError::Compile {
            top: core.top.clone(),
            step: "C++ baseline".into(),
            message: format!(
                "{}{}",
                String::from_utf8_lossy(&o.stdout),
                String::from_utf8_lossy(&o.stderr)
            ),
        });
    }
    let o = Command::new(dir.join("obj/harness"))
        .output()
        .map_err(|e| BridgeError::Io {
            context: "running the harness".into(),
            source: e,
        })?;
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    let mut it = text.split_whitespace();
    let parse_err = || BridgeError::Compile {
        top: core.top.clone(),
        step: "C++ baseline output".into(),
        message: text.clone(),
    };
    let cycles: u64 = it
        .next()
        .and_then(|s| s.parse().ok())
        .ok_or_else(parse_err)?;
    let seconds: f64 = it
        .next()
        .and_then(|s| s.parse().ok())
        .ok_or_else(parse_err)?;
    Ok(Baseline { cycles, seconds })
}

/// A raw C++ harness for the same top: the speed baseline for the bridge.
/// It toggles `clk_port` (and `host_clk_port`, if given, at its own
/// period) with the same event order as the Rust kernel, one `eval` per
/// event time, and prints `cycles seconds`.
///
/// `can_half_ps`/`host_half_ps` are the half periods; the loop runs
/// `cycles` CAN clock cycles. Inputs not named stay at their reset value,
/// except `reset_port` which is held high for the first 4 host cycles.
fn gen_cpp_harness(
    top: &str,
    clk_port: &str,
    host_clk_port: Option<&str>,
    reset_port: Option<&str>,
    can_half_ps: u64,
    host_half_ps: u64,
    cycles: u64,
) -> String {
    let class = format!("V{top}");
    let mut s = String::new();
    let _ = writeln!(
        s,
        "// Generated by cosim's perf: raw Verilator loop (speed baseline)."
    );
    let _ = writeln!(
        s,
        "#include \"{class}.h\"\n#include \"verilated.h\"\n#include <chrono>\n#include <cstdio>\n#include <cstdint>"
    );
    let _ = writeln!(
        s,
        "int main() {{\n  VerilatedContext ctx;\n  {class} m(&ctx, \"TOP\");"
    );
    let _ = writeln!(
        s,
        "  uint64_t t = 0, next_can = 0, next_host = 0; bool can_clk = false, host_clk = false;"
    );
    let _ = writeln!(s, "  uint64_t can_rises = 0, host_rises = 0;");
    if let Some(r) = reset_port {
        let _ = writeln!(s, "  m.{r} = 1;");
    }
    let _ = writeln!(s, "  auto t0 = std::chrono::steady_clock::now();");
    let _ = writeln!(s, "  while (can_rises < {cycles}ull) {{");
    let _ = writeln!(s, "    t = next_can;");
    if host_clk_port.is_some() {
        let _ = writeln!(s, "    if (next_host < t) t = next_host;");
    }
    let _ = writeln!(
        s,
        "    if (t == next_can) {{ can_clk = !can_clk; m.{clk_port} = can_clk; if (can_clk) ++can_rises; next_can += {can_half_ps}ull; }}"
    );
    if let Some(h) = host_clk_port {
        let _ = writeln!(
            s,
            "    if (t == next_host) {{ host_clk = !host_clk; m.{h} = host_clk; if (host_clk) ++host_rises; next_host += {host_half_ps}ull; }}"
        );
        if let Some(r) = reset_port {
            let _ = writeln!(s, "    if (host_rises == 4) m.{r} = 0;");
        }
    }
    let _ = writeln!(s, "    m.eval();\n  }}");
    let _ = writeln!(
        s,
        "  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();"
    );
    let _ = writeln!(
        s,
        "  m.final();\n  std::printf(\"%llu %.9f\\n\", (unsigned long long)can_rises, secs);\n  return 0;\n}}"
    );
    let _ = host_half_ps;
    s
}

