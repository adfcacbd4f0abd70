//! The mutant loop: a baseline run of every test with the select at 0,
//! then each mutant as simulations with its select set, stopped at the
//! first failing test; tests ordered by kills per second so far (shortest
//! first until something kills); workers, shards, a journal to resume.

use crate::mutation::Mutation;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::io::Write;
use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// A test of the suite (a scenario), with its place in the order.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TestInfo {
    /// Name in reports.
    pub name: String,
}

/// What one test said about one select value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum TestResult {
    /// It passed.
    Pass,
    /// Not run for a reason of the suite's (a scenario fixed to another host).
    Skipped(String),
    /// It failed: where first, and the CAN frame field if the failure has one.
    Fail {
        /// First divergence or failed expectation, in words.
        why: String,
        /// Frame field of the first divergence.
        field: Option<String>,
    },
}

/// The tests, run on the one build with a select value.
pub trait Suite: Sync {
    /// The tests, in the suite's own order.
    fn tests(&self) -> Vec<TestInfo>;
    /// Runs test `index` with the mutant select at `select` (0 = original).
    fn run(&self, index: usize, select: u64) -> TestResult;
}

/// How a mutant ended.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "verdict", rename_all = "kebab-case")]
pub enum Verdict {
    /// A test failed.
    Killed {
        /// The test.
        test: String,
        /// Its first divergence / failed expectation.
        why: String,
        /// Frame field, if any.
        field: Option<String>,
    },
    /// Every test passed.
    Survived,
    /// Its tests took longer than the budget before any failed.
    TimedOut {
        /// Tests run before the budget ran out.
        tests_run: usize,
    },
    /// Yosys could not insert it.
    BuildError {
        /// Yosys's words.
        message: String,
    },
}

/// One mutant's result.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MutantResult {
    /// Select value.
    pub id: u32,
    /// The mutation.
    pub mutation: Mutation,
    /// `file:line`.
    pub location: String,
    /// In words.
    pub description: String,
    /// How it ended.
    pub verdict: Verdict,
    /// Tests run.
    pub tests_run: usize,
    /// Wall time of its tests.
    pub seconds: f64,
}

/// A test's baseline (select 0).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Baseline {
    /// Test name.
    pub test: String,
    /// Passed on the original (only those can kill).
    pub passed: bool,
    /// Why not, when it did not.
    pub note: Option<String>,
    /// Wall time.
    pub seconds: f64,
}

/// Options of the loop.
#[derive(Clone, Debug)]
pub struct CampaignOptions {
    /// Worker threads (0 = one per core).
    pub jobs: usize,
    /// Only mutants with `(index % n) == k - 1`.
    pub shard: Option<(usize, usize)>,
    /// Append each result here as a JSON line; results already in it
    /// (same id and mutation) are taken, not re-run.
    pub journal: Option<PathBuf>,
    /// Show a progress bar.
    pub progress: bool,
    /// A mutant times out when its tests take longer than this many times
    /// the baseline's total (and at least `min_budget`).
    pub budget_factor: f64,
    /// Floor of the budget.
    pub min_budget: Duration,
}

impl Default for CampaignOptions {
    fn default() -> Self {
        CampaignOptions { jobs: 0, shard: None, journal: None, progress: false, budget_factor: 4.0, min_budget: Duration::from_secs(30) }
    }
}

/// Runs every test with select 0, in parallel.
pub fn baseline(suite: &dyn Suite, jobs: usize) -> Vec<Baseline> {
    let tests = suite.tests();
    let out: Mutex<Vec<Option<Baseline>>> = Mutex::new(vec![None; tests.len()]);
    let next = AtomicUsize::new(0);
    std::thread::scope(|sc| {
        for _ in 0..workers(jobs).min(tests.len().max(1)) {
            sc.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(t) = tests.get(i) else { break };
                    let t0 = Instant::now();
                    let r = suite.run(i, 0);
                    let b = Baseline {
                        test: t.name.clone(),
                        passed: r == TestResult::Pass,
                        note: match r {
                            TestResult::Pass => None,
                            TestResult::Skipped(w) => Some(format!("skipped: {w}")),
                            TestResult::Fail { why, .. } => Some(format!("fails on the original: {why}")),
                        },
                        seconds: t0.elapsed().as_secs_f64(),
                    };
                    out.lock().expect("no panics under the lock")[i] = Some(b);
                }
            });
        }
    });
    out.into_inner().expect("no panics under the lock").into_iter().map(|b| b.expect("every test ran")).collect()
}

fn workers(jobs: usize) -> usize {
    if jobs == 0 { std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1) } else { jobs }
}

/// Results already in the journal (by id, mutation unchanged).
pub fn read_journal(path: &std::path::Path, mutations: &[Mutation]) -> HashMap<u32, MutantResult> {
    let Ok(text) = std::fs::read_to_string(path) else { return HashMap::new() };
    text.lines()
        .filter_map(|l| serde_json::from_str::<MutantResult>(l).ok())
        .filter(|r| mutations.iter().any(|m| m.id == r.id && m.args == r.mutation.args))
        .map(|r| (r.id, r))
        .collect()
}

/// Runs the mutants (after [`baseline`]): tests that failed on the
/// original are not used. Returns one result per mutant of this shard, in
/// id order.
pub fn run_mutants(suite: &dyn Suite, base: &[Baseline], mutations: &[Mutation], build_errors: &[(u32, String)], opts: &CampaignOptions) -> std::io::Result<Vec<MutantResult>> {
    let tests = suite.tests();
    let usable: Vec<usize> = (0..tests.len()).filter(|&i| base[i].passed).collect();
    let total: f64 = usable.iter().map(|&i| base[i].seconds).sum();
    let budget = Duration::from_secs_f64((total * opts.budget_factor).max(opts.min_budget.as_secs_f64()));
    let mine: Vec<&Mutation> = mutations.iter().enumerate().filter(|(i, _)| opts.shard.is_none_or(|(k, n)| i % n == k - 1)).map(|(_, m)| m).collect();
    let done = opts.journal.as_deref().map(|p| read_journal(p, mutations)).unwrap_or_default();
    let kills: Mutex<HashMap<usize, u32>> = Mutex::new(HashMap::new());
    let journal = match &opts.journal {
        Some(p) => Some(Mutex::new(
            std::fs::OpenOptions::new().create(true).append(true).open(p).map_err(|e| std::io::Error::new(e.kind(), format!("opening the journal {}: {e}", p.display())))?,
        )),
        None => None,
    };
    let results: Mutex<Vec<MutantResult>> = Mutex::new(Vec::new());
    let todo: Vec<&Mutation> = mine.iter().copied().filter(|m| !done.contains_key(&m.id)).collect();
    for m in &mine {
        if let Some(r) = done.get(&m.id) {
            if let Verdict::Killed { test, .. } = &r.verdict
                && let Some(i) = tests.iter().position(|t| &t.name == test)
            {
                *kills.lock().expect("no panics under the lock").entry(i).or_default() += 1;
            }
            results.lock().expect("no panics under the lock").push(r.clone());
        }
    }
    let bar = if opts.progress { indicatif::ProgressBar::new(mine.len() as u64) } else { indicatif::ProgressBar::hidden() };
    bar.set_style(indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} mutants {elapsed} (eta {eta}) {msg}").unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()));
    bar.set_position((mine.len() - todo.len()) as u64);
    let next = AtomicUsize::new(0);
    std::thread::scope(|sc| {
        for _ in 0..workers(opts.jobs).min(todo.len().max(1)) {
            sc.spawn(|| {
                loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(m) = todo.get(i) else { break };
                    let r = if let Some((_, msg)) = build_errors.iter().find(|(id, _)| *id == m.id) {
                        result(m, Verdict::BuildError { message: msg.clone() }, 0, 0.0)
                    } else {
                        // Most kills per second of test so far first; with no
                        // kills yet, shortest first.
                        let mut order = usable.clone();
                        {
                            let k = kills.lock().expect("no panics under the lock");
                            let rate = |t: &usize| (1.0 + *k.get(t).unwrap_or(&0) as f64) / base[*t].seconds.max(1e-3);
                            order.sort_by(|a, b| rate(b).total_cmp(&rate(a)).then(a.cmp(b)));
                        }
                        run_one(suite, &tests, m, &order, budget, &kills)
                    };
                    if let Some(j) = &journal {
                        let mut f = j.lock().expect("no panics under the lock");
                        let _ = writeln!(f, "{}", serde_json::to_string(&r).expect("plain data"));
                    }
                    let mut all = results.lock().expect("no panics under the lock");
                    all.push(r);
                    let killed = all.iter().filter(|r| matches!(r.verdict, Verdict::Killed { .. })).count();
                    bar.set_message(format!("{killed} killed, {} survived", all.iter().filter(|r| r.verdict == Verdict::Survived).count()));
                    bar.inc(1);
                }
            });
        }
    });
    bar.finish_and_clear();
    let mut v = results.into_inner().expect("no panics under the lock");
    v.sort_by_key(|r| r.id);
    Ok(v)
}

fn result(m: &Mutation, verdict: Verdict, tests_run: usize, seconds: f64) -> MutantResult {
    MutantResult { id: m.id, mutation: m.clone(), location: m.location(), description: m.describe(), verdict, tests_run, seconds }
}

fn run_one(suite: &dyn Suite, tests: &[TestInfo], m: &Mutation, order: &[usize], budget: Duration, kills: &Mutex<HashMap<usize, u32>>) -> MutantResult {
    let t0 = Instant::now();
    for (n, &t) in order.iter().enumerate() {
        if t0.elapsed() > budget {
            return result(m, Verdict::TimedOut { tests_run: n }, n, t0.elapsed().as_secs_f64());
        }
        if let TestResult::Fail { why, field } = suite.run(t, m.id as u64) {
            *kills.lock().expect("no panics under the lock").entry(t).or_default() += 1;
            return result(m, Verdict::Killed { test: tests[t].name.clone(), why, field }, n + 1, t0.elapsed().as_secs_f64());
        }
    }
    result(m, Verdict::Survived, order.len(), t0.elapsed().as_secs_f64())
}
