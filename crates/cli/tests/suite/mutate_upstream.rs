//! `cancosim mutate` on the opencores core (never shipped here: its
//! directory comes from CAN_UPSTREAM_DIR), with its profile and waiver file.
//! A sample of MUTATE_COUNT mutants (default 20, seed MUTATE_SEED, default 1).

use std::path::PathBuf;
use std::process::Command;

#[test]
#[ignore = "needs the opencores core on disk (CAN_UPSTREAM_DIR) and minutes of Verilator build and simulation"]
fn mutants_of_the_upstream_core_are_judged_only_by_scenarios_that_pass_it() {
    let dir = std::env::var("CAN_UPSTREAM_DIR").expect("set CAN_UPSTREAM_DIR to the opencores rtl/verilog directory");
    let count = std::env::var("MUTATE_COUNT").unwrap_or_else(|_| "20".into());
    let seed = std::env::var("MUTATE_SEED").unwrap_or_else(|_| "1".into());
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_cancosim"))
        .args(["mutate", "tb/regression.list", "--external", &dir, "--profile", "opencores-can", "--waivers", "tb/waivers/opencores-upstream.toml"])
        .args(["--count", &count, "--seed", &seed, "--no-formal", "--out"])
        .arg(out.path())
        .current_dir(&root)
        .output()
        .unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    println!("{text}");
    assert!(matches!(o.status.code(), Some(0 | 1)), "{text}");
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.path().join("report.json")).unwrap()).unwrap();
    let c = &r["counts"];
    let n = count.parse::<u64>().unwrap();
    assert_eq!(c["mutants"], n);
    let sum: u64 = ["killed", "survived", "hidden_by_waiver", "equivalent", "timed_out", "build_errors"].iter().map(|k| c[k].as_u64().unwrap()).sum();
    assert_eq!(sum, n, "every mutant has one verdict");
    // The waiver audit: a survivor a waiver masks is named with the
    // scenario, the waiver and the values, and is not killed.
    let hidden = r["hidden"].as_array().unwrap();
    assert_eq!(hidden.len() as u64, c["hidden_by_waiver"].as_u64().unwrap());
    for h in hidden {
        let m = r["mutants"].as_array().unwrap().iter().find(|m| m["id"] == h["id"]).expect("a mutant of the run");
        assert_eq!(m["verdict"]["verdict"], "survived", "hidden mutant {}", h["id"]);
        let d = &h["differences"][0];
        assert!(d["how"].is_string(), "{h}");
        println!("hidden by a waiver: mutant {} in {}: {d}", h["id"], h["test"]);
    }
    // A kill counts only from a scenario that passes the unmutated core
    // with its waivers: a scenario failing there is not used.
    let passing: Vec<&str> = r["baseline"].as_array().unwrap().iter().filter(|b| b["passed"] == true).map(|b| b["test"].as_str().unwrap()).collect();
    assert!(!passing.is_empty());
    for m in r["mutants"].as_array().unwrap() {
        if m["verdict"]["verdict"] == "killed" {
            let t = m["verdict"]["test"].as_str().unwrap();
            assert!(passing.contains(&t), "mutant {} killed by {t}, which fails on the original", m["id"]);
        }
    }
}
