//! Shipped scenarios on our RTL (Verilated).

use diagnose::Category;
use scenario::{DutSpec, RunOptions, Scenario, run};
use std::path::PathBuf;

fn load(name: &str) -> Scenario {
    Scenario::load(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tb").join(format!("{name}.toml"))).unwrap()
}

#[test]
fn probe_rtl() {
    for n in ["de2-thesis", "de2-with-ack-node"] {
        let o = run(&load(n), &RunOptions { dut: Some(DutSpec::rtl()), ..Default::default() });
        eprintln!("{}\n{:?} {:?}", o.diagnosis.to_text(), o.mismatches, o.wall);
        let _ = Category::Pass;
    }
}
