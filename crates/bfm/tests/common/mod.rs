//! Shared test bench: steps a master against a target under a monitor,
//! following the crate's stepping contract; a thread-local log capture.
#![allow(dead_code)]

use std::cell::RefCell;
use std::sync::Once;

use bfm::{
    AvMasterOut, AvSlaveOut, AvalonMonitor, BfmError, HostBusTarget, HostMaster, OpHandle,
    OpResult, Pause, Violation, WbMasterOut, WbSlaveOut, WishboneMonitor, cycle_pause,
};

/// Anything that watches one cycle of pins.
pub trait Watch<O, I> {
    fn watch(&mut self, cycle: u64, m: &O, s: &I) -> Vec<Violation>;
}

impl Watch<WbMasterOut, WbSlaveOut> for WishboneMonitor {
    fn watch(&mut self, cycle: u64, m: &WbMasterOut, s: &WbSlaveOut) -> Vec<Violation> {
        self.observe(cycle, m, s)
    }
}

impl Watch<AvMasterOut, AvSlaveOut> for AvalonMonitor {
    fn watch(&mut self, cycle: u64, m: &AvMasterOut, s: &AvSlaveOut) -> Vec<Violation> {
        self.observe(cycle, m, s)
    }
}

/// No monitor.
pub struct NoWatch;
impl<O, I> Watch<O, I> for NoWatch {
    fn watch(&mut self, _: u64, _: &O, _: &I) -> Vec<Violation> {
        Vec::new()
    }
}

/// Master + target + monitor, stepped together.
pub struct Bench<M: HostMaster, T, W> {
    pub master: M,
    pub target: T,
    pub watch: W,
    pub cycle: u64,
    pub violations: Vec<Violation>,
}

impl<M, T, W> Bench<M, T, W>
where
    M: HostMaster,
    T: HostBusTarget<M::Out, M::In>,
    W: Watch<M::Out, M::In>,
{
    pub fn new(master: M, target: T, watch: W) -> Self {
        Self {
            master,
            target,
            watch,
            cycle: 0,
            violations: Vec::new(),
        }
    }

    /// One host cycle, exactly as the kernel does it.
    pub fn step(&mut self) {
        let m = self.master.outputs();
        let s = self.target.cycle(&m);
        self.master.on_edge(&s);
        let v = self.watch.watch(self.cycle, &m, &s);
        self.violations.extend(v);
        self.cycle += 1;
    }

    pub fn steps(&mut self, n: u64) {
        for _ in 0..n {
            self.step();
        }
    }

    /// Step until `h` completes (bounded: fails the test rather than hang).
    pub fn wait(&mut self, h: OpHandle) -> Result<OpResult, BfmError> {
        for _ in 0..1_000_000 {
            if let Some(r) = self.master.poll(h) {
                return r;
            }
            self.step();
        }
        panic!("{h} did not complete within 1e6 cycles: the timeout did not fire");
    }
}

/// The two pause settings of every BFM test: none, and 1-1-1-0.
/// A named pause setting.
pub type PauseSetting = (&'static str, fn() -> Option<Pause>);

pub fn pause_settings() -> [PauseSetting; 2] {
    [("none", || None), ("1-1-1-0", || Some(cycle_pause()))]
}

/// {master pause} x {target backpressure}, each none or 1-1-1-0.
pub fn matrix() -> Vec<(String, Option<Pause>, Option<Pause>)> {
    let mut v = Vec::new();
    for (mn, mp) in pause_settings() {
        for (tn, tp) in pause_settings() {
            v.push((format!("idle {mn}, backpressure {tn}"), mp(), tp()));
        }
    }
    v
}

thread_local! {
    static LOGS: RefCell<Vec<(log::Level, String)>> = const { RefCell::new(Vec::new()) };
}

struct Capture;
impl log::Log for Capture {
    fn enabled(&self, _: &log::Metadata) -> bool {
        true
    }
    fn log(&self, r: &log::Record) {
        LOGS.with(|l| l.borrow_mut().push((r.level(), r.args().to_string())));
    }
    fn flush(&self) {}
}

static INIT: Once = Once::new();
static CAPTURE: Capture = Capture;

/// Install the capturing logger (once per test binary) and clear this
/// thread's records.
pub fn capture_logs() {
    INIT.call_once(|| {
        log::set_logger(&CAPTURE).expect("logger");
        log::set_max_level(log::LevelFilter::Debug);
    });
    LOGS.with(|l| l.borrow_mut().clear());
}

/// This thread's log records so far.
pub fn logs() -> Vec<(log::Level, String)> {
    LOGS.with(|l| l.borrow().clone())
}
