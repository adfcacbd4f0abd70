//! `cocotbext.sja1000._native`: the Rust side of the cocotb extension.
//! Three small classes, one job each; the cocotb agents in Python
//! (`CanBus`, `CanMonitor`, `Sja1000Scoreboard`) drive them once per CAN
//! clock.
//!
//! - `Model`: the golden SJA1000 shadowing a DUT (`sja1000_model::Shadow`:
//!   the profile's access timing, the CLI's comparator, the diagnoser).
//! - `Node`: a golden SJA1000 node on the bus (sends and receives frames).
//! - `Decoder`: the bench's bit clock and the bit-stream decoder, fed the
//!   bus level once per CAN clock.
//! - `Faults`: bit flips, glitches and a stuck bus, with the command line's
//!   semantics, placed by frame bit or by field.

mod faults;

use can_proto::decode::{DecodeEvent, Decoder as BitDecoder};
use can_proto::timing::BusTiming;
use can_proto::{CanFrame, FrameTrait, Id};
use cosim::bitclock::BitClock;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use sja1000::Sja1000;
use sja1000::host::{self, Config};
use sja1000_model::{DutPins, Shadow};

/// A frame as Python sees it: (arbitration id, extended, remote, data).
type PyFrame = (u32, bool, bool, Vec<u8>);

fn frame_of(f: &CanFrame) -> PyFrame {
    let id = match f.id() {
        Id::Standard(s) => s.as_raw() as u32,
        Id::Extended(e) => e.as_raw(),
    };
    let data = if f.is_remote_frame() {
        Vec::new()
    } else {
        f.data().to_vec()
    };
    (id, f.is_extended(), f.is_remote_frame(), data)
}

fn make_frame(
    id: u32,
    data: &[u8],
    extended: bool,
    remote: bool,
    dlc: Option<u8>,
) -> PyResult<CanFrame> {
    let bad = |what: String| PyValueError::new_err(what);
    let ident: Id = if extended {
        CanFrame::ext_id(id)
            .ok_or_else(|| bad(format!("extended id 0x{id:X} does not fit 29 bits")))?
    } else {
        let raw = u16::try_from(id)
            .map_err(|_| bad(format!("standard id 0x{id:X} does not fit 11 bits")))?;
        CanFrame::std_id(raw)
            .ok_or_else(|| bad(format!("standard id 0x{id:X} does not fit 11 bits")))?
    };
    if data.len() > 8 {
        return Err(bad(format!(
            "{} data bytes: a CAN 2.0 frame holds at most 8",
            data.len()
        )));
    }
    let dlc = dlc.unwrap_or(data.len() as u8);
    if dlc > 15 {
        return Err(bad(format!("DLC {dlc} does not fit 4 bits")));
    }
    CanFrame::with_dlc(ident, remote, dlc, if remote { &[] } else { data }).ok_or_else(|| {
        bad(format!(
            "no CAN frame with id 0x{id:X}, DLC {dlc}, {} data bytes",
            data.len()
        ))
    })
}

/// The golden SJA1000 shadowing one DUT.
#[pyclass(unsendable, module = "cocotbext.sja1000._native")]
struct Model {
    inner: Shadow,
}

#[pymethods]
impl Model {
    /// `profile`: "rtl", "opencores-can", a .toml path, or "immediate";
    /// `can_hz`: the DUT's CAN clock.
    #[new]
    #[pyo3(signature = (profile = "rtl", can_hz = 24e6, name = None))]
    fn new(profile: &str, can_hz: f64, name: Option<&str>) -> PyResult<Self> {
        let made = if profile == "immediate" {
            Shadow::immediate(can_hz)
        } else {
            Shadow::new(profile, can_hz)
        };
        let mut inner = made.map_err(|e| PyValueError::new_err(e.to_string()))?;
        if let Some(n) = name {
            inner.set_test_name(n);
        }
        Ok(Model { inner })
    }

    /// The test's name, for the diagnosis's first line.
    fn set_test_name(&mut self, name: &str) {
        self.inner.set_test_name(name);
    }

    /// The host bus the accesses come through: "wishbone" (default),
    /// "avalon", "pio", "axi4-lite", "apb", "regport" or "motorola"; the
    /// model takes them at the CAN clock the profile declares for that bus.
    fn set_host_bus(&mut self, bus: &str) -> PyResult<()> {
        let Some(b) = sja1000_model::host_bus_named(bus) else {
            return Err(PyValueError::new_err(format!(
                "host bus {bus:?}: expected {}",
                sja1000_model::HOST_BUS_NAMES
            )));
        };
        self.inner.set_host_bus(b);
        Ok(())
    }

    /// The bench's time (ps) of the next CAN clock; later clocks are
    /// `period_ps` apart. Call again after clocks the model did not see.
    fn set_time_ps(&mut self, t_ps: u64) {
        self.inner.set_time_ps(t_ps);
    }

    /// The bench's CAN clock period (ps); 0 keeps the one from `can_hz`.
    fn set_period_ps(&mut self, period_ps: u64) {
        self.inner.set_period_ps(period_ps);
    }

    /// Time of the last CAN clock (ps) on the bench's time line.
    #[getter]
    fn now_ps(&self) -> u64 {
        self.inner.now()
    }

    /// Writes the scoreboard's events as a VCD at `vcd` (divergence,
    /// host accesses as the model took them, model events, frames) and,
    /// with `gtkw`, a GTKWave save file with the marker on the divergence.
    #[pyo3(signature = (vcd, gtkw = None))]
    fn write_markers(&self, vcd: &str, gtkw: Option<&str>) -> PyResult<()> {
        let io = |e: std::io::Error, p: &str| {
            pyo3::exceptions::PyOSError::new_err(format!("cannot write {p}: {e}"))
        };
        sja1000_model::markers::write_vcd(&self.inner, std::path::Path::new(vcd))
            .map_err(|e| io(e, vcd))?;
        if let Some(g) = gtkw {
            let text = sja1000_model::markers::save_file(&self.inner, std::path::Path::new(vcd));
            std::fs::write(g, text).map_err(|e| io(e, g))?;
        }
        Ok(())
    }

    /// Time (ps) of the primary marker: the first divergence, else a
    /// transmission request that never completed; None without either.
    #[getter]
    fn marker_ps(&self) -> Option<u64> {
        sja1000_model::markers::marker_ps(&self.inner)
    }

    /// The DUT's reset input.
    fn reset(&mut self) {
        self.inner.hard_reset();
    }

    /// A host access presented to the DUT, at the host edge it samples it.
    fn request(&mut self, write: bool, addr: u8, data: u8) {
        self.inner.request(write, addr, data);
    }

    /// A write the model takes now.
    fn write(&mut self, addr: u8, data: u8) {
        self.inner.write(addr, data);
    }

    /// A read the model takes now.
    fn read(&mut self, addr: u8) -> u8 {
        self.inner.read(addr)
    }

    /// The DUT's read data; returns the model's value.
    fn compare_read(&mut self, addr: u8, dut_data: u8) -> u8 {
        self.inner.compare_read(addr, dut_data)
    }

    /// One CAN clock with rx level `rx` and, to compare, the DUT's pins
    /// after it (None: not compared). Returns the model's tx.
    #[pyo3(signature = (rx, tx = None, irq_n = None, bus_on = None, compare = true))]
    fn clock(
        &mut self,
        rx: bool,
        tx: Option<bool>,
        irq_n: Option<bool>,
        bus_on: Option<bool>,
        compare: bool,
    ) -> bool {
        let pins = compare.then_some(DutPins { tx, irq_n, bus_on });
        self.inner.clock(rx, pins)
    }

    /// Register value without a read's side effects.
    fn peek(&self, addr: u8) -> u8 {
        self.inner.peek(addr)
    }

    /// End of the test: True if the run failed.
    fn finish(&mut self) -> bool {
        self.inner.finish()
    }

    #[getter]
    fn failed(&self) -> bool {
        self.inner.failed()
    }

    /// The diagnosis text, or None.
    #[getter]
    fn diagnosis(&self) -> Option<String> {
        self.inner.diagnosis().map(str::to_string)
    }

    #[getter]
    fn open_clocks(&self) -> u32 {
        self.inner.open_clocks()
    }

    #[getter]
    fn compared_reads(&self) -> u64 {
        self.inner.compared_reads()
    }

    #[getter]
    fn compared_bits(&self) -> u64 {
        self.inner.compared_bits()
    }

    #[getter]
    fn bits(&self) -> u64 {
        self.inner.bits()
    }

    /// The bus log in can-utils `candump -l` format, as `cancosim run
    /// --candump` writes it (frames on the DUT's rx, the model's error frames).
    #[pyo3(signature = (iface = "can0"))]
    fn candump_log(&self, iface: &str) -> String {
        self.inner.candump_log(iface)
    }

    /// The run record as JSON (what `cancosim diagnose` reads back).
    fn record_json(&self) -> String {
        self.inner.record().to_json()
    }

    #[getter]
    fn tolerances(&self) -> String {
        self.inner.tolerances().to_string()
    }
}

/// A golden SJA1000 node on the bus, configured (PeliCAN, accept all).
#[pyclass(unsendable, module = "cocotbext.sja1000._native")]
struct Node {
    m: Sja1000,
    tx: bool,
}

#[pymethods]
impl Node {
    #[new]
    #[pyo3(signature = (btr0 = 0x41, btr1 = 0x25, listen_only = false))]
    fn new(btr0: u8, btr1: u8, listen_only: bool) -> Self {
        let mut m = Sja1000::new();
        let cfg = Config {
            btr0,
            btr1,
            listen_only,
            ..Config::pelican()
        };
        host::configure(&mut m, &cfg);
        Node { m, tx: true }
    }

    /// Queues a frame (TX buffer + CMR.TR). False if the TX buffer is busy.
    #[pyo3(signature = (id, data, extended = false, remote = false, dlc = None))]
    fn send(
        &mut self,
        id: u32,
        data: Vec<u8>,
        extended: bool,
        remote: bool,
        dlc: Option<u8>,
    ) -> PyResult<bool> {
        let f = make_frame(id, &data, extended, remote, dlc)?;
        Ok(host::transmit(&mut self.m, &f, regmap::peli::cmr::TR).is_ok())
    }

    /// One CAN clock with bus level `rx`; returns the node's tx.
    fn clock(&mut self, rx: bool) -> bool {
        self.tx = self.m.clock(rx);
        self.tx
    }

    /// The next received frame, or None.
    fn recv(&mut self) -> Option<PyFrame> {
        host::receive(&mut self.m).map(|f| frame_of(&f))
    }

    #[getter]
    fn tx(&self) -> bool {
        self.tx
    }

    /// True while a transmission is pending (SR.TBS = 0).
    #[getter]
    fn busy(&self) -> bool {
        self.m.peek(2) & 0x04 == 0
    }

    #[getter]
    fn tec(&self) -> u8 {
        self.m.engine().tec() as u8
    }

    #[getter]
    fn rec(&self) -> u8 {
        self.m.engine().rec() as u8
    }

    /// Register value without side effects.
    fn peek(&self, addr: u8) -> u8 {
        self.m.peek(addr)
    }
}

/// The bench's bit clock (from BTR0/BTR1, hard-synchronised on every
/// recessive-to-dominant edge) and the bit-stream decoder.
#[pyclass(unsendable, module = "cocotbext.sja1000._native")]
struct Decoder {
    clock: BitClock,
    dec: BitDecoder,
}

#[pymethods]
impl Decoder {
    #[new]
    #[pyo3(signature = (btr0 = 0x41, btr1 = 0x25))]
    fn new(btr0: u8, btr1: u8) -> Self {
        Decoder {
            clock: BitClock::new(BusTiming::from_btr(btr0, btr1)),
            dec: BitDecoder::new(),
        }
    }

    /// One CAN clock with bus `level`; the events of a sample point, each a
    /// tuple: ("frame", (id, ext, remote, data), ack, start_bit, end_bit),
    /// ("error", kind, field, bit), ("field", field, bit), ("stuff", bit).
    fn clock(&mut self, py: Python<'_>, level: bool) -> PyResult<Vec<Py<PyAny>>> {
        let mut out = Vec::new();
        if !self.clock.clock(level) {
            return Ok(out);
        }
        for e in self.dec.push(level) {
            let o = match e {
                DecodeEvent::Frame(d) => {
                    ("frame", frame_of(&d.frame), d.ack, d.start_bit, d.end_bit)
                        .into_pyobject(py)?
                        .into_any()
                        .unbind()
                }
                DecodeEvent::Error { error, field, bit } => {
                    ("error", format!("{error:?}"), field.to_string(), bit)
                        .into_pyobject(py)?
                        .into_any()
                        .unbind()
                }
                DecodeEvent::FieldStart { field, bit } => ("field", field.to_string(), bit)
                    .into_pyobject(py)?
                    .into_any()
                    .unbind(),
                DecodeEvent::StuffBit { bit } => {
                    ("stuff", bit).into_pyobject(py)?.into_any().unbind()
                }
            };
            out.push(o);
        }
        Ok(out)
    }

    /// Bits sampled so far.
    #[getter]
    fn bits(&self) -> u64 {
        self.clock.bits()
    }
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Model>()?;
    m.add_class::<Node>()?;
    m.add_class::<Decoder>()?;
    m.add_class::<faults::Faults>()?;
    Ok(())
}
