//! The shadow stays aligned: `model-skips-sleep`.
//! The DUT is the golden model behind a wrapper with two deliberate
//! deviations: it has no sleep mode (a MOD write never sets SM, as the
//! opencores core), and its reads of RXB[1] (address 17) come back with bit
//! 0 flipped. A waiver accepts the first with the resync; the second must
//! then be the next (and only) failure reported, not hidden and not buried
//! under the consequences of the first (a model asleep for the frame).

use crate::common;
use common::AlteredModel;
use std::sync::Arc;

use cosim::waivers::{CollectMode, WaiverSet};
use cosim::{
    CompareConfig, CustomDut, Dut, DutChoice, HostBfm, NodeConfig, ReferenceChoice, TbConfig,
    Testbench,
};
use diagnose::DivergenceKind;

const MOD: u8 = 0;
const IR: u8 = 3;
const RMC: u8 = 29;
const RXB1: u8 = 17;

fn waivers(resync: &str) -> WaiverSet {
    WaiverSet::parse(
        &format!(
            r#"
[[waiver]]
id = "no-sleep-mode"
kind = "register-read"
register = "MOD"
address = 0
bits = [4]
expected = [0x10]
seen = [0x00]
max-hits = 1
dut = ["no-sleep"]
explanation = "the DUT has no sleep mode (test fixture)"
resync = ["{resync}"]
"#
        ),
        "t.toml",
    )
    .expect("waiver file")
}

/// PeliCAN, open filter, RIE | WUIE; MOD = SM (the DUT ignores it), read
/// MOD; a frame from the other node; read IR, RMC, the frame, release it.
fn run(resync: &str) -> waivers::WaiverReport {
    let make: Arc<dyn Fn() -> Box<dyn Dut> + Send + Sync> =
        Arc::new(|| Box::new(
            AlteredModel::new("golden model without sleep mode, RXB[1] bit 0 flipped")
                .on_write(|m| {
                    if m.we && m.adr == MOD {
                        m.dat &= !0x10;
                    }
                })
                .on_read(|adr, d, _| if adr == RXB1 { d ^ 0x01 } else { d }),
        ));
    let pelican_open = vec![
        (0u8, 0x01u8),
        (31, 0x80),
        (6, 0x41),
        (7, 0x25),
        (20, 0xFF),
        (21, 0xFF),
        (22, 0xFF),
        (23, 0xFF),
    ];
    let mut node_init = pelican_open.clone();
    node_init.push((0, 0x00));
    let mut tb = Testbench::new(TbConfig {
        scenario: "no-sleep-mode".into(),
        dut: DutChoice::Custom(CustomDut { name: "no-sleep".into(), make }),
        host: HostBfm::Wishbone,
        nodes: vec![NodeConfig { name: "talker".into(), init: node_init }],
        lockstep: Some((ReferenceChoice::Model, CompareConfig::default())),
        waivers: waivers(resync),
        collect: CollectMode::Collect,
        ..TbConfig::default()
    })
    .expect("test bench");
    for (a, d) in pelican_open {
        tb.write(a, d).unwrap();
    }
    tb.write(4, 0x11).unwrap(); // IER = RIE | WUIE
    tb.write(MOD, 0x00).unwrap();
    tb.run_bits(20).unwrap();
    tb.write(MOD, 0x10).unwrap();
    assert_eq!(tb.read(MOD).unwrap() & 0x10, 0, "the DUT never sleeps");
    // The talker sends ID 0x120, one byte.
    let talker = tb.bus_mut().node_mut(0);
    for (a, d) in [(16u8, 0x01u8), (17, 0x24), (18, 0x00), (19, 0x5A), (1, 0x01)] {
        talker.write(a, d);
    }
    tb.run_bits(90).unwrap();
    assert_eq!(tb.read(IR).unwrap(), 0x01, "the DUT received it: RI, no WUI");
    assert_eq!(tb.read(RMC).unwrap(), 1);
    for a in 16..=19 {
        tb.read(a).unwrap();
    }
    tb.write(1, 0x04).unwrap();
    tb.run_bits(5).unwrap();
    tb.waiver_report()
}

#[test]
fn after_a_waived_sleep_request_the_next_real_difference_is_the_one_reported() {
    let r = run("model-skips-sleep");
    let waived: Vec<&str> = r.waived.iter().map(|w| w.waiver_id.as_str()).collect();
    assert_eq!(waived, ["no-sleep-mode"], "{}", r.to_text());
    let failures: Vec<(DivergenceKind, Option<&str>, u32, u32)> =
        r.failures.iter().map(|d| (d.kind, d.register.as_deref(), d.seen, d.expected)).collect();
    // The RXB[1] read: ID 0x120 -> RXB[1] = 0x24 on the model, 0x25 on the DUT.
    assert_eq!(failures.len(), 1, "only the flipped RXB[1] bit: {}", r.to_text());
    assert_eq!(failures[0].0, DivergenceKind::RegisterRead);
    assert_eq!((failures[0].2, failures[0].3), (0x25, 0x24), "{}", r.to_text());
}

#[test]
fn without_the_resync_the_sleeping_model_buries_it_in_consequences() {
    // The same run with `none`: the model sleeps through the frame (WUI, no
    // RI, RMC 0): the first failure is a consequence, not the RXB[1] bit.
    let r = run("none");
    assert_eq!(r.waived.len(), 1, "{}", r.to_text());
    assert!(r.failures.len() > 1, "{}", r.to_text());
    let first = &r.failures[0];
    assert!(!(first.kind == DivergenceKind::RegisterRead && first.seen == 0x25), "{}", r.to_text());
}
