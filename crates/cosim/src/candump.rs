//! Bus logs in can-utils `candump -l` format, both ways: the traffic of a
//! run as a log (`(0000000001.000250) can0 123#A55520`, one frame a line),
//! and a log read back (for replay as a model node's traffic).
//!
//! The format, as can-utils' `candump -l` writes it and `canplayer`,
//! python-can, Wireshark and SavvyCAN read it:
//! - timestamp `(SSSSSSSSSS.UUUUUU)`, seconds and microseconds;
//! - interface name;
//! - `ID#DATA`: a standard ID as 3 hex digits, an extended one as 8, data
//!   as hex byte pairs; a remote frame `ID#R` (`ID#Rn` when its DLC n is
//!   not zero); a DLC of 9..15 as `_X` after 8 data bytes (`-8` option);
//! - error frames (Linux `can/error.h`): ID = `CAN_ERR_FLAG` (0x20000000)
//!   with the error classes, as 8 hex digits, and 8 data bytes.
//!
//! What the log of a run holds: every frame completed on the bus (as the
//! DUT's interface sees them with the kernel's default local echo), and the
//! error frames the Linux `sja1000` driver would raise for the DUT, taken
//! from the golden model that shadows it: bus errors (`CAN_ERR_PROT |
//! CAN_ERR_BUSERROR`, type and location from the ECC, `CAN_ERR_PROT_TX`
//! when transmitting), lost arbitration (`CAN_ERR_LOSTARB`, ALC bit),
//! warning/passive/active changes (`CAN_ERR_CRTL`) and bus-off
//! (`CAN_ERR_BUSOFF`), each with TXERR/RXERR (`CAN_ERR_CNT`).

use can_proto::{CanFrame, FrameTrait};
use diagnose::EventKind;
use std::fmt::Write as _;

/// Error-frame flag and classes of Linux `include/uapi/linux/can/error.h`.
pub mod err {
    /// The frame is an error frame (bit 29 of `can_id`).
    pub const FLAG: u32 = 0x2000_0000;
    /// Lost arbitration, bit in `data[0]`.
    pub const LOSTARB: u32 = 0x0002;
    /// Controller problems, `data[1]`.
    pub const CRTL: u32 = 0x0004;
    /// Protocol violations, type in `data[2]`, location in `data[3]`.
    pub const PROT: u32 = 0x0008;
    /// Bus off.
    pub const BUSOFF: u32 = 0x0040;
    /// Bus error.
    pub const BUSERROR: u32 = 0x0080;
    /// TX/RX error counters in `data[6]`/`data[7]`.
    pub const CNT: u32 = 0x0200;
    /// `data[1]`: reached the warning level (RX / TX).
    pub const CRTL_RX_WARNING: u8 = 0x04;
    /// See [`CRTL_RX_WARNING`].
    pub const CRTL_TX_WARNING: u8 = 0x08;
    /// `data[1]`: error passive (RX / TX).
    pub const CRTL_RX_PASSIVE: u8 = 0x10;
    /// See [`CRTL_RX_PASSIVE`].
    pub const CRTL_TX_PASSIVE: u8 = 0x20;
    /// `data[1]`: back to error active.
    pub const CRTL_ACTIVE: u8 = 0x40;
    /// `data[2]`: bit error.
    pub const PROT_BIT: u8 = 0x01;
    /// `data[2]`: form error.
    pub const PROT_FORM: u8 = 0x02;
    /// `data[2]`: stuff error.
    pub const PROT_STUFF: u8 = 0x04;
    /// `data[2]`: the error happened while transmitting.
    pub const PROT_TX: u8 = 0x80;
}

/// What one log line carries.
#[derive(Clone, Debug, PartialEq)]
pub enum LogKind {
    /// A data or remote frame.
    Frame(CanFrame),
    /// An error frame: `can_id` with [`err::FLAG`] and its classes, 8 bytes.
    Error {
        /// `CAN_ERR_FLAG | classes`.
        id: u32,
        /// The error frame's data.
        data: [u8; 8],
    },
}

/// One line of a bus log.
#[derive(Clone, Debug, PartialEq)]
pub struct LogEntry {
    /// Simulated time, picoseconds from the start of the run.
    pub t_ps: u64,
    /// The frame.
    pub kind: LogKind,
}

/// Controller state, for reporting changes only (as the kernel's
/// `can_change_state` does).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum State {
    #[default]
    Active,
    Warning,
    Passive,
    BusOff,
}

/// Builds a run's log: frames from the bus decoder, error frames from the
/// engine events of the model that shadows the DUT.
#[derive(Clone, Debug, Default)]
pub struct BusLog {
    entries: Vec<LogEntry>,
    /// Error warning (SR.ES) as last reported by the engine.
    warning: bool,
    /// Fault confinement state as last reported by the engine.
    fault: Option<can_engine::FaultState>,
    /// The state last written to the log.
    reported: State,
}

impl BusLog {
    /// An empty log.
    pub fn new() -> Self {
        Self::default()
    }

    /// The lines so far, in time order.
    pub fn entries(&self) -> &[LogEntry] {
        &self.entries
    }

    /// A frame completed on the bus at `t_ps`.
    pub fn frame(&mut self, t_ps: u64, frame: CanFrame) {
        self.entries.push(LogEntry { t_ps, kind: LogKind::Frame(frame) });
    }

    /// An engine event of the DUT's shadow model at `t_ps`, with its TEC and
    /// REC after the event: error frames for the events the Linux driver
    /// reports, nothing for the others.
    pub fn event(&mut self, t_ps: u64, e: &EventKind, counters: Option<(u16, u16)>) {
        let (tec, rec) = counters.unwrap_or((0, 0));
        let mut id = err::FLAG;
        let mut data = [0u8; 8];
        match e {
            EventKind::BusError { ecc, .. } => {
                id |= err::PROT | err::BUSERROR;
                data[2] = match ecc >> 6 {
                    0 => err::PROT_BIT,
                    1 => err::PROT_FORM,
                    2 => err::PROT_STUFF,
                    _ => 0,
                };
                // ECC.DIR = 0: during transmission.
                if ecc & 0x20 == 0 {
                    data[2] |= err::PROT_TX;
                }
                // The kernel's CAN_ERR_PROT_LOC_* codes are the ECC segment codes.
                data[3] = ecc & 0x1F;
            }
            EventKind::ArbitrationLost { alc } => {
                id |= err::LOSTARB;
                data[0] = alc & 0x1F;
            }
            EventKind::ErrorWarning(on) => {
                self.warning = *on;
                let Some(classes) = self.state_change(&mut data, tec, rec) else { return };
                id |= classes;
            }
            EventKind::FaultState(s) => {
                // Bus-off recovery clears both counters, so SR.ES with them.
                if self.fault == Some(can_engine::FaultState::BusOff) && *s == can_engine::FaultState::ErrorActive {
                    self.warning = false;
                }
                self.fault = Some(*s);
                let Some(classes) = self.state_change(&mut data, tec, rec) else { return };
                id |= classes;
            }
            _ => return,
        }
        id |= err::CNT;
        data[6] = tec.min(255) as u8;
        data[7] = rec.min(255) as u8;
        self.entries.push(LogEntry { t_ps, kind: LogKind::Error { id, data } });
    }

    /// Classes and `data[1]` when the controller state changed, else None.
    fn state_change(&mut self, data: &mut [u8; 8], tec: u16, rec: u16) -> Option<u32> {
        use can_engine::FaultState as F;
        let now = match self.fault {
            Some(F::BusOff) => State::BusOff,
            Some(F::ErrorPassive) => State::Passive,
            _ if self.warning => State::Warning,
            _ => State::Active,
        };
        if std::mem::replace(&mut self.reported, now) == now {
            return None;
        }
        let tx = tec >= rec;
        Some(match now {
            State::BusOff => err::BUSOFF,
            State::Passive => {
                data[1] = if tx { err::CRTL_TX_PASSIVE } else { err::CRTL_RX_PASSIVE };
                err::CRTL
            }
            State::Warning => {
                data[1] = if tx { err::CRTL_TX_WARNING } else { err::CRTL_RX_WARNING };
                err::CRTL
            }
            State::Active => {
                data[1] = err::CRTL_ACTIVE;
                err::CRTL
            }
        })
    }
}

/// The `ID#DATA` part of a line.
pub fn frame_text(kind: &LogKind) -> String {
    let mut s = String::new();
    match kind {
        LogKind::Error { id, data } => {
            let _ = write!(s, "{id:08X}#");
            for b in data {
                let _ = write!(s, "{b:02X}");
            }
        }
        LogKind::Frame(f) => {
            if f.is_extended() {
                let _ = write!(s, "{:08X}#", f.raw_id());
            } else {
                let _ = write!(s, "{:03X}#", f.raw_id());
            }
            let dlc = f.dlc_raw();
            if f.is_remote_frame() {
                s.push('R');
                if dlc != 0 {
                    let _ = write!(s, "{}", dlc.min(8));
                }
            } else {
                for b in f.data() {
                    let _ = write!(s, "{b:02X}");
                }
            }
            if dlc > 8 {
                let _ = write!(s, "_{dlc:X}");
            }
        }
    }
    s
}

/// One log line (no newline): `(seconds.micros) iface ID#DATA`.
pub fn line(e: &LogEntry, iface: &str) -> String {
    let us = e.t_ps / 1_000_000;
    format!("({:010}.{:06}) {iface} {}", us / 1_000_000, us % 1_000_000, frame_text(&e.kind))
}

/// A whole log, one line per entry, each ending in a newline.
pub fn write_log(entries: &[LogEntry], iface: &str) -> String {
    entries.iter().map(|e| line(e, iface) + "\n").collect()
}

/// A line of a log that could not be read.
#[derive(Debug, thiserror::Error)]
#[error("{file}:{line}: {message}")]
pub struct CandumpError {
    /// File name.
    pub file: String,
    /// Line, from 1.
    pub line: usize,
    /// What is wrong, with the text at fault.
    pub message: String,
}

/// A line read back from a log.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadLine {
    /// Line in the file, from 1.
    pub line: usize,
    /// Timestamp in microseconds.
    pub t_us: u64,
    /// Interface name.
    pub iface: String,
    /// The frame.
    pub kind: LogKind,
}

fn hex_u8(s: &str) -> Option<u8> {
    (s.len() == 2 && s.bytes().all(|b| b.is_ascii_hexdigit())).then(|| u8::from_str_radix(s, 16).ok()).flatten()
}

/// Parses `ID#DATA` (classic CAN; CAN FD `##` is refused).
pub fn parse_frame(text: &str) -> Result<LogKind, String> {
    let (id_s, data_s) = text.split_once('#').ok_or_else(|| format!("`{text}`: expected ID#DATA"))?;
    if data_s.starts_with('#') {
        return Err(format!("`{text}`: a CAN FD frame (##); classic CAN only"));
    }
    if !(id_s.len() == 3 || id_s.len() == 8) || !id_s.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(format!("`{id_s}`: an ID is 3 hex digits (standard) or 8 (extended)"));
    }
    let id = u32::from_str_radix(id_s, 16).map_err(|e| format!("`{id_s}`: {e}"))?;
    let (body, raw_dlc) = match data_s.split_once('_') {
        Some((b, d)) => {
            let dlc = u8::from_str_radix(d, 16).ok().filter(|x| (9..=15).contains(x) && d.len() == 1);
            (b, Some(dlc.ok_or_else(|| format!("`_{d}`: a raw DLC after `_` is one hex digit 9..F"))?))
        }
        None => (data_s, None),
    };
    if id_s.len() == 8 && id & err::FLAG != 0 {
        let bytes = parse_bytes(body)?;
        if bytes.len() != 8 {
            return Err(format!("`{text}`: an error frame carries 8 data bytes, {} given", bytes.len()));
        }
        let mut data = [0u8; 8];
        data.copy_from_slice(&bytes);
        return Ok(LogKind::Error { id, data });
    }
    let ext = id_s.len() == 8;
    let cid = if ext {
        if id > 0x1FFF_FFFF {
            return Err(format!("`{id_s}`: extended ID above 0x1FFFFFFF (only the error flag may be set)"));
        }
        CanFrame::ext_id(id)
    } else {
        if id > 0x7FF {
            return Err(format!("`{id_s}`: standard ID above 0x7FF"));
        }
        CanFrame::std_id(id as u16)
    }
    .expect("range checked");
    let frame = if let Some(r) = body.strip_prefix(['R', 'r']) {
        let dlc = match r {
            "" => 0,
            d => d.parse::<u8>().ok().filter(|d| *d <= 8).ok_or_else(|| format!("`R{d}`: a remote frame's DLC is one digit 0..8"))?,
        };
        let dlc = match raw_dlc {
            Some(x) if dlc == 8 => x,
            Some(_) => return Err(format!("`{text}`: a raw DLC needs DLC 8 first")),
            None => dlc,
        };
        CanFrame::with_dlc(cid, true, dlc, &[])
    } else {
        let data = parse_bytes(body)?;
        if data.len() > 8 {
            return Err(format!("`{body}`: {} data bytes, a CAN 2.0 frame carries at most 8", data.len()));
        }
        let dlc = match raw_dlc {
            Some(x) if data.len() == 8 => x,
            Some(_) => return Err(format!("`{text}`: a raw DLC needs 8 data bytes")),
            None => data.len() as u8,
        };
        CanFrame::with_dlc(cid, false, dlc, &data)
    };
    frame.map(LogKind::Frame).ok_or_else(|| format!("`{text}`: not a valid CAN frame"))
}

fn parse_bytes(s: &str) -> Result<Vec<u8>, String> {
    // can-utils accepts `.` between bytes.
    let s: String = s.chars().filter(|c| *c != '.').collect();
    if s.len() & 1 == 1 {
        return Err(format!("`{s}`: data is hex byte pairs (odd number of digits)"));
    }
    (0..s.len()).step_by(2).map(|i| hex_u8(&s[i..i + 2]).ok_or_else(|| format!("`{}`: not a hex byte", &s[i..i + 2]))).collect()
}

fn parse_time(s: &str) -> Option<u64> {
    let inner = s.strip_prefix('(')?.strip_suffix(')')?;
    let (sec, frac) = inner.split_once('.')?;
    if sec.is_empty() || frac.is_empty() || frac.len() > 9 || !sec.bytes().chain(frac.bytes()).all(|b| b.is_ascii_digit()) {
        return None;
    }
    // Microseconds, from up to nine fraction digits (nanosecond logs).
    let mut f = frac.to_string();
    while f.len() < 6 {
        f.push('0');
    }
    let us: u64 = f[..6].parse().ok()?;
    sec.parse::<u64>().ok()?.checked_mul(1_000_000)?.checked_add(us)
}

/// Reads a log. Blank lines are skipped; a trailing `R`/`T` direction (as
/// `candump -x` writes it) is accepted. `file` names it in errors.
pub fn parse_log(text: &str, file: &str) -> Result<Vec<ReadLine>, CandumpError> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let err = |message: String| CandumpError { file: file.to_string(), line: i + 1, message };
        let l = raw.trim();
        if l.is_empty() {
            continue;
        }
        let parts: Vec<&str> = l.split_whitespace().collect();
        if !(parts.len() == 3 || parts.len() == 4 && matches!(parts[3], "R" | "T" | "r" | "t")) {
            return Err(err(format!("`{l}`: expected `(seconds.micros) iface ID#DATA`")));
        }
        let t_us = parse_time(parts[0]).ok_or_else(|| err(format!("`{}`: expected a timestamp like (1700000000.000123)", parts[0])))?;
        let kind = parse_frame(parts[2]).map_err(err)?;
        out.push(ReadLine { line: i + 1, t_us, iface: parts[1].to_string(), kind });
    }
    Ok(out)
}
