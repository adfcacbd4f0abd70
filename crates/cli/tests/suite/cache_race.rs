//! Two `cancosim` processes started at once on the same external core and
//! an empty cache (two terminals, two CI jobs): both build it
//! (each in a work directory of its own), both run the scenario on it, and
//! the cache ends with one complete entry.

use std::process::{Command, Stdio};

#[test]
fn two_cancosim_runs_build_one_external_core_at_once_on_an_empty_cache() {
    let scratch = tempfile::tempdir().unwrap();
    let (core, cache) = (scratch.path().join("core"), scratch.path().join("cache"));
    std::fs::create_dir_all(&core).unwrap();
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    std::fs::copy(root.join("tb/fixtures/cosim_echo.v"), core.join("cosim_echo.v")).unwrap();
    let spawn = || {
        Command::new(env!("CARGO_BIN_EXE_cancosim"))
            .args(["run", "tb/de2-pelican-selftest.toml", "--top", "cosim_echo", "--profile", "tb/fixtures/at-ack.toml", "--external"])
            .arg(&core)
            .current_dir(&root)
            .env("COSIM_CACHE_DIR", &cache)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("cancosim runs")
    };
    let children = [spawn(), spawn()];
    for c in children {
        let o = c.wait_with_output().unwrap();
        let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        // The echo fixture is no CAN controller: the run gets as far as a
        // divergence on the wire, which needs the built core.
        assert!(all.contains("tx-bit") && all.contains("DutDeviatesFromModel"), "ran on the built core:\n{all}");
        assert_eq!(o.status.code(), Some(1), "{all}");
    }
    let entries: Vec<String> =
        std::fs::read_dir(&cache).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(entries.len(), 1, "one entry, no work directory left: {entries:?}");
    assert!(cache.join(&entries[0]).join("libcosim_cosim_echo.so").is_file());
}
