//! The bounded formal check of a survivor with yosys: a miter of the
//! original (select 0) and the mutant (select fixed at its id), every clock
//! a free input (`clk2fflogic`), registers from zero. A bounded check
//! (`sat -seq N`) either finds an input trace after which an output differs
//! (the trace is turned into a scenario skeleton) or none; then temporal
//! induction may prove the two equivalent from any reachable state.

use crate::instrument::{InstrumentError, Instrumented, SELECT, yosys_logged};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Bounds of the check.
#[derive(Clone, Copy, Debug)]
pub struct FormalOptions {
    /// Time steps of the bounded check (each clock edge is one step or more).
    pub steps: u32,
    /// Induction depth tried after a bounded check found nothing.
    pub induction: u32,
    /// Seconds a single SAT call may take.
    pub timeout_s: u32,
}

impl Default for FormalOptions {
    fn default() -> Self {
        FormalOptions { steps: 20, induction: 20, timeout_s: 60 }
    }
}

/// One input of a counterexample at one step.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct TraceValue {
    /// Step from 1.
    pub step: u32,
    /// Input port of the core.
    pub port: String,
    /// Its value.
    pub value: u64,
}

/// What the formal check says about a survivor.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "formal", rename_all = "kebab-case")]
pub enum FormalVerdict {
    /// Proved: no input sequence from reset-to-zero makes an output differ.
    Equivalent {
        /// How (e.g. "temporal induction, depth 3").
        method: String,
    },
    /// An input trace makes an output differ: a test can kill it.
    Differs {
        /// Steps of the trace.
        steps: u32,
        /// The core's inputs, step by step.
        trace: Vec<TraceValue>,
    },
    /// The outputs of the mutated module differ from the original's after
    /// reset for some input sequence at its ports (reset_proof.rs); whether
    /// the rest of the core can drive those inputs is not checked.
    ModuleDiffers {
        /// The module checked alone.
        module: String,
        /// Steps of the trace.
        steps: u32,
        /// The module's inputs, step by step (empty when only a bounded
        /// check found the difference).
        trace: Vec<TraceValue>,
        /// What the check assumed.
        assumed: String,
    },
    /// Neither within the bounds.
    Unknown {
        /// What was tried.
        why: String,
    },
}

impl FormalVerdict {
    /// In words, for the report.
    pub fn describe(&self) -> String {
        match self {
            FormalVerdict::Equivalent { method } => format!("equivalent ({method})"),
            FormalVerdict::Differs { steps, .. } => format!("differs: counterexample of {steps} steps (scenario skeleton written)"),
            FormalVerdict::ModuleDiffers { module, steps, .. } => {
                format!("differs at the ports of {module} after reset ({steps} clocks, its inputs free; not shown reachable in the core)")
            }
            FormalVerdict::Unknown { why } => format!("unknown: {why}"),
        }
    }
}

/// The miter script up to the `sat` call.
fn miter_script(inst: &Instrumented, id: u32) -> String {
    let w = inst.select_width;
    let top = &inst.top;
    format!(
        "read_verilog {v}\nproc\n\
         copy {top} cosim_gate\n\
         rename {top} cosim_gold\n\
         delete -port cosim_gold/{SELECT} cosim_gate/{SELECT}\n\
         cd cosim_gold\nconnect -set {SELECT} {w}'d0\ncd ..\n\
         cd cosim_gate\nconnect -set {SELECT} {w}'d{id}\ncd ..\n\
         memory\nopt_clean\nclk2fflogic\n\
         miter -equiv -flatten -make_outputs cosim_gold cosim_gate cosim_miter\n\
         hierarchy -top cosim_miter\nopt_clean\n",
        v = inst.verilog.display()
    )
}

/// Parses `sat -show-inputs` tables: `  <step> \in_<port>  <hex> <dec> <bin>`.
pub(crate) fn parse_trace(text: &str) -> Vec<TraceValue> {
    let mut out = Vec::new();
    for l in text.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        if w.len() >= 3
            && let Ok(step) = w[0].parse::<u32>()
            && let Some(port) = w[1].trim_start_matches('\\').strip_prefix("in_")
        {
            let bin = w.last().copied().unwrap_or("");
            let value = u64::from_str_radix(&bin.replace(['x', 'z'], "0"), 2).unwrap_or(0);
            out.push(TraceValue { step, port: port.to_string(), value });
        }
    }
    out
}

/// Checks mutant `id` of `inst` (a survivor), working in `work`.
pub fn check(inst: &Instrumented, id: u32, opts: &FormalOptions, work: &Path) -> Result<FormalVerdict, InstrumentError> {
    std::fs::create_dir_all(work).map_err(|source| InstrumentError::Io { what: format!("creating {}", work.display()), source })?;
    let base = miter_script(inst, id);
    let bmc = format!(
        "{base}sat -seq {} -prove trigger 0 -set-init-zero -show-inputs -timeout {} cosim_miter\n",
        opts.steps, opts.timeout_s
    );
    // A yosys failure here (a solver out of its depth) leaves the survivor unknown.
    let text = match yosys_logged(&bmc, work, &format!("bmc {id}"), true) {
        Ok(t) => t,
        Err(InstrumentError::Yosys { message, .. }) => return Ok(FormalVerdict::Unknown { why: format!("yosys stopped: {}", message.lines().last().unwrap_or("")) }),
        Err(e) => return Err(e),
    };
    if text.contains("model found: FAIL") {
        let trace = parse_trace(&text);
        let steps = trace.iter().map(|t| t.step).max().unwrap_or(0);
        return Ok(FormalVerdict::Differs { steps, trace });
    }
    if !text.contains("no model found: SUCCESS") {
        return Ok(FormalVerdict::Unknown { why: format!("bounded check of {} steps timed out after {} s", opts.steps, opts.timeout_s) });
    }
    let ind = format!(
        "{base}sat -tempinduct -prove trigger 0 -set-init-zero -seq 1 -maxsteps {} -timeout {} cosim_miter\n",
        opts.induction, opts.timeout_s
    );
    let text = match yosys_logged(&ind, work, &format!("induction {id}"), true) {
        Ok(t) => t,
        Err(InstrumentError::Yosys { message, .. }) => return Ok(FormalVerdict::Unknown { why: format!("no difference within {} steps; induction stopped: {}", opts.steps, message.lines().last().unwrap_or("")) }),
        Err(e) => return Err(e),
    };
    if text.contains("Induction step proven: SUCCESS") {
        let depth = text.lines().filter(|l| l.contains("Trying induction with length")).count();
        return Ok(FormalVerdict::Equivalent { method: format!("temporal induction, depth {}", depth.max(1)) });
    }
    Ok(FormalVerdict::Unknown { why: format!("no difference within {} steps; induction to depth {} inconclusive", opts.steps, opts.induction) })
}

/// A scenario skeleton (our TOML format) from a counterexample on a core
/// with the `can_top` Wishbone ports: the trace's Wishbone write and read
/// cycles in order, rx_i levels in a comment. Clock phases in the trace are
/// free (both clocks are inputs of the check), so the skeleton is a start
/// to tune, not a replay; `None` when the trace has no Wishbone port.
pub fn skeleton(id: u32, location: &str, description: &str, trace: &[TraceValue]) -> String {
    let steps = trace.iter().map(|t| t.step).max().unwrap_or(0);
    let at = |step: u32, port: &str| trace.iter().find(|t| t.step == step && t.port == port).map(|t| t.value);
    let mut lines = Vec::new();
    let mut rx = String::new();
    let mut other = Vec::new();
    let wishbone = trace.iter().any(|t| t.port == "wb_stb_i");
    let mut last: Option<(u64, u64, u64)> = None;
    for s in 1..=steps {
        if let Some(v) = at(s, "rx_i") {
            rx.push(if v == 0 { '0' } else { '1' });
        }
        if wishbone {
            let cyc = at(s, "wb_cyc_i").unwrap_or(0) & at(s, "wb_stb_i").unwrap_or(0);
            let (we, adr, dat) = (at(s, "wb_we_i").unwrap_or(0), at(s, "wb_adr_i").unwrap_or(0), at(s, "wb_dat_i").unwrap_or(0));
            let acc = (we, adr, if we == 1 { dat } else { 0 });
            if cyc == 1 && last != Some(acc) {
                lines.push(if we == 1 {
                    format!("    {{ write = 0x{adr:02X}, value = 0x{dat:02X}, note = \"counterexample step {s}\" }},")
                } else {
                    format!("    {{ read = 0x{adr:02X}, note = \"counterexample step {s}: add the expected value\" }},")
                });
            }
            last = if cyc == 1 { Some(acc) } else { None };
        } else {
            let vals: Vec<String> = trace.iter().filter(|t| t.step == s).map(|t| format!("{}={}", t.port, t.value)).collect();
            other.push(format!("#   step {s}: {}", vals.join(" ")));
        }
    }
    let mut t = format!(
        "# Skeleton from the formal counterexample of mutant {id} ({location}: {description}).\n\
         # After these {steps} steps (both clocks free inputs, registers from zero) an\n\
         # output of the mutant differs from the original. Add the clocks, bit timing,\n\
         # nodes and [expect] that make the difference visible, then add the file to\n\
         # tb/regression.list.\n"
    );
    if !rx.is_empty() {
        t += &format!("# rx_i per step: {rx}\n");
    }
    for o in other {
        t += &o;
        t += "\n";
    }
    t += &format!(
        "purpose = \"Kills mutant {id}: {location}: {}\"\nverifies = [\"TODO: the behaviour {location} implements\"]\nsequence = [\"The host accesses of the counterexample\"]\n\n[dut]\nkind = \"rtl\"\n\n[run]\nmax_bits = 2000\n\n",
        description.replace('"', "'")
    );
    if lines.is_empty() {
        t += "[[step]]\nwait_bits = 100\nnote = \"the counterexample has no host access: drive rx_i as above\"\n";
    } else {
        t += "step = [\n";
        t += &lines.join("\n");
        t += "\n]\n";
    }
    t
}
