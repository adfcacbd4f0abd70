//! The equivalence proofs of today's rtl/ mutants 14, 17 and 197 (seed 1;
//! tb/mutation-holes/equiv/rtl-14-17-197-bsp-counters.sh): each one proved by
//! 1-induction, and each control refuted from reset. Slow (yosys SAT, 3 to 5
//! min), so it is ignored:
//! `cargo test --release -p mutate --test equiv_bsp_counters -- --ignored`.

use std::path::PathBuf;
use std::process::Command;

#[test]
#[ignore = "three yosys induction proofs and six refuted controls, 3 to 5 min"]
fn bsp_counter_mutants_are_proved_and_their_controls_refuted() {
    if Command::new("yosys").arg("-V").output().is_err() {
        eprintln!("yosys not installed: skipped");
        return;
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap();
    let out = Command::new("sh").arg("tb/mutation-holes/equiv/rtl-14-17-197-bsp-counters.sh").current_dir(&root).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    let verdict = |label: &str| -> String {
        text.lines().find_map(|l| l.strip_prefix(label).map(str::to_string)).unwrap_or_else(|| panic!("no verdict for `{label}` in:\n{text}"))
    };
    for proof in ["197, can_bsp, every input free: ", "17, can_bsp + can_btl, every other input free: ", "14, can_bsp + can_btl, every other input free: "] {
        assert_eq!(verdict(proof), "PROVED (1-induction)", "{proof}\n{text}");
    }
    for control in [
        "197 control: the invariant without 'cnt 10 stands for 2': ",
        "197 control: the neighbour mutant -ctrlbit 0, outputs only: ",
        "17 control: the invariant without the phase term: ",
        "17 control: can_bsp alone (sample free), outputs only: ",
        "14 control: the invariant without the phase term: ",
        "14 control: can_bsp alone (sample free), outputs only: ",
    ] {
        assert!(verdict(control).starts_with("counterexample from reset"), "{control}\n{text}");
    }
    assert!(out.status.success(), "the script's own exit status: {:?}\n{text}", out.status);
}
