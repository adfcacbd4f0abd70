//! The CI-sized bench run: every workload runs (tiny counts) and the report
//! is complete, every figure finite and positive. Not a timing assertion.

use bench::{BenchOptions, NODE_COUNTS, run};

#[test]
fn smoke_run_reports_every_figure_finite_and_positive() {
    // The default work dir: builds are cached by content, shared with `cancosim bench`.
    let opts = BenchOptions::smoke();
    let r = run(&opts).unwrap_or_else(|e| panic!("{e}"));
    r.check().unwrap_or_else(|e| panic!("{e}"));
    assert!(r.options.smoke && r.options.frames == BenchOptions::SMOKE_FRAMES);

    let nodes: Vec<usize> = r.scaling.iter().map(|s| s.nodes).collect();
    assert_eq!(nodes, NODE_COUNTS);
    let names: Vec<&str> = r.selftest.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "model",
            "cosim",
            "cosim-no-lockstep",
            "cosim-de2-clocks",
            "verilator-raw",
            "icarus"
        ]
    );
    assert_eq!(r.targets.len(), 4);

    // Every self-test simulator sent the same frames through the same sequence.
    for s in &r.selftest {
        assert_eq!(s.errors, 0, "{}", s.name);
        let want = match s.name.as_str() {
            "icarus" => r.options.icarus_frames as u64,
            "model" => r.options.frames as u64 * bench::MODEL_SELFTEST_REPEAT,
            _ => r.options.frames as u64,
        };
        assert_eq!(s.frames, want, "{}", s.name);
    }
    // The raw harness and Icarus run the same stimulus on the same RTL: with
    // one frame each, the Icarus cycle count is a prefix of the harness run.
    let cyc = |n: &str| r.selftest.iter().find(|s| s.name == n).unwrap().cycles;
    assert!(cyc("icarus") <= cyc("verilator-raw"));
    // The co-simulation runs the same workload: within 10 % of the harness's cycles.
    let (c, h) = (cyc("cosim") as f64, cyc("verilator-raw") as f64);
    assert!((c - h).abs() / h < 0.10, "co-sim {c} cycles vs harness {h}");

    let figures = r.figures();
    assert!(figures.len() >= 4 * 5 + 6 * 6 + 4);
    for (name, v) in &figures {
        assert!(v.is_finite() && *v > 0.0, "{name} = {v}");
    }

    let table = r.to_table();
    for s in &r.selftest {
        assert!(table.contains(&s.name), "table lacks {}:\n{table}", s.name);
    }
    for t in &r.targets {
        assert!(table.contains(&t.name), "table lacks {}:\n{table}", t.name);
    }
    let json: serde_json::Value = serde_json::from_str(&r.to_json()).unwrap();
    assert_eq!(json["selftest"].as_array().unwrap().len(), 6);
    assert_eq!(json["scaling"].as_array().unwrap().len(), 4);
}

#[test]
#[ignore = "the full bench (tens of seconds, plus about 30 s to build the harness after an RTL change); run with: cargo test --release -p bench -- --ignored --nocapture"]
fn full_bench() {
    let r = run(&BenchOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    println!("{}", r.to_table());
    r.check().unwrap_or_else(|e| panic!("{e}"));
    for (name, v) in r.figures() {
        assert!(v.is_finite() && v > 0.0, "{name} = {v}");
    }
}

#[test]
fn repeated_rows_keep_their_least_cpu_time_and_the_same_workload() {
    let one = run(&BenchOptions::smoke()).unwrap_or_else(|e| panic!("{e}"));
    let r = run(&BenchOptions { repeat: 3, ..BenchOptions::smoke() }).unwrap_or_else(|e| panic!("{e}"));
    r.check().unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(r.options.repeat, 3);
    assert!(r.to_table().contains("least CPU time of 3 interleaved runs"));
    // Same rows, same frames and cycles as a single run: only the timing is the best of three.
    let key = |r: &bench::BenchReport| -> Vec<(String, u64, u64)> {
        r.selftest.iter().map(|s| (s.name.clone(), s.frames, s.cycles)).collect()
    };
    assert_eq!(key(&r), key(&one));
    assert_eq!(BenchOptions { repeat: 0, ..BenchOptions::smoke() }.effective().repeat, 1);
    assert_eq!(BenchOptions::default().repeat, 3);
}

/// Two threads compile the Icarus bench into one empty cache at once (the
/// raw harness shares the same `cached_build`): both get the one
/// complete image, and nothing else is left in the cache.
#[test]
fn two_threads_build_one_bench_image_at_once_on_an_empty_cache() {
    let root = std::path::PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    let work = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("bench-race-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&work);
    let built: Vec<_> = std::thread::scope(|s| {
        let hs: Vec<_> = (0..2).map(|_| s.spawn(|| bench::external::build_icarus(&root, &work))).collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for b in &built {
        let b = b.as_ref().unwrap_or_else(|e| panic!("{e}"));
        assert!(b.path.is_file(), "{}", b.path.display());
    }
    assert!(built.iter().any(|b| b.as_ref().is_ok_and(|b| !b.cached)), "the cache was empty: someone built");
    let entries: Vec<_> = std::fs::read_dir(&work).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(entries.len(), 1, "one entry, no work directory left: {entries:?}");
    let r = bench::external::run_icarus(&built[0].as_ref().unwrap().path, 1, 1).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((r.frames, r.errors), (1, 0));
    let _ = std::fs::remove_dir_all(&work);
}
