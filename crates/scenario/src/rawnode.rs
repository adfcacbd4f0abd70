//! `[[raw-node]]` tables: a bit-level sender on the wire (the lower tester
//! of ISO 16845-1), validated into [`RawNodeSpec`] with file:line:key errors.
//!
//! ```toml
//! [[raw-node]]
//! name = "lt"
//! frame = 1; bit_in_frame = 57   # or at_bit = N, or idle_bits = 11
//! bits = "0 0000 1"              # levels per bit time, 0 = dominant
//! expect_bits = "0 0000 1 x 0"   # optional: the wire it must see from its first
//!                                # bit on (x: any); a miss, or a start that never
//!                                # comes, fails the run (a step-0 expectation)
//! # or a frame by its fields, any of them non-nominal; the CRC is computed
//! # over the bits as sent and stuff bits inserted, unless crc / flip say otherwise
//! fields = { id = 0x123, data = [1], r0 = 1, extended = false, srr = 0, r1 = 1, ack = 1, crc = 0x1234, flip = [40], until_bit = 40 }
//! # expect_ack = true in fields: the ACK slot must be dominant (another node's ACK)
//! offset_tq = 7                  # or offset_clocks: the first bit starts this far into
//!                                # the start bit (the DUT's quanta), the whole sequence
//!                                # with it: an early edge on the wire, seen by every node
//! ```

use crate::format::{RawFields, RawRawNode};
use crate::{Ctx, NodeSpec, ScenarioError};
use cosim::agents::raw::{RawFrame, RawStart};
use toml::Spanned;

/// A validated raw node.
#[derive(Clone, Debug, PartialEq)]
pub struct RawNodeSpec {
    /// Name.
    pub name: String,
    /// Where it starts.
    pub start: RawStart,
    /// The levels it drives, one per bit time (`false` = dominant).
    pub bits: Vec<bool>,
    /// The frame the levels were made from, if given by fields.
    pub frame: Option<RawFrame>,
    /// Levels it expects on the wire from its first bit on (`None`: any).
    pub expect: Vec<Option<bool>>,
    /// CAN clocks from the start point to its first bit (`offset_tq` /
    /// `offset_clocks`).
    pub delay_clocks: u32,
}

type Span = std::ops::Range<usize>;

fn level(ctx: &Ctx, span: &Span, key: &str, p: &str, v: Option<i64>, nominal: bool) -> Result<bool, ScenarioError> {
    match v {
        None => Ok(nominal),
        Some(0) => Ok(false),
        Some(1) => Ok(true),
        Some(x) => Err(ctx.err_key(span, key, &format!("{p}.{key}"), format!("{x} is not a bus level; use 0 (dominant) or 1 (recessive)"))),
    }
}

fn fields(ctx: &Ctx, span: &Span, p: &str, f: &RawFields) -> Result<RawFrame, ScenarioError> {
    let max = if f.extended { 0x1FFF_FFFF } else { 0x7FF };
    if !(0..=max).contains(&f.id) {
        return Err(ctx.err_key(span, "id", &format!("{p}.id"), format!("identifier {} is out of range (0..={max:#X}{})", f.id, if f.extended { "" } else { "; extended = true for 29 bits" })));
    }
    let dlc = f.dlc.unwrap_or(f.data.len() as i64);
    if !(0..=15).contains(&dlc) {
        return Err(ctx.err_key(span, "dlc", &format!("{p}.dlc"), format!("DLC {dlc} does not fit the 4-bit field (0..=15)")));
    }
    let want = if f.rtr { 0 } else { (dlc as usize).min(8) };
    if f.data.len() != want {
        return Err(ctx.err_key(span, "data", &format!("{p}.data"), format!("DLC {dlc}{} sends {want} data byte(s), {} given", if f.rtr { " (remote frame)" } else { "" }, f.data.len())));
    }
    let mut data = Vec::with_capacity(8);
    for &b in &f.data {
        data.push(u8::try_from(b).map_err(|_| ctx.err_key(span, "data", &format!("{p}.data"), format!("{b} does not fit in a byte (0..=255)")))?);
    }
    let crc = match f.crc {
        None => None,
        Some(c) if (0..=0x7FFF).contains(&c) => Some(c as u16),
        Some(c) => return Err(ctx.err_key(span, "crc", &format!("{p}.crc"), format!("{c} does not fit the 15-bit CRC (0..=0x7FFF)"))),
    };
    let mut frame = RawFrame {
        id: f.id as u32,
        extended: f.extended,
        rtr: f.rtr,
        dlc: dlc as u8,
        data,
        srr: level(ctx, span, "srr", p, f.srr, true)?,
        r1: level(ctx, span, "r1", p, f.r1, false)?,
        r0: level(ctx, span, "r0", p, f.r0, false)?,
        crc,
        ack: level(ctx, span, "ack", p, f.ack, true)?,
        flip: Vec::new(),
        until: None,
    };
    if !f.extended && (f.srr.is_some() || f.r1.is_some()) {
        let key = if f.srr.is_some() { "srr" } else { "r1" };
        return Err(ctx.err_key(span, key, &format!("{p}.{key}"), format!("{key} is a bit of the extended format; set extended = true (the base format's RTR is `rtr`)")));
    }
    let len = frame.wire_bits().len() as i64;
    for &i in &f.flip {
        if !(0..len).contains(&i) {
            return Err(ctx.err_key(span, "flip", &format!("{p}.flip"), format!("wire bit {i} is outside the frame's {len} bits (0..{len}, stuff bits included)")));
        }
        frame.flip.push(i as u32);
    }
    if let Some(u) = f.until_bit {
        if !(0..len).contains(&u) {
            return Err(ctx.err_key(span, "until_bit", &format!("{p}.until_bit"), format!("wire bit {u} is outside the frame's {len} bits (0..{len}, stuff bits included)")));
        }
        frame.until = Some(u as u32);
    }
    Ok(frame)
}

/// Validates the `[[raw-node]]` tables (`nodes`: the model nodes, whose
/// names a raw node may not take; `clocks_per_tq` / `clocks_per_bit`: the
/// DUT's timing, for `offset_tq` / `offset_clocks`).
pub(crate) fn build(ctx: &Ctx, raw: Vec<Spanned<RawRawNode>>, nodes: &[NodeSpec], clocks_per_tq: u32, clocks_per_bit: u32) -> Result<Vec<RawNodeSpec>, ScenarioError> {
    let mut out: Vec<RawNodeSpec> = Vec::new();
    for (i, r) in raw.into_iter().enumerate() {
        let span = r.span();
        let r = r.into_inner();
        let p = format!("raw-node[{}]", i + 1);
        if r.name.trim().is_empty() || nodes.iter().any(|n| n.name == r.name) {
            return Err(ctx.err_key(&span, "name", &format!("{p}.name"), format!("`{}`: a raw node needs a name of its own (not empty, not a [[node]]'s)", r.name)));
        }
        let start = match (r.at_bit, r.frame, r.bit_in_frame, r.idle_bits) {
            (Some(b), None, None, None) if b >= 0 => RawStart::AtBit(b as u64),
            (None, Some(f), Some(b), None) if f >= 1 && b >= 0 && f <= u32::MAX as i64 && b <= u32::MAX as i64 => RawStart::FrameBit { frame: f as u32, bit: b as u32 },
            (None, None, None, Some(n)) if (1..=1_000_000).contains(&n) => RawStart::IdleBits(n as u32),
            (None, Some(_), None, None) | (None, None, Some(_), None) => {
                return Err(ctx.err_key(&span, "frame", &format!("{p}.frame"), "give frame (from 1) and bit_in_frame (from 0) together"));
            }
            (None, None, None, None) => return Err(ctx.err(span, &p, "say where it starts: at_bit, frame + bit_in_frame, or idle_bits")),
            (Some(b), None, None, None) => return Err(ctx.err_key(&span, "at_bit", &format!("{p}.at_bit"), format!("{b}: a bit time is not negative"))),
            (None, Some(f), Some(b), None) => return Err(ctx.err_key(&span, "frame", &format!("{p}.frame"), format!("frame {f}, bit_in_frame {b}: frames count from 1, bits from 0"))),
            (None, None, None, Some(n)) => return Err(ctx.err_key(&span, "idle_bits", &format!("{p}.idle_bits"), format!("{n}: give 1 or more recessive bit times"))),
            _ => return Err(ctx.err(span, &p, "give one start: at_bit, frame + bit_in_frame, or idle_bits")),
        };
        let expect_ack = r.fields.as_ref().is_some_and(|f| f.expect_ack);
        let (bits, frame) = match (&r.bits, &r.fields) {
            (Some(s), None) => {
                let mut bits = Vec::new();
                for c in s.chars() {
                    match c {
                        '0' => bits.push(false),
                        '1' => bits.push(true),
                        ' ' | '_' => {}
                        other => return Err(ctx.err_key(&span, "bits", &format!("{p}.bits"), format!("`{other}` is not a level; use 0 (dominant) and 1 (recessive), spaces and _ to group"))),
                    }
                }
                if bits.is_empty() {
                    return Err(ctx.err_key(&span, "bits", &format!("{p}.bits"), "no level given"));
                }
                (bits, None)
            }
            (None, Some(f)) => {
                let frame = fields(ctx, &span, &format!("{p}.fields"), f)?;
                (frame.wire_bits(), Some(frame))
            }
            _ => return Err(ctx.err(span, &p, "give either bits (levels) or fields (a frame), not both")),
        };
        let mut expect = Vec::new();
        for c in r.expect_bits.as_deref().unwrap_or("").chars() {
            match c {
                '0' => expect.push(Some(false)),
                '1' => expect.push(Some(true)),
                'x' | 'X' => expect.push(None),
                ' ' | '_' => {}
                other => return Err(ctx.err_key(&span, "expect_bits", &format!("{p}.expect_bits"), format!("`{other}` is not a level; use 0, 1 or x (any), spaces and _ to group"))),
            }
        }
        if r.expect_bits.is_some() && expect.is_empty() {
            return Err(ctx.err_key(&span, "expect_bits", &format!("{p}.expect_bits"), "no level given"));
        }
        if expect_ack {
            let key = format!("{p}.fields.expect_ack");
            let f = frame.as_ref().expect("expect_ack is a key of fields");
            if r.expect_bits.is_some() {
                return Err(ctx.err_key(&span, "expect_ack", &key, "give expect_ack or expect_bits, not both"));
            }
            if !f.ack {
                return Err(ctx.err_key(&span, "expect_ack", &key, "the node drives its own ACK slot dominant (ack = 0): it would see its own bit"));
            }
            let slot = f.ack_slot().ok_or_else(|| ctx.err_key(&span, "expect_ack", &key, "the frame is cut (until_bit) before its ACK slot"))?;
            expect = vec![None; slot];
            expect.push(Some(false));
        }
        // A start inside the start bit, in the DUT's quanta or in clocks.
        let delay_clocks = match (r.offset_tq, r.offset_clocks) {
            (None, None) => 0,
            (Some(_), Some(_)) => return Err(ctx.err_key(&span, "offset_tq", &format!("{p}.offset_tq"), "give offset_tq or offset_clocks, not both")),
            (Some(o), None) if o >= 0 && o * i64::from(clocks_per_tq) < i64::from(clocks_per_bit) => o as u32 * clocks_per_tq,
            (None, Some(o)) if o >= 0 && o < i64::from(clocks_per_bit) => o as u32,
            (o_tq, _) => {
                let key = if o_tq.is_some() { "offset_tq" } else { "offset_clocks" };
                let v = o_tq.or(r.offset_clocks).unwrap_or_default();
                return Err(ctx.err_key(&span, key, &format!("{p}.{key}"), format!("{v}: the first bit must start inside the start bit ({} quanta, {clocks_per_bit} CAN clocks of the DUT's timing)", clocks_per_bit / clocks_per_tq.max(1))));
            }
        };
        if delay_clocks > 0 && matches!(start, RawStart::IdleBits(_)) {
            return Err(ctx.err_key(&span, if r.offset_tq.is_some() { "offset_tq" } else { "offset_clocks" }, &format!("{p}.offset_tq"), "an offset counts from a bit's start: give frame + bit_in_frame or at_bit"));
        }
        out.push(RawNodeSpec { name: r.name, start, bits, frame, expect, delay_clocks });
    }
    Ok(out)
}
