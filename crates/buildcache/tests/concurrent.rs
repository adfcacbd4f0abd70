//! Two builders of one key at the same moment, on an empty cache, from two
//! threads of one process and from two processes: both succeed and see one
//! complete entry. The build stands in for `make`: it writes an object,
//! waits until the other builder is building too, then reads its object
//! back and links the product from it. Builders sharing a work directory
//! (the bug: `<key>.tmp<pid>` for two threads) delete each
//! other's objects and fail here.

use buildcache::{Entry, Origin, build_once};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Set in the child process: `<cache dir>|<rendezvous dir>|<builder name>`.
const CHILD_ENV: &str = "BUILDCACHE_TEST_CHILD";

/// Waits until `n` builders have announced themselves in `meet` (files),
/// or 60 s: a helper that wrongly serialised builders would just be slow
/// here, and the checks below still judge the result.
fn rendezvous(meet: &Path, me: &str, n: usize) {
    std::fs::create_dir_all(meet).unwrap();
    std::fs::write(meet.join(me), "").unwrap();
    let t0 = Instant::now();
    while std::fs::read_dir(meet).unwrap().count() < n && t0.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// A make-like build: its own object, read back after the other builder
/// has started, linked into `product`.
fn fake_make(work: &Path, meet: &Path, me: &str) -> Result<(), String> {
    std::fs::create_dir_all(work.join("obj")).map_err(|e| format!("{me}: mkdir obj: {e}"))?;
    let obj = work.join("obj/top.o");
    std::fs::write(&obj, format!("object of {me}")).map_err(|e| format!("{me}: write object: {e}"))?;
    rendezvous(meet, me, 2);
    std::thread::sleep(Duration::from_millis(50));
    let o = std::fs::read_to_string(&obj).map_err(|e| format!("{me}: opening {}: {e}", obj.display()))?;
    if o != format!("object of {me}") {
        return Err(format!("{me}: linked someone else's object: {o:?}"));
    }
    std::fs::write(work.join("product"), format!("linked from [{o}]")).map_err(|e| format!("{me}: link: {e}"))
}

fn build(cache: &Path, meet: &Path, me: &str) -> Result<Entry, String> {
    build_once(&cache.join("key-0123"), "product", |w| fake_make(w, meet, me)).map_err(|e| e.to_string())
}

/// One complete entry, made by exactly one of the builders, and nothing
/// else left in the cache (the loser's copy is gone).
fn check_cache(cache: &Path, results: &[Result<Entry, String>]) {
    for r in results {
        let e = r.as_ref().unwrap_or_else(|e| panic!("a concurrent build failed: {e}"));
        assert_ne!(e.origin, Origin::Cached, "the cache was empty: both builders built");
    }
    let product = std::fs::read_to_string(cache.join("key-0123/product")).unwrap();
    assert!(
        product == "linked from [object of a]" || product == "linked from [object of b]",
        "{product}"
    );
    let names: Vec<String> =
        std::fs::read_dir(cache).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(names, vec!["key-0123".to_string()], "only the entry is left");
}

#[test]
fn two_threads_build_one_key_at_once_and_both_succeed() {
    let root = tempfile::tempdir().unwrap();
    let (cache, meet) = (root.path().join("cache"), root.path().join("meet"));
    let results: Vec<Result<Entry, String>> = std::thread::scope(|s| {
        let hs: Vec<_> = ["a", "b"].map(|me| {
            let (cache, meet) = (&cache, &meet);
            s.spawn(move || build(cache, meet, me))
        })
        .into_iter()
        .collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    check_cache(&cache, &results);
}

#[test]
fn two_processes_build_one_key_at_once_and_both_succeed() {
    let root = tempfile::tempdir().unwrap();
    let (cache, meet) = (root.path().join("cache"), root.path().join("meet"));
    let exe = std::env::current_exe().unwrap();
    let children: Vec<_> = ["a", "b"]
        .map(|me| {
            std::process::Command::new(&exe)
                .args(["--exact", "child_builder", "--include-ignored", "--nocapture", "--test-threads", "1"])
                .env(CHILD_ENV, format!("{}|{}|{me}", cache.display(), meet.display()))
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        })
        .into_iter()
        .collect();
    let mut results = Vec::new();
    for c in children {
        let o = c.wait_with_output().unwrap();
        let out = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        assert!(out.contains("child: built "), "the child ran the build: {out}");
        results.push(if o.status.success() {
            let origin = if out.contains("child: built BuiltElsewhere") { Origin::BuiltElsewhere } else { Origin::Built };
            let dir = cache.join("key-0123");
            Ok(Entry { product: dir.join("product"), dir, origin })
        } else {
            Err(out)
        });
    }
    check_cache(&cache, &results);
}

/// The other process of `two_processes_build_one_key_at_once_and_both_succeed`.
#[test]
#[ignore = "the child process of two_processes_build_one_key_at_once_and_both_succeed, which runs it"]
fn child_builder() {
    let spec = std::env::var(CHILD_ENV).expect("run by two_processes_build_one_key_at_once_and_both_succeed");
    let parts: Vec<&str> = spec.split('|').collect();
    let (cache, meet, me) = (PathBuf::from(parts[0]), PathBuf::from(parts[1]), parts[2]);
    match build(&cache, &meet, me) {
        Ok(e) => println!("child: built {:?}", e.origin),
        Err(e) => panic!("child: built nothing: {e}"),
    }
}
