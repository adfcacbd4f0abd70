//! The widened formal check (crates/mutate/src/widen.rs) on a fixture of
//! three modules (tb/fixtures/formal_widen.v): a mutant the per-module check
//! refutes only because its module's input is free is proved once the
//! module that drives that input is kept; a mutant seen only through the
//! input of a module the widened check cuts is still refuted there.

use mutate::widen::{self, Scope};
use mutate::{CoreSources, FormalOptions, FormalVerdict, Mutation, MutationSource};
use std::path::PathBuf;

fn fixture() -> CoreSources {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tb/fixtures").canonicalize().unwrap();
    CoreSources { dir, top: "formal_widen".into(), files: vec!["formal_widen.v".into()], ..Default::default() }
}

fn yosys_missing() -> bool {
    std::process::Command::new("yosys-abc").arg("-c").arg("quit").output().is_err() || std::process::Command::new("yosys").arg("-V").output().is_err()
}

fn pick<'a>(ms: &'a [Mutation], what: &str, f: impl Fn(&Mutation) -> bool) -> &'a Mutation {
    ms.iter().find(|m| f(m)).unwrap_or_else(|| panic!("the sample has no {what}"))
}

const OPTS: FormalOptions = FormalOptions { steps: 8, induction: 8, timeout_s: 30 };

fn the_scope() -> Scope {
    Scope { mutated: "u_use".into(), with: vec!["u_drv".into()] }
}

/// `code == 3 ? d : !q` with the B input (d) inverted: per module (code free)
/// q differs after a clock with code = 3; widen_drv never drives 3, so with
/// it kept the mutant is proved, and the kit chooses that scope itself.
#[test]
fn a_mutant_its_driver_never_exercises_is_refuted_per_module_and_proved_widened() {
    if yosys_missing() {
        eprintln!("yosys / yosys-abc not installed: skipped");
        return;
    }
    let src = fixture();
    let cache = tempfile::tempdir().unwrap();
    let inst = mutate::instrument(&src, &MutationSource::Sample { count: 200, seed: 1 }, cache.path()).unwrap();
    let m = pick(&inst.mutations, "inverted B input of the next-state mux", |m| {
        m.cell.starts_with("$flatten\\u_use.$ternary$") && m.port == "B" && m.mode == "inv"
    });
    let work = tempfile::tempdir().unwrap();

    let c = mutate::reset_proof::check_in_module(&src, m, &OPTS, work.path()).unwrap().unwrap();
    assert_eq!(c.module, "widen_use");
    let FormalVerdict::ModuleDiffers { trace, .. } = &c.verdict else { panic!("per module: {:?}", c.verdict) };
    assert!(trace.iter().any(|t| t.port == "code" && t.value == 3), "refuted per module only through code = 3: {trace:?}");

    let design_scopes = widen::check_widened(&src, m, None, &OPTS, work.path()).unwrap();
    assert_eq!(design_scopes.len(), 1, "one scope tried, and it proved the mutant: {design_scopes:?}");
    let w = &design_scopes[0];
    assert_eq!(w.scope, the_scope(), "the driver of code is kept, the sink is not");
    let FormalVerdict::Equivalent { method } = &w.verdict else { panic!("widened: {:?}", w.verdict) };
    assert!(method.contains("u_use (widen_use) + u_drv (widen_drv)") && method.contains("other modules cut") && method.contains("rst forced"), "{method}");

    // What the mutate flow reports: the widened proof, naming its scope.
    let v = widen::combine(&c.module, c.verdict.clone(), &design_scopes);
    assert!(matches!(&v, FormalVerdict::Equivalent { method } if method.contains("formal_widen scope u_use")), "{v:?}");
}

/// `side = d & code[1]` with the AND's output inverted: side only feeds
/// widen_sink, which the widened check cuts. Its input is compared, so the
/// mutant is refuted in the widened scope too, never proved (the soundness
/// guard: without that comparison nothing the scope's outputs show differs).
#[test]
fn a_mutant_seen_only_at_a_cut_modules_input_is_still_refuted() {
    if yosys_missing() {
        eprintln!("yosys / yosys-abc not installed: skipped");
        return;
    }
    let src = fixture();
    let cache = tempfile::tempdir().unwrap();
    let inst = mutate::instrument(&src, &MutationSource::Sample { count: 200, seed: 1 }, cache.path()).unwrap();
    let m = pick(&inst.mutations, "inverted output of side's AND", |m| m.cell.starts_with("$flatten\\u_use.$and$") && m.port == "Y" && m.mode == "inv");
    let work = tempfile::tempdir().unwrap();
    let ws = widen::check_widened(&src, m, Some(&the_scope()), &OPTS, work.path()).unwrap();
    assert_eq!(ws.len(), 1);
    let FormalVerdict::ModuleDiffers { module, trace, assumed, .. } = &ws[0].verdict else { panic!("widened: {:?}", ws[0].verdict) };
    assert!(module.contains("formal_widen scope u_use (widen_use) + u_drv (widen_drv)"), "{module}");
    assert!(assumed.contains("the 2 bits the scope drives into them"), "side and the top output q are compared: {assumed}");
    assert!(!trace.is_empty(), "a trace in the scope's inputs: {trace:?}");
    let v = widen::combine("widen_use", FormalVerdict::Unknown { why: "per module".into() }, &ws);
    assert!(matches!(v, FormalVerdict::ModuleDiffers { .. }), "{v:?}");
}
