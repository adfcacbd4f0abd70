//! Flows shared by the host tests: each drives the C driver through
//! `CDriver` and checks the other end of the bus on a golden-model node.
#![allow(dead_code)]

use can_proto::CanFrame;
use cdriver::{CDriver, Config, SimHost, View, Wiring, ecc_kind};
use regmap::peli;
use sja1000::Sja1000;

pub fn std_frame(id: u16, data: &[u8]) -> CanFrame {
    CanFrame::with_dlc(CanFrame::std_id(id).unwrap(), false, data.len() as u8, data).unwrap()
}

pub fn ext_frame(id: u32, data: &[u8]) -> CanFrame {
    CanFrame::with_dlc(CanFrame::ext_id(id).unwrap(), false, data.len() as u8, data).unwrap()
}

pub fn remote(id: u16, dlc: u8) -> CanFrame {
    CanFrame::with_dlc(CanFrame::std_id(id).unwrap(), true, dlc, &[]).unwrap()
}

fn node_has_frame(n: &Sja1000) -> bool {
    n.peek(peli::SR) & peli::sr::RBS != 0
}

/// Runs the bus until model node `i` holds a frame, then reads it from the
/// node's RX buffer through its registers (and releases it).
pub fn node_receive<W>(drv: &mut CDriver<W>, i: usize, max_bits: u64) -> CanFrame
where
    W: Wiring,
    W::Host: SimHost,
{
    let mut waited = 0;
    while !node_has_frame(drv.host_mut().node(i)) {
        assert!(waited < max_bits, "model node {i} received nothing within {max_bits} bit times");
        drv.host_mut().run_bits(4);
        if let Some(e) = drv.host().stalled() {
            panic!("the bench stopped: {e}");
        }
        waited += 4;
    }
    sja1000::host::receive(drv.host_mut().node(i)).expect("RBS = 1, so a frame is there")
}

/// The model node transmits `f` (loads its TX buffer, CMR.TR).
pub fn node_transmit<W>(drv: &mut CDriver<W>, i: usize, f: &CanFrame)
where
    W: Wiring,
    W::Host: SimHost,
{
    sja1000::host::transmit(drv.host_mut().node(i), f, peli::cmr::TR).expect("model node TX buffer free");
}

/// Polls the driver until its transmission is complete (SR.TCS = 1).
fn driver_tx_complete<W: Wiring>(drv: &mut CDriver<W>) -> u8
where
    W::Host: SimHost,
{
    for _ in 0..400 {
        let e = drv.read_errors().unwrap();
        if e.sr & peli::sr::TCS != 0 {
            return e.sr;
        }
        drv.host_mut().run_bits(2);
    }
    panic!("the driver's controller never reported SR.TCS");
}

/// `init` in `view`, then: the driver transmits and the model node
/// receives; the model node transmits and the driver receives; in PeliCAN
/// also an extended frame and a remote frame both ways.
pub fn exchange<W>(drv: &mut CDriver<W>, view: View)
where
    W: Wiring,
    W::Host: SimHost,
{
    drv.init(view, &Config::accept_all()).unwrap();
    assert_eq!(drv.view(), Some(view));
    // Bus integration: 11 recessive bits before the controller may start.
    drv.host_mut().run_bits(16);

    let mut frames = vec![(std_frame(0x123, &[0x11, 0x22, 0x33]), std_frame(0x2A5, &[0xDE, 0xAD, 0xBE, 0xEF, 0x55, 0xAA, 0x01, 0x80]))];
    frames.push((std_frame(0x7FF, &[]), remote(0x001, 4)));
    if view == View::Peli {
        frames.push((ext_frame(0x1ABC_DE01, &[9, 8, 7, 6, 5]), ext_frame(0x0000_0155, &[0xC3; 8])));
    }
    for (to_node, to_driver) in frames {
        drv.transmit(&to_node).unwrap();
        let got = node_receive(drv, 0, 400);
        assert_eq!(got, to_node, "model node's RX buffer");
        driver_tx_complete(drv);

        node_transmit(drv, 0, &to_driver);
        let got = drv.receive_polling(50_000).unwrap();
        assert_eq!(got, to_driver, "frame returned by can_receive");
        // can_receive released the buffer: nothing is left.
        assert_eq!(drv.receive().unwrap(), None);
    }
    assert_eq!(drv.overruns(), 0);
}

/// BasicCAN cannot carry an extended identifier: the driver refuses it
/// before touching the TX buffer.
pub fn basic_rejects_extended<W: Wiring>(drv: &mut CDriver<W>) {
    drv.init(View::Basic, &Config::accept_all()).unwrap();
    assert_eq!(drv.transmit(&ext_frame(0x100, &[1])), Err(cdriver::CDriverError::Invalid(View::Basic)));
}

/// Nobody acknowledges: the driver reads a bus error captured in the ACK
/// slot (ECC = other, TX, segment 11001) and a rising TX error counter.
pub fn no_ack<W>(drv: &mut CDriver<W>)
where
    W: Wiring,
    W::Host: SimHost,
{
    let cfg = Config { irq_enable: peli::ier::BEIE | peli::ier::EPIE, ..Config::accept_all() };
    drv.init(View::Peli, &cfg).unwrap();
    drv.host_mut().run_bits(16);
    drv.transmit(&std_frame(0x0F0, &[0xA5])).unwrap();
    // One frame up to the ACK slot is about 40 bits; let a few attempts pass.
    drv.host_mut().run_bits(120);
    let e = drv.read_errors().unwrap();
    let c = e.capture.expect("PeliCAN has ECC/ALC");
    assert_eq!(c.ecc & 0x1F, 0x19, "ECC segment = ACK slot (11001), ecc 0x{:02X}", c.ecc);
    assert_eq!(c.ecc & 0x20, 0, "ECC.DIR = transmission");
    assert_eq!(ecc_kind(c.ecc), "other");
    assert!(c.txerr >= 8, "TXERR {} after failed attempts", c.txerr);
    assert!(e.ir & peli::ir::BEI != 0, "IR.BEI (enabled) after a bus error, IR 0x{:02X}", e.ir);
    assert!(!e.bus_off, "an unacknowledged transmitter stays error passive, never bus-off");
    assert_eq!(e.sr & peli::sr::TCS, 0, "no transmission completed");
    // Keep going to error passive: TXERR stops at 128 (ACK errors while
    // error passive do not count, CAN 2.0B 7.2 rule 3 exception 1).
    drv.host_mut().run_bits(16 * 80 + 200);
    let e = drv.read_errors().unwrap();
    let c = e.capture.unwrap();
    assert_eq!(c.txerr, 128, "TXERR when error passive without acknowledge");
    assert!(e.ir & peli::ir::EPI != 0, "IR.EPI on the way to error passive (IR 0x{:02X})", e.ir);
}

/// The driver's frame loses arbitration against model node 1 (both start
/// after model node 0's frame): ALC says at which identifier bit.
pub fn arbitration_lost<W>(drv: &mut CDriver<W>)
where
    W: Wiring,
    W::Host: SimHost,
{
    let cfg = Config { irq_enable: peli::ier::ALIE, ..Config::accept_all() };
    drv.init(View::Peli, &cfg).unwrap();
    drv.host_mut().run_bits(16);
    // Node 0 occupies the bus so the two requests below wait for the same
    // end of intermission.
    node_transmit(drv, 0, &std_frame(0x050, &[0; 8]));
    drv.host_mut().run_bits(4);
    // 0x100 = 001 0000 0000 and 0x0FF = 000 1111 1111 differ first at
    // ID.8, the third identifier bit (ALC bit number 2): the driver's
    // recessive 1 loses against the dominant 0.
    drv.transmit(&std_frame(0x100, &[1, 2])).unwrap();
    node_transmit(drv, 1, &std_frame(0x0FF, &[3, 4]));
    let first = node_receive(drv, 1, 400);
    assert_eq!(first, std_frame(0x050, &[0; 8]));
    let second = node_receive(drv, 0, 400);
    assert_eq!(second, std_frame(0x0FF, &[3, 4]), "the winner's frame comes first");
    let e = drv.read_errors().unwrap();
    assert!(e.ir & peli::ir::ALI != 0, "IR.ALI (enabled), IR 0x{:02X}", e.ir);
    assert_eq!(e.capture.unwrap().alc, 2, "ALC bit number");
    // The controller retransmits on its own after losing.
    let third = node_receive(drv, 0, 400);
    assert_eq!(third, std_frame(0x100, &[1, 2]));
}

/// Two frames wait in the RX FIFO: each `can_receive` returns one and
/// releases exactly one (a duplicated CMR.RRB write would drop the second).
pub fn two_frames_queued<W>(drv: &mut CDriver<W>, view: View)
where
    W: Wiring,
    W::Host: SimHost,
{
    drv.init(view, &Config::accept_all()).unwrap();
    drv.host_mut().run_bits(16);
    let a = std_frame(0x301, &[1, 2, 3]);
    let b = std_frame(0x302, &[4, 5, 6, 7]);
    node_transmit(drv, 0, &a);
    drv.host_mut().run_bits(160);
    node_transmit(drv, 0, &b);
    drv.host_mut().run_bits(160);
    assert_eq!(drv.receive().unwrap(), Some(a));
    assert_eq!(drv.receive().unwrap(), Some(b), "second frame still in the FIFO after the first release");
    assert_eq!(drv.receive().unwrap(), None);
}

/// BasicCAN, nobody acknowledges: no capture registers in this view, but
/// SR.ES rises once TXERR passes the warning limit (96) and IR.EI (enabled
/// through CR.EIE) reports it; the controller never goes bus-off.
pub fn basic_no_ack<W>(drv: &mut CDriver<W>)
where
    W: Wiring,
    W::Host: SimHost,
{
    let cfg = Config { irq_enable: regmap::basic::cr::EIE, ..Config::accept_all() };
    drv.init(View::Basic, &cfg).unwrap();
    drv.host_mut().run_bits(16);
    let e = drv.read_errors().unwrap();
    assert!(!e.error_warning && e.capture.is_none(), "{e:?}");
    drv.transmit(&std_frame(0x0F0, &[0xA5])).unwrap();
    // 12 failed attempts (8 each) reach 96; allow 16 of about 70 bits.
    drv.host_mut().run_bits(16 * 80);
    let e = drv.read_errors().unwrap();
    assert!(e.capture.is_none(), "BasicCAN has no ECC/ALC/counters");
    assert!(e.error_warning, "SR.ES after repeated ACK errors, SR 0x{:02X}", e.sr);
    assert!(e.ir & regmap::basic::ir::EI != 0, "IR.EI (enabled), IR 0x{:02X}", e.ir);
    assert!(!e.bus_off);
    assert_eq!(e.sr & regmap::basic::sr::TCS, 0);
}

/// With IER.RIE (PeliCAN) or CR.RIE (BasicCAN) the interrupt line rises
/// when the model node's frame is stored, and `can_receive`'s release
/// (CMR.RRB, RI follows RBS) drops it.
pub fn receive_interrupt<W>(drv: &mut CDriver<W>, view: View)
where
    W: Wiring,
    W::Host: SimHost,
{
    let rie = match view {
        View::Peli => peli::ier::RIE,
        View::Basic => regmap::basic::cr::RIE,
    };
    drv.init(view, &Config { irq_enable: rie, ..Config::accept_all() }).unwrap();
    drv.host_mut().run_bits(16);
    assert!(!drv.host().irq(), "no interrupt before any frame");
    let f = std_frame(0x3C5, &[0x5A; 6]);
    node_transmit(drv, 0, &f);
    let mut waited = 0;
    while !drv.host().irq() {
        assert!(waited < 400, "no receive interrupt within 400 bit times");
        drv.host_mut().run_bits(1);
        waited += 1;
    }
    assert!(waited > 40, "the interrupt came only after a whole frame ({waited} bits)");
    assert_eq!(drv.receive().unwrap(), Some(f));
    drv.host_mut().run_bits(2);
    assert!(!drv.host().irq(), "RRB released the only frame: RI and the line drop");
}

/// Seven 8-byte frames arrive while the driver does not read: the 64-byte
/// RX FIFO holds five (11 bytes each in PeliCAN), the rest overrun. The
/// driver reads the five in order, counts one overrun and clears it
/// (CMR.CDO with the release).
pub fn overrun<W>(drv: &mut CDriver<W>)
where
    W: Wiring,
    W::Host: SimHost,
{
    drv.init(View::Peli, &Config::accept_all()).unwrap();
    drv.host_mut().run_bits(16);
    let sent: Vec<CanFrame> = (0..7u8).map(|i| std_frame(0x100 + i as u16, &[i; 8])).collect();
    for f in &sent {
        let mut waited = 0;
        while drv.host_mut().node(0).peek(peli::SR) & peli::sr::TBS == 0 {
            assert!(waited < 400, "model node never finished a frame");
            drv.host_mut().run_bits(4);
            waited += 4;
        }
        node_transmit(drv, 0, f);
        drv.host_mut().run_bits(4);
    }
    drv.host_mut().run_bits(200);
    let e = drv.read_errors().unwrap();
    assert!(e.sr & peli::sr::DOS != 0, "SR.DOS after 7 frames into 64 bytes, SR 0x{:02X}", e.sr);
    let mut got = Vec::new();
    while let Some(f) = drv.receive().unwrap() {
        got.push(f);
        assert!(got.len() <= 7);
    }
    assert_eq!(got, sent[..5].to_vec(), "the five frames that fit, in order");
    assert_eq!(drv.overruns(), 1);
    let e = drv.read_errors().unwrap();
    assert_eq!(e.sr & (peli::sr::DOS | peli::sr::RBS), 0, "overrun cleared, FIFO empty, SR 0x{:02X}", e.sr);
}
