//! The FFI layer alone, on small Rust hosts: offsets, return codes,
//! failures reported instead of hidden, frame conversion.

use can_proto::CanFrame;
use cdriver::{CDriver, CDriverError, Config, Host, View, ecc_kind};

/// 256 bytes of registers that keep what is written; address 0 bit 0 (the
/// reset bit) can be pinned.
struct Ram {
    regs: [u8; 256],
    log: Vec<(bool, u32, u8)>,
    reset_stuck: Option<bool>,
    panic_at: Option<u32>,
}

impl Ram {
    fn new() -> Ram {
        let mut regs = [0u8; 256];
        regs[0] = 1;
        Ram { regs, log: Vec::new(), reset_stuck: None, panic_at: None }
    }
}

impl Host for Ram {
    fn iord8(&mut self, offset: u32) -> u8 {
        if self.panic_at == Some(offset) {
            panic!("simulated host failure at {offset}");
        }
        let mut v = self.regs[offset as usize];
        if let (0, Some(s)) = (offset, self.reset_stuck) {
            v = (v & !1) | s as u8;
        }
        self.log.push((false, offset, v));
        v
    }
    fn iowr8(&mut self, offset: u32, v: u8) {
        self.log.push((true, offset, v));
        self.regs[offset as usize] = v;
    }
}

#[test]
fn accesses_arrive_as_register_offsets_from_the_driver_base() {
    let mut drv = CDriver::new(Ram::new());
    let cfg = Config { btr0: 0x41, btr1: 0x25, ..Config::accept_all() };
    drv.init(View::Peli, &cfg).unwrap();
    let log = &drv.host().log;
    // First access: CDR (31) read to learn the view in force.
    assert_eq!(log[0], (false, 31, 0));
    // BTR0/BTR1 are registers 6 and 7 in the PeliCAN view.
    assert!(log.contains(&(true, 6, 0x41)) && log.contains(&(true, 7, 0x25)), "{log:?}");
    assert!(log.iter().all(|&(_, o, _)| o < 32), "PeliCAN registers only: {log:?}");
    assert_eq!(drv.view(), Some(View::Peli));
}

#[test]
fn a_reset_bit_that_never_clears_is_can_etimedout() {
    let mut ram = Ram::new();
    ram.reset_stuck = Some(true);
    let mut drv = CDriver::new(ram);
    assert_eq!(drv.init(View::Basic, &Config::accept_all()), Err(CDriverError::ResetTimeout { call: "can_init" }));
    assert_eq!(drv.view(), None);
    // CAN_DRV_POLLS (1000) write/read pairs on the way out of reset mode.
    let polls = drv.host().log.iter().filter(|&&(w, o, _)| !w && o == 0).count();
    assert_eq!(polls, 1000 + 1);
}

#[test]
fn a_panicking_host_becomes_an_error_and_the_call_stops_touching_it() {
    let mut ram = Ram::new();
    ram.panic_at = Some(31);
    let mut drv = CDriver::new(ram);
    match drv.init(View::Peli, &Config::accept_all()) {
        Err(CDriverError::Host { call: "can_init", message }) => assert!(message.contains("simulated host failure at 31"), "{message}"),
        other => panic!("{other:?}"),
    }
    assert!(drv.host().log.is_empty(), "no access after the failed one: {:?}", drv.host().log);
}

#[test]
fn frames_cross_the_ffi_unchanged_and_transmit_checks_the_view() {
    let mut drv = CDriver::new(Ram::new());
    assert_eq!(drv.transmit(&CanFrame::with_dlc(CanFrame::std_id(1).unwrap(), false, 0, &[]).unwrap()), Err(CDriverError::NotInitialised("can_transmit")));
    drv.init(View::Peli, &Config::accept_all()).unwrap();
    // TX buffer free (SR.TBS).
    drv.host_mut().regs[2] = 0x0C;
    let f = CanFrame::with_dlc(CanFrame::ext_id(0x1234_5678).unwrap(), false, 3, &[7, 8, 9]).unwrap();
    drv.transmit(&f).unwrap();
    // TXFI: FF | DLC 3, then ID.28..21, ID.20..13, ID.12..5, ID.4..0 << 3.
    assert_eq!(&drv.host().regs[16..24], &[0x83, 0x91, 0xA2, 0xB3, 0xC0, 7, 8, 9]);
    assert_eq!(drv.host().regs[1], 0x01, "CMR.TR");
    // Receive reads the same window (RX buffer = TX buffer in this RAM).
    drv.host_mut().regs[2] = 0x0D;
    assert_eq!(drv.receive().unwrap(), Some(f));
    // SR.TBS = 0: locked.
    drv.host_mut().regs[2] = 0x00;
    assert_eq!(drv.transmit(&f), Err(CDriverError::Busy));
    drv.host_mut().regs[2] = 0x80 | 0x04;
    assert_eq!(drv.transmit(&f), Err(CDriverError::BusOff));
}

#[test]
fn ecc_kind_names_the_error_code() {
    assert_eq!(ecc_kind(0x00), "bit");
    assert_eq!(ecc_kind(0x40), "form");
    assert_eq!(ecc_kind(0x80), "stuff");
    assert_eq!(ecc_kind(0xD9), "other");
}
