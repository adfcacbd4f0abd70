//! Campaigns on the golden model as DUT (self-check: no disagreement may
//! appear), on a deliberately deviating fixture (a disagreement must be
//! found and reproduce exactly from its seed and frame count), and on our
//! RTL against the model.

use campaign::{CampaignConfig, DisagreementKind, DutChoice, run_campaign};

#[test]
fn golden_model_against_itself_never_disagrees_under_faults() {
    let cfg = CampaignConfig { seed: 0x5EED, frames: 30, dut: DutChoice::Model, fault_rate: 0.8, ..CampaignConfig::default() };
    let r = run_campaign(&cfg);
    println!("{}", r.to_text());
    assert!(r.passed(), "{}", r.to_text());
    assert_eq!(r.frames_run, 30);
    // The faults did something: they were reached and the DUT saw errors.
    assert!(r.faults_injected >= 15, "{}", r.faults_injected);
    assert!(r.faults_reached >= r.faults_injected / 2, "{} of {}", r.faults_reached, r.faults_injected);
    assert!(r.bus_errors > 0 && r.max_rec + r.max_tec > 0, "{}", r.to_text());
    assert!(r.dut_received > 0 && r.dut_transmissions > 0);
    assert!(r.reads_compared > 30 * 7 && r.bits_compared > 30 * 40, "{}", r.to_text());
}

#[test]
fn a_deviating_dut_is_caught_and_each_disagreement_reproduces_exactly() {
    let cfg = CampaignConfig {
        seed: 99,
        frames: 6,
        dut: DutChoice::Bundled("cosim_deviant".into()),
        max_disagreements: 2,
        ..CampaignConfig::default()
    };
    let r = run_campaign(&cfg);
    assert!(r.setup_error.is_none(), "{:?}", r.setup_error);
    assert_eq!(r.disagreements.len(), 2, "{}", r.to_text());
    for d in &r.disagreements {
        assert!(matches!(d.kind, DisagreementKind::Lockstep(_)), "{d:?}");
        assert!(d.dut_value.is_some() && d.model_value != d.dut_value, "{d:?}");
        let again = run_campaign(&d.reproduce(&cfg));
        assert_eq!(again.disagreements.first(), Some(d), "re-run of {}", d.command());
        assert_eq!(again.disagreements.len(), 1);
    }
    // The second one happened in a later segment: its command says where.
    let second = &r.disagreements[1];
    assert!(second.segment_start > 0 && second.command().contains("--first-frame"), "{}", second.command());
}

#[test]
fn rtl_against_the_model_under_random_faults() {
    let cfg = CampaignConfig { seed: 0x5EED, frames: 30, dut: DutChoice::Rtl, fault_rate: 0.8, ..CampaignConfig::default() };
    let r = run_campaign(&cfg);
    println!("{}", r.to_text());
    assert!(r.setup_error.is_none(), "{:?}", r.setup_error);
    assert!(r.passed(), "{}", r.to_text());
    assert_eq!(r.frames_run, 30);
}

/// Faults reach the DUT's receiver (the test bench gives it no frame
/// context of its own): a flip of a body bit seen only by the DUT is always
/// a bus error for the DUT (bit, stuff, form or CRC error), captured in ECC.
#[test]
fn a_flip_seen_only_by_the_dut_is_a_bus_error_on_the_dut() {
    use campaign::{Aim, FaultKind, FaultTarget};
    let cfg = CampaignConfig { seed: 3, frames: 60, dut: DutChoice::Model, fault_rate: 1.0, ..CampaignConfig::default() };
    let r = run_campaign(&cfg);
    assert!(r.passed(), "{}", r.to_text());
    let hits: Vec<_> = r
        .frames
        .iter()
        .filter(|f| {
            f.fault.as_ref().is_some_and(|p| {
                p.fault.kind == FaultKind::Flip && p.fault.target == FaultTarget::Dut && matches!(p.aim, Aim::Control | Aim::Data | Aim::Crc)
            })
        })
        .collect();
    assert!(!hits.is_empty(), "seed 3 draws such a fault within 60 frames");
    for f in hits {
        assert!(f.fault_reached, "{f:?}");
        assert!(f.ir & 0x80 != 0, "IR.BEI after {f:?}");
    }
    // The same on one model node's receiver: that node detects the error.
    let node_hits: Vec<_> = r
        .frames
        .iter()
        .filter_map(|f| {
            let p = f.fault.as_ref()?;
            match p.fault.target {
                FaultTarget::Node(i) if p.fault.kind == FaultKind::Flip && matches!(p.aim, Aim::Control | Aim::Data | Aim::Crc) => Some((i, f)),
                _ => None,
            }
        })
        .collect();
    assert!(!node_hits.is_empty(), "seed 3 draws such a fault within 60 frames");
    for (i, f) in node_hits {
        assert!(f.node_errors[i], "node{} after {f:?}", i + 1);
    }
    // Frames without a fault see no bus error at all.
    let cfg = CampaignConfig { fault_rate: 0.0, frames: 20, ..cfg };
    let r = run_campaign(&cfg);
    assert!(r.passed(), "{}", r.to_text());
    assert_eq!(r.faults_injected, 0);
    assert!(r.frames.iter().all(|f| f.ir & 0x80 == 0 && f.txerr == 0 && f.rxerr == 0 && f.node_errors.iter().all(|e| !e)), "{:?}", r.frames);
}
