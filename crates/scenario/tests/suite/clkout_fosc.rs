//! Mutant 77 of the seed-1 campaign (can_regs.v: `clkout_fosc` stuck at 0,
//! so with CDR.2..0 = 7 CLKOUT is held low instead of being the clock):
//! the CLKOUT check reads clkout_o at every instant the bench evaluates a
//! Verilated DUT (both CAN clock edges), so `clkout-divider` catches it,
//! while rtl/ and the model pass.

use diagnose::Category;
use scenario::{DutSpec, RunOptions, Scenario, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

const FROM: &str = "assign clkout_fosc = (cdr[2:0] == 3'd7) && !cdr[3] && !sleep;";
const TO: &str = "assign clkout_fosc = 1'b0;";

#[test]
#[ignore = "verilates a mutated copy of rtl/ (about a minute); run with: cargo test --release -p scenario --test suite clkout_fosc:: -- --ignored"]
fn clkout_held_low_at_cd7_is_caught_and_rtl_and_model_pass() {
    let s = Scenario::load(root().join("tb/mutation-holes/clkout-divider.toml")).unwrap();
    for dut in [DutSpec::rtl(), DutSpec::model()] {
        let o = run(&s, &RunOptions { dut: Some(dut), ..Default::default() });
        assert!(o.passed, "{}: {:?}", o.dut, o.mismatches);
    }
    let dir = std::env::temp_dir().join(format!("clkout-fosc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for e in std::fs::read_dir(root().join("rtl")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "v" || x == "vh") {
            let mut text = std::fs::read_to_string(&p).unwrap();
            if p.file_name().unwrap() == "can_regs.v" {
                assert!(text.contains(FROM), "the mutation point moved in can_regs.v");
                text = text.replace(FROM, TO);
            }
            std::fs::write(dir.join(p.file_name().unwrap()), text).unwrap();
        }
    }
    let o = run(&s, &RunOptions { dut: Some(DutSpec::external("clkout-fosc-0", &dir, "can_top")), ..Default::default() });
    let _ = std::fs::remove_dir_all(&dir);
    let text = o.diagnosis.to_text();
    assert!(!o.passed, "clkout-divider does not catch CLKOUT held low at CD = 7");
    assert_eq!(o.diagnosis.category, Category::DutDeviatesFromModel, "{text}");
    let d = o.record.divergence.as_ref().expect("a divergence");
    assert!(d.context.contains("clkout_o stayed low"), "{d:?}");
}
