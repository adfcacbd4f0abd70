//! [`CDriver`]: the C driver of `crates/regmap/c/can_driver.c` called from
//! Rust, its `IORD`/`IOWR` answered by a host object.
//!
//! The stand-in `io.h` sends every access to `host_io_callback.c`, which
//! keeps one set of callbacks in C globals. Calls into C therefore take a
//! process-wide lock, install this driver's callbacks with a pointer to its
//! host as the context, run, and uninstall them: several drivers (test
//! threads) can exist, one runs C at a time.

use std::ffi::{CStr, c_int, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Mutex;

use can_proto::{CanFrame, FrameTrait, Id};

use crate::ffi;

/// The C globals of `host_io_callback.c` and `pio_shim.c` belong to one
/// call at a time.
static C_LOCK: Mutex<()> = Mutex::new(());

/// Where the driver sees the controller's register window (any value works;
/// a non-zero one shows that offsets are taken from the driver's base).
pub const CAN_BASE: usize = 0x4000;

/// A host answering the driver's 8-bit register accesses (`IORD_8DIRECT` /
/// `IOWR_8DIRECT` at `base + offset`): byte-spaced registers, as on the
/// Avalon wrapper.
pub trait Host {
    /// Reads register `offset` of the controller.
    fn iord8(&mut self, offset: u32) -> u8;
    /// Writes register `offset` of the controller.
    fn iowr8(&mut self, offset: u32, v: u8);
    /// The first access failure since the last call (the C macros cannot
    /// return errors, so a failing host answers reads with 0xFF and reports
    /// here).
    fn take_error(&mut self) -> Option<String> {
        None
    }
}

/// The five PIO cores of the thesis wiring, in `can_sja_pio.h`'s names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Pio {
    /// `CAN_SJA_PIO_ADDR_BASE`: drives `wb_adr_i`.
    Addr,
    /// `CAN_SJA_PIO_DOUT_BASE`: drives `wb_dat_i`.
    Dout,
    /// `CAN_SJA_PIO_CTRL_BASE`: we = bit 0, stb = 1, cyc = 2, rst = 3.
    Ctrl,
    /// `CAN_SJA_PIO_ACK_BASE`: `wb_ack_o` on bit 0, with edge capture.
    Ack,
    /// `CAN_SJA_PIO_DIN_BASE`: `wb_dat_o`.
    Din,
}

/// Register numbers of an Altera PIO core (word spaced).
pub mod pio_reg {
    /// `data`: the output register (write) or the input pins (read).
    pub const DATA: u32 = 0;
    /// `direction`.
    pub const DIRECTION: u32 = 1;
    /// `interruptmask`.
    pub const IRQ_MASK: u32 = 2;
    /// `edgecapture`: bits set by an input edge, cleared by writing 1.
    pub const EDGE_CAP: u32 = 3;
}

/// A host answering the GPIO accesses of the generated `can_sja_pio.h`
/// accessors: the driver's register accesses become bit-banged Wishbone
/// cycles in C, and only PIO register accesses reach the host.
pub trait PioHost {
    /// Reads register `reg` (see [`pio_reg`]) of PIO core `pio`.
    fn pio_read(&mut self, pio: Pio, reg: u32) -> u32;
    /// Writes register `reg` of PIO core `pio`.
    fn pio_write(&mut self, pio: Pio, reg: u32, v: u32);
    /// The first failure since the last call.
    fn take_error(&mut self) -> Option<String> {
        None
    }
}

mod sealed {
    use super::ffi;
    use std::ffi::c_void;

    pub struct Callbacks {
        pub rd8: ffi::Read8,
        pub wr8: ffi::Write8,
        pub rd32: Option<ffi::Read32>,
        pub wr32: Option<ffi::Write32>,
    }

    pub trait Wiring {
        fn callbacks(&self) -> Callbacks;
        /// Called with the C lock held, before a driver call.
        fn before(&mut self, _base: usize) {}
        fn take_error(&mut self) -> Option<String>;
        fn ctx(&mut self) -> *mut c_void {
            self as *mut Self as *mut c_void
        }
    }
}

/// How the driver's accesses reach the host: [`Direct`] or [`ViaPio`].
pub trait Wiring: sealed::Wiring {
    /// The host object behind the wiring.
    type Host;
    /// The host.
    fn host(&self) -> &Self::Host;
    /// The host, mutably.
    fn host_mut(&mut self) -> &mut Self::Host;
}

fn record(slot: &mut Option<String>, msg: String) {
    if slot.is_none() {
        *slot = Some(msg);
    }
}

fn panic_text(p: Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned()).unwrap_or_else(|| "panic".into())
}

/// The driver's 8-bit accesses go straight to a [`Host`].
pub struct Direct<H> {
    host: H,
    base: usize,
    error: Option<String>,
}

impl<H: Host> Direct<H> {
    /// Moves the host's failure, if any, into this call's record.
    fn collect(&mut self) {
        if let Some(e) = self.host.take_error() {
            record(&mut self.error, e);
        }
    }

    fn offset(&mut self, addr: usize) -> Option<u32> {
        match addr.checked_sub(self.base) {
            Some(o) if o < 256 => Some(o as u32),
            _ => {
                record(&mut self.error, format!("access at 0x{addr:X} outside the register window 0x{:X}..0x{:X}", self.base, self.base + 256));
                None
            }
        }
    }
}

unsafe extern "C" fn direct_rd8<H: Host>(ctx: *mut c_void, addr: usize) -> u8 {
    // SAFETY: ctx is the `Direct<H>` installed by `CDriver::call`, alive and
    // not otherwise borrowed for the duration of the C call.
    let d = unsafe { &mut *(ctx as *mut Direct<H>) };
    // After a failed access the rest of the call fails fast (the driver's
    // bounded loops would otherwise wait out every timeout again).
    if d.error.is_some() {
        return 0xFF;
    }
    let Some(o) = d.offset(addr) else { return 0xFF };
    let v = match catch_unwind(AssertUnwindSafe(|| d.host.iord8(o))) {
        Ok(v) => v,
        Err(p) => {
            record(&mut d.error, format!("host panicked reading offset {o}: {}", panic_text(p)));
            0xFF
        }
    };
    d.collect();
    v
}

unsafe extern "C" fn direct_wr8<H: Host>(ctx: *mut c_void, addr: usize, v: u8) {
    // SAFETY: as in `direct_rd8`.
    let d = unsafe { &mut *(ctx as *mut Direct<H>) };
    if d.error.is_some() {
        return;
    }
    let Some(o) = d.offset(addr) else { return };
    if let Err(p) = catch_unwind(AssertUnwindSafe(|| d.host.iowr8(o, v))) {
        record(&mut d.error, format!("host panicked writing offset {o}: {}", panic_text(p)));
    }
    d.collect();
}

impl<H: Host> sealed::Wiring for Direct<H> {
    fn callbacks(&self) -> sealed::Callbacks {
        sealed::Callbacks { rd8: direct_rd8::<H>, wr8: direct_wr8::<H>, rd32: None, wr32: None }
    }
    fn before(&mut self, base: usize) {
        self.base = base;
    }
    fn take_error(&mut self) -> Option<String> {
        self.collect();
        self.error.take()
    }
}
impl<H: Host> Wiring for Direct<H> {
    type Host = H;
    fn host(&self) -> &H {
        &self.host
    }
    fn host_mut(&mut self) -> &mut H {
        &mut self.host
    }
}

/// The driver's accesses go through the generated `can_sja_pio.h`
/// accessors (compiled in `c/pio_shim.c`) to a [`PioHost`].
pub struct ViaPio<P> {
    host: P,
    bases: [usize; 5],
    error: Option<String>,
}

const PIOS: [Pio; 5] = [Pio::Addr, Pio::Dout, Pio::Ctrl, Pio::Ack, Pio::Din];

impl<P: PioHost> ViaPio<P> {
    fn decode(&mut self, addr: usize) -> Option<(Pio, u32)> {
        for (i, &b) in self.bases.iter().enumerate() {
            if let Some(o) = addr.checked_sub(b).filter(|o| *o < 16 && o % 4 == 0) {
                return Some((PIOS[i], (o / 4) as u32));
            }
        }
        record(&mut self.error, format!("32-bit access at 0x{addr:X} is not a PIO register"));
        None
    }
}

unsafe extern "C" fn pio_rd32<P: PioHost>(ctx: *mut c_void, addr: usize) -> u32 {
    // SAFETY: ctx is the `ViaPio<P>` installed by `CDriver::call`; the C
    // 8-bit callbacks never touch it, so this is its only borrow.
    let d = unsafe { &mut *(ctx as *mut ViaPio<P>) };
    if d.error.is_some() {
        return 0xFFFF_FFFF;
    }
    let Some((pio, reg)) = d.decode(addr) else { return 0xFFFF_FFFF };
    match catch_unwind(AssertUnwindSafe(|| d.host.pio_read(pio, reg))) {
        Ok(v) => v,
        Err(p) => {
            record(&mut d.error, format!("PIO host panicked reading {pio:?}[{reg}]: {}", panic_text(p)));
            0xFFFF_FFFF
        }
    }
}

unsafe extern "C" fn pio_wr32<P: PioHost>(ctx: *mut c_void, addr: usize, v: u32) {
    // SAFETY: as in `pio_rd32`.
    let d = unsafe { &mut *(ctx as *mut ViaPio<P>) };
    if d.error.is_some() {
        return;
    }
    let Some((pio, reg)) = d.decode(addr) else { return };
    if let Err(p) = catch_unwind(AssertUnwindSafe(|| d.host.pio_write(pio, reg, v))) {
        record(&mut d.error, format!("PIO host panicked writing {pio:?}[{reg}]: {}", panic_text(p)));
    }
}

impl<P: PioHost> sealed::Wiring for ViaPio<P> {
    fn callbacks(&self) -> sealed::Callbacks {
        sealed::Callbacks { rd8: ffi::cdriver_pio_read8, wr8: ffi::cdriver_pio_write8, rd32: Some(pio_rd32::<P>), wr32: Some(pio_wr32::<P>) }
    }
    fn before(&mut self, base: usize) {
        // SAFETY: plain setter of a C global; the C lock is held.
        unsafe { ffi::cdriver_pio_set_base(base) };
    }
    fn take_error(&mut self) -> Option<String> {
        // SAFETY: plain getter of a C global; the C lock is held.
        let timeouts = unsafe { ffi::cdriver_pio_take_timeouts() };
        // SAFETY: as above.
        let polls = unsafe { ffi::cdriver_pio_timeout_polls() };
        let t = (timeouts > 0).then(|| format!("{timeouts} PIO register access(es) saw no ack within {polls} polls of the ack PIO"));
        self.error.take().or(t).or_else(|| self.host.take_error())
    }
}
impl<P: PioHost> Wiring for ViaPio<P> {
    type Host = P;
    fn host(&self) -> &P {
        &self.host
    }
    fn host_mut(&mut self) -> &mut P {
        &mut self.host
    }
}

/// The two register views of the controller.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// BasicCAN (CDR.CANMODE = 0).
    Basic,
    /// PeliCAN (CDR.CANMODE = 1).
    Peli,
}

/// `can_config_t`: what `can_init` programs in reset mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// Bus timing register 0.
    pub btr0: u8,
    /// Bus timing register 1.
    pub btr1: u8,
    /// Output control.
    pub ocr: u8,
    /// Clock divider bits other than CANMODE (the driver sets CANMODE).
    pub cdr: u8,
    /// Acceptance code (BasicCAN uses `acr[0]`).
    pub acr: [u8; 4],
    /// Acceptance mask, 1 = don't care (BasicCAN uses `amr[0]`).
    pub amr: [u8; 4],
    /// PeliCAN MOD.AFM: one 32-bit filter.
    pub single_filter: bool,
    /// PeliCAN IER, or BasicCAN CR enable bits.
    pub irq_enable: u8,
}

impl Config {
    /// Accept every frame, no interrupt, OCR normal mode, and the thesis bit
    /// timing (BTR0 = 0x41, BTR1 = 0x25: 40 clocks per bit, 600 kbit/s at 24 MHz).
    pub fn accept_all() -> Config {
        Config { btr0: 0x41, btr1: 0x25, ocr: 0xDA, cdr: 0, acr: [0; 4], amr: [0xFF; 4], single_filter: true, irq_enable: 0 }
    }

    fn to_c(self) -> ffi::CanConfigC {
        ffi::CanConfigC {
            btr0: self.btr0,
            btr1: self.btr1,
            ocr: self.ocr,
            cdr: self.cdr,
            acr: self.acr,
            amr: self.amr,
            single_filter: self.single_filter as u8,
            irq_enable: self.irq_enable,
        }
    }
}

/// Error capture of the PeliCAN view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Capture {
    /// Error code capture (ECC).
    pub ecc: u8,
    /// Arbitration lost capture, bit number (ALC.BITNO).
    pub alc: u8,
    /// RX error counter.
    pub rxerr: u8,
    /// TX error counter.
    pub txerr: u8,
}

/// `can_errors_t`, as `can_read_errors` fills it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ErrorStatus {
    /// Status register.
    pub sr: u8,
    /// Interrupt flags (consumed by the read).
    pub ir: u8,
    /// SR.BS.
    pub bus_off: bool,
    /// SR.ES.
    pub error_warning: bool,
    /// ECC/ALC/counters (PeliCAN only).
    pub capture: Option<Capture>,
}

/// A driver call that failed.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum CDriverError {
    /// A register access did not complete (the host's words).
    #[error("{call}: register access failed: {message}")]
    Host {
        /// The driver function.
        call: &'static str,
        /// What the host reported.
        message: String,
    },
    /// `CAN_ETIMEDOUT`: the controller did not enter or leave reset mode.
    #[error("{call}: the controller did not enter/leave reset mode (CAN_ETIMEDOUT)")]
    ResetTimeout {
        /// The driver function.
        call: &'static str,
    },
    /// `CAN_EBUSY`: SR.TBS = 0, the transmit buffer is locked.
    #[error("can_transmit: transmit buffer locked (CAN_EBUSY)")]
    Busy,
    /// `CAN_EINVAL`: the frame does not fit the view (extended id in BasicCAN).
    #[error("can_transmit: frame not representable in the {0:?} view (CAN_EINVAL)")]
    Invalid(View),
    /// `CAN_EBUSOFF`: SR.BS = 1.
    #[error("can_transmit: controller is bus-off (CAN_EBUSOFF)")]
    BusOff,
    /// A return code `can_driver.h` does not define.
    #[error("{call}: unknown return code {code}")]
    Code {
        /// The driver function.
        call: &'static str,
        /// The value returned.
        code: i32,
    },
    /// A call that needs `can_init` first.
    #[error("{0}: call init first")]
    NotInitialised(&'static str),
    /// The driver returned a frame that is not a CAN frame.
    #[error("can_receive returned an impossible frame: {0}")]
    BadFrame(String),
    /// Nothing arrived while polling.
    #[error("no frame after {polls} polls of can_receive")]
    NothingReceived {
        /// Polls made.
        polls: u32,
    },
}

/// The C driver, owning its host. `W` is [`Direct`] or [`ViaPio`].
pub struct CDriver<W> {
    wiring: Box<W>,
    dev: ffi::CanDev,
    initialised: bool,
}

impl<H: Host> CDriver<Direct<H>> {
    /// The driver on a host that answers 8-bit register accesses.
    pub fn new(host: H) -> Self {
        CDriver { wiring: Box::new(Direct { host, base: CAN_BASE, error: None }), dev: ffi::CanDev { base: CAN_BASE, ..Default::default() }, initialised: false }
    }
}

impl<P: PioHost> CDriver<ViaPio<P>> {
    /// The driver on the thesis PIO wiring: every register access is a
    /// Wishbone cycle bit-banged by the generated `can_sja_pio.h`.
    pub fn via_pio(host: P) -> Self {
        let mut bases = [0usize; 5];
        // SAFETY: writes exactly five entries into `bases`.
        unsafe { ffi::cdriver_pio_bases(bases.as_mut_ptr()) };
        CDriver { wiring: Box::new(ViaPio { host, bases, error: None }), dev: ffi::CanDev { base: CAN_BASE, ..Default::default() }, initialised: false }
    }

    /// Pulses the core's reset through the control PIO
    /// (`can_sja_pio_reset`); `hold` is a busy loop with no bus access, so
    /// the pulse lasts the two control-PIO writes.
    pub fn pio_reset(&mut self, hold: u64) -> Result<(), CDriverError> {
        self.call("can_sja_pio_reset", |_| {
            // SAFETY: C function without pointer arguments.
            unsafe { ffi::cdriver_pio_reset(hold as std::ffi::c_ulong) }
        })
    }
}

impl<W: Wiring> CDriver<W> {
    /// The host.
    pub fn host(&self) -> &W::Host {
        self.wiring.host()
    }

    /// The host, to advance time or inspect the bus between driver calls.
    pub fn host_mut(&mut self) -> &mut W::Host {
        self.wiring.host_mut()
    }

    /// Runs one C call with this driver's callbacks installed.
    fn call<R>(&mut self, name: &'static str, f: impl FnOnce(&mut ffi::CanDev) -> R) -> Result<R, CDriverError> {
        let _guard = C_LOCK.lock().unwrap_or_else(|p| p.into_inner());
        let w: &mut W = &mut self.wiring;
        sealed::Wiring::before(w, self.dev.base);
        let cb = sealed::Wiring::callbacks(w);
        let ctx = sealed::Wiring::ctx(w);
        // SAFETY: the callbacks match host_io_callback.h; ctx points into
        // the boxed wiring, which outlives the call and is only reached
        // through the callbacks until they are removed below.
        unsafe { ffi::host_io_set_callbacks(Some(cb.rd8), Some(cb.wr8), cb.rd32, cb.wr32, ctx) };
        let r = f(&mut self.dev);
        // SAFETY: NULL callbacks make any stray access abort in C, loudly.
        unsafe { ffi::host_io_set_callbacks(None, None, None, None, std::ptr::null_mut()) };
        match sealed::Wiring::take_error(&mut *self.wiring) {
            Some(message) => Err(CDriverError::Host { call: name, message }),
            None => Ok(r),
        }
    }

    fn check(call: &'static str, rc: c_int) -> Result<(), CDriverError> {
        match rc {
            ffi::CAN_OK => Ok(()),
            ffi::CAN_ETIMEDOUT => Err(CDriverError::ResetTimeout { call }),
            ffi::CAN_EBUSY => Err(CDriverError::Busy),
            ffi::CAN_EBUSOFF => Err(CDriverError::BusOff),
            code => Err(CDriverError::Code { call, code }),
        }
    }

    /// `can_init`: reset mode, view, timing, filters, operating mode.
    pub fn init(&mut self, view: View, cfg: &Config) -> Result<(), CDriverError> {
        let c = cfg.to_c();
        let v = match view {
            View::Basic => ffi::CAN_VIEW_BASIC,
            View::Peli => ffi::CAN_VIEW_PELI,
        };
        let base = self.dev.base;
        // SAFETY: dev and c are valid for the call.
        let rc = self.call("can_init", |dev| unsafe { ffi::can_init(dev, base, v, &c) })?;
        Self::check("can_init", rc)?;
        self.initialised = true;
        Ok(())
    }

    /// The view the driver is in (after `init`).
    pub fn view(&self) -> Option<View> {
        self.initialised.then_some(if self.dev.view == ffi::CAN_VIEW_PELI { View::Peli } else { View::Basic })
    }

    /// Data overruns the driver has seen and cleared.
    pub fn overruns(&self) -> u64 {
        // c_ulong is u32 on some targets.
        #[allow(clippy::useless_conversion)]
        u64::from(self.dev.overruns)
    }

    fn need_init(&self, call: &'static str) -> Result<View, CDriverError> {
        self.view().ok_or(CDriverError::NotInitialised(call))
    }

    /// `can_transmit`: loads the TX buffer and requests transmission.
    pub fn transmit(&mut self, frame: &CanFrame) -> Result<(), CDriverError> {
        let view = self.need_init("can_transmit")?;
        let c = to_c(frame);
        // SAFETY: dev and c are valid for the call.
        let rc = self.call("can_transmit", |dev| unsafe { ffi::can_transmit(dev, &c) })?;
        if rc == ffi::CAN_EINVAL {
            return Err(CDriverError::Invalid(view));
        }
        Self::check("can_transmit", rc)
    }

    /// `can_receive`: the waiting frame (buffer released), if any.
    pub fn receive(&mut self) -> Result<Option<CanFrame>, CDriverError> {
        self.need_init("can_receive")?;
        let mut c = ffi::CanFrameC::default();
        // SAFETY: dev and c are valid for the call.
        let rc = self.call("can_receive", |dev| unsafe { ffi::can_receive(dev, &mut c) })?;
        match rc {
            0 => Ok(None),
            1 => from_c(&c).map(Some),
            code => Err(CDriverError::Code { call: "can_receive", code }),
        }
    }

    /// Calls `can_receive` until a frame comes, at most `max_polls` times
    /// (each empty poll is one SR read, so simulated time passes).
    pub fn receive_polling(&mut self, max_polls: u32) -> Result<CanFrame, CDriverError> {
        for _ in 0..max_polls {
            if let Some(f) = self.receive()? {
                return Ok(f);
            }
        }
        Err(CDriverError::NothingReceived { polls: max_polls })
    }

    /// `can_read_errors`: SR, IR (consumed), and in PeliCAN ECC (re-armed),
    /// ALC and the error counters.
    pub fn read_errors(&mut self) -> Result<ErrorStatus, CDriverError> {
        self.need_init("can_read_errors")?;
        let mut e = ffi::CanErrorsC::default();
        // SAFETY: dev and e are valid for the call.
        let rc = self.call("can_read_errors", |dev| unsafe { ffi::can_read_errors(dev, &mut e) })?;
        Self::check("can_read_errors", rc)?;
        Ok(ErrorStatus {
            sr: e.sr,
            ir: e.ir,
            bus_off: e.bus_off != 0,
            error_warning: e.error_warning != 0,
            capture: (e.has_capture != 0).then_some(Capture { ecc: e.ecc, alc: e.alc, rxerr: e.rxerr, txerr: e.txerr }),
        })
    }

    /// `can_bus_off_recover`: leaves the reset mode bus-off forced.
    pub fn bus_off_recover(&mut self) -> Result<(), CDriverError> {
        self.need_init("can_bus_off_recover")?;
        // SAFETY: dev is valid for the call.
        let rc = self.call("can_bus_off_recover", |dev| unsafe { ffi::can_bus_off_recover(dev) })?;
        Self::check("can_bus_off_recover", rc)
    }
}

/// `can_ecc_kind`: the driver's name for ECC's error code ("bit", "form",
/// "stuff", "other").
pub fn ecc_kind(ecc: u8) -> &'static str {
    // SAFETY: can_ecc_kind returns a pointer to a static NUL-terminated literal.
    let s = unsafe { CStr::from_ptr(ffi::can_ecc_kind(ecc)) };
    match s.to_str().unwrap_or("other") {
        "bit" => "bit",
        "form" => "form",
        "stuff" => "stuff",
        _ => "other",
    }
}

fn to_c(f: &CanFrame) -> ffi::CanFrameC {
    let mut data = [0u8; 8];
    data[..f.data().len()].copy_from_slice(f.data());
    ffi::CanFrameC { id: f.raw_id(), extended: matches!(f.id(), Id::Extended(_)) as u8, rtr: f.is_remote_frame() as u8, dlc: f.dlc_raw(), data }
}

fn from_c(c: &ffi::CanFrameC) -> Result<CanFrame, CDriverError> {
    let id = if c.extended != 0 { CanFrame::ext_id(c.id) } else { CanFrame::std_id(c.id as u16).filter(|_| c.id <= 0x7FF) };
    let bad = || CDriverError::BadFrame(format!("{c:?}"));
    let id = id.ok_or_else(bad)?;
    let n = if c.rtr != 0 { 0 } else { c.dlc.min(8) as usize };
    CanFrame::with_dlc(id, c.rtr != 0, c.dlc, &c.data[..n]).ok_or_else(bad)
}
