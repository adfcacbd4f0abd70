//! After a divergence listed in collect mode the reference
//! resynchronises where it can (it adopts the DUT's value of the read that
//! differed), so the next report is the next real difference, not the
//! cascade of the first. The DUT is the golden model behind a wrapper with
//! one deliberate deviation: a host write of TXERR stores the value + 1.

use crate::common;
use common::AlteredModel;
use std::sync::Arc;

use cosim::waivers::CollectMode;
use cosim::{CompareConfig, CustomDut, Dut, DutChoice, HostBfm, ReferenceChoice, TbConfig, Testbench};
use diagnose::DivergenceKind;

const TXERR: u8 = 15;

fn bench() -> Testbench {
    let make: Arc<dyn Fn() -> Box<dyn Dut> + Send + Sync> =
        Arc::new(|| Box::new(AlteredModel::new("golden model, TXERR written + 1").on_write(|m| {
            if m.we && m.adr == TXERR {
                m.dat = m.dat.wrapping_add(1);
            }
        })));
    Testbench::new(TbConfig {
        scenario: "txerr-written-plus-one".into(),
        dut: DutChoice::Custom(CustomDut { name: "txerr-written-plus-one".into(), make }),
        host: HostBfm::Wishbone,
        lockstep: Some((ReferenceChoice::Model, CompareConfig::default())),
        collect: CollectMode::Collect,
        ..TbConfig::default()
    })
    .expect("test bench")
}

/// TXERR written 5 (the DUT stores 6), then a frame nobody acknowledges:
/// each attempt adds 8 on both sides. Without the resync every later TXERR
/// read is a new difference (14/13, 22/21, ...: the cascade of the one
/// write); with it the model takes 6 at the first differing read and the
/// counters agree, so the only other difference listed is the next real
/// one, the second TXERR write (DUT 41, model 40).
#[test]
fn collect_mode_adopts_the_duts_register_so_the_next_report_is_the_next_difference() {
    let mut tb = bench();
    for (a, d) in [(0u8, 0x01u8), (31, 0x80), (6, 0x41), (7, 0x25), (TXERR, 5)] {
        tb.write(a, d).unwrap();
    }
    assert_eq!(tb.read(TXERR).unwrap(), 6, "the wrapper's deviation");
    for (a, d) in [(0u8, 0x00u8), (16, 0x01), (17, 0x0A), (18, 0xA0), (19, 0x5A), (1, 0x01)] {
        tb.write(a, d).unwrap();
    }
    let mut seen = Vec::new();
    for _ in 0..3 {
        tb.run_bits(70).unwrap();
        seen.push(tb.read(TXERR).unwrap());
    }
    assert!(seen.windows(2).all(|w| w[1] > w[0]) && seen[0] > 6, "ACK errors count up: {seen:?}");
    tb.write(0, 0x01).unwrap();
    tb.write(TXERR, 40).unwrap();
    assert_eq!(tb.read(TXERR).unwrap(), 41);
    tb.run_bits(3).unwrap();
    let r = tb.waiver_report();
    let listed: Vec<(DivergenceKind, Option<&str>, u32, u32)> =
        r.failures.iter().map(|d| (d.kind, d.register.as_deref(), d.seen, d.expected)).collect();
    assert_eq!(
        listed,
        [
            (DivergenceKind::RegisterRead, Some("TXERR"), 6, 5),
            (DivergenceKind::RegisterRead, Some("TXERR"), 41, 40),
        ],
        "the first difference and the next real one, no cascade: {}",
        r.to_text()
    );
}
