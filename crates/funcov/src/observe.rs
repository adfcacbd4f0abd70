//! What one run hit: read from its record and the bus decoder's frames.

use crate::Coverage;
use crate::bins;
use can_engine::FaultState;
use can_proto::Field;
use can_proto::CanFrame;
use diagnose::{Access as OpAccess, CanMode, EventKind, HostOp, RunRecord, Side, WriteOutcome};
use embedded_can::Frame as _;
use regmap::{Access, Mode, OpMode};
use sja1000::filter::{FilterMode, basic_accepts, pelican_accepts};

/// A data or remote frame the bench's bus decoder saw complete, with when.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BusFrame {
    /// Simulated time, picoseconds.
    pub t_ps: u64,
    /// The frame.
    pub frame: CanFrame,
}

fn view(m: CanMode) -> Mode {
    match m {
        CanMode::BasicCan => Mode::BasicCan,
        CanMode::PeliCan => Mode::PeliCan,
    }
}

/// A write the model did not take changes nothing: it exercises no bit.
fn taken(op: &HostOp) -> bool {
    op.error.is_none()
        && !matches!(
            op.outcome,
            Some(WriteOutcome::IgnoredNotInResetMode | WriteOutcome::IgnoredTxBufferLocked | WriteOutcome::IgnoredReadOnly)
        )
}

/// The acceptance filter as the host configured it (the reference's
/// registers follow the same writes).
struct FilterRegs {
    view: Mode,
    basic: (u8, u8),
    acr: [u8; 4],
    amr: [u8; 4],
    single: bool,
}

impl FilterRegs {
    fn new() -> FilterRegs {
        FilterRegs { view: Mode::BasicCan, basic: (0, 0), acr: [0; 4], amr: [0; 4], single: false }
    }

    fn apply(&mut self, op: &HostOp) {
        self.view = view(op.mode);
        if op.access != OpAccess::Write || !op.reset_mode || !taken(op) {
            return;
        }
        // Addresses of the datasheet's tables: BasicCAN ACR 4, AMR 5;
        // PeliCAN MOD 0 (AFM = bit 3), ACR0-3 16-19, AMR0-3 20-23, all
        // written in reset mode.
        match (self.view, op.addr) {
            (Mode::BasicCan, 4) => self.basic.0 = op.data,
            (Mode::BasicCan, 5) => self.basic.1 = op.data,
            (Mode::PeliCan, 0) => self.single = op.data & 0x08 != 0,
            (Mode::PeliCan, a @ 16..=19) => self.acr[(a - 16) as usize] = op.data,
            (Mode::PeliCan, a @ 20..=23) => self.amr[(a - 20) as usize] = op.data,
            _ => {}
        }
    }

    /// Bin of a frame the reference received (as receiver or by self
    /// reception): which filter judged it and its verdict.
    fn bin(&self, f: &CanFrame) -> String {
        let ext = f.is_extended();
        match self.view {
            Mode::BasicCan => {
                let ok = match f.id() {
                    embedded_can::Id::Standard(s) => basic_accepts(self.basic.0, self.basic.1, s.as_raw()),
                    embedded_can::Id::Extended(_) => false,
                };
                bins::filter("BasicCAN", ext, ok)
            }
            Mode::PeliCan => {
                let (mode, name) = if self.single { (FilterMode::Single, "PeliCAN single") } else { (FilterMode::Dual, "PeliCAN dual") };
                bins::filter(name, ext, pelican_accepts(mode, self.acr, self.amr, f))
            }
        }
    }
}

pub(crate) fn run(c: &mut Coverage, r: &RunRecord, frames: &[BusFrame]) {
    for f in frames {
        c.hit(bins::FRAMES, &bins::frame(f.frame.is_extended(), f.frame.is_remote_frame(), f.frame.dlc_raw()));
    }
    host_ops(c, &r.host_ops);
    events(c, r, frames);
}

/// Register bits written and read (each value of each bit) per view and
/// mode, and interrupts seen raised and cleared in IR reads.
fn host_ops(c: &mut Coverage, ops: &[HostOp]) {
    // Last IR value read per view: a bit read as 1, then as 0, was cleared.
    let mut last_ir: [u8; 2] = [0; 2];
    for op in ops.iter().filter(|o| taken(o)) {
        let v = view(op.mode);
        let opm = if op.reset_mode { OpMode::Reset } else { OpMode::Operating };
        let access = match op.access {
            OpAccess::Read => Access::Read,
            OpAccess::Write => Access::Write,
        };
        // A read counts what the golden model read (the DUT's value when the
        // record has no model value, e.g. a record written before it had one).
        let data = if access == Access::Read { op.model_data.unwrap_or(op.data) } else { op.data };
        if let Some((reg, mask)) = bins::register_bits(v, opm, access, op.addr) {
            let group = bins::register_group(v, opm, access);
            for bit in (0..8).filter(|b| mask & (1 << b) != 0) {
                c.hit(&group, &bins::register_bit(reg, bit, data & (1 << bit) != 0));
            }
        }
        if access == Access::Read && op.addr == bins::ir_addr(v) {
            let k = (v == Mode::PeliCan) as usize;
            for (name, m) in bins::interrupt_fields(v) {
                if data & m != 0 {
                    c.hit(&bins::interrupt_group(v), &format!("{name} raised"));
                } else if last_ir[k] & m != 0 {
                    c.hit(&bins::interrupt_group(v), &format!("{name} cleared"));
                }
            }
            last_ir[k] = data;
        }
    }
}

/// The reference's events: errors by field, fault confinement,
/// arbitration loss, and the filter's verdict on each frame it received.
fn events(c: &mut Coverage, r: &RunRecord, frames: &[BusFrame]) {
    let mut state = FaultState::ErrorActive;
    let mut filter = FilterRegs::new();
    // The reference reports no warning event of its own: the limit is
    // crossed when a counter after an event reaches EWLR (the last value
    // the host wrote, else the reset value 96).
    let ewl = r
        .host_ops
        .iter()
        .filter(|o| o.access == OpAccess::Write && view(o.mode) == Mode::PeliCan && o.addr == 13 && o.reset_mode && taken(o))
        .last()
        .map_or(96, |o| o.data as u16);
    let mut warning = false;
    let mut next_op = 0;
    let mut next_frame = 0;
    for e in r.events.iter().filter(|e| e.node == Side::Model) {
        if let (Some(tec), Some(rec)) = (e.tec, e.rec)
            && (tec >= ewl || rec >= ewl) != warning
        {
            warning = !warning;
            c.hit(bins::FAULT, if warning { bins::WARNING_REACHED } else { bins::WARNING_LEFT });
        }
        match &e.kind {
            // The event's field is where the engine is when it reports (an
            // ACK error shows up in the error flag); the ECC says where the
            // error was detected, as the SJA1000 reports it.
            // The SJA1000 has one ECC segment for the error and the
            // overload delimiter: the field the model was in at the bit
            // before the report (where the error was) tells which.
            EventKind::BusError { kind, field, ecc } => {
                let f = match diagnose::field_from_ecc(*ecc) {
                    Some(Field::ErrorDelimiter) if *field == Field::OverloadDelimiter || field_at(r, e.bit.wrapping_sub(1)) == Some(Field::OverloadDelimiter) => {
                        Field::OverloadDelimiter
                    }
                    Some(f) => f,
                    None => *field,
                };
                c.hit(bins::ERRORS, &bins::error(*kind, f))
            }
            EventKind::ArbitrationLost { alc } => c.hit(bins::ARBITRATION, &bins::arbitration(*alc)),
            EventKind::FaultState(s) if *s != state => {
                c.hit(bins::FAULT, &bins::transition(state, *s));
                state = *s;
            }
            EventKind::Received { id, dlc, .. } => {
                // The bus frame it is (the decoder logs every frame in
                // order), and the filter as configured before it.
                let Some(k) = frames[next_frame..].iter().position(|f| f.frame.raw_id() == *id && f.frame.dlc_raw() == *dlc) else {
                    continue;
                };
                let f = &frames[next_frame + k];
                next_frame += k + 1;
                while let Some(op) = r.host_ops.get(next_op).filter(|o| o.time_ps <= f.t_ps) {
                    filter.apply(op);
                    next_op += 1;
                }
                c.hit(bins::FILTER, &filter.bin(&f.frame));
            }
            _ => {}
        }
    }
}

/// The field the model was in at `bit`, if the record kept that bit.
fn field_at(r: &RunRecord, bit: u64) -> Option<Field> {
    let k = r.bus_bits.binary_search_by_key(&bit, |b| b.bit).ok()?;
    r.bus_bits[k].field
}
