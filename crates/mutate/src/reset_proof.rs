//! The formal check of a survivor in its own module, from reset: the
//! mutated module alone (not the whole core), a miter of the original and
//! the mutant sharing every input, every register zero at power-up and the
//! module's reset forced in the first clock (so the state the comparison
//! starts from is the state after the reset sequence), outputs compared
//! from the second clock on, the reset input free afterwards.
//!
//! The proof engine is ABC: signal correspondence (`scorr`: induction over
//! pairs of equal signals, sound from the initial state) and then PDR, an
//! unbounded model checker that ends with an inductive invariant. Only
//! "Property proved" is reported as equivalent; a bounded check without a
//! difference is reported as "no difference within N steps".
//!
//! What the proof assumes, stated in every verdict: the module's inputs are
//! free (any value every clock, so a proof holds in any context); registers
//! the reset leaves alone start at zero in both copies (as the bench's
//! Verilator build starts them); `x` constants are free values chosen
//! independently in the two copies (so a mutant that pins an `x` is only
//! equivalent if that `x` can never reach an output). A counterexample is
//! a difference at the module's ports; whether the rest of the core can
//! drive those inputs is not checked ([`FormalVerdict::ModuleDiffers`]).

use crate::formal::{FormalOptions, FormalVerdict, parse_trace};
use crate::instrument::{CoreSources, InstrumentError, read_command, sources, yosys_logged};
use crate::mutation::Mutation;
use serde_json::Value;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// Result of one mutant's check in its module.
#[derive(Clone, Debug)]
pub struct ModuleCheck {
    /// The module the mutated cell belongs to.
    pub module: String,
    /// The verdict.
    pub verdict: FormalVerdict,
    /// Wall time of the check.
    pub seconds: f64,
}

/// Where the check cannot run per module (the caller falls back to the
/// whole-core check).
#[derive(Clone, Debug, PartialEq)]
pub enum NotPerModule {
    /// The module has more than one clock input.
    Clocks(String, Vec<String>),
    /// The mutated cell was not found in the unflattened design.
    CellNotFound(String),
}

pub(crate) fn io(what: impl Into<String>) -> impl FnOnce(std::io::Error) -> InstrumentError {
    let what = what.into();
    move |source| InstrumentError::Io { what, source }
}

/// A port of the mutated module.
#[derive(Clone, Debug)]
pub(crate) struct Port {
    pub(crate) name: String,
    pub(crate) width: usize,
    pub(crate) input: bool,
}

/// The hierarchy of the core after `prep` (not flattened), as JSON; cached
/// in `work` by a hash of the sources (the same commands as the mutants'
/// build, so private cell names such as `$procmux$2131` are the same).
pub(crate) fn hierarchy(src: &CoreSources, work: &Path) -> Result<Value, InstrumentError> {
    let files = sources(src)?;
    let read = read_command(src, &files);
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    crate::instrument::fnv1a(&mut h, read.as_bytes());
    for f in &files {
        crate::instrument::fnv1a(&mut h, &std::fs::read(f).map_err(io(format!("reading {}", f.display())))?);
    }
    let json = work.join(format!("hierarchy-{h:016x}.json"));
    if !json.exists() {
        let script = format!("{read}\nhierarchy -top {t}\nprep -top {t}\nwrite_json {}\n", json.display(), t = src.top);
        yosys_logged(&script, work, "hierarchy", false)?;
    }
    serde_json::from_str(&std::fs::read_to_string(&json).map_err(io(format!("reading {}", json.display())))?)
        .map_err(|e| InstrumentError::Io { what: json.display().to_string(), source: std::io::Error::other(e) })
}

/// The module holding a cell of the flattened top (`$flatten\u_a.u_b.$x`
/// is cell `$x` of the type of `u_b` inside the type of `u_a`), and the
/// cell's name there.
fn locate(design: &Value, top: &str, cell: &str) -> Option<(String, String)> {
    let modules = design.get("modules")?;
    let mut module = top.to_string();
    // A private cell of a submodule is `$flatten\u_a.$x`; a public one (a
    // memory such as `u_regs.ramfree`) keeps its plain dotted path.
    let in_top = modules.get(top)?.get("cells")?.get(cell).is_some();
    let Some(mut rest) = cell.strip_prefix("$flatten\\").or_else(|| (!in_top && cell.contains('.')).then_some(cell)) else {
        return in_top.then(|| (module, cell.to_string()));
    };
    loop {
        let cells = modules.get(&module)?.get("cells")?.as_object()?;
        if cells.contains_key(rest) {
            return Some((module, rest.to_string()));
        }
        // the instance whose name, plus a dot, starts the rest (longest first)
        let (inst, ty) = cells
            .iter()
            .filter_map(|(name, c)| {
                let ty = c.get("type")?.as_str()?;
                (modules.get(ty).is_some() && rest.starts_with(&format!("{name}."))).then(|| (name.clone(), ty.to_string()))
            })
            .max_by_key(|(name, _)| name.len())?;
        rest = &rest[inst.len() + 1..];
        module = ty;
    }
}

pub(crate) fn ports(design: &Value, module: &str) -> Vec<Port> {
    let Some(ps) = design["modules"][module]["ports"].as_object() else { return Vec::new() };
    ps.iter()
        .map(|(name, p)| Port { name: name.clone(), width: p["bits"].as_array().map(|b| b.len()).unwrap_or(1), input: p["direction"] == "input" })
        .collect()
}

/// Inputs of `module` that clock a flip-flop (found in its netlist: the
/// bits on every `CLK` connection).
pub(crate) fn clocks(design: &Value, module: &str, ports: &[Port]) -> Vec<String> {
    let m = &design["modules"][module];
    let mut clk_bits = Vec::new();
    for c in m["cells"].as_object().into_iter().flat_map(|c| c.values()) {
        if let Some(bits) = c["connections"]["CLK"].as_array() {
            clk_bits.extend(bits.iter().cloned());
        }
    }
    ports
        .iter()
        .filter(|p| p.input && m["ports"][&p.name]["bits"].as_array().is_some_and(|b| b.iter().any(|x| clk_bits.contains(x))))
        .map(|p| p.name.clone())
        .collect()
}

/// The reset input by name (`rst`, `reset`, `rst_i`, ...; `_n` / `n`
/// endings active low).
pub(crate) fn reset_port(ports: &[Port]) -> Option<(String, bool)> {
    ports.iter().filter(|p| p.input && p.width == 1).find_map(|p| {
        let n = p.name.to_ascii_lowercase();
        let base = n.trim_end_matches("_i");
        match base {
            "rst" | "reset" | "arst" | "rst_in" | "wb_rst" => Some((p.name.clone(), true)),
            "rst_n" | "rstn" | "reset_n" | "resetn" | "nrst" | "arst_n" => Some((p.name.clone(), false)),
            _ => None,
        }
    })
}

fn vname(n: &str) -> String {
    if n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') && !n.starts_with(|c: char| c.is_ascii_digit()) { n.to_string() } else { format!("\\{n} ") }
}

/// The wrapper: both copies on the same inputs (`in_<port>`, the names
/// `sat -show-inputs` prints), the reset forced while `started` is 0 (the
/// first clock), `trigger` when an output differs after that.
fn wrapper(ports: &[Port], clock: Option<&str>, reset: Option<&(String, bool)>) -> String {
    let range = |w: usize| if w == 1 { String::new() } else { format!("[{}:0] ", w - 1) };
    let ins: Vec<&Port> = ports.iter().filter(|p| p.input).collect();
    let outs: Vec<&Port> = ports.iter().filter(|p| !p.input).collect();
    let mut s = String::from("module cosim_formal (\n");
    for p in &ins {
        s += &format!("    input wire {}in_{},\n", range(p.width), p.name);
    }
    s += "    output wire trigger\n);\n";
    match clock {
        Some(c) => s += &format!("    reg started = 1'b0;\n    always @(posedge in_{c}) started <= 1'b1;\n"),
        None => s += "    wire started = 1'b1;\n",
    }
    for p in &outs {
        s += &format!("    wire {r}gold_{n}, gate_{n};\n", r = range(p.width), n = p.name);
    }
    let conn = |copy: &str| {
        let mut c: Vec<String> = ins
            .iter()
            .map(|p| match reset {
                Some((r, high)) if *r == p.name && clock.is_some() => format!(".{}(in_{} {} !started)", vname(&p.name), p.name, if *high { "|" } else { "&" }),
                _ => format!(".{}(in_{})", vname(&p.name), p.name),
            })
            .collect();
        c.extend(outs.iter().map(|p| format!(".{}({copy}_{})", vname(&p.name), p.name)));
        c.join(", ")
    };
    s += &format!("    cosim_gold gold ({});\n    cosim_gate gate ({});\n", conn("gold"), conn("gate"));
    let cat = |copy: &str| outs.iter().map(|p| format!("{copy}_{}", p.name)).collect::<Vec<_>>().join(", ");
    if outs.is_empty() {
        s += "    assign trigger = 1'b0;\n";
    } else {
        s += &format!("    assign trigger = started && ({{{}}} != {{{}}});\n", cat("gold"), cat("gate"));
    }
    s += "endmodule\n";
    s
}

/// The mutation's options rewritten for the module copy `cosim_gate`
/// (`-wire` and `-src` dropped: they name the flattened design).
fn mutate_command(m: &Mutation, cell: &str) -> String {
    let mut s = format!("mutate -mode {} -module cosim_gate -cell {} -port {} -portbit {}", m.mode, cell, m.port, m.portbit);
    if let Some(c) = m.ctrlbit {
        s += &format!(" -ctrlbit {c}");
    }
    s
}

/// Options of the check from the survivor check's [`FormalOptions`]:
/// `steps` bounds the counterexample search, `timeout_s` the proof.
fn pdr_seconds(o: &FormalOptions) -> u32 {
    o.timeout_s.max(1)
}

/// Checks mutation `m` of the core `src` in its own module, from reset.
/// `Err(NotPerModule)` inside `Ok` when it cannot (more than one clock, or
/// the cell is unknown): the caller then uses the whole-core check.
pub fn check_in_module(src: &CoreSources, m: &Mutation, opts: &FormalOptions, work: &Path) -> Result<Result<ModuleCheck, NotPerModule>, InstrumentError> {
    let t0 = Instant::now();
    std::fs::create_dir_all(work).map_err(io(format!("creating {}", work.display())))?;
    let work = &std::path::absolute(work).map_err(io(format!("resolving {}", work.display())))?;
    let design = hierarchy(src, work)?;
    let Some((module, cell)) = locate(&design, &src.top, &m.cell) else {
        return Ok(Err(NotPerModule::CellNotFound(m.cell.clone())));
    };
    let ports = ports(&design, &module);
    let clks = clocks(&design, &module, &ports);
    if clks.len() > 1 {
        return Ok(Err(NotPerModule::Clocks(module, clks)));
    }
    let clock = clks.first().map(String::as_str);
    let reset = reset_port(&ports);
    let assumed = format!(
        "module {module} alone, inputs free, {}",
        match (&reset, clock) {
            (Some((r, _)), Some(c)) => format!("{r} forced in the first {c} cycle, unreset registers zero in both copies"),
            (None, Some(_)) => "no reset input: from all registers zero".to_string(),
            (_, None) => "combinational (no clock)".to_string(),
        }
    );
    let files = sources(src)?;
    let dir = work.join(format!("mutant-{}", m.id));
    let head = format!("{read}\nhierarchy -top {top}\nprep -top {top}\nhierarchy -top {module}\n", read = read_command(src, &files), top = src.top);
    let plain = Miter { module: &module, label: &module, cell: &cell, m, opts, ports: &ports, clock, reset: reset.as_ref(), assumed };
    let verdict = verdict_with_shared_undef(plain, &dir, &head)?;
    Ok(Ok(ModuleCheck { module, verdict, seconds: t0.elapsed().as_secs_f64() }))
}

/// The verdict of a miter (`head` leaves `plain.module` in the design); if
/// the module differs from itself, again with its undefined values shared
/// by both copies (shared_undef.rs), its own control run deciding.
pub(crate) fn verdict_with_shared_undef(plain: Miter<'_>, dir: &Path, head: &str) -> Result<FormalVerdict, InstrumentError> {
    let module = plain.module;
    let label = plain.label;
    let assumed = plain.assumed.clone();
    Ok(match plain.judge(dir, head)? {
        Judged::Verdict(v) => v,
        // The module differs from itself: again with its undefined values
        // shared by both copies (shared_undef.rs), its own control run.
        Judged::SelfDiffers => {
            let sdir = dir.join("shared-undef");
            std::fs::create_dir_all(&sdir).map_err(io(format!("creating {}", sdir.display())))?;
            let expose = format!("{head}{}write_rtlil exposed.il\nwrite_json exposed.json\n", crate::shared_undef::expose_commands(module));
            yosys_logged(&expose, &sdir, "expose", false)?;
            let json = sdir.join("exposed.json");
            let exposed: Value = serde_json::from_str(&std::fs::read_to_string(&json).map_err(io(format!("reading {}", json.display())))?)
                .map_err(|e| InstrumentError::Io { what: json.display().to_string(), source: std::io::Error::other(e) })?;
            let sports = self::ports(&exposed, module);
            let n = sports.iter().filter(|p| p.input && crate::shared_undef::is_undef_port(&p.name)).count();
            let assumed = format!("{assumed}; its {n} undefined values (x) shared: each one free input, the same in both copies");
            let shared = Miter { ports: &sports, assumed: assumed.clone(), ..plain };
            match shared.judge(&sdir, &format!("read_rtlil {}\n", sdir.join("exposed.il").display()))? {
                Judged::Verdict(v) => v,
                Judged::SelfDiffers => FormalVerdict::Unknown {
                    why: format!("no verdict: {label} differs from itself (its undefined values reach an output), even with its x constants shared (values left undefined by its memories or submodules); {assumed}"),
                },
            }
        }
    })
}

/// What a miter says before the control run is weighed.
enum Judged {
    /// A verdict that stands.
    Verdict(FormalVerdict),
    /// The mutant differs, but so does the module from itself (the control
    /// run): the difference says nothing.
    SelfDiffers,
}

/// One miter of the mutated module: the module (after `head`, a yosys
/// script that leaves it in the design as `module`), copied, the copy
/// mutated, both in the wrapper on shared inputs.
pub(crate) struct Miter<'a> {
    /// The module (in the design after the head script).
    pub(crate) module: &'a str,
    /// What it is, in the verdicts (the module's name, or a scope's).
    pub(crate) label: &'a str,
    pub(crate) cell: &'a str,
    pub(crate) m: &'a Mutation,
    pub(crate) opts: &'a FormalOptions,
    pub(crate) ports: &'a [Port],
    pub(crate) clock: Option<&'a str>,
    pub(crate) reset: Option<&'a (String, bool)>,
    pub(crate) assumed: String,
}

impl Miter<'_> {
    /// Builds the miter in `dir` and judges it: a proof, a counterexample
    /// (if the control run, the module against itself, shows none), or
    /// bounded.
    fn judge(&self, dir: &Path, head: &str) -> Result<Judged, InstrumentError> {
        let (module, m, opts) = (self.module, self.m, self.opts);
        std::fs::create_dir_all(dir).map_err(io(format!("creating {}", dir.display())))?;
        let wrap = dir.join("wrapper.v");
        std::fs::write(&wrap, wrapper(self.ports, self.clock, self.reset)).map_err(io(format!("writing {}", wrap.display())))?;
        // Up to `prep` exactly as the mutants' build (same cell names); then
        // the module alone, copied, the copy mutated, both flattened (their own
        // submodules), memories as flip-flops, `x` free, every flip-flop
        // without an initial value given one of zero (`write_aiger -zinit`
        // makes the initial value of an uninitialised flip-flop a free input,
        // a different one per copy: registers the reset leaves alone, such
        // as a memory's words, then differed from themselves).
        let prep = format!(
            "{head}copy {module} cosim_gate\nrename {module} cosim_gold\n{mutate}\n\
             read_verilog {wrap}\nproc\nhierarchy -top cosim_formal\nflatten\nmemory\nsetundef -anyseq\nsetundef -zero -init\n\
             opt_clean\nasync2sync\ndffunmap\nwrite_rtlil miter.il\n\
             techmap\nopt -fast\ndffunmap\nabc -fast -g AND\nopt_clean\ndffunmap\nwrite_aiger -zinit miter.aig\n",
            mutate = mutate_command(m, self.cell),
            wrap = wrap.display()
        );
        yosys_logged(&prep, dir, "miter", false)?;
        // The control: the module against itself (no mutation). If it differs,
        // values the module leaves undefined (`x`, out-of-range memory reads)
        // reach an output, and a difference of the mutant means nothing.
        let control = |dir: &Path| -> Result<bool, InstrumentError> {
            std::fs::create_dir_all(dir).map_err(io(format!("creating {}", dir.display())))?;
            let script = prep.replace(&mutate_command(m, self.cell), "");
            yosys_logged(&script, dir, "miter", false)?;
            let (t, _) = abc(dir, &format!("read_aiger miter.aig; fold; strash; scorr; dc2; pdr -T {}", pdr_seconds(opts)), 2 * pdr_seconds(opts), "abc.log")?;
            Ok(asserted_frame(&t).is_some())
        };
        let assumed = self.assumed.clone();
        let secs = pdr_seconds(opts);
        // Signal correspondence (`scorr`) merges the gold/gate pairs that stay
        // equal; PDR proves the rest or finds a counterexample. Wall-clock
        // bounded (the machine may be loaded): twice the PDR time for both.
        let (text, _) = abc(dir, &format!("read_aiger miter.aig; fold; strash; scorr; dc2; pdr -T {secs}"), 2 * secs, "abc.log")?;
        let verdict = if text.contains("Property proved") {
            FormalVerdict::Equivalent { method: format!("proved from reset by ABC scorr + PDR (inductive invariant): {assumed}") }
        } else if asserted_frame(&text).is_some() && control(&dir.join("control"))? {
            return Ok(Judged::SelfDiffers);
        } else if let Some(frame) = asserted_frame(&text) {
            // The input trace from a bounded check just deep enough.
            let steps = frame + 2;
            let bmc = format!("read_rtlil miter.il\nsat -seq {steps} -prove trigger 0 -set-init-zero -show-inputs -timeout {secs} cosim_formal\n");
            // `sat -timeout` is not kept on a large module (can_bsp: 9-15 min):
            // the process is killed after its time and the trace left empty.
            let (out, _) = yosys_killed_after(&bmc, dir, "trace", secs + 30)?;
            let trace = parse_trace(&out);
            FormalVerdict::ModuleDiffers { module: self.label.to_string(), steps: trace.iter().map(|t| t.step).max().unwrap_or(steps), trace, assumed }
        } else {
            // No proof: how deep is there surely no difference?
            let why = if text.contains("UNDECIDED") { format!("PDR undecided after {secs} s") } else { format!("ABC stopped after {} s", 2 * secs) };
            let (b, _) = abc(dir, &format!("read_aiger miter.aig; fold; strash; bmc3 -v -F {} -T {secs}", opts.steps), secs + 30, "bmc.log")?;
            if let Some(frame) = asserted_frame(&b) {
                FormalVerdict::ModuleDiffers { module: self.label.to_string(), steps: frame + 1, trace: Vec::new(), assumed }
            } else {
                let depth = match bmc_depth(&b) {
                    Some(d) => format!("no difference within {d} clocks (bounded, not a proof)"),
                    None => "bounded check inconclusive".into(),
                };
                FormalVerdict::Unknown { why: format!("{depth}; {why}; {assumed}") }
            }
        };
        Ok(Judged::Verdict(verdict))
    }
}

/// Runs a yosys script (`step`.ys, its log `step`.log) in `dir`, killed
/// after `limit_s` seconds of wall time: its log and whether it was killed.
pub(crate) fn yosys_killed_after(script: &str, dir: &Path, step: &str, limit_s: u32) -> Result<(String, bool), InstrumentError> {
    let ys = dir.join(format!("{step}.ys"));
    std::fs::write(&ys, script).map_err(io(format!("writing {}", ys.display())))?;
    run_killed_after(Command::new("yosys").arg("-s").arg(&ys), dir, limit_s, &format!("{step}.log"))
}

/// Runs `yosys-abc -c script` in `dir`, killed after `limit_s` seconds of
/// wall time; its output (also written to `log`) and whether it was killed.
fn abc(dir: &Path, script: &str, limit_s: u32, log: &str) -> Result<(String, bool), InstrumentError> {
    run_killed_after(Command::new("yosys-abc").arg("-c").arg(script), dir, limit_s, log)
}

/// Runs `cmd` in `dir`, its output to `log`, killed after `limit_s` seconds.
fn run_killed_after(cmd: &mut Command, dir: &Path, limit_s: u32, log: &str) -> Result<(String, bool), InstrumentError> {
    let out_path = dir.join(log);
    let out = std::fs::File::create(&out_path).map_err(io(format!("creating {}", out_path.display())))?;
    let err = out.try_clone().map_err(io("log file"))?;
    let name = cmd.get_program().to_string_lossy().into_owned();
    let mut child = match cmd.current_dir(dir).stdout(out).stderr(err).spawn() {
        Ok(c) => c,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound && name == "yosys" => return Err(InstrumentError::NoYosys),
        Err(e) => return Err(io(format!("running {name}"))(e)),
    };
    let deadline = Instant::now() + std::time::Duration::from_secs(u64::from(limit_s));
    let killed = loop {
        if child.try_wait().map_err(io(format!("waiting for {name}")))?.is_some() {
            break false;
        }
        if Instant::now() >= deadline {
            let _ = child.kill();
            let _ = child.wait();
            break true;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    Ok((std::fs::read_to_string(&out_path).unwrap_or_default(), killed))
}

/// Frames `bmc3 -v` finished without a difference: `No output asserted
/// in N frames.`, else its last progress line `F + : Var = ...` (frame F,
/// from 0, done: F counted, one less than proved, to stay on the safe side).
fn bmc_depth(text: &str) -> Option<u32> {
    if let Some(l) = text.lines().find(|l| l.contains("No output asserted in")) {
        return l.split(" in ").nth(1)?.split_whitespace().next()?.parse().ok();
    }
    let l = text.lines().rev().find(|l| l.contains(" + : Var ="))?;
    l.split_whitespace().next()?.parse::<u32>().ok()
}

/// `Output 0 of miter "m" was asserted in frame 5.` → 5.
fn asserted_frame(text: &str) -> Option<u32> {
    let l = text.lines().find(|l| l.contains("was asserted in frame"))?;
    l.split("frame").last()?.split_whitespace().next()?.trim_end_matches('.').parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn abc_messages_are_read() {
        assert_eq!(asserted_frame("Output 0 of miter \"miter\" was asserted in frame 5.  Time =     0.01 sec"), Some(5));
        assert_eq!(asserted_frame("Property proved.  Time = 0.01 sec"), None);
        assert_eq!(bmc_depth("  12 + : Var =   18108. Cla =    62251.\n  13 + : Var =   20565. Cla = 71237.\n"), Some(13));
        assert_eq!(bmc_depth("No output asserted in 30 frames. Time = 1 sec"), Some(30));
        assert_eq!(bmc_depth("Reached timeout"), None);
    }

    #[test]
    fn nested_flattened_names_resolve_to_their_module() {
        let d: Value = serde_json::from_str(
            r#"{"modules": {
                "top": {"cells": {"u_a": {"type": "a"}, "$and$x": {"type": "$and"}}},
                "a": {"cells": {"u_b": {"type": "b"}, "$procmux$1": {"type": "$mux"}}},
                "b": {"cells": {"$ternary$/x/b.v:3$7": {"type": "$mux"}}}}}"#,
        )
        .unwrap();
        assert_eq!(locate(&d, "top", "$flatten\\u_a.$procmux$1"), Some(("a".into(), "$procmux$1".into())));
        assert_eq!(locate(&d, "top", "$flatten\\u_a.u_b.$ternary$/x/b.v:3$7"), Some(("b".into(), "$ternary$/x/b.v:3$7".into())));
        assert_eq!(locate(&d, "top", "$and$x"), Some(("top".into(), "$and$x".into())));
        assert_eq!(locate(&d, "top", "$flatten\\u_a.$nope$2"), None);
        // a memory keeps its public, dotted name in the flattened design
        let d: Value = serde_json::from_str(r#"{"modules": {"top": {"cells": {"u_a": {"type": "a"}}}, "a": {"cells": {"ram": {"type": "$mem_v2"}}}}}"#).unwrap();
        assert_eq!(locate(&d, "top", "u_a.ram"), Some(("a".into(), "ram".into())));
        assert_eq!(locate(&d, "top", "u_a.nope"), None);
    }

    #[test]
    fn the_reset_is_forced_only_in_the_first_clock() {
        let ports = vec![
            Port { name: "clk".into(), width: 1, input: true },
            Port { name: "rst_n".into(), width: 1, input: true },
            Port { name: "q".into(), width: 4, input: false },
        ];
        let r = reset_port(&ports);
        assert_eq!(r, Some(("rst_n".into(), false)));
        let w = wrapper(&ports, Some("clk"), r.as_ref());
        assert!(w.contains(".rst_n(in_rst_n & !started)"), "{w}");
        assert!(w.contains("assign trigger = started && ({gold_q} != {gate_q});"), "{w}");
    }
}
