//! VHDL sources of an external core, through GHDL: the
//! `.vhd`/`.vhdl` files are analysed in dependency order (`ghdl
//! --elab-order`, or the order a profile's `[vhdl] files` gives), the VHDL
//! top (or each VHDL entity the Verilog sources instantiate) is turned
//! into Verilog with `ghdl --synth --out=verilog`, and that Verilog joins
//! the core's own `.v`/`.sv` files for Verilator, as any external core.
//! The GHDL step is cached like the Verilator one (`buildcache`, keyed on
//! the VHDL sources, the options and GHDL's version).
//!
//! Needs GHDL with `--synth` (Debian 12's `ghdl` 2.0.0, mcode back end,
//! has it). GHDL lower-cases VHDL names: the module and its ports are the
//! entity's names in lower case, so a profile's `[ports]` names them so.

use std::path::{Path, PathBuf};
use std::process::Command;

pub use crate::error::VhdlError;
use crate::error::BridgeError;
pub use crate::external::{VhdlOptions, VhdlStandard};
use crate::external::ExternalCore;

fn is_vhdl(p: &Path) -> bool {
    matches!(p.extension().and_then(|e| e.to_str()), Some("vhd" | "vhdl"))
}

fn is_verilog(p: &Path) -> bool {
    matches!(p.extension().and_then(|e| e.to_str()), Some("v" | "sv"))
}

fn resolve(dir: &Path, f: &Path) -> PathBuf {
    if f.is_absolute() { f.to_path_buf() } else { dir.join(f) }
}

/// The core's sources split into (Verilog, VHDL): its `files` (and the
/// profile's `[vhdl] files`) when given, else the directory's.
fn split_sources(core: &ExternalCore) -> std::io::Result<(Vec<PathBuf>, Vec<PathBuf>)> {
    let listed: Vec<PathBuf> = if core.files.is_empty() {
        let mut v: Vec<PathBuf> =
            std::fs::read_dir(&core.dir)?.filter_map(|e| e.ok().map(|e| e.path())).collect();
        v.sort();
        v
    } else {
        core.files.iter().map(|f| resolve(&core.dir, f)).collect()
    };
    let verilog = listed.iter().filter(|p| is_verilog(p)).cloned().collect();
    let vhdl = if core.vhdl.files.is_empty() {
        listed.into_iter().filter(|p| is_vhdl(p)).collect()
    } else {
        core.vhdl.files.iter().map(|f| resolve(&core.dir, f)).collect()
    };
    Ok((verilog, vhdl))
}

/// Entity names declared in VHDL text (lower case; comments skipped).
fn entities(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in text.lines() {
        let code = line.split("--").next().unwrap_or("").to_ascii_lowercase();
        let words: Vec<&str> = code
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .filter(|w| !w.is_empty())
            .collect();
        for w in words.windows(3) {
            if w[0] == "entity" && w[2] == "is" {
                out.push(w[1].to_string());
            }
        }
    }
    out
}

fn words(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '$')).filter(|w| !w.is_empty())
}

/// True when the core has VHDL sources to go through GHDL.
pub fn has_vhdl(core: &ExternalCore) -> bool {
    split_sources(core).map(|(_, vhdl)| !vhdl.is_empty()).unwrap_or(false)
}

/// [`ExternalCore::check`] for a core with VHDL: the files exist and the
/// top is a VHDL entity or a Verilog module. `None`: no VHDL here.
pub(crate) fn check(core: &ExternalCore) -> Option<Result<(), BridgeError>> {
    let (verilog, vhdl) = split_sources(core).ok()?;
    if vhdl.is_empty() {
        return None;
    }
    let bad = |problem: String| BridgeError::BadSources { dir: core.dir.display().to_string(), problem };
    let mut found = false;
    let top = core.top.to_ascii_lowercase();
    for f in vhdl.iter().chain(&verilog) {
        let text = match std::fs::read(f) {
            Ok(t) => String::from_utf8_lossy(&t).into_owned(),
            Err(e) => return Some(Err(bad(format!("{}: cannot be read ({e})", f.display())))),
        };
        found |= if is_vhdl(f) {
            entities(&text).contains(&top)
        } else {
            words(&text).collect::<Vec<_>>().windows(2).any(|w| w[0] == "module" && w[1] == core.top)
        };
    }
    Some(if found {
        Ok(())
    } else {
        Err(bad(format!(
            "no `entity {}` (VHDL) or `module {}` (Verilog) in its {} source file(s); give the top with --top",
            core.top,
            core.top,
            vhdl.len() + verilog.len()
        )))
    })
}

/// GHDL's output reduced to its first diagnostic line (`file:line:col:
/// message`) and a count of the rest.
fn ghdl_failure(step: String, standard: VhdlStandard, out: &std::process::Output) -> VhdlError {
    let text = format!("{}{}", String::from_utf8_lossy(&out.stderr), String::from_utf8_lossy(&out.stdout));
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    // A located message first ("f.vhd:4:14: ..."), else GHDL's own line.
    let first = lines
        .iter()
        .position(|l| {
            let mut p = l.splitn(3, ':');
            p.next().is_some_and(|f| !f.is_empty()) && p.next().is_some_and(|n| n.trim().parse::<u32>().is_ok())
        })
        .or(if lines.is_empty() { None } else { Some(0) });
    let (first, rest) = match first {
        Some(i) => (lines[i].trim().to_string(), lines.len() - 1),
        None => (format!("GHDL exited with {} and said nothing", out.status), 0),
    };
    VhdlError::Ghdl {
        step,
        standard: standard.describe(),
        first,
        more: if rest > 0 { format!(" (and {rest} more line(s) from GHDL)") } else { String::new() },
    }
}

/// `ghdl <command> --workdir=W <rest>` (GHDL takes options before files).
fn ghdl(args: &[String], workdir: &Path) -> std::io::Result<std::process::Output> {
    let (command, rest) = args.split_first().expect("a GHDL command");
    Command::new("ghdl").arg(command).arg(format!("--workdir={}", workdir.display())).args(rest).output()
}

fn fnv1a(h: &mut u64, bytes: &[u8]) {
    for b in bytes {
        *h ^= *b as u64;
        *h = h.wrapping_mul(0x100_0000_01b3);
    }
}

/// The core with its VHDL turned into Verilog: the same directory,
/// defines and includes, `files` = its Verilog sources plus GHDL's output
/// (cached in `cache`), top lower-cased if it is a VHDL entity. `None`:
/// the core has no VHDL.
pub fn lower(core: &ExternalCore, cache: &Path) -> Result<Option<ExternalCore>, BridgeError> {
    let (verilog, vhdl) = split_sources(core).map_err(|e| BridgeError::Io {
        context: format!("reading core directory {}", core.dir.display()),
        source: e,
    })?;
    if vhdl.is_empty() {
        return Ok(None);
    }
    let dir = core.dir.display().to_string();
    let version = Command::new("ghdl").arg("--version").output();
    let version = match version {
        Ok(o) if o.status.success() => o.stdout,
        _ => return Err(VhdlError::NoGhdl { dir }.into()),
    };
    // The roots: the top if it is a VHDL entity, else every VHDL entity a
    // Verilog source names (a mixed design with a Verilog top).
    let mut all_entities = Vec::new();
    for f in &vhdl {
        let t = std::fs::read(f).map_err(|e| BridgeError::Io { context: format!("reading {}", f.display()), source: e })?;
        all_entities.extend(entities(&String::from_utf8_lossy(&t)));
    }
    let top_lc = core.top.to_ascii_lowercase();
    let roots: Vec<String> = if all_entities.contains(&top_lc) {
        vec![top_lc.clone()]
    } else {
        let mut named = std::collections::BTreeSet::new();
        for f in &verilog {
            let t = std::fs::read(f).map_err(|e| BridgeError::Io { context: format!("reading {}", f.display()), source: e })?;
            let t = String::from_utf8_lossy(&t).into_owned();
            named.extend(words(&t).map(str::to_ascii_lowercase).filter(|w| all_entities.contains(w)));
        }
        named.into_iter().collect()
    };
    if roots.is_empty() {
        return Err(VhdlError::NoRoot { dir, top: core.top.clone(), entities: all_entities.join(", ") }.into());
    }
    let std_flag = core.vhdl.standard.ghdl_flag().to_string();
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for f in &vhdl {
        fnv1a(&mut h, f.display().to_string().as_bytes());
        fnv1a(&mut h, &std::fs::read(f).unwrap_or_default());
    }
    fnv1a(&mut h, format!("{std_flag} {:?} {roots:?} {}", core.vhdl.ghdl_args, core.vhdl.files.is_empty()).as_bytes());
    fnv1a(&mut h, &version);
    let entry_dir = cache.join(format!("ghdl-{}-{h:016x}", roots.join("+")));
    let product = "ghdl_synth.v";
    let entry = buildcache::build_once(&entry_dir, product, |work| {
        synthesise(core, &vhdl, &roots, work, product)
    })
    .map_err(|e| match e {
        buildcache::Error::Build(e) => e,
        buildcache::Error::Io { what, source } => BridgeError::Io { context: what, source },
    })?;
    let mut files = verilog;
    files.push(entry.product);
    Ok(Some(ExternalCore {
        top: if roots == [top_lc.clone()] { top_lc } else { core.top.clone() },
        files,
        vhdl: VhdlOptions::default(),
        ..core.clone()
    }))
}

/// Analyses `vhdl` in dependency order in `work` and writes the Verilog
/// of every root to `work/product`.
fn synthesise(core: &ExternalCore, vhdl: &[PathBuf], roots: &[String], work: &Path, product: &str) -> Result<(), BridgeError> {
    let o = &core.vhdl;
    let lib = work.join("ghdl-work");
    std::fs::create_dir_all(&lib).map_err(|e| BridgeError::Io { context: format!("creating {}", lib.display()), source: e })?;
    let base: Vec<String> = std::iter::once(o.standard.ghdl_flag().to_string()).chain(o.ghdl_args.iter().cloned()).collect();
    let io = |e: std::io::Error| BridgeError::Io { context: "running ghdl".into(), source: e };
    let failed = |step: String, out: &std::process::Output| BridgeError::from(ghdl_failure(step, o.standard, out));
    // Analysis order: the profile's, else GHDL's own from an import of every file.
    let order: Vec<PathBuf> = if !o.files.is_empty() {
        vhdl.to_vec()
    } else {
        let mut args = vec!["-i".to_string()];
        args.extend(base.iter().cloned());
        args.extend(vhdl.iter().map(|f| f.display().to_string()));
        let out = ghdl(&args, &lib).map_err(io)?;
        if !out.status.success() {
            return Err(failed("read the VHDL files".into(), &out));
        }
        let mut order: Vec<PathBuf> = Vec::new();
        for r in roots {
            let mut args = vec!["--elab-order".to_string()];
            args.extend(base.iter().cloned());
            args.push(r.clone());
            let out = ghdl(&args, &lib).map_err(io)?;
            if !out.status.success() {
                return Err(failed(format!("order the VHDL of `{r}`"), &out));
            }
            for l in String::from_utf8_lossy(&out.stdout).lines().map(str::trim).filter(|l| !l.is_empty()) {
                let p = PathBuf::from(l);
                if !order.contains(&p) {
                    order.push(p);
                }
            }
        }
        order
    };
    for f in &order {
        let mut args = vec!["-a".to_string()];
        args.extend(base.iter().cloned());
        args.push(f.display().to_string());
        let out = ghdl(&args, &lib).map_err(io)?;
        if !out.status.success() {
            return Err(failed(format!("analyse {}", f.display()), &out));
        }
    }
    let mut verilog = String::from("// Written by cosim::vhdl (ghdl --synth --out=verilog); do not edit.\n");
    for r in roots {
        let mut args = vec!["--synth".to_string()];
        args.extend(base.iter().cloned());
        args.extend(["--out=verilog".to_string(), r.clone()]);
        let out = ghdl(&args, &lib).map_err(io)?;
        if !out.status.success() {
            return Err(failed(format!("synthesise `{r}`"), &out));
        }
        verilog.push_str(&String::from_utf8_lossy(&out.stdout));
    }
    std::fs::write(work.join(product), verilog).map_err(|e| BridgeError::Io { context: format!("writing {product}"), source: e })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entity_scan_skips_comments_and_lowercases() {
        let t = "-- entity fake is\nENTITY Can_Top IS port (a : in bit); end;\nentity sub is end entity;";
        assert_eq!(entities(t), vec!["can_top".to_string(), "sub".to_string()]);
    }

    #[test]
    fn standards_by_name() {
        assert_eq!(VhdlStandard::from_name("08"), Some(VhdlStandard::V08));
        assert_eq!(VhdlStandard::from_name("2008"), Some(VhdlStandard::V08));
        assert_eq!(VhdlStandard::from_name("93").map(VhdlStandard::ghdl_flag), Some("--std=93"));
        assert_eq!(VhdlStandard::default().ghdl_flag(), "--std=93c");
        assert_eq!(VhdlStandard::from_name("95"), None);
    }
}
