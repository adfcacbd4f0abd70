//! Yosys: the core's sources flattened, a seeded list of mutations, and one
//! Verilog file holding every mutation behind a run-time select input (the
//! way mcy builds its mutants), cached by a hash of everything that feeds it.

use crate::mutation::Mutation;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Name of the select input every mutation is keyed on (0 = the original).
pub const SELECT: &str = "cosim_mutsel";

/// A core's sources as yosys and Verilator read them.
#[derive(Clone, Debug, Default)]
pub struct CoreSources {
    /// Directory (include directory too).
    pub dir: PathBuf,
    /// Top module.
    pub top: String,
    /// Source files; empty means every `*.v` / `*.sv` in `dir`.
    pub files: Vec<PathBuf>,
    /// `NAME` or `NAME=VALUE` macros.
    pub defines: Vec<String>,
    /// Extra include directories.
    pub include_dirs: Vec<PathBuf>,
}

/// Where the mutations come from.
#[derive(Clone, Debug)]
pub enum MutationSource {
    /// `mutate -list count -seed seed`.
    Sample {
        /// How many.
        count: u32,
        /// RNG seed.
        seed: u64,
    },
    /// A saved list (lines of `mutate ...`, as `mutate -list` writes them).
    Saved(PathBuf),
}

/// What went wrong preparing the mutants.
#[derive(Debug, thiserror::Error)]
pub enum InstrumentError {
    /// Yosys is not installed.
    #[error("`yosys` was not found: install it (apt-get install yosys, or scripts/setup.sh)")]
    NoYosys,
    /// Yosys rejected a script.
    #[error("yosys failed ({step}):\n{message}")]
    Yosys {
        /// Which step.
        step: String,
        /// Its last lines.
        message: String,
    },
    /// A saved list line is not a mutation.
    #[error("{file}:{line}: {message}")]
    BadList {
        /// List file.
        file: String,
        /// Line number from 1.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// File-system trouble.
    #[error("{what}: {source}")]
    Io {
        /// What was being done.
        what: String,
        /// The error.
        source: std::io::Error,
    },
}

fn io(what: impl Into<String>) -> impl FnOnce(std::io::Error) -> InstrumentError {
    let what = what.into();
    move |source| InstrumentError::Io { what, source }
}

/// The mutants, built once.
#[derive(Clone, Debug)]
pub struct Instrumented {
    /// Cache entry directory.
    pub dir: PathBuf,
    /// The Verilog of the flattened core with every mutation behind [`SELECT`].
    pub verilog: PathBuf,
    /// The flattened original (RTLIL), for the formal check.
    pub design: PathBuf,
    /// Top module.
    pub top: String,
    /// Width of the select input.
    pub select_width: u32,
    /// Every mutation listed.
    pub mutations: Vec<Mutation>,
    /// Mutations yosys could not apply: (id, its words).
    pub build_errors: Vec<(u32, String)>,
}

impl Instrumented {
    /// The external core Verilator builds (once) from the mutated Verilog.
    pub fn external_core(&self) -> cosim::ExternalCore {
        // Every `*.v` of the entry (only mutated.v): the same cache key as the
        // scenario runner's `DutKind::External`, so one build serves both.
        cosim::ExternalCore { dir: self.dir.clone(), top: self.top.clone(), ..Default::default() }
    }
}

/// Runs a yosys script quietly; its output on failure (last 30 lines).
pub(crate) fn yosys(script: &str, cwd: &Path, step: &str) -> Result<String, InstrumentError> {
    yosys_logged(script, cwd, step, false)
}

/// [`yosys`], with the whole log returned when `log` (the `sat` tables).
pub(crate) fn yosys_logged(script: &str, cwd: &Path, step: &str, log: bool) -> Result<String, InstrumentError> {
    // absolute: yosys runs in `cwd`, so a relative `--out` would be joined twice
    let path = std::path::absolute(cwd.join(format!("{}.ys", step.replace(' ', "_")))).map_err(io(format!("resolving {}", cwd.display())))?;
    std::fs::write(&path, script).map_err(io(format!("writing {}", path.display())))?;
    let o = match Command::new("yosys").args(if log { &[][..] } else { &["-q"][..] }).arg("-s").arg(&path).current_dir(cwd).output() {
        Ok(o) => o,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(InstrumentError::NoYosys),
        Err(e) => return Err(io("running yosys")(e)),
    };
    let text = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    if o.status.success() {
        Ok(text)
    } else {
        let lines: Vec<&str> = text.lines().collect();
        Err(InstrumentError::Yosys { step: step.into(), message: lines[lines.len().saturating_sub(30)..].join("\n") })
    }
}

pub(crate) fn sources(src: &CoreSources) -> Result<Vec<PathBuf>, InstrumentError> {
    let abs = |p: &Path| if p.is_absolute() { p.to_path_buf() } else { src.dir.join(p) };
    if !src.files.is_empty() {
        return Ok(src.files.iter().map(|f| abs(f)).collect());
    }
    let mut v: Vec<PathBuf> = std::fs::read_dir(&src.dir)
        .map_err(io(format!("reading {}", src.dir.display())))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("v" | "sv")))
        .collect();
    v.sort();
    Ok(v)
}

pub(crate) fn fnv1a(h: &mut u64, bytes: &[u8]) {
    for b in bytes {
        *h ^= *b as u64;
        *h = h.wrapping_mul(0x100_0000_01b3);
    }
}

/// Bits needed for the select to count to `n`.
fn select_width(n: u32) -> u32 {
    (32 - n.leading_zeros()).max(1)
}

fn read_list(text: &str, file: &str) -> Result<Vec<Mutation>, InstrumentError> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let id = out.len() as u32 + 1;
        out.push(Mutation::parse(id, l).map_err(|message| InstrumentError::BadList { file: file.into(), line: i + 1, message })?);
    }
    Ok(out)
}

/// Lists the mutations and builds the mutated Verilog (or finds both in
/// the cache under `cache`).
pub fn instrument(src: &CoreSources, from: &MutationSource, cache: &Path) -> Result<Instrumented, InstrumentError> {
    let files = sources(src)?;
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for f in &files {
        fnv1a(&mut h, f.display().to_string().as_bytes());
        fnv1a(&mut h, &std::fs::read(f).map_err(io(format!("reading {}", f.display())))?);
    }
    fnv1a(&mut h, src.top.as_bytes());
    fnv1a(&mut h, src.defines.join(" ").as_bytes());
    let saved = match from {
        MutationSource::Sample { count, seed } => {
            fnv1a(&mut h, format!("sample {count} {seed}").as_bytes());
            None
        }
        MutationSource::Saved(p) => {
            let t = relocate(&std::fs::read_to_string(p).map_err(io(format!("reading {}", p.display())))?, &files);
            read_list(&t, &p.display().to_string())?;
            fnv1a(&mut h, t.as_bytes());
            Some(t)
        }
    };
    let ver = Command::new("yosys").arg("-V").output().map_err(|_| InstrumentError::NoYosys)?.stdout;
    fnv1a(&mut h, &ver);
    fnv1a(&mut h, include_str!("instrument.rs").as_bytes());
    let dir = cache.join(format!("mutants-{}-{h:016x}", src.top));
    let entry = buildcache::build_once(&dir, "mutated.v", |work| build(src, &files, from, saved.as_deref(), work)).map_err(|e| match e {
        buildcache::Error::Build(e) => e,
        buildcache::Error::Io { what, source } => InstrumentError::Io { what, source },
    })?;
    let list = std::fs::read_to_string(entry.dir.join("list.txt")).map_err(io("reading the mutation list"))?;
    let mutations = read_list(&list, "list.txt")?;
    let errors: Vec<(u32, String)> = serde_json::from_str(&std::fs::read_to_string(entry.dir.join("build_errors.json")).map_err(io("reading build_errors.json"))?)
        .map_err(|e| InstrumentError::Io { what: "build_errors.json".into(), source: std::io::Error::other(e) })?;
    Ok(Instrumented {
        dir: entry.dir.clone(),
        verilog: entry.product,
        design: entry.dir.join("design.il"),
        top: src.top.clone(),
        select_width: select_width(mutations.len() as u32),
        mutations,
        build_errors: errors,
    })
}

/// A saved list made in another checkout names its cells after that
/// checkout's source paths (yosys puts the path read into `$add$/old/rtl/x.v:47$557`
/// and `-src`), so none of its cells would be found here. Each path that ends
/// in the name of one of this core's files (a name no other file of the core
/// has) is moved to that file; everything else is kept as written.
pub fn relocate(list: &str, files: &[PathBuf]) -> String {
    let mut out = String::with_capacity(list.len());
    for line in list.split_inclusive('\n') {
        let mut l = line.to_string();
        for f in files {
            let Some(name) = f.file_name().and_then(|n| n.to_str()) else { continue };
            if files.iter().filter(|g| g.file_name() == f.file_name()).count() != 1 {
                continue; // ambiguous: two files of that name
            }
            let here = f.display().to_string();
            let needle = format!("/{name}:");
            let mut from = 0;
            while let Some(i) = l[from..].find(&needle).map(|i| i + from) {
                // the path starts after the delimiter yosys writes before it
                let start = l[..i].rfind([' ', '\t', '$']).map_or(0, |d| d + 1);
                let end = i + needle.len() - 1;
                if l[start..end] != here {
                    l.replace_range(start..end, &here);
                }
                from = start + here.len() + 1;
            }
        }
        out += &l;
    }
    out
}

/// The `read_verilog` line of the core (defines, include directories, files
/// in order): the formal check per module repeats it so that yosys numbers
/// the cells as in the mutants' build.
pub(crate) fn read_command(src: &CoreSources, files: &[PathBuf]) -> String {
    let mut read = String::from("read_verilog");
    for d in &src.defines {
        read += &format!(" -D{d}");
    }
    for d in std::iter::once(&src.dir).chain(&src.include_dirs) {
        let d = if d.is_absolute() { d.clone() } else { src.dir.join(d) };
        read += &format!(" -I{}", d.display());
    }
    for f in files {
        read += &format!(" {}", f.display());
    }
    read
}

fn build(src: &CoreSources, files: &[PathBuf], from: &MutationSource, saved: Option<&str>, work: &Path) -> Result<(), InstrumentError> {
    let read = read_command(src, files);
    // Flattened, so every mutation (and its select) lands in the top module.
    let prep = format!("{read}\nhierarchy -top {top}\nprep -top {top}\nflatten\nopt_clean\nwrite_rtlil design.il\n", top = src.top);
    match (from, saved) {
        (MutationSource::Sample { count, seed }, _) => {
            yosys(&format!("{prep}mutate -list {count} -seed {seed} -o list.txt\n"), work, "list")?;
        }
        (MutationSource::Saved(_), Some(t)) => {
            yosys(&prep, work, "prepare")?;
            std::fs::write(work.join("list.txt"), t).map_err(io("writing list.txt"))?;
        }
        (MutationSource::Saved(p), None) => unreachable!("saved list {} read before the build", p.display()),
    }
    let mutations = read_list(&std::fs::read_to_string(work.join("list.txt")).map_err(io("reading list.txt"))?, "list.txt")?;
    let width = select_width(mutations.len() as u32);
    let apply = |ms: &[&Mutation], write: bool| {
        let mut s = String::from("read_rtlil design.il\n");
        for m in ms {
            s += &format!("mutate -ctrl {SELECT} {width} {} {}\n", m.id, m.args);
        }
        if write {
            s += "opt_clean\nwrite_verilog -noattr mutated.v\n";
        }
        s
    };
    let all: Vec<&Mutation> = mutations.iter().collect();
    let mut errors: Vec<(u32, String)> = Vec::new();
    if let Err(e) = yosys(&apply(&all, true), work, "apply") {
        // Find the mutations yosys refuses, one by one, written out too
        // (a memory read port's RD_ARST inverted is accepted by `mutate`
        // but fails `write_verilog`); build the rest.
        for m in &mutations {
            if let Err(e) = yosys(&apply(&[m], true), work, "apply one") {
                errors.push((m.id, e.to_string().lines().last().unwrap_or("").to_string()));
            }
        }
        if errors.is_empty() {
            return Err(e);
        }
        let ok: Vec<&Mutation> = mutations.iter().filter(|m| !errors.iter().any(|(id, _)| *id == m.id)).collect();
        yosys(&apply(&ok, true), work, "apply")?;
    }
    std::fs::write(work.join("build_errors.json"), serde_json::to_string(&errors).expect("plain data")).map_err(io("writing build_errors.json"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    /// A list saved under /work/main/rtl applies to a checkout elsewhere:
    /// both the cell name and the `-src` paths move; a path to a file the
    /// core does not have is left alone.
    #[test]
    fn a_saved_list_moves_to_this_checkouts_paths() {
        let files = vec![std::path::PathBuf::from("/home/u/co/rtl/can_btl.v"), std::path::PathBuf::from("/home/u/co/rtl/can_top.v")];
        let line = "mutate -mode cnot1 -module can_top -cell $flatten\\u_btl.$add$/work/main/rtl/can_btl.v:47$557 -port Y -src /work/main/rtl/can_top.v:111.13-116.6 -src /work/main/rtl/can_btl.v:47.23-47.43 -src /x/other.v:1.1-1.2\n";
        let got = super::relocate(line, &files);
        assert_eq!(
            got,
            "mutate -mode cnot1 -module can_top -cell $flatten\\u_btl.$add$/home/u/co/rtl/can_btl.v:47$557 -port Y -src /home/u/co/rtl/can_top.v:111.13-116.6 -src /home/u/co/rtl/can_btl.v:47.23-47.43 -src /x/other.v:1.1-1.2\n"
        );
        // already here: unchanged
        assert_eq!(super::relocate(&got, &files), got);
        // two files of one name: no guess
        let twin = vec![files[0].clone(), std::path::PathBuf::from("/elsewhere/can_btl.v")];
        assert_eq!(super::relocate(line, &twin), line);
    }

    /// A relative work directory (`--out out/x` from the CLI) works: the
    /// script path handed to yosys must not be relative to the directory
    /// yosys runs in (the formal check failed with "Can't open script file").
    #[test]
    fn yosys_runs_in_a_relative_work_directory() {
        // under the test's working directory (the crate), named relatively
        let dir = tempfile::tempdir_in(".").unwrap();
        let rel = std::path::PathBuf::from(dir.path().file_name().unwrap());
        assert!(rel.is_relative() && rel.is_dir(), "{}", rel.display());
        let out = super::yosys("log relative-ok\n", &rel, "rel step");
        match out {
            Err(super::InstrumentError::NoYosys) => eprintln!("yosys not installed: skipped"),
            other => {
                other.unwrap();
            }
        }
    }
}
