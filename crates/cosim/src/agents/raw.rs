//! A bit-level sender on the bus (ISO 16845-1's lower tester): drives a
//! given level sequence onto the wire from a chosen point, one level per bit
//! time of the bench's bit clock. It sends what the model nodes never send:
//! a frame with non-nominal reserved bits or SRR (its CRC computed over the
//! bits actually sent, stuff bits inserted), a start of frame at a chosen
//! intermission bit, a late or long acknowledge. It does not listen or back
//! off: every level it drives is the scenario's. Recessive drives nothing
//! (wired-AND), so the rest of the bus shows through.

use can_proto::{Crc15, DOMINANT, RECESSIVE};
use sja1000::BusContext;

/// Where a raw node starts driving its sequence.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RawStart {
    /// After this many bit times of recessive bus in a row (11: bus idle).
    IdleBits(u32),
    /// At the start of wire bit `bit` (SOF = 0, stuff bits, error and
    /// overload flags included) of frame `frame` (SOFs on the bus from 1):
    /// the numbering of frame-relative faults.
    FrameBit {
        /// Frame, from 1.
        frame: u32,
        /// Bit in it, from 0.
        bit: u32,
    },
    /// At bit time `at_bit` of the run (CAN clocks / clocks per bit).
    AtBit(u64),
}

/// A data or remote frame described by its fields, any of which may take
/// a value a nominal transmitter never sends. The CRC is computed over the
/// bits as sent (unless given), stuff bits are inserted from SOF to the end
/// of the CRC; the frame is valid except where a field says otherwise.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RawFrame {
    /// 11-bit or 29-bit identifier.
    pub id: u32,
    /// Extended format (IDE recessive).
    pub extended: bool,
    /// RTR level: true = recessive (remote frame).
    pub rtr: bool,
    /// DLC field (0..=15).
    pub dlc: u8,
    /// Data bytes sent (as many as the DLC asks, at most 8; none if RTR).
    pub data: Vec<u8>,
    /// SRR level (extended frames; nominal recessive).
    pub srr: bool,
    /// r1 level (extended frames; nominal dominant).
    pub r1: bool,
    /// r0 level (nominal dominant).
    pub r0: bool,
    /// CRC sequence sent instead of the computed one.
    pub crc: Option<u16>,
    /// Level the sender drives in the ACK slot (nominal recessive: it is the
    /// transmitter; dominant stands for another receiver's ACK).
    pub ack: bool,
    /// Wire bits (SOF = 0, after stuffing) sent inverted.
    pub flip: Vec<u32>,
    /// Last wire bit sent (the sender stops after it: a frame cut short by
    /// the error it provokes); `None`: through the end of frame.
    pub until: Option<u32>,
}

impl RawFrame {
    /// A nominal base-format data frame.
    pub fn base(id: u16, data: &[u8]) -> RawFrame {
        RawFrame {
            id: id as u32,
            extended: false,
            rtr: false,
            dlc: data.len() as u8,
            data: data.to_vec(),
            srr: RECESSIVE,
            r1: DOMINANT,
            r0: DOMINANT,
            crc: None,
            ack: RECESSIVE,
            flip: Vec::new(),
            until: None,
        }
    }

    /// A nominal extended-format data frame.
    pub fn extended(id: u32, data: &[u8]) -> RawFrame {
        RawFrame { extended: true, ..RawFrame::base(0, data) }.with_id(id)
    }

    fn with_id(mut self, id: u32) -> RawFrame {
        self.id = id;
        self
    }

    /// Destuffed bits from SOF to the last data bit.
    fn header_and_data(&self) -> Vec<bool> {
        let mut bits = Vec::with_capacity(120);
        let mut put = |value: u32, width: u32| {
            for i in (0..width).rev() {
                bits.push((value >> i) & 1 != 0);
            }
        };
        put(0, 1); // SOF
        if self.extended {
            put(self.id >> 18, 11);
            put(self.srr as u32, 1);
            put(1, 1); // IDE
            put(self.id & 0x3_FFFF, 18);
            put(self.rtr as u32, 1);
            put(self.r1 as u32, 1);
            put(self.r0 as u32, 1);
        } else {
            put(self.id & 0x7FF, 11);
            put(self.rtr as u32, 1);
            put(0, 1); // IDE
            put(self.r0 as u32, 1);
        }
        put(self.dlc as u32 & 0xF, 4);
        let n = if self.rtr { 0 } else { (self.dlc as usize).min(8) };
        for &b in self.data.iter().take(n) {
            put(b as u32, 8);
        }
        bits
    }

    /// Wire bit index of the ACK slot (SOF = 0), if the frame gets there
    /// (`until` may cut it short).
    pub fn ack_slot(&self) -> Option<usize> {
        let whole = RawFrame { until: None, ..self.clone() }.wire_bits().len();
        let slot = whole - 9;
        (self.until.is_none_or(|u| u as usize >= slot)).then_some(slot)
    }

    /// The CRC sent: the given one, else CRC-15 over the bits as sent.
    pub fn crc_sent(&self) -> u16 {
        self.crc.unwrap_or_else(|| Crc15::of(self.header_and_data()))
    }

    /// The whole frame as this sender drives it: stuffed SOF..CRC, CRC
    /// delimiter, ACK slot (`ack`), ACK delimiter, 7 EOF bits; `flip`
    /// applied, then cut after `until`.
    pub fn wire_bits(&self) -> Vec<bool> {
        let mut plain = self.header_and_data();
        let crc = self.crc_sent();
        for i in (0..15).rev() {
            plain.push((crc >> i) & 1 != 0);
        }
        let mut out = Vec::with_capacity(plain.len() + plain.len() / 4 + 10);
        let (mut last, mut run) = (None, 0u8);
        for b in plain {
            out.push(b);
            if last == Some(b) {
                run += 1;
            } else {
                (last, run) = (Some(b), 1);
            }
            if run == 5 {
                out.push(!b);
                (last, run) = (Some(!b), 1);
            }
        }
        out.push(RECESSIVE); // CRC delimiter
        out.push(self.ack);
        out.extend([RECESSIVE; 8]); // ACK delimiter, EOF
        for &i in &self.flip {
            if let Some(b) = out.get_mut(i as usize) {
                *b = !*b;
            }
        }
        if let Some(u) = self.until {
            out.truncate(u as usize + 1);
        }
        out
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// Not started; recessive clocks seen in a row (for `IdleBits`).
    Waiting { recessive: u64 },
    /// Driving (and monitoring); the clock its first bit started.
    Sending { from: u64 },
    /// Sequence sent and monitored.
    Done,
}

/// A raw node: a name, where it starts, the levels it drives, and the
/// levels it expects on the wire (the lower tester's monitor).
#[derive(Clone, Debug)]
pub struct RawNode {
    /// Name for reports.
    pub name: String,
    /// Where it starts.
    pub start: RawStart,
    /// One level per bit time (`false` = dominant).
    pub bits: Vec<bool>,
    /// Levels expected on the wire from its first bit on (`None`: any),
    /// sampled 3/4 into each of its bits; may run past `bits`.
    pub expect: Vec<Option<bool>>,
    /// Wire levels sampled so far, one per bit of `expect`.
    seen: Vec<bool>,
    /// Bits whose whole bit time has passed since its start.
    completed: usize,
    /// CAN clocks from its start point to its first bit (a start placed
    /// inside a bit, in quanta: an edge every node sees early).
    delay: u64,
    state: State,
}

impl RawNode {
    /// A node that drives `bits` from `start`.
    pub fn new(name: impl Into<String>, start: RawStart, bits: Vec<bool>) -> RawNode {
        RawNode { name: name.into(), start, bits, expect: Vec::new(), seen: Vec::new(), completed: 0, delay: 0, state: State::Waiting { recessive: 0 } }
    }

    /// Its first bit starts `clocks` CAN clocks after its start point (the
    /// whole sequence moves with it).
    pub fn delayed(mut self, clocks: u32) -> RawNode {
        self.delay = u64::from(clocks);
        self
    }

    /// The levels it expects on the wire from its first bit on.
    pub fn expecting(mut self, expect: Vec<Option<bool>>) -> RawNode {
        self.expect = expect;
        self
    }

    /// Bit times it is active for: driving up to its last dominant bit
    /// (trailing recessive bits drive nothing), monitoring up to its last
    /// expected bit.
    fn len(&self) -> usize {
        self.driven_len().max(self.expect.len())
    }

    /// Bits up to its last dominant one.
    fn driven_len(&self) -> usize {
        self.bits.iter().rposition(|&b| b == DOMINANT).map_or(0, |i| i + 1)
    }

    /// The level it drives for the coming CAN clock, given the bench's bus
    /// context for that clock and the bus level at the last clock.
    pub fn drive(&mut self, ctx: &BusContext, last_level: bool) -> bool {
        let cpb = u64::from(ctx.clocks_per_bit.max(1));
        if let State::Waiting { recessive } = self.state {
            let recessive = if last_level == RECESSIVE { recessive + 1 } else { 0 };
            let go = match self.start {
                RawStart::IdleBits(n) => recessive >= u64::from(n) * cpb,
                RawStart::FrameBit { frame, bit } => {
                    ctx.frame == Some(u64::from(frame) - 1) && ctx.frame_bit == bit
                }
                RawStart::AtBit(b) => ctx.clock >= b * cpb,
            };
            // A frame bit starts where the bench's bit started: for bits
            // after the SOF that is this clock (the bit boundary); the SOF's
            // frame number is known only from its sample point on, so bit 0
            // of a frame is joined late, on the grid of the SOF.
            let from = match self.start {
                RawStart::FrameBit { .. } => ctx.clock - u64::from(ctx.sub).min(ctx.clock),
                _ => ctx.clock,
            };
            self.state = if go { State::Sending { from: from + self.delay } } else { State::Waiting { recessive } };
        }
        match self.state {
            // Started, its first bit not yet (`delay`).
            State::Sending { from } if ctx.clock < from => RECESSIVE,
            State::Sending { from } => {
                let k = ctx.clock - from;
                let i = (k / cpb) as usize;
                // The wire 3/4 into bit i - the level of the clock before
                // this one - for the monitor.
                if k % cpb == (cpb * 3 / 4 + 1).min(cpb - 1) && i < self.expect.len() && self.seen.len() == i {
                    self.seen.push(last_level);
                }
                self.completed = i;
                if i >= self.len() {
                    self.state = State::Done;
                    return RECESSIVE;
                }
                self.bits.get(i).copied().unwrap_or(RECESSIVE)
            }
            _ => RECESSIVE,
        }
    }

    /// True once its whole sequence was driven and monitored.
    pub fn done(&self) -> bool {
        self.state == State::Done
    }

    /// Its verdict at the end of a run: `Ok` with what it did, or `Err`
    /// with why not: it never started (its start point did not come), the
    /// run ended before its sequence did, or the wire differed from what it
    /// expects (the first such bit, counted from its start).
    pub fn verdict(&self) -> Result<String, String> {
        let show = |v: &[bool]| v.iter().map(|&b| if b { '1' } else { '0' }).collect::<String>();
        let start = match self.start {
            RawStart::IdleBits(n) => format!("after {n} recessive bits"),
            RawStart::FrameBit { frame, bit } => format!("at bit {bit} of frame {frame}"),
            RawStart::AtBit(b) => format!("at bit time {b}"),
        };
        if let State::Waiting { .. } = self.state {
            return Err(format!("never started: its start ({start}) did not come"));
        }
        for (i, (want, &got)) in self.expect.iter().zip(&self.seen).enumerate() {
            if want.is_some_and(|w| w != got) {
                return Err(format!("wire bit {i} from its start ({start}) is {}, expected {}; wire seen: {}", got as u8, !got as u8, show(&self.seen)));
            }
        }
        if self.completed < self.driven_len() || self.seen.len() < self.expect.len() {
            return Err(format!(
                "the run ended before its sequence did ({} of {} bit(s) to its last dominant one driven, {} of {} expected bit(s) seen; {start})",
                self.completed.min(self.driven_len()),
                self.driven_len(),
                self.seen.len(),
                self.expect.len()
            ));
        }
        Ok(format!("{} bit(s) driven{} {start}", self.bits.len(), if self.expect.is_empty() { String::new() } else { format!(", wire as expected ({})", show(&self.seen)) }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx(clock: u64, frame: Option<u64>, frame_bit: u32) -> BusContext {
        BusContext { clock, frame, frame_bit, sub: 0, clocks_per_bit: 4 }
    }

    fn bits(s: &str) -> Vec<bool> {
        s.chars().filter(|c| *c == '0' || *c == '1').map(|c| c == '1').collect()
    }

    #[test]
    fn a_nominal_frame_is_the_wire_format_of_can_proto() {
        // The same frame from can-proto's transmitter path: the raw sender's
        // encoding (CRC, stuffing, tail) agrees bit for bit.
        for (raw, frame) in [
            (RawFrame::base(0x3C3, &[0]), can_proto::CanFrame::with_dlc(can_proto::CanFrame::std_id(0x3C3).unwrap(), false, 1, &[0]).unwrap()),
            (RawFrame::base(0x000, &[]), can_proto::CanFrame::with_dlc(can_proto::CanFrame::std_id(0).unwrap(), false, 0, &[]).unwrap()),
            (
                RawFrame::extended(0x1555_5555, &[0xFF, 0x00, 0xAA]),
                can_proto::CanFrame::with_dlc(can_proto::CanFrame::ext_id(0x1555_5555).unwrap(), false, 3, &[0xFF, 0x00, 0xAA]).unwrap(),
            ),
        ] {
            let want: Vec<bool> = frame.wire_bits().iter().by_vals().collect();
            assert_eq!(raw.wire_bits(), want, "{raw:?}");
            assert_eq!(raw.crc_sent(), frame.crc());
        }
    }

    #[test]
    fn a_recessive_r0_is_sent_with_the_crc_over_the_bits_as_sent() {
        // ID 0x000, DLC 0: SOF and 11 ID bits dominant; stuff bits after
        // SOF+4, then every 5. With r0 recessive the header differs at r0.
        let nominal = RawFrame::base(0, &[]);
        let odd = RawFrame { r0: RECESSIVE, ..nominal.clone() };
        assert_ne!(odd.crc_sent(), nominal.crc_sent(), "the CRC covers r0");
        let mut plain = vec![false; 12]; // SOF, ID
        plain.extend([false, false, true]); // RTR, IDE, r0 = 1
        plain.extend([false; 4]); // DLC 0
        assert_eq!(odd.crc_sent(), Crc15::of(plain.clone()));
        // Stuffed: 0000 0[1] 0000 [1] 00 0 1 0000 [1]? spelled out:
        let w = odd.wire_bits();
        assert_eq!(&w[..5], &bits("00000"));
        assert!(w[5], "stuff bit after 5 dominant bits");
        // SOF + ID + RTR + IDE = 14 dominant destuffed bits: stuff at 5, 11, 17.
        assert_eq!(&w[6..11], &bits("00000"));
        assert!(w[11]);
        assert_eq!(&w[12..16], &bits("0000"), "ID.1, ID.0, RTR, IDE");
        assert!(w[16], "r0 recessive");
        // The tail: CRC delimiter, ACK slot sent recessive, ACK delimiter, EOF.
        assert_eq!(&w[w.len() - 10..], &[true; 10]);
    }

    #[test]
    fn dominant_srr_and_recessive_r1_in_an_extended_frame() {
        let nominal = RawFrame::extended(0x0ABC_DEF0 & 0x1FFF_FFFF, &[0x55]);
        let odd = RawFrame { srr: DOMINANT, r1: RECESSIVE, ..nominal.clone() };
        let (n, o) = (nominal.header_and_data(), odd.header_and_data());
        // SRR is destuffed bit 12, r1 bit 33 (after RTR at 32).
        assert_eq!((n[12], o[12]), (RECESSIVE, DOMINANT));
        assert_eq!((n[33], o[33]), (DOMINANT, RECESSIVE));
        let diff: Vec<usize> = (0..n.len()).filter(|&i| n[i] != o[i]).collect();
        assert_eq!(diff, vec![12, 33], "nothing else changes");
        assert_eq!(odd.crc_sent(), Crc15::of(o));
    }

    #[test]
    fn given_crc_ack_and_flips_are_sent_as_said() {
        let f = RawFrame { crc: Some(0x1234), ack: DOMINANT, flip: vec![0], ..RawFrame::base(0x7FF, &[]) };
        assert_eq!(f.crc_sent(), 0x1234);
        let w = f.wire_bits();
        assert!(w[0], "SOF flipped");
        assert_eq!(w[w.len() - 9], DOMINANT, "ACK slot driven");
        assert_eq!(f.ack_slot(), Some(w.len() - 9));
        assert_eq!(RawFrame::base(0x3C3, &[0]).ack_slot(), Some(46), "0x3C3 [00]: CRC delimiter 45, ACK 46");
        // 0x3C3 [00]: stuff bits at 17, 25, 31; flipping 25 makes a sixth
        // dominant bit (a stuff error), and the sender stops there.
        let f = RawFrame { flip: vec![25], until: Some(25), ..RawFrame::base(0x3C3, &[0]) };
        let w = f.wire_bits();
        assert_eq!(w.len(), 26);
        assert_eq!(f.ack_slot(), None, "cut before its ACK slot");
        assert_eq!(&w[20..26], &[DOMINANT; 6], "data bits 0-4 and the flipped stuff bit");
        let nominal = RawFrame::base(0x3C3, &[0]).wire_bits();
        assert_eq!(&w[..25], &nominal[..25]);
        assert_eq!(nominal[25], RECESSIVE, "the stuff bit");
    }

    #[test]
    fn it_starts_at_a_frame_bit_and_drives_one_level_per_bit_time() {
        let mut n = RawNode::new("lt", RawStart::FrameBit { frame: 2, bit: 57 }, bits("010"));
        assert_eq!(n.drive(&ctx(10, Some(0), 57), true), RECESSIVE, "frame 1: not yet");
        assert_eq!(n.drive(&ctx(11, Some(1), 56), true), RECESSIVE);
        let got: Vec<bool> = (0..14).map(|k| n.drive(&ctx(20 + k, Some(1), 57), true)).collect();
        assert_eq!(got, bits("0000 1111 0000 11"), "4 clocks per bit, then recessive");
        assert!(n.done());
    }

    #[test]
    fn bit_0_of_a_frame_is_joined_on_the_grid_of_its_sof() {
        // The frame number appears at the SOF's sample point (sub 25 of 40 here):
        // the node's bit 0 is the rest of that bit, its bit 1 the next bit.
        let mut n = RawNode::new("lt", RawStart::FrameBit { frame: 1, bit: 0 }, bits("01"));
        let c = |clock, sub| BusContext { clock, frame: Some(0), frame_bit: 0, sub, clocks_per_bit: 40 };
        assert_eq!(n.drive(&c(125, 25), false), DOMINANT);
        assert_eq!(n.drive(&c(139, 39), false), DOMINANT, "still bit 0");
        assert_eq!(n.drive(&c(140, 0), false), RECESSIVE, "bit 1 from the bench's next bit");
    }

    #[test]
    fn it_starts_after_idle_bits_of_recessive_bus_and_a_dominant_bit_restarts_the_count() {
        let mut n = RawNode::new("lt", RawStart::IdleBits(2), bits("0"));
        let mut out = Vec::new();
        // 7 recessive clocks, one dominant, then recessive: starts after 8 recessive in a row.
        for k in 0..20u64 {
            let level = k != 7;
            out.push(n.drive(&ctx(k, None, 0), level));
        }
        let first = out.iter().position(|&b| !b).unwrap();
        assert_eq!(first, 15, "8 recessive clocks (2 bits) counted from clock 8");
        assert_eq!(out[15..19], [false; 4]);
        assert!(out[19]);
    }

    #[test]
    fn the_monitor_compares_the_wire_and_a_start_that_never_comes_is_a_failure() {
        // Drives "0", expects "0 x 1 0": bit 2 recessive and bit 3 dominant
        // (another transmitter's bits) on the wire.
        let run = |wire: &str| {
            let wire = bits(wire);
            let mut n = RawNode::new("lt", RawStart::AtBit(0), bits("0")).expecting(vec![Some(false), None, Some(true), Some(false)]);
            let mut level = true;
            for k in 0..20u64 {
                let drive = n.drive(&ctx(k, None, 0), level);
                level = drive & wire[(k / 4) as usize];
            }
            n
        };
        let ok = run("1 0 1 0 1");
        assert!(ok.done());
        assert!(ok.verdict().unwrap().contains("wire as expected (0010)"), "{:?}", ok.verdict());
        let bad = run("1 1 0 0 1");
        assert!(bad.verdict().unwrap_err().contains("wire bit 2"), "{:?}", bad.verdict());
        let never = RawNode::new("lt", RawStart::FrameBit { frame: 3, bit: 0 }, bits("0"));
        assert!(never.verdict().unwrap_err().contains("never started"));
        let mut cut = RawNode::new("lt", RawStart::AtBit(0), bits("000"));
        cut.drive(&ctx(0, None, 0), true);
        assert!(cut.verdict().unwrap_err().contains("run ended"));
    }

    #[test]
    fn a_delayed_node_moves_its_whole_sequence_and_its_monitor() {
        // Start at bit 57 of frame 2, 6 clocks in: "01" at 4 clocks per bit
        // is dominant over clocks 6..10 of the run, recessive after.
        let mut n = RawNode::new("lt", RawStart::FrameBit { frame: 2, bit: 57 }, bits("01")).delayed(6).expecting(vec![Some(false), Some(true)]);
        let mut level = true;
        let mut out = Vec::new();
        for k in 0..16u64 {
            let d = n.drive(&ctx(k, Some(1), 57), level);
            out.push(d);
            level = d;
        }
        assert_eq!(out, bits("1111 1100 0011 1111"), "the dominant bit from clock 6 on");
        assert!(n.done());
        assert!(n.verdict().unwrap().contains("wire as expected (01)"), "{:?}", n.verdict());
        let undelayed: Vec<bool> = {
            let mut n = RawNode::new("lt", RawStart::FrameBit { frame: 2, bit: 57 }, bits("01"));
            (0..8u64).map(|k| n.drive(&ctx(k, Some(1), 57), true)).collect()
        };
        assert_eq!(undelayed, bits("0000 1111"));
    }

    #[test]
    fn at_bit_counts_bit_times_of_the_bench() {
        let mut n = RawNode::new("lt", RawStart::AtBit(3), bits("0"));
        let first = (0..20u64).position(|k| !n.drive(&ctx(k, None, 0), true)).unwrap();
        assert_eq!(first, 12);
    }
}
