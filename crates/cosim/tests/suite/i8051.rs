//! Our `can_top_8051` driven by the 8051 multiplexed-bus BFM: registers
//! written and read back, the read latency the default RD strobe covers,
//! a strobe too short for the wrapper caught, and a frame in lockstep with
//! the golden model.

use bfm::I8051Timing;
use cosim::{CompareConfig, DutChoice, HostBfm, NodeConfig, ReferenceChoice, TbConfig, Testbench};

const SETUP: [(u8, u8); 6] = [
    (0, 0x01),
    (4, 0x00),
    (5, 0xFF),
    (6, 0x41),
    (7, 0x25),
    (8, 0x1A),
];

fn cfg(t: I8051Timing) -> TbConfig {
    TbConfig {
        scenario: "i8051".into(),
        dut: DutChoice::Rtl,
        host: HostBfm::I8051(t),
        ..TbConfig::default()
    }
}

#[test]
fn wrapper_configures_in_reset_mode_and_reads_back() {
    let mut tb = Testbench::new(cfg(I8051Timing::default())).unwrap();
    assert!(tb.dut_name().contains("can_top_8051"), "{}", tb.dut_name());
    for &(a, d) in &SETUP {
        tb.write(a, d).unwrap();
    }
    for &(a, d) in &SETUP[1..] {
        assert_eq!(tb.read(a).unwrap(), d, "address {a}");
    }
    // MOD reads back reset mode; TEST (9) is a plain register.
    assert_eq!(tb.read(0).unwrap() & 0x01, 0x01);
    for v in [0x00, 0x5A, 0xA5, 0xFF] {
        tb.write(9, v).unwrap();
        assert_eq!(tb.read(9).unwrap(), v);
    }
    assert!(tb.violations().is_empty(), "{:?}", tb.violations());
}

/// The shortest RD strobe the wrapper answers in, at 50 MHz host and
/// 24 MHz CAN clock: reads of a known value with RD shortened cycle by
/// cycle; the default keeps a margin above it.
#[test]
fn read_latency_is_covered_by_the_default_strobe() {
    let mut shortest = None;
    for rd in (8..=40).rev() {
        let t = I8051Timing {
            rd,
            ..I8051Timing::default()
        };
        let mut tb = Testbench::new(cfg(t)).unwrap();
        tb.write(0, 0x01).unwrap();
        tb.write(9, 0x3C).unwrap();
        let ok = (0..8).all(|_| tb.read(9).unwrap() == 0x3C);
        if ok {
            shortest = Some(rd);
        } else {
            break;
        }
    }
    let shortest = shortest.expect("the wrapper answers within 40 cycles");
    eprintln!("shortest RD strobe the wrapper answers in: {shortest} host cycles");
    assert!(
        I8051Timing::default().rd >= shortest + 2,
        "default RD {} has no margin over {shortest}",
        I8051Timing::default().rd
    );
    assert!(
        shortest > 8,
        "a strobe of 8 cycles cannot be enough through the CDC"
    );
}

/// A too-short RD reads the pull-ups: the bench reports the value, and the
/// lockstep comparator flags the register read as a divergence.
#[test]
fn too_short_rd_reads_pull_ups_and_diverges() {
    let t = I8051Timing {
        rd: 10,
        ..I8051Timing::default()
    };
    let mut c = cfg(t);
    c.lockstep = Some((ReferenceChoice::Model, CompareConfig::default()));
    let mut tb = Testbench::new(c).unwrap();
    tb.write(0, 0x01).unwrap();
    tb.write(9, 0x3C).unwrap();
    let r = tb.read(9);
    match r {
        Ok(v) => assert_eq!(v, 0xFF, "pull-ups expected"),
        Err(e) => assert!(e.to_string().contains("diverged"), "{e}"),
    }
    assert!(
        tb.record().divergence.is_some(),
        "the comparator saw the wrong read"
    );
}

#[test]
fn frame_to_a_model_node_in_lockstep() {
    let mut init = SETUP.to_vec();
    init.push((0, 0x00));
    let mut c = cfg(I8051Timing::default());
    c.nodes = vec![NodeConfig {
        name: "node1".into(),
        init,
    }];
    c.lockstep = Some((ReferenceChoice::Model, CompareConfig::default()));
    let mut tb = Testbench::new(c).unwrap();
    for &(a, d) in &SETUP {
        tb.write(a, d).unwrap();
    }
    tb.write(0, 0x00).unwrap();
    tb.run_bits(12).unwrap();
    // ID 0x123, DLC 2, data 0xA5 0x5A; then CMR.TR.
    for (a, d) in [(10u8, 0x24u8), (11, 0x62), (12, 0xA5), (13, 0x5A)] {
        tb.write(a, d).unwrap();
    }
    tb.write(1, 0x01).unwrap();
    let sr = tb.wait_sr(0x08, 0x08, 200).unwrap();
    assert_eq!(sr & 0x0C, 0x0C, "TCS and TBS");
    assert!(tb.comparator().unwrap().compared_bits > 40);
    assert!(
        tb.record().divergence.is_none(),
        "{:?}",
        tb.record().divergence
    );
    assert_eq!(tb.bus().node(0).peek(2) & 0x01, 0x01, "node1 SR.RBS");
    assert!(tb.violations().is_empty(), "{:?}", tb.violations());
}
