//! The `block = [...]` step (a Wishbone block cycle): how it parses, the
//! file:line:key errors of a bad block, and that the block scenario's checks
//! are live (a changed expected value inside a block fails).

use scenario::{Action, DutSpec, RunOptions, Scenario, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

const HEAD: &str = r#"purpose = "t"
[clocks]
host_mhz = 50.0
can_mhz = 24.0

[[step]]
write = "CR"
value = 1
"#;

fn err(text: &str) -> scenario::ScenarioError {
    Scenario::parse(text, "tb/bad.toml").expect_err("must be rejected")
}

#[test]
fn a_block_expands_to_its_accesses_marked_with_their_block() {
    let text = format!(
        "{HEAD}\n[[step]]\nblock = [ {{ write = \"ACR\", value = 0x5A }}, {{ read = \"ACR\", expect = 0x5A }}, {{ load_tx = {{ id = 0x12, data = [1] }} }} ]\n[[step]]\nread = \"SR\"\n"
    );
    let s = Scenario::parse(&text, "tb/block.toml").unwrap();
    // CR, then ACR write, ACR read, 3 TX buffer bytes (BasicCAN: ID, DLC, 1 data byte), then SR.
    let blocks: Vec<Option<usize>> = s.steps.iter().map(|st| st.block).collect();
    assert_eq!(blocks, [None, Some(2), Some(2), Some(2), Some(2), Some(2), None]);
    assert!(matches!(s.steps[1].action, Action::Write { addr: 4, value: 0x5A, .. }));
    assert!(matches!(s.steps[2].action, Action::Read { addr: 4, expect: Some((0xFF, 0x5A)), .. }));
    assert!(s.steps[1..6].iter().all(|st| st.table == 2));
}

#[test]
fn a_bad_block_names_its_entry() {
    let e = err(&format!("{HEAD}\n[[step]]\nblock = [ {{ write = \"ACR\", value = 1 }}, {{ wait_bits = 3 }} ]\n"));
    assert!(e.to_string().contains("one access"), "{e}");
    assert_eq!(e.key(), "step[2].block[2]", "{e}");
    assert_eq!(e.line(), 11, "{e}");
    let e = err(&format!("{HEAD}\n[[step]]\nblock = [ {{ write = \"ACR\", value = 1 }} ]\n"));
    assert!(e.to_string().contains("at least two accesses"), "{e}");
    let e = err(&format!("{HEAD}\n[[step]]\nblock = [ {{ write = \"ACR\" }}, {{ read = \"ACR\" }} ]\n"));
    assert_eq!(e.key(), "step[2].block[1].value", "{e}");
    let e = err(&format!("{HEAD}\n[[step]]\nblock = [ {{ read = \"ACR\", write = \"ACR\", value = 1 }}, {{ read = \"SR\" }} ]\n"));
    assert_eq!(e.key(), "step[2].block[1]", "{e}");
    let e = err(&format!("{HEAD}\n[[step]]\nwait_bits = 3\nblock = [ {{ read = \"ACR\" }}, {{ read = \"SR\" }} ]\n"));
    assert!(e.to_string().contains("exactly one action"), "{e}");
}

#[test]
fn the_block_scenario_fails_with_a_changed_value_inside_a_block() {
    let path = root().join("tb/mutation-holes/wb-block-cycles.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let s = Scenario::parse(&text, &path).unwrap();
    assert_eq!(s.steps.iter().filter_map(|st| st.block).collect::<std::collections::BTreeSet<_>>().len(), 6, "six block cycles");
    assert!(run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() }).passed);
    for (from, to) in [
        ("{ read = \"RXB+9\", expect = 0x18 }", "{ read = \"RXB+9\", expect = 0x19 }"),
        ("{ read = \"BTR1\", expect = 0x25 }", "{ read = \"BTR1\", expect = 0x24 }"),
    ] {
        assert!(text.contains(from), "the mutation point moved: {from}");
        let s = Scenario::parse(&text.replacen(from, to, 1), &path).unwrap();
        let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
        assert!(!o.passed, "a wrong expectation inside a block passed: {to}");
    }
}
