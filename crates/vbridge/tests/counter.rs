//! vbridge on a tiny counter (tests/counter/counter.v): build, reset, clock,
//! read by name; a bad source's error; the build cache reused and keyed.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use vbridge::{BridgeError, CompiledCore, ExternalCore, PortDir};

fn counter_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/counter")
}

fn counter(defines: &[&str]) -> ExternalCore {
    ExternalCore {
        dir: counter_dir(),
        top: "counter".into(),
        defines: defines.iter().map(|d| d.to_string()).collect(),
        ..Default::default()
    }
}

/// One build of the plain counter for the tests that only use it, in a
/// cache under the target directory (keyed, so reruns reuse it safely).
fn shared_counter() -> &'static CompiledCore {
    static BUILT: OnceLock<CompiledCore> = OnceLock::new();
    BUILT.get_or_init(|| {
        let cache = Path::new(env!("CARGO_TARGET_TMPDIR")).join("vbridge-counter-cache");
        counter(&[]).build_in(&cache).unwrap_or_else(|e| panic!("{e}"))
    })
}

#[test]
fn counter_builds_resets_counts_and_is_read_by_name() {
    let built = shared_counter();
    let mut m = built.instantiate(false);
    assert_eq!(m.top(), "counter");
    let shape: Vec<(&str, u32, PortDir)> =
        m.ports().iter().map(|p| (p.name.as_str(), p.width, p.dir)).collect();
    assert_eq!(
        shape,
        vec![
            ("clk", 1, PortDir::In),
            ("rst", 1, PortDir::In),
            ("en", 1, PortDir::In),
            ("count", 8, PortDir::Out),
            ("wrapped", 1, PortDir::Out),
        ]
    );
    let clk = m.port("clk", Some(1), "counter").unwrap();
    let rst = m.port_by_name("rst").unwrap();
    let en = m.port_by_name("en").unwrap();
    let count = m.port("count", Some(8), "counter").unwrap();
    let wrapped = m.port_by_name("wrapped").unwrap();
    m.set(rst, 1);
    m.step_clock(clk, 1);
    assert_eq!(m.get(count), 0, "reset clears the count");
    assert_eq!(m.get(wrapped), 1);
    m.set(rst, 0);
    m.step_clock(clk, 5);
    assert_eq!(m.get(count), 0, "disabled: holds");
    m.set(en, 3); // masked to the port's 1 bit
    assert_eq!(m.get(en), 1, "writes are masked to the width");
    m.step_clock(clk, 7);
    assert_eq!(m.get(count), 7);
    assert_eq!(m.get(wrapped), 0);
    // Edges by hand: only a rising edge counts.
    m.set(clk, 1);
    m.eval();
    assert_eq!(m.get(count), 8);
    m.eval();
    assert_eq!(m.get(count), 8, "no edge, no count");
    m.set(clk, 0);
    m.eval();
    m.step_clock(clk, 248);
    assert_eq!(m.get(count), 0, "8 bits wrap at 256");
    assert_eq!(m.get(wrapped), 1);
    // Two instances of one build do not share state.
    let other = built.instantiate(false);
    let other_count = other.port_by_name("count").unwrap();
    assert_eq!(other.get(other_count), 0);
}

#[test]
fn missing_and_misshaped_ports_are_named() {
    let m = shared_counter().instantiate(false);
    let e = m.port_by_name("reset_n").unwrap_err();
    assert!(matches!(e, BridgeError::MissingPort { .. }), "{e}");
    let msg = e.to_string();
    assert!(msg.contains("`reset_n`") && msg.contains("clk rst en count wrapped"), "{msg}");
    let e = m.port("count", Some(16), "counter").unwrap_err();
    assert!(e.to_string().contains("8 bits wide"), "{e}");
}

#[test]
fn a_syntax_error_names_file_and_line() {
    let src = tempfile::tempdir().unwrap();
    std::fs::write(
        src.path().join("bad.v"),
        "module bad(input a, output b);\n  assign b = a +;\nendmodule\n",
    )
    .unwrap();
    let core = ExternalCore { dir: src.path().into(), top: "bad".into(), ..Default::default() };
    let e = core.build_in(&src.path().join("cache")).unwrap_err();
    assert!(matches!(e, BridgeError::Verilate { .. }), "{e}");
    let msg = e.to_string();
    assert!(msg.contains("bad.v:2:"), "file:line of the error: {msg}");
    assert!(msg.starts_with("Verilator could not build top `bad`"), "{msg}");
    // Nothing half-built is left to be mistaken for a build.
    let cache = src.path().join("cache");
    let left: Vec<_> = std::fs::read_dir(&cache).map(|d| d.count()).into_iter().collect();
    assert!(left.iter().all(|n| *n == 0), "no entry after a failed build: {left:?}");
}

#[test]
fn check_rejects_a_directory_without_the_top_in_one_line() {
    let mut core = counter(&[]);
    core.top = "countr".into();
    let e = core.check().unwrap_err().to_string();
    assert!(e.contains("no `module countr`") && !e.contains('\n'), "{e}");
    assert!(counter(&[]).check().is_ok());
}

#[test]
fn the_cache_is_reused_and_keyed_on_the_options() {
    let cache = tempfile::tempdir().unwrap();
    let first = counter(&[]).build_in(cache.path()).unwrap();
    let again = counter(&[]).build_in(cache.path()).unwrap();
    assert!(!first.cached, "an empty cache builds");
    assert!(again.cached, "the second build is a cache hit");
    assert_eq!(first.path, again.path);
    // Another define is another key, and the define reaches the design.
    let by_two = counter(&["STEP=2"]).build_in(cache.path()).unwrap();
    assert!(!by_two.cached);
    assert_ne!(by_two.path, first.path);
    let mut m = by_two.instantiate(false);
    let (clk, en, count) = (
        m.port_by_name("clk").unwrap(),
        m.port_by_name("en").unwrap(),
        m.port_by_name("count").unwrap(),
    );
    m.set(en, 1);
    m.step_clock(clk, 3);
    assert_eq!(m.get(count), 6, "STEP=2 counts by two");
    // An inner loop is part of the key too.
    let mut looped = counter(&[]);
    looped.inner_loop = Some("  return 7;".into());
    let looped = looped.build_in(cache.path()).unwrap();
    assert_ne!(looped.path, first.path);
    let entries = std::fs::read_dir(cache.path()).unwrap().count();
    assert_eq!(entries, 3, "three keys, no work directories left");
}

#[test]
fn an_inner_loop_runs_many_evals_in_one_call() {
    // The loop clocks the counter `n` times; its argument is a pointer to
    // the clock port's storage and a count.
    #[repr(C)]
    struct Arg {
        clk: *mut u8,
        n: u32,
    }
    let mut core = counter(&[]);
    core.inner_loop = Some(
        "  struct Arg { uint8_t* clk; uint32_t n; };\n  const Arg* a = (const Arg*)arg;\n  \
         for (uint32_t k = 0; k < a->n; ++k) { *a->clk = 1; m->eval(); *a->clk = 0; m->eval(); }\n  \
         return a->n;"
            .into(),
    );
    let cache = tempfile::tempdir().unwrap();
    let mut m = core.build_in(cache.path()).unwrap().instantiate(false);
    let (clk, en, count) = (
        m.port_by_name("clk").unwrap(),
        m.port_by_name("en").unwrap(),
        m.port_by_name("count").unwrap(),
    );
    m.set(en, 1);
    m.eval();
    let arg = Arg { clk: clk.as_ptr(), n: 10 };
    // SAFETY: the loop above reads an `Arg` whose pointer is this model's
    // 1-bit clock.
    let made = unsafe { m.run_inner_loop(&arg as *const Arg as *const std::ffi::c_void) };
    assert_eq!(made, 10);
    assert_eq!(m.get(count), 10);
}

#[test]
fn a_vcd_trace_records_the_counter() {
    let cache = tempfile::tempdir().unwrap();
    let built = shared_counter();
    let mut untraced = built.instantiate(false);
    let vcd = cache.path().join("counter.vcd");
    let e = untraced.trace_open(&vcd).unwrap_err();
    assert!(e.to_string().contains("without tracing"), "{e}");
    let mut m = built.instantiate(true);
    m.trace_open(&vcd).unwrap();
    let (clk, en) = (m.port_by_name("clk").unwrap(), m.port_by_name("en").unwrap());
    m.set(en, 1);
    for t in 0..4u64 {
        m.set(clk, t & 1);
        m.eval();
        m.trace_dump(t * 1000);
    }
    m.trace_close();
    let text = std::fs::read_to_string(&vcd).unwrap();
    assert!(text.contains("$var") && text.contains(" count "), "a VCD with the count: {}", &text[..text.len().min(400)]);
}
