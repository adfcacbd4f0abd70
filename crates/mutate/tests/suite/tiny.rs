//! Mutation testing end to end on a tiny fixture core (tb/fixtures/
//! mutate_tiny.v): yosys mutations behind one select, one Verilator build,
//! the select held by the bridge, kills / survivors / equivalents checked
//! against rules derived from the fixture's logic, shards and the journal.

use mutate::{CampaignOptions, CoreSources, FormalOptions, FormalVerdict, MutationSource, Suite, TestInfo, TestResult, Verdict};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

fn fixture() -> CoreSources {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tb/fixtures").canonicalize().unwrap();
    CoreSources { dir, top: "mutate_tiny".into(), files: vec!["mutate_tiny.v".into()], ..Default::default() }
}

/// Two tests: `sum` checks y for every a, b with op = 0; `red` checks red
/// for the four a[0], b[0] combinations.
struct TinySuite {
    core: cosim::CompiledCore,
    runs: AtomicUsize,
}

impl Suite for TinySuite {
    fn tests(&self) -> Vec<TestInfo> {
        vec![TestInfo { name: "sum".into() }, TestInfo { name: "red".into() }]
    }

    fn run(&self, index: usize, select: u64) -> TestResult {
        self.runs.fetch_add(1, Ordering::SeqCst);
        let mut m = self.core.instantiate(false);
        let p = |m: &cosim::Model, n: &str| m.port(n, None, "fixture").unwrap();
        let sel = p(&m, mutate::SELECT);
        m.set(sel, select);
        let (clk, a, b, op, y, red) = (p(&m, "clk"), p(&m, "a"), p(&m, "b"), p(&m, "op"), p(&m, "y"), p(&m, "red"));
        m.set(op, 0);
        for va in 0..16u64 {
            for vb in 0..16u64 {
                if index == 1 && (va > 1 || vb > 1) {
                    continue;
                }
                // New inputs, then the rising edge: a flop on the wrong edge
                // still holds the previous vector's result.
                m.set(a, va);
                m.set(b, vb);
                m.set(clk, 1);
                m.eval();
                let (want, got, what) = if index == 0 { ((va + vb) & 15, m.get(y), "y") } else { (va & 1, m.get(red), "red") };
                if want != got {
                    return TestResult::Fail { why: format!("a={va} b={vb}: {what} = {got}, expected {want}"), field: None };
                }
                m.set(clk, 0);
                m.eval();
            }
        }
        TestResult::Pass
    }
}

/// What the fixture's logic says a mutation must end as.
#[derive(Debug, PartialEq)]
enum Expected {
    Killed,
    SurvivesWithCounterexample,
    Equivalent,
}

fn expected(m: &mutate::Mutation) -> Expected {
    let line = m.location();
    let on = |cell: &str| m.cell.starts_with(cell);
    // y <= op ? alt : sum: yosys's $mux is Y = S ? B : A, so B is alt.
    if line.ends_with(":15") || (line.ends_with(":16") && (m.port == "B" || (m.port == "S" && m.mode == "const0"))) {
        return Expected::SurvivesWithCounterexample;
    }
    // red = a[0] | (a[0] & b[0]) = a[0]: evaluate the mutated gate pair on
    // all four a[0], b[0]; the `red` test checks exactly those four.
    if on("$and") || on("$or") {
        let bit = |cell: &str, port: &str, v: bool| {
            if !(on(cell) && m.port == port) {
                return v;
            }
            match m.mode.as_str() {
                "inv" => !v,
                "const0" => false,
                "const1" => true,
                other => panic!("single-bit ports have no {other} mutation"),
            }
        };
        let red = |a0: bool, b0: bool| {
            let both = bit("$and", "Y", bit("$and", "A", a0) & bit("$and", "B", b0));
            bit("$or", "Y", bit("$or", "A", a0) | bit("$or", "B", both))
        };
        let same = [(false, false), (false, true), (true, false), (true, true)].iter().all(|&(a0, b0)| red(a0, b0) == a0);
        return if same { Expected::Equivalent } else { Expected::Killed };
    }
    Expected::Killed
}

#[test]
fn the_fixture_s_mutants_end_as_its_logic_says() {
    let cache = tempfile::tempdir().unwrap();
    let t0 = std::time::Instant::now();
    let inst = mutate::instrument(&fixture(), &MutationSource::Sample { count: 60, seed: 3 }, cache.path()).unwrap();
    assert_eq!(inst.mutations.len(), 60);
    assert!(inst.build_errors.is_empty(), "{:?}", inst.build_errors);
    let t = std::fs::read_to_string(&inst.verilog).unwrap();
    assert!(t.contains(mutate::SELECT), "the select is an input of the mutated top");
    // One Verilator build for every mutant.
    let mut core = inst.external_core();
    let compiled = core.build_in(cache.path()).unwrap();
    // The bridge holds the select: every instance starts with it set (same build).
    core.held_inputs = vec![(mutate::SELECT.into(), 5)];
    let held = core.build_in(cache.path()).unwrap();
    assert_eq!(held.path, compiled.path, "held inputs are not part of the build");
    let m = held.instantiate(false);
    assert_eq!(m.get(m.port(mutate::SELECT, None, "t").unwrap()), 5);
    // A held input the core lacks is a build error, not a silent no-op.
    core.held_inputs = vec![("no_such_port".into(), 1)];
    assert!(matches!(core.build_in(cache.path()), Err(cosim::BridgeError::MissingPort { .. })));

    eprintln!("yosys + verilator: {:.1} s", t0.elapsed().as_secs_f64());
    let suite = TinySuite { core: compiled, runs: AtomicUsize::new(0) };
    let base = mutate::campaign::baseline(&suite, 2);
    assert!(base.iter().all(|b| b.passed), "the original passes its tests: {base:?}");
    let opts = CampaignOptions { jobs: 2, ..Default::default() };
    let results = mutate::campaign::run_mutants(&suite, &base, &inst.mutations, &inst.build_errors, &opts).unwrap();
    assert_eq!(results.len(), 60);
    let mut report = mutate::Report { core: "tiny".into(), source: "test".into(), baseline: base.clone(), mutants: results, formal: Vec::new(), hidden: Vec::new(), audit: None, build_seconds: 0.0, run_seconds: 0.0 };
    let work = tempfile::tempdir().unwrap();
    mutate::check_survivors(&mut report, &inst, &FormalOptions { steps: 6, induction: 6, timeout_s: 30 }, work.path(), &mut |_| {}).unwrap();
    eprintln!("campaign + formal: {:.1} s", t0.elapsed().as_secs_f64());
    let mut seen = [0usize; 3];
    for m in &report.mutants {
        let want = expected(&m.mutation);
        let formal = report.formal_of(m.id);
        match want {
            Expected::Killed => {
                assert!(matches!(m.verdict, Verdict::Killed { .. }), "{} {}: {:?}", m.location, m.description, m.verdict);
                seen[0] += 1;
            }
            Expected::SurvivesWithCounterexample => {
                assert_eq!(m.verdict, Verdict::Survived, "{} {}", m.location, m.description);
                let Some(FormalVerdict::Differs { trace, .. }) = formal else { panic!("{} {}: {formal:?}", m.location, m.description) };
                assert!(trace.iter().any(|t| t.port == "op" && t.value == 1), "only op = 1 shows the xor path: {trace:?}");
                let sk = work.path().join(format!("skeletons/mutant-{}.toml", m.id));
                assert!(std::fs::read_to_string(&sk).unwrap().contains(&format!("Kills mutant {}", m.id)));
                seen[1] += 1;
            }
            Expected::Equivalent => {
                assert_eq!(m.verdict, Verdict::Survived, "{} {}", m.location, m.description);
                assert!(matches!(formal, Some(FormalVerdict::Equivalent { .. })), "{} {}: {formal:?}", m.location, m.description);
                seen[2] += 1;
            }
        }
    }
    assert!(seen.iter().all(|&n| n > 0), "the sample has every kind (killed, survivor, equivalent): {seen:?}");
    let c = report.counts();
    assert_eq!((c.killed, c.survived, c.equivalent), (seen[0], seen[1], seen[2]));
    let score = report.score().unwrap();
    assert!((score - seen[0] as f64 / (60 - seen[2]) as f64).abs() < 1e-12);
    let md = report.to_markdown();
    assert!(md.contains("## Survivors") && md.contains("mutate_tiny.v:15"), "{md}");
    let json: serde_json::Value = serde_json::from_str(&report.to_json()).unwrap();
    assert_eq!(json["counts"]["equivalent"], seen[2]);

    // Shards partition the mutants; the journal resumes without re-running.
    let journal = work.path().join("journal.jsonl");
    let mut union = Vec::new();
    for k in 1..=2 {
        let o = CampaignOptions { jobs: 1, shard: Some((k, 2)), journal: Some(journal.clone()), ..Default::default() };
        union.extend(mutate::campaign::run_mutants(&suite, &base, &inst.mutations, &inst.build_errors, &o).unwrap());
    }
    union.sort_by_key(|r| r.id);
    assert_eq!(union.iter().map(|r| (r.id, r.verdict.clone())).collect::<Vec<_>>(), report.mutants.iter().map(|r| (r.id, r.verdict.clone())).collect::<Vec<_>>());
    let before = suite.runs.load(Ordering::SeqCst);
    let again = mutate::campaign::run_mutants(&suite, &base, &inst.mutations, &inst.build_errors, &CampaignOptions { journal: Some(journal), ..Default::default() }).unwrap();
    assert_eq!(again.len(), 60);
    assert_eq!(suite.runs.load(Ordering::SeqCst), before, "every mutant came from the journal");
}
