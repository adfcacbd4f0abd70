//! Host-side conveniences over the register interface, the way a driver
//! would program the chip: every access goes through [`Sja1000::write`] /
//! [`Sja1000::read`] at `regmap` addresses.

use can_proto::{CanFrame, FrameTrait, Id};
use regmap::{Mode, basic, peli};

use crate::controller::{Sja1000, WriteOutcome, bit};

/// A node configuration (applied in reset mode, then reset mode is left).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// BasicCAN or PeliCAN.
    pub mode: Mode,
    /// BTR0 value.
    pub btr0: u8,
    /// BTR1 value.
    pub btr1: u8,
    /// ACR0..3 (BasicCAN uses ACR0 as ACR).
    pub acr: [u8; 4],
    /// AMR0..3 (BasicCAN uses AMR0 as AMR).
    pub amr: [u8; 4],
    /// PeliCAN single filter (MOD.AFM).
    pub single_filter: bool,
    /// PeliCAN MOD.LOM.
    pub listen_only: bool,
    /// PeliCAN MOD.STM.
    pub self_test: bool,
    /// PeliCAN IER, or BasicCAN CR enable bits (RIE..OIE, CR positions).
    pub interrupts: u8,
}

impl Config {
    /// PeliCAN, accept everything, no interrupt enabled, 40 clocks per bit
    /// (BTR0 = 0x41, BTR1 = 0x25: the thesis setting, 600 kbit/s at 24 MHz).
    pub fn pelican() -> Self {
        Config {
            mode: Mode::PeliCan,
            btr0: 0x41,
            btr1: 0x25,
            acr: [0; 4],
            amr: [0xFF; 4],
            single_filter: true,
            listen_only: false,
            self_test: false,
            interrupts: 0,
        }
    }

    /// BasicCAN with one ACR/AMR pair, same timing as [`Config::pelican`].
    pub fn basic(acr: u8, amr: u8) -> Self {
        Config {
            mode: Mode::BasicCan,
            acr: [acr, 0, 0, 0],
            amr: [amr, 0xFF, 0xFF, 0xFF],
            ..Config::pelican()
        }
    }
}

/// Programs `node` (entering reset mode first) and leaves reset mode.
pub fn configure(node: &mut Sja1000, cfg: &Config) {
    enter_reset(node);
    match cfg.mode {
        Mode::PeliCan => {
            node.write(peli::CDR, peli::cdr::CANMODE);
            node.write(peli::BTR0, cfg.btr0);
            node.write(peli::BTR1, cfg.btr1);
            for i in 0..4 {
                node.write(peli::ACR0 + i as u8, cfg.acr[i]);
                node.write(peli::AMR0 + i as u8, cfg.amr[i]);
            }
            node.write(peli::IER, cfg.interrupts);
            let m = peli::r#mod::RM
                | bit(cfg.listen_only, peli::r#mod::LOM)
                | bit(cfg.self_test, peli::r#mod::STM)
                | bit(cfg.single_filter, peli::r#mod::AFM);
            node.write(peli::MOD, m);
            node.write(peli::MOD, m & !peli::r#mod::RM);
        }
        Mode::BasicCan => {
            node.write(basic::CDR, 0);
            node.write(basic::ACR, cfg.acr[0]);
            node.write(basic::AMR, cfg.amr[0]);
            node.write(basic::BTR0, cfg.btr0);
            node.write(basic::BTR1, cfg.btr1);
            node.write(basic::CR, cfg.interrupts & !basic::cr::RR);
        }
    }
}

/// Sets MOD.RM / CR.RR.
pub fn enter_reset(node: &mut Sja1000) {
    // MOD.RM and CR.RR are the same bit of address 0.
    let v = node.read(peli::MOD);
    node.write(peli::MOD, v | peli::r#mod::RM);
}

/// Clears MOD.RM / CR.RR.
pub fn leave_reset(node: &mut Sja1000) {
    let v = node.read(peli::MOD);
    node.write(peli::MOD, v & !peli::r#mod::RM);
}

/// Writes `frame` into the TX buffer in the node's view. Errors with the
/// outcome of the first write that did not apply (e.g. buffer locked).
pub fn load_tx(node: &mut Sja1000, frame: &CanFrame) -> Result<(), WriteOutcome> {
    let mut bytes = [0u8; 13];
    let (base, n) = match node.mode() {
        Mode::PeliCan => (peli::TXFI, encode_peli(frame, &mut bytes)),
        Mode::BasicCan => (basic::TXID1, encode_basic(frame, &mut bytes)),
    };
    for (i, &b) in bytes[..n].iter().enumerate() {
        match node.write(base + i as u8, b) {
            WriteOutcome::Applied => {}
            o => return Err(o),
        }
    }
    Ok(())
}

/// Loads `frame` and writes CMR with `cmd` (e.g. TR, TR|AT, SRR).
pub fn transmit(node: &mut Sja1000, frame: &CanFrame, cmd: u8) -> Result<(), WriteOutcome> {
    load_tx(node, frame)?;
    match node.write(peli::CMR, cmd) {
        WriteOutcome::Applied => Ok(()),
        o => Err(o),
    }
}

/// PeliCAN buffer layout: frame information, 2 or 4 ID bytes, data.
pub fn encode_peli(frame: &CanFrame, out: &mut [u8; 13]) -> usize {
    let rtr = bit(frame.is_remote_frame(), peli::rxfi::RTR);
    let data = frame.data();
    let head = match frame.id() {
        Id::Standard(s) => {
            let id = s.as_raw();
            out[0] = rtr | frame.dlc_raw();
            out[1] = (id >> 3) as u8;
            out[2] = (id as u8 & 7) << 5;
            3
        }
        Id::Extended(e) => {
            let id = e.as_raw();
            out[0] = peli::rxfi::FF | rtr | frame.dlc_raw();
            out[1] = (id >> 21) as u8;
            out[2] = (id >> 13) as u8;
            out[3] = (id >> 5) as u8;
            out[4] = (id as u8 & 0x1F) << 3;
            5
        }
    };
    out[head..head + data.len()].copy_from_slice(data);
    head + data.len()
}

/// BasicCAN buffer layout: ID.10..3, then ID.2..0 RTR DLC, data.
/// Extended identifiers keep their 11 base bits.
pub fn encode_basic(frame: &CanFrame, out: &mut [u8; 13]) -> usize {
    let id = match frame.id() {
        Id::Standard(s) => s.as_raw(),
        Id::Extended(e) => (e.as_raw() >> 18) as u16,
    };
    out[0] = (id >> 3) as u8;
    out[1] = ((id as u8 & 7) << basic::txid2::lsb::ID)
        | bit(frame.is_remote_frame(), basic::txid2::RTR)
        | frame.dlc_raw();
    let data = frame.data();
    out[2..2 + data.len()].copy_from_slice(data);
    2 + data.len()
}

/// Reads the current RX message through the receive buffer window and
/// releases it (RRB); `None` if SR.RBS = 0.
pub fn receive(node: &mut Sja1000) -> Option<CanFrame> {
    if node.read(peli::SR) & peli::sr::RBS == 0 {
        return None;
    }
    let frame = match node.mode() {
        Mode::PeliCan => {
            let b = |n: &mut Sja1000, i: u8| n.read(peli::RXFI + i);
            let fi = b(node, 0);
            let rtr = fi & peli::rxfi::RTR != 0;
            let dlc = fi & peli::rxfi::DLC;
            let n = if rtr { 0 } else { dlc.min(8) as usize };
            let (id, first): (Id, u8) = if fi & peli::rxfi::FF != 0 {
                let raw = (b(node, 1) as u32) << 21
                    | (b(node, 2) as u32) << 13
                    | (b(node, 3) as u32) << 5
                    | (b(node, 4) as u32) >> 3;
                (CanFrame::ext_id(raw)?, 5)
            } else {
                let raw = (b(node, 1) as u16) << 3 | (b(node, 2) as u16) >> 5;
                (CanFrame::std_id(raw)?, 3)
            };
            let mut data = [0u8; 8];
            for (i, d) in data[..n].iter_mut().enumerate() {
                *d = b(node, first + i as u8);
            }
            CanFrame::with_dlc(id, rtr, dlc, &data[..n])
        }
        Mode::BasicCan => {
            let d1 = node.read(basic::RXID1);
            let d2 = node.read(basic::RXID2);
            let raw = (d1 as u16) << 3 | ((d2 & basic::txid2::ID) >> basic::txid2::lsb::ID) as u16;
            let rtr = d2 & basic::txid2::RTR != 0;
            let dlc = d2 & basic::txid2::DLC;
            let n = if rtr { 0 } else { dlc.min(8) as usize };
            let mut data = [0u8; 8];
            for (i, d) in data[..n].iter_mut().enumerate() {
                *d = node.read(basic::RXDATA + i as u8);
            }
            CanFrame::with_dlc(CanFrame::std_id(raw)?, rtr, dlc, &data[..n])
        }
    };
    node.write(peli::CMR, peli::cmr::RRB);
    frame
}
