//! The random campaign on the golden model, on our RTL and on a planted
//! defect: every drawn run passes where DUT and model agree; a defect is
//! found, shrunk, saved as a scenario, and the saved file fails the same
//! way under `scenario::run` while the model passes it.

use campaign::plan::DrawLimits;
use campaign::random::{RandomConfig, run_campaign};
use scenario::{DutSpec, RunOptions, Scenario};

#[path = "../../../cosim/tests/common/mod.rs"]
mod altered;

fn root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fixed small budget on our RTL (under a minute on 2 cores): no divergence, the scoreboard satisfied.
#[test]
fn a_small_campaign_on_rtl_passes() {
    let mut c = RandomConfig::new(2026, 120, DutSpec::rtl());
    // Quanta of up to 8 CAN clocks keep the budget small; the large-BRP
    // space runs in the long campaigns.
    c.limits = DrawLimits { max_brp: 3, ..DrawLimits::default() };
    let r = run_campaign(&c);
    assert!(r.frames >= 120 && r.runs >= 5, "{} frames in {} runs", r.frames, r.runs);
    assert!(r.passed(), "{}", r.to_text(&c));
}

/// Every host with a wrapper of its own drives a campaign (`campaign
/// --host`): a few frames each on our RTL through that wrapper.
#[test]
fn a_tiny_campaign_runs_on_every_new_host() {
    for h in [scenario::HostBfm::Axi4Lite, scenario::HostBfm::Apb, scenario::HostBfm::Apb3, scenario::HostBfm::Regport, scenario::HostBfm::Motorola] {
        let mut c = RandomConfig::new(7, 12, DutSpec::rtl());
        c.host = Some(h);
        c.shrink_runs = 0;
        c.limits = DrawLimits { max_brp: 1, ..DrawLimits::default() };
        let r = run_campaign(&c);
        assert!(r.frames >= 12 && r.runs >= 1, "{}: {} frames in {} runs", h.name(), r.frames, r.runs);
        assert!(r.passed(), "{}: {}", h.name(), r.to_text(&c));
    }
}

/// The model against itself: any failure here is a kit defect.
#[test]
fn the_model_against_itself_never_fails() {
    let c = RandomConfig::new(7, 150, DutSpec::model());
    let r = run_campaign(&c);
    assert!(r.passed(), "{}", r.to_text(&c));
}

/// A planted defect (the receive window shows DLC 9..15 as DLC - 8) is
/// found, shrunk to a smaller plan, and saved; the saved scenario fails on
/// the defect with the same divergence and passes on the model.
#[test]
fn a_planted_defect_is_found_shrunk_saved_and_replayed() {
    let planted = || {
        altered::AlteredModel::new("dlc-bug").on_read(|adr, d, w| {
            // PeliCAN (CDR.7 written) frame information, in operating mode.
            let pelican = w.iter().any(|&(a, v)| a == 31 && v & 0x80 != 0);
            if pelican && adr == 16 && d & 0x0F > 8 && w.iter().rev().find(|(a, _)| *a == 0).is_some_and(|(_, v)| v & 1 == 0) { d - 8 } else { d }
        })
    };
    let dut = cosim::CustomDut { name: "dlc-bug".into(), make: std::sync::Arc::new(move || Box::new(planted())) };
    let dir = std::env::temp_dir().join(format!("campaign-planted-{}", std::process::id()));
    let mut c = RandomConfig::new(3, 2000, DutSpec::model());
    c.custom_dut = Some(dut.clone());
    c.max_failures = 1;
    c.shrink_runs = 60;
    c.jobs = 2;
    c.limits = DrawLimits { max_brp: 3, ..DrawLimits::default() };
    c.save_failures = Some(dir.clone());
    let r = run_campaign(&c);
    assert!(!r.passed(), "the planted defect went unnoticed over {} frames", r.frames);
    let f = &r.failures[0];
    assert!(f.what.contains("RegisterRead"), "{}", f.what);
    let k = f.shrunk.as_ref().expect("shrunk");
    assert!(k.size.1 < k.size.0, "shrinking kept the size {}", k.size.0);
    assert_eq!(f.replayed, Some(true), "the saved file does not fail the same way");
    let saved = f.saved.as_ref().expect("saved");
    let s = Scenario::load(saved).expect("the saved scenario loads");
    assert!(s.purpose.contains("RegisterRead"), "purpose: {}", s.purpose);
    let on_model = scenario::run(&s, &RunOptions { dut: Some(DutSpec::model()), ..Default::default() });
    assert!(on_model.passed, "the saved scenario fails on the model: {:?}", on_model.mismatches);
    let on_bug = scenario::run(&s, &RunOptions { dut: Some(DutSpec::model()), custom_dut: Some(dut), ..Default::default() });
    assert!(!on_bug.passed, "the saved scenario passes on the defect");
    let _ = std::fs::remove_dir_all(dir);
}

/// The scenarios the campaign found (tb/random.list) pass on the model and
/// on our RTL without divergence.
#[test]
fn the_found_scenarios_pass_on_model_and_rtl() {
    let list = scenario::load_list(root().join("tb/random.list")).expect("tb/random.list loads");
    assert!(!list.is_empty());
    for s in &list {
        for dut in [DutSpec::model(), DutSpec::rtl()] {
            let o = scenario::run(s, &RunOptions { dut: Some(dut.clone()), ..Default::default() });
            assert!(o.passed, "{} on {}: {:?}\n{}", s.name, dut.name, o.mismatches, o.diagnosis.to_text());
        }
    }
}

/// A run that panics (here: a DUT that cannot be made) is a failed run
/// named as a kit defect, and the campaign goes on to its budget.
#[test]
fn a_panicking_run_is_a_failure_not_the_end_of_the_campaign() {
    let dut = cosim::CustomDut { name: "panics".into(), make: std::sync::Arc::new(|| panic!("this DUT cannot be made")) };
    let mut c = RandomConfig::new(5, 20, DutSpec::model());
    c.custom_dut = Some(dut);
    c.shrink_runs = 0;
    c.max_failures = 3;
    c.jobs = 1;
    let r = run_campaign(&c);
    assert_eq!(r.failures.len(), 3, "{}", r.to_text(&c));
    assert!(r.failures.iter().all(|f| f.signature.0.starts_with("kit defect: panic")), "{}", r.to_text(&c));
    assert!(r.failures[0].what.contains("this DUT cannot be made"));
}
