//! `after = "data-overrun"` through the test bench: the comparator hands the
//! waiver session the number of messages the reference (the golden model)
//! lost to an RX FIFO overrun since its FIFO was last emptied. The DUT is
//! the golden model behind a wrapper whose RMC reads one more than it
//! holds (the opencores core's D8c, a lost message counted, but in every
//! run), so no Verilator build is needed. The node receives its own frames
//! (self-test mode, self reception): five extended 8-byte messages (13
//! bytes each) overrun the 64-byte FIFO once.

use crate::common;
use common::AlteredModel;
use std::sync::Arc;

use cosim::waivers::{CollectMode, WaiverReport, WaiverSet};
use cosim::{CompareConfig, CustomDut, Dut, DutChoice, HostBfm, ReferenceChoice, TbConfig, Testbench};
use diagnose::DivergenceKind;

const MOD: u8 = 0;
const CMR: u8 = 1;
const RMC: u8 = 29;

const WAIVER: &str = r#"
[[waiver]]
id = "rmc-counts-lost-message"
kind = "register-read"
register = "RMC"
seen-offset = 1
after = "data-overrun"
dut = ["rmc-one-more"]
explanation = "a lost message keeps an entry in the DUT's message counter (test wrapper)"
resync = ["none"]
"#;

fn bench(waiver: &str) -> Testbench {
    let make: Arc<dyn Fn() -> Box<dyn Dut> + Send + Sync> =
        Arc::new(|| Box::new(AlteredModel::new("golden model, RMC one more").on_read(|adr, d, _| if adr == RMC { d.wrapping_add(1) } else { d })));
    Testbench::new(TbConfig {
        scenario: "rmc-one-more".into(),
        dut: DutChoice::Custom(CustomDut { name: "rmc-one-more".into(), make }),
        host: HostBfm::Wishbone,
        lockstep: Some((ReferenceChoice::Model, CompareConfig::default())),
        collect: CollectMode::Collect,
        waivers: WaiverSet::parse(waiver, "t.toml").unwrap(),
        ..TbConfig::default()
    })
    .expect("test bench")
}

/// PeliCAN, filter open, self-test mode (no acknowledge needed).
fn self_test_mode(tb: &mut Testbench) {
    for (a, d) in [(MOD, 0x01u8), (31, 0x80), (20, 0xFF), (21, 0xFF), (22, 0xFF), (23, 0xFF), (6, 0x41), (7, 0x25), (MOD, 0x04)] {
        tb.write(a, d).unwrap();
    }
    tb.run_bits(20).unwrap();
}

/// Sends `n` extended 8-byte frames to itself (self reception request),
/// each to its end.
fn self_receive(tb: &mut Testbench, n: u8) {
    for k in 0..n {
        let frame = [0x88, 0x10, 0x00, 0x00, 0x08 * k, 1, 2, 3, 4, 5, 6, 7, 8];
        for (i, b) in frame.iter().enumerate() {
            tb.write(16 + i as u8, *b).unwrap();
        }
        tb.write(CMR, 0x10).unwrap();
        tb.run_bits(200).unwrap();
    }
}

fn rmc_failures(r: &WaiverReport) -> Vec<(u32, u32)> {
    r.failures.iter().filter(|d| d.kind == DivergenceKind::RegisterRead).map(|d| (d.expected, d.seen)).collect()
}

/// No message lost: RMC one more is a failure, with the near miss named.
#[test]
fn rmc_one_more_without_a_lost_message_is_a_failure() {
    let mut tb = bench(WAIVER);
    self_test_mode(&mut tb);
    self_receive(&mut tb, 2);
    assert_eq!(tb.read(RMC).unwrap(), 3, "the wrapper: two messages, one more");
    tb.run_bits(2).unwrap();
    let r = tb.waiver_report();
    assert_eq!(rmc_failures(&r), [(2, 3)], "{}", r.to_text());
    assert!(r.waived.is_empty(), "{}", r.to_text());
}

/// Five messages of 13 bytes: the fifth is lost. The same difference is
/// then waived, and printed with its condition; reset mode empties the
/// FIFO, and with it the count of lost messages.
#[test]
fn rmc_one_more_after_a_lost_message_is_waived_until_reset_mode_empties_the_fifo() {
    let mut tb = bench(WAIVER);
    self_test_mode(&mut tb);
    self_receive(&mut tb, 5);
    assert_eq!(tb.read(2).unwrap() & 0x02, 0x02, "SR.DOS: the fifth message was lost");
    assert_eq!(tb.read(RMC).unwrap(), 5, "four stored, one more");
    tb.run_bits(2).unwrap();
    let r = tb.waiver_report();
    assert!(r.failures.is_empty(), "{}", r.to_text());
    assert_eq!(r.waived.len(), 1, "{}", r.to_text());
    let dev = &r.deviations[0];
    assert_eq!((dev.waiver_id.as_str(), dev.hits), ("rmc-counts-lost-message", 1));
    assert!(dev.bound_text().contains("after = \"data-overrun\""), "{}", dev.bound_text());
    // Reset mode empties the FIFO: no lost message any more.
    tb.write(MOD, 0x05).unwrap();
    tb.write(MOD, 0x04).unwrap();
    tb.run_bits(20).unwrap();
    self_receive(&mut tb, 1);
    assert_eq!(tb.read(RMC).unwrap(), 2);
    tb.run_bits(2).unwrap();
    let r = tb.waiver_report();
    assert_eq!(rmc_failures(&r), [(1, 2)], "{}", r.to_text());
}
