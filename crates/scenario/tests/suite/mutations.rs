//! The feature scenarios catch a wrong DUT: copies of rtl/ with one
//! deliberate bug each, run on the scenario written for that feature, must
//! fail (diverge from the golden model), while the unmutated RTL passes.

use diagnose::Category;
use scenario::{DutSpec, RunOptions, Scenario, run};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// (name, file, original text, mutated text, scenario that must catch it)
const MUTATIONS: &[(&str, &str, &str, &str, &str)] = &[
    (
        "acf-dual-data",
        "can_acf.v",
        "(!has1 || (m8({data12[15:12], 4'b0000}",
        "(1'b1 || (m8({data12[15:12], 4'b0000}",
        "pelican-filter-dual-std",
    ),
    ("lom-transmits", "can_bsp.v", "wire can_tx    = req && !lom;", "wire can_tx    = req;", "pelican-listen-only"),
    (
        "alc-ext-off",
        "can_bsp.v",
        "S_IDB:  alc_pos = 5'd13 + cnt[4:0];",
        "S_IDB:  alc_pos = 5'd12 + cnt[4:0];",
        "pelican-arbitration",
    ),
    ("sleep-busy", "can_regs.v", "wire can_sleep = bus_idle && !irq;", "wire can_sleep = !irq;", "pelican-sleep-wakeup"),
    (
        "fifo-63",
        "can_rxfifo.v",
        "wire fits      = ({3'b000, len} + fill) <= 7'd64;",
        "wire fits      = ({3'b000, len} + fill) < 7'd64;",
        "pelican-fifo-overrun",
    ),
    // The two halves of the former basic-sleep-overrun-abort: each catches
    // the mutation of its own feature in BasicCAN (measured: fifo-63 at the
    // 7th message's EOF, irq; sleep-busy at the SR read during frame 0x300).
    (
        "fifo-63-basic",
        "can_rxfifo.v",
        "wire fits      = ({3'b000, len} + fill) <= 7'd64;",
        "wire fits      = ({3'b000, len} + fill) < 7'd64;",
        "basic-overrun-abort",
    ),
    ("sleep-busy-basic", "can_regs.v", "wire can_sleep = bus_idle && !irq;", "wire can_sleep = !irq;", "basic-sleep-wakeup"),
];

#[test]
#[ignore = "verilates seven mutated copies of rtl/ (about a minute each); run with: cargo test --release -p scenario --test suite mutations:: -- --ignored"]
fn each_feature_scenario_catches_its_mutation() {
    for (name, file, from, to, scen) in MUTATIONS {
        let dir = std::env::temp_dir().join(format!("scen-mut-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for e in std::fs::read_dir(root().join("rtl")).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "v" || x == "vh") {
                let mut text = std::fs::read_to_string(&p).unwrap();
                if p.file_name().unwrap() == *file {
                    assert!(text.contains(from), "{name}: the mutation point moved in {file}");
                    text = text.replace(from, to);
                }
                std::fs::write(dir.join(p.file_name().unwrap()), text).unwrap();
            }
        }
        let s = Scenario::load(root().join("tb").join(format!("{scen}.toml"))).unwrap();
        let good = run(&s, &RunOptions { dut: Some(DutSpec::rtl()), ..Default::default() });
        assert!(good.passed, "{scen} on the real RTL: {:?}", good.mismatches);
        let o = run(&s, &RunOptions { dut: Some(DutSpec::external(name, &dir, "can_top")), ..Default::default() });
        let _ = std::fs::remove_dir_all(&dir);
        eprintln!("{name} on {scen}: {}", o.diagnosis.to_text());
        assert!(!o.passed, "{scen} does not catch mutation {name}");
        assert_eq!(o.diagnosis.category, Category::DutDeviatesFromModel, "{name}: {}", o.diagnosis.to_text());
    }
}
