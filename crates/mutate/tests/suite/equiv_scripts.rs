//! The equivalence scripts of today's rtl/ sample (seed 1,
//! tb/mutation-holes/equiv/), run so they cannot rot: mutant 12 (proved
//! invisible to a Wishbone B4 master) and mutant 79 (proved equal up to the
//! datasheet-undefined TX-buffer reset value), seconds each; mutants 14, 17
//! and 197 (1-induction, 3 to 5 min, so ignored:
//! `cargo test --release -p mutate --test suite equiv_scripts:: -- --ignored`).
//! Each script exits non-zero when a proof is not found or a control is not
//! refuted; the verdict lines are checked here as well.

use std::path::PathBuf;
use std::process::Command;

fn run(script: &str) -> Option<String> {
    let tools = ["yosys", "yosys-abc"].iter().all(|t| Command::new(t).arg("-h").output().is_ok());
    if !tools {
        eprintln!("yosys / yosys-abc not installed (scripts/setup.sh installs them): skipped");
        return None;
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap();
    let out = Command::new("bash").arg(format!("tb/mutation-holes/equiv/{script}")).current_dir(&root).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{script} exited {:?}:\n{text}\n{}", out.status, String::from_utf8_lossy(&out.stderr));
    Some(text)
}

fn verdict<'a>(text: &'a str, label: &str) -> &'a str {
    text.lines().find_map(|l| l.strip_prefix(label)).unwrap_or_else(|| panic!("no verdict for `{label}` in:\n{text}"))
}

#[test]
fn mutant_12_is_invisible_to_a_b4_master_and_its_controls_are_refuted() {
    let Some(t) = run("rtl-12-wb-cdc-dat-o.sh") else { return };
    assert!(verdict(&t, "1. mutant 12, ACK_LEVEL = 0, wb_dat_o compared while wb_ack_o: ").starts_with("Property proved"), "{t}");
    assert!(verdict(&t, "2. control: wb_dat_o compared at every step: ").contains("was asserted"), "{t}");
    assert!(verdict(&t, "3. control: ACK_LEVEL = 1 (level ack), compared while wb_ack_o: ").contains("was asserted"), "{t}");
}

#[test]
fn mutant_79_differs_only_in_the_undefined_tx_buffer_reset_value() {
    let Some(t) = run("rtl-79-txb-reset-value.sh") else { return };
    assert!(verdict(&t, "1. original vs mutant 79, rst free: ").contains("was asserted"), "{t}");
    assert!(verdict(&t, "2. original vs mutant 79, rst only in the first clock: ").starts_with("Property proved"), "{t}");
    assert!(verdict(&t, "3. spec (txb[1] not reset) vs mutant 79, rst free: ").starts_with("Property proved"), "{t}");
    assert!(verdict(&t, "3. control: spec vs original, rst free: ").contains("was asserted"), "{t}");
}

#[test]
#[ignore = "three yosys induction proofs and six refuted controls, 3 to 5 min"]
fn bsp_counter_mutants_are_proved_and_their_controls_refuted() {
    let Some(t) = run("rtl-14-17-197-bsp-counters.sh") else { return };
    for proof in ["197, can_bsp, every input free: ", "17, can_bsp + can_btl, every other input free: ", "14, can_bsp + can_btl, every other input free: "] {
        assert_eq!(verdict(&t, proof), "PROVED (1-induction)", "{proof}\n{t}");
    }
    for control in [
        "197 control: the invariant without 'cnt 10 stands for 2': ",
        "197 control: the neighbour mutant -ctrlbit 0, outputs only: ",
        "17 control: the invariant without the phase term: ",
        "17 control: can_bsp alone (sample free), outputs only: ",
        "14 control: the invariant without the phase term: ",
        "14 control: can_bsp alone (sample free), outputs only: ",
    ] {
        assert!(verdict(&t, control).starts_with("counterexample from reset"), "{control}\n{t}");
    }
}
