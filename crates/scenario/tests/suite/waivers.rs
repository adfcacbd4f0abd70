//! Waivers at scenario level: the deviant fixture (address 4 bit 7
//! stuck at 0) as an external DUT against the golden model, with waiver
//! files named in `[run] waivers` and in `RunOptions::waivers`.

use diagnose::DivergenceKind;
use scenario::regress::{RegressOptions, regress};
use scenario::{DutSpec, RunOptions, RunOutcome, Scenario, run};
use std::path::{Path, PathBuf};

/// Reset mode, ACR (address 4) written 0xFF and read back: the fixture
/// answers 0x7F, the model 0xFF. Then a few idle bits (tx agrees: recessive).
const SCENARIO: &str = r#"purpose = "deviant fixture: a known register-read deviation"
verifies = ["a waived divergence lets the run pass"]
[clocks]
host_mhz = 50.0
can_mhz = 24.0
[host]
bfm = "wishbone"
[run]
max_bits = 2000
WAIVERS
[[step]]
write = "CR"
value = 0x01
[[step]]
write = "ACR"
value = 0xFF
[[step]]
read = "ACR"
[[step]]
wait_bits = 20
"#;

const REG4: &str = r#"[[waiver]]
id = "reg4-bit7"
kind = "register-read"
address = 4
bits = [7]
seen = [0x7F]
dut = ["*cosim_deviant*"]
explanation = "bit 7 of address 4 is not implemented in the fixture, on purpose"
resync = ["none"]
"#;

const STALE: &str = r#"[[waiver]]
id = "never-matches"
kind = "irq"
dut = ["*cosim_deviant*"]
explanation = "an irq deviation the fixture does not have: must come out stale"
resync = ["none"]
"#;

/// A directory with the fixture alone (the external DUT) and the waiver files.
fn workdir(test: &str) -> PathBuf {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = std::env::temp_dir().join(format!("scenario-waivers-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A fixed path for the core: the run-time build cache is keyed on the
    // sources' paths too, so only the first run verilates (about 15 s).
    let core = core_dir();
    std::fs::create_dir_all(&core).unwrap();
    let src = std::fs::read(root.join("tb/fixtures/cosim_deviant.v")).unwrap();
    if std::fs::read(core.join("cosim_deviant.v")).ok().as_deref() != Some(&src[..]) {
        // Written aside and renamed: the other test may be reading it.
        let tmp = core.with_file_name(format!("cosim_deviant.v.{test}.{}", std::process::id()));
        std::fs::write(&tmp, src).unwrap();
        std::fs::rename(&tmp, core.join("cosim_deviant.v")).unwrap();
    }
    std::fs::write(dir.join("reg4.toml"), REG4).unwrap();
    std::fs::write(dir.join("stale.toml"), STALE).unwrap();
    dir
}

fn core_dir() -> PathBuf {
    std::env::temp_dir().join("scenario-waivers-fixture").join("cosim_deviant")
}

fn deviant() -> DutSpec {
    DutSpec::external("cosim_deviant", core_dir(), "cosim_deviant")
}

/// The scenario written next to the waiver files, naming `files` in `[run]`.
fn scenario(dir: &Path, name: &str, files: &[&str]) -> Scenario {
    let list = if files.is_empty() {
        String::new()
    } else {
        format!("waivers = [{}]", files.iter().map(|f| format!("\"{f}\"")).collect::<Vec<_>>().join(", "))
    };
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, SCENARIO.replace("WAIVERS", &list)).unwrap();
    Scenario::load(&path).unwrap()
}

fn show(o: &RunOutcome) {
    eprintln!(
        "{}\n{}\nmismatches {:?}\nwall {:?}",
        o.diagnosis.to_text(),
        o.waivers.as_ref().map(|r| r.to_text()).unwrap_or_default(),
        o.mismatches,
        o.wall
    );
}

#[test]
fn the_deviant_fixture_fails_without_waivers_and_passes_with_them() {
    let dir = workdir("fail-pass");
    let dut = deviant();

    // No waiver: the run fails at the register read.
    let s = scenario(&dir, "none", &[]);
    let o = run(&s, &RunOptions { dut: Some(dut.clone()), ..Default::default() });
    show(&o);
    assert!(o.record.error.is_none(), "the fixture builds and runs: {:?}", o.record.error);
    assert!(!o.passed);
    let d = o.record.divergence.as_ref().expect("a divergence");
    assert_eq!(d.kind, DivergenceKind::RegisterRead);
    let r = o.waivers.as_ref().expect("a waiver report");
    assert_eq!((r.failures.len(), r.waived.len()), (1, 0));
    assert!(r.stopped_early || r.failures[0].kind == DivergenceKind::RegisterRead);

    // The scenario names the waiver file: passes, the divergence is waived.
    let s = scenario(&dir, "waived", &["reg4.toml"]);
    assert_eq!(s.waivers, [dir.join("reg4.toml")], "relative to the scenario file");
    let o = run(&s, &RunOptions { dut: Some(dut.clone()), ..Default::default() });
    show(&o);
    assert!(o.passed, "{:?}", o.mismatches);
    assert!(o.record.divergence.is_none());
    let r = o.waivers.as_ref().unwrap();
    assert!(r.passed());
    assert_eq!(r.waived.len(), 1);
    assert_eq!(r.waived[0].waiver_id, "reg4-bit7");
    assert_eq!(r.waived[0].divergence.kind, DivergenceKind::RegisterRead);
    assert!(o.warnings.is_empty(), "{:?}", o.warnings);

    // A second file from the options with a waiver that never matches:
    // still passes, with a stale-waiver warning.
    let o = run(&s, &RunOptions { dut: Some(dut.clone()), waivers: vec![dir.join("stale.toml")], ..Default::default() });
    show(&o);
    assert!(o.passed, "{:?}", o.mismatches);
    assert_eq!(o.warnings.len(), 1, "{:?}", o.warnings);
    assert!(o.warnings[0].contains("never-matches"), "{:?}", o.warnings);

    // Collect mode without waivers: run_bits goes on, the report fails it.
    let s0 = scenario(&dir, "collect", &[]);
    let o = run(&s0, &RunOptions { dut: Some(dut.clone()), collect: waivers::CollectMode::Collect, ..Default::default() });
    show(&o);
    assert!(!o.passed);
    assert!(o.mismatches.iter().any(|m| m.contains("unwaived")), "{:?}", o.mismatches);

    // Regression: the table says how many were waived, JUnit lists them as skipped.
    let rep = regress(
        &[s],
        &[dut],
        &RegressOptions { jobs: 1, waivers: vec![dir.join("stale.toml")], ..Default::default() },
    );
    let table = rep.to_table();
    eprintln!("{table}");
    assert!(rep.passed(), "{table}");
    assert!(table.contains("pass (1 waived)"), "{table}");
    assert!(table.contains("WARNING") && table.contains("never-matches"), "{table}");
    let junit = rep.to_junit();
    assert!(junit.contains("<skipped message=\"waived by reg4-bit7\"/>"), "{junit}");
    assert!(junit.contains("skipped=\"1\""), "{junit}");
    assert!(junit.contains("<system-err>"), "{junit}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The golden model adopts a DUT's counters in operating mode: error
/// warning and error passive are re-evaluated at once (SR.ES, the engine's
/// fault state, IR.EI/EPI), and back to active when they drop again.
#[test]
fn the_model_adopts_counters_in_operating_mode_and_reevaluates_its_fault_state() {
    use cosim::Reference;
    use sja1000::{FaultState, Sja1000};
    let mut m = Sja1000::new();
    // PeliCAN, every interrupt enabled, operating mode.
    m.write(0, 0x01);
    m.write(31, 0x80);
    m.write(4, 0xFF);
    m.write(0, 0x00);
    assert!(!m.in_reset_mode());
    let es = |m: &Sja1000| m.peek(2) & 0x40 != 0;
    assert!(!es(&m));
    m.adopt_counters(Some(100), None);
    assert_eq!((m.engine().tec(), m.engine().fault_state()), (100, FaultState::ErrorActive));
    assert!(es(&m), "TEC 100 >= EWL 96: SR.ES at once, not at the next reset-mode exit");
    assert_ne!(m.peek(3) & 0x04, 0, "IR.EI on the error-status change");
    m.adopt_counters(None, Some(130));
    assert_eq!(m.engine().fault_state(), FaultState::ErrorPassive);
    assert_eq!(m.peek(14), 130, "RXERR reads the adopted value");
    m.adopt_counters(Some(0), Some(0));
    assert_eq!(m.engine().fault_state(), FaultState::ErrorActive);
    assert!(!es(&m));
    // Storage registers adopt; derived ones refuse (nothing changed).
    assert!(m.adopt_register(4, 0x05), "IER");
    assert_eq!(m.peek(4), 0x05);
    assert!(!m.adopt_register(2, 0x00), "SR is derived state");
    // SR's latched flags (TCS, DOS) are taken when every other bit agrees.
    let sr = m.peek(2);
    assert!(m.adopt_register(2, sr ^ 0x08), "SR.TCS is a stored flag");
    assert_eq!(m.peek(2), sr ^ 0x08);
    assert!(m.adopt_register(2, sr), "and back");
    assert!(!m.adopt_register(2, sr ^ 0x08 ^ 0x04), "TBS follows the TX buffer: refused");
    assert_eq!(m.peek(2), sr, "a refused adoption changes nothing");
    assert!(m.adopt_register(15, 42), "TXERR via adopt_counters");
    assert_eq!(m.engine().tec(), 42);
    assert!(m.adopt_register(14, 9), "RXERR via adopt_counters");
    assert_eq!(m.engine().rec(), 9);
    // The lockstep reference forwards both hooks.
    let mut r = cosim::ModelRef::new();
    assert!(r.adopt_counters(Some(7), Some(3)));
    assert_eq!((r.model().engine().tec(), r.model().engine().rec()), (7, 3));
    assert!(!r.adopt_register(2, 0x00));
}

/// `resync = ["adopt-dut-register"]`: the golden model takes the fixture's
/// 0x7F, so a second read of ACR agrees (no second divergence, no note).
#[test]
fn an_adopted_register_is_not_reported_again() {
    let dir = workdir("adopt");
    std::fs::write(dir.join("adopt.toml"), REG4.replace("resync = [\"none\"]", "resync = [\"adopt-dut-register\"]")).unwrap();
    let path = dir.join("adopt-scenario.toml");
    let text = SCENARIO.replace("WAIVERS", "waivers = [\"adopt.toml\"]") + "[[step]]\nread = \"ACR\"\n";
    std::fs::write(&path, text).unwrap();
    let s = Scenario::load(&path).unwrap();
    let o = run(&s, &RunOptions { dut: Some(deviant()), ..Default::default() });
    show(&o);
    let r = o.waivers.as_ref().unwrap();
    assert!(o.passed, "{:?}", o.mismatches);
    assert_eq!(r.waived.len(), 1, "one waived read; the second read agrees with the adopted value: {}", r.to_text());
    assert!(r.notes.is_empty(), "the model applied the resync: {:?}", r.notes);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Stale waivers are judged over the suite: a waiver that one scenario of
/// the regression uses is not stale, one that no scenario uses is reported
/// once for the DUT (not once per scenario), with the number of scenarios.
#[test]
fn a_regression_reports_a_stale_waiver_once_and_only_if_no_scenario_used_it() {
    let dir = workdir("suite-stale");
    let dut = deviant();
    // Two scenarios with both files: the first reads ACR (reg4-bit7 hits),
    // the second never reads it (reg4-bit7 unused there).
    let reads = scenario(&dir, "reads-acr", &["reg4.toml", "stale.toml"]);
    let quiet_path = dir.join("no-acr-read.toml");
    let text = std::fs::read_to_string(dir.join("reads-acr.toml")).unwrap().replace("[[step]]\nread = \"ACR\"\n", "");
    assert!(!text.contains("read = \"ACR\""), "the second scenario must not read ACR");
    std::fs::write(&quiet_path, text).unwrap();
    let quiet = Scenario::load(&quiet_path).unwrap();
    let rep = regress(&[reads, quiet], std::slice::from_ref(&dut), &RegressOptions { jobs: 2, ..Default::default() });
    let table = rep.to_table();
    eprintln!("{table}");
    assert!(rep.passed(), "{table}");
    // Each run alone still has its own stale list (single `run` warns per run).
    let per_run: usize = rep.cells.iter().map(|c| c.stale.len()).sum();
    assert_eq!(per_run, 3, "reads-acr: never-matches; no-acr-read: both");
    let stale = rep.stale_warnings();
    assert_eq!(stale.len(), 1, "{stale:?}");
    assert!(stale[0].1.contains("`never-matches`") && stale[0].1.contains("the 2 scenario(s) run on"), "{stale:?}");
    assert!(!stale[0].1.contains("stopped at a failure"), "{stale:?}");
    assert_eq!(table.matches("WARNING").count(), 1, "{table}");
    assert!(!table.contains("`reg4-bit7`"), "used by one scenario: not stale\n{table}");
    // The waivers hit, with the deviation in plain words.
    let hit = rep.waivers_hit(&dut.name);
    assert_eq!(hit.len(), 1, "{hit:?}");
    assert_eq!((hit[0].deviation.waiver_id.as_str(), hit[0].deviation.hits), ("reg4-bit7", 1));
    assert_eq!(hit[0].scenarios, ["reads-acr"]);
    assert!(table.contains("reg4-bit7 x1 in 1 scenario(s): bit 7 of address 4 is not implemented in the fixture"), "{table}");
    let junit = rep.to_junit();
    assert!(junit.contains("<system-out>waived reg4-bit7 x1 in reads-acr"), "{junit}");
    assert_eq!(junit.matches("never-matches").count(), 1, "{junit}");
    // The diagnosis of the run that hit it names the deviation.
    let c = rep.cells.iter().find(|c| c.scenario == "reads-acr").unwrap();
    assert!(c.report.contains("Waived: bit 7 of address 4 is not implemented in the fixture, on purpose (reg4-bit7)"), "{}", c.report);

    // A run stopped at a failure is noted differently: the waiver may not
    // have been reached. Without reg4.toml the ACR read fails and stops.
    let bare = scenario(&dir, "stops", &["stale.toml"]);
    let rep = regress(&[bare], std::slice::from_ref(&dut), &RegressOptions { jobs: 1, ..Default::default() });
    let stale = rep.stale_warnings();
    assert_eq!(stale.len(), 1, "{stale:?}");
    assert!(stale[0].1.contains("1 of them stopped at a failure"), "{stale:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
