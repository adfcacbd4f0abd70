//! Profile inference on three cores: our rtl/ as an external core, a
//! fixture with renamed ports, an active-low reset, inverted irq/bus-off
//! and two host clocks more of access latency, and a fixture whose
//! interrupt is one bit late (a deviation: reported, never profiled). The
//! opencores core is checked when CAN_UPSTREAM_DIR names it. On AXI4-Lite,
//! APB3, the register port and the Motorola bus: the fork fixtures
//! (tb/fixtures/fork), each against its hand-written profile.

use profile_infer::{InferOptions, infer};
use scenario::regress::{RegressOptions, Status, regress};
use scenario::{DutSpec, HostBfm};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// rtl/ and `fixture` (if any) copied into one directory, as a user's core.
fn core_dir(fixture: Option<&str>) -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    for e in std::fs::read_dir(root().join("rtl")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "v" || x == "vh") {
            std::fs::copy(&p, d.path().join(p.file_name().unwrap())).unwrap();
        }
    }
    if let Some(f) = fixture {
        std::fs::copy(root().join("tb/fixtures/infer").join(f), d.path().join(f)).unwrap();
    }
    d
}

/// The fork fixtures (our bus wrappers under a fork's names, with copies
/// of the rtl files they wrap) copied into a directory of their own per
/// test; a stable one, so a rerun finds the core's build in the cache
/// (its key holds the path).
fn fork_dir(top: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("infer-{top}"));
    std::fs::create_dir_all(&d).unwrap();
    for e in std::fs::read_dir(root().join("tb/fixtures/fork")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "v" || x == "vh") {
            std::fs::copy(&p, d.join(p.file_name().unwrap())).unwrap();
        }
    }
    d
}

fn opts(dir: &Path, top: &str) -> InferOptions {
    InferOptions { dir: dir.into(), top: top.into(), defines: Vec::new(), includes: Vec::new(), host: HostBfm::Wishbone, read_latency: None, ports: Vec::new(), name: top.into(), waivers: Vec::new() }
}

fn external(dir: &Path, top: &str, p: cosim::Profile) -> DutSpec {
    let mut d = DutSpec::external(top, dir, top).with_profile(p);
    if let scenario::DutKind::External { defines, includes, .. } = &mut d.kind {
        defines.push("CAN_WISHBONE_IF".into());
        includes.push(dir.into());
    }
    d
}

/// Pass / not pass per scenario of the main list on `dut` (Wishbone host).
fn verdicts(dut: &DutSpec) -> Vec<(String, bool)> {
    verdicts_on(dut, HostBfm::Wishbone)
}

/// Pass / not pass per scenario of the main list on `dut` through `host`.
fn verdicts_on(dut: &DutSpec, host: HostBfm) -> Vec<(String, bool)> {
    let list = scenario::load_list(root().join("tb/regression.list")).unwrap();
    let opts = RegressOptions { jobs: 2, host: Some(host), ..RegressOptions::default() };
    let r = regress(&list, std::slice::from_ref(dut), &opts);
    r.cells.iter().map(|c| (c.scenario.clone(), matches!(c.status, Status::Pass | Status::Skipped(_)))).collect()
}

/// Infers the fork top `top` through `host` and checks it against the
/// hand-written `profile`: the same port map (bus roles with their
/// polarities and the CAN-side roles), the register port's read latency,
/// and the main-list verdicts on that host: every scenario passes under the
/// inferred profile.
fn fork_against_its_profile(top: &str, profile: &str, host: HostBfm) -> profile_infer::Inference {
    let d = fork_dir(top);
    let inf = infer(&InferOptions { host, ..opts(&d, top) }).unwrap();
    assert!(inf.deviations.is_empty(), "{:?}\n{}", inf.deviations, inf.toml);
    let hand = cosim::Profile::load(root().join("tb/fixtures/fork").join(format!("{profile}.toml"))).unwrap();
    assert_eq!(inf.profile.ports, hand.ports, "{top}: inferred [ports] and [ports.<bus>] differ from {profile}.toml\n{}", inf.toml);
    let key = match host {
        HostBfm::Axi4Lite => "axi4-lite",
        HostBfm::Apb | HostBfm::Apb3 => "apb",
        HostBfm::Regport => "regport",
        _ => "motorola",
    };
    assert!(inf.toml.contains(&format!("[access.{key}]\ntakes-effect = \"can-edges\"")), "{}", inf.toml);
    assert!(inf.toml.contains(&format!("[ports.{key}]")), "{}", inf.toml);
    // The hand-written read latency is the one measured (the Motorola edge
    // counts are ranges that agree; the caller checks what it needs).
    if matches!(host, HostBfm::Regport) && hand.regport.read_latency.is_some() {
        assert_eq!(inf.profile.regport.read_latency, hand.regport.read_latency, "{top}: read-latency differs from {profile}.toml\n{}", inf.toml);
    }
    let inferred = verdicts_on(&external(&d, top, inf.profile.clone()), host);
    assert!(inferred.iter().all(|v| v.1), "{top}: the fork is our RTL behind a wrapper, correct everywhere: {inferred:?}");
    assert!(inferred.len() >= 20, "the main list ran: {inferred:?}");
    inf
}

#[test]
fn our_rtl_gets_a_profile_with_the_verdicts_of_rtl_toml() {
    let d = core_dir(None);
    let inf = infer(&opts(d.path(), "can_top")).unwrap();
    assert!(inf.deviations.is_empty(), "{:?}", inf.deviations);
    let p = &inf.profile;
    assert_eq!(p.phase_origin, cosim::PhaseOrigin::ResetModeExit);
    assert!(!p.ts_clear_in_suspend, "rtl/ keeps SR.TS through suspend transmission");
    assert_eq!(p.ports, cosim::PortMap::default(), "can_top's names and polarities");
    let cosim::AccessTiming::CanEdges { write, .. } = p.wishbone else { panic!("edge counts") };
    assert_eq!(write, 4, "can_wb_cdc writes at the 4th CAN edge (rtl.toml)");
    // Every entry carries its evidence in the file.
    for key in ["phase-origin", "sof", "status", "pins", "tx-edge", "command", "read", "ports", "ts-in-suspend"] {
        assert!(inf.evidence.iter().any(|e| e.key == key), "no evidence for {key}");
    }
    assert!(inf.toml.matches("# evidence: ").count() >= 8, "{}", inf.toml);
    let inferred = verdicts(&external(d.path(), "can_top", p.clone()));
    let shipped = verdicts(&external(d.path(), "can_top", cosim::Profile::rtl()));
    assert_eq!(inferred, shipped, "the inferred profile's verdicts differ from rtl.toml's");
}

#[test]
fn a_renamed_slower_fixture_is_found_and_passes_the_list() {
    let d = core_dir(Some("fx_renamed.v"));
    let inf = infer(&opts(d.path(), "fx_renamed")).unwrap();
    assert!(inf.deviations.is_empty(), "{:?}", inf.deviations);
    let m = &inf.profile.ports;
    assert_eq!((m.host_clock.name.as_str(), m.can_clock.name.as_str()), ("clk", "can_clk"));
    assert_eq!((m.reset.name.as_str(), m.reset.active_high), ("rst_n", false));
    assert_eq!((m.irq.name.as_str(), m.irq.active_high), ("irq", true), "irq is active high: found from its idle level");
    assert_eq!((m.bus_off.name.as_str(), m.bus_off.active_high), ("bus_off", true));
    let cosim::AccessTiming::CanEdges { write, .. } = inf.profile.wishbone else { panic!("edge counts") };
    assert_eq!(write, 5, "two host clocks (40 ns) in front of can_top's 4 edges: one CAN edge more");
    let v = verdicts(&external(d.path(), "fx_renamed", inf.profile.clone()));
    let failed: Vec<&String> = v.iter().filter(|x| !x.1).map(|x| &x.0).collect();
    assert!(failed.is_empty(), "the fixture is our RTL behind a wrapper, correct everywhere: {failed:?}");
}

#[test]
fn a_late_interrupt_is_reported_as_a_deviation_not_profiled() {
    let d = core_dir(Some("fx_late_irq.v"));
    let inf = infer(&opts(d.path(), "fx_late_irq")).unwrap();
    let dev = inf.deviations.iter().find(|d| d.freedom == "pins").unwrap_or_else(|| panic!("no pins deviation: {:?}", inf.deviations));
    assert!(dev.probe == "status" || dev.probe.starts_with("phase"), "{dev:?}");
    assert!(dev.divergence.contains("irq"), "the first divergence names the pin: {dev:?}");
    assert_eq!(inf.profile.tolerances.pin_tolerance, profile_infer::PINS_MAX, "the entry stays at its bound");
    assert!(inf.toml.contains("candidate deviation in `pins`"), "{}", inf.toml);
    // At its bound the comparator still shows the late interrupt.
    let v = verdicts(&external(d.path(), "fx_late_irq", inf.profile.clone()));
    assert!(v.iter().any(|x| !x.1), "the late interrupt is not absorbed: every scenario passed");
}

#[test]
fn an_axi4_lite_fork_gets_its_hand_written_ports_and_verdicts() {
    let inf = fork_against_its_profile("fork_axi", "axi4-lite", HostBfm::Axi4Lite);
    let Some(cosim::AccessTiming::CanEdges { write, .. }) = inf.profile.axi4lite else { panic!("edge counts in [access.axi4-lite]") };
    assert_eq!(write, 4, "can_axi4lite is can_top behind a combinational request: its 4th CAN edge");
    assert_eq!(inf.profile.wishbone, cosim::AccessTiming::AtAck, "no Wishbone port: not measured");
}

#[test]
#[ignore = "an inference and the main list, about 40 s; the AXI4-Lite and register-port forks run in the default suite; run with: cargo test --release -p profile-infer --test infer -- --ignored fork"]
fn an_apb3_fork_gets_its_hand_written_ports_and_verdicts() {
    let inf = fork_against_its_profile("fork_apb", "apb", HostBfm::Apb3);
    assert!(matches!(inf.profile.apb, Some(cosim::AccessTiming::CanEdges { write: 4, .. })), "{:?}", inf.profile.apb);
}

#[test]
fn a_register_port_fork_gets_its_read_latency_measured() {
    let inf = fork_against_its_profile("fork_regport", "regport", HostBfm::Regport);
    // Its delay line answers 8 clocks after can_regport's 14: one less and
    // the port's monitor sees the data change after the master sampled it.
    assert_eq!(inf.profile.regport.read_latency, Some(22), "{}", inf.toml);
    assert_eq!(inf.profile.regport.one_address, Some(true));
    let e = inf.evidence.iter().find(|e| e.key == "read-latency").expect("read-latency evidence");
    assert!(e.line.contains("at 21") && e.line.contains("later than its read latency of 21"), "{}", e.line);
}

#[test]
#[ignore = "an inference and the main list, about 40 s; the AXI4-Lite and register-port forks run in the default suite; run with: cargo test --release -p profile-infer --test infer -- --ignored fork"]
fn a_motorola_fork_gets_its_hand_written_ports_and_verdicts() {
    // motorola.toml counts from the edge raising E, as the reference does
    // for an external core; a write lands after E falls.
    let inf = fork_against_its_profile("fork_mcu", "motorola", HostBfm::Motorola);
    let Some(cosim::AccessTiming::CanEdges { write, command, .. }) = inf.profile.motorola.timing else { panic!("edge counts in [access.motorola]") };
    assert!(write > profile_infer::MOTOROLA_E_WRITE && command >= write, "a write is taken after E falls: {write}/{command}");
}

#[test]
fn an_axi4_lite_top_with_one_clock_runs_the_list_on_it() {
    // fork_axi with its CAN clock tied to the bus clock: one clock port.
    let d = fork_dir("one_axi");
    let v = std::fs::read_to_string(d.join("fork_axi.v")).unwrap();
    let one = v.replace("module fork_axi", "module one_axi").replace("    input  wire        can_clk,\n", "").replace(".clk_i(can_clk)", ".clk_i(S_AXI_ACLK)");
    assert!(!one.contains("can_clk"), "the fixture changed: {one}");
    std::fs::write(d.join("one_axi.v"), one).unwrap();
    let inf = infer(&InferOptions { host: HostBfm::Axi4Lite, ..opts(&d, "one_axi") }).unwrap();
    assert!(inf.deviations.is_empty(), "{:?}", inf.deviations);
    let m = &inf.profile.ports;
    assert_eq!((m.axi4lite.pin("clock").name.as_str(), m.can_clock.name.as_str()), ("S_AXI_ACLK", "S_AXI_ACLK"));
    assert!(inf.evidence.iter().any(|e| e.line.starts_with("one clock (S_AXI_ACLK)")), "{}", inf.toml);
    // The scenarios' 50 MHz host clock would drive the same port as their
    // CAN clock: the host runs on the CAN clock.
    let v = verdicts_on(&external(&d, "one_axi", inf.profile.clone()), HostBfm::Axi4Lite);
    assert!(v.iter().all(|x| x.1), "{v:?}");
}

#[test]
fn a_bus_role_missing_or_twice_names_the_port_option() {
    use cosim::bridge::PortDir::{In, Out};
    use cosim::profile::PortBus;
    use profile_infer::ports::{PortSig, find_roles};
    let apb = |extra: &[(&str, cosim::bridge::PortDir)]| -> Vec<PortSig> {
        let mut v: Vec<PortSig> = [("PCLK", In), ("PRESETn", In), ("PENABLE", In), ("PWRITE", In), ("PREADY", Out), ("PSLVERR", Out), ("CAN_CLK", In), ("CAN_RX", In), ("CAN_TX", Out), ("IRQ_N", Out), ("BUS_OFF_N", Out), ("CLKOUT", Out)]
            .iter()
            .chain(extra)
            .map(|(n, d)| PortSig::new(n, *d, 1))
            .collect();
        v.extend([PortSig::new("PADDR", In, 32), PortSig::new("PWDATA", In, 32), PortSig::new("PRDATA", Out, 32)]);
        v
    };
    let e = find_roles(&apb(&[("SEL", In)]), &Vec::new(), Some(PortBus::Apb)).unwrap_err().to_string();
    assert!(e.contains("`apb.psel`") && e.contains("--port apb.psel=NAME"), "{e}");
    let e = find_roles(&apb(&[("PSEL", In), ("apb_psel", In)]), &Vec::new(), Some(PortBus::Apb)).unwrap_err().to_string();
    assert!(e.contains("PSEL, apb_psel") && e.contains("--port apb.psel=PSEL"), "{e}");
    // The override settles both.
    let m = find_roles(&apb(&[("SEL", In)]), &vec![("apb.psel".into(), "SEL".into())], Some(PortBus::Apb)).unwrap();
    assert_eq!(m.apb.pin("psel").name, "SEL");
    let m = find_roles(&apb(&[("PSEL", In), ("apb_psel", In)]), &vec![("apb.psel".into(), "apb_psel".into())], Some(PortBus::Apb)).unwrap();
    assert_eq!(m.apb.pin("psel").name, "apb_psel");
    // The Wishbone roles are not asked for on another bus, and a bus role
    // is no role on Wishbone.
    let e = find_roles(&apb(&[("PSEL", In)]), &vec![("apb.psel".into(), "PSEL".into())], None).unwrap_err().to_string();
    assert!(e.contains("no such role"), "{e}");
}

#[test]
#[ignore = "needs the opencores core: CAN_UPSTREAM_DIR=/path/to/can/rtl/verilog cargo test --release -p profile-infer -- --ignored opencores"]
fn opencores_gets_a_profile_with_the_verdicts_of_its_shipped_one() {
    let dir = PathBuf::from(std::env::var("CAN_UPSTREAM_DIR").expect("CAN_UPSTREAM_DIR"));
    let waivers = vec![root().join("tb/waivers/opencores-upstream.toml")];
    let inf = infer(&InferOptions { name: "opencores-can".into(), waivers: waivers.clone(), ..opts(&dir, "can_top") }).unwrap();
    eprintln!("{}", inf.toml);
    assert!(inf.deviations.is_empty(), "{:?}", inf.deviations);
    assert_eq!(inf.profile.phase_origin, cosim::PhaseOrigin::HardwareReset);
    assert!(inf.profile.ts_clear_in_suspend, "D3: the core's SR.TS reads 0 in suspend transmission");
    let run = |p: cosim::Profile| {
        let mut d = external(&dir, "can_top", p);
        d.name = "opencores-can".into();
        let list = scenario::load_list(root().join("tb/regression.list")).unwrap();
        let opts = RegressOptions { jobs: 2, host: Some(HostBfm::Wishbone), waivers: waivers.clone(), ..RegressOptions::default() };
        regress(&list, &[d], &opts).cells.iter().map(|c| (c.scenario.clone(), matches!(c.status, Status::Pass | Status::Skipped(_)))).collect::<Vec<_>>()
    };
    let mut inferred = inf.profile.clone();
    inferred.name = "opencores-can".into();
    assert_eq!(run(inferred), run(cosim::Profile::find("opencores-can").unwrap()));
}
