//! The Verilator bridge: one Rust type, [`Model`], for every Verilated top,
//! whether compiled into this crate by `build.rs` (bundled RTL and fixtures)
//! or built at run time from an external directory into a cached shared
//! library ([`ExternalCore`]). Port reads and writes go straight through
//! pointers into the model; `eval` is the only foreign call per edge.

use std::ffi::{CString, c_char, c_void};
use std::fmt;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::shimgen::{self, PortDecl, PortDir};

/// The shim's entry points for one top.
#[derive(Clone, Copy)]
pub(crate) struct VTable {
    pub(crate) new: unsafe extern "C" fn(i32) -> *mut c_void,
    pub(crate) delete: unsafe extern "C" fn(*mut c_void),
    pub(crate) eval: unsafe extern "C" fn(*mut c_void),
    /// Runs a [`Batch`] (its address), returns the instants made.
    pub(crate) run: unsafe extern "C" fn(*mut c_void, *const c_void) -> u32,
    pub(crate) ports: unsafe extern "C" fn(*mut c_void, *mut *const c_void) -> u32,
    pub(crate) trace_open: unsafe extern "C" fn(*mut c_void, *const c_char) -> i32,
    pub(crate) trace_dump: unsafe extern "C" fn(*mut c_void, u64),
    pub(crate) trace_close: unsafe extern "C" fn(*mut c_void),
}

include!(concat!(env!("OUT_DIR"), "/bundled.rs"));

/// Names of the tops compiled into this crate (fixtures, and `can_top` /
/// `can_avalon` when `rtl/` verilated).
pub fn bundled_tops() -> Vec<&'static str> {
    BUNDLED.iter().map(|(n, _)| *n).collect()
}

/// What can go wrong building, loading or binding a model. Each variant
/// prints as one paragraph, including Verilator's or the compiler's own words.
#[derive(Debug, thiserror::Error)]
pub enum BridgeError {
    /// The top was not compiled into this crate.
    #[error(
        "no bundled top `{name}`; this build has: {available}. (The RTL tops are missing when rtl/ did not verilate at build time.)"
    )]
    UnknownTop {
        /// Requested top.
        name: String,
        /// Tops that exist.
        available: String,
    },
    /// The core's directory cannot hold the core ([`ExternalCore::check`]).
    #[error("external core {dir}: {problem}")]
    BadSources {
        /// Source directory.
        dir: String,
        /// What is wrong, in one line.
        problem: String,
    },
    /// Verilator rejected the sources.
    #[error("Verilator could not build top `{top}` from {dir}; Verilator said:\n{message}")]
    Verilate {
        /// Top module.
        top: String,
        /// Source directory.
        dir: String,
        /// Verilator's output.
        message: String,
    },
    /// The C++ compiler or linker failed on the Verilated model.
    #[error("compiling the Verilated model of `{top}` failed ({step}):\n{message}")]
    Compile {
        /// Top module.
        top: String,
        /// Which step.
        step: String,
        /// Compiler output.
        message: String,
    },
    /// A port the DUT kind needs is absent.
    #[error(
        "top `{top}` has no port `{port}` (it has: {available}); a DUT needs the {kind} port list"
    )]
    MissingPort {
        /// Top module.
        top: String,
        /// Missing port.
        port: String,
        /// Ports it has.
        available: String,
        /// Which port list was expected.
        kind: String,
    },
    /// A port has an unexpected width or direction.
    #[error("port `{port}` of top `{top}` is {got}; expected {want}")]
    PortShape {
        /// Top module.
        top: String,
        /// Port.
        port: String,
        /// What it is.
        got: String,
        /// What it should be.
        want: String,
    },
    /// The shared library could not be loaded.
    #[error("could not load {path}: {message}")]
    Load {
        /// Library path.
        path: String,
        /// Loader message.
        message: String,
    },
    /// Tracing could not start.
    #[error("could not open VCD trace {path}: {reason}")]
    Trace {
        /// VCD path.
        path: String,
        /// Why.
        reason: String,
    },
    /// File-system trouble.
    #[error("{context}: {source}")]
    Io {
        /// What was being done.
        context: String,
        /// The error.
        source: std::io::Error,
    },
}

fn io_err(context: impl Into<String>) -> impl FnOnce(std::io::Error) -> BridgeError {
    let context = context.into();
    move |source| BridgeError::Io { context, source }
}

/// One entry of a model's port table.
#[derive(Clone, Debug)]
pub struct PortInfo {
    /// Port name.
    pub name: String,
    /// Width in bits.
    pub width: u32,
    /// Direction.
    pub dir: PortDir,
    ptr: *mut u8,
}

#[repr(C)]
struct RawPort {
    name: *const c_char,
    ptr: *mut c_void,
    width: u32,
    dir: u32,
}

/// A resolved port of one [`Model`]: a pointer and a width. Cheap to copy;
/// only usable with the model it came from (checked).
#[derive(Clone, Copy, Debug)]
pub struct Port {
    ptr: *mut u8,
    width: u32,
    model: u64,
}

static NEXT_MODEL_ID: AtomicU64 = AtomicU64::new(1);

/// The ports a batch drives and watches (all of one model, 8 bits or fewer).
#[derive(Clone, Copy, Debug)]
pub(crate) struct BatchPins {
    pub(crate) host_clk: Port,
    pub(crate) can_clk: Port,
    pub(crate) rx: Port,
    pub(crate) tx: Port,
    pub(crate) irq: Port,
    pub(crate) bus_off: Port,
    pub(crate) clkout: Port,
    pub(crate) ack: Port,
    pub(crate) dat: Port,
}

/// Several instants in one foreign call, for stretches in which nothing
/// but the two clocks and the DUT's own tx drive its inputs (the host
/// master idle, no other node, no fault on rx). Per instant `k`,
/// `levels[k]` has bit 0 the host clock level, bit 1 the CAN clock level,
/// bit 2 "the CAN clock rises": then `rx` takes `rx_mode` (0 or 1), or
/// `tx` (2), before the eval; other bits are the caller's (ignored).
/// After the eval, `out[k]` gets bit 0 `tx`, bit 1 `irq`, bit 2 `bus_off`,
/// bit 3 `clkout` (nonzero = 1). The call returns after an instant whose
/// `ack` or `dat` differs from before the call, or whose `irq` equals
/// `stop_irq` (2: never), so the caller can replay every instant's
/// outputs exactly. Layout shared with the generated shim.
#[repr(C)]
struct Batch {
    host_clk: *mut u8,
    can_clk: *mut u8,
    rx: *mut u8,
    tx: *const u8,
    irq: *const u8,
    bus_off: *const u8,
    clkout: *const u8,
    ack: *const u8,
    dat: *const u8,
    levels: *const u8,
    out: *mut u8,
    n: u32,
    rx_mode: u8,
    stop_irq: u8,
}

/// One instance of a Verilated top. Not `Send`: Verilator models belong to
/// the thread that made them; run several on several threads.
pub struct Model {
    vt: VTable,
    handle: *mut c_void,
    ports: Vec<PortInfo>,
    id: u64,
    top: String,
    tracing: bool,
    /// Keeps a run-time built library mapped while the model lives.
    _lib: Option<Arc<libloading::Library>>,
}

impl fmt::Debug for Model {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Model")
            .field("top", &self.top)
            .field("ports", &self.ports.len())
            .finish()
    }
}

impl Model {
    /// A fresh instance of a bundled top (`can_top`, `can_avalon`, or a
    /// fixture such as `cosim_echo`). `trace` enables VCD tracing (it must
    /// be chosen before construction; it costs a little speed).
    pub fn bundled(name: &str, trace: bool) -> Result<Model, BridgeError> {
        let Some((_, vt)) = BUNDLED.iter().find(|(n, _)| *n == name) else {
            return Err(BridgeError::UnknownTop {
                name: name.to_string(),
                available: bundled_tops().join(", "),
            });
        };
        // SAFETY: the vtable entries are the shim generated for this top.
        Ok(unsafe { Model::from_vtable(*vt, name, trace, None) })
    }

    unsafe fn from_vtable(
        vt: VTable,
        top: &str,
        trace: bool,
        lib: Option<Arc<libloading::Library>>,
    ) -> Model {
        // SAFETY: caller passes a vtable from the shim generator.
        let handle = unsafe { (vt.new)(trace as i32) };
        // Settle once with every input at 0, so that the first rising edge
        // the caller makes is seen as an edge (Verilator initialises its
        // edge detectors on the first eval).
        unsafe { (vt.eval)(handle) };
        let mut raw: *const c_void = std::ptr::null();
        let n = unsafe { (vt.ports)(handle, &mut raw) } as usize;
        let raw = raw as *const RawPort;
        let mut ports = Vec::with_capacity(n);
        for k in 0..n {
            // SAFETY: the shim returns a table of `n` entries living as long as the instance.
            let r = unsafe { &*raw.add(k) };
            let name = unsafe { std::ffi::CStr::from_ptr(r.name) }
                .to_string_lossy()
                .into_owned();
            let dir = match r.dir {
                0 => PortDir::In,
                1 => PortDir::Out,
                _ => PortDir::InOut,
            };
            ports.push(PortInfo {
                name,
                width: r.width,
                dir,
                ptr: r.ptr as *mut u8,
            });
        }
        Model {
            vt,
            handle,
            ports,
            id: NEXT_MODEL_ID.fetch_add(1, Ordering::Relaxed),
            top: top.to_string(),
            tracing: trace,
            _lib: lib,
        }
    }

    /// The top module's name.
    pub fn top(&self) -> &str {
        &self.top
    }

    /// The port table.
    pub fn ports(&self) -> &[PortInfo] {
        &self.ports
    }

    /// Resolves a port by name; `width` (if given) must match, and the
    /// port must be at most 64 bits wide.
    pub fn port(&self, name: &str, width: Option<u32>, kind: &str) -> Result<Port, BridgeError> {
        let Some(p) = self.ports.iter().find(|p| p.name == name) else {
            return Err(BridgeError::MissingPort {
                top: self.top.clone(),
                port: name.to_string(),
                available: self
                    .ports
                    .iter()
                    .map(|p| p.name.as_str())
                    .collect::<Vec<_>>()
                    .join(" "),
                kind: kind.to_string(),
            });
        };
        if let Some(w) = width
            && w != p.width
        {
            return Err(BridgeError::PortShape {
                top: self.top.clone(),
                port: name.to_string(),
                got: format!("{} bits wide", p.width),
                want: format!("{w} bits"),
            });
        }
        if p.width > 64 {
            return Err(BridgeError::PortShape {
                top: self.top.clone(),
                port: name.to_string(),
                got: format!("{} bits wide", p.width),
                want: "at most 64 bits".into(),
            });
        }
        Ok(Port {
            ptr: p.ptr,
            width: p.width,
            model: self.id,
        })
    }

    /// Writes an input port (masked to its width).
    #[inline(always)]
    pub fn set(&mut self, p: Port, v: u64) {
        assert_eq!(p.model, self.id, "port used with another model");
        let v = if p.width >= 64 {
            v
        } else {
            v & ((1u64 << p.width) - 1)
        };
        // SAFETY: `p` came from this model's port table (checked above),
        // the pointer is valid for the model's life and sized by its width.
        unsafe {
            match p.width {
                0..=8 => *p.ptr = v as u8,
                9..=16 => *(p.ptr as *mut u16) = v as u16,
                17..=32 => *(p.ptr as *mut u32) = v as u32,
                _ => *(p.ptr as *mut u64) = v,
            }
        }
    }

    /// Reads a port.
    #[inline(always)]
    pub fn get(&self, p: Port) -> u64 {
        assert_eq!(p.model, self.id, "port used with another model");
        // SAFETY: as in `set`.
        unsafe {
            match p.width {
                0..=8 => *p.ptr as u64,
                9..=16 => *(p.ptr as *const u16) as u64,
                17..=32 => *(p.ptr as *const u32) as u64,
                _ => *(p.ptr as *const u64),
            }
        }
    }

    /// Whether `p` is a port of this model.
    #[inline(always)]
    pub(crate) fn owns(&self, p: Port) -> bool {
        p.model == self.id
    }

    /// Reads a port of 8 bits or fewer without the per-call checks.
    ///
    /// # Safety
    /// `p` is a port of this model ([`Model::owns`]) at most 8 bits wide.
    #[inline(always)]
    pub(crate) unsafe fn get_u8_unchecked(&self, p: Port) -> u8 {
        debug_assert!(self.owns(p) && p.width <= 8);
        // SAFETY: by the caller's contract the pointer is this live model's
        // byte-sized port storage.
        unsafe { *p.ptr }
    }

    /// Writes a 1-bit port without the per-call checks.
    ///
    /// # Safety
    /// `p` is a port of this model ([`Model::owns`]) 1 bit wide.
    #[inline(always)]
    pub(crate) unsafe fn set_bit_unchecked(&mut self, p: Port, v: bool) {
        debug_assert!(self.owns(p) && p.width == 1);
        // SAFETY: by the caller's contract, this live model's 1-bit port.
        unsafe { *p.ptr = v as u8 }
    }

    /// Evaluates the model after input changes (one call per edge).
    #[inline(always)]
    pub fn eval(&mut self) {
        // SAFETY: handle is live.
        unsafe { (self.vt.eval)(self.handle) }
    }

    /// Makes `levels.len()` instants in one foreign call (see [`Batch`];
    /// `rx`: the level `rx` takes at each CAN rising edge, `None`: `tx`);
    /// returns how many were made (it stops early after an instant that
    /// changed `ack` or `dat`, or whose `irq` equals `stop_irq`).
    ///
    /// # Safety
    /// Every port of `pins` belongs to this model and is 8 bits or fewer;
    /// `out` is at least as long as `levels`.
    pub(crate) unsafe fn run_batch(
        &mut self,
        pins: &BatchPins,
        levels: &[u8],
        out: &mut [u8],
        rx: Option<bool>,
        stop_irq: Option<bool>,
    ) -> usize {
        debug_assert!(out.len() >= levels.len());
        let b = Batch {
            host_clk: pins.host_clk.ptr,
            can_clk: pins.can_clk.ptr,
            rx: pins.rx.ptr,
            tx: pins.tx.ptr,
            irq: pins.irq.ptr,
            bus_off: pins.bus_off.ptr,
            clkout: pins.clkout.ptr,
            ack: pins.ack.ptr,
            dat: pins.dat.ptr,
            levels: levels.as_ptr(),
            out: out.as_mut_ptr(),
            n: levels.len() as u32,
            rx_mode: rx.map_or(2, |v| v as u8),
            stop_irq: stop_irq.map_or(2, |v| v as u8),
        };
        // SAFETY: handle is live; the batch's pointers are this model's
        // byte-sized ports (caller's contract) and the two buffers.
        unsafe { (self.vt.run)(self.handle, &b as *const Batch as *const c_void) as usize }
    }

    /// Starts Verilator's VCD trace of every signal of the design.
    pub fn trace_open(&mut self, path: &Path) -> Result<(), BridgeError> {
        let err = |reason: &str| BridgeError::Trace {
            path: path.display().to_string(),
            reason: reason.to_string(),
        };
        if !self.tracing {
            return Err(err("the model was created without tracing"));
        }
        let c = CString::new(path.as_os_str().as_encoded_bytes())
            .map_err(|_| err("path contains NUL"))?;
        // SAFETY: handle is live; c is NUL-terminated.
        match unsafe { (self.vt.trace_open)(self.handle, c.as_ptr()) } {
            0 => Ok(()),
            -1 => Err(err("a trace is already open")),
            _ => Err(err("Verilator could not open the file")),
        }
    }

    /// Dumps the traced signals at time `t_ps` (no-op without an open trace).
    pub fn trace_dump(&mut self, t_ps: u64) {
        // SAFETY: handle is live.
        unsafe { (self.vt.trace_dump)(self.handle, t_ps) }
    }

    /// Closes the trace file (also done on drop).
    pub fn trace_close(&mut self) {
        // SAFETY: handle is live.
        unsafe { (self.vt.trace_close)(self.handle) }
    }
}

impl Drop for Model {
    fn drop(&mut self) {
        // SAFETY: handle is live and dropped once.
        unsafe { (self.vt.delete)(self.handle) }
    }
}

/// An HDL core outside this repository, built at run time with Verilator's
/// own makefile into a shared library cached by a hash of its sources and
/// options. The opencores core, for instance, needs
/// `defines = ["CAN_WISHBONE_IF"]` and its directory as include dir (for
/// `timescale.v`).
#[derive(Clone, Debug, Default)]
pub struct ExternalCore {
    /// Directory holding the sources.
    pub dir: PathBuf,
    /// Top module name.
    pub top: String,
    /// Source files; empty means every `*.v` / `*.sv` in `dir`.
    pub files: Vec<PathBuf>,
    /// `NAME` or `NAME=VALUE` macros.
    pub defines: Vec<String>,
    /// Extra include directories (`dir` is always one).
    pub include_dirs: Vec<PathBuf>,
    /// Extra Verilator arguments. `*.v` files are read as Verilog-2005
    /// (`+1364-2005ext+v`, so identifiers such as `do` that SystemVerilog
    /// reserves still parse); `*.sv` as SystemVerilog.
    pub extra_args: Vec<String>,
    /// Inputs held at a constant for the whole run, set on every instance
    /// before its first eval (the run-time mutant select of `cancosim
    /// mutate`). Not part of the cache key: one build serves every value.
    pub held_inputs: Vec<(String, u64)>,
}

/// A built external core: the loaded library and the symbol prefix.
#[derive(Clone)]
pub struct CompiledCore {
    lib: Arc<libloading::Library>,
    vt: VTable,
    top: String,
    /// The cached shared library.
    pub path: PathBuf,
    /// [`ExternalCore::held_inputs`], checked to exist at build.
    held: Vec<(String, u64)>,
}

impl fmt::Debug for CompiledCore {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CompiledCore")
            .field("top", &self.top)
            .field("path", &self.path)
            .finish()
    }
}

impl CompiledCore {
    /// A fresh instance (each thread makes its own).
    pub fn instantiate(&self, trace: bool) -> Model {
        // SAFETY: vt was resolved from this library's generated shim.
        let mut m = unsafe { Model::from_vtable(self.vt, &self.top, trace, Some(self.lib.clone())) };
        for (name, value) in &self.held {
            // Present: checked in `ExternalCore::build_in`.
            if let Ok(p) = m.port(name, None, "held input") {
                m.set(p, *value);
            }
        }
        m
    }
}

/// FNV-1a, 64 bits: a stable hash for cache keys (no new dependency).
fn fnv1a(h: &mut u64, bytes: &[u8]) {
    for b in bytes {
        *h ^= *b as u64;
        *h = h.wrapping_mul(0x100_0000_01b3);
    }
}

/// True if `text` has the keyword `module` followed by the name `top`.
fn declares_module(text: &str, top: &str) -> bool {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '$';
    let words: Vec<&str> = text.split(|c: char| !ident(c)).filter(|w| !w.is_empty()).collect();
    words.windows(2).any(|w| (w[0] == "module" || w[0] == "macromodule") && w[1] == top)
}

/// Where run-time builds are cached: `$COSIM_CACHE_DIR`, else
/// `$XDG_CACHE_HOME/sja1000-cosim`, else `~/.cache/sja1000-cosim`.
pub fn cache_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("COSIM_CACHE_DIR") {
        return PathBuf::from(d);
    }
    if let Some(d) = std::env::var_os("XDG_CACHE_HOME") {
        return PathBuf::from(d).join("sja1000-cosim");
    }
    if let Some(h) = std::env::var_os("HOME") {
        return PathBuf::from(h).join(".cache/sja1000-cosim");
    }
    std::env::temp_dir().join("sja1000-cosim")
}

const OPT_FLAGS: &str = "-fPIC -fno-semantic-interposition";

fn run(cmd: &mut Command, top: &str, step: &str) -> Result<String, BridgeError> {
    let o = cmd.output().map_err(|e| BridgeError::Compile {
        top: top.into(),
        step: step.into(),
        message: format!("could not start: {e}"),
    })?;
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    if o.status.success() {
        Ok(text)
    } else {
        Err(BridgeError::Compile {
            top: top.into(),
            step: step.into(),
            message: text.trim().to_string(),
        })
    }
}

impl ExternalCore {
    fn sources(&self) -> Result<Vec<PathBuf>, BridgeError> {
        if !self.files.is_empty() {
            return Ok(self
                .files
                .iter()
                .map(|f| {
                    if f.is_absolute() {
                        f.clone()
                    } else {
                        self.dir.join(f)
                    }
                })
                .collect());
        }
        let mut v: Vec<PathBuf> = std::fs::read_dir(&self.dir)
            .map_err(io_err(format!(
                "reading core directory {}",
                self.dir.display()
            )))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("v" | "sv")))
            .collect();
        v.sort();
        if v.is_empty() {
            return Err(BridgeError::Verilate {
                top: self.top.clone(),
                dir: self.dir.display().to_string(),
                message: "no *.v or *.sv files in that directory".into(),
            });
        }
        Ok(v)
    }

    /// Cheap checks before any build (for bad command-line input: one
    /// clear line, not one failed build per scenario): the directory
    /// exists, holds `*.v`/`*.sv` files (or the given files exist), and one
    /// of them declares `module <top>` (a textual scan, comments not parsed).
    pub fn check(&self) -> Result<(), BridgeError> {
        let bad = |problem: String| BridgeError::BadSources { dir: self.dir.display().to_string(), problem };
        match std::fs::metadata(&self.dir) {
            Ok(m) if m.is_dir() => {}
            Ok(_) => return Err(bad("is not a directory".into())),
            Err(e) => return Err(bad(format!("cannot be read ({e})"))),
        }
        let sources = self.sources().map_err(|_| bad("holds no *.v or *.sv files".into()))?;
        let mut texts = Vec::new();
        for f in &sources {
            texts.push(std::fs::read(f).map_err(|e| bad(format!("{}: cannot be read ({e})", f.display())))?);
        }
        if !texts.iter().any(|t| declares_module(&String::from_utf8_lossy(t), &self.top)) {
            return Err(bad(format!(
                "no `module {}` in its {} source file(s); give the top module with --top",
                self.top,
                sources.len()
            )));
        }
        Ok(())
    }

    fn verilator_args(&self, sources: &[PathBuf]) -> Vec<String> {
        let mut a: Vec<String> = [
            "--cc",
            "--trace",
            "--no-timing",
            "-Wno-fatal",
            "-Wno-lint",
            "-Wno-style",
            "--top-module",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.push(self.top.clone());
        a.push("--prefix".into());
        a.push(format!("V{}", self.top));
        a.push("+1364-2005ext+v".into());
        a.extend(self.extra_args.iter().cloned());
        for d in &self.defines {
            a.push(format!("-D{d}"));
        }
        a.push(format!("-I{}", self.dir.display()));
        for d in &self.include_dirs {
            let d = if d.is_absolute() {
                d.clone()
            } else {
                self.dir.join(d)
            };
            a.push(format!("-I{}", d.display()));
        }
        a.extend(sources.iter().map(|s| s.display().to_string()));
        a
    }

    /// The cache key: every source (and include-directory file), the
    /// options, the Verilator version and this crate's shim generator.
    fn cache_key(&self, sources: &[PathBuf]) -> Result<String, BridgeError> {
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        let mut files: Vec<PathBuf> = sources.to_vec();
        for d in std::iter::once(&self.dir).chain(self.include_dirs.iter()) {
            if let Ok(rd) = std::fs::read_dir(if d.is_absolute() {
                d.clone()
            } else {
                self.dir.join(d)
            }) {
                let mut extra: Vec<PathBuf> = rd
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| {
                        matches!(
                            p.extension().and_then(|e| e.to_str()),
                            Some("v" | "sv" | "vh" | "svh")
                        )
                    })
                    .collect();
                extra.sort();
                files.extend(extra);
            }
        }
        for f in &files {
            fnv1a(&mut h, f.display().to_string().as_bytes());
            fnv1a(
                &mut h,
                &std::fs::read(f).map_err(io_err(format!("reading {}", f.display())))?,
            );
        }
        fnv1a(&mut h, self.verilator_args(sources).join(" ").as_bytes());
        fnv1a(&mut h, OPT_FLAGS.as_bytes());
        fnv1a(&mut h, include_str!("shimgen.rs").as_bytes());
        let ver = Command::new("verilator")
            .arg("--version")
            .output()
            .map(|o| o.stdout)
            .unwrap_or_default();
        fnv1a(&mut h, &ver);
        Ok(format!("{}-{h:016x}", self.top))
    }

    /// Verilates, compiles and loads the core (or loads it from the cache,
    /// [`cache_dir`]).
    pub fn build(&self) -> Result<CompiledCore, BridgeError> {
        self.build_in(&cache_dir())
    }

    /// [`ExternalCore::build`] with the cache in `cache`.
    pub fn build_in(&self, cache: &Path) -> Result<CompiledCore, BridgeError> {
        let sources = self.sources()?;
        let key = self.cache_key(&sources)?;
        let dir = cache.join(&key);
        let lib_name = format!("libcosim_{}.so", self.top);
        // One work directory per build, also between threads of one process
        // (regress workers, parallel tests): two makes in one directory link
        // each other's half-written objects. The first complete build moved
        // into place wins; a slower one uses it.
        let entry = buildcache::build_once(&dir, &lib_name, |work| {
            self.build_into(&sources, work, &lib_name)
        })
        .map_err(|e| match e {
            buildcache::Error::Build(e) => e,
            buildcache::Error::Io { what, source } => BridgeError::Io {
                context: what,
                source,
            },
        })?;
        let core = self.load(&entry.product)?;
        if !core.held.is_empty() {
            let m = core.instantiate(false);
            for (name, _) in &core.held {
                m.port(name, None, "held input")?;
            }
        }
        Ok(core)
    }

    /// Verilates and links the shared library `lib_name` in `tmp` (an empty
    /// directory of this build's own).
    fn build_into(&self, sources: &[PathBuf], tmp: &Path, lib_name: &str) -> Result<(), BridgeError> {
        let top = &self.top;
        let which = Command::new("verilator").arg("--version").output();
        if which.is_err() {
            return Err(BridgeError::Verilate { top: top.clone(), dir: self.dir.display().to_string(), message: "`verilator` was not found: install Verilator (apt-get install verilator) or run scripts/setup.sh".into() });
        }
        let o = Command::new("verilator")
            .args(self.verilator_args(sources))
            .arg("-Mdir")
            .arg(tmp)
            .output()
            .map_err(io_err("running verilator"))?;
        if !o.status.success() {
            return Err(BridgeError::Verilate {
                top: top.clone(),
                dir: self.dir.display().to_string(),
                message: format!(
                    "{}{}",
                    String::from_utf8_lossy(&o.stdout),
                    String::from_utf8_lossy(&o.stderr)
                )
                .trim()
                .to_string(),
            });
        }
        let prefix = format!("V{top}");
        let header = std::fs::read_to_string(tmp.join(format!("{prefix}.h")))
            .map_err(io_err(format!("reading {prefix}.h")))?;
        let ports: Vec<PortDecl> = shimgen::parse_ports(&header);
        std::fs::write(
            tmp.join("cosim_shim.cpp"),
            shimgen::gen_shim(top, &ports, true),
        )
        .map_err(io_err("writing the shim"))?;
        let classes = shimgen::parse_classes_mk(
            &std::fs::read_to_string(tmp.join(format!("{prefix}_classes.mk")))
                .map_err(io_err(format!("reading {prefix}_classes.mk")))?,
        );
        let globals: Vec<String> = classes.global.iter().map(|g| format!("{g}.o")).collect();
        let jobs = std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
            .to_string();
        run(
            Command::new("make")
                .arg("-C")
                .arg(tmp)
                .arg("-j")
                .arg(&jobs)
                .arg("-f")
                .arg(format!("{prefix}.mk"))
                .arg("OPT_FAST=-O3")
                .arg("OPT_SLOW=-O2")
                .arg("OPT_GLOBAL=-O3")
                .arg(format!("CXXFLAGS={OPT_FLAGS}"))
                .arg(format!("{prefix}__ALL.a"))
                .arg("cosim_shim.o")
                .args(&globals),
            top,
            "make",
        )?;
        let cxx = std::env::var("CXX").unwrap_or_else(|_| "g++".into());
        run(
            Command::new(cxx)
                .current_dir(tmp)
                .args(["-shared", "-Wl,-Bsymbolic", "-o"])
                .arg(lib_name)
                .arg("cosim_shim.o")
                .arg(format!("{prefix}__ALL.a"))
                .args(&globals)
                .args(["-pthread", "-latomic"]),
            top,
            "link",
        )?;
        Ok(())
    }

    fn load(&self, lib_path: &Path) -> Result<CompiledCore, BridgeError> {
        let load_err = |m: String| BridgeError::Load {
            path: lib_path.display().to_string(),
            message: m,
        };
        // SAFETY: the library was built by us from the generated shim; its
        // initialisers are Verilator's runtime's.
        let lib =
            unsafe { libloading::Library::new(lib_path) }.map_err(|e| load_err(e.to_string()))?;
        let p = shimgen::symbol_prefix(&self.top);
        macro_rules! sym {
            ($name:literal, $t:ty) => {{
                // SAFETY: symbol types match gen_shim's declarations.
                let s: libloading::Symbol<$t> =
                    unsafe { lib.get(format!("{p}{}", $name).as_bytes()) }
                        .map_err(|e| load_err(e.to_string()))?;
                *s
            }};
        }
        let vt = VTable {
            new: sym!("new", unsafe extern "C" fn(i32) -> *mut c_void),
            delete: sym!("delete", unsafe extern "C" fn(*mut c_void)),
            eval: sym!("eval", unsafe extern "C" fn(*mut c_void)),
            run: sym!("run", unsafe extern "C" fn(*mut c_void, *const c_void) -> u32),
            ports: sym!(
                "ports",
                unsafe extern "C" fn(*mut c_void, *mut *const c_void) -> u32
            ),
            trace_open: sym!(
                "trace_open",
                unsafe extern "C" fn(*mut c_void, *const c_char) -> i32
            ),
            trace_dump: sym!("trace_dump", unsafe extern "C" fn(*mut c_void, u64)),
            trace_close: sym!("trace_close", unsafe extern "C" fn(*mut c_void)),
        };
        Ok(CompiledCore {
            lib: Arc::new(lib),
            vt,
            top: self.top.clone(),
            path: lib_path.to_path_buf(),
            held: self.held_inputs.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::declares_module;

    #[test]
    fn module_scan_finds_the_top_by_whole_name_only() {
        assert!(declares_module("// x\nmodule can_top (\n input a);", "can_top"));
        assert!(declares_module("module\n  can_top#(parameter P=1)(a);", "can_top"));
        assert!(!declares_module("module can_top_pio (a);", "can_top"));
        assert!(!declares_module("can_top u0 (.a(a));", "can_top"), "an instance is not a declaration");
    }
}
