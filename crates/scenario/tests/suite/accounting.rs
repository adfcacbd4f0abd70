//! The bus's frame accounting in the scenario runner: with two or more golden-model
//! nodes, the bus's frame accounting runs at the end of every run; a
//! frame a node never received, with no error frame, overrun or off-bus
//! time to explain it, fails the run with a mismatch that names it.

use scenario::{DutSpec, RunOptions, Scenario, run};
use std::path::PathBuf;

/// The DUT (the golden model) configured and on the bus, two model nodes;
/// node `a` sends one frame at bit 40.
const TWO_NODES: &str = r#"purpose = "accounting"
verifies = ["x"]
[clocks]
host_mhz = 50.0
can_mhz = 24.0
[host]
bfm = "wishbone"
[dut]
kind = "model"
[run]
max_bits = 600
[[step]]
write = "CR"
value = 0x01
[[step]]
write = "ACR"
value = 0x00
[[step]]
write = "AMR"
value = 0xFF
[[step]]
write = "BTR0"
value = 0x41
[[step]]
write = "BTR1"
value = 0x25
[[step]]
write = "CR"
value = 0x00
[[step]]
wait_bits = 400
[[node]]
name = "a"
btr0 = 0x41
btr1 = 0x25
acr = [0x00]
amr = [0xFF]
send = [ { id = 0x123, data = [1, 2, 3], at_bit = 40 } ]
[[node]]
name = "b"
btr0 = 0x41
btr1 = 0x25
acr = [0x00]
amr = [0xFF]
"#;

fn outcome(extra: &str) -> scenario::RunOutcome {
    let s = Scenario::parse(&format!("{TWO_NODES}{extra}"), "accounting.toml").unwrap();
    run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() })
}

#[test]
fn a_clean_multi_node_run_accounts_for_every_frame() {
    let o = outcome("[expect]\nreceived = { b = 1 }\n");
    assert!(o.passed, "{:?}\n{}", o.mismatches, o.diagnosis.to_text());
}

/// Node b's receiver stuck recessive for the whole frame: it sees no SOF,
/// signals nothing, and the DUT acknowledges, so node a completes. The
/// frame never reached b: the run fails and says so.
#[test]
fn a_deaf_node_fails_the_run_with_the_lost_frame() {
    let o = outcome("[[fault]]\nkind = \"stuck-recessive\"\nat_bit = 30\nduration_bits = 300\ntarget = \"b\"\n");
    assert!(!o.passed, "a lost frame must fail the run");
    let m = o.mismatches.iter().find(|m| m.contains("frame accounting")).unwrap_or_else(|| panic!("{:?}", o.mismatches));
    assert!(m.contains("never reached node 1") && m.contains("1 = b"), "{m}");
}

/// Every shipped scenario with model nodes still passes on the model with
/// the accounting on (parking-10-nodes: nine nodes with filters).
#[test]
fn shipped_multi_node_scenarios_pass_the_accounting() {
    let tb = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tb");
    let mut checked = 0;
    for s in scenario::load_list(tb.join("regression.list")).unwrap() {
        if s.nodes.len() < 2 {
            continue;
        }
        let o = run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
        assert!(!o.mismatches.iter().any(|m| m.contains("frame accounting")), "{}: {:?}", s.name, o.mismatches);
        checked += 1;
    }
    assert!(checked >= 1);
}
