//! `decode`: annotate a CAN bit stream with its fields, frames and errors.
//! Input is either a bit list ("0101...", one char per bit time; blanks and
//! `_` ignored) or a VCD file with a signal sampled at the bit timing's
//! sample point, re-aligned on every recessive-to-dominant edge as a CAN
//! controller's hard sync does.

use anyhow::{Context, bail};
use can_proto::decode::{DecodeEvent, Decoder};
use can_proto::timing::BusTiming;
use std::path::PathBuf;

/// Arguments of `cancosim decode`.
#[derive(clap::Args)]
pub struct Args {
    /// A file holding a bit list, or a `.vcd` waveform.
    #[arg(conflicts_with = "bits")]
    input: Option<PathBuf>,
    /// A bit list given inline, e.g. "11111111111 0101001010010000010101010...".
    #[arg(long)]
    bits: Option<String>,
    /// VCD: the signal to decode (its reference name, e.g. tx_o or bus).
    #[arg(long, default_value = "tx_o")]
    signal: String,
    /// VCD: the CAN clock, to turn BTR0/BTR1 into a bit time.
    #[arg(long, default_value = "24MHz", value_parser = super::parse_si)]
    clock: u32,
    /// VCD: BTR0 of the bus.
    #[arg(long, default_value = "0x41", value_parser = super::parse_byte)]
    btr0: u8,
    /// VCD: BTR1 of the bus.
    #[arg(long, default_value = "0x25", value_parser = super::parse_byte)]
    btr1: u8,
    /// Show stuff bits and every field start, not only frames and errors.
    #[arg(long)]
    verbose: bool,
}

/// Runs the subcommand; returns 1 when the stream holds an error.
pub fn run(a: Args) -> anyhow::Result<i32> {
    let levels = match (&a.input, &a.bits) {
        (_, Some(s)) => parse_bit_list(s)?,
        (Some(p), None) if p.extension().is_some_and(|e| e == "vcd") => {
            let t = BusTiming::from_btr(a.btr0, a.btr1);
            let bit_ps = 1e12 * t.clocks_per_bit() as f64 / a.clock as f64;
            vcd_levels(p, &a.signal, bit_ps, t.sample_point())?
        }
        (Some(p), None) => {
            let s = std::fs::read_to_string(p).with_context(|| format!("reading {}", p.display()))?;
            parse_bit_list(&s)?
        }
        (None, None) => bail!("give a file (bit list or .vcd) or --bits"),
    };
    let mut dec = Decoder::new();
    let (mut frames, mut errors) = (0, 0);
    for l in levels {
        for ev in dec.push(l) {
            match ev {
                DecodeEvent::Frame(_) => frames += 1,
                DecodeEvent::Error { .. } => errors += 1,
                DecodeEvent::StuffBit { .. } | DecodeEvent::FieldStart { .. } if !a.verbose => continue,
                _ => {}
            }
            println!("{ev}");
        }
    }
    println!("{frames} frame(s), {errors} error(s)");
    Ok(if errors > 0 { 1 } else { 0 })
}

fn parse_bit_list(s: &str) -> anyhow::Result<Vec<bool>> {
    let mut v = Vec::with_capacity(s.len());
    for (i, c) in s.chars().enumerate() {
        match c {
            '0' => v.push(false),
            '1' => v.push(true),
            c if c.is_whitespace() || c == '_' => {}
            c => bail!("character {} ('{c}') is not a bit: a bit list holds only 0, 1, blanks and _", i + 1),
        }
    }
    Ok(v)
}

/// Samples `signal` of a VCD once per bit at `sample_point` of the bit, the
/// bit grid restarting at each falling edge (hard sync on every edge: good
/// enough for a waveform from one clock domain).
fn vcd_levels(path: &PathBuf, signal: &str, bit_ps: f64, sample_point: f64) -> anyhow::Result<Vec<bool>> {
    let f = std::fs::File::open(path).with_context(|| format!("opening {}", path.display()))?;
    let mut p = vcd::Parser::new(std::io::BufReader::new(f));
    let header = p.parse_header().with_context(|| format!("{}: not a VCD header", path.display()))?;
    let ps_per_unit = timescale_ps(&header);
    let var = find_var(&header.items, signal)
        .with_context(|| format!("{}: no signal named '{signal}'", path.display()))?;
    // Collect (time in ps, level) changes of the signal.
    let mut t = 0f64;
    let mut changes: Vec<(f64, bool)> = Vec::new();
    for cmd in p {
        match cmd.with_context(|| format!("{}: malformed VCD body", path.display()))? {
            vcd::Command::Timestamp(ts) => t = ts as f64 * ps_per_unit,
            vcd::Command::ChangeScalar(id, v) if id == var => changes.push((t, v == vcd::Value::V1)),
            vcd::Command::ChangeVector(id, v) if id == var => {
                changes.push((t, v.iter().last().is_some_and(|b| b == vcd::Value::V1)))
            }
            _ => {}
        }
    }
    let Some(&(end, _)) = changes.last() else { bail!("{}: signal '{signal}' never changes", path.display()) };
    let end = end + 20.0 * bit_ps; // see the trailing recessive bits through
    let mut levels = Vec::new();
    let mut level = changes[0].1;
    let (mut bit_start, mut next_change) = (changes[0].0, 1);
    loop {
        let sample = bit_start + sample_point * bit_ps;
        if sample > end {
            break;
        }
        // Apply changes up to the sample point; a falling edge restarts the grid.
        while next_change < changes.len() && changes[next_change].0 <= sample {
            let (ct, cv) = changes[next_change];
            next_change += 1;
            if level && !cv && ct > bit_start {
                bit_start = ct;
                level = cv;
                continue;
            }
            level = cv;
        }
        if bit_start + sample_point * bit_ps > sample {
            continue; // the grid moved: sample again in the new bit
        }
        levels.push(level);
        bit_start += bit_ps;
    }
    Ok(levels)
}

fn timescale_ps(h: &vcd::Header) -> f64 {
    match h.timescale {
        Some((n, unit)) => n as f64 * 1e12 / unit.divisor() as f64,
        None => 1.0,
    }
}

fn find_var(items: &[vcd::ScopeItem], name: &str) -> Option<vcd::IdCode> {
    for it in items {
        match it {
            vcd::ScopeItem::Var(v) if v.reference == name => return Some(v.code),
            vcd::ScopeItem::Scope(s) => {
                if let Some(c) = find_var(&s.items, name) {
                    return Some(c);
                }
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use can_proto::{CanFrame, FrameTrait};

    fn thesis_frame() -> CanFrame {
        CanFrame::new(CanFrame::std_id(0x529).unwrap(), &[0x51]).unwrap()
    }

    /// A VCD of the thesis frame at 40 clocks per bit of 24 MHz, with the
    /// sender's edges a little late (as a real transceiver's would be), must
    /// decode back to the same frame.
    #[test]
    fn vcd_round_trip_with_jittered_edges() {
        let frame = thesis_frame();
        let mut levels = vec![true; 12];
        levels.extend(frame.wire_bits().iter().by_vals());
        // Receivers ACK: make the ACK slot dominant so it decodes as acknowledged.
        let ack_slot = 12 + frame.wire_bits().len() - 9;
        levels[ack_slot] = false;
        levels.extend([true; 12]);
        let bit_ps = 1e12 * 40.0 / 24e6;
        let dir = std::env::temp_dir().join(format!("cancosim-decode-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("frame.vcd");
        let mut w = vcd::Writer::new(std::fs::File::create(&path).unwrap());
        w.timescale(1, vcd::TimescaleUnit::PS).unwrap();
        w.add_module("top").unwrap();
        let id = w.add_wire(1, "tx_o").unwrap();
        w.upscope().unwrap();
        w.enddefinitions().unwrap();
        let mut last = None;
        for (i, &l) in levels.iter().enumerate() {
            if last != Some(l) {
                let jitter = (i % 3) as f64 * 0.03 * bit_ps; // up to 6% late
                w.timestamp((i as f64 * bit_ps + jitter) as u64).unwrap();
                w.change_scalar(id, if l { vcd::Value::V1 } else { vcd::Value::V0 }).unwrap();
                last = Some(l);
            }
        }
        w.timestamp((levels.len() as f64 * bit_ps) as u64).unwrap();
        drop(w);
        let t = BusTiming::from_btr(0x41, 0x25);
        let got = vcd_levels(&path, "tx_o", bit_ps, t.sample_point()).unwrap();
        let frames: Vec<_> = Decoder::decode(got)
            .into_iter()
            .filter_map(|e| if let DecodeEvent::Frame(f) = e { Some(f) } else { None })
            .collect();
        assert_eq!(frames.len(), 1, "exactly the one frame");
        assert_eq!(frames[0].frame, frame);
        assert!(frames[0].ack);
        assert!(vcd_levels(&path, "rx_i", bit_ps, 0.7).is_err(), "unknown signal is an error");
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn bit_lists_reject_other_characters() {
        assert_eq!(parse_bit_list("01 1_0").unwrap(), vec![false, true, true, false]);
        let e = parse_bit_list("012").unwrap_err().to_string();
        assert!(e.contains("character 3"), "{e}");
    }
}
