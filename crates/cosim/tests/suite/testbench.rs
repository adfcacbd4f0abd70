//! The test bench on the bundled fixtures: every BFM, the monitors, the
//! timeouts, the lockstep comparator and the VCD.

use bfm::{AvalonTiming, PioTiming};
use cosim::{
    AvalonWiring, CompareConfig, DutChoice, HostBfm, ReferenceChoice, TbConfig, TbError, Testbench,
};
use diagnose::{DivergenceKind, RxWiring};

fn cfg(dut: &str, host: HostBfm) -> TbConfig {
    TbConfig {
        scenario: "fixture".into(),
        dut: DutChoice::Bundled(dut.into()),
        host,
        ..TbConfig::default()
    }
}

fn all_bfms() -> Vec<(&'static str, HostBfm)> {
    vec![
        ("wishbone", HostBfm::Wishbone),
        (
            "avalon-bridge",
            HostBfm::Avalon {
                timing: AvalonTiming::Waitrequest,
                wiring: AvalonWiring::Bridge,
            },
        ),
        ("pio", HostBfm::Pio(PioTiming::default())),
    ]
}

#[test]
fn every_bfm_writes_and_reads_the_echo_fixture_without_violations() {
    for (name, host) in all_bfms() {
        let mut tb = Testbench::new(cfg("cosim_echo", host)).unwrap();
        for (a, d) in [(5u8, 0xA5u8), (6, 0x5A), (17, 0xFF)] {
            tb.write(a, d).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        for (a, d) in [(5u8, 0xA5u8), (6, 0x5A), (17, 0xFF)] {
            assert_eq!(tb.read(a).unwrap(), d, "{name}: read back address {a}");
        }
        if name == "pio" {
            // A bit-banged master holds stb for many cycles: the fixture's
            // one-cycle ack ends the transfer and the held stb starts
            // another, which the CPU then abandons by clearing the control
            // PIO. The monitor reports exactly that, and nothing else.
            assert!(
                tb.violations()
                    .iter()
                    .all(|v| v.rule == "wb.cyc_dropped_before_ack"
                        || v.rule == "wb.ack_without_request"),
                "{:?}",
                tb.violations()
            );
        } else {
            assert!(tb.violations().is_empty(), "{name}: {:?}", tb.violations());
        }
        // tx follows register 0 bit 0; with tx on the bus, rx (address 31) follows it.
        tb.write(0, 0x00).unwrap();
        tb.run_can_cycles(4).unwrap();
        assert!(!tb.pins().tx, "{name}: tx dominant");
        assert_eq!(tb.read(31).unwrap(), 0, "{name}: rx sees the dominant bus");
        tb.write(0, 0x01).unwrap();
        tb.run_can_cycles(4).unwrap();
        assert_eq!(tb.read(31).unwrap(), 1, "{name}: rx back to recessive");
        // irq_on and bus_off_on follow register 1.
        tb.write(1, 0x03).unwrap();
        tb.run_host_cycles(2).unwrap();
        let p = tb.pins();
        assert!(!p.irq_n && !p.bus_on, "{name}: {p:?}");
        let rec = tb.record();
        assert!(rec.host_ops.len() >= 10, "{name}: ops recorded");
        assert!(
            rec.host_ops
                .iter()
                .all(|o| o.cycles > 0 && o.error.is_none())
        );
    }
}

#[test]
fn host_cycles_per_register_access_for_each_bfm() {
    let mut line = Vec::new();
    for (name, host) in all_bfms() {
        let mut tb = Testbench::new(cfg("cosim_echo", host)).unwrap();
        let c0 = tb.host_cycles();
        for k in 0..8u8 {
            tb.write(k + 2, k).unwrap();
            tb.read(k + 2).unwrap();
        }
        let per = (tb.host_cycles() - c0) as f64 / 16.0;
        line.push(format!("{name} {per:.1}"));
        match name {
            "wishbone" => assert!((2.0..=4.0).contains(&per), "wishbone {per}"),
            "avalon-bridge" => assert!((2.0..=5.0).contains(&per), "avalon {per}"),
            _ => assert!(
                per > 15.0,
                "PIO bit-banging costs many GPIO accesses: {per}"
            ),
        }
    }
    println!(
        "host cycles per register access (echo fixture, 1-cycle registered ack): {}",
        line.join(", ")
    );
}

#[test]
fn thesis_avalon_wiring_is_caught_by_the_wishbone_monitor() {
    let host = HostBfm::Avalon {
        timing: AvalonTiming::FixedWaitStates { read: 1, write: 1 },
        wiring: AvalonWiring::Seed000,
    };
    let mut tb = Testbench::new(cfg("cosim_echo", host)).unwrap();
    let _ = tb.write(5, 0x11);
    let v = tb.violations();
    assert!(
        !v.is_empty(),
        "seed 000 wiring drops cyc after the first cycle"
    );
    assert!(v.iter().any(|v| v.rule.starts_with("wb.")), "{v:?}");
}

#[test]
fn acks_without_request_are_flagged_with_their_cycle() {
    let mut tb = Testbench::new(cfg("cosim_badwb", HostBfm::Wishbone)).unwrap();
    tb.run_host_cycles(40).unwrap();
    let v: Vec<_> = tb
        .violations()
        .iter()
        .filter(|v| v.rule == "wb.ack_without_request")
        .cloned()
        .collect();
    assert!(v.len() >= 2, "{:?}", tb.violations());
    // The fixture's counter acks every 16 cycles: consecutive reports 16 apart.
    assert_eq!(v[1].cycle - v[0].cycle, 16, "{v:?}");
    // And the clean fixture produces none over the same time.
    let mut ok = Testbench::new(cfg("cosim_echo", HostBfm::Wishbone)).unwrap();
    ok.run_host_cycles(40).unwrap();
    assert!(ok.violations().is_empty());
}

#[test]
fn a_slave_that_never_acks_times_out_with_a_diagnosis() {
    for (name, host) in all_bfms() {
        let mut c = cfg("cosim_noack", host);
        c.op_timeout_cycles = 200;
        c.monitor_ack_timeout = 100;
        let mut tb = Testbench::new(c).unwrap();
        let t0 = std::time::Instant::now();
        let e = tb.write(4, 0x12).unwrap_err();
        assert!(t0.elapsed().as_secs() < 5, "{name}: no hang");
        let msg = e.to_string();
        assert!(matches!(e, TbError::Host { .. }), "{name}: {msg}");
        assert!(msg.contains("0x04"), "{name}: {msg}");
        if name == "wishbone" {
            assert!(
                msg.contains("no ack") || msg.contains("wb_ack_o"),
                "monitor's view included: {msg}"
            );
        }
        let rec = tb.record();
        assert!(rec.error.is_some() && rec.host_ops.last().unwrap().error.is_some());
        assert_eq!(rec.host_ops.last().unwrap().acks_seen, 0, "{name}: the DUT never answered");
        let d = diagnose::diagnose(&rec);
        let text = d.to_text();
        assert!(
            text.contains("0x04") || text.to_lowercase().contains("ack"),
            "{name}: the diagnoser explains it: {text}"
        );
        // Never answered is not the PIO "missed one-cycle pulse" story.
        assert!(!text.contains("missed between two polls"), "{name}: {text}");
    }
}

fn lockstep(dut: &str) -> Testbench {
    let mut c = cfg(dut, HostBfm::Wishbone);
    c.lockstep = Some((
        ReferenceChoice::Echo,
        CompareConfig {
            tx_edge_tolerance: 2,
            ..CompareConfig::default()
        },
    ));
    Testbench::new(c).unwrap()
}

#[test]
fn lockstep_fixture_against_its_rust_twin_agrees() {
    let mut tb = lockstep("cosim_echo");
    for k in 0..8u8 {
        tb.write(k + 2, 0xF0 | k).unwrap();
        assert_eq!(tb.read(k + 2).unwrap(), 0xF0 | k);
    }
    // Drive tx dominant for a while and back, and run bits.
    tb.write(0, 0x00).unwrap();
    tb.run_bits(5).unwrap();
    tb.write(0, 0x01).unwrap();
    tb.run_bits(5).unwrap();
    tb.write(1, 0x01).unwrap();
    tb.run_bits(2).unwrap();
    let c = tb.comparator().unwrap();
    assert!(c.divergence().is_none());
    assert!(c.compared_bits >= 10, "{}", c.compared_bits);
    assert_eq!(c.compared_reads, 8);
    let rec = tb.record();
    assert!(rec.divergence.is_none());
    assert!(rec.bus_bits.iter().any(|b| !b.bus) && rec.bus_bits.iter().any(|b| b.bus));
}

#[test]
fn comparator_finds_the_deviant_fixtures_register_and_tx_divergences() {
    // Register: bit 7 of address 4 stuck at 0.
    let mut tb = lockstep("cosim_deviant");
    tb.write(4, 0xFF).unwrap();
    let e = tb.read(4).unwrap_err();
    assert!(matches!(e, TbError::Diverged(_)), "{e}");
    let d = tb.record().divergence.unwrap();
    assert_eq!(
        (d.kind, d.expected, d.seen),
        (DivergenceKind::RegisterRead, 0xFF, 0x7F)
    );
    assert!(
        tb.write(3, 0).is_err(),
        "the run stops at the first divergence"
    );
    // tx: stuck recessive while the reference drives dominant.
    let mut tb = lockstep("cosim_deviant");
    tb.run_bits(3).unwrap();
    tb.write(0, 0x00).unwrap();
    let e = tb.run_bits(3).unwrap_err();
    assert!(matches!(e, TbError::Diverged(_)));
    let rec = tb.record();
    let d = rec.divergence.as_ref().unwrap();
    assert_eq!((d.kind, d.expected, d.seen), (DivergenceKind::TxBit, 0, 1));
    assert!(d.context.contains("tolerances"), "{}", d.context);
    let last = rec.bus_bits.last().unwrap();
    assert!(
        last.dut_tx && !last.model_tx,
        "context bits end at the divergence: {last:?}"
    );
    assert!(rec.bus_bits.len() >= 3);
}

#[test]
fn disconnected_rx_is_tied_and_tx_can_stay_off_the_bus() {
    let mut c = cfg("cosim_echo", HostBfm::Wishbone);
    c.rx = RxWiring::TiedRecessive;
    let mut tb = Testbench::new(c).unwrap();
    tb.write(0, 0x00).unwrap();
    tb.run_can_cycles(4).unwrap();
    assert!(!tb.pins().tx);
    assert_eq!(
        tb.read(31).unwrap(),
        1,
        "rx tied recessive whatever tx does (the thesis wiring)"
    );
    let mut c = cfg("cosim_echo", HostBfm::Wishbone);
    c.tx_on_bus = false;
    let mut tb = Testbench::new(c).unwrap();
    tb.write(0, 0x00).unwrap();
    tb.run_can_cycles(4).unwrap();
    assert_eq!(tb.read(31).unwrap(), 1, "tx not looped to rx");
    let mut c = cfg("cosim_echo", HostBfm::Wishbone);
    c.dut_rx_faults.push(Box::new(sja1000::StuckAt::forever(
        false,
        sja1000::Target::All,
    )));
    let mut tb = Testbench::new(c).unwrap();
    tb.run_can_cycles(4).unwrap();
    assert_eq!(
        tb.read(31).unwrap(),
        0,
        "stuck-dominant fault on the DUT's receiver"
    );
}

#[test]
fn vcd_has_ports_bus_and_fields_and_verilator_trace_works() {
    let dir = std::env::temp_dir().join(format!("cosim-vcd-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut c = cfg("cosim_echo", HostBfm::Wishbone);
    c.vcd = Some(dir.join("tb.vcd"));
    c.dut_trace = Some(dir.join("dut.vcd"));
    c.lockstep = Some((ReferenceChoice::Echo, CompareConfig::default()));
    let mut tb = Testbench::new(c).unwrap();
    tb.write(0, 0x00).unwrap();
    tb.run_bits(2).unwrap();
    tb.flush().unwrap();
    drop(tb);
    let ours = std::fs::read_to_string(dir.join("tb.vcd")).unwrap();
    for sig in [
        "wb_cyc_i",
        "tx_o",
        "bus",
        "model_tx",
        "sample_point",
        "field",
    ] {
        assert!(ours.contains(sig), "{sig} in our VCD");
    }
    let theirs = std::fs::read_to_string(dir.join("dut.vcd")).unwrap();
    assert!(
        theirs.contains("mem") || theirs.contains("rx_q"),
        "Verilator traced the internals"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The deviant fixture's two deviations (address 4 bit 7 stuck at 0; tx
/// stuck recessive) against its Rust twin, with 0, 1 and 2 waivers.
const DEVIANT_WAIVERS: &str = r#"
[[waiver]]
id = "reg4-bit7"
kind = "register-read"
register = "address 4"
address = 4
bits = [7]
seen = [0x7F]
dut = ["cosim_deviant"]
explanation = "bit 7 of address 4 is not implemented in this fixture, on purpose"
resync = ["adopt-dut-register"]

[[waiver]]
id = "tx-stuck-recessive"
kind = "tx-bit"
expected = [0]
seen = [1]
dut = ["cosim_deviant"]
explanation = "tx_o is stuck recessive in this fixture, on purpose (the DE2 thesis symptom)"
resync = ["none"]

[[waiver]]
id = "never-matches"
kind = "irq"
dut = ["cosim_deviant"]
explanation = "an irq deviation this fixture does not have: must come out stale"
resync = ["none"]
"#;

fn deviant_with(ids: &[&str], collect: waivers::CollectMode) -> Testbench {
    let all = waivers::WaiverSet::parse(DEVIANT_WAIVERS, "deviant.toml").unwrap();
    let mut set = waivers::WaiverSet::empty();
    for w in ids {
        let one = DEVIANT_WAIVERS
            .split("[[waiver]]")
            .find(|t| t.contains(&format!("id = \"{w}\"")))
            .unwrap();
        set.merge(waivers::WaiverSet::parse(&format!("[[waiver]]{one}"), "deviant.toml").unwrap())
            .unwrap();
    }
    assert!(all.waivers().len() >= ids.len());
    let mut c = cfg("cosim_deviant", HostBfm::Wishbone);
    c.lockstep = Some((
        ReferenceChoice::Echo,
        CompareConfig {
            tx_edge_tolerance: 2,
            ..CompareConfig::default()
        },
    ));
    c.waivers = set;
    c.collect = collect;
    Testbench::new(c).unwrap()
}

/// Register deviation first, then tx; Ok if the sequence ran to the end.
fn deviant_sequence(tb: &mut Testbench) -> Result<(), TbError> {
    tb.write(4, 0xFF)?;
    assert_eq!(tb.read(4)?, 0x7F);
    tb.run_bits(3)?;
    tb.write(0, 0x00)?;
    tb.run_bits(4)?;
    tb.write(0, 0x01)?;
    tb.run_bits(3)?;
    assert_eq!(
        tb.read(4)?,
        0x7F,
        "the model adopted 0x7F: no new divergence"
    );
    Ok(())
}

#[test]
fn waivers_let_the_deviant_fixture_run_past_its_deviations() {
    use waivers::CollectMode::*;
    // No waiver: stops at the register read.
    let mut tb = deviant_with(&[], StopAtFirst);
    assert!(matches!(
        deviant_sequence(&mut tb),
        Err(TbError::Diverged(_))
    ));
    let r = tb.waiver_report();
    assert_eq!((r.failures.len(), r.waived.len()), (1, 0));
    assert_eq!(r.failures[0].kind, DivergenceKind::RegisterRead);
    // One waiver: stops at the tx bit.
    let mut tb = deviant_with(&["reg4-bit7"], StopAtFirst);
    assert!(matches!(
        deviant_sequence(&mut tb),
        Err(TbError::Diverged(_))
    ));
    let r = tb.waiver_report();
    assert_eq!((r.failures.len(), r.waived.len()), (1, 1));
    assert_eq!(r.failures[0].kind, DivergenceKind::TxBit);
    assert_eq!(
        tb.record().divergence.as_ref().unwrap().kind,
        DivergenceKind::TxBit,
        "the record keeps the first unwaived"
    );
    // Both: completes; both listed as waived, the third waiver is stale.
    let mut tb = deviant_with(
        &["reg4-bit7", "tx-stuck-recessive", "never-matches"],
        StopAtFirst,
    );
    deviant_sequence(&mut tb).unwrap();
    let r = tb.waiver_report();
    assert!(r.passed(), "{}", r.to_text());
    assert_eq!(r.waived[0].waiver_id, "reg4-bit7");
    assert!(
        r.waived.len() >= 3
            && r.waived[1..]
                .iter()
                .all(|w| w.waiver_id == "tx-stuck-recessive"),
        "{}",
        r.to_text()
    );
    assert_eq!(r.stale.len(), 1);
    assert!(r.to_text().contains("WARNING stale waiver `never-matches`"));
    assert!(tb.record().divergence.is_none());
    // Collect mode without waivers: both deviations, each once: the lasting
    // tx one, and the register one; after the listed read the reference
    // adopts the DUT's value, so the second read of the
    // same state agrees: no repeat, no second listing.
    let mut tb = deviant_with(&[], Collect);
    deviant_sequence(&mut tb).unwrap_or_else(|e| panic!("collect mode does not stop: {e}"));
    let r = tb.waiver_report();
    let kinds: Vec<DivergenceKind> = r.failures.iter().map(|d| d.kind).collect();
    assert_eq!(
        kinds,
        [DivergenceKind::RegisterRead, DivergenceKind::TxBit],
        "{}",
        r.to_text()
    );
    assert_eq!(tb.comparator().unwrap().repeated, 0, "the second read of address 4 agrees after the adoption");
    assert!(
        !r.notes.iter().any(|n| n.contains("read of address 4")),
        "{}",
        r.to_text()
    );
    assert!(!r.passed());
}

/// A waiver asks the reference to adopt the DUT's TEC; the echo twin has no
/// error counters, so the report must say the resync was not applied.
#[test]
fn a_resync_the_reference_cannot_apply_is_reported_not_hidden() {
    let set = waivers::WaiverSet::parse(
        r#"
[[waiver]]
id = "tx-stuck-recessive"
kind = "tx-bit"
expected = [0]
seen = [1]
dut = ["cosim_deviant"]
dut-tec = [8]
explanation = "tx_o stuck recessive; pretend the DUT counted one error"
resync = ["adopt-dut-tec"]
"#,
        "adopt.toml",
    )
    .unwrap();
    let mut c = cfg("cosim_deviant", HostBfm::Wishbone);
    c.lockstep = Some((
        ReferenceChoice::Echo,
        CompareConfig {
            tx_edge_tolerance: 2,
            ..CompareConfig::default()
        },
    ));
    c.waivers = set;
    c.dut_revision = Some("r1".into());
    let mut tb = Testbench::new(c).unwrap();
    tb.write(0, 0x00).unwrap();
    tb.run_bits(4).unwrap();
    tb.write(0, 0x01).unwrap();
    tb.run_bits(2).unwrap();
    let r = tb.waiver_report();
    assert!(r.passed(), "{}", r.to_text());
    assert!(!r.waived.is_empty());
    assert_eq!(r.revision.as_deref(), Some("r1"));
    assert!(
        r.notes
            .iter()
            .any(|n| n.contains("AdoptTec(Some(8)) could not be applied")),
        "{}",
        r.to_text()
    );
    assert!(r.to_text().contains("could not be applied"));
    // Without a measured value the TEC is to be taken at the next TXERR
    // read; none came, so the report says it is still pending.
    let set = waivers::WaiverSet::parse(
        r#"
[[waiver]]
id = "tx-stuck-recessive"
kind = "tx-bit"
seen = [1]
dut = ["cosim_deviant"]
explanation = "tx_o stuck recessive"
resync = ["adopt-dut-tec"]
"#,
        "adopt.toml",
    )
    .unwrap();
    let mut c = cfg("cosim_deviant", HostBfm::Wishbone);
    c.lockstep = Some((ReferenceChoice::Echo, CompareConfig::default()));
    c.waivers = set;
    let mut tb = Testbench::new(c).unwrap();
    let r = tb.waiver_report();
    assert!(r.notes.is_empty(), "no divergence yet: {:?}", r.notes);
    tb.write(0, 0x00).unwrap();
    tb.run_bits(4).unwrap();
    let r = tb.waiver_report();
    assert!(!r.waived.is_empty(), "{}", r.to_text());
    assert!(
        r.notes.iter().any(|n| n.contains("TXERR not applied yet")),
        "{}",
        r.to_text()
    );
}

/// A scenario expectation that fails on a read whose divergence a
/// waiver covered counts as waived and is listed, never passed silently; an
/// expectation the model would have missed too, or one on a read that did
/// not diverge, still fails.
#[test]
fn an_expectation_failed_on_a_waived_read_is_listed_as_waived() {
    use waivers::CollectMode::*;
    let mut tb = deviant_with(&["reg4-bit7"], StopAtFirst);
    tb.write(4, 0xFF).unwrap();
    // DUT 0x7F, model 0xFF: the read is waived, and so is the expectation.
    assert!(tb.expect(1, "address 4 all ones", 4, 0xFF, 0xFF).unwrap());
    // The model adopted 0x7F: no divergence now, so a miss is a miss.
    assert!(!tb.expect(2, "address 4 bit 7", 4, 0x80, 0x80).unwrap());
    // Diverging again (model 0xFF), but the model misses this one too.
    tb.write(4, 0xFF).unwrap();
    assert!(!tb.expect(3, "address 4 bit 0 clear", 4, 0x01, 0x00).unwrap());
    let r = tb.waiver_report();
    assert!(r.passed(), "{}", r.to_text());
    assert_eq!(r.waived_expectations.len(), 1, "{}", r.to_text());
    let e = &r.waived_expectations[0];
    assert_eq!((e.step, e.seen, e.model, e.waiver_id.as_str()), (1, 0x7F, 0xFF, "reg4-bit7"));
    assert!(r.to_text().contains("WAIVED [reg4-bit7] expectation of step 1"));
    let exp = &tb.record().expectations;
    assert!(exp[0].passed && exp[0].seen.contains("waived by reg4-bit7"), "{exp:?}");
    assert!(!exp[1].passed && !exp[2].passed, "{exp:?}");
    // Without the waiver the read itself stops the run.
    let mut tb = deviant_with(&[], StopAtFirst);
    tb.write(4, 0xFF).unwrap();
    assert!(matches!(tb.expect(1, "address 4 all ones", 4, 0xFF, 0xFF), Err(TbError::Diverged(_))));
    assert!(tb.waiver_report().waived_expectations.is_empty());
}

/// A core whose top differs from can_top's in port names and polarities
/// (tb/fixtures/cosim_echo_ports.v: active-low reset, active-high irq and
/// bus-off) is co-simulated through its profile's port map, no wrapper:
/// without the map binding fails naming the missing port; with it the
/// fixture agrees with the echo twin, interrupts and bus-off included;
/// names right but polarities wrong, the comparator flags the irq pin.
#[test]
fn a_profile_port_map_binds_a_renamed_and_inverted_top() {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tb/fixtures/cosim_echo_ports.toml");
    let p = cosim::Profile::load(&file).unwrap();
    let e = Testbench::new(cfg("cosim_echo_ports", HostBfm::Wishbone)).err().expect("can_top names do not bind");
    assert!(e.to_string().contains("wb_clk_i"), "{e}");
    let run = |profile: cosim::Profile| {
        let mut c = cfg("cosim_echo_ports", HostBfm::Wishbone);
        c.lockstep = Some((ReferenceChoice::Echo, profile.tolerances));
        c.profile = Some(profile);
        let mut tb = Testbench::new(c).unwrap();
        let mut seen = Vec::new();
        let steps: [(u8, u8); 5] = [(2, 0x5A), (0, 0x00), (1, 0x01), (1, 0x02), (1, 0x00)];
        for (a, d) in steps {
            tb.write(a, d)?;
            tb.run_bits(3)?;
            seen.push((tb.pins().irq_n, tb.pins().bus_on));
        }
        assert_eq!(tb.read(2)?, 0x5A);
        Ok::<_, TbError>(seen)
    };
    let seen = run(p.clone()).unwrap();
    // (irq_n, bus_on) after each write: irq pending only after (1, 0x01), bus-off only after (1, 0x02).
    assert_eq!(seen, vec![(true, true), (true, true), (false, true), (true, false), (true, true)]);
    let mut wrong = p.clone();
    wrong.ports.irq.active_high = false;
    let e = run(wrong).unwrap_err();
    assert!(matches!(e, TbError::Diverged(ref m) if m.contains("Irq")), "{e}");
}

/// A waiver's `consequences`: a listed expectation that fails on a read
/// where DUT and model agree is waived (and listed) only after the waiver
/// was hit in this run; before the hit, or unlisted, it still fails.
#[test]
fn a_listed_consequence_is_waived_only_after_its_waiver_was_hit() {
    use waivers::CollectMode::*;
    let one = DEVIANT_WAIVERS.split("[[waiver]]").find(|t| t.contains("id = \"reg4-bit7\"")).unwrap();
    let src = format!("[[waiver]]{}\nconsequences = [\"fixture:step 2\"]\n", one.trim_end());
    let tb_with = || {
        let mut c = cfg("cosim_deviant", HostBfm::Wishbone);
        c.lockstep = Some((ReferenceChoice::Echo, CompareConfig { tx_edge_tolerance: 2, ..CompareConfig::default() }));
        c.waivers = waivers::WaiverSet::parse(&src, "deviant.toml").unwrap();
        c.collect = StopAtFirst;
        Testbench::new(c).unwrap()
    };
    // Before any hit: DUT and model agree on 0x7F, the listed step 2 fails.
    let mut tb = tb_with();
    tb.write(4, 0x7F).unwrap();
    assert!(!tb.expect(2, "address 4 bit 7", 4, 0x80, 0x80).unwrap());
    assert!(tb.waiver_report().waived_expectations.is_empty());
    // After the hit (step 1, model adopts 0x7F): step 2 is waived as a
    // consequence; step 3, the same read unlisted, still fails.
    let mut tb = tb_with();
    tb.write(4, 0xFF).unwrap();
    assert!(tb.expect(1, "address 4 all ones", 4, 0xFF, 0xFF).unwrap());
    assert!(tb.expect(2, "address 4 bit 7", 4, 0x80, 0x80).unwrap());
    assert!(!tb.expect(3, "address 4 bit 7 again", 4, 0x80, 0x80).unwrap());
    let r = tb.waiver_report();
    assert_eq!(r.waived_expectations.len(), 2, "{}", r.to_text());
    let e = &r.waived_expectations[1];
    assert!(e.consequence && e.step == 2 && e.seen == 0x00 && e.model == 0x00 && e.waiver_id == "reg4-bit7", "{e:?}");
    assert!(r.to_text().contains("a listed consequence of waiver reg4-bit7"), "{}", r.to_text());
    let exp = &tb.record().expectations;
    assert!(exp[1].passed && exp[1].seen.contains("a consequence of reg4-bit7"), "{exp:?}");
    assert!(!exp[2].passed, "{exp:?}");
}

/// A listed consequence may also be a
/// read that itself diverged (waived) where the model misses the
/// expectation too, as when a waived deviation ends the host's wait early
/// and its reads land where the scenario did not mean them. Waived only when
/// listed and when the waiver was hit BEFORE that read; unlisted, or with
/// the read as the first hit, it still fails.
#[test]
fn a_listed_consequence_on_a_waived_read_the_model_also_misses_is_waived() {
    use waivers::CollectMode::*;
    let one = DEVIANT_WAIVERS.split("[[waiver]]").find(|t| t.contains("id = \"reg4-bit7\"")).unwrap();
    let src = format!("[[waiver]]{}\nconsequences = [\"fixture:step 2\"]\n", one.trim_end());
    let tb_with = || {
        let mut c = cfg("cosim_deviant", HostBfm::Wishbone);
        c.lockstep = Some((ReferenceChoice::Echo, CompareConfig { tx_edge_tolerance: 2, ..CompareConfig::default() }));
        c.waivers = waivers::WaiverSet::parse(&src, "deviant.toml").unwrap();
        c.collect = StopAtFirst;
        Testbench::new(c).unwrap()
    };
    // DUT 0x7F, model 0xFF: expected 0x00 under mask 0x81, both miss.
    // The read is the waiver's first hit: the listed step 2 still fails.
    let mut tb = tb_with();
    tb.write(4, 0xFF).unwrap();
    assert!(!tb.expect(2, "address 4 bits 7, 0 clear", 4, 0x81, 0x00).unwrap());
    assert!(tb.waiver_report().waived_expectations.is_empty(), "{}", tb.waiver_report().to_text());
    // Hit before (step 1): step 2, diverging again, is a consequence; step
    // 3, the same read unlisted, still fails.
    let mut tb = tb_with();
    tb.write(4, 0xFF).unwrap();
    assert!(tb.expect(1, "address 4 all ones", 4, 0xFF, 0xFF).unwrap());
    tb.write(4, 0xFF).unwrap();
    assert!(tb.expect(2, "address 4 bits 7, 0 clear", 4, 0x81, 0x00).unwrap());
    tb.write(4, 0xFF).unwrap();
    assert!(!tb.expect(3, "address 4 bits 7, 0 clear again", 4, 0x81, 0x00).unwrap());
    let r = tb.waiver_report();
    assert!(r.passed(), "{}", r.to_text());
    assert_eq!(r.waived_expectations.len(), 2, "{}", r.to_text());
    let e = &r.waived_expectations[1];
    assert!(e.consequence && e.step == 2 && e.seen == 0x01 && e.model == 0x81 && e.waiver_id == "reg4-bit7", "{e:?}");
    let exp = &tb.record().expectations;
    assert!(exp[1].passed && exp[1].seen.contains("a consequence of reg4-bit7"), "{exp:?}");
    assert!(!exp[2].passed, "{exp:?}");
}
