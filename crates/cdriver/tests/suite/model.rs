//! Host (c): the C driver on the golden model as the DUT (`cosim::ModelDut`,
//! a Wishbone slave), through the Wishbone BFM and through the Avalon BFM
//! over the Avalon-to-Wishbone bridge wiring. No Verilator needed.

use crate::common;

use bfm::AvalonTiming;
use cdriver::{BenchHost, CDriver, View};
use cosim::{AvalonWiring, DutChoice, HostBfm};

const AVALON: HostBfm = HostBfm::Avalon { timing: AvalonTiming::Waitrequest, wiring: AvalonWiring::Bridge };

fn driver(host: HostBfm, node_view: View) -> CDriver<cdriver::Direct<BenchHost>> {
    CDriver::new(BenchHost::with_model_node(DutChoice::Model, host, node_view).unwrap())
}

fn driver_two_nodes(host: HostBfm) -> CDriver<cdriver::Direct<BenchHost>> {
    let mut h = BenchHost::with_model_node(DutChoice::Model, host, View::Peli).unwrap();
    h.tb_mut().bus_mut().add_node(cdriver::model_node(View::Peli));
    CDriver::new(h)
}

#[test]
fn wishbone_pelican_exchange() {
    common::exchange(&mut driver(HostBfm::Wishbone, View::Peli), View::Peli);
}

#[test]
fn wishbone_basiccan_exchange() {
    common::exchange(&mut driver(HostBfm::Wishbone, View::Basic), View::Basic);
}

#[test]
fn avalon_bridge_pelican_exchange() {
    common::exchange(&mut driver(AVALON, View::Peli), View::Peli);
}

#[test]
fn avalon_bridge_basiccan_exchange() {
    common::exchange(&mut driver(AVALON, View::Basic), View::Basic);
}

#[test]
fn basiccan_refuses_extended_frames() {
    common::basic_rejects_extended(&mut driver(HostBfm::Wishbone, View::Peli));
}

#[test]
fn no_acknowledge_is_read_through_ecc_and_txerr() {
    let mut drv = CDriver::new(BenchHost::alone(DutChoice::Model, HostBfm::Wishbone).unwrap());
    common::no_ack(&mut drv);
}

#[test]
fn arbitration_loss_is_read_through_alc() {
    common::arbitration_lost(&mut driver_two_nodes(AVALON));
}

#[test]
fn two_frames_queued_are_received_in_order() {
    common::two_frames_queued(&mut driver(AVALON, View::Peli), View::Peli);
    common::two_frames_queued(&mut driver(HostBfm::Wishbone, View::Basic), View::Basic);
}

#[test]
fn basiccan_no_acknowledge_is_read_through_sr_es() {
    let mut drv = CDriver::new(BenchHost::alone(DutChoice::Model, AVALON).unwrap());
    common::basic_no_ack(&mut drv);
}

#[test]
fn receive_interrupt_follows_the_rx_buffer() {
    common::receive_interrupt(&mut driver(AVALON, View::Peli), View::Peli);
    common::receive_interrupt(&mut driver(HostBfm::Wishbone, View::Peli), View::Basic);
}

#[test]
fn overrun_is_counted_and_cleared() {
    common::overrun(&mut driver(AVALON, View::Peli));
}
