//! A GTKWave save file (`.gtkw`) for the VCD of [`crate::wave`]: signals in
//! groups (decoded bus, CAN pins, reference model, host bus), frame fields
//! and model state as text traces, the primary marker on the first
//! divergence and the view centred on it, zoomed to a few bits around it.
//! `gtkwave run.gtkw` opens the VCD with that view.

use std::fmt::Write as _;
use std::path::Path;

/// Bits shown across the window around a divergence.
pub const BITS_IN_VIEW: u64 = 12;

/// Pixels of the wave pane the zoom is computed for (the window is
/// `WIDTH` wide, the signal names take the rest).
const WIDTH: u32 = 1400;
const WAVE_PANE: f64 = 900.0;

/// GTKWave trace flags (`@hex` lines): binary, hex, ASCII text; group
/// begin/end are blank traces with a name.
const BIN: &str = "@28";
const HEX: &str = "@22";
const TEXT: &str = "@2028";
const GROUP_BEGIN: &str = "@800200";
const GROUP_END: &str = "@1000200";

/// The groups: name, then (signal, flags).
fn groups() -> Vec<(&'static str, Vec<(&'static str, &'static str)>)> {
    vec![
        ("Decoded bus", vec![("bus", BIN), ("field", TEXT), ("sample_point", BIN)]),
        ("CAN pins (DUT)", vec![("tx_o", BIN), ("rx_i", BIN), ("irq_on", BIN), ("bus_off_on", BIN)]),
        ("Model (reference)", vec![("model_tx", BIN), ("model_rx", BIN), ("model_field", TEXT)]),
        (
            "Host bus",
            vec![
                ("wb_clk_i", BIN),
                ("wb_rst_i", BIN),
                ("wb_cyc_i", BIN),
                ("wb_stb_i", BIN),
                ("wb_we_i", BIN),
                ("wb_adr_i[7:0]", HEX),
                ("wb_dat_i[7:0]", HEX),
                ("wb_dat_o[7:0]", HEX),
                ("wb_ack_o", BIN),
            ],
        ),
        ("Clocks", vec![("clk_i", BIN), ("clkout_o", BIN)]),
    ]
}

/// GTKWave's zoom for `span_ps` across the wave pane. Measured with
/// GTKWave 3.3.118 on our 1 ps VCDs: a zoom of z shows 2^-z / 200 ps per
/// pixel (z = -14: 82 ps per pixel; the same for runs of 5 and 21 µs).
fn zoom_for(span_ps: u64) -> f64 {
    let per_px = (span_ps.max(1) as f64 / WAVE_PANE).max(0.01);
    -(per_px * 200.0).log2()
}

/// The save file for `vcd`. With `divergence_ps`, the marker is there and
/// the view shows [`BITS_IN_VIEW`] bit times of `bit_ps` around it; without,
/// the whole run (`end_ps`).
pub fn save_file(vcd: &Path, divergence_ps: Option<u64>, bit_ps: u64, end_ps: u64) -> String {
    let groups = groups();
    let groups: Vec<(&str, &[(&str, &str)])> =
        groups.iter().map(|(n, sigs)| (*n, sigs.as_slice())).collect();
    view(
        "cancosim view: groups, fields as text, marker on the first divergence",
        vcd,
        "cosim",
        &groups,
        divergence_ps,
        bit_ps,
        end_ps,
    )
}

/// How a trace is drawn in a [`view`] (GTKWave's `@` flags).
pub mod trace {
    /// One bit, binary.
    pub const BIN: &str = super::BIN;
    /// A vector in hex.
    pub const HEX: &str = super::HEX;
    /// A string signal as text.
    pub const TEXT: &str = super::TEXT;
}

/// A save file for any VCD: `groups` of (signal under `scope`, [`trace`]
/// flags), the primary marker at `marker_ps` with [`BITS_IN_VIEW`] bit
/// times of `bit_ps` around it, or the whole dump (`end_ps`) without one.
/// `gtkwave other.vcd this.gtkw` puts the same marker and view on another
/// dump of the same time line (signals it lacks are left out).
pub fn view(
    title: &str,
    vcd: &Path,
    scope: &str,
    groups: &[(&str, &[(&str, &str)])],
    marker_ps: Option<u64>,
    bit_ps: u64,
    end_ps: u64,
) -> String {
    let divergence_ps = marker_ps;
    let mut s = String::new();
    let _ = writeln!(s, "[*] {title}");
    let _ = writeln!(s, "[dumpfile] \"{}\"", vcd.display());
    let (start, span, marker) = match divergence_ps {
        Some(t) => {
            let span = BITS_IN_VIEW * bit_ps;
            // Centred; but GTKWave shows nothing past the end of the dump
            // (it starts the view at 0 instead), and a run that stops at
            // its first divergence ends a moment after it: then the view
            // ends with the dump, the marker near its right edge.
            let start = t.saturating_sub(span / 2).min(end_ps.saturating_sub(span));
            (start, span, t.to_string())
        }
        None => (0, end_ps.max(1), "-1".to_string()),
    };
    let _ = writeln!(s, "[timestart] {start}");
    let _ = writeln!(s, "[size] {WIDTH} 760");
    let _ = writeln!(s, "[pos] -1 -1");
    // Zoom, primary marker, then the 26 named markers (A..Z) unset.
    let _ = writeln!(s, "*{:.6} {marker}{}", zoom_for(span), " -1".repeat(26));
    let _ = writeln!(s, "[treeopen] {scope}.");
    let _ = writeln!(s, "[sst_width] 200");
    let _ = writeln!(s, "[signals_width] 200");
    let _ = writeln!(s, "[sst_expanded] 1");
    let _ = writeln!(s, "[sst_vpaned_height] 200");
    for (name, sigs) in groups {
        let _ = writeln!(s, "{GROUP_BEGIN}\n-{name}");
        for (sig, flags) in sigs.iter() {
            let _ = writeln!(s, "{flags}\n{scope}.{sig}");
        }
        let _ = writeln!(s, "{GROUP_END}\n-{name}");
    }
    let _ = writeln!(s, "[pattern_trace] 1\n[pattern_trace] 0");
    s
}

/// The save file's path next to a VCD: `x.vcd` -> `x.gtkw`.
pub fn path_for(vcd: &Path) -> std::path::PathBuf {
    vcd.with_extension("gtkw")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_view_puts_the_marker_and_its_signals_under_the_scope() {
        let sigs = [("divergence", trace::BIN), ("host_access", trace::TEXT)];
        let s = view("t", Path::new("x.vcd"), "sb", &[("G", &sigs)], Some(5_000_000), 1_000, 20_000_000);
        assert!(s.starts_with("[*] t\n[dumpfile] \"x.vcd\"\n"), "{s}");
        let marker = s.lines().find(|l| l.starts_with('*')).unwrap();
        assert_eq!(marker.split(' ').nth(1), Some("5000000"), "{s}");
        // 12 bits around the marker.
        assert!(s.contains(&format!("[timestart] {}\n", 5_000_000 - 6_000)), "{s}");
        assert!(s.contains("@28\nsb.divergence\n@2028\nsb.host_access\n"), "{s}");
        // The command line's view: its signals under `cosim`, no marker without a divergence.
        let c = save_file(Path::new("run.vcd"), None, 1_000, 20_000_000);
        assert!(c.contains("[*] cancosim view:") && c.contains("@28\ncosim.bus\n"), "{c}");
        assert_eq!(c.lines().find(|l| l.starts_with('*')).unwrap().split(' ').nth(1), Some("-1"));
    }
}
