//! Our own VCD (with the `vcd` crate), viewable in GTKWave: the DUT's
//! ports, the host pins, the bus, the reference model's tx/rx and sample
//! points, and the decoded frame fields as string signals. Verilator's own
//! trace of the DUT's internals is a separate file ([`crate::Dut::trace_open`]).

use std::fs::File;
use std::io::{self, BufWriter};
use std::path::Path;

use can_proto::Field;
use vcd::{IdCode, TimescaleUnit, Value, VarType};

/// Everything drawn at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WaveSample {
    /// `wb_clk_i` (or the Avalon `clk`).
    pub host_clk: bool,
    /// `clk_i` (or `can_clk`).
    pub can_clk: bool,
    /// Host reset.
    pub rst: bool,
    /// Wishbone pins as driven (Avalon DUTs: chipselect on stb/cyc).
    pub cyc: bool,
    /// `wb_stb_i`.
    pub stb: bool,
    /// `wb_we_i`.
    pub we: bool,
    /// `wb_adr_i`.
    pub adr: u8,
    /// `wb_dat_i`.
    pub dat_i: u8,
    /// `wb_dat_o`.
    pub dat_o: u8,
    /// `wb_ack_o` (Avalon: `!waitrequest` while selected).
    pub ack: bool,
    /// DUT `rx_i`.
    pub rx: bool,
    /// DUT `tx_o`.
    pub tx: bool,
    /// `irq_on`.
    pub irq_n: bool,
    /// `bus_off_on`.
    pub bus_on: bool,
    /// `clkout_o`.
    pub clkout: bool,
    /// Wired-AND bus level.
    pub bus: bool,
    /// Reference model tx (shadow: not on the bus).
    pub model_tx: bool,
    /// Reference model rx.
    pub model_rx: bool,
    /// One CAN clock high at each sample point.
    pub sample: bool,
    /// Decoded field of the bus (from the sampled bits).
    pub field: Option<Field>,
    /// The reference model's own field.
    pub model_field: Option<Field>,
}

/// A VCD writer over [`WaveSample`]s that writes only changes.
pub struct Wave {
    w: vcd::Writer<BufWriter<File>>,
    ids: Vec<IdCode>,
    prev: Option<WaveSample>,
}

const SCALARS: [&str; 16] = [
    "wb_clk_i",
    "clk_i",
    "wb_rst_i",
    "wb_cyc_i",
    "wb_stb_i",
    "wb_we_i",
    "wb_ack_o",
    "rx_i",
    "tx_o",
    "irq_on",
    "bus_off_on",
    "clkout_o",
    "bus",
    "model_tx",
    "model_rx",
    "sample_point",
];

fn field_text(f: Option<Field>) -> String {
    match f {
        // String values cannot contain spaces.
        Some(f) => format!("{f:?}"),
        None => "-".into(),
    }
}

impl Wave {
    /// Creates `path` and writes the header (timescale 1 ps).
    pub fn create(path: &Path) -> io::Result<Wave> {
        let mut w = vcd::Writer::new(BufWriter::new(File::create(path)?));
        w.timescale(1, TimescaleUnit::PS)?;
        w.add_module("cosim")?;
        let mut ids = Vec::new();
        for name in &SCALARS {
            ids.push(w.add_wire(1, name)?);
        }
        ids.push(w.add_wire(8, "wb_adr_i")?);
        ids.push(w.add_wire(8, "wb_dat_i")?);
        ids.push(w.add_wire(8, "wb_dat_o")?);
        ids.push(w.add_var(VarType::String, 1, "field", None)?);
        ids.push(w.add_var(VarType::String, 1, "model_field", None)?);
        w.upscope()?;
        w.enddefinitions()?;
        Ok(Wave { w, ids, prev: None })
    }

    /// Writes the changes at `t_ps`.
    pub fn dump(&mut self, t_ps: u64, s: &WaveSample) -> io::Result<()> {
        if self.prev.as_ref() == Some(s) {
            return Ok(());
        }
        let p = self.prev;
        self.w.timestamp(t_ps)?;
        let bits = [
            s.host_clk, s.can_clk, s.rst, s.cyc, s.stb, s.we, s.ack, s.rx, s.tx, s.irq_n, s.bus_on,
            s.clkout, s.bus, s.model_tx, s.model_rx, s.sample,
        ];
        let old = p.map(|p| {
            [
                p.host_clk, p.can_clk, p.rst, p.cyc, p.stb, p.we, p.ack, p.rx, p.tx, p.irq_n,
                p.bus_on, p.clkout, p.bus, p.model_tx, p.model_rx, p.sample,
            ]
        });
        for (k, b) in bits.iter().enumerate() {
            if old.is_none_or(|o| o[k] != *b) {
                self.w.change_scalar(self.ids[k], Value::from(*b))?;
            }
        }
        let bytes = [s.adr, s.dat_i, s.dat_o];
        let old_bytes = p.map(|p| [p.adr, p.dat_i, p.dat_o]);
        for (k, v) in bytes.iter().enumerate() {
            if old_bytes.is_none_or(|o| o[k] != *v) {
                let vals = (0..8).rev().map(|i| Value::from(v >> i & 1 != 0));
                self.w.change_vector(self.ids[16 + k], vals)?;
            }
        }
        if p.is_none_or(|p| p.field != s.field) {
            self.w.change_string(self.ids[19], &field_text(s.field))?;
        }
        if p.is_none_or(|p| p.model_field != s.model_field) {
            self.w
                .change_string(self.ids[20], &field_text(s.model_field))?;
        }
        self.prev = Some(*s);
        Ok(())
    }

    /// Flushes the file.
    pub fn flush(&mut self) -> io::Result<()> {
        self.w.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_a_parseable_vcd_with_string_fields_and_only_changes() {
        let path = std::env::temp_dir().join(format!("cosim-wave-{}.vcd", std::process::id()));
        let mut w = Wave::create(&path).unwrap();
        let mut s = WaveSample {
            bus: true,
            ..WaveSample::default()
        };
        w.dump(0, &s).unwrap();
        w.dump(5, &s).unwrap(); // no change: no timestamp
        s.bus = false;
        s.adr = 0xA5;
        s.field = Some(Field::Sof);
        w.dump(10, &s).unwrap();
        w.flush().unwrap();
        drop(w);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("$timescale 1 ps $end"), "{text}");
        assert!(!text.contains("#5\n"), "unchanged instant skipped");
        assert!(text.contains("sSof "), "field as a string signal: {text}");
        assert!(text.contains("b10100101 "), "vector value: {text}");
        // The vcd crate reads it back.
        let mut p = vcd::Parser::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let h = p.parse_header().unwrap();
        assert!(h.find_var(&["cosim", "field"]).is_some());
        let n = p.count();
        assert!(n > 10, "{n} commands");
        let _ = std::fs::remove_file(&path);
    }
}
