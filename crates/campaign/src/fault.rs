//! Faults of a campaign: what is injected, where it is aimed, and the one
//! injector shared by the model nodes' receivers and the DUT's `rx_i`.
//!
//! The test bench applies one fault list to the DUT's receiver (with a
//! context from its own bit clock) and the `sja1000` bus another to the
//! model nodes (with the bus tracker's context). A single
//! [`SharedInjector`] is installed in both places:
//! the bus calls it first for every node, it keeps that context, and the
//! DUT's call in the same CAN clock reuses it. So a fault aimed at "bit 37
//! of bus frame 12" hits the DUT and the model nodes at the same instant.

use std::cell::RefCell;
use std::fmt;
use std::rc::Rc;

use can_proto::{CanFrame, Field};
use rand::{Rng, RngExt};
use sja1000::{BusContext, FaultInjector, FlipBit, Glitch, Target};

/// What a fault does to the level a receiver sees.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultKind {
    /// One bit inverted.
    Flip,
    /// The level forced for `bits` bit times.
    Stuck {
        /// Level forced (`true` = recessive).
        level: bool,
        /// Length in bit times.
        bits: u32,
    },
    /// A pulse of the opposite level inside one bit.
    Glitch {
        /// First CAN clock of the pulse within the bit.
        offset: u32,
        /// Pulse length in CAN clocks.
        width: u32,
    },
}

impl FaultKind {
    /// Name for the report's tallies.
    pub fn name(&self) -> &'static str {
        match self {
            FaultKind::Flip => "bit flip",
            FaultKind::Stuck { level: false, .. } => "stuck dominant",
            FaultKind::Stuck { level: true, .. } => "stuck recessive",
            FaultKind::Glitch { .. } => "glitch",
        }
    }
}

impl fmt::Display for FaultKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FaultKind::Flip => write!(f, "bit flip"),
            FaultKind::Stuck { level, bits } => write!(f, "stuck {} for {bits} bit(s)", if *level { "recessive" } else { "dominant" }),
            FaultKind::Glitch { offset, width } => write!(f, "glitch of {width} clock(s) at clock {offset} of the bit"),
        }
    }
}

/// Who sees a fault.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaultTarget {
    /// Every receiver: the DUT and all model nodes (a disturbed bus).
    All,
    /// Only the DUT's `rx_i` (and its lockstep reference, which is clocked with it).
    Dut,
    /// Only model node `i`'s receiver.
    Node(usize),
}

impl fmt::Display for FaultTarget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FaultTarget::All => write!(f, "every receiver"),
            FaultTarget::Dut => write!(f, "the DUT's rx"),
            FaultTarget::Node(i) => write!(f, "node{}'s rx", i + 1),
        }
    }
}

/// The part of the frame a fault is aimed at (CAN 2.0B field names).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Aim {
    /// Start of frame.
    Sof,
    /// Identifier, SRR, IDE, RTR.
    Arbitration,
    /// r1, r0, DLC.
    Control,
    /// Data field.
    Data,
    /// CRC sequence.
    Crc,
    /// A stuff bit (any field).
    StuffBit,
    /// CRC delimiter.
    CrcDelim,
    /// ACK slot.
    AckSlot,
    /// ACK delimiter.
    AckDelim,
    /// End of frame.
    Eof,
    /// Inside the error flags that follow a provoking flip.
    ErrorFlag,
    /// Inside the error delimiter that follows a provoking flip (position approximate).
    ErrorDelimiter,
    /// Intermission after the frame.
    Intermission,
}

impl Aim {
    /// Every aim, in frame order.
    pub const ALL: [Aim; 13] = [
        Aim::Sof,
        Aim::Arbitration,
        Aim::Control,
        Aim::Data,
        Aim::Crc,
        Aim::StuffBit,
        Aim::CrcDelim,
        Aim::AckSlot,
        Aim::AckDelim,
        Aim::Eof,
        Aim::ErrorFlag,
        Aim::ErrorDelimiter,
        Aim::Intermission,
    ];

    /// The aim of a frame field.
    pub fn of_field(f: Field) -> Option<Aim> {
        Some(match f {
            Field::Sof => Aim::Sof,
            Field::BaseId | Field::SrrRtr | Field::Ide | Field::ExtId | Field::Rtr => Aim::Arbitration,
            Field::R1 | Field::R0 | Field::Dlc => Aim::Control,
            Field::Data => Aim::Data,
            Field::Crc => Aim::Crc,
            Field::CrcDelim => Aim::CrcDelim,
            Field::AckSlot => Aim::AckSlot,
            Field::AckDelim => Aim::AckDelim,
            Field::Eof => Aim::Eof,
            Field::Intermission => Aim::Intermission,
            _ => return None,
        })
    }

    /// Name for the report.
    pub fn name(&self) -> &'static str {
        match self {
            Aim::Sof => "start of frame",
            Aim::Arbitration => "arbitration field",
            Aim::Control => "control field",
            Aim::Data => "data field",
            Aim::Crc => "CRC sequence",
            Aim::StuffBit => "stuff bit",
            Aim::CrcDelim => "CRC delimiter",
            Aim::AckSlot => "ACK slot",
            Aim::AckDelim => "ACK delimiter",
            Aim::Eof => "end of frame",
            Aim::ErrorFlag => "error flag",
            Aim::ErrorDelimiter => "error delimiter",
            Aim::Intermission => "intermission",
        }
    }
}

/// One fault at a wire bit of a bus frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaultAt {
    /// What it does.
    pub kind: FaultKind,
    /// Who sees it.
    pub target: FaultTarget,
    /// Wire bit from SOF = 0 (stuff bits, flags and intermission counted).
    pub bit: u32,
}

/// The fault of one campaign frame: the aimed fault, and for aims inside
/// an error frame the flip (seen by every receiver) that provokes it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlannedFault {
    /// Where it is aimed.
    pub aim: Aim,
    /// The aimed fault.
    pub fault: FaultAt,
    /// Flip that provokes the error frame, for [`Aim::ErrorFlag`] and [`Aim::ErrorDelimiter`].
    pub provoke: Option<FaultAt>,
}

impl fmt::Display for PlannedFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} seen by {} at wire bit {} ({})", self.fault.kind, self.fault.target, self.fault.bit, self.aim.name())?;
        if let Some(p) = &self.provoke {
            write!(f, ", after a flip seen by {} at wire bit {}", p.target, p.bit)?;
        }
        Ok(())
    }
}

/// Draws a fault aimed at a random part of `frame` (the frame expected to
/// be on the wire). `n_nodes` model nodes; `clocks_per_bit` of the bus
/// timing; a glitch never overlaps the CAN clocks `keep_out` (first, last)
/// of the bit, if given.
pub fn plan(rng: &mut impl Rng, frame: &CanFrame, n_nodes: usize, clocks_per_bit: u32, keep_out: Option<(u32, u32)>) -> PlannedFault {
    let layout = frame.wire_layout();
    let kind = match rng.random_range(0..10u32) {
        0..4 => FaultKind::Flip,
        4..7 => FaultKind::Stuck { level: rng.random_bool(0.5), bits: rng.random_range(1..=6) },
        _ => {
            let cpb = clocks_per_bit.max(2);
            let mut g = (0, 1);
            for _ in 0..64 {
                let (offset, width) = (rng.random_range(0..cpb), rng.random_range(1..=(cpb / 4).max(1)));
                if keep_out.is_none_or(|(lo, hi)| offset + width <= lo || offset > hi) {
                    g = (offset, width);
                    break;
                }
            }
            FaultKind::Glitch { offset: g.0, width: g.1 }
        }
    };
    let target = match rng.random_range(0..4u32) {
        0 | 1 => FaultTarget::All,
        2 => FaultTarget::Dut,
        _ => FaultTarget::Node(rng.random_range(0..n_nodes.max(1))),
    };
    let pick = |rng: &mut _, want: &dyn Fn(usize) -> bool| -> Option<u32> {
        let c: Vec<u32> = (0..layout.len()).filter(|&i| want(i)).map(|i| i as u32).collect();
        if c.is_empty() { None } else { Some(c[RngExt::random_range(rng, 0..c.len())]) }
    };
    // Draw an aim; aims the frame lacks (no data, no stuff bit) are drawn again.
    for _ in 0..16 {
        let aim = Aim::ALL[rng.random_range(0..Aim::ALL.len())];
        let (bit, provoke) = match aim {
            Aim::StuffBit => match pick(rng, &|i| layout[i].stuff) {
                Some(b) => (b, None),
                None => continue,
            },
            Aim::Intermission => (layout.len() as u32 + rng.random_range(0..3), None),
            Aim::ErrorFlag | Aim::ErrorDelimiter => {
                let Some(p) = pick(rng, &|i| matches!(layout[i].field, Field::Dlc | Field::Data | Field::Crc) && !layout[i].stuff) else {
                    continue;
                };
                // The transmitter's flag starts right after the flipped bit;
                // the others' flags end at the latest 12 bits after it.
                let off = if aim == Aim::ErrorFlag { rng.random_range(1..=6) } else { rng.random_range(13..=15) };
                (p + off, Some(FaultAt { kind: FaultKind::Flip, target: FaultTarget::All, bit: p }))
            }
            a => match pick(rng, &|i| !layout[i].stuff && Aim::of_field(layout[i].field) == Some(a)) {
                Some(b) => (b, None),
                None => continue,
            },
        };
        return PlannedFault { aim, fault: FaultAt { kind, target, bit }, provoke };
    }
    PlannedFault { aim: Aim::Sof, fault: FaultAt { kind, target, bit: 0 }, provoke: None }
}

#[derive(Clone, Copy, Debug)]
struct Armed {
    frame: u64,
    at: FaultAt,
    aimed: bool,
}

/// State shared by every copy of the injector.
#[derive(Debug, Default)]
pub struct Shared {
    n_nodes: usize,
    armed: Vec<Armed>,
    last: BusContext,
    /// The aimed fault's bit went by on the wire.
    pub reached: bool,
    /// Receiver levels the faults changed (summed over receivers and clocks).
    pub changed: u64,
}

impl Shared {
    /// Arms `p` for bus frame `frame` (replacing what was armed).
    pub fn arm(&mut self, frame: u64, p: &PlannedFault) {
        self.armed.clear();
        self.reached = false;
        self.changed = 0;
        self.armed.push(Armed { frame, at: p.fault, aimed: true });
        if let Some(q) = p.provoke {
            self.armed.push(Armed { frame, at: q, aimed: false });
        }
    }

    /// Removes every armed fault.
    pub fn disarm(&mut self) {
        self.armed.clear();
        self.reached = false;
    }
}

/// The injector installed on the bus and on the DUT's receiver; clones share state.
#[derive(Clone, Debug)]
pub struct SharedInjector(pub Rc<RefCell<Shared>>);

impl SharedInjector {
    /// An injector for a bus of `n_nodes` model nodes (the DUT is node `n_nodes`).
    pub fn new(n_nodes: usize) -> Self {
        SharedInjector(Rc::new(RefCell::new(Shared { n_nodes, ..Shared::default() })))
    }
}

impl FaultInjector for SharedInjector {
    fn apply(&mut self, ctx: &BusContext, node: usize, level: bool) -> bool {
        let mut s = self.0.borrow_mut();
        // The bus applies it to its nodes, then to the DUT's rx (node
        // `n_nodes`) in the same CAN clock: the DUT reuses the bus's frame
        // context, so frames and bits are counted the same way for every receiver.
        let ctx = if node < s.n_nodes {
            s.last = *ctx;
            *ctx
        } else {
            s.last
        };
        let mut out = level;
        let mut reached = false;
        for a in &s.armed {
            let target = match a.at.target {
                FaultTarget::All => Target::All,
                FaultTarget::Dut => Target::Node(s.n_nodes),
                FaultTarget::Node(i) => Target::Node(i),
            };
            if a.aimed && ctx.frame == Some(a.frame) && ctx.frame_bit == a.at.bit {
                reached = true;
            }
            out = match a.at.kind {
                FaultKind::Flip => FlipBit { frame: a.frame, bit: a.at.bit, target }.apply(&ctx, node, out),
                FaultKind::Glitch { offset, width } => Glitch { frame: a.frame, bit: a.at.bit, offset, width, target }.apply(&ctx, node, out),
                FaultKind::Stuck { level: l, bits } => {
                    let on = ctx.frame == Some(a.frame) && ctx.frame_bit >= a.at.bit && ctx.frame_bit < a.at.bit + bits;
                    let hits = match target {
                        Target::All => true,
                        Target::Node(n) => n == node,
                    };
                    if on && hits { l } else { out }
                }
            };
        }
        s.reached |= reached;
        s.changed += (out != level) as u64;
        out
    }

    fn needs_clocks(&self) -> bool {
        true
    }
}
