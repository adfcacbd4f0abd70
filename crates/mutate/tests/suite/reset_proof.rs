//! The formal check per module from reset (crates/mutate/src/reset_proof.rs)
//! on two fixtures: it proves mutants equivalent only by a completed proof,
//! refutes visible ones with a trace, and the reset state is what makes the
//! difference for a mutant of a state the reset never leads to.

use mutate::{CoreSources, FormalOptions, FormalVerdict, MutationSource, Mutation};
use std::path::PathBuf;

fn fixture(file: &str, top: &str) -> CoreSources {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tb/fixtures").canonicalize().unwrap();
    CoreSources { dir, top: top.into(), files: vec![file.into()], ..Default::default() }
}

fn yosys_missing() -> bool {
    std::process::Command::new("yosys-abc").arg("-c").arg("quit").output().is_err() || std::process::Command::new("yosys").arg("-V").output().is_err()
}

fn pick<'a>(ms: &'a [Mutation], what: &str, f: impl Fn(&Mutation) -> bool) -> &'a Mutation {
    ms.iter().find(|m| f(m)).unwrap_or_else(|| panic!("the sample has no {what}"))
}

const OPTS: FormalOptions = FormalOptions { steps: 8, induction: 8, timeout_s: 30 };

#[test]
fn a_mutant_of_a_state_reset_never_reaches_is_proved_and_a_visible_one_refuted() {
    if yosys_missing() {
        eprintln!("yosys / yosys-abc not installed: skipped");
        return;
    }
    let src = fixture("formal_reset.v", "formal_reset");
    let cache = tempfile::tempdir().unwrap();
    let inst = mutate::instrument(&src, &MutationSource::Sample { count: 200, seed: 1 }, cache.path()).unwrap();
    let at_zero = |m: &Mutation| m.cell.starts_with("$flatten\\u_ring.$ternary$") && m.location().ends_with("formal_reset.v:16");
    let hidden = pick(&inst.mutations, "mutation of at_zero's B input (st == 0 only)", |m| at_zero(m) && m.port == "B");
    let shown = pick(&inst.mutations, "mutation of at_zero's A input (st != 0)", |m| at_zero(m) && m.port == "A");
    let work = tempfile::tempdir().unwrap();

    let c = mutate::reset_proof::check_in_module(&src, hidden, &OPTS, work.path()).unwrap().unwrap();
    assert_eq!(c.module, "formal_ring", "checked in its own module, not the top");
    let FormalVerdict::Equivalent { method } = &c.verdict else { panic!("{}: {:?}", hidden.args, c.verdict) };
    assert!(method.contains("proved from reset") && method.contains("rst forced in the first clk cycle"), "{method}");

    let c = mutate::reset_proof::check_in_module(&src, shown, &OPTS, work.path()).unwrap().unwrap();
    let FormalVerdict::ModuleDiffers { module, trace, .. } = &c.verdict else { panic!("{}: {:?}", shown.args, c.verdict) };
    assert_eq!(module, "formal_ring");
    assert!(trace.iter().any(|t| t.port == "rst"), "the trace is in the module's inputs: {trace:?}");

    // Without the reset state (the whole-core check, registers from zero)
    // st starts at 0 and the hidden mutant shows: the reset is what proves it.
    let old = mutate::formal::check(&inst, hidden.id, &OPTS, &work.path().join("whole")).unwrap();
    assert!(matches!(old, FormalVerdict::Differs { .. }), "{old:?}");
}

#[test]
fn the_tiny_fixture_without_reset_is_checked_from_zero() {
    if yosys_missing() {
        eprintln!("yosys / yosys-abc not installed: skipped");
        return;
    }
    let src = fixture("mutate_tiny.v", "mutate_tiny");
    let cache = tempfile::tempdir().unwrap();
    let inst = mutate::instrument(&src, &MutationSource::Sample { count: 60, seed: 3 }, cache.path()).unwrap();
    // red = a[0] | (a[0] & b[0]): the & output stuck at 0 leaves red = a[0].
    let eq = pick(&inst.mutations, "& output stuck at 0", |m| m.cell.starts_with("$and") && m.port == "Y" && m.mode == "const0");
    // y <= op ? alt : sum: the xor path shows with op = 1.
    let xor = pick(&inst.mutations, "mutation of the xor", |m| m.cell.starts_with("$xor"));
    let work = tempfile::tempdir().unwrap();
    let c = mutate::reset_proof::check_in_module(&src, eq, &OPTS, work.path()).unwrap().unwrap();
    let FormalVerdict::Equivalent { method } = &c.verdict else { panic!("{}: {:?}", eq.args, c.verdict) };
    assert!(method.contains("no reset input"), "{method}");
    let c = mutate::reset_proof::check_in_module(&src, xor, &OPTS, work.path()).unwrap().unwrap();
    let FormalVerdict::ModuleDiffers { trace, .. } = &c.verdict else { panic!("{}: {:?}", xor.args, c.verdict) };
    assert!(trace.iter().any(|t| t.port == "op" && t.value == 1), "only op = 1 shows the xor path: {trace:?}");
}

/// A module whose own outputs are undefined at times (x at address 3) differs from itself when each copy picks its x
/// freely; with its x shared by both copies (shared_undef.rs) its mutants get verdicts, and no false "equivalent":
/// a mutant of the register writes, seen only through q at a defined address, is refuted; one that pins the x is
/// refuted; a redundant gate is proved. (Before shared_undef.rs all three were "no verdict".)
#[test]
fn a_module_with_undefined_outputs_gets_verdicts_with_its_undefined_values_shared() {
    if yosys_missing() {
        eprintln!("yosys / yosys-abc not installed: skipped");
        return;
    }
    let src = fixture("formal_undef.v", "formal_undef");
    let cache = tempfile::tempdir().unwrap();
    let inst = mutate::instrument(&src, &MutationSource::Sample { count: 60, seed: 1 }, cache.path()).unwrap();
    let work = tempfile::tempdir().unwrap();
    let check = |m: &Mutation| mutate::reset_proof::check_in_module(&src, m, &OPTS, work.path()).unwrap().unwrap().verdict;

    // r1's flop, bit 0, inverted under bit 1: r1 reaches q only at a = 1 or 2, where q is defined.
    let write = pick(&inst.mutations, "mutation of r1", |m| m.cell.starts_with("$procdff$") && m.args.contains("-wire r1 "));
    let FormalVerdict::ModuleDiffers { trace, assumed, .. } = check(write) else { panic!("{}: not refuted", write.args) };
    assert!(assumed.contains("1 undefined values (x) shared"), "{assumed}");
    assert!(trace.iter().any(|t| t.port == "cosim_undef_0"), "the shared x is an input of the trace: {trace:?}");
    assert!(trace.iter().any(|t| t.port == "a" && (t.value == 1 || t.value == 2)), "seen through a defined q (a = 1 or 2): {trace:?}");

    // The x input of q's mux (a == 3) held at 1: it pins the undefined value, seen whenever the shared x is 0.
    let pin = pick(&inst.mutations, "mutation of the x input of q's mux", |m| m.cell.starts_with("$ternary$") && m.port == "B" && m.args.contains("formal_undef.v:22.57-22.100"));
    let v = check(pin);
    assert!(matches!(v, FormalVerdict::ModuleDiffers { .. }), "{}: {v:?}", pin.args);

    // wen = we | (we & d[1]): its AND term stuck at 0 changes nothing.
    let redundant = pick(&inst.mutations, "AND of wen stuck at 0", |m| m.cell.starts_with("$and$") && m.port == "Y" && m.mode == "const0");
    let v = check(redundant);
    let FormalVerdict::Equivalent { method } = &v else { panic!("{}: not proved: {v:?}", redundant.args) };
    assert!(method.contains("proved from reset") && method.contains("shared"), "{method}");
}

/// The control run still decides: the x of a submodule (formal_undef inside formal_undef_outer) is not one of the
/// checked module's own x constants, so it is not shared; it reaches q, the module differs from itself even with its
/// x constants shared, and a mutant of its own flop gets no verdict rather than a difference or a proof.
#[test]
fn a_module_that_differs_from_itself_with_its_x_shared_gives_no_verdict() {
    if yosys_missing() {
        eprintln!("yosys / yosys-abc not installed: skipped");
        return;
    }
    let src = fixture("formal_undef.v", "formal_undef_outer");
    let cache = tempfile::tempdir().unwrap();
    let inst = mutate::instrument(&src, &MutationSource::Sample { count: 60, seed: 1 }, cache.path()).unwrap();
    let m = pick(&inst.mutations, "mutation of seen's flop", |m| m.cell.starts_with("$procdff$") && m.args.contains("-wire seen "));
    let work = tempfile::tempdir().unwrap();
    let c = mutate::reset_proof::check_in_module(&src, m, &OPTS, work.path()).unwrap().unwrap();
    assert_eq!(c.module, "formal_undef_outer");
    let FormalVerdict::Unknown { why } = &c.verdict else { panic!("{}: {:?}", m.args, c.verdict) };
    assert!(why.contains("differs from itself") && why.contains("even with its x constants shared"), "{why}");
}
