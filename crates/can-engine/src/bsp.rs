//! Bit stream processor: the CAN 2.0B frame state machine, one call per bit
//! at the sample point ([`Bsp::bit`]). Transmitters and receivers run the
//! same destuffing/decoding path on the sampled level; a transmitter also
//! compares it with the level it sent (bit error, arbitration).
//!
//! Counter changes are asked of [`crate::fault`]; this file only says which
//! rule applies.

use crate::ecc::{self, seg};
use crate::fault::Fault;
use crate::{ErrorKind, Event, FaultState, Options};
use can_proto::{CanFrame, DOMINANT, ExtendedId, Field, FrameTrait, Id, RECESSIVE, StandardId};

/// Where the processor is. Frame fields inside the stuffed region are
/// tracked by `Bsp::fld`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Phase {
    /// Reset mode (or bus-off before recovery may start): drives recessive.
    Off,
    /// Sleep mode: a dominant bit wakes the node.
    Sleep,
    /// Bus integration: waiting for 11 consecutive recessive bits.
    Integrating,
    /// Bus-off; counts 128 x 11 recessive bits once reset mode is left.
    BusOff,
    /// Bus idle.
    Idle,
    /// SOF to the end of the CRC sequence (stuffed).
    Stuffed,
    CrcDelim,
    AckSlot,
    AckDelim,
    Eof,
    Intermission,
    Suspend,
    ActiveFlag,
    PassiveFlag,
    /// After an error flag, sending recessive until the bus is recessive.
    ErrorTolerate,
    ErrorDelim,
    OverloadFlag,
    OverloadTolerate,
    OverloadDelim,
}

/// A transmission request with its stuffed SOF..CRC bits precomputed.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TxRequest {
    pub(crate) frame: CanFrame,
    pub(crate) single_shot: bool,
    pub(crate) self_rx: bool,
    bits: [u64; 3],
    len: u8,
}

impl TxRequest {
    pub(crate) fn new(frame: CanFrame, single_shot: bool, self_rx: bool) -> Self {
        let (bits, len) = stuff_packed(frame);
        TxRequest {
            frame,
            single_shot,
            self_rx,
            bits,
            len,
        }
    }

    #[cfg(test)]
    pub(crate) fn stuffed(&self) -> Vec<bool> {
        (0..self.len)
            .map(|i| (self.bits[(i >> 6) as usize] >> (i & 63)) & 1 != 0)
            .collect()
    }
}

/// ORs the low `n` bits of `v` into `out` from bit `at` on (bit `i` of
/// the stream is `out[i / 64] >> (i % 64)`).
#[inline]
fn put_bits(out: &mut [u64; 3], mut at: usize, mut v: u128, mut n: usize) {
    if n < 128 {
        v &= (1u128 << n) - 1;
    }
    while n > 0 {
        let s = at & 63;
        let take = (64 - s).min(n);
        out[at >> 6] |= (v as u64) << s;
        v = if take < 128 { v >> take } else { 0 };
        at += take;
        n -= take;
    }
}

/// The stuffed SOF..CRC bits of `frame` (SOF at bit 0) and their number.
/// Word-wise: each step finds the first run of five equal bits with a
/// mask (a stuff bit starts the next run), so the cost is one step per
/// stuff bit rather than one per bit.
fn stuff_packed(frame: CanFrame) -> ([u64; 3], u8) {
    let (msb_first, ulen, _) = frame.unstuffed_packed();
    let ulen = ulen as usize;
    // SOF at bit 0.
    let src = msb_first.reverse_bits() >> (128 - ulen);
    let mut out = [0u64; 3];
    let mut olen = 0usize;
    let mut pos = 0usize;
    // The stuff bit just sent (already in `out`): first bit of the next run.
    let mut prev: Option<bool> = None;
    loop {
        let rem = ulen - pos;
        let chunk = if pos < 128 { src >> pos } else { 0 };
        let (w, wl, off) = match prev {
            Some(p) => ((chunk << 1) | p as u128, rem + 1, 1),
            None => (chunk, rem, 0),
        };
        // same bit i: w[i] == w[i + 1]; five bit i: w[i..=i + 4] equal.
        let same = !(w ^ (w >> 1)) & ((1u128 << (wl - 1)) - 1);
        let five = same & (same >> 1) & (same >> 2) & (same >> 3);
        if five == 0 {
            put_bits(&mut out, olen, w >> off, wl - off);
            olen += wl - off;
            break;
        }
        let j = five.trailing_zeros() as usize + 4; // the fifth equal bit
        put_bits(&mut out, olen, w >> off, j + 1 - off);
        olen += j + 1 - off;
        let stuff = (w >> j) & 1 == 0;
        put_bits(&mut out, olen, stuff as u128, 1);
        olen += 1;
        pos += j + 1 - off;
        prev = Some(stuff);
    }
    (out, olen as u8)
}

/// Frame state machine and the state it needs.
#[derive(Clone, Debug)]
pub(crate) struct Bsp {
    pub(crate) phase: Phase,
    /// Level driven in the current bit; set for the next bit by [`Bsp::bit`].
    pub(crate) tx: bool,
    /// Bits done in a fixed-length phase, or the recessive run length.
    cnt: u8,
    /// Phase and count when sleep was entered, for [`Bsp::cancel_sleep`].
    slept_from: (Phase, u8),
    // Decoder of the stuffed region.
    fld: Field,
    idx: u8,
    flen: u8,
    last: bool,
    run: u8,
    crc: u16,
    crc_calc: u16,
    acc: u32,
    id_base: u32,
    srr_rtr: bool,
    ide: bool,
    rtr: bool,
    id_ext: u32,
    dlc: u8,
    data: [u8; 8],
    crc_ok: bool,
    // Transmitter.
    /// A transmitter from SOF until the bus is idle or arbitration is lost.
    pub(crate) role_tx: bool,
    tx_ext: bool,
    tx_idx: u8,
    /// Stuffed bits of the frame under way (a copy: the request may change).
    txb: [u64; 3],
    tx_len: u8,
    pub(crate) pending: Option<TxRequest>,
    abort_req: bool,
    // Error signalling.
    flag_lvl: bool,
    flag_run: u8,
    dom_cnt: u32,
    /// Rule 3 exception 1 may apply: ACK error while error passive; TEC is
    /// raised only if a dominant bit shows during the passive flag.
    ack_exc: bool,
    recovery: u8,
    /// Recessive bus-idle bits since the last bus-on (255: not idle since
    /// a bus-on), for [`Bsp::wait_bus_free_after_bus_on`].
    since_bus_on: u8,
    /// Bits past the 11th recessive one for which integration holds a
    /// pending transmission, waiting for another node's start of frame
    /// (a resync; 0: no hold).
    sof_hold: u8,
    /// A TXERR write of 255 in reset mode: the bus-off it forces happens
    /// when reset mode is left (datasheet TXERR).
    bus_off_armed: bool,
    pub(crate) reset_mode: bool,
    pub(crate) fc: Fault,
    pub(crate) ev: Vec<Event>,
    pub(crate) opt: Options,
}

impl Bsp {
    pub(crate) fn new(opt: Options) -> Self {
        let mut fc = Fault::new(opt.ewl);
        fc.set_ewl(opt.ewl, opt.listen_only);
        Bsp {
            phase: Phase::Integrating,
            tx: RECESSIVE,
            cnt: 0,
            slept_from: (Phase::Idle, 0),
            fld: Field::Sof,
            idx: 0,
            flen: 1,
            last: RECESSIVE,
            run: 0,
            crc: 0,
            crc_calc: 0,
            acc: 0,
            id_base: 0,
            srr_rtr: false,
            ide: false,
            rtr: false,
            id_ext: 0,
            dlc: 0,
            data: [0; 8],
            crc_ok: false,
            role_tx: false,
            tx_ext: false,
            tx_idx: 0,
            txb: [0; 3],
            tx_len: 0,
            pending: None,
            abort_req: false,
            flag_lvl: RECESSIVE,
            flag_run: 0,
            dom_cnt: 0,
            ack_exc: false,
            recovery: 0,
            since_bus_on: u8::MAX,
            sof_hold: 0,
            bus_off_armed: false,
            reset_mode: false,
            fc,
            ev: Vec::with_capacity(8),
            opt,
        }
    }

    /// One bit, sampled at `rx`; sets [`Bsp::tx`] for the next bit.
    /// The stuffed region (most bits of a busy bus) is tested first with a
    /// plain, well-predicted branch instead of the phase jump table.
    #[inline(always)]
    pub(crate) fn bit(&mut self, rx: bool) {
        if self.phase == Phase::Stuffed {
            self.stuffed_fast(rx)
        } else {
            self.bit_other(rx)
        }
    }

    /// [`Bsp::bit`] outside the stuffed region.
    #[inline(never)]
    fn bit_other(&mut self, rx: bool) {
        match self.phase {
            Phase::Stuffed => self.stuffed(rx),
            Phase::Idle => self.idle(rx),
            Phase::CrcDelim => {
                if !rx {
                    return self.error(ErrorKind::Form, false);
                }
                self.phase = Phase::AckSlot;
                // Receivers that got a matching CRC acknowledge (never in
                // listen-only mode; never the transmitter itself).
                self.tx = if !self.role_tx && self.crc_ok && !self.opt.listen_only {
                    DOMINANT
                } else {
                    RECESSIVE
                };
            }
            Phase::AckSlot => self.ack_slot(rx),
            Phase::AckDelim => {
                if !rx {
                    return self.error(ErrorKind::Form, false);
                }
                if !self.role_tx && !self.crc_ok {
                    // CRC error: flag after the ACK delimiter (CAN 2.0B §7.2).
                    return self.error(ErrorKind::Crc, false);
                }
                self.phase = Phase::Eof;
                self.cnt = 0;
            }
            Phase::Eof => self.eof(rx),
            Phase::Intermission => self.intermission(rx),
            Phase::Suspend => {
                self.cnt += 1;
                if !rx {
                    // Another node's SOF: become its receiver.
                    self.role_tx = false;
                    self.begin_frame();
                    return self.stuffed(rx);
                }
                if self.cnt == 8 {
                    self.enter_idle();
                }
            }
            Phase::ActiveFlag | Phase::OverloadFlag => self.dominant_flag(rx),
            Phase::PassiveFlag => self.passive_flag(rx),
            Phase::ErrorTolerate | Phase::OverloadTolerate => self.tolerate(rx),
            Phase::ErrorDelim | Phase::OverloadDelim => {
                self.cnt += 1;
                if !rx {
                    if self.cnt == 8 {
                        // Dominant at the last delimiter bit: overload frame,
                        // no counter change (CAN 2.0B §7.2).
                        return self.start_overload();
                    }
                    return self.error(ErrorKind::Form, false);
                }
                if self.cnt == 8 {
                    self.phase = Phase::Intermission;
                    self.cnt = 0;
                }
            }
            Phase::Integrating => {
                if rx {
                    self.cnt = self.cnt.saturating_add(1);
                    let held = self.sof_hold > 0 && self.pending.is_some() && self.cnt < 11 + self.sof_hold;
                    if self.cnt >= 11 && !held {
                        self.sof_hold = 0;
                        self.enter_idle();
                    }
                } else {
                    self.cnt = 0;
                    self.sof_hold = 0;
                }
            }
            Phase::BusOff => self.bus_off_recovery(rx),
            Phase::Sleep => {
                if !rx {
                    self.wake_by_bus();
                }
            }
            Phase::Off => {}
        }
    }

    // ---- frame --------------------------------------------------------

    fn begin_frame(&mut self) {
        self.phase = Phase::Stuffed;
        self.fld = Field::Sof;
        self.idx = 0;
        self.flen = 1;
        self.last = RECESSIVE;
        self.run = 0;
        self.crc = 0;
        self.acc = 0;
        self.crc_ok = false;
    }

    fn idle(&mut self, rx: bool) {
        if !rx {
            self.since_bus_on = u8::MAX;
            self.role_tx = false;
            self.begin_frame();
            return self.stuffed(rx);
        }
        if self.since_bus_on < u8::MAX {
            self.since_bus_on += 1;
        }
        self.try_start_tx();
    }

    /// Bus idle reached: start a pending transmission with the next bit.
    fn enter_idle(&mut self) {
        self.since_bus_on = u8::MAX;
        self.phase = Phase::Idle;
        self.role_tx = false;
        self.tx = RECESSIVE;
        self.try_start_tx();
    }

    /// Starts a request made in bus idle just after a sample point, as if
    /// it had been pending there (its start of frame is the next bit).
    pub(crate) fn start_idle_request(&mut self) {
        if self.phase == Phase::Idle && !self.role_tx {
            self.try_start_tx();
        }
    }

    fn try_start_tx(&mut self) {
        if let Some(req) = &self.pending {
            if !self.opt.listen_only && !self.reset_mode {
                self.tx_ext = req.frame.is_extended();
                self.txb = req.bits;
                self.tx_len = req.len;
                self.role_tx = true;
                self.tx_idx = 0;
                self.tx = DOMINANT; // SOF
                self.begin_frame();
            }
        }
    }

    /// Level of the next stuffed bit this transmitter sends.
    #[inline]
    fn next_tx_bit(&mut self) {
        if self.role_tx {
            self.tx_idx += 1;
            let i = self.tx_idx;
            self.tx = i >= self.tx_len || (self.txb[(i >> 6) as usize] >> (i & 63)) & 1 != 0;
        }
    }

    /// The fields whose recessive bits may lose arbitration. IDE belongs to
    /// it only in extended frames (in standard frames it follows RTR).
    #[inline]
    fn in_arbitration(&self) -> bool {
        match self.fld {
            Field::BaseId | Field::SrrRtr | Field::ExtId | Field::Rtr => true,
            Field::Ide => self.tx_ext,
            _ => false,
        }
    }

    /// [`Bsp::stuffed`] inlined for its common case: no stuff bit due, no
    /// transmitter mismatch, a bit inside a field that ends no field and
    /// completes no data byte (then `field_bit` only shifts it in). Every
    /// other bit goes to `stuffed`, so the result is the same.
    #[inline(always)]
    fn stuffed_fast(&mut self, rx: bool) {
        let next = self.idx + 1;
        let plain = (self.run != 5)
            & !(self.role_tx & (rx != self.tx))
            & (next < self.flen)
            & ((self.fld != Field::Data) | (next & 7 != 0));
        if !plain {
            return self.stuffed(rx);
        }
        self.run = if rx == self.last { self.run + 1 } else { 1 };
        self.last = rx;
        if self.fld != Field::Crc {
            self.crc_push(rx);
        }
        self.acc = (self.acc << 1) | rx as u32;
        self.idx = next;
        self.next_tx_bit();
    }

    #[inline(never)]
    fn stuffed(&mut self, rx: bool) {
        let sent = self.tx;
        if self.run == 5 {
            // A stuff bit is due.
            if self.role_tx {
                if rx != sent {
                    // Rule 3 exception 2: a recessive stuff bit before RTR
                    // monitored dominant is a stuff error, TEC unchanged.
                    if sent && self.in_arbitration() {
                        return self.error(ErrorKind::Stuff, true);
                    }
                    return self.error(ErrorKind::Bit, false);
                }
            } else if rx == self.last {
                return self.error(ErrorKind::Stuff, false);
            }
            self.last = rx;
            self.run = 1;
            if self.fld == Field::CrcDelim {
                // It was the stuff bit after the last CRC bit.
                self.phase = Phase::CrcDelim;
            }
            return self.next_tx_bit();
        }
        if self.role_tx && rx != sent {
            if sent && self.in_arbitration() {
                self.lose_arbitration();
            } else {
                return self.error(ErrorKind::Bit, false);
            }
        }
        // Random data makes these data-dependent branches unpredictable:
        // written as selects.
        self.run = if rx == self.last { self.run + 1 } else { 1 };
        self.last = rx;
        self.field_bit(rx);
        self.next_tx_bit();
    }

    #[inline]
    fn crc_push(&mut self, b: bool) {
        let fb = (self.crc >> 14) & 1;
        let xor = 0u16.wrapping_sub(fb ^ b as u16) & 0x4599;
        self.crc = ((self.crc << 1) & 0x7fff) ^ xor;
    }

    #[inline]
    fn set_fld(&mut self, f: Field, len: u8) {
        self.fld = f;
        self.flen = len;
        self.idx = 0;
        self.acc = 0;
    }

    /// A destuffed bit of the field `fld`.
    #[inline]
    fn field_bit(&mut self, b: bool) {
        if self.fld != Field::Crc {
            self.crc_push(b);
        }
        self.acc = (self.acc << 1) | b as u32;
        self.idx += 1;
        match self.fld {
            Field::Data => {
                if self.idx & 7 == 0 {
                    self.data[((self.idx >> 3) - 1) as usize] = self.acc as u8;
                }
                if self.idx == self.flen {
                    self.crc_calc = self.crc;
                    self.set_fld(Field::Crc, 15);
                }
            }
            _ if self.idx < self.flen => {}
            Field::Sof => self.set_fld(Field::BaseId, 11),
            Field::BaseId => {
                self.id_base = self.acc;
                self.set_fld(Field::SrrRtr, 1);
            }
            Field::SrrRtr => {
                self.srr_rtr = b;
                self.set_fld(Field::Ide, 1);
            }
            Field::Ide => {
                self.ide = b;
                if b {
                    self.set_fld(Field::ExtId, 18);
                } else {
                    self.rtr = self.srr_rtr;
                    self.set_fld(Field::R0, 1);
                }
            }
            Field::ExtId => {
                self.id_ext = self.acc;
                self.set_fld(Field::Rtr, 1);
            }
            Field::Rtr => {
                self.rtr = b;
                self.set_fld(Field::R1, 1);
            }
            Field::R1 => self.set_fld(Field::R0, 1),
            Field::R0 => self.set_fld(Field::Dlc, 4),
            Field::Dlc => {
                self.dlc = self.acc as u8;
                let n = if self.rtr { 0 } else { self.dlc.min(8) };
                if n > 0 {
                    self.set_fld(Field::Data, 8 * n);
                } else {
                    self.crc_calc = self.crc;
                    self.set_fld(Field::Crc, 15);
                }
            }
            Field::Crc => {
                self.crc_ok = (self.acc & 0x7fff) as u16 == self.crc_calc;
                if self.run == 5 {
                    self.fld = Field::CrcDelim; // a stuff bit still follows
                } else {
                    self.phase = Phase::CrcDelim;
                }
            }
            _ => {}
        }
    }

    fn lose_arbitration(&mut self) {
        self.role_tx = false;
        self.tx = RECESSIVE;
        let alc = ecc::alc(self.fld, self.idx);
        self.ev.push(Event::ArbitrationLost { alc });
        self.drop_if_single_shot();
    }

    /// Single shot (or an abort during the attempt): no retransmission.
    fn drop_if_single_shot(&mut self) {
        let single = self.pending.as_ref().is_some_and(|r| r.single_shot);
        if single || self.abort_req {
            self.pending = None;
            self.abort_req = false;
            self.ev.push(Event::TxAborted);
        }
    }

    fn received_frame(&self) -> CanFrame {
        let id: Id = if self.ide {
            Id::Extended(
                ExtendedId::new((self.id_base << 18) | self.id_ext).unwrap_or(ExtendedId::ZERO),
            )
        } else {
            Id::Standard(StandardId::new(self.id_base as u16).unwrap_or(StandardId::ZERO))
        };
        let n = if self.rtr {
            0
        } else {
            self.dlc.min(8) as usize
        };
        // Cannot fail: DLC <= 15 and n matches it.
        CanFrame::with_dlc(id, self.rtr, self.dlc, &self.data[..n]).expect("decoded frame is valid")
    }

    fn ack_slot(&mut self, rx: bool) {
        let sent = self.tx;
        self.tx = RECESSIVE;
        if self.role_tx {
            if rx && !self.opt.self_test {
                return self.error(ErrorKind::Ack, false);
            }
        } else if !sent {
            if rx {
                return self.error(ErrorKind::Bit, false);
            }
            // Rule 8: received without error up to the ACK slot, ACK sent.
            self.fc.rule8_receive_success(&mut self.ev);
        }
        self.phase = Phase::AckDelim;
    }

    fn eof(&mut self, rx: bool) {
        self.cnt += 1;
        if !rx {
            if !self.role_tx && self.cnt == 7 {
                // Last EOF bit is "don't care" for receivers: the frame is
                // valid; a dominant level there starts an overload frame.
                return self.start_overload();
            }
            return self.error(ErrorKind::Form, false);
        }
        if self.cnt == 6 && !self.role_tx {
            // Valid for receivers at the last-but-one EOF bit (CAN 2.0B §5).
            let frame = self.received_frame();
            self.ev.push(Event::Received { frame, own: false });
        }
        if self.cnt == 7 {
            if self.role_tx {
                self.transmit_success();
            }
            self.phase = Phase::Intermission;
            self.cnt = 0;
        }
    }

    fn transmit_success(&mut self) {
        if let Some(req) = self.pending.take() {
            if req.self_rx {
                self.ev.push(Event::Received {
                    frame: req.frame,
                    own: true,
                });
            }
        }
        self.abort_req = false;
        self.fc.rule7_transmit_success(&mut self.ev);
        self.ev.push(Event::TxComplete);
    }

    fn intermission(&mut self, rx: bool) {
        self.cnt += 1;
        if !rx {
            if self.cnt < 3 {
                // Dominant at the 1st or 2nd intermission bit: overload.
                return self.start_overload();
            }
            // 3rd bit: a start of frame. A node with a message waiting
            // takes it as its own SOF and goes on with the identifier.
            let suspended = self.role_tx && self.fc.state() == FaultState::ErrorPassive;
            self.role_tx = false;
            if self.pending.is_some() && !suspended && !self.opt.listen_only && !self.reset_mode {
                self.try_start_tx();
                self.tx = DOMINANT;
            } else {
                self.begin_frame();
            }
            return self.stuffed(rx);
        }
        if self.cnt == 3 {
            if self.role_tx && self.fc.state() == FaultState::ErrorPassive {
                // Error-passive transmitter: suspend transmission (8 bits).
                self.phase = Phase::Suspend;
                self.cnt = 0;
            } else {
                self.enter_idle();
            }
        }
    }

    // ---- errors and overload -----------------------------------------

    /// Current ECC segment code.
    fn segment(&self) -> u8 {
        match self.phase {
            Phase::Stuffed if self.fld == Field::CrcDelim => seg::CRC_SEQ,
            Phase::Stuffed => ecc::segment(self.fld, self.idx),
            Phase::ErrorTolerate | Phase::OverloadTolerate => seg::TOLERATE_DOMINANT,
            _ => ecc::segment(self.field(), 0),
        }
    }

    fn push_error(&mut self, kind: ErrorKind) {
        let ecc = ecc::ecc(kind, !self.role_tx, self.segment());
        let field = self.field();
        self.ev.push(Event::BusError { kind, ecc, field });
    }

    /// An error detected in a frame, delimiter or intermission; the error
    /// flag starts with the next bit. `exc2`: rule 3 exception 2 applies.
    fn error(&mut self, kind: ErrorKind, exc2: bool) {
        self.push_error(kind);
        // Rule 9: the flag is chosen by the state *before* this error's
        // increment ("an error condition letting a node become error
        // passive causes the node to send an active error flag").
        let active = self.fc.is_active();
        let bus_off = if self.role_tx {
            let off = if kind == ErrorKind::Ack && !active {
                self.ack_exc = true; // rule 3 exception 1, decided in the flag
                false
            } else if exc2 {
                false
            } else {
                self.fc.rule3_transmitter_flag(&mut self.ev)
            };
            self.drop_if_single_shot();
            off
        } else {
            self.fc.rule1_receiver_error(&mut self.ev)
        };
        if bus_off {
            return self.enter_bus_off();
        }
        self.start_error_flag(active);
    }

    fn start_error_flag(&mut self, active: bool) {
        self.cnt = 0;
        if active && !self.opt.listen_only {
            self.phase = Phase::ActiveFlag;
            self.tx = DOMINANT;
        } else {
            self.phase = Phase::PassiveFlag;
            self.tx = RECESSIVE;
            self.flag_run = 0;
        }
    }

    fn start_overload(&mut self) {
        self.phase = Phase::OverloadFlag;
        self.cnt = 0;
        self.tx = if self.opt.listen_only {
            RECESSIVE
        } else {
            DOMINANT
        };
    }

    /// Active error flag or overload flag: six dominant bits.
    fn dominant_flag(&mut self, rx: bool) {
        if rx && self.tx == DOMINANT {
            // Rules 4/5: bit error in the flag, +8; a new error flag follows.
            self.push_error(ErrorKind::Bit);
            let active = self.fc.is_active();
            if self
                .fc
                .rule4_5_bit_error_in_flag(self.role_tx, &mut self.ev)
            {
                return self.enter_bus_off();
            }
            return self.start_error_flag(active);
        }
        self.cnt += 1;
        if self.cnt == 6 {
            self.phase = if self.phase == Phase::ActiveFlag {
                Phase::ErrorTolerate
            } else {
                Phase::OverloadTolerate
            };
            self.tx = RECESSIVE;
            self.dom_cnt = 0;
        }
    }

    /// Passive error flag: done after six consecutive equal bits.
    fn passive_flag(&mut self, rx: bool) {
        if !rx && self.ack_exc {
            // Exception 1 no longer holds: a dominant bit during the flag.
            self.ack_exc = false;
            if self.fc.rule3_transmitter_flag(&mut self.ev) {
                return self.enter_bus_off();
            }
        }
        if self.flag_run == 0 || rx != self.flag_lvl {
            self.flag_lvl = rx;
            self.flag_run = 1;
        } else {
            self.flag_run += 1;
        }
        if self.flag_run == 6 {
            self.ack_exc = false;
            self.phase = Phase::ErrorTolerate;
            self.dom_cnt = 0;
        }
    }

    /// After a flag: recessive sent until the bus is recessive.
    fn tolerate(&mut self, rx: bool) {
        if !rx {
            self.dom_cnt += 1;
            let mut off = false;
            if self.dom_cnt == 1 && !self.role_tx && self.phase == Phase::ErrorTolerate {
                // Rule 2: dominant as the first bit after an error flag.
                off |= self.fc.rule2_dominant_after_flag(&mut self.ev);
            }
            if self.dom_cnt % 8 == 0 {
                // Rule 6: 14th dominant bit after an active/overload flag
                // (6 flag bits + 8), 8th after a passive one, and each 8 more.
                off |= self.fc.rule6_dominant_sequence(self.role_tx, &mut self.ev);
            }
            if off {
                self.enter_bus_off();
            }
            return;
        }
        self.phase = if self.phase == Phase::ErrorTolerate {
            Phase::ErrorDelim
        } else {
            Phase::OverloadDelim
        };
        self.cnt = 1;
    }

    fn enter_bus_off(&mut self) {
        self.phase = Phase::BusOff;
        self.tx = RECESSIVE;
        self.role_tx = false;
        self.cnt = 0;
        self.recovery = 0;
        self.ack_exc = false;
        self.abort_req = false;
        if self.pending.take().is_some() {
            self.ev.push(Event::TxAborted);
        }
        // The SJA1000 sets MOD.RM itself at bus-off.
        self.reset_mode = true;
    }

    /// Rule 12: 128 occurrences of 11 consecutive recessive bits.
    fn bus_off_recovery(&mut self, rx: bool) {
        // The recovery runs only outside reset mode (the bus-off sets it;
        // the host clears it to start the recovery, datasheet MOD.RM).
        if !rx || self.reset_mode {
            self.cnt = 0;
            return;
        }
        self.cnt += 1;
        if self.cnt == 11 {
            self.cnt = 0;
            self.recovery += 1;
            if self.fc.recovery_step(self.recovery, &mut self.ev) {
                self.enter_idle();
                if self.phase == Phase::Idle && !self.role_tx {
                    self.since_bus_on = 0;
                }
            }
        }
    }

    // ---- resynchronisation (waivers) ------------------------------------

    /// For a DUT that waits for one more bus-free sequence (11 recessive
    /// bits) after bus-on before it may start a frame: if at most
    /// `max_since` recessive idle bits have passed since this node's bus-on
    /// and it has started nothing since, it goes back to integrating, as if
    /// the sequence had begun at its bus-on; a transmission requested now
    /// is then held for at most `slack` bits past the 11th, for another
    /// node's start of frame ([`Bsp::start_held_tx`]). True if done, or
    /// already so.
    pub(crate) fn wait_bus_free_after_bus_on(&mut self, max_since: u8, slack: u8) -> bool {
        if self.phase == Phase::Integrating && self.sof_hold > 0 {
            return true;
        }
        if self.phase != Phase::Idle || self.role_tx || self.since_bus_on > max_since || slack == 0 {
            return false;
        }
        self.phase = Phase::Integrating;
        self.cnt = self.since_bus_on;
        self.since_bus_on = u8::MAX;
        self.sof_hold = slack;
        true
    }

    /// A transmission held by [`Bsp::wait_bus_free_after_bus_on`] past its
    /// 11 recessive bits, waiting for another node's start of frame.
    pub(crate) fn tx_held(&self) -> bool {
        self.phase == Phase::Integrating && self.sof_hold > 0 && self.cnt >= 11 && self.pending.is_some()
    }

    /// Starts the held transmission: its start of frame is driven from now.
    pub(crate) fn start_held_tx(&mut self) -> bool {
        if !self.tx_held() || self.opt.listen_only || self.reset_mode {
            return false;
        }
        self.sof_hold = 0;
        self.phase = Phase::Idle;
        self.try_start_tx();
        true
    }

    // ---- queries -----------------------------------------------------

    /// A recessive-to-dominant edge now would be a start of frame.
    #[inline]
    /// A transmission decided at the last sample point whose SOF bit has
    /// not been sampled yet (the BTL drives it from the next bit start).
    pub(crate) fn sof_pending(&self) -> bool {
        self.phase == Phase::Stuffed && self.role_tx && self.fld == Field::Sof
    }

    pub(crate) fn hard_sync_allowed(&self) -> bool {
        match self.phase {
            Phase::Idle
            | Phase::Integrating
            | Phase::Suspend
            | Phase::BusOff
            | Phase::Sleep
            | Phase::Off => true,
            Phase::Intermission => self.cnt == 2,
            _ => false,
        }
    }

    pub(crate) fn field(&self) -> Field {
        match self.phase {
            Phase::Off | Phase::Sleep | Phase::Integrating | Phase::BusOff | Phase::Idle => {
                Field::BusIdle
            }
            Phase::Stuffed if self.fld == Field::CrcDelim => Field::Crc,
            Phase::Stuffed => self.fld,
            Phase::CrcDelim => Field::CrcDelim,
            Phase::AckSlot => Field::AckSlot,
            Phase::AckDelim => Field::AckDelim,
            Phase::Eof => Field::Eof,
            Phase::Intermission => Field::Intermission,
            Phase::Suspend => Field::SuspendTransmission,
            Phase::ActiveFlag => Field::ActiveErrorFlag,
            Phase::PassiveFlag => Field::PassiveErrorFlag,
            Phase::ErrorTolerate | Phase::ErrorDelim => Field::ErrorDelimiter,
            Phase::OverloadFlag => Field::OverloadFlag,
            Phase::OverloadTolerate | Phase::OverloadDelim => Field::OverloadDelimiter,
        }
    }

    /// In a frame or in error/overload signalling.
    pub(crate) fn busy(&self) -> bool {
        !matches!(
            self.phase,
            Phase::Off
                | Phase::Sleep
                | Phase::Integrating
                | Phase::BusOff
                | Phase::Idle
                | Phase::Intermission
                | Phase::Suspend
        )
    }

    pub(crate) fn request(&mut self, req: TxRequest) {
        self.pending = Some(req);
        self.abort_req = false;
    }

    pub(crate) fn abort(&mut self) {
        if self.pending.is_none() {
            return;
        }
        if self.role_tx && self.busy() {
            self.abort_req = true;
        } else {
            self.pending = None;
            self.ev.push(Event::TxAborted);
        }
    }

    pub(crate) fn set_reset_mode(&mut self, on: bool) {
        if on == self.reset_mode {
            return;
        }
        self.reset_mode = on;
        self.sof_hold = 0;
        if on {
            if self.phase != Phase::BusOff {
                self.phase = Phase::Off;
            }
            self.tx = RECESSIVE;
            self.role_tx = false;
            // The controller releases the transmit buffer in reset mode.
            self.pending = None;
            self.abort_req = false;
        } else {
            if std::mem::take(&mut self.bus_off_armed) {
                // Datasheet TXERR: the CPU-driven bus-off is performed now,
                // as a bus-off by errors (reset mode is entered again).
                self.fc.force_bus_off(&mut self.ev);
                self.enter_bus_off();
                return;
            }
            self.cnt = 0;
            // A recovery interrupted by reset mode goes on from where it
            // was: its count is TXERR, which reset mode leaves unchanged
            // (datasheet reset-value table); only the current run of
            // recessive bits starts again.
            if self.phase != Phase::BusOff {
                self.phase = Phase::Integrating;
            }
            // Status changes from CPU writes to TXERR/RXERR show now.
            self.fc.update(&mut self.ev);
        }
    }

    /// A dominant bit while asleep: the wake-up event, then (datasheet)
    /// a bus-free sequence (11 recessive bits) before taking part.
    pub(crate) fn wake_by_bus(&mut self) {
        self.ev.push(Event::WakeUp);
        self.phase = Phase::Integrating;
        self.cnt = 0;
    }

    pub(crate) fn set_sleep(&mut self, on: bool) {
        if on {
            if !matches!(self.phase, Phase::Off | Phase::BusOff | Phase::Sleep) {
                self.slept_from = (self.phase, self.cnt);
                self.phase = Phase::Sleep;
                self.tx = RECESSIVE;
                self.role_tx = false;
            }
        } else if self.phase == Phase::Sleep {
            self.phase = Phase::Integrating;
            self.cnt = 0;
        }
    }

    /// Undoes a sleep as if it had never been entered (lockstep resync for
    /// a DUT with no sleep mode): back to the phase it left, no wake-up
    /// integration. Bits that passed meanwhile are not replayed.
    pub(crate) fn cancel_sleep(&mut self) {
        if self.phase == Phase::Sleep {
            (self.phase, self.cnt) = self.slept_from;
        }
    }

    pub(crate) fn write_counters(&mut self, tec: Option<u8>, rec: Option<u8>) {
        let was_off = self.fc.state() == FaultState::BusOff;
        if tec == Some(255) {
            // Datasheet: writing 255 to TXERR forces a bus-off event (a
            // no-op while bus-off). In reset mode TXERR reads 255 and the
            // bus-off waits until the mode is left; outside it (only a
            // lockstep resync writes there) it happens at once.
            if was_off {
                return;
            }
            if self.reset_mode {
                self.fc.write(tec, rec, &mut self.ev);
                self.bus_off_armed = true;
            } else {
                self.fc.force_bus_off(&mut self.ev);
                self.enter_bus_off();
            }
            return;
        }
        if tec.is_some() {
            self.bus_off_armed = false;
        }
        self.fc.write(tec, rec, &mut self.ev);
        if was_off && self.fc.state() != FaultState::BusOff {
            // Bus-off cleared by the write: one bus-free sequence once reset
            // mode is left.
            self.phase = if self.reset_mode {
                Phase::Off
            } else {
                Phase::Integrating
            };
            self.cnt = 0;
        }
    }
}

#[cfg(test)]
mod stuff_tests {
    use super::TxRequest;
    use can_proto::{CanFrame, stuff};

    /// The word-wise stuffer gives can-proto's bit-by-bit stuffing on
    /// random frames (long runs included: all-zero and all-one data).
    #[test]
    fn word_stuffing_matches_can_proto_on_random_frames() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for k in 0..3000 {
            let r = next();
            let id = if k % 2 == 0 {
                CanFrame::std_id((r & 0x7ff) as u16).unwrap()
            } else {
                CanFrame::ext_id((r & 0x1fff_ffff) as u32).unwrap()
            };
            let rtr = (r >> 40) & 7 == 0;
            let dlc = ((r >> 44) & 15) as u8;
            let data = match k % 5 {
                0 => [0u8; 8],
                1 => [0xff; 8],
                _ => next().to_le_bytes(),
            };
            let n = if rtr { 0 } else { dlc.min(8) as usize };
            let f = CanFrame::with_dlc(id, rtr, dlc, &data[..n]).unwrap();
            let want: Vec<bool> = stuff::stuff(&f.unstuffed_bits()).iter().by_vals().collect();
            assert_eq!(TxRequest::new(f, false, false).stuffed(), want, "{f:?}");
        }
    }
}
