//! The scoreboard's events as a VCD of their own, to load beside the
//! simulator's waveform: the first divergence (a one-bit `divergence` that
//! rises at it, and its kind as text), each host access as the model took
//! it, the model's engine events and the frames on the DUT's rx; and a
//! GTKWave save file with the primary marker on the divergence, as the
//! command line writes next to its VCD (`cosim::gtkw`).
//!
//! Times are the [`Shadow`]'s: the bench's own once it anchors them
//! ([`Shadow::set_time_ps`]), so `gtkwave dut.vcd <name>.gtkw` puts the
//! marker on the simulator's dump too.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{self, BufWriter};
use std::path::Path;

use cosim::candump::LogKind;
use diagnose::{Access, DivergenceKind, EventKind};
use vcd::{IdCode, TimescaleUnit, Value, VarType};

use crate::Shadow;

/// The VCD's scope.
pub const SCOPE: &str = "sja1000_scoreboard";

/// Text signals, in order (after the scalar `divergence`).
const TEXT_VARS: [&str; 4] = ["divergence_kind", "host_access", "model_event", "bus_frame"];

/// Where the primary marker goes: the first divergence, else the
/// transmission request that never completed (the diagnosis's instant).
pub fn marker_ps(s: &Shadow) -> Option<u64> {
    let r = s.record();
    r.divergence
        .as_ref()
        .map(|d| d.time_ps)
        .or(r.stuck.as_ref().map(|st| st.requested_ps))
}

/// A VCD string value has no white space.
fn token(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join("_")
}

fn event_text(k: &EventKind) -> String {
    match k {
        EventKind::BusError { kind, ecc, field } => {
            format!("BusError:{kind:?}@{field:?}(ECC=0x{ecc:02X})")
        }
        EventKind::TxComplete => "TxComplete".into(),
        EventKind::TxAborted => "TxAborted".into(),
        EventKind::ArbitrationLost { alc } => format!("ArbitrationLost:ALC={alc}"),
        EventKind::ErrorWarning(on) => format!("ErrorWarning:{}", if *on { "on" } else { "off" }),
        EventKind::FaultState(s) => format!("FaultState:{s:?}"),
        EventKind::Received { id, dlc, own } => {
            format!(
                "Received:0x{id:X},DLC={dlc}{}",
                if *own { ",own" } else { "" }
            )
        }
        EventKind::WakeUp => "WakeUp".into(),
    }
}

/// Every change, per signal: time -> text (several at one time joined by `+`).
struct Changes {
    per_var: Vec<BTreeMap<u64, String>>,
}

impl Changes {
    fn put(&mut self, var: usize, t: u64, text: String) {
        let e = self.per_var[var].entry(t).or_default();
        if !e.is_empty() {
            e.push('+');
        }
        e.push_str(&token(&text));
    }
}

/// Writes the scoreboard's events of `s` as a VCD at `path` (timescale
/// 1 ps, ending at the last CAN clock). Each text event holds for one CAN
/// clock, then the signal reads `-` again, so two equal events in a row
/// still show as two.
pub fn write_vcd(s: &Shadow, path: &Path) -> io::Result<()> {
    let r = s.record();
    let period = s.period_ps().max(1);
    let mut c = Changes {
        per_var: vec![BTreeMap::new(); TEXT_VARS.len()],
    };
    let divergence = r.divergence.as_ref().map(|d| d.time_ps);
    if let Some(d) = &r.divergence {
        let what = match d.kind {
            DivergenceKind::RegisterRead => format!(
                "RegisterRead:{}:expected=0x{:02X},seen=0x{:02X}",
                d.register.as_deref().unwrap_or("?"),
                d.expected,
                d.seen
            ),
            k => format!(
                "{k:?}{}:expected={},seen={}",
                d.field.map(|f| format!("@{f:?}")).unwrap_or_default(),
                d.expected,
                d.seen
            ),
        };
        c.put(0, d.time_ps, what);
    } else if let Some(st) = &r.stuck {
        c.put(0, st.requested_ps, "TransmissionNeverCompleted".into());
    }
    for op in &r.host_ops {
        let reg = op.reg.clone().unwrap_or_else(|| format!("{}", op.addr));
        let text = match op.access {
            Access::Write => format!("W:{reg}=0x{:02X}", op.data),
            Access::Read => format!("R:{reg}=0x{:02X}", op.model_data.unwrap_or(op.data)),
        };
        c.put(1, op.time_ps, text);
    }
    for (t, k) in s.timed_events() {
        // SR.ES is reported at every sample point with events; only its
        // changes are events here (the journal's own).
        c.put(2, *t, event_text(k));
    }
    for e in s.bus_log_entries() {
        // candump's own text (`123#A55A`; an error frame `20000088#...`).
        let text = cosim::candump::frame_text(&e.kind);
        let text = match e.kind {
            LogKind::Frame(_) => text,
            LogKind::Error { .. } => format!("ErrorFrame:{text}"),
        };
        c.put(3, e.t_ps, text);
    }
    // Back to "-" one CAN clock after each event (unless another follows).
    for var in 1..TEXT_VARS.len() {
        let times: Vec<u64> = c.per_var[var].keys().copied().collect();
        for t in times {
            c.per_var[var]
                .entry(t + period)
                .or_insert_with(|| "-".into());
        }
    }
    let end = s.now().max(divergence.unwrap_or(0));

    let mut w = vcd::Writer::new(BufWriter::new(File::create(path)?));
    w.timescale(1, TimescaleUnit::PS)?;
    w.add_module(SCOPE)?;
    let div_id = w.add_wire(1, "divergence")?;
    let ids: Vec<IdCode> = TEXT_VARS
        .iter()
        .map(|n| w.add_var(VarType::String, 1, n, None))
        .collect::<io::Result<_>>()?;
    w.upscope()?;
    w.enddefinitions()?;
    // Everything by time; the initial values at 0.
    let mut by_time: BTreeMap<u64, Vec<(Option<usize>, String)>> = BTreeMap::new();
    for (var, m) in c.per_var.iter().enumerate() {
        for (t, text) in m {
            by_time
                .entry(*t)
                .or_default()
                .push((Some(var), text.clone()));
        }
    }
    if let Some(t) = divergence {
        by_time.entry(t).or_default().push((None, String::new()));
    }
    w.timestamp(0)?;
    w.change_scalar(div_id, Value::V0)?;
    for id in &ids {
        w.change_string(*id, "-")?;
    }
    let mut last = 0;
    for (t, changes) in by_time {
        last = t;
        if t > 0 {
            w.timestamp(t)?;
        }
        for (var, text) in changes {
            match var {
                None => w.change_scalar(div_id, Value::V1)?,
                Some(v) => w.change_string(ids[v], &text)?,
            }
        }
    }
    // The dump lasts to the last CAN clock (or past the last "-").
    if end > last {
        w.timestamp(end)?;
    }
    w.flush()
}

/// The GTKWave save file for the VCD at `vcd`: the scoreboard's signals,
/// the primary marker at [`marker_ps`] with a few bit times around it.
pub fn save_file(s: &Shadow, vcd: &Path) -> String {
    use cosim::gtkw::trace::{BIN, TEXT};
    let sigs: [(&str, &str); 5] = [
        ("divergence", BIN),
        ("divergence_kind", TEXT),
        ("host_access", TEXT),
        ("model_event", TEXT),
        ("bus_frame", TEXT),
    ];
    let bit_ps = s.period_ps() * s.clocks_per_bit().max(1) as u64;
    cosim::gtkw::view(
        "golden SJA1000 scoreboard: its events, marker on the first divergence",
        vcd,
        SCOPE,
        &[("Scoreboard", &sigs)],
        marker_ps(s),
        bit_ps,
        s.now(),
    )
}
