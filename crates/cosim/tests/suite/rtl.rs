//! The test bench on our RTL (`can_top`, `can_avalon`) and on the golden
//! model as a DUT: every BFM drives it, and a lockstep run against the model
//! transmits a frame to a model node.

use bfm::{AvalonTiming, PioTiming};
use cosim::{
    AvalonWiring, CompareConfig, DutChoice, HostBfm, NodeConfig, ReferenceChoice, TbConfig,
    Testbench,
};

/// BasicCAN setup as the thesis does it (seed 000): reset mode, acceptance
/// all, 600 kbit/s at 24 MHz (BTR0 0x41, BTR1 0x25), OCR normal mode.
const SETUP: [(u8, u8); 6] = [
    (0, 0x01),
    (4, 0x00),
    (5, 0xFF),
    (6, 0x41),
    (7, 0x25),
    (8, 0x1A),
];

fn node() -> NodeConfig {
    let mut init = SETUP.to_vec();
    init.push((0, 0x00));
    NodeConfig {
        name: "node1".into(),
        init,
    }
}

fn cfg(dut: DutChoice, host: HostBfm) -> TbConfig {
    TbConfig {
        scenario: "rtl".into(),
        dut,
        host,
        ..TbConfig::default()
    }
}

fn bfms() -> Vec<(&'static str, DutChoice, HostBfm)> {
    vec![
        ("wishbone", DutChoice::Rtl, HostBfm::Wishbone),
        (
            "avalon-bridge",
            DutChoice::Rtl,
            HostBfm::Avalon {
                timing: AvalonTiming::Waitrequest,
                wiring: AvalonWiring::Bridge,
            },
        ),
        (
            "avalon-native",
            DutChoice::RtlAvalon,
            HostBfm::Avalon {
                timing: AvalonTiming::Waitrequest,
                wiring: AvalonWiring::Native,
            },
        ),
    ]
}

#[test]
fn every_bfm_configures_the_rtl_in_reset_mode_and_reads_it_back() {
    let mut figures = Vec::new();
    for (name, dut, host) in bfms() {
        let mut tb = Testbench::new(cfg(dut, host)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let c0 = tb.host_cycles();
        for &(a, d) in &SETUP {
            tb.write(a, d)
                .unwrap_or_else(|e| panic!("{name}: write {a}: {e}"));
        }
        for &(a, d) in &SETUP[1..] {
            assert_eq!(tb.read(a).unwrap(), d, "{name}: address {a}");
        }
        figures.push(format!(
            "{name} {:.1}",
            (tb.host_cycles() - c0) as f64 / 11.0
        ));
        assert!(tb.violations().is_empty(), "{name}: {:?}", tb.violations());
    }
    println!(
        "host cycles per register access on can_top (50 MHz host, 24 MHz CAN clock): {}",
        figures.join(", ")
    );
}

fn transmit(dut: DutChoice, lockstep: bool) -> Testbench {
    let mut c = cfg(dut, HostBfm::Wishbone);
    c.nodes = vec![node()];
    if lockstep {
        c.lockstep = Some((ReferenceChoice::Model, CompareConfig::default()));
    }
    let mut tb = Testbench::new(c).unwrap();
    for &(a, d) in &SETUP {
        tb.write(a, d).unwrap();
    }
    tb.write(0, 0x00).unwrap();
    tb.run_bits(12).unwrap();
    // TX buffer: ID 0x123, DLC 2, data 0xA5 0x5A; then CMR.TR.
    for (a, d) in [(10u8, 0x24u8), (11, 0x62), (12, 0xA5), (13, 0x5A)] {
        tb.write(a, d).unwrap();
    }
    tb.write(1, 0x01).unwrap();
    tb
}

#[test]
fn golden_model_as_dut_against_itself_transmits_without_divergence() {
    let mut tb = transmit(DutChoice::Model, true);
    let sr = tb
        .wait_sr(0x08, 0x08, 200)
        .unwrap_or_else(|e| panic!("{e}\n{:?}", tb.record().divergence));
    assert_eq!(sr & 0x0C, 0x0C, "TCS and TBS");
    let c = tb.comparator().unwrap();
    assert!(c.compared_bits > 40, "{}", c.compared_bits);
    assert!(tb.record().divergence.is_none());
    // The node received it.
    assert_eq!(tb.bus().node(0).peek(2) & 0x01, 0x01, "node1 SR.RBS");
}

#[test]
fn rtl_transmits_a_frame_to_a_model_node_in_lockstep_with_the_model() {
    let mut tb = transmit(DutChoice::Rtl, true);
    let res = tb.wait_sr(0x08, 0x08, 200);
    let rec = tb.record();
    if let Some(d) = &rec.divergence {
        let bits: String = rec
            .bus_bits
            .iter()
            .rev()
            .take(20)
            .rev()
            .map(|b| format!("{}{}{} ", b.bus as u8, b.dut_tx as u8, b.model_tx as u8))
            .collect();
        panic!(
            "divergence {d:?}\nlast bits (bus dut model): {bits}\n{}",
            diagnose::diagnose(&rec).to_text()
        );
    }
    res.unwrap();
    assert_eq!(
        tb.bus().node(0).peek(2) & 0x01,
        0x01,
        "node1 SR.RBS: frame received"
    );
    assert!(tb.comparator().unwrap().compared_bits > 40);
}

/// The PIO master polls `wb_ack_o` through a GPIO input, one sample per
/// `IORD` (5 host cycles by default), while `can_top` acknowledges with a
/// one-cycle pulse: a poll can miss it. Whatever the outcome, the bench must
/// either complete the accesses with the right data or stop on a host
/// timeout that says what the monitor saw, quickly.
#[test]
fn pio_on_the_rtl_completes_or_reports_the_missed_ack() {
    let mut c = cfg(DutChoice::Rtl, HostBfm::Pio(PioTiming::default()));
    c.op_timeout_cycles = 3_000;
    let mut tb = Testbench::new(c).unwrap();
    let t0 = std::time::Instant::now();
    let mut failure = None;
    for &(a, d) in &SETUP {
        if let Err(e) = tb.write(a, d) {
            failure = Some(e);
            break;
        }
    }
    if failure.is_none() {
        for &(a, d) in &SETUP[1..] {
            match tb.read(a) {
                Ok(v) => assert_eq!(v, d, "address {a}"),
                Err(e) => {
                    failure = Some(e);
                    break;
                }
            }
        }
    }
    assert!(t0.elapsed().as_secs() < 5);
    match failure {
        None => println!("PIO: every access completed"),
        Some(e) => {
            let msg = e.to_string();
            assert!(matches!(e, cosim::TbError::Host { .. }), "{msg}");
            assert!(
                msg.contains("timed out") && msg.contains("protocol monitor"),
                "{msg}"
            );
            let rec = tb.record();
            assert!(rec.host_ops.last().unwrap().error.is_some());
            println!("PIO on can_top: {msg}");
        }
    }
}

/// The DE2 thesis wiring: rx_i tied recessive through a PIO. The frame can
/// never complete; the bench must stop on a timeout and leave a record the
/// diagnoser can explain (stuck transfer, TEC per attempt), with the RTL in
/// lockstep with the model all along.
#[test]
fn thesis_wiring_rx_tied_recessive_leaves_a_stuck_transfer_for_the_diagnoser() {
    let mut c = cfg(DutChoice::Rtl, HostBfm::Wishbone);
    c.rx = diagnose::RxWiring::TiedRecessive;
    c.lockstep = Some((ReferenceChoice::Model, CompareConfig::default()));
    let mut tb = Testbench::new(c).unwrap();
    for &(a, d) in &SETUP {
        tb.write(a, d).unwrap();
    }
    tb.write(0, 0x00).unwrap();
    tb.run_bits(12).unwrap();
    for (a, d) in [(10u8, 0x24u8), (11, 0x62), (12, 0xA5), (13, 0x5A)] {
        tb.write(a, d).unwrap();
    }
    tb.write(1, 0x01).unwrap();
    let e = tb.wait_sr(0x0C, 0x0C, 200).unwrap_err();
    assert!(matches!(e, cosim::TbError::Timeout { .. }), "{e}");
    let f = tb.capture_final().unwrap();
    assert_eq!(
        f.sr & 0x0C,
        0x00,
        "TBS = 0 and TCS = 0: the buffer stays locked"
    );
    let rec = tb.record();
    assert!(rec.divergence.is_none(), "{:?}", rec.divergence);
    let stuck = rec.stuck.expect("stuck transfer recorded");
    assert!(stuck.requested_ps > 0 && stuck.waited_bits == 200);
    let tec = rec.tec_of(diagnose::Side::Model);
    assert!(tec.len() >= 3, "TEC per attempt: {tec:?}");
    let text = diagnose::diagnose(&rec).to_text();
    assert!(text.to_lowercase().contains("rx"), "{text}");
    println!("{text}");
}

/// A bit flipped in what the model node receives: it signals an error, the
/// RTL (transmitter) sees the error flag and retransmits; lockstep with the
/// model holds through the error frame and the frame still arrives.
#[test]
fn a_flipped_bit_at_the_model_node_causes_an_error_frame_and_a_retransmission() {
    let mut c = cfg(DutChoice::Rtl, HostBfm::Wishbone);
    c.nodes = vec![node()];
    c.faults.push(Box::new(sja1000::FlipBit {
        frame: 0,
        bit: 20,
        target: sja1000::Target::Node(0),
    }));
    c.lockstep = Some((ReferenceChoice::Model, CompareConfig::default()));
    let mut tb = Testbench::new(c).unwrap();
    for &(a, d) in &SETUP {
        tb.write(a, d).unwrap();
    }
    tb.write(0, 0x00).unwrap();
    tb.run_bits(12).unwrap();
    for (a, d) in [(10u8, 0x24u8), (11, 0x62), (12, 0xA5), (13, 0x5A)] {
        tb.write(a, d).unwrap();
    }
    tb.write(1, 0x01).unwrap();
    let res = tb.wait_sr(0x08, 0x08, 400);
    let rec = tb.record();
    assert!(rec.divergence.is_none(), "{:?}", rec.divergence);
    res.unwrap();
    assert!(
        rec.events
            .iter()
            .any(|e| matches!(e.kind, diagnose::EventKind::BusError { .. })),
        "the model (transmitter side) saw the error flag: {:?}",
        rec.events
    );
    assert!(
        rec.bus_bits
            .iter()
            .any(|b| b.field == Some(can_proto::Field::ActiveErrorFlag)),
        "error flag on the bus"
    );
    assert_eq!(
        tb.bus().node(0).peek(2) & 0x01,
        0x01,
        "received on the second attempt"
    );
}
