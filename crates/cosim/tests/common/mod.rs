//! The golden model as a DUT with one behaviour altered, for the tests of
//! the comparator and the waivers: a DUT that differs from the reference in
//! a known way, without a Verilator build.

// each test uses some of these helpers, not all
#![allow(dead_code)]

use bfm::{WbMasterOut, WbSlaveOut};
use cosim::model::ModelDut;
use cosim::{CanPins, Dut};

/// Host writes the wrapper has seen, (address, data) in order.
pub type Writes = Vec<(u8, u8)>;

type AlterWrite = Box<dyn Fn(&mut WbMasterOut) + Send>;
type AlterRead = Box<dyn Fn(u8, u8, &Writes) -> u8 + Send>;

/// The golden model behind the Wishbone pins, with the host's writes and
/// the data of the reads it acknowledges passed through two functions.
pub struct AlteredModel {
    name: String,
    inner: ModelDut,
    wb_in: WbMasterOut,
    host_clk: bool,
    writes: Writes,
    write: AlterWrite,
    read: AlterRead,
}

impl AlteredModel {
    /// The model unaltered, under `name` (for reports).
    pub fn new(name: &str) -> Self {
        Self {
            name: name.into(),
            inner: ModelDut::new(),
            wb_in: WbMasterOut::default(),
            host_clk: false,
            writes: Writes::new(),
            write: Box::new(|_| {}),
            read: Box::new(|_, d, _| d),
        }
    }
    /// What the model receives instead of the host's pins.
    pub fn on_write(mut self, f: impl Fn(&mut WbMasterOut) + Send + 'static) -> Self {
        self.write = Box::new(f);
        self
    }
    /// The data of an acknowledged read: `f(address, model's data, writes so far)`.
    pub fn on_read(mut self, f: impl Fn(u8, u8, &Writes) -> u8 + Send + 'static) -> Self {
        self.read = Box::new(f);
        self
    }
}

impl Dut for AlteredModel {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn set_reset(&mut self, on: bool) {
        self.inner.set_reset(on);
    }
    fn set_wb(&mut self, m: &WbMasterOut) {
        self.wb_in = *m;
        let mut m = *m;
        (self.write)(&mut m);
        self.inner.set_wb(&m);
    }
    fn wb(&self) -> WbSlaveOut {
        let mut o = self.inner.wb();
        if o.ack && !self.wb_in.we {
            o.dat = (self.read)(self.wb_in.adr, o.dat, &self.writes);
        }
        o
    }
    fn set_rx(&mut self, rx: bool) {
        self.inner.set_rx(rx);
    }
    fn can(&self) -> CanPins {
        self.inner.can()
    }
    fn eval(&mut self, host_clk: bool, can_clk: bool) {
        let w = self.wb_in;
        // a held strobe spans several edges: equal writes in a row are one entry
        if host_clk && !self.host_clk && w.cyc && w.stb && w.we && self.writes.last() != Some(&(w.adr, w.dat)) {
            self.writes.push((w.adr, w.dat));
        }
        self.host_clk = host_clk;
        self.inner.eval(host_clk, can_clk);
    }
}
