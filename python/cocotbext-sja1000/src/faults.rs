//! Faults on the cocotb bus, with the command line's semantics: the
//! `sja1000` injectors (`FlipBit`, `Glitch`, `StuckAt`) and a stuck level
//! that starts at a frame bit, placed by frame (from 1) and wire bit (SOF =
//! 0, stuff bits counted) or by field and bit within the field (stuff bits
//! not counted). Their context is the bench's, as for the CLI's faults on
//! the DUT's rx: the bit clock and the decoder on the wired-AND level
//! (frame = SOFs seen, frame bit counted from bit boundary to boundary).

use can_proto::Field;
use can_proto::decode::{DecodeEvent, Decoder};
use can_proto::timing::BusTiming;
use cosim::bitclock::BitClock;
use diagnose::named::Named;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use sja1000::{BusContext, FaultInjector, FlipBit, ForcedPulse, Glitch, StuckAt, StuckInFrame, Target};

#[derive(Clone, Copy, Debug)]
enum Kind {
    Flip,
    Glitch {
        offset: u32,
        width: u32,
        level: Option<bool>,
    },
    Stuck {
        level: bool,
        bits: u64,
    },
}

/// A fault placed by field, waiting for its bit to come.
#[derive(Clone, Copy, Debug)]
struct ByField {
    frame: u32,
    field: Field,
    bit: u32,
    kind: Kind,
    target: Target,
}

fn injector(kind: Kind, frame: u64, bit: u32, target: Target) -> Box<dyn FaultInjector> {
    match kind {
        Kind::Flip => Box::new(FlipBit { frame, bit, target }),
        Kind::Glitch {
            offset,
            width,
            level: None,
        } => Box::new(Glitch {
            frame,
            bit,
            offset,
            width,
            target,
        }),
        Kind::Glitch {
            offset,
            width,
            level: Some(level),
        } => Box::new(ForcedPulse {
            frame,
            bit,
            offset,
            width,
            level,
            target,
        }),
        Kind::Stuck { level, bits } => Box::new(StuckInFrame {
            level,
            target,
            frame,
            bit,
            bits,
            until: None,
        }),
    }
}

/// A field by its name: `Crc`, `crc`, `base_id`, `ack-slot`...
fn field_named(name: &str) -> PyResult<Field> {
    let norm = |s: &str| {
        s.chars()
            .filter(|c| c.is_ascii_alphanumeric())
            .collect::<String>()
            .to_ascii_lowercase()
    };
    let want = norm(name);
    Field::ALL
        .iter()
        .copied()
        .find(|f| norm(&f.name()) == want)
        .ok_or_else(|| {
            let names: Vec<String> = Field::ALL.iter().map(|f| f.name()).collect();
            PyValueError::new_err(format!(
                "`{name}` is not a CAN field; one of {}",
                names.join(", ")
            ))
        })
}

/// The faults of one bus, and the bench's view of where the bus is.
#[pyclass(unsendable, module = "cocotbext.sja1000._native")]
pub struct Faults {
    clock: BitClock,
    dec: Decoder,
    clocks: u64,
    /// SOFs seen.
    frames: u32,
    /// Bit index of the last SOF.
    sof_bit: u64,
    /// The field of the last sampled bit, and its non-stuff bits so far.
    field: Option<Field>,
    field_bits: u32,
    active: Vec<Box<dyn FaultInjector>>,
    by_field: Vec<ByField>,
    /// CAN clocks at which a fault changed what someone received.
    applied: u64,
}

impl Faults {
    /// Where the bus is now, asked before the clock's bit clock step.
    fn context(&self) -> BusContext {
        BusContext {
            clock: self.clocks,
            frame: self.frames.checked_sub(1).map(u64::from),
            frame_bit: self.clock.bit_in_progress().saturating_sub(self.sof_bit) as u32,
            sub: self.clock.sub(),
            clocks_per_bit: self.clock.clocks_per_bit(),
        }
    }

    /// A sample point of `level`: the decoder, then the faults placed by
    /// field whose bit is the next one.
    fn sample(&mut self, level: bool) {
        let mut stuff = false;
        for e in self.dec.push(level) {
            match e {
                DecodeEvent::FieldStart { field, .. } => {
                    if field == Field::Sof {
                        self.frames += 1;
                        self.sof_bit = self.clock.bits() - 1;
                    }
                    self.field = Some(field);
                    self.field_bits = 0;
                }
                DecodeEvent::StuffBit { .. } => stuff = true,
                _ => {}
            }
        }
        if !stuff {
            self.field_bits += 1;
        }
        if self.by_field.is_empty() || self.frames == 0 {
            return;
        }
        // The next bit's field and index: a stuff bit whatever its level;
        // else what a recessive bit would be (a dominant one only starts
        // something the fault is not aimed at: an error, overload or SOF).
        let (mut next_stuff, mut next_start) = (false, None);
        for probe in [true, false] {
            let mut d = self.dec.clone();
            for e in d.push(probe) {
                match e {
                    DecodeEvent::StuffBit { .. } => next_stuff = true,
                    DecodeEvent::FieldStart { field, .. } if probe => next_start = Some(field),
                    _ => {}
                }
            }
        }
        if next_stuff {
            return;
        }
        let (field, index) = match (next_start, self.field) {
            (Some(f), _) => (f, 0),
            (None, Some(f)) => (f, self.field_bits),
            (None, None) => return,
        };
        let frame_bit = (self.clock.bits() - self.sof_bit) as u32;
        let frame = self.frames;
        let mut i = 0;
        while i < self.by_field.len() {
            let p = self.by_field[i];
            if p.frame == frame && p.field == field && p.bit == index {
                self.active
                    .push(injector(p.kind, u64::from(frame - 1), frame_bit, p.target));
                self.by_field.remove(i);
            } else {
                i += 1;
            }
        }
    }

    fn add(
        &mut self,
        kind: Kind,
        frame: u32,
        bit: u32,
        field: Option<&str>,
        target: Option<usize>,
    ) -> PyResult<()> {
        if frame == 0 {
            return Err(PyValueError::new_err(
                "frames are counted from 1 (the first frame on the bus)",
            ));
        }
        let target = target.map_or(Target::All, Target::Node);
        match field {
            None => self
                .active
                .push(injector(kind, u64::from(frame - 1), bit, target)),
            Some(name) => self.by_field.push(ByField {
                frame,
                field: field_named(name)?,
                bit,
                kind,
                target,
            }),
        }
        Ok(())
    }
}

#[pymethods]
impl Faults {
    #[new]
    #[pyo3(signature = (btr0 = 0x41, btr1 = 0x25))]
    fn new(btr0: u8, btr1: u8) -> Self {
        Faults {
            clock: BitClock::new(BusTiming::from_btr(btr0, btr1)),
            dec: Decoder::new(),
            clocks: 0,
            frames: 0,
            sof_bit: 0,
            field: None,
            field_bits: 0,
            active: Vec::new(),
            by_field: Vec::new(),
            applied: 0,
        }
    }

    /// Inverts bit `bit` of frame `frame` (from 1) for `target` (None:
    /// everyone; else a receiver index).
    #[pyo3(signature = (frame, bit, field = None, target = None))]
    fn flip(
        &mut self,
        frame: u32,
        bit: u32,
        field: Option<&str>,
        target: Option<usize>,
    ) -> PyResult<()> {
        self.add(Kind::Flip, frame, bit, field, target)
    }

    /// A pulse of `width` CAN clocks from `offset` clocks into the bit:
    /// the inverted level, or `level` if given.
    #[pyo3(signature = (frame, bit, offset, width, field = None, level = None, target = None))]
    #[allow(clippy::too_many_arguments)]
    fn glitch(
        &mut self,
        frame: u32,
        bit: u32,
        offset: u32,
        width: u32,
        field: Option<&str>,
        level: Option<bool>,
        target: Option<usize>,
    ) -> PyResult<()> {
        let per_bit = self.clock.clocks_per_bit();
        if width == 0 || offset + width > per_bit {
            return Err(PyValueError::new_err(format!(
                "offset {offset}, width {width}: the pulse must be at least 1 clock wide and end within the bit of {per_bit} CAN clocks"
            )));
        }
        self.add(
            Kind::Glitch {
                offset,
                width,
                level,
            },
            frame,
            bit,
            field,
            target,
        )
    }

    /// `level` for `bits` bit times from bit `bit` of frame `frame`, or
    /// from now when `frame` is None.
    #[pyo3(signature = (level, bits, frame = None, bit = 0, field = None, target = None))]
    fn stuck(
        &mut self,
        level: bool,
        bits: u64,
        frame: Option<u32>,
        bit: u32,
        field: Option<&str>,
        target: Option<usize>,
    ) -> PyResult<()> {
        if bits == 0 {
            return Err(PyValueError::new_err("a stuck bus lasts at least 1 bit"));
        }
        match frame {
            Some(f) => self.add(Kind::Stuck { level, bits }, f, bit, field, target),
            None if field.is_some() => Err(PyValueError::new_err(
                "a field names a bit of a frame: give frame too",
            )),
            None => {
                let from = self.clocks;
                self.active.push(Box::new(StuckAt {
                    level,
                    target: target.map_or(Target::All, Target::Node),
                    from,
                    until: Some(from + bits * u64::from(self.clock.clocks_per_bit())),
                }));
                Ok(())
            }
        }
    }

    /// One CAN clock of the wired-AND `level`: what receivers `0..n`
    /// receive (None while no fault is placed: everyone gets `level`).
    fn clock(&mut self, level: bool, n: usize) -> Option<Vec<bool>> {
        if self.active.is_empty() && self.by_field.is_empty() {
            self.clocks += 1;
            if self.clock.clock(level) {
                self.sample(level);
            }
            return None;
        }
        let ctx = self.context();
        let mut out = Vec::with_capacity(n);
        let mut changed = false;
        for node in 0..n {
            let mut l = level;
            for f in &mut self.active {
                l = f.apply(&ctx, node, l);
            }
            changed |= l != level;
            out.push(l);
        }
        self.applied += u64::from(changed);
        self.clocks += 1;
        if self.clock.clock(level) {
            self.sample(level);
        }
        Some(out)
    }

    /// CAN clocks at which a fault changed what some receiver got.
    #[getter]
    fn applied(&self) -> u64 {
        self.applied
    }

    /// Faults placed by field whose bit has not come yet.
    #[getter]
    fn waiting(&self) -> usize {
        self.by_field.len()
    }

    /// SOFs seen on the bus.
    #[getter]
    fn frames(&self) -> u32 {
        self.frames
    }
}
