//! D10g: the opencores core waits for one more bus-free sequence
//! after bus-on. The shipped waiver `bus-free-wait-after-bus-on` takes the
//! first SR read that shows it and resynchronises the model
//! (`model-waits-bus-free-after-bus-on`); what it still catches.

use diagnose::{Divergence, DivergenceKind};
use waivers::{DutInfo, Resync, Verdict, WaiverSet};

const ID: &str = "bus-free-wait-after-bus-on";

fn shipped() -> WaiverSet {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tb/waivers/opencores-upstream.toml");
    WaiverSet::load(path).unwrap()
}

fn dut() -> DutInfo {
    DutInfo::new("opencores-can (/cores/can)")
}

fn sr(model: u32, seen: u32) -> Divergence {
    Divergence {
        kind: DivergenceKind::RegisterRead,
        bit: Some(2136),
        register: Some("SR".into()),
        expected: model,
        seen,
        ..Divergence::default()
    }
}

fn ours(v: &Verdict) -> bool {
    matches!(v, Verdict::Waived { waiver_id, .. } if waiver_id == ID)
}

#[test]
fn the_first_read_after_bus_on_is_waived_once_and_resynchronises_the_model() {
    let d = dut();
    // Measured: model idle at bus-on (TBS), DUT still BS with TS = RS = 1.
    let mut set = shipped();
    let v = set.check(&sr(0x04, 0xB4), &d);
    assert_eq!(
        v,
        Verdict::Waived { waiver_id: ID.into(), resync: vec![Resync::ModelWaitsBusFreeAfterBusOn] }
    );
    // max-hits 1: a second such read fails (the model was resynchronised,
    // so it cannot come again unless the resync did not hold).
    assert!(!ours(&set.check(&sr(0x04, 0x34), &d)));
    assert_eq!(set.check(&sr(0x04, 0x34), &d), Verdict::Failure);

    // The DUT's BS already clear: also the deviation.
    let mut set = shipped();
    assert!(ours(&set.check(&sr(0x04, 0x34), &d)));
}

#[test]
fn what_the_bus_on_waiver_still_catches() {
    let d = dut();
    for (model, seen, why) in [
        (0x24, 0x34, "the model already transmitting (TS) while the DUT waits: too late to resync"),
        (0x84, 0xB4, "the model still bus-off: not after bus-on"),
        (0x04, 0x14, "RS alone on the DUT: not the waiting state"),
        (0x04, 0x24, "TS alone on the DUT: transmitting, not waiting"),
        (0x04, 0x30, "TBS differs too"),
        (0x04, 0x3C, "TCS differs too"),
        (0x44, 0x74, "ES on both: error counters not reset, not a bus-on"),
        (0x00, 0x30, "a request pending on the model: the waiver is for the first read after bus-on"),
    ] {
        let mut set = shipped();
        let v = set.check(&sr(model, seen), &d);
        assert!(!ours(&v), "model 0x{model:02X}, DUT 0x{seen:02X}: {why}: {v:?}");
    }
}

/// The resync changes the model's bus timing: only on a read of SR and
/// only with a max-hits bound.
#[test]
fn model_waits_bus_free_after_bus_on_needs_a_read_of_sr_and_max_hits() {
    let waiver = |kind_and_place: &str| {
        format!(
            "[[waiver]]\nid = \"bus-on\"\n{kind_and_place}\ndut = [\"x\"]\nexplanation = \"the core waits for one more bus-free sequence after bus-on\"\nresync = [\"model-waits-bus-free-after-bus-on\"]\n"
        )
    };
    for ok in [
        "kind = \"register-read\"\nregister = \"SR\"\nmax-hits = 1",
        "kind = \"register-read\"\naddress = 2\nmax-hits = 2",
    ] {
        WaiverSet::parse(&waiver(ok), "w.toml").unwrap_or_else(|e| panic!("{ok}: {e}"));
    }
    for bad in [
        "kind = \"register-read\"\nregister = \"SR\"",
        "kind = \"tx-bit\"\nmax-hits = 1",
        "kind = \"register-read\"\nregister = \"IR\"\nmax-hits = 1",
        "kind = \"irq\"\nmax-hits = 1",
    ] {
        let e = WaiverSet::parse(&waiver(bad), "w.toml").expect_err(bad).to_string();
        assert!(
            e.starts_with("w.toml:") && e.contains("resync") && e.contains("model-waits-bus-free-after-bus-on needs"),
            "{e}"
        );
    }
}
