//! A scenario whose expected verdict is a set-up one under which a
//! divergence is the symptom (ConfigWriteOutsideReset, ...) still judges its
//! own reads after that divergence, with or without `--collect`. Before, the
//! run stopped at the first divergence (the wrong read itself), the read's
//! expectation was never recorded, the diagnosis stayed the expected one
//! and the scenario passed: mutant 125 (BasicCAN AMR reading F7H in
//! operating mode) survived `registers/basic-reset-values-and-access`.

#[path = "../../../cosim/tests/common/mod.rs"]
mod altered;
use altered::AlteredModel;

use scenario::{DutSpec, RunOptions, Scenario, run};
use waivers::CollectMode;

fn scenario() -> Scenario {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let s = Scenario::load(root.join("tb/registers/basic-reset-values-and-access.toml")).expect("the scenario loads");
    assert_eq!(s.expect.category, Some(diagnose::Category::ConfigWriteOutsideReset), "the scenario no longer expects a set-up verdict");
    s
}

/// The golden model with BasicCAN AMR (address 5) reading F7H instead of
/// FFH in operating mode (the last CR write has RR = 0), as mutant 125.
fn amr_f7_in_operating_mode() -> cosim::CustomDut {
    cosim::CustomDut {
        name: "model, AMR F7H in operating mode".into(),
        make: std::sync::Arc::new(|| {
            Box::new(AlteredModel::new("model, AMR F7H in operating mode").on_read(|addr, d, writes| {
                let operating = writes.iter().rev().find(|w| w.0 == 0).is_some_and(|w| w.1 & 0x01 == 0);
                if addr == 5 && operating && d == 0xFF { 0xF7 } else { d }
            }))
        }),
    }
}

fn options(collect: CollectMode, dut: Option<cosim::CustomDut>) -> RunOptions {
    RunOptions { dut: Some(DutSpec::model()), collect, custom_dut: dut, ..Default::default() }
}

/// The wrong AMR read comes after the scenario's first write outside reset
/// mode (ACR, one step before): the verdict is still ConfigWriteOutsideReset,
/// and the read is a failure, stopping at the first divergence or not.
#[test]
fn a_wrong_read_after_the_set_up_verdicts_first_event_fails_without_collect() {
    let s = scenario();
    for mode in [CollectMode::StopAtFirst, CollectMode::Collect] {
        let out = run(&s, &options(mode, Some(amr_f7_in_operating_mode())));
        assert_eq!(out.diagnosis.category, diagnose::Category::ConfigWriteOutsideReset, "{mode:?}: {:?}", out.mismatches);
        assert!(!out.passed, "{mode:?}: a DUT reading AMR F7H in operating mode passed");
        assert!(
            out.mismatches.iter().any(|m| m.starts_with("step 57: AMR & 0xFF expected 0xFF") && m.ends_with("seen 0xF7")),
            "{mode:?}: the AMR read is not the failure: {:?}",
            out.mismatches
        );
    }
}

/// The same scenario on the unaltered model passes in both modes: the
/// failure above is the altered read's.
#[test]
fn the_unaltered_model_passes_in_both_modes() {
    let s = scenario();
    for mode in [CollectMode::StopAtFirst, CollectMode::Collect] {
        let out = run(&s, &options(mode, None));
        assert!(out.passed, "{mode:?}: {:?}", out.mismatches);
    }
}

/// Only the verdicts whose reads are judged behind a divergence switch to
/// collect mode; the others run as asked.
#[test]
fn collect_mode_is_forced_only_for_set_up_verdicts_with_judged_reads() {
    use diagnose::Category as C;
    for c in [C::ConfigWriteOutsideReset, C::TxBufferWriteWhileLocked, C::AddressModeConfusion] {
        assert_eq!(scenario::run::collect_mode(Some(c), CollectMode::StopAtFirst), CollectMode::Collect, "{c:?}");
    }
    for c in [None, Some(C::Pass), Some(C::NoAcknowledge), Some(C::HostBusViolation), Some(C::DutDeviatesFromModel)] {
        assert_eq!(scenario::run::collect_mode(c, CollectMode::StopAtFirst), CollectMode::StopAtFirst, "{c:?}");
        assert_eq!(scenario::run::collect_mode(c, CollectMode::Collect), CollectMode::Collect, "{c:?}");
    }
}
