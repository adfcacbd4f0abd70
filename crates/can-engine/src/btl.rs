//! Bit timing logic (CAN 2.0B §9, SJA1000 BTR0/BTR1): the prescaler makes
//! time quanta of 2 * (BRP + 1) CAN clocks; a bit is the sync segment
//! (1 tq), TSEG1 (TSEG1 + 1 tq, propagation + phase segment 1) and TSEG2
//! (TSEG2 + 1 tq, phase segment 2); the bus is sampled at the end of TSEG1.
//!
//! Model: the bus is looked at once per time quantum, at the last CAN clock
//! of the quantum. An edge is a recessive level at the previous look and a
//! dominant one now (only recessive-to-dominant edges synchronise); it is
//! placed in the quantum that just ended. Synchronisation rules (§9.2.4):
//! 1. at most one synchronisation between two sample points (an edge in the
//!    sync segment is one, with phase error 0);
//! 2. an edge counts only if the level sampled at the previous sample point
//!    was recessive (it differs from the level after the edge);
//! 3. hard synchronisation on an edge while the bus is idle (the bit stream
//!    processor says when a dominant bit would be a start of frame);
//! 4. all other edges resynchronise: phase segment 1 is lengthened or phase
//!    segment 2 shortened by the phase error, at most SJW + 1 tq; a node
//!    sending a dominant bit does not resynchronise on a late edge (positive
//!    phase error), as its own edge would otherwise move it.
//!
//! Triple sampling (BTR1.SAM): the datasheet says the bus is then "sampled
//! three times" and recommends it for low/medium-speed buses to filter
//! spikes; it does not give the spacing. We take the majority of the levels
//! at the ends of the last three quanta of TSEG1 (1 tq apart, the last one at
//! the sample point), so TSEG1 must be at least 3 tq (the validator in
//! `can_proto::timing` flags shorter ones).

use can_proto::timing::BusTiming;

/// What a time-quantum boundary produced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Tq {
    /// Nothing for the bit stream processor.
    Quiet,
    /// The sample point: the (majority) level of the bit.
    Sample(bool),
    /// A new bit begins: drive the level the processor chose for it.
    BitStart,
}

/// Prescaler, segment counters and synchronisation state.
#[derive(Clone, Debug)]
pub(crate) struct Btl {
    /// CAN clocks per tq.
    cpt: u32,
    /// Clock within the current tq (0..cpt).
    clk: u32,
    /// Nominal index of the sample tq (the last tq of TSEG1).
    sp0: u8,
    /// Nominal index of the last tq of the bit.
    end0: u8,
    sjw: u8,
    sam: bool,
    /// Index of the tq that ends at the next look (0 = sync segment).
    pos: u8,
    /// Sample tq index for this bit (after any lengthening).
    sp: u8,
    /// Last tq index for this bit (after any lengthening/shortening).
    end: u8,
    /// Level at the previous look.
    prev_rx: bool,
    /// Levels at the last three looks, newest in bit 0.
    hist: u8,
    /// Level sampled at the last sample point.
    last_sample: bool,
    /// A synchronisation happened since the last sample point (rule 1).
    synced: bool,
    /// The state before the last quantum's end and what it was given, for
    /// [`Btl::retime`] to redo it (see [`Btl::retime`]'s `lag`).
    before_tq: Option<BeforeTq>,
    /// CAN clocks after a quantum's end in which [`Btl::retime`] may redo
    /// it (the DUT's declared segment lag; 0: never, and nothing is kept).
    redo_lag: u32,
}

/// The lag the unit tests use: the opencores core's (its profile's
/// `segment-lag`): it registers its prescaler's wrap twice and moves its
/// segments on the second, two clocks after the quantum boundary this
/// model takes, so a BTR write landing in those two clocks meets the old
/// segment counter with the new lengths.
#[cfg(test)]
const RETIME_LAG: u32 = 2;

/// What [`Btl::tq`] started from, and its arguments.
#[derive(Clone, Copy, Debug)]
struct BeforeTq {
    pos: u8,
    sp: u8,
    end: u8,
    prev_rx: bool,
    hist: u8,
    last_sample: bool,
    synced: bool,
    rx: bool,
    hard_sync: bool,
    sending_dominant: bool,
}

impl Btl {
    pub(crate) fn new(t: BusTiming) -> Self {
        let mut b = Btl {
            cpt: 2,
            clk: 0,
            sp0: 0,
            end0: 0,
            sjw: 1,
            sam: false,
            pos: 0,
            sp: 0,
            end: 0,
            prev_rx: true,
            hist: 7,
            last_sample: true,
            synced: false,
            before_tq: None,
            redo_lag: 0,
        };
        b.set_timing(t);
        b
    }

    pub(crate) fn set_timing(&mut self, t: BusTiming) {
        self.cpt = t.clocks_per_tq();
        self.sp0 = t.tseg1_tq() as u8;
        self.end0 = self.sp0 + t.tseg2_tq() as u8;
        self.sjw = t.sjw_tq() as u8;
        self.sam = t.sam;
        self.restart();
    }

    /// New lengths without restarting the count (a bit timing that runs
    /// from the hardware reset): the prescaler keeps its clock (a quantum
    /// already past the new length ends at the next clock), the bit keeps
    /// its quantum (a bit already past its new end ends at the next one).
    ///
    /// `redo_last`: the change may redo the quantum that ended less than
    /// [`Btl::set_redo_lag`] clocks ago, with the new lengths (only where
    /// nothing but the bit timing saw that quantum: in reset mode).
    pub(crate) fn retime(&mut self, t: BusTiming, redo_last: bool) {
        let redo = if redo_last && self.clk < self.redo_lag { self.before_tq } else { None };
        if let Some(b) = redo {
            self.pos = b.pos;
            self.sp = b.sp;
            self.end = b.end;
            self.prev_rx = b.prev_rx;
            self.hist = b.hist;
            self.last_sample = b.last_sample;
            self.synced = b.synced;
        }
        self.apply_lengths(t);
        if let Some(b) = redo {
            let _ = self.tq(b.rx, b.hard_sync, b.sending_dominant);
        }
    }

    /// The DUT's declared segment lag (profile `segment-lag`), for
    /// [`Btl::retime`]'s redo.
    pub(crate) fn set_redo_lag(&mut self, lag: u32) {
        self.redo_lag = lag;
    }

    /// [`Btl::retime`]'s new lengths, from the current segment.
    fn apply_lengths(&mut self, t: BusTiming) {
        self.cpt = t.clocks_per_tq();
        self.sp0 = t.tseg1_tq() as u8;
        self.end0 = self.sp0 + t.tseg2_tq() as u8;
        self.sjw = t.sjw_tq() as u8;
        self.sam = t.sam;
        // The bit keeps its segment and the quanta done in it: a bit in
        // phase segment 2 stays there (it does not go back into TSEG1 when
        // TSEG1 grows), with the new TSEG2 length.
        if self.pos > self.sp {
            let done_in_tseg2 = self.pos - self.sp - 1;
            self.pos = self.sp0 + 1 + done_in_tseg2;
        }
        self.sp = self.sp0;
        self.end = self.end0;
        self.pos = self.pos.min(self.end);
        self.clk = self.clk.min(self.cpt - 1);
    }

    /// The first quantum after a hardware reset is the first of TSEG1, not
    /// a sync segment (a bit timing that runs from the hardware reset and
    /// comes out of it in TSEG1, as the opencores core does).
    pub(crate) fn start_in_tseg1(&mut self) {
        self.restart();
        self.pos = 1;
    }

    /// Starts a fresh bit on the next clock (reset, wake-up).
    pub(crate) fn restart(&mut self) {
        self.clk = 0;
        self.pos = 0;
        self.sp = self.sp0;
        self.end = self.end0;
        self.synced = false;
    }

    /// Starts from scratch as after reset mode: prescaler at zero, a fresh
    /// bit on the next clock, the bus taken as recessive since the last
    /// look and at the last sample point (an edge at the first look counts).
    pub(crate) fn restart_idle(&mut self) {
        self.restart();
        self.prev_rx = true;
        self.hist = 7;
        self.last_sample = true;
    }

    /// CAN clocks until the next time-quantum boundary (1 = the next clock
    /// is one); lets a kernel skip clocks in which nothing can happen.
    pub(crate) fn clocks_to_next_tq(&self) -> u32 {
        self.cpt - self.clk
    }

    /// In phase segment 2, the sample point at most the declared segment
    /// lag ago (and a lag is declared): a core whose segments act
    /// that late samples this bit at that clock, with what its registers
    /// held before it, so a request written then is still in time.
    pub(crate) fn within_lag_of_sample_point(&self) -> bool {
        self.redo_lag > 0 && self.pos > self.sp && u32::from(self.pos - self.sp - 1) * self.cpt + self.clk <= self.redo_lag
    }

    /// CAN clocks per time quantum.
    pub(crate) fn clocks_per_tq(&self) -> u32 {
        self.cpt
    }

    /// How many of the next quantum ends, with the bus staying at `rx`,
    /// return [`Tq::Quiet`] and do nothing but move the quantum count: no
    /// edge at the next look (after it the level is `rx` at every look), so
    /// no synchronisation, and neither the sample point nor the bit's end
    /// among them. With `through_bit_start` (the caller does nothing at a
    /// [`Tq::BitStart`]), the bit's end counts too, and the next bit's
    /// quanta up to its sample point.
    pub(crate) fn quiet_tqs(&self, rx: bool, through_bit_start: bool) -> u32 {
        if self.prev_rx && !rx {
            return 0;
        }
        if self.pos < self.sp {
            return u32::from(self.sp - self.pos);
        }
        if self.pos == self.sp {
            return 0;
        }
        let before_end = u32::from(self.end.saturating_sub(self.pos));
        if through_bit_start {
            // The bit's end, then a fresh bit's quanta before its sample point.
            before_end + 1 + u32::from(self.sp0)
        } else {
            before_end
        }
    }

    /// `n` CAN clocks that end no quantum (`n` below
    /// [`Btl::clocks_to_next_tq`]): `clock` `n` times.
    #[inline]
    pub(crate) fn count(&mut self, n: u32) {
        debug_assert!(n < self.clocks_to_next_tq());
        self.clk += n;
    }

    /// One CAN clock; `None` between quantum boundaries.
    #[inline]
    pub(crate) fn clock(&mut self) -> bool {
        self.clk += 1;
        if self.clk < self.cpt {
            return false;
        }
        self.clk = 0;
        true
    }

    /// The end of a time quantum with the bus at `rx`. `hard_sync`: a
    /// dominant bit would be a start of frame now; `sending_dominant`: this
    /// node drives dominant in the current bit.
    pub(crate) fn tq(&mut self, rx: bool, hard_sync: bool, sending_dominant: bool) -> Tq {
        // Kept only when a redo can use it (a declared segment lag).
        self.before_tq = (self.redo_lag > 0).then(|| BeforeTq {
            pos: self.pos,
            sp: self.sp,
            end: self.end,
            prev_rx: self.prev_rx,
            hist: self.hist,
            last_sample: self.last_sample,
            synced: self.synced,
            rx,
            hard_sync,
            sending_dominant,
        });
        let edge = self.prev_rx && !rx;
        self.prev_rx = rx;
        self.hist = ((self.hist << 1) | rx as u8) & 7;
        if edge && self.last_sample && !self.synced {
            if self.pos == 0 {
                // Phase error 0 (§9.2.4): nothing moves, but it is this
                // bit's synchronisation (rule 1), so a glitch edge later in
                // the bit, before the sample point, is not used.
                self.synced = true;
            } else if hard_sync {
                // Rule 3: this quantum becomes the sync segment of a new bit.
                let sampled = self.pos > self.sp;
                self.new_bit_after_sync();
                return if sampled { Tq::BitStart } else { Tq::Quiet };
            } else if self.pos <= self.sp {
                // Late edge: lengthen phase segment 1 by min(e, SJW).
                if !sending_dominant {
                    let e = self.pos.min(self.sjw);
                    self.sp += e;
                    self.end += e;
                    self.synced = true;
                }
            } else {
                // Early edge: shorten phase segment 2 by min(|e|, SJW).
                let e = self.end + 1 - self.pos;
                if e <= self.sjw {
                    self.new_bit_after_sync();
                    return Tq::BitStart;
                }
                self.end -= self.sjw;
                self.synced = true;
            }
        }
        if self.pos == self.sp {
            let v = if self.sam {
                (self.hist & 1) + ((self.hist >> 1) & 1) + (self.hist >> 2) >= 2
            } else {
                rx
            };
            self.last_sample = v;
            self.synced = false;
            self.pos += 1;
            Tq::Sample(v)
        } else if self.pos >= self.end {
            self.pos = 0;
            self.sp = self.sp0;
            self.end = self.end0;
            Tq::BitStart
        } else {
            self.pos += 1;
            Tq::Quiet
        }
    }

    /// The quantum just ended was a sync segment.
    fn new_bit_after_sync(&mut self) {
        self.pos = 1;
        self.sp = self.sp0;
        self.end = self.end0;
        self.synced = true;
    }
}

#[cfg(test)]
mod retime_tests {
    use super::*;

    /// Quanta from now to the next bit start, and how many sample points on the way.
    fn to_bit_start(b: &mut Btl) -> (u32, u32) {
        let (mut n, mut samples) = (0, 0);
        loop {
            n += 1;
            match b.tq(true, false, false) {
                Tq::BitStart => return (n, samples),
                Tq::Sample(_) => samples += 1,
                Tq::Quiet => {}
            }
        }
    }

    /// A BTR1 write that lands in phase segment 2 (after the sample point)
    /// keeps the bit in phase segment 2, which then lasts the new TSEG2 from
    /// its start: no second sample point in that bit (a segment counter, as
    /// the opencores core has). Before: the bit went back to TSEG1, sampled
    /// a second time and ended new TSEG1 + TSEG2 quanta later.
    #[test]
    fn retime_in_phase_segment_2_stays_in_phase_segment_2() {
        // Hardware-reset BTRs: 1 tq TSEG1, 1 tq TSEG2 (3 tq bits).
        let mut b = Btl::new(BusTiming::from_btr(0x00, 0x00));
        to_bit_start(&mut b);
        assert_eq!(b.tq(true, false, false), Tq::Quiet, "sync segment");
        assert_eq!(b.tq(true, false, false), Tq::Sample(true), "TSEG1 (1 tq) ends at the sample point");
        // Now in phase segment 2 (its first quantum is next); TSEG2 becomes 3 tq.
        b.retime(BusTiming::from_btr(0x00, 0x25), false);
        assert_eq!(to_bit_start(&mut b), (3, 0), "phase segment 2 of 3 tq, no sample");
        // The next bit has the new lengths: sample after 6 tq, 10 tq in all.
        assert_eq!(to_bit_start(&mut b), (10, 1));
    }

    /// A BTR1 write that lands within [`RETIME_LAG`] clocks after the
    /// quantum that was the (old, 1 tq) TSEG1's sample point: the core's
    /// segment logic has not acted on that quantum yet and meets it with the
    /// new TSEG1, so the bit stays in TSEG1 (sample 4 quanta later); a write
    /// 2 clocks later finds the bit already in phase segment 2.
    #[test]
    fn retime_just_after_a_quantum_redoes_it_with_the_new_lengths() {
        let at_sample = || {
            let mut b = Btl::new(BusTiming::from_btr(0x41, 0x00));
            b.set_redo_lag(RETIME_LAG);
            to_bit_start(&mut b);
            assert_eq!(b.tq(true, false, false), Tq::Quiet, "sync segment");
            assert_eq!(b.tq(true, false, false), Tq::Sample(true), "old TSEG1 ends");
            b
        };
        for clocks in 0..RETIME_LAG {
            let mut b = at_sample();
            for _ in 0..clocks {
                assert!(!b.clock());
            }
            b.retime(BusTiming::from_btr(0x41, 0x25), true);
            assert_eq!(to_bit_start(&mut b), (8, 1), "{clocks} clock(s) after: TSEG1 to its new end, then TSEG2");
        }
        let mut b = at_sample();
        for _ in 0..RETIME_LAG {
            assert!(!b.clock());
        }
        b.retime(BusTiming::from_btr(0x41, 0x25), true);
        assert_eq!(to_bit_start(&mut b), (3, 0), "past the lag: phase segment 2 of 3 tq");
        // Outside reset mode (redo_last false) nothing is redone.
        let mut b = at_sample();
        b.retime(BusTiming::from_btr(0x41, 0x25), false);
        assert_eq!(to_bit_start(&mut b), (3, 0));
    }

    /// A write in TSEG1 before its sample point takes the new TSEG1.
    #[test]
    fn retime_in_tseg1_takes_the_new_lengths() {
        let mut b = Btl::new(BusTiming::from_btr(0x00, 0x00));
        to_bit_start(&mut b);
        b.retime(BusTiming::from_btr(0x00, 0x25), false);
        assert_eq!(to_bit_start(&mut b), (10, 1), "sync + 6 tq TSEG1 + 3 tq TSEG2");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The next quantum boundary that is a sample point or a bit start
    /// (bus recessive, no synchronisation), and the quanta it took.
    fn next_event(b: &mut Btl) -> (Tq, u32) {
        for n in 1..64 {
            while !b.clock() {}
            match b.tq(true, false, false) {
                Tq::Quiet => {}
                e => return (e, n),
            }
        }
        panic!("no sample point or bit start in 64 quanta");
    }

    /// An edge in the sync segment (phase error 0) is the bit's one
    /// synchronisation (CAN 2.0B §9.2.5 rule 1): a glitch's second
    /// recessive-to-dominant edge before the sample point does not lengthen
    /// phase segment 1, so a dominant bit is sampled where it is, not SJW
    /// later in the next bit.
    #[test]
    fn an_edge_in_the_sync_segment_blocks_a_later_edge_in_the_bit() {
        // SJW 4 tq; sync + 11 tq TSEG1 + 2 tq TSEG2.
        let mut b = Btl::new(BusTiming::from_btr(0xC0, 0x1A));
        // A recessive bit, sampled recessive, to its end.
        let mut n = 0;
        while b.tq(true, false, false) != Tq::BitStart {
            n += 1;
            assert!(n < 64);
        }
        // Bus dominant from the sync segment on, recessive in quanta 3 and 4.
        let bus = |q: u32| (3..=4).contains(&q);
        let events: Vec<_> = (0..14).map(|q| (q, b.tq(bus(q), false, false))).filter(|e| e.1 != Tq::Quiet).collect();
        assert_eq!(
            events,
            vec![(11, Tq::Sample(false)), (13, Tq::BitStart)],
            "sampled once, dominant, at the nominal sample point; the bit keeps its 14 tq"
        );
    }

    #[test]
    fn out_of_a_hardware_reset_the_first_quantum_is_tseg1s() {
        // BTR0 = BTR1 = 0: 1 tq sync, 1 tq TSEG1, 1 tq TSEG2.
        let mut b = Btl::new(BusTiming::from_btr(0, 0));
        b.start_in_tseg1();
        assert_eq!(next_event(&mut b), (Tq::Sample(true), 1), "sampled at the end of the first quantum");
        assert_eq!(next_event(&mut b), (Tq::BitStart, 1));
    }

    #[test]
    fn a_btr_write_in_phase_segment_2_keeps_the_bit_there() {
        let mut b = Btl::new(BusTiming::from_btr(0, 0));
        b.start_in_tseg1();
        assert_eq!(next_event(&mut b).0, Tq::Sample(true));
        // Now in TSEG2; TSEG1 grows to 6 tq and TSEG2 to 3 tq: the bit ends
        // after the new TSEG2, without a second sample point.
        b.retime(BusTiming::from_btr(0x41, 0x25), false);
        assert_eq!(next_event(&mut b), (Tq::BitStart, 3));
        assert_eq!(next_event(&mut b), (Tq::Sample(true), 7), "then whole bits: sync + 6 tq");
    }
}
