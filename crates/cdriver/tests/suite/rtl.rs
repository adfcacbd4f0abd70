//! Hosts (a) and (b): the C driver on our RTL, Verilated.
//! (a) Avalon BFM -> `can_avalon` (the wrapper Platform Designer sees).
//! (b) the generated `can_sja_pio.h` bit-banging `can_top`'s Wishbone pins
//!     through five PIO cores (the DE2 thesis wiring), ack on edge capture.

use crate::common;

use bfm::{AvalonTiming, PioTiming};
use cdriver::{BenchHost, CDriver, Direct, PioBench, SimHost, View, ViaPio};
use cosim::{AvalonWiring, DutChoice, HostBfm, HostPort, VerilatedDut};

const AVALON: HostBfm = HostBfm::Avalon { timing: AvalonTiming::Waitrequest, wiring: AvalonWiring::Native };

fn avalon(node_view: View) -> CDriver<Direct<BenchHost>> {
    CDriver::new(BenchHost::with_model_node(DutChoice::RtlAvalon, AVALON, node_view).unwrap())
}

fn pio(nodes: usize) -> CDriver<ViaPio<PioBench<VerilatedDut>>> {
    let dut = VerilatedDut::bundled("can_top", HostPort::Wishbone, false).unwrap();
    let nodes = (0..nodes).map(|_| cdriver::model_node(View::Peli)).collect();
    CDriver::via_pio(PioBench::new(dut, nodes, PioTiming::default()))
}

#[test]
fn avalon_can_avalon_pelican_exchange() {
    common::exchange(&mut avalon(View::Peli), View::Peli);
}

#[test]
fn avalon_can_avalon_basiccan_exchange() {
    common::exchange(&mut avalon(View::Basic), View::Basic);
}

#[test]
fn avalon_can_avalon_no_acknowledge() {
    let mut drv = CDriver::new(BenchHost::alone(DutChoice::RtlAvalon, AVALON).unwrap());
    common::no_ack(&mut drv);
}

#[test]
fn avalon_can_avalon_arbitration_loss() {
    let mut h = BenchHost::with_model_node(DutChoice::RtlAvalon, AVALON, View::Peli).unwrap();
    h.tb_mut().bus_mut().add_node(cdriver::model_node(View::Peli));
    common::arbitration_lost(&mut CDriver::new(h));
}

#[test]
fn avalon_can_avalon_refuses_extended_in_basiccan() {
    common::basic_rejects_extended(&mut avalon(View::Peli));
}

#[test]
fn pio_header_can_top_pelican_exchange() {
    let mut drv = pio(1);
    common::exchange(&mut drv, View::Peli);
    let h = drv.host();
    eprintln!(
        "PIO path: {} register accesses, {} Wishbone acks, {} GPIO accesses, {} host cycles",
        h.register_accesses(),
        h.acks(),
        h.gpio_accesses(),
        h.host_cycles()
    );
    assert_eq!(h.acks(), h.register_accesses(), "one Wishbone transfer per register access");
}

#[test]
fn pio_header_can_top_basiccan_exchange() {
    common::exchange(&mut pio(1), View::Basic);
}

#[test]
fn pio_header_can_top_no_acknowledge() {
    common::no_ack(&mut pio(0));
}

#[test]
fn pio_header_can_top_arbitration_loss() {
    common::arbitration_lost(&mut pio(2));
}

#[test]
fn pio_bench_runs_time() {
    let mut drv = pio(0);
    let before = drv.host().host_cycles();
    drv.host_mut().run_bits(10);
    // 10 bits of 40 CAN clocks at 24 MHz = 16.7 us = 833 host cycles at 50 MHz.
    let d = drv.host().host_cycles() - before;
    assert!((830..=836).contains(&d), "{d} host cycles");
}

#[test]
fn avalon_can_avalon_two_frames_queued() {
    common::two_frames_queued(&mut avalon(View::Peli), View::Peli);
}

/// The thesis sequence holds cyc/stb for the cycles the CPU needs to see
/// the ack (poll, read data, write control = 0), and Wishbone classic reads
/// cyc & stb after ack as the next transfer: `can_top` performs every
/// access twice. A doubled CMR.RRB releases two frames.
#[test]
#[ignore = "known defect of the thesis PIO wiring (not of the driver): each bit-banged access reaches can_top twice because cyc/stb stay high after wb_ack_o, so the doubled CMR.RRB drops the second queued frame; fix in the PIO glue (see pio_header_with_ack_gate_two_frames_queued) or can_top; run with --ignored"]
fn pio_header_can_top_two_frames_queued() {
    common::two_frames_queued(&mut pio(1), View::Peli);
}

/// The same flow with a one-shot between the control PIO and cyc/stb
/// (dropped from ack until the next control write): every access is one
/// transfer and both frames arrive.
#[test]
fn pio_header_with_ack_gate_two_frames_queued() {
    let mut drv = pio(1);
    drv.host_mut().set_ack_gate(true);
    common::two_frames_queued(&mut drv, View::Peli);
}

#[test]
fn pio_header_with_ack_gate_pelican_exchange() {
    let mut drv = pio(1);
    drv.host_mut().set_ack_gate(true);
    common::exchange(&mut drv, View::Peli);
}

/// The bfm crate's own PIO master (a Rust model of the thesis sequence
/// polling the ack PIO's level) on `can_top` through the test bench.
#[test]
#[ignore = "bfm::PioMaster polls the ack PIO level and can_top's wb_ack_o is a one-cycle pulse: the first access (CDR read in can_init) times out with cyc dropped before ack; the generated can_sja_pio.h path with edge capture works (pio_header_* tests); run with --ignored"]
fn pio_master_can_top_pelican_exchange() {
    let h = BenchHost::with_model_node(DutChoice::Rtl, HostBfm::Pio(PioTiming::default()), View::Peli).unwrap();
    common::exchange(&mut CDriver::new(h), View::Peli);
}

/// A core that never acknowledges: the driver call fails with the BFM's
/// timeout in its words, instead of hanging.
#[test]
fn avalon_bridge_on_a_core_without_ack_fails_cleanly() {
    let h = BenchHost::alone(DutChoice::Bundled("cosim_noack".into()), HostBfm::Avalon { timing: AvalonTiming::Waitrequest, wiring: AvalonWiring::Bridge }).unwrap();
    let mut drv = CDriver::new(h);
    let e = drv.init(View::Peli, &cdriver::Config::accept_all()).unwrap_err();
    match &e {
        cdriver::CDriverError::Host { call: "can_init", message } => assert!(message.contains("timed out"), "{message}"),
        other => panic!("expected a host error from can_init, got {other:?}"),
    }
    assert_eq!(drv.view(), None, "a failed init leaves the driver uninitialised");
    assert_eq!(drv.receive().unwrap_err(), cdriver::CDriverError::NotInitialised("can_receive"));
}

#[test]
fn pio_header_on_a_core_without_ack_fails_cleanly() {
    let dut = VerilatedDut::bundled("cosim_noack", HostPort::Wishbone, false).unwrap();
    let mut drv = CDriver::via_pio(PioBench::new(dut, Vec::new(), PioTiming::default()));
    let e = drv.init(View::Peli, &cdriver::Config::accept_all()).unwrap_err();
    match &e {
        cdriver::CDriverError::Host { call: "can_init", message } => assert!(message.contains("saw no ack"), "{message}"),
        other => panic!("expected a host error from can_init, got {other:?}"),
    }
    // can_sja_pio.h dropped the cycle after its timeout.
    assert!(!cosim::Dut::wb(drv.host().dut()).ack);
}

/// Wishbone BFM straight into `can_top`.
#[test]
fn wishbone_can_top_pelican_exchange() {
    let h = BenchHost::with_model_node(DutChoice::Rtl, HostBfm::Wishbone, View::Peli).unwrap();
    common::exchange(&mut CDriver::new(h), View::Peli);
}

/// The whole driver flow on `can_avalon` with the golden model shadowing
/// the RTL in lockstep (same host accesses, same rx): every register read
/// and the CAN pins are compared, and a divergence fails the driver call.
#[test]
fn avalon_can_avalon_exchange_in_lockstep_with_the_model() {
    for view in [View::Peli, View::Basic] {
        let mut cfg = BenchHost::config(DutChoice::RtlAvalon, AVALON);
        cfg.lockstep = Some((cosim::ReferenceChoice::Model, cosim::CompareConfig::default()));
        let mut drv = CDriver::new(BenchHost::with_nodes(cfg, vec![cdriver::model_node(View::Peli)]).unwrap());
        common::exchange(&mut drv, view);
        let tb = drv.host_mut().tb_mut();
        assert!(tb.comparator().unwrap().divergence().is_none());
        assert!(tb.violations().is_empty(), "{:?}", tb.violations());
    }
}

#[test]
fn avalon_can_avalon_basiccan_no_acknowledge() {
    let mut drv = CDriver::new(BenchHost::alone(DutChoice::RtlAvalon, AVALON).unwrap());
    common::basic_no_ack(&mut drv);
}

#[test]
fn pio_header_can_top_basiccan_no_acknowledge() {
    common::basic_no_ack(&mut pio(0));
}

/// `can_sja_pio_reset` through the control PIO resets `can_top`: frames
/// are no longer received until the driver initialises it again.
#[test]
fn pio_header_reset_pulse_resets_can_top() {
    let mut drv = pio(1);
    drv.init(View::Peli, &cdriver::Config::accept_all()).unwrap();
    drv.host_mut().run_bits(16);
    drv.pio_reset(0).unwrap();
    drv.host_mut().run_bits(4);
    let f = common::std_frame(0x42, &[1]);
    common::node_transmit(&mut drv, 0, &f);
    drv.host_mut().run_bits(120);
    // In reset mode the core neither acknowledges nor stores the frame.
    assert_eq!(drv.receive().unwrap(), None);
    drv.init(View::Peli, &cdriver::Config::accept_all()).unwrap();
    // The model node retransmits until acknowledged.
    assert_eq!(drv.receive_polling(20_000).unwrap(), f);
}

#[test]
fn avalon_can_avalon_receive_interrupt() {
    common::receive_interrupt(&mut avalon(View::Peli), View::Peli);
    common::receive_interrupt(&mut avalon(View::Peli), View::Basic);
}

#[test]
fn pio_header_can_top_receive_interrupt() {
    common::receive_interrupt(&mut pio(1), View::Peli);
}

#[test]
fn avalon_can_avalon_overrun() {
    common::overrun(&mut avalon(View::Peli));
}

#[test]
fn pio_header_with_ack_gate_overrun() {
    let mut drv = pio(1);
    drv.host_mut().set_ack_gate(true);
    common::overrun(&mut drv);
}
