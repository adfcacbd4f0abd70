//! The C side: the records of `can_driver.h` and the functions of
//! `can_driver.h`, `host_io_callback.h` and our `c/pio_shim.c`.

use std::ffi::{c_char, c_int, c_ulong, c_void};

/// `can_dev_t`.
#[repr(C)]
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct CanDev {
    pub base: usize,
    pub view: c_int,
    pub overruns: c_ulong,
}

/// `can_frame_t`.
#[repr(C)]
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub(crate) struct CanFrameC {
    pub id: u32,
    pub extended: u8,
    pub rtr: u8,
    pub dlc: u8,
    pub data: [u8; 8],
}

/// `can_config_t`.
#[repr(C)]
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct CanConfigC {
    pub btr0: u8,
    pub btr1: u8,
    pub ocr: u8,
    pub cdr: u8,
    pub acr: [u8; 4],
    pub amr: [u8; 4],
    pub single_filter: u8,
    pub irq_enable: u8,
}

/// `can_errors_t`.
#[repr(C)]
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct CanErrorsC {
    pub sr: u8,
    pub ir: u8,
    pub has_capture: u8,
    pub ecc: u8,
    pub alc: u8,
    pub rxerr: u8,
    pub txerr: u8,
    pub bus_off: u8,
    pub error_warning: u8,
}

pub(crate) const CAN_VIEW_BASIC: c_int = 0;
pub(crate) const CAN_VIEW_PELI: c_int = 1;
pub(crate) const CAN_OK: c_int = 0;
pub(crate) const CAN_ETIMEDOUT: c_int = -1;
pub(crate) const CAN_EBUSY: c_int = -2;
pub(crate) const CAN_EINVAL: c_int = -3;
pub(crate) const CAN_EBUSOFF: c_int = -4;

pub(crate) type Read8 = unsafe extern "C" fn(*mut c_void, usize) -> u8;
pub(crate) type Write8 = unsafe extern "C" fn(*mut c_void, usize, u8);
pub(crate) type Read32 = unsafe extern "C" fn(*mut c_void, usize) -> u32;
pub(crate) type Write32 = unsafe extern "C" fn(*mut c_void, usize, u32);

unsafe extern "C" {
    pub(crate) fn host_io_set_callbacks(
        read8: Option<Read8>,
        write8: Option<Write8>,
        read32: Option<Read32>,
        write32: Option<Write32>,
        ctx: *mut c_void,
    );
    pub(crate) fn can_init(dev: *mut CanDev, base: usize, view: c_int, cfg: *const CanConfigC) -> c_int;
    pub(crate) fn can_transmit(dev: *mut CanDev, frame: *const CanFrameC) -> c_int;
    pub(crate) fn can_receive(dev: *mut CanDev, frame: *mut CanFrameC) -> c_int;
    pub(crate) fn can_read_errors(dev: *mut CanDev, err: *mut CanErrorsC) -> c_int;
    pub(crate) fn can_bus_off_recover(dev: *mut CanDev) -> c_int;
    pub(crate) fn can_ecc_kind(ecc: u8) -> *const c_char;

    pub(crate) fn cdriver_pio_set_base(base: usize);
    pub(crate) fn cdriver_pio_take_timeouts() -> c_ulong;
    pub(crate) fn cdriver_pio_bases(out: *mut usize);
    pub(crate) fn cdriver_pio_timeout_polls() -> c_ulong;
    pub(crate) fn cdriver_pio_read8(ctx: *mut c_void, addr: usize) -> u8;
    pub(crate) fn cdriver_pio_write8(ctx: *mut c_void, addr: usize, data: u8);
    pub(crate) fn cdriver_pio_reset(hold: c_ulong);
}
