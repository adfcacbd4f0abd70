//! Every host runs where a host is chosen: `mutate --host` on our rtl/
//! mutates that host's wrapper (the scenario passes on the unmutated
//! wrapper, so the mutants are judged), `bench --host` adds a campaign row
//! on that host.

use std::process::Command;

fn root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn cancosim(args: &[&str]) -> (bool, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_cancosim")).args(args).current_dir(root()).output().expect("cancosim runs");
    (o.status.code().is_some_and(|c| c <= 1), format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr)))
}

/// One host end to end (a mutate build is a yosys and Verilator build of
/// its own, about a minute): Motorola, whose wrapper adds two files. The
/// wrapper of every other host is checked without a build by the unit test
/// `every_host_wrapper_is_a_module_of_its_files` (crates/cli/src/cmd/mutate.rs).
#[test]
fn mutate_runs_on_a_new_host_through_its_wrapper() {
    for host in ["motorola"] {
        let out = std::env::temp_dir().join(format!("host-commands-mutate-{host}-{}", std::process::id()));
        let (ok, text) = cancosim(&["mutate", "tb/basic-filter-frames.toml", "--count", "1", "--seed", "3", "--jobs", "1", "--no-formal", "--fresh", "--host", host, "--out", out.to_str().unwrap()]);
        assert!(ok, "{host}: {text}");
        assert!(!text.contains("fails on the original") && !text.contains("no scenario passes"), "{host}: the baseline must pass on the wrapper: {text}");
        let report = std::fs::read_to_string(out.join("report.md")).unwrap_or_else(|e| panic!("{host}: no report ({e}): {text}"));
        assert!(report.contains("1 mutant") || report.contains("mutants: 1") || report.contains("| 1 "), "{host}: {report}");
        let _ = std::fs::remove_dir_all(&out);
    }
}

#[test]
fn bench_adds_a_campaign_row_per_host() {
    let (ok, text) = cancosim(&["bench", "--smoke", "--json", "--campaign-frames", "6", "--host", "regport", "--host", "apb3"]);
    assert!(ok, "{text}");
    for dut in ["rtl (host regport)", "rtl (host apb3)"] {
        assert!(text.contains(&format!("\"dut\": \"{dut}\"")), "no campaign row {dut}: {text}");
    }
}
