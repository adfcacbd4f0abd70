//! One Rust type, [`Model`], for every Verilated top, whether linked into
//! the executable by a build script ([`Model::from_table`]) or built at run
//! time into a cached shared library ([`ExternalCore`]). Port reads and
//! writes go straight through pointers into the model; `eval` is the only
//! foreign call per edge.

use std::ffi::{CString, c_char, c_void};
use std::fmt;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::BridgeError;
use crate::external::ExternalCore;
use crate::shimgen::{self, PortDecl, PortDir};

/// The entry points of one top's generated shim ([`shimgen::gen_shim`]).
/// A build script that links tops into the executable writes one per top
/// ([`shimgen::gen_rust_table`]); run-time builds resolve them by symbol.
#[derive(Clone, Copy)]
pub struct VTable {
    /// `new(trace)`: a fresh instance.
    pub new: unsafe extern "C" fn(i32) -> *mut c_void,
    /// `delete(instance)`.
    pub delete: unsafe extern "C" fn(*mut c_void),
    /// `eval(instance)`.
    pub eval: unsafe extern "C" fn(*mut c_void),
    /// `run(instance, arg)`: the caller's inner loop ([`Model::run_inner_loop`]).
    pub run: unsafe extern "C" fn(*mut c_void, *const c_void) -> u32,
    /// `ports(instance, &table)`: the port table and its length.
    pub ports: unsafe extern "C" fn(*mut c_void, *mut *const c_void) -> u32,
    /// `trace_open(instance, path)`.
    pub trace_open: unsafe extern "C" fn(*mut c_void, *const c_char) -> i32,
    /// `trace_dump(instance, t_ps)`.
    pub trace_dump: unsafe extern "C" fn(*mut c_void, u64),
    /// `trace_close(instance)`.
    pub trace_close: unsafe extern "C" fn(*mut c_void),
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

impl Port {
    /// Width in bits.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// The port's storage inside its model, for an inner loop
    /// ([`Model::run_inner_loop`]) to read or write: 1 byte up to 8 bits
    /// wide, 2 up to 16, 4 up to 32, else 8. Valid while the model lives.
    pub fn as_ptr(&self) -> *mut u8 {
        self.ptr
    }
}

static NEXT_MODEL_ID: AtomicU64 = AtomicU64::new(1);

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
    /// Coverage build: the shim's writer and the `.dat` it writes when the
    /// model is dropped ([`CompiledCore::instantiate_with_coverage`]).
    coverage_out: Option<(CoverageWrite, CString)>,
}

/// `cosim_<top>_coverage_write(handle, path)` of a coverage build.
type CoverageWrite = unsafe extern "C" fn(*mut c_void, *const c_char) -> i32;

impl fmt::Debug for Model {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Model")
            .field("top", &self.top)
            .field("ports", &self.ports.len())
            .finish()
    }
}

impl Model {
    /// A fresh instance of the top `name` of `table`, the tops a build
    /// script linked into the executable ([`shimgen::gen_rust_table`]).
    /// `trace` enables VCD tracing (it must be chosen before construction;
    /// it costs a little speed).
    ///
    /// # Safety
    /// Every entry of `table` holds the entry points of the shim generated
    /// for that top ([`shimgen::gen_shim`]).
    pub unsafe fn from_table(
        table: &[(&str, VTable)],
        name: &str,
        trace: bool,
    ) -> Result<Model, BridgeError> {
        let Some((_, vt)) = table.iter().find(|(n, _)| *n == name) else {
            return Err(BridgeError::UnknownTop {
                name: name.to_string(),
                available: table.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", "),
            });
        };
        // SAFETY: by the caller's contract.
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
            coverage_out: None,
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

    /// Resolves a port by name (at most 64 bits wide).
    pub fn port_by_name(&self, name: &str) -> Result<Port, BridgeError> {
        self.port(name, None, "")
    }

    /// Resolves a port by name; `width` (if given) must match, and the
    /// port must be at most 64 bits wide. `kind` names the port list the
    /// caller wants, for the error message ("" for none).
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
    pub fn owns(&self, p: Port) -> bool {
        p.model == self.id
    }

    /// Reads a port of 8 bits or fewer without the per-call checks.
    ///
    /// # Safety
    /// `p` is a port of this model ([`Model::owns`]) at most 8 bits wide.
    #[inline(always)]
    pub unsafe fn get_u8_unchecked(&self, p: Port) -> u8 {
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
    pub unsafe fn set_bit_unchecked(&mut self, p: Port, v: bool) {
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

    /// Calls the top's inner loop: the C++ function body given to the shim
    /// generator ([`shimgen::gen_shim`]'s `inner_loop`, [`ExternalCore::inner_loop`])
    /// runs with this instance's model and `arg`; returns what it returns
    /// (0 when the shim has no inner loop). Many evals in one foreign call,
    /// for stretches the caller can describe in a buffer.
    ///
    /// # Safety
    /// `arg` is what that C++ code expects, and every pointer in it that
    /// points into a model points into this one.
    #[inline]
    pub unsafe fn run_inner_loop(&mut self, arg: *const c_void) -> u32 {
        // SAFETY: handle is live; `arg` by the caller's contract.
        unsafe { (self.vt.run)(self.handle, arg) }
    }

    /// Sets the 1-bit input `clk` high, evaluates, sets it low, evaluates:
    /// `cycles` times. The simplest way to step a single-clock design.
    pub fn step_clock(&mut self, clk: Port, cycles: u64) {
        for _ in 0..cycles {
            self.set(clk, 1);
            self.eval();
            self.set(clk, 0);
            self.eval();
        }
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
        if let Some((write, path)) = &self.coverage_out {
            // SAFETY: handle is live; the writer is this library's shim.
            // A failed write shows as a missing .dat, which the caller reports.
            unsafe { write(self.handle, path.as_ptr()) };
        }
        // SAFETY: handle is live and dropped once.
        unsafe { (self.vt.delete)(self.handle) }
    }
}

/// A built external core: the loaded library and the symbol prefix.
#[derive(Clone)]
pub struct CompiledCore {
    lib: Arc<libloading::Library>,
    vt: VTable,
    /// The coverage writer of a coverage build.
    coverage_write: Option<CoverageWrite>,
    top: String,
    /// The cached shared library.
    pub path: PathBuf,
    /// Whether an earlier build left it in the cache (nothing was built).
    pub cached: bool,
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

    /// A fresh instance that writes its coverage counters to `dat` when
    /// dropped; an error when the core was not built with `coverage`.
    pub fn instantiate_with_coverage(&self, trace: bool, dat: &Path) -> Result<Model, BridgeError> {
        let Some(write) = self.coverage_write else {
            return Err(BridgeError::Load { path: self.path.display().to_string(), message: "not a coverage build (ExternalCore::coverage is false)".into() });
        };
        let path = CString::new(dat.display().to_string()).map_err(|_| BridgeError::Load { path: dat.display().to_string(), message: "coverage path holds a NUL byte".into() })?;
        let mut m = self.instantiate(trace);
        m.coverage_out = Some((write, path));
        Ok(m)
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
        if let Some(r) = crate::vhdl::check(self) {
            return r;
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
        if self.coverage {
            // line (with its branch points), toggle and user coverage
            a.push("--coverage".into());
        }
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
        fnv1a(&mut h, self.inner_loop.as_deref().unwrap_or("").as_bytes());
        let ver = Command::new("verilator")
            .arg("--version")
            .output()
            .map(|o| o.stdout)
            .unwrap_or_default();
        fnv1a(&mut h, &ver);
        Ok(format!("{}-{h:016x}", self.top))
    }

    /// Verilates, compiles and loads the core, or loads it from `cache`
    /// where an earlier build of the same sources and options left it
    /// (one sub-directory per key; threads and processes building the same
    /// key at once are safe).
    pub fn build_in(&self, cache: &Path) -> Result<CompiledCore, BridgeError> {
        if let Some(lowered) = crate::vhdl::lower(self, cache)? {
            return lowered.build_in(cache);
        }
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
        let mut core = self.load(&entry.product)?;
        core.cached = entry.origin == buildcache::Origin::Cached;
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
            return Err(BridgeError::Verilate { top: top.clone(), dir: self.dir.display().to_string(), message: "`verilator` was not found: install Verilator (apt-get install verilator)".into() });
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
        let mut shim = shimgen::gen_shim(top, &ports, true, self.inner_loop.as_deref());
        if self.coverage {
            shim.push_str(&shimgen::gen_coverage_writer(top));
        }
        std::fs::write(tmp.join("cosim_shim.cpp"), shim)
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
        let coverage_write = if self.coverage {
            Some(sym!("coverage_write", CoverageWrite))
        } else {
            None
        };
        Ok(CompiledCore {
            lib: Arc::new(lib),
            vt,
            coverage_write,
            top: self.top.clone(),
            path: lib_path.to_path_buf(),
            cached: false,
            held: self.held_inputs.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::declares_module;

    #[test]
    fn module_scan_finds_the_top_by_whole_name_only() {
        assert!(declares_module("// x\nmodule core (\n input a);", "core"));
        assert!(declares_module("module\n  core#(parameter P=1)(a);", "core"));
        assert!(!declares_module("module core_pio (a);", "core"));
        assert!(!declares_module("core u0 (.a(a));", "core"), "an instance is not a declaration");
    }
}
