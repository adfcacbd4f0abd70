//! The formal check of a survivor in a widened scope: the mutated module
//! together with sibling modules that drive its inputs, as the top
//! instantiates them, every other module of the top cut.
//!
//! The per-module check ([`crate::reset_proof`]) leaves every input of the
//! mutated module free, so a mutant whose difference needs an input sequence
//! its driver never makes (a `sample` pulse an odd number of clocks after the
//! last one) is refuted there although no test can kill it. Here the driver
//! is kept, and the cut is sound:
//! - the outputs of the cut modules (and of the top's own glue logic) that
//!   the scope reads become free inputs of the check, the same in both
//!   copies of the miter (any behaviour of the cut modules, so a proof holds
//!   whatever they do);
//! - every signal the scope drives into a cut module or a top output is a
//!   compared output, so a difference that would flow into the cut modules
//!   (the register file, the FIFO...) is still seen. Signals only between
//!   the scope's modules are not compared: that is the point.
//!
//! Why that is sound: if the two copies agree on every compared signal at
//! every clock, the cut modules see the same inputs in the original and in
//! the mutant, so they behave the same, and the shared free inputs cover
//! what they do (the design has no combinational loop through the cut).
//!
//! The scope is built as a wrapper module (`cosim_scope`) around the kept
//! instances, flattened after the same `read_verilog`/`prep` as the mutants'
//! build, so the mutated cell keeps its name (`$flatten\u_bsp.$procdff$6992`).
//! The miter, the reset forced in the first clock, the control run and the
//! shared `x` values are the per-module check's ([`crate::reset_proof`]).

use crate::formal::{FormalOptions, FormalVerdict};
use crate::instrument::{CoreSources, InstrumentError, read_command, sources, yosys_logged};
use crate::mutation::Mutation;
use crate::reset_proof::{self, Miter, clocks, hierarchy, io, ports, reset_port};
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::Path;
use std::time::Instant;

/// Name of the wrapper module holding the scope.
pub const SCOPE_MODULE: &str = "cosim_scope";

/// How many widened scopes are tried per mutant (one sibling driver each,
/// the smallest first), unless the caller names the scope.
pub const MAX_SCOPES: usize = 2;

/// Instances of the top kept together in one check.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Scope {
    /// The mutated module's instance (a child of the top).
    pub mutated: String,
    /// The sibling instances kept with it.
    pub with: Vec<String>,
}

impl Scope {
    /// Every kept instance, the mutated one first.
    pub fn instances(&self) -> Vec<&str> {
        std::iter::once(self.mutated.as_str()).chain(self.with.iter().map(String::as_str)).collect()
    }

    /// In words: `top: u_bsp (can_bsp) + u_btl (can_btl), other modules cut`.
    pub fn describe(&self, design: &Value, top: &str) -> String {
        let ty = |i: &str| design["modules"][top]["cells"][i]["type"].as_str().unwrap_or("?").to_string();
        let parts: Vec<String> = self.instances().iter().map(|i| format!("{i} ({})", ty(i))).collect();
        format!("{top} scope {}", parts.join(" + "))
    }
}

/// The result of one widened check.
#[derive(Clone, Debug)]
pub struct ScopeCheck {
    /// The scope.
    pub scope: Scope,
    /// In words ([`Scope::describe`]).
    pub label: String,
    /// The verdict.
    pub verdict: FormalVerdict,
    /// Wall time.
    pub seconds: f64,
}

/// The instance of the top that holds the mutated cell: `$flatten\u_bsp.$x`
/// and `u_regs.ramfree` are in `u_bsp` / `u_regs`; a cell of the top's own
/// logic has none.
pub fn mutated_instance(design: &Value, top: &str, cell: &str) -> Option<String> {
    let cells = design["modules"][top]["cells"].as_object()?;
    if cells.contains_key(cell) {
        return None;
    }
    let rest = cell.strip_prefix("$flatten\\").unwrap_or(cell);
    let inst = rest.split('.').next()?;
    cells.get(inst).filter(|c| is_instance(design, c)).map(|_| inst.to_string())
}

fn is_instance(design: &Value, cell: &Value) -> bool {
    cell["type"].as_str().is_some_and(|t| design["modules"].get(t).is_some())
}

/// Flip-flop bits of a module (its own cells; the hierarchy is prepped).
fn ff_bits(design: &Value, module: &str) -> usize {
    let Some(cells) = design["modules"][module]["cells"].as_object() else { return 0 };
    cells
        .values()
        .map(|c| {
            let ty = c["type"].as_str().unwrap_or("");
            if ty.contains("dff") || ty.contains("dlatch") {
                c["connections"]["Q"].as_array().map_or(0, Vec::len)
            } else if let Some(sub) = design["modules"].get(ty).map(|_| ty) {
                ff_bits(design, sub)
            } else {
                0
            }
        })
        .sum()
}

/// Top-level bits of an instance's clock inputs.
fn clock_bits(design: &Value, top: &str, inst: &str) -> BTreeSet<u64> {
    let cell = &design["modules"][top]["cells"][inst];
    let Some(ty) = cell["type"].as_str() else { return BTreeSet::new() };
    let ps = ports(design, ty);
    clocks(design, ty, &ps).iter().flat_map(|p| cell["connections"][p].as_array().cloned().unwrap_or_default()).filter_map(|b| b.as_u64()).collect()
}

/// Bits of the top an instance drives (`output`) or reads (`input`).
fn conn_bits(cell: &Value, dir: &str) -> BTreeSet<u64> {
    let mut out = BTreeSet::new();
    let Some(conns) = cell["connections"].as_object() else { return out };
    for (p, bits) in conns {
        if cell["port_directions"][p] == dir {
            out.extend(bits.as_array().into_iter().flatten().filter_map(Value::as_u64));
        }
    }
    out
}

/// The scopes tried for a mutant of instance `mutated`: the mutated
/// instance with one sibling that drives one of its inputs, on its clock
/// (or without a clock), the smallest (flip-flop bits) first, at most
/// [`MAX_SCOPES`].
pub fn candidate_scopes(design: &Value, top: &str, mutated: &str) -> Vec<Scope> {
    let Some(cells) = design["modules"][top]["cells"].as_object() else { return Vec::new() };
    let reads = conn_bits(&cells[mutated], "input");
    let clk = clock_bits(design, top, mutated);
    let mut drivers: Vec<(usize, String)> = cells
        .iter()
        .filter(|(n, c)| *n != mutated && is_instance(design, c))
        .filter(|(_, c)| !conn_bits(c, "output").is_disjoint(&reads))
        .filter(|(n, _)| clock_bits(design, top, n).is_subset(&clk))
        .map(|(n, c)| (ff_bits(design, c["type"].as_str().unwrap_or("")), n.clone()))
        .collect();
    drivers.sort();
    drivers.into_iter().take(MAX_SCOPES).map(|(_, d)| Scope { mutated: mutated.to_string(), with: vec![d] }).collect()
}

fn sanitize(name: &str) -> String {
    let mut s: String = name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }).collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, 'n');
    }
    s
}

fn escaped(name: &str) -> String {
    if name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') && !name.starts_with(|c: char| c.is_ascii_digit()) { name.to_string() } else { format!("\\{name} ") }
}

/// Ports of the wrapper: groups of top bits named after the top's nets
/// (its ports first, then public names), what is left one bit each.
fn name_ports(top: &Value, bits: &BTreeSet<u64>, taken: &mut BTreeSet<String>) -> Vec<(String, Vec<u64>)> {
    let mut nets: Vec<(u8, String, Vec<u64>)> = top["netnames"]
        .as_object()
        .into_iter()
        .flatten()
        .filter_map(|(n, v)| {
            let b: Vec<u64> = v["bits"].as_array()?.iter().map(Value::as_u64).collect::<Option<_>>()?;
            let rank = if top["ports"].get(n).is_some() { 0 } else if v["hide_name"] == 0 { 1 } else { 2 };
            Some((rank, n.clone(), b))
        })
        .collect();
    nets.sort();
    let mut left = bits.clone();
    let mut out = Vec::new();
    for (_, n, b) in nets {
        if !b.is_empty() && b.iter().all(|x| left.contains(x)) && b.iter().collect::<BTreeSet<_>>().len() == b.len() {
            let mut name = sanitize(&n);
            while !taken.insert(name.clone()) {
                name += "_";
            }
            b.iter().for_each(|x| {
                left.remove(x);
            });
            out.push((name, b));
        }
    }
    for x in left {
        let mut name = format!("cosim_net{x}");
        while !taken.insert(name.clone()) {
            name += "_";
        }
        out.push((name, vec![x]));
    }
    out
}

/// The wrapper module of `scope` in the top's nets, and how many bits it
/// compares and leaves free.
pub fn scope_verilog(design: &Value, top_name: &str, scope: &Scope) -> Result<(String, usize, usize), String> {
    let top = &design["modules"][top_name];
    let cells = top["cells"].as_object().ok_or("the top has no cells")?;
    let kept: BTreeSet<&str> = scope.instances().into_iter().collect();
    for k in &kept {
        if !cells.get(*k).is_some_and(|c| is_instance(design, c)) {
            return Err(format!("{k} is not an instance of {top_name}"));
        }
    }
    let (mut driven, mut read, mut read_outside) = (BTreeSet::new(), BTreeSet::new(), BTreeSet::new());
    for (n, c) in cells {
        if kept.contains(n.as_str()) {
            driven.extend(conn_bits(c, "output"));
            read.extend(conn_bits(c, "input"));
            if !conn_bits(c, "inout").is_empty() {
                return Err(format!("{n} has an inout port"));
            }
        } else {
            read_outside.extend(conn_bits(c, "input"));
            read_outside.extend(conn_bits(c, "inout"));
        }
    }
    for p in top["ports"].as_object().into_iter().flatten().map(|(_, p)| p) {
        if p["direction"] != "input" {
            read_outside.extend(p["bits"].as_array().into_iter().flatten().filter_map(Value::as_u64));
        }
    }
    let inputs: BTreeSet<u64> = read.difference(&driven).copied().collect();
    let outputs: BTreeSet<u64> = driven.intersection(&read_outside).copied().collect();
    let mut taken = BTreeSet::new();
    let ins = name_ports(top, &inputs, &mut taken);
    let outs = name_ports(top, &outputs, &mut taken);
    let range = |w: usize| if w == 1 { String::new() } else { format!("[{}:0] ", w - 1) };
    let net = |b: &Value| match b.as_u64() {
        Some(x) => format!("cosim_b{x}"),
        None => format!("1'b{}", b.as_str().unwrap_or("x")),
    };
    let cat = |bits: &[Value]| format!("{{{}}}", bits.iter().rev().map(net).collect::<Vec<_>>().join(", "));
    let mut v = format!("module {SCOPE_MODULE} (\n");
    let mut decl: Vec<String> = ins.iter().map(|(n, b)| format!("    input wire {}{n}", range(b.len()))).collect();
    decl.extend(outs.iter().map(|(n, b)| format!("    output wire {}{n}", range(b.len()))));
    v += &decl.join(",\n");
    v += "\n);\n";
    let all: BTreeSet<u64> = driven.union(&read).copied().collect();
    for x in &all {
        v += &format!("    wire cosim_b{x};\n");
    }
    let as_values = |b: &[u64]| b.iter().map(|x| Value::from(*x)).collect::<Vec<_>>();
    for (n, b) in &ins {
        v += &format!("    assign {} = {n};\n", cat(&as_values(b)));
    }
    for (n, b) in &outs {
        v += &format!("    assign {n} = {};\n", cat(&as_values(b)));
    }
    for k in scope.instances() {
        let c = &cells[k];
        let conns: Vec<String> = c["connections"]
            .as_object()
            .into_iter()
            .flatten()
            .map(|(p, bits)| format!(".{}({})", escaped(p), cat(bits.as_array().map(Vec::as_slice).unwrap_or(&[]))))
            .collect();
        v += &format!("    {} {} ({});\n", escaped(c["type"].as_str().unwrap_or("")), escaped(k), conns.join(", "));
    }
    v += "endmodule\n";
    Ok((v, outputs.len(), inputs.len()))
}

/// Checks mutation `m` in `scope` (instances of the top `src.top`), from
/// reset, as [`reset_proof::check_in_module`] checks it in its module.
pub fn check_in_scope(src: &CoreSources, m: &Mutation, scope: &Scope, opts: &FormalOptions, work: &Path) -> Result<ScopeCheck, InstrumentError> {
    let t0 = Instant::now();
    std::fs::create_dir_all(work).map_err(io(format!("creating {}", work.display())))?;
    let work = &std::path::absolute(work).map_err(io(format!("resolving {}", work.display())))?;
    let design = hierarchy(src, work)?;
    let label = scope.describe(&design, &src.top);
    let dir = work.join(format!("mutant-{}", m.id)).join(format!("scope-{}", scope.instances().join("+")));
    std::fs::create_dir_all(&dir).map_err(io(format!("creating {}", dir.display())))?;
    let (text, compared, free) = scope_verilog(&design, &src.top, scope).map_err(|message| InstrumentError::Yosys { step: "scope".into(), message })?;
    let file = dir.join("scope.v");
    std::fs::write(&file, text).map_err(io(format!("writing {}", file.display())))?;
    let files = sources(src)?;
    // Up to `prep` exactly as the mutants' build (the same cell names), then
    // the scope flattened: its cells are named as in the flattened top.
    let head = format!(
        "{read}\nhierarchy -top {top}\nprep -top {top}\nread_verilog {file}\nhierarchy -top {SCOPE_MODULE}\nflatten\nopt_clean\n",
        read = read_command(src, &files),
        top = src.top,
        file = file.display()
    );
    yosys_logged(&format!("{head}write_json scope.json\n"), &dir, "scope", false)?;
    let json = dir.join("scope.json");
    let built: Value = serde_json::from_str(&std::fs::read_to_string(&json).map_err(io(format!("reading {}", json.display())))?)
        .map_err(|e| InstrumentError::Io { what: json.display().to_string(), source: std::io::Error::other(e) })?;
    if built["modules"][SCOPE_MODULE]["cells"].get(&m.cell).is_none() {
        return Err(InstrumentError::Yosys { step: "scope".into(), message: format!("{} is not a cell of the scope {label}", m.cell) });
    }
    let sports = ports(&built, SCOPE_MODULE);
    let clks = clocks(&built, SCOPE_MODULE, &sports);
    if clks.len() > 1 {
        return Ok(ScopeCheck {
            scope: scope.clone(),
            label: label.clone(),
            verdict: FormalVerdict::Unknown { why: format!("{label}: more than one clock ({})", clks.join(", ")) },
            seconds: t0.elapsed().as_secs_f64(),
        });
    }
    let clock = clks.first().map(String::as_str);
    let reset = reset_port(&sports);
    let assumed = format!(
        "{label}, other modules cut: the {free} bits the scope reads from them or from the top's inputs free inputs, the same in both copies, the {compared} bits the scope drives into them or to the top's outputs compared; {}",
        match (&reset, clock) {
            (Some((r, _)), Some(c)) => format!("{r} forced in the first {c} cycle, unreset registers zero in both copies"),
            (None, Some(_)) => "no reset input: from all registers zero".to_string(),
            (_, None) => "combinational (no clock)".to_string(),
        }
    );
    let plain = Miter { module: SCOPE_MODULE, label: &label, cell: &m.cell, m, opts, ports: &sports, clock, reset: reset.as_ref(), assumed };
    let verdict = reset_proof::verdict_with_shared_undef(plain, &dir, &head)?;
    Ok(ScopeCheck { scope: scope.clone(), label, verdict, seconds: t0.elapsed().as_secs_f64() })
}

/// The widened checks of mutant `m` after its per-module check did not prove
/// it: each of [`candidate_scopes`] (or `scope` if given) until one proves
/// it. Empty when the mutated cell is in the top's own logic or its module
/// has no sibling driver.
pub fn check_widened(src: &CoreSources, m: &Mutation, scope: Option<&Scope>, opts: &FormalOptions, work: &Path) -> Result<Vec<ScopeCheck>, InstrumentError> {
    std::fs::create_dir_all(work).map_err(io(format!("creating {}", work.display())))?;
    let work = &std::path::absolute(work).map_err(io(format!("resolving {}", work.display())))?;
    let scopes = match scope {
        Some(s) => vec![s.clone()],
        None => {
            let design = hierarchy(src, work)?;
            match mutated_instance(&design, &src.top, &m.cell) {
                Some(inst) => candidate_scopes(&design, &src.top, &inst),
                None => Vec::new(),
            }
        }
    };
    let mut out = Vec::new();
    for s in scopes {
        let c = check_in_scope(src, m, &s, opts, work)?;
        let proved = matches!(c.verdict, FormalVerdict::Equivalent { .. });
        out.push(c);
        if proved {
            break;
        }
    }
    Ok(out)
}

/// The verdict to report from a per-module verdict and the widened checks
/// after it: a proof in any scope; else, if every scope refuted it, the
/// first scope's difference (with the cut modules' outputs free, as the
/// per-module one); else (a scope without a verdict) no verdict, every
/// scope's result in the reason. The scope is named in every case.
pub fn combine(module: &str, per_module: FormalVerdict, widened: &[ScopeCheck]) -> FormalVerdict {
    if let Some(c) = widened.iter().find(|c| matches!(c.verdict, FormalVerdict::Equivalent { .. })) {
        return c.verdict.clone();
    }
    if !widened.is_empty() && widened.iter().all(|c| matches!(c.verdict, FormalVerdict::ModuleDiffers { .. })) {
        return widened[0].verdict.clone();
    }
    if widened.is_empty() {
        return per_module;
    }
    let tried: Vec<String> = widened.iter().map(|c| format!("{}: {}", c.label, c.verdict.describe())).collect();
    match per_module {
        FormalVerdict::Unknown { why } => FormalVerdict::Unknown { why: format!("{module} alone: {why}; widened: {}", tried.join("; ")) },
        other => FormalVerdict::Unknown { why: format!("{module} alone: {}; widened: {}", other.describe(), tried.join("; ")) },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// top: u_m reads a (from u_small), b (from u_big), c (from u_fast, on
    /// another clock); u_m's y goes to u_small (inside the scope) and to
    /// u_read (cut); u_read drives nothing u_m reads.
    fn design() -> Value {
        let dff = |clk: u64, q: &[u64]| serde_json::json!({"type": "$dff", "port_directions": {"CLK": "input", "Q": "output"}, "connections": {"CLK": [clk], "Q": q}});
        let port = |d: &str, bits: &[u64]| serde_json::json!({"direction": d, "bits": bits});
        let inst = |ty: &str, dirs: Value, conns: Value| serde_json::json!({"type": ty, "port_directions": dirs, "connections": conns});
        serde_json::json!({"modules": {
            "top": {
                "ports": {"clk": port("input", &[2]), "clk2": port("input", &[3]), "z": port("output", &[9])},
                "netnames": {"clk": {"hide_name": 0, "bits": [2]}, "a": {"hide_name": 0, "bits": [4]}, "y": {"hide_name": 0, "bits": [7]}},
                "cells": {
                    "u_m": inst("m", serde_json::json!({"clk": "input", "a": "input", "b": "input", "c": "input", "y": "output"}), serde_json::json!({"clk": [2], "a": [4], "b": [5], "c": [6], "y": [7]})),
                    "u_small": inst("small", serde_json::json!({"clk": "input", "y": "input", "a": "output"}), serde_json::json!({"clk": [2], "y": [7], "a": [4]})),
                    "u_big": inst("big", serde_json::json!({"clk": "input", "b": "output"}), serde_json::json!({"clk": [2], "b": [5]})),
                    "u_fast": inst("fast", serde_json::json!({"clk": "input", "c": "output"}), serde_json::json!({"clk": [3], "c": [6]})),
                    "u_read": inst("read", serde_json::json!({"clk": "input", "y": "input", "z": "output"}), serde_json::json!({"clk": [2], "y": [7], "z": [9]}))
                }
            },
            "m": {"ports": {"clk": port("input", &[2])}, "cells": {"$procdff$1": dff(2, &[10])}},
            "small": {"ports": {"clk": port("input", &[2])}, "cells": {"r": dff(2, &[10])}},
            "big": {"ports": {"clk": port("input", &[2])}, "cells": {"r": dff(2, &[10, 11, 12])}},
            "fast": {"ports": {"clk": port("input", &[2])}, "cells": {"r": dff(2, &[10])}},
            "read": {"ports": {"clk": port("input", &[2])}, "cells": {"r": dff(2, &[10])}}
        }})
    }

    #[test]
    fn scopes_are_the_drivers_on_the_same_clock_smallest_first() {
        let d = design();
        assert_eq!(mutated_instance(&d, "top", "$flatten\\u_m.$procdff$1"), Some("u_m".into()));
        assert_eq!(mutated_instance(&d, "top", "u_m.mem"), Some("u_m".into()));
        assert_eq!(mutated_instance(&d, "top", "$flatten\\u_nope.$x"), None);
        let s = candidate_scopes(&d, "top", "u_m");
        let with: Vec<&str> = s.iter().map(|s| s.with[0].as_str()).collect();
        assert_eq!(with, ["u_small", "u_big"], "u_fast is on another clock, u_read drives nothing u_m reads");
    }

    #[test]
    fn the_scope_compares_what_it_drives_into_cut_modules_only() {
        let d = design();
        let (v, compared, free) = scope_verilog(&d, "top", &Scope { mutated: "u_m".into(), with: vec!["u_small".into()] }).unwrap();
        // y (bit 7) is read by u_read (cut): compared; a (bit 4) only inside the scope: not a port
        assert_eq!(compared, 1, "{v}");
        assert!(v.contains("output wire y") && !v.contains("input wire a") && !v.contains("output wire a"), "{v}");
        // clk, b and c (from the cut u_big and u_fast) are free inputs
        assert_eq!(free, 3, "{v}");
        assert!(v.contains("input wire clk") && v.contains("m u_m (") && v.contains("small u_small ("), "{v}");
    }

    #[test]
    fn a_proof_in_any_scope_wins_a_difference_needs_every_scope() {
        let sc = |v: FormalVerdict| ScopeCheck { scope: Scope { mutated: "u_m".into(), with: vec![] }, label: "top scope u_m".into(), verdict: v, seconds: 1.0 };
        let diff = || FormalVerdict::ModuleDiffers { module: "top scope u_m".into(), steps: 3, trace: vec![], assumed: String::new() };
        let unknown = || FormalVerdict::Unknown { why: "bounded".into() };
        let proved = || FormalVerdict::Equivalent { method: "pdr".into() };
        assert_eq!(combine("m", diff(), &[sc(diff()), sc(proved())]), proved());
        assert_eq!(combine("m", unknown(), &[sc(diff()), sc(diff())]), diff());
        let FormalVerdict::Unknown { why } = combine("m", diff(), &[sc(unknown()), sc(diff())]) else { panic!("one scope without a verdict") };
        assert!(why.starts_with("m alone: differs") && why.contains("top scope u_m: unknown: bounded") && why.contains("top scope u_m: differs"), "{why}");
        assert_eq!(combine("m", diff(), &[]), diff(), "no scope: the per-module verdict");
    }
}
