//! The golden SJA1000 as a scoreboard inside a bench the kit does not run:
//! a C ABI (`include/sja1000_model.h`, for SystemVerilog DPI-C, C or C++
//! test benches) and the Rust type under it, [`Shadow`], which the Python
//! extension (cocotb) uses too.
//!
//! The bench reports what its DUT does, when it does it: each CAN clock
//! (rx level, the DUT's pins), each host access at the host edge that
//! presents it, and the data of each read at its ack. The model takes an
//! access when the core's profile says the core does (`rtl`: the 3rd CAN
//! edge for a read, the 4th for a write), the comparator is the CLI's
//! (tx at sample points, SR/IR reads with the profile's status tolerance,
//! irq and bus-off pins), and the first divergence, or a transmission
//! still pending at [`Shadow::finish`], becomes the diagnoser's text.
//!
//! ```
//! use sja1000_model::Shadow;
//! let mut m = Shadow::immediate(24e6).unwrap();
//! m.write(0, 0x01); // reset mode
//! m.write(31, 0x80); // PeliCAN
//! assert_eq!(m.compare_read(31, 0x80), 0x80);
//! assert!(!m.failed());
//! m.compare_read(31, 0x00); // the DUT says PeliCAN is off
//! assert!(m.diagnosis().unwrap().contains("CDR"));
//! ```

pub mod markers;
mod shadow;

pub use shadow::{DutPins, Shadow, ShadowError};

/// The host bus named `name` as the benches name it (`"wishbone"`,
/// `"avalon"`, `"pio"`, `"axi4-lite"`, `"apb"`, `"regport"`, `"motorola"`;
/// any case), for
/// [`Shadow::set_host_bus`].
pub fn host_bus_named(name: &str) -> Option<diagnose::HostBus> {
    use diagnose::HostBus;
    Some(match name.to_ascii_lowercase().as_str() {
        "wishbone" => HostBus::Wishbone,
        "avalon" => HostBus::Avalon,
        "pio" => HostBus::Pio,
        "axi4-lite" | "axi4lite" => HostBus::Axi4Lite,
        "apb" => HostBus::Apb,
        "regport" => HostBus::Regport,
        "motorola" => HostBus::Motorola,
        _ => return None,
    })
}

/// The names [`host_bus_named`] takes, for a message.
pub const HOST_BUS_NAMES: &str =
    "\"wishbone\", \"avalon\", \"pio\", \"axi4-lite\", \"apb\", \"regport\" or \"motorola\"";

use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char, c_double, c_int};

/// A model behind a C handle: the shadow and the last strings handed out.
pub struct Sja1000Model {
    shadow: Shadow,
    diagnosis: CString,
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_error(e: &str) {
    let c = CString::new(e.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|l| *l.borrow_mut() = c);
}

/// Borrows the model behind `m`; None for a null handle.
///
/// # Safety
/// `m` is NULL or a live handle (the callers' own contract).
unsafe fn model<'a>(m: *mut Sja1000Model) -> Option<&'a mut Sja1000Model> {
    // SAFETY: a non-null handle comes from `sja1000_model_new` and is
    // live until `sja1000_model_free` (the header's contract).
    unsafe { m.as_mut() }
}

/// A new model for a DUT described by `profile` (a shipped profile name
/// such as "rtl", a `.toml` path; NULL or "" = "rtl") whose CAN clock
/// runs at `can_hz`. NULL on error: `sja1000_model_last_error` says why.
///
/// # Safety
/// `profile` is NULL or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_new(
    profile: *const c_char,
    can_hz: c_double,
) -> *mut Sja1000Model {
    let name = if profile.is_null() {
        String::new()
    } else {
        // SAFETY: the caller passes a NUL-terminated string (header).
        match unsafe { CStr::from_ptr(profile) }.to_str() {
            Ok(s) => s.to_string(),
            Err(_) => {
                set_error("profile name is not UTF-8");
                return std::ptr::null_mut();
            }
        }
    };
    let made = if name == "immediate" {
        Shadow::immediate(can_hz)
    } else {
        Shadow::new(&name, can_hz)
    };
    match made {
        Ok(shadow) => Box::into_raw(Box::new(Sja1000Model {
            shadow,
            diagnosis: CString::default(),
        })),
        Err(e) => {
            set_error(&e.to_string());
            std::ptr::null_mut()
        }
    }
}

/// Why the last `sja1000_model_new` of this thread returned NULL.
#[unsafe(no_mangle)]
pub extern "C" fn sja1000_model_last_error() -> *const c_char {
    LAST_ERROR.with(|l| l.borrow().as_ptr())
}

/// Frees a model (NULL is allowed).
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_free(m: *mut Sja1000Model) {
    if !m.is_null() {
        // SAFETY: made by Box::into_raw in sja1000_model_new, freed once.
        drop(unsafe { Box::from_raw(m) });
    }
}

/// The test's name, for the diagnosis's first line (NULL is ignored).
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`; `name` is NULL or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_set_name(m: *mut Sja1000Model, name: *const c_char) {
    if let Some(m) = unsafe { model(m) }
        && !name.is_null()
    {
        // SAFETY: the caller passes a NUL-terminated string (header).
        let n = unsafe { CStr::from_ptr(name) }.to_string_lossy();
        m.shadow.set_test_name(&n);
    }
}

/// The host bus the accesses come through: "wishbone" (default), "avalon",
/// "pio", "axi4-lite", "apb", "regport" or "motorola"; the model takes them
/// at the CAN clock the profile declares for that bus. 0, or -1 for an
/// unknown name (the reason in `sja1000_model_last_error`) or a NULL
/// argument.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`; `name` is NULL or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_set_host_bus(
    m: *mut Sja1000Model,
    name: *const c_char,
) -> c_int {
    let Some(m) = (unsafe { model(m) }) else {
        return -1;
    };
    if name.is_null() {
        set_error("host bus: NULL name");
        return -1;
    }
    // SAFETY: the caller passes a NUL-terminated string (header).
    let n = unsafe { CStr::from_ptr(name) }.to_string_lossy();
    match host_bus_named(&n) {
        Some(b) => {
            m.shadow.set_host_bus(b);
            0
        }
        None => {
            set_error(&format!("host bus {n:?}: expected {HOST_BUS_NAMES}"));
            -1
        }
    }
}

/// Hardware reset of the model (the DUT's reset input).
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_reset(m: *mut Sja1000Model) {
    if let Some(m) = unsafe { model(m) } {
        m.shadow.hard_reset();
    }
}

/// One CAN clock (a rising edge of the DUT's clk_i) with rx level `rx`
/// (1 = recessive), nothing compared. Returns the model's tx.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_clock(m: *mut Sja1000Model, rx: c_int) -> c_int {
    unsafe { model(m) }.map_or(1, |m| m.shadow.clock(rx != 0, None) as c_int)
}

/// One CAN clock with rx level `rx`, then the DUT's pins compared with the
/// model's: `tx_o` at sample points (the profile's tx-edge and SOF
/// tolerances), `irq_on` and `bus_off_on` (active low / high while on the
/// bus) within the pin tolerance. A pin given as -1 is not compared.
/// Returns the model's tx.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_clock_compare(
    m: *mut Sja1000Model,
    rx: c_int,
    dut_tx: c_int,
    dut_irq_n: c_int,
    dut_bus_on: c_int,
) -> c_int {
    let Some(m) = (unsafe { model(m) }) else {
        return 1;
    };
    let pin = |v: c_int| (v >= 0).then_some(v != 0);
    let dut = DutPins {
        tx: pin(dut_tx),
        irq_n: pin(dut_irq_n),
        bus_on: pin(dut_bus_on),
    };
    m.shadow.clock(rx != 0, Some(dut)) as c_int
}

/// A host access the DUT has just seen presented (`write` 1 = write),
/// reported at the host clock edge at which the DUT samples the request.
/// The model takes it at the CAN clock the profile declares.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_request(
    m: *mut Sja1000Model,
    write: c_int,
    addr: u8,
    data: u8,
) {
    if let Some(m) = unsafe { model(m) } {
        m.shadow.request(write != 0, addr, data);
    }
}

/// A write the model takes now.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_write(m: *mut Sja1000Model, addr: u8, data: u8) {
    if let Some(m) = unsafe { model(m) } {
        m.shadow.write(addr, data);
    }
}

/// A read the model takes now; its value (-1 for a NULL handle).
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_read(m: *mut Sja1000Model, addr: u8) -> c_int {
    unsafe { model(m) }.map_or(-1, |m| m.shadow.read(addr) as c_int)
}

/// The DUT's read of `addr` returned `dut_data` (at its ack): compared
/// with the model's value of the same read (SR and IR within the status
/// tolerance). Returns the model's value (-1 for a NULL handle). Check
/// `sja1000_model_failed` after it and after each clock: an SR read may
/// diverge only when its window closes.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_compare_read(
    m: *mut Sja1000Model,
    addr: u8,
    dut_data: u8,
) -> c_int {
    unsafe { model(m) }.map_or(-1, |m| m.shadow.compare_read(addr, dut_data) as c_int)
}

/// CAN clocks still needed before every comparison made so far is judged.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_open_clocks(m: *mut Sja1000Model) -> c_int {
    unsafe { model(m) }.map_or(0, |m| m.shadow.open_clocks() as c_int)
}

/// End of the test: a transmission still pending becomes a diagnosis.
/// Returns 1 if the run failed (a divergence or that), else 0.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_finish(m: *mut Sja1000Model) -> c_int {
    unsafe { model(m) }.map_or(1, |m| m.shadow.finish() as c_int)
}

/// 1 once the DUT diverged from the model (or `finish` found a stuck
/// transfer), else 0.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_failed(m: *mut Sja1000Model) -> c_int {
    unsafe { model(m) }.map_or(1, |m| m.shadow.failed() as c_int)
}

/// The diagnosis text ("" if none): what happened, figures, root cause,
/// fix, the profile and tolerances. Valid until the next call on `m`.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_diagnosis(m: *mut Sja1000Model) -> *const c_char {
    static EMPTY: &CStr = c"";
    let Some(m) = (unsafe { model(m) }) else {
        return EMPTY.as_ptr();
    };
    m.diagnosis =
        CString::new(m.shadow.diagnosis().unwrap_or("").replace('\0', " ")).unwrap_or_default();
    m.diagnosis.as_ptr()
}

/// Register value without a read's side effects.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_peek(m: *mut Sja1000Model, addr: u8) -> c_int {
    unsafe { model(m) }.map_or(-1, |m| m.shadow.peek(addr) as c_int)
}

/// Register reads compared so far.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_compared_reads(m: *mut Sja1000Model) -> u64 {
    unsafe { model(m) }.map_or(0, |m| m.shadow.compared_reads())
}

/// Sample points at which tx was compared so far.
///
/// # Safety
/// `m` is NULL or a live handle from `sja1000_model_new`, not used by another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sja1000_model_compared_bits(m: *mut Sja1000Model) -> u64 {
    unsafe { model(m) }.map_or(0, |m| m.shadow.compared_bits())
}
