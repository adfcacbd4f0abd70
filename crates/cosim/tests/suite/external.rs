//! Co-simulation of an HDL core outside this repository, built at run time
//! by the bridge. For the upstream opencores core (the `freecores/can`
//! repository, used locally only, never committed):
//!
//! ```sh
//! CAN_EXTERNAL_DIR=/path/to/can/rtl/verilog CAN_EXTERNAL_TOP=can_top \
//! CAN_EXTERNAL_DEFINES=CAN_WISHBONE_IF CAN_EXTERNAL_INCLUDES=/path/to/can/bench/verilog \
//! cargo test -p cosim --release -- --ignored external
//! ```
//!
//! `CAN_EXTERNAL_DEFINES` is comma-separated (default `CAN_WISHBONE_IF`),
//! `CAN_EXTERNAL_INCLUDES` colon-separated (for `timescale.v`).

use std::path::PathBuf;

use cosim::{
    CompareConfig, DutChoice, ExternalCore, HostBfm, NodeConfig, ReferenceChoice, TbConfig,
    Testbench,
};

const SETUP: [(u8, u8); 6] = [
    (0, 0x01),
    (4, 0x00),
    (5, 0xFF),
    (6, 0x41),
    (7, 0x25),
    (8, 0x1A),
];

fn core_from_env() -> ExternalCore {
    let dir = std::env::var("CAN_EXTERNAL_DIR")
        .expect("set CAN_EXTERNAL_DIR to the core's source directory");
    let top = std::env::var("CAN_EXTERNAL_TOP").unwrap_or_else(|_| "can_top".into());
    let defines =
        std::env::var("CAN_EXTERNAL_DEFINES").unwrap_or_else(|_| "CAN_WISHBONE_IF".into());
    let includes = std::env::var("CAN_EXTERNAL_INCLUDES").unwrap_or_default();
    ExternalCore {
        dir: PathBuf::from(dir),
        top,
        files: Vec::new(),
        defines: defines
            .split(',')
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect(),
        include_dirs: includes
            .split(':')
            .filter(|s| !s.is_empty())
            .map(PathBuf::from)
            .collect(),
        extra_args: Vec::new(),
        ..Default::default()
    }
}

#[test]
#[ignore = "needs an external core: set CAN_EXTERNAL_DIR=... CAN_EXTERNAL_TOP=can_top; cargo test -p cosim --release -- --ignored"]
fn external_core_configures_and_transmits_in_lockstep_with_the_model() {
    let core = core_from_env();
    let t0 = std::time::Instant::now();
    let built = cosim::build_external(&core).unwrap_or_else(|e| panic!("{e}"));
    println!(
        "built/loaded {} in {:.1} s",
        built.path.display(),
        t0.elapsed().as_secs_f64()
    );
    let mut init = SETUP.to_vec();
    init.push((0, 0x00));
    let cfg = TbConfig {
        scenario: "external".into(),
        dut: DutChoice::External(core),
        host: HostBfm::Wishbone,
        nodes: vec![NodeConfig {
            name: "node1".into(),
            init,
        }],
        lockstep: Some((ReferenceChoice::Model, CompareConfig::default())),
        ..TbConfig::default()
    };
    let mut tb = Testbench::new(cfg).unwrap_or_else(|e| panic!("{e}"));
    for &(a, d) in &SETUP {
        tb.write(a, d).unwrap();
    }
    // ACR, AMR, BTR0, BTR1 (the upstream core does not keep OCR).
    for &(a, d) in &SETUP[1..5] {
        assert_eq!(tb.read(a).unwrap(), d, "address {a}");
    }
    assert!(tb.violations().is_empty(), "{:?}", tb.violations());
    tb.write(0, 0x00).unwrap();
    tb.run_bits(12).unwrap();
    for (a, d) in [(10u8, 0x24u8), (11, 0x62), (12, 0xA5), (13, 0x5A)] {
        tb.write(a, d).unwrap();
    }
    tb.write(1, 0x01).unwrap();
    let res = tb.wait_sr(0x08, 0x08, 300);
    let rec = tb.record();
    let diag = diagnose::diagnose(&rec);
    println!("result: {res:?}\n{}", diag.to_text());
    assert!(
        res.is_ok() || rec.divergence.is_some() || rec.stuck.is_some(),
        "a failure is explained by the record"
    );
}
