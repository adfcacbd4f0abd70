//! The project's side of the Verilator bridge (`vbridge`): the tops
//! `build.rs` links in (our RTL and the fixtures), where run-time builds
//! are cached, and the CAN test bench's inner loop (several instants per
//! foreign call, see [`Batch`]).

use std::ffi::c_void;
use std::path::PathBuf;

use vbridge::{BridgeError, CompiledCore, ExternalCore, Model, Port};

include!(concat!(env!("OUT_DIR"), "/bundled.rs"));

/// Names of the tops compiled into this crate (fixtures, and `can_top` /
/// `can_avalon` when `rtl/` verilated).
pub fn bundled_tops() -> Vec<&'static str> {
    BUNDLED.iter().map(|(n, _)| *n).collect()
}

/// A fresh instance of a bundled top (`can_top`, `can_avalon`, or a
/// fixture such as `cosim_echo`). `trace` enables VCD tracing (it must be
/// chosen before construction; it costs a little speed).
pub fn bundled(name: &str, trace: bool) -> Result<Model, BridgeError> {
    // SAFETY: build.rs generated every entry from the shim of that top.
    unsafe { Model::from_table(BUNDLED, name, trace) }.map_err(|e| match e {
        BridgeError::UnknownTop { name, available } => BridgeError::UnknownTop {
            name,
            available: format!(
                "{available}. (The RTL tops are missing when rtl/ did not verilate at build time.)"
            ),
        },
        e => e,
    })
}

/// Where run-time builds are cached: `$COSIM_CACHE_DIR`, else
/// `$XDG_CACHE_HOME/sja1000-cosim`, else `~/.cache/sja1000-cosim`.
pub fn cache_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("COSIM_CACHE_DIR") {
        return PathBuf::from(d);
    }
    if let Some(d) = std::env::var_os("XDG_CACHE_HOME") {
        return PathBuf::from(d).join("sja1000-cosim");
    }
    if let Some(h) = std::env::var_os("HOME") {
        return PathBuf::from(h).join(".cache/sja1000-cosim");
    }
    std::env::temp_dir().join("sja1000-cosim")
}

/// Builds an external core (or loads it from [`cache_dir`]) with the test
/// bench's inner loop, as every DUT built at run time needs it.
pub fn build_external(core: &ExternalCore) -> Result<CompiledCore, BridgeError> {
    let mut core = core.clone();
    core.inner_loop = Some(crate::batch_shim::batch_loop_cpp().to_string());
    core.build_in(&cache_dir())
}

/// The ports a batch drives and watches (all of one model, 8 bits or fewer).
#[derive(Clone, Copy, Debug)]
pub(crate) struct BatchPins {
    pub(crate) host_clk: Port,
    pub(crate) can_clk: Port,
    pub(crate) rx: Port,
    pub(crate) tx: Port,
    pub(crate) irq: Port,
    pub(crate) bus_off: Port,
    pub(crate) clkout: Port,
    pub(crate) ack: Port,
    pub(crate) dat: Port,
}

/// Several instants in one foreign call, for stretches in which nothing
/// but the two clocks and the DUT's own tx drive its inputs (the host
/// master idle, no other node, no fault on rx). Per instant `k`,
/// `levels[k]` has bit 0 the host clock level, bit 1 the CAN clock level,
/// bit 2 "the CAN clock rises": then `rx` takes `rx_mode` (0 or 1), or
/// `tx` (2), before the eval; other bits are the caller's (ignored).
/// After the eval, `out[k]` gets bit 0 `tx`, bit 1 `irq`, bit 2 `bus_off`,
/// bit 3 `clkout` (nonzero = 1). The call returns after an instant whose
/// `ack` or `dat` differs from before the call, or whose `irq` equals
/// `stop_irq` (2: never), so the caller can replay every instant's
/// outputs exactly. Layout shared with [`crate::batch_shim`].
#[repr(C)]
struct Batch {
    host_clk: *mut u8,
    can_clk: *mut u8,
    rx: *mut u8,
    tx: *const u8,
    irq: *const u8,
    bus_off: *const u8,
    clkout: *const u8,
    ack: *const u8,
    dat: *const u8,
    levels: *const u8,
    out: *mut u8,
    n: u32,
    rx_mode: u8,
    stop_irq: u8,
}

/// Makes `levels.len()` instants in one foreign call (see [`Batch`];
/// `rx`: the level `rx` takes at each CAN rising edge, `None`: `tx`);
/// returns how many were made (it stops early after an instant that
/// changed `ack` or `dat`, or whose `irq` equals `stop_irq`).
///
/// # Safety
/// Every port of `pins` belongs to `m` and is 8 bits or fewer; `m` was
/// built with the inner loop of [`crate::batch_shim`] (every bundled top
/// and [`build_external`] are); `out` is at least as long as `levels`.
#[inline]
pub(crate) unsafe fn run_batch(
    m: &mut Model,
    pins: &BatchPins,
    levels: &[u8],
    out: &mut [u8],
    rx: Option<bool>,
    stop_irq: Option<bool>,
) -> usize {
    debug_assert!(out.len() >= levels.len());
    let b = Batch {
        host_clk: pins.host_clk.as_ptr(),
        can_clk: pins.can_clk.as_ptr(),
        rx: pins.rx.as_ptr(),
        tx: pins.tx.as_ptr(),
        irq: pins.irq.as_ptr(),
        bus_off: pins.bus_off.as_ptr(),
        clkout: pins.clkout.as_ptr(),
        ack: pins.ack.as_ptr(),
        dat: pins.dat.as_ptr(),
        levels: levels.as_ptr(),
        out: out.as_mut_ptr(),
        n: levels.len() as u32,
        rx_mode: rx.map_or(2, |v| v as u8),
        stop_irq: stop_irq.map_or(2, |v| v as u8),
    };
    // SAFETY: the batch's pointers are this model's byte-sized ports
    // (caller's contract) and the two buffers; the loop is ours.
    unsafe { m.run_inner_loop(&b as *const Batch as *const c_void) as usize }
}
