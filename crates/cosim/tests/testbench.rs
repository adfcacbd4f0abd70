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
        let d = diagnose::diagnose(&rec);
        let text = d.to_text();
        assert!(
            text.contains("0x04") || text.to_lowercase().contains("ack"),
            "{name}: the diagnoser explains it: {text}"
        );
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
