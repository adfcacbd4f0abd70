//! The lockstep reference takes each host access at the CAN clock the DUT's
//! CAN side takes it (our RTL behind `can_wb_cdc`, the golden model as a
//! Wishbone slave), so the two run clock for clock: their tx pins never
//! differ, not even by a CAN clock around a bit edge. Before, the reference
//! took a write at the ack, left reset mode a few CAN clocks after the DUT
//! and placed its time quanta (and so every tx edge) that far apart.

use cosim::{AvalonWiring, CompareConfig, DutChoice, HostBfm, NodeConfig, PhaseOrigin, Profile, ReferenceChoice, TbConfig, Testbench};

/// PeliCAN, accept all, 600 kbit/s at 24 MHz, every interrupt enabled.
fn setup(ier: u8) -> Vec<(u8, u8)> {
    let mut v = vec![(0u8, 0x01u8), (31, 0x80)];
    for i in 0..4 {
        v.push((16 + i, 0x00));
        v.push((20 + i, 0xFF));
    }
    v.extend([(6, 0x41), (7, 0x25), (8, 0xDA), (4, ier), (0, 0x00)]);
    v
}

/// Instants (VCD times) after the reset at which the DUT's tx_o and the
/// reference's tx differ, from the VCD the bench wrote.
fn tx_mismatches(vcd: &str) -> Vec<u64> {
    let (mut id_tx, mut id_model, mut id_rst) = (String::new(), String::new(), String::new());
    for l in vcd.lines().filter(|l| l.starts_with("$var")) {
        let p: Vec<&str> = l.split_whitespace().collect();
        match p.get(4) {
            Some(&"tx_o") => id_tx = p[3].to_string(),
            Some(&"model_tx") => id_model = p[3].to_string(),
            Some(&"wb_rst_i") => id_rst = p[3].to_string(),
            _ => {}
        }
    }
    assert!(!id_tx.is_empty() && !id_model.is_empty() && !id_rst.is_empty(), "tx_o, model_tx and wb_rst_i in the VCD");
    let (mut tx, mut model, mut rst) = ('1', '1', '1');
    let mut t = 0u64;
    let mut bad = Vec::new();
    let mut check = |t: u64, tx: char, model: char, rst: char| {
        if tx != model && rst == '0' {
            bad.push(t);
        }
    };
    for l in vcd.lines() {
        if let Some(v) = l.strip_prefix('#') {
            check(t, tx, model, rst);
            t = v.parse().unwrap();
        } else if let Some(c) = l.chars().next().filter(|c| *c == '0' || *c == '1') {
            if l[1..] == id_tx {
                tx = c;
            } else if l[1..] == id_model {
                model = c;
            } else if l[1..] == id_rst {
                rst = c;
            }
        }
    }
    check(t, tx, model, rst);
    bad
}

fn run(dut: DutChoice, name: &str) {
    run_on(dut, HostBfm::Wishbone, name)
}

fn run_on(dut: DutChoice, host: HostBfm, name: &str) {
    let bad = mismatches(dut, host, name, None, PhaseOrigin::ResetModeExit);
    assert!(bad.is_empty(), "{name}: DUT and reference tx differ at {} instants: {:?} ps", bad.len(), &bad[..bad.len().min(20)]);
}

/// The instants at which DUT and reference tx differ over the run below,
/// with the DUT's `profile` (None: the bench's default for it) and, for
/// the golden model as DUT, its bit timing's phase origin.
fn mismatches(dut: DutChoice, host: HostBfm, name: &str, profile: Option<Profile>, model_origin: PhaseOrigin) -> Vec<u64> {
    let strict = CompareConfig { tx_edge_tolerance: 0, sof_tolerance: 0, ..CompareConfig::default() };
    exercise(dut, host, name, profile, model_origin, strict).0
}

/// The run below with the comparator set to `cmp`: the instants at which
/// DUT and reference tx differ, and the comparator's divergences.
fn exercise(
    dut: DutChoice,
    host: HostBfm,
    name: &str,
    profile: Option<Profile>,
    model_origin: PhaseOrigin,
    cmp: CompareConfig,
) -> (Vec<u64>, Vec<String>) {
    let (text, divergences) = exercise_text(dut, host, name, profile, model_origin, cmp);
    (tx_mismatches(&text), divergences)
}

/// [`exercise`]'s run: the VCD text and the comparator's divergences.
fn exercise_text(
    dut: DutChoice,
    host: HostBfm,
    name: &str,
    profile: Option<Profile>,
    model_origin: PhaseOrigin,
    cmp: CompareConfig,
) -> (String, Vec<String>) {
    let vcd = std::env::temp_dir().join(format!("cosim-reference-timing-{name}-{}.vcd", std::process::id()));
    let mut node = setup(0x00);
    node.push((0, 0x00));
    let mut tb = Testbench::new(TbConfig {
        scenario: "reference timing".into(),
        dut,
        host,
        nodes: vec![NodeConfig { name: "node1".into(), init: node }],
        lockstep: Some((ReferenceChoice::Model, cmp)),
        vcd: Some(vcd.clone()),
        profile,
        model_dut_phase_origin: model_origin,
        // Count every differing instant, do not stop at the first.
        collect: cosim::waivers::CollectMode::Collect,
        ..TbConfig::default()
    })
    .unwrap();
    for (a, d) in setup(0xFF) {
        tb.write(a, d).unwrap();
    }
    tb.run_bits(12).unwrap();
    // Transmission requests at many phases of the bit (a CMR.TR just before
    // a sample point starts a SOF on one side only if the two disagree on
    // when it landed), and reset-mode round trips (each restarts the bit timing) at several host-clock phases.
    for k in 0..14u64 {
        if k % 3 == 2 {
            tb.write(0, 0x01).unwrap();
            tb.run_host_cycles(k).unwrap();
            tb.write(0, 0x00).unwrap();
            tb.run_bits(12).unwrap();
        }
        for (i, b) in [0x08u8, 0x20 + k as u8, 0x40, 0xA5, 0x5A, 0x0F, 0xF0, 0x33, 0xCC].iter().enumerate() {
            tb.write(16 + i as u8, *b).unwrap();
        }
        tb.run_can_cycles(k * 3).unwrap();
        tb.write(1, 0x01).unwrap();
        tb.wait_sr(0x0C, 0x0C, 400).unwrap();
        tb.read(3).unwrap();
    }
    tb.flush().unwrap();
    let divergences: Vec<String> = tb
        .waiver_report()
        .failures
        .iter()
        .map(|d| format!("{:?} bit {:?} {:?}: expected {}, saw {}", d.kind, d.bit, d.field, d.expected, d.seen))
        .collect();
    let text = std::fs::read_to_string(&vcd).unwrap();
    if std::env::var_os("KEEP_VCD").is_none() {
        let _ = std::fs::remove_file(&vcd);
    }
    assert!(text.matches("\n0").count() > 100, "{name}: the VCD shows transmissions");
    (text, divergences)
}

#[test]
fn reference_tx_follows_the_rtl_clock_for_clock() {
    run(DutChoice::Rtl, "rtl");
}

#[test]
fn reference_tx_follows_the_model_dut_clock_for_clock() {
    run(DutChoice::Model, "model");
}

#[test]
fn reference_tx_follows_the_rtl_through_avalon_clock_for_clock() {
    let host = HostBfm::Avalon { timing: bfm::AvalonTiming::Waitrequest, wiring: AvalonWiring::Native };
    run_on(DutChoice::RtlAvalon, host, "rtl-avalon");
}

#[test]
fn reference_tx_follows_the_pio_rtl_clock_for_clock() {
    run_on(DutChoice::Bundled("can_top_pio".into()), HostBfm::Pio(bfm::PioTiming::default()), "rtl-pio");
}

#[test]
fn reference_tx_follows_the_model_dut_over_pio_clock_for_clock() {
    run_on(DutChoice::Model, HostBfm::Pio(bfm::PioTiming::default()), "model-pio");
}

/// Kit defect 1: a core whose bit timing runs from the hardware
/// reset (here the golden model as DUT, configured so) is a legal SJA1000:
/// a reference that restarts its prescaler when reset mode is left (the
/// old, only behaviour) drifts from it by up to a bit after every
/// reset-mode round trip; a profile declaring `hardware-reset` makes the
/// reference run clock for clock with it.
#[test]
fn phase_origin_hardware_reset_needs_the_profile() {
    let mut declared = Profile::rtl();
    declared.phase_origin = PhaseOrigin::HardwareReset;
    // The model as DUT takes accesses at its launch edge whatever the profile says.
    let wrong = mismatches(DutChoice::Model, HostBfm::Wishbone, "hw-origin-undeclared", None, PhaseOrigin::HardwareReset);
    assert!(wrong.len() > 20, "an undeclared hardware-reset origin must show: {} instants", wrong.len());
    let right = mismatches(DutChoice::Model, HostBfm::Wishbone, "hw-origin-declared", Some(declared), PhaseOrigin::HardwareReset);
    assert!(right.is_empty(), "declared: tx differs at {} instants: {:?}", right.len(), &right[..right.len().min(20)]);
}

/// Kit defect 2: when a host access takes effect comes from the
/// profile. Our `can_top` given as a plain bundled top has no implicit
/// profile: the reference takes each access at the ack (what every
/// external core got before), leaves reset mode CAN clocks after the DUT
/// and its tx edges land elsewhere; with rtl.toml's `can-edges` timing
/// they agree clock for clock.
#[test]
fn access_timing_comes_from_the_profile() {
    let wrong = mismatches(DutChoice::Bundled("can_top".into()), HostBfm::Wishbone, "at-ack", None, PhaseOrigin::ResetModeExit);
    assert!(!wrong.is_empty(), "accesses taken at the ack must show on tx");
    let right = mismatches(DutChoice::Bundled("can_top".into()), HostBfm::Wishbone, "rtl-profile", Some(Profile::rtl()), PhaseOrigin::ResetModeExit);
    assert!(right.is_empty(), "with rtl.toml: tx differs at {} instants: {:?}", right.len(), &right[..right.len().min(20)]);
}

/// On the real opencores core (directory in `CAN_UPSTREAM_DIR`, with
/// timescale.v), with its profile and the profile's tolerances, on
/// Wishbone and through an Avalon bridge: the comparator finds no divergence (its tx_o
/// lags the model's by 2 CAN clocks, its output pipeline, inside the
/// 4-clock tx-edge tolerance), where the bench's old assumptions (bit
/// timing restarted at reset-mode exit, accesses taken at the ack) do.
#[test]
#[ignore = "needs the third-party opencores core on disk: CAN_UPSTREAM_DIR=<dir> cargo test --release -p cosim --test suite reference_timing::upstream -- --ignored"]
fn upstream_tx_follows_with_its_profile() {
    let dir = std::path::PathBuf::from(std::env::var("CAN_UPSTREAM_DIR").expect("CAN_UPSTREAM_DIR"));
    let core = cosim::ExternalCore {
        dir: dir.clone(),
        top: "can_top".into(),
        defines: vec!["CAN_WISHBONE_IF".into()],
        include_dirs: vec![dir],
        ..cosim::ExternalCore::default()
    };
    let p = Profile::find("opencores-can").unwrap();
    let bridge = HostBfm::Avalon { timing: bfm::AvalonTiming::Waitrequest, wiring: AvalonWiring::Bridge };
    for (host, name) in [(HostBfm::Wishbone, "upstream-wb"), (bridge, "upstream-avalon")] {
        let (bad, div) = exercise(DutChoice::External(core.clone()), host, name, Some(p.clone()), PhaseOrigin::ResetModeExit, p.tolerances);
        eprintln!("{name}: tx differs at {} instants (strictly), {} divergences", bad.len(), div.len());
        assert!(div.is_empty(), "{name}: {} divergences: {:?}", div.len(), &div[..div.len().min(5)]);
        let mut old = p.clone();
        old.phase_origin = PhaseOrigin::ResetModeExit;
        old.wishbone = cosim::AccessTiming::AtAck;
        old.avalon = cosim::AccessTiming::AtAck;
        let (_, div) = exercise(DutChoice::External(core.clone()), host, name, Some(old), PhaseOrigin::ResetModeExit, p.tolerances);
        assert!(!div.is_empty(), "{name}: the old assumptions must diverge");
    }
}

/// The times (ps) of the edges of `tx_o` and of `model_tx` after the reset
/// is released, from the VCD the bench wrote.
fn tx_edges(vcd: &str) -> (Vec<u64>, Vec<u64>) {
    let (mut id_tx, mut id_model, mut id_rst) = (String::new(), String::new(), String::new());
    for l in vcd.lines().filter(|l| l.starts_with("$var")) {
        let p: Vec<&str> = l.split_whitespace().collect();
        match p.get(4) {
            Some(&"tx_o") => id_tx = p[3].to_string(),
            Some(&"model_tx") => id_model = p[3].to_string(),
            Some(&"wb_rst_i") => id_rst = p[3].to_string(),
            _ => {}
        }
    }
    let (mut t, mut rst) = (0u64, '1');
    let (mut tx, mut model) = ('1', '1');
    let (mut dut_edges, mut model_edges) = (Vec::new(), Vec::new());
    for l in vcd.lines() {
        if let Some(v) = l.strip_prefix('#') {
            t = v.parse().unwrap();
        } else if let Some(c) = l.chars().next().filter(|c| *c == '0' || *c == '1') {
            let id = &l[1..];
            if id == id_rst {
                rst = c;
            } else if id == id_tx && c != tx {
                tx = c;
                if rst == '0' {
                    dut_edges.push(t);
                }
            } else if id == id_model && c != model {
                model = c;
                if rst == '0' {
                    model_edges.push(t);
                }
            }
        }
    }
    (dut_edges, model_edges)
}

/// The measured alignment of the opencores core with the reference (its
/// directory in `CAN_UPSTREAM_DIR`): with its profile, every tx_o edge is
/// the model's 2 CAN clocks later (the core's tx register after its
/// tx_point register), from the first frame after the hardware reset on,
/// and no transmission starts a bit apart, although the run loads the TX
/// buffer and writes CMR.TR back to back (the core's hold-off after an ack
/// delays that TR by 5-6 CAN clocks) at 14 phases of the bit. Without
/// `busy-after-ack` or with the model's bit timing starting in its sync
/// segment after the reset, SOFs land a bit apart.
#[test]
#[ignore = "needs the third-party opencores core on disk: CAN_UPSTREAM_DIR=<dir> cargo test --release -p cosim --test suite reference_timing::upstream -- --ignored"]
fn upstream_tx_is_the_model_tx_two_can_clocks_later() {
    let dir = std::path::PathBuf::from(std::env::var("CAN_UPSTREAM_DIR").expect("CAN_UPSTREAM_DIR"));
    let core = cosim::ExternalCore {
        dir: dir.clone(),
        top: "can_top".into(),
        defines: vec!["CAN_WISHBONE_IF".into()],
        include_dirs: vec![dir],
        ..cosim::ExternalCore::default()
    };
    let p = Profile::find("opencores-can").unwrap();
    let can_period_ps = 1e12 / 24e6;
    let lag = |name: &str, profile: Profile| -> Vec<(u64, f64)> {
        let cmp = profile.tolerances;
        let (text, _) = exercise_text(DutChoice::External(core.clone()), HostBfm::Wishbone, name, Some(profile), PhaseOrigin::ResetModeExit, cmp);
        let (dut, model) = tx_edges(&text);
        assert!(dut.len() > 100, "{name}: transmissions seen");
        // Each DUT edge against the model edge nearest to it.
        dut.iter()
            .filter_map(|&d| {
                let m = *model.iter().min_by_key(|&&m| m.abs_diff(d))?;
                let clocks = (d as f64 - m as f64) / can_period_ps;
                ((clocks - 2.0).abs() > 0.01).then_some((d, clocks))
            })
            .collect()
    };
    let off = lag("upstream-lag", p.clone());
    assert!(off.is_empty(), "tx_o edges not 2 CAN clocks after the model's: {} e.g. {:?}", off.len(), &off[..off.len().min(8)]);
    let mut no_holdoff = p.clone();
    no_holdoff.holdoff.wishbone = None;
    let off = lag("upstream-no-holdoff", no_holdoff);
    assert!(!off.is_empty(), "without busy-after-ack a back-to-back TR must land a bit apart");
}

