//! A candump log as a model node's traffic: each data or remote frame is
//! requested at the bit time its timestamp gives, gaps kept (scaled from
//! seconds to bit times at the capture's bit rate).

use crate::FrameSpec;
use cosim::candump::{LogKind, parse_log};
use std::path::Path;

/// The frames of the log at `path` as node traffic: the first frame at
/// `start_bit`, each next one `gap * bit_rate` bit times later, rounded to
/// the nearest bit. Returns the frames and the number of error frames left
/// out. Only lines of `iface` when given. Errors name file:line.
pub fn traffic(path: &Path, bit_rate: f64, start_bit: u64, iface: Option<&str>) -> Result<(Vec<FrameSpec>, usize), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("cannot read candump log {}: {e}", path.display()))?;
    let lines = parse_log(&text, &path.display().to_string()).map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    let mut skipped = 0;
    let mut t0 = None;
    let mut last = 0;
    for l in lines.iter().filter(|l| iface.is_none_or(|i| i == l.iface)) {
        if l.t_us < last {
            return Err(format!("{}:{}: timestamp goes back in time (a candump log is in time order)", path.display(), l.line));
        }
        last = l.t_us;
        let t0 = *t0.get_or_insert(l.t_us);
        match l.kind {
            LogKind::Error { .. } => skipped += 1,
            LogKind::Frame(frame) => {
                let gap_bits = ((l.t_us - t0) as f64 * bit_rate / 1e6).round() as u64;
                out.push(FrameSpec { frame, at_bit: start_bit + gap_bits });
            }
        }
    }
    if out.is_empty() {
        return Err(format!("{}: no data or remote frame to replay{}", path.display(), iface.map(|i| format!(" on interface {i}")).unwrap_or_default()));
    }
    Ok((out, skipped))
}
