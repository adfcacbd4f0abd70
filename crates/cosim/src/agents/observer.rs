//! The observer agent: watches the bus and the reference and writes down
//! what happened, never drives anything. It holds the bench's bit clock
//! (sample points from BTR0/BTR1), the field decoder of the bus bits (frame
//! number, field, start of the current frame), our VCD, the run record for
//! the diagnoser and the bus log for `--candump`.

use can_proto::decode::{DecodeEvent, Decoder};
use can_proto::timing::BusTiming;
use can_proto::Field;
use diagnose::{BusBit, EngineEvent, RunRecord, Side};
use sja1000::BusContext;

use crate::bitclock::BitClock;
use crate::candump::BusLog;
use crate::model::AnyRef;
use crate::types::{CanPins, RefView, SR_ADDR, Stamp};
use crate::wave::{Wave, WaveSample};

/// Bit clock, field decoder, VCD, run record and bus log of one run.
pub struct Observer {
    bitclock: BitClock,
    /// Decodes the wire: frames (SOFs) and the bus log.
    decoder: Decoder,
    /// Decodes the bus as the nodes see it (the wire through the faults
    /// every node receives): the fields. After such a fault the wire alone
    /// would take the nodes' error flags for frame bits and name every
    /// later field wrong until the bus is idle.
    seen_decoder: Decoder,
    /// The field now, of the bus as the nodes see it.
    field: Option<Field>,
    /// Frames seen (SOFs), counted from 1.
    frame: u32,
    /// Bit index (bit clock count) of the last SOF.
    sof_bit: u64,
    /// This CAN clock is a sample point (for the VCD).
    sample_now: bool,
    wave: Option<Wave>,
    /// Bus bits kept in the record.
    keep_bits: usize,
    /// The run record (every agent reports into it through the bench).
    pub record: RunRecord,
    /// Scratch for the reference's engine events of one clock.
    events: Vec<diagnose::EventKind>,
    /// Time and bit of the last transmission request (CMR.TR / SRR).
    pub last_tr: Option<(u64, u64)>,
    /// Transmission attempts of the reference since a request (TEC trace).
    attempts: u32,
    /// Frames on the bus and the DUT's error frames, for `--candump`.
    bus_log: BusLog,
}

impl Observer {
    /// An observer of a bus timed by `btr0`/`btr1`, writing `record`, our
    /// VCD to `wave` if given, keeping `keep_bits` bus bits.
    pub fn new(btr0: u8, btr1: u8, record: RunRecord, wave: Option<Wave>, keep_bits: usize) -> Observer {
        Observer {
            bitclock: BitClock::new(BusTiming::from_btr(btr0, btr1)),
            decoder: Decoder::new(),
            seen_decoder: Decoder::new(),
            field: None,
            frame: 0,
            sof_bit: 0,
            sample_now: false,
            wave,
            keep_bits,
            record,
            events: Vec::new(),
            last_tr: None,
            attempts: 0,
            bus_log: BusLog::new(),
        }
    }

    /// Bits sampled so far.
    #[inline]
    pub fn bits(&self) -> u64 {
        self.bitclock.bits()
    }

    /// CAN clocks per bit of the bit timing in force.
    #[inline]
    pub fn clocks_per_bit(&self) -> u32 {
        self.bitclock.clocks_per_bit()
    }

    /// The decoder's field now.
    pub fn field(&self) -> Option<Field> {
        self.field
    }

    /// Frames seen so far (0: none yet).
    pub fn frame(&self) -> u32 {
        self.frame
    }

    /// The frame number for a stamp (`None` before the first SOF).
    #[inline]
    pub fn frame_no(&self) -> Option<u32> {
        if self.frame > 0 { Some(self.frame) } else { None }
    }

    /// Our VCD is being written.
    #[inline]
    pub fn waving(&self) -> bool {
        self.wave.is_some()
    }

    /// One CAN clock of the bus at `level`: true at a sample point.
    #[inline]
    pub fn clock(&mut self, level: bool) -> bool {
        let s = self.bitclock.clock(level);
        self.sample_now = s;
        s
    }

    /// `n` clocks of the bus at the level of the last one, none a sample
    /// point (at most [`Observer::clocks_before_sample`]): `clock` `n` times.
    #[inline]
    pub fn quiet_clocks(&mut self, n: u32) {
        self.bitclock.quiet_clocks(n);
        self.sample_now = false;
    }

    /// CAN clocks ahead, with the bus staying at `level`, that are not
    /// sample points of the bench's bit clock ([`BitClock::clocks_before_sample`]).
    #[inline]
    pub fn clocks_before_sample(&self, level: bool) -> u32 {
        self.bitclock.clocks_before_sample(level)
    }

    /// Where a comparison of this clock happens: the reference's field if
    /// it knows one, else the decoder's.
    #[inline]
    pub fn stamp(&self, t_ps: u64, bit: u64, ref_field: Option<Field>) -> Stamp {
        Stamp { t_ps, bit, field: ref_field.or(self.field), frame: self.frame_no() }
    }

    /// What a fault on the DUT's rx sees of the bus now (frames counted
    /// from 0 for `sja1000::BusContext`).
    pub fn bus_context(&self, can_clock: u64) -> BusContext {
        BusContext {
            clock: can_clock,
            frame: self.frame.checked_sub(1).map(u64::from),
            // Bit-boundary aligned (bitclock::bit_in_progress): a one-bit
            // fault covers the whole bit for the DUT and the reference.
            frame_bit: self.bitclock.bit_in_progress().saturating_sub(self.sof_bit) as u32,
            sub: self.bitclock.sub(),
            clocks_per_bit: self.bitclock.clocks_per_bit(),
        }
    }

    /// A host write to BTR0 or BTR1 took effect: the record and the bit
    /// clock follow it.
    pub fn set_btr(&mut self, addr: u8, data: u8) {
        let t = &mut self.record.timing;
        if addr == 6 {
            t.btr0 = data
        } else {
            t.btr1 = data
        }
        let (b0, b1) = (t.btr0, t.btr1);
        self.bitclock.set_timing(BusTiming::from_btr(b0, b1));
    }

    /// A sample point at `bit`: the decoder, and the bus bit into the record
    /// while `recording` (the comparison has not stopped). Out of line
    /// (once per bit), so the per-clock part stays small.
    #[inline(never)]
    pub fn sample_point(
        &mut self,
        t_ps: u64,
        level: bool,
        seen: bool,
        bit: u64,
        pins: CanPins,
        dut_rx: bool,
        view: Option<RefView>,
        recording: bool,
    ) {
        for e in self.decoder.push(level) {
            match e {
                DecodeEvent::FieldStart { field: Field::Sof, .. } => {
                    self.frame += 1;
                    self.sof_bit = bit - 1;
                }
                DecodeEvent::Frame(d) => self.bus_log.frame(t_ps, d.frame),
                _ => {}
            }
        }
        for e in self.seen_decoder.push(seen) {
            if let DecodeEvent::FieldStart { field, .. } = e {
                self.field = Some(field);
            }
        }
        if recording {
            let dut_tx = pins.tx;
            let (model_tx, mfield) = match &view {
                Some(v) => (v.pins.tx, v.field),
                None => (dut_tx, None),
            };
            self.record.push_bit(
                BusBit {
                    bit,
                    bus: level,
                    dut_tx,
                    model_tx,
                    dut_rx,
                    field: mfield.or(self.field),
                    frame: self.frame_no(),
                },
                self.keep_bits,
            );
        }
    }

    /// The reference's engine events of this clock into the record and the
    /// bus log (out of line: rare).
    #[inline(never)]
    pub fn reference_events(&mut self, t_ps: u64, bit: u64, r: &mut AnyRef) {
        r.drain_events(&mut self.events);
        if !self.events.is_empty() {
            let counters = r.counters();
            for k in self.events.drain(..) {
                if matches!(
                    k,
                    diagnose::EventKind::TxComplete | diagnose::EventKind::BusError { .. }
                ) && self.last_tr.is_some()
                {
                    self.attempts += 1;
                    let (tec, _) = counters.unwrap_or((0, 0));
                    self.record.tec_trace.push(diagnose::TecStep {
                        node: Side::Model,
                        attempt: self.attempts,
                        bit,
                        tec,
                        bus_off: tec > 255,
                    });
                }
                self.bus_log.event(t_ps, &k, counters);
                let mut e = EngineEvent::new(bit, Side::Model, k);
                if let Some((tec, rec)) = counters {
                    e.tec = Some(tec);
                    e.rec = Some(rec);
                }
                self.record.events.push(e);
            }
            // SR.ES (error warning) for the bus log's state frames: the
            // reference's journal has no warning event of its own.
            let es = r.peek(SR_ADDR) & 0x40 != 0;
            self.bus_log.event(t_ps, &diagnose::EventKind::ErrorWarning(es), counters);
        }
    }

    /// Draws one instant into our VCD (`sample` and `field` are filled in
    /// here: the bit clock's and the decoder's).
    pub fn dump_wave(&mut self, t_ps: u64, mut s: WaveSample) {
        s.sample = self.sample_now && s.can_clk;
        s.field = self.field;
        if let Some(w) = &mut self.wave {
            let _ = w.dump(t_ps, &s);
        }
    }

    /// Flushes our VCD.
    pub fn flush(&mut self) -> std::io::Result<()> {
        match &mut self.wave {
            Some(w) => w.flush(),
            None => Ok(()),
        }
    }

    /// The bus log so far.
    pub fn bus_log(&self) -> &[crate::candump::LogEntry] {
        self.bus_log.entries()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use can_proto::CanFrame;

    /// Bits of a standard data frame as they appear on the wire (stuffed),
    /// with the ACK slot dominant (a receiver acknowledged), then 11 recessive bits.
    fn wire_bits(id: u16, data: &[u8]) -> Vec<bool> {
        let f = CanFrame::with_dlc(CanFrame::std_id(id).unwrap(), false, data.len() as u8, data).expect("valid frame");
        let mut bits: Vec<bool> = f.wire_bits().iter().by_vals().collect();
        let slot = bits.len() - 9;
        bits[slot] = false;
        bits.extend(std::iter::repeat_n(true, 11));
        bits
    }

    fn observer(keep: usize) -> Observer {
        Observer::new(0x41, 0x25, RunRecord::new("t", "d"), None, keep)
    }

    #[test]
    fn fields_follow_the_bus_the_nodes_see_and_frames_the_wire() {
        // ID 0x000: SOF and ID.10-7 are five dominant bits, wire bit 5 the
        // recessive stuff bit. The nodes see it dominant (a bus fault): a
        // stuff error, everyone's error flag from bit 6; the wire alone has
        // the stuff bit and takes the flags for identifier bits.
        let mut wire = vec![true; 11];
        wire.extend([false, false, false, false, false, true]);
        wire.extend([false; 6]);
        wire.extend([true; 8]);
        let mut seen = wire.clone();
        seen[11 + 5] = false;
        let (mut with_fault, mut wire_only) = (observer(1000), observer(1000));
        let pins = CanPins::default();
        for i in 0..11 + 7 {
            with_fault.sample_point(0, wire[i], seen[i], i as u64 + 1, pins, seen[i], None, true);
            wire_only.sample_point(0, wire[i], wire[i], i as u64 + 1, pins, wire[i], None, true);
        }
        assert!(matches!(with_fault.field(), Some(Field::ActiveErrorFlag | Field::PassiveErrorFlag)), "{:?}", with_fault.field());
        assert_eq!(wire_only.field(), Some(Field::BaseId), "the wire alone is still in the identifier");
        assert_eq!(with_fault.frame(), 1, "frames are counted on the wire");
    }

    #[test]
    fn sample_points_count_frames_fields_and_record_bits() {
        let mut o = observer(1000);
        let pins = CanPins { tx: true, irq_n: true, bus_on: true, clkout: false };
        // Two frames back to back, after 11 bits of bus idle.
        let mut bits = vec![true; 11];
        bits.extend(wire_bits(0x123, &[1, 2]));
        bits.extend(wire_bits(0x7FF, &[]));
        for (i, &b) in bits.iter().enumerate() {
            o.sample_point(i as u64, b, b, i as u64 + 1, pins, b, None, true);
        }
        assert_eq!(o.frame(), 2, "two SOFs seen");
        assert_eq!(o.frame_no(), Some(2));
        assert_eq!(o.bus_log().len(), 2, "two frames completed on the bus");
        assert_eq!(o.record.bus_bits.len(), bits.len(), "every sample point recorded");
        assert_eq!(o.record.bus_bits.last().unwrap().frame, Some(2));
        // Not recording (the comparison stopped): the decoder still runs.
        let n = o.record.bus_bits.len();
        o.sample_point(0, true, true, 999, pins, true, None, false);
        assert_eq!(o.record.bus_bits.len(), n);
    }

    #[test]
    fn the_stamp_prefers_the_reference_field_and_counts_frames_from_one() {
        let mut o = observer(10);
        assert_eq!(o.stamp(5, 7, None).frame, None, "no frame before the first SOF");
        // Bus idle (11 recessive bits), then a start of frame at bit 12.
        for b in 1..=11 {
            o.sample_point(0, true, true, b, CanPins::default(), true, None, true);
        }
        o.sample_point(0, false, false, 12, CanPins::default(), false, None, true);
        let s = o.stamp(5, 7, Some(Field::AckSlot));
        assert_eq!((s.t_ps, s.bit, s.field, s.frame), (5, 7, Some(Field::AckSlot), Some(1)));
        assert_eq!(o.stamp(5, 7, None).field, Some(Field::Sof));
        // The rx faults' context counts frames from 0.
        let ctx = o.bus_context(42);
        assert_eq!((ctx.clock, ctx.frame), (42, Some(0)));
    }

    #[test]
    fn a_btr_write_retimes_the_bit_clock_and_the_record() {
        let mut o = observer(10);
        let before = o.clocks_per_bit();
        o.set_btr(6, 0x43);
        assert_eq!(o.record.timing.btr0, 0x43);
        assert_ne!(o.clocks_per_bit(), before, "a slower prescaler, a longer bit");
        assert_eq!(o.clocks_per_bit(), BusTiming::from_btr(0x43, 0x25).clocks_per_bit());
    }
}
