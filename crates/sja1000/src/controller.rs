//! The SJA1000 controller: the register file over [`regmap`], commands,
//! status, interrupts, RX FIFO, TX buffer, acceptance filter, sleep and
//! CLKOUT, around a [`can_engine::Engine`].
//!
//! Every address decision (what an access reaches in which view and mode,
//! which bits a write may change, reset values, field masks) comes from
//! `regmap`; this file only gives each register its behaviour.

use can_engine::{Engine, Event, FaultState, Options, PhaseOrigin};
use can_proto::timing::BusTiming;
use can_proto::{CanFrame, Field, FrameTrait, Id};
use std::sync::OnceLock;

use regmap::{
    Access, Mode, OpMode, RegError, Register, RegisterView, ResetValue, Target, basic, peli,
};

use crate::fifo::RxFifo;
use crate::filter::{self, FilterMode};

/// Which reset (tetanes-style `ResetKind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ResetKind {
    /// Power-on / RST pin: every register takes its hardware reset value.
    Hardware,
    /// Reset mode entered by software (MOD.RM / CR.RR) or by bus-off.
    ResetMode,
}

/// What a host write did. The diagnoser uses it to explain writes that had
/// no effect ("configuration written outside reset mode", "TX buffer
/// written while locked").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum WriteOutcome {
    /// The write took effect.
    Applied,
    /// The register is writable in reset mode only; nothing changed.
    IgnoredNotInResetMode {
        /// Register name (data sheet symbol).
        reg: &'static str,
    },
    /// Some bits are writable in reset mode only (e.g. MOD.LOM/STM/AFM,
    /// CDR.7); those bits kept their value, the others were written.
    BitsIgnoredNotInResetMode {
        /// Register name.
        reg: &'static str,
        /// The bits the write tried to change but could not.
        bits: u8,
    },
    /// Bits that cannot be set in reset mode (MOD.SM); the others were written.
    BitsIgnoredInResetMode {
        /// Register name.
        reg: &'static str,
        /// The bits the write tried to change but could not.
        bits: u8,
    },
    /// The address is writable in operating mode only (BasicCAN TX buffer).
    IgnoredInResetMode {
        /// Register name.
        reg: &'static str,
    },
    /// TX buffer written while SR.TBS = 0 (a transmission is pending).
    IgnoredTxBufferLocked {
        /// Register name.
        reg: &'static str,
    },
    /// The register is read only.
    IgnoredReadOnly {
        /// Register name.
        reg: &'static str,
    },
    /// Nothing is writable at this address in this view.
    IgnoredReserved,
    /// A command had no effect; the rest of the write was applied.
    CommandIgnored {
        /// Command bit name (TR, SRR, GTS, SM).
        command: &'static str,
        /// Why, in a few words.
        reason: &'static str,
    },
}

impl std::fmt::Display for WriteOutcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            WriteOutcome::Applied => write!(f, "write applied"),
            WriteOutcome::IgnoredNotInResetMode { reg } => {
                write!(
                    f,
                    "{reg} written outside reset mode: it is writable in reset mode only, the write was ignored"
                )
            }
            WriteOutcome::BitsIgnoredNotInResetMode { reg, bits } => write!(
                f,
                "{reg} bits {bits:#04x} written outside reset mode: they are writable in reset mode only and kept their value"
            ),
            WriteOutcome::BitsIgnoredInResetMode { reg, bits } => {
                write!(
                    f,
                    "{reg} bits {bits:#04x} cannot be set in reset mode and kept their value"
                )
            }
            WriteOutcome::IgnoredInResetMode { reg } => {
                write!(
                    f,
                    "{reg} written in reset mode: it is writable in operating mode only, the write was ignored"
                )
            }
            WriteOutcome::IgnoredTxBufferLocked { reg } => write!(
                f,
                "{reg} written while the TX buffer is locked (SR.TBS = 0, a transmission is pending): the write was ignored"
            ),
            WriteOutcome::IgnoredReadOnly { reg } => {
                write!(f, "{reg} is read only: the write was ignored")
            }
            WriteOutcome::IgnoredReserved => write!(
                f,
                "nothing is writable at this address: the write was ignored"
            ),
            WriteOutcome::CommandIgnored { command, reason } => {
                write!(f, "command {command} ignored: {reason}")
            }
        }
    }
}

/// What a node did with a frame it received valid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RxOutcome {
    /// Accepted and stored in the RX FIFO.
    Stored,
    /// Accepted but the RX FIFO had no room: data overrun.
    Overrun,
    /// Rejected by the acceptance filter.
    Filtered,
    /// An extended frame in BasicCAN mode: acknowledged, never stored.
    ExtendedInBasicCan,
}

/// One entry of a node's journal (kept only when enabled, for the bus's
/// accounting check and for diagnostics).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NodeEvent {
    /// Our transmission completed.
    Sent(CanFrame),
    /// A frame was received valid.
    Received {
        /// The frame.
        frame: CanFrame,
        /// Received back from our own transmission.
        own: bool,
        /// What happened to it.
        outcome: RxOutcome,
    },
    /// A bus error was detected (an error frame follows).
    BusError {
        /// ECC value.
        ecc: u8,
    },
    /// Arbitration lost at ALC bit `alc`.
    ArbitrationLost {
        /// ALC value.
        alc: u8,
    },
    /// Reset mode entered (true) or left (false).
    ResetMode(bool),
    /// Sleep mode entered (true) or left (false).
    Sleep(bool),
    /// The fault confinement state changed.
    FaultState(FaultState),
}

/// Internal name of what a register view reaches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum R {
    Mod,
    Cr,
    Cmr,
    Sr,
    Ir,
    Ier,
    Btr0,
    Btr1,
    Ocr,
    Test,
    Alc,
    Ecc,
    Ewlr,
    RxErr,
    TxErr,
    Acr(usize),
    Amr(usize),
    /// Receive buffer window byte (index from the window base).
    RxWindow,
    /// TX buffer byte (index from the buffer base).
    TxBuffer,
    Rmc,
    Rbsa,
    Cdr,
    RxFifoRam,
    TxBufRam,
    RamFree,
    Unknown,
}

fn classify(r: &Register) -> R {
    match r.name {
        "MOD" => R::Mod,
        "CR" => R::Cr,
        "CMR" => R::Cmr,
        "SR" => R::Sr,
        "IR" => R::Ir,
        "IER" => R::Ier,
        "BTR0" => R::Btr0,
        "BTR1" => R::Btr1,
        "OCR" => R::Ocr,
        "TEST" => R::Test,
        "ALC" => R::Alc,
        "ECC" => R::Ecc,
        "EWLR" => R::Ewlr,
        "RXERR" => R::RxErr,
        "TXERR" => R::TxErr,
        "ACR" | "ACR0" => R::Acr(0),
        "ACR1" => R::Acr(1),
        "ACR2" => R::Acr(2),
        "ACR3" => R::Acr(3),
        "AMR" | "AMR0" => R::Amr(0),
        "AMR1" => R::Amr(1),
        "AMR2" => R::Amr(2),
        "AMR3" => R::Amr(3),
        "RXFI" | "RXB" | "RXID1" | "RXID2" | "RXDATA" => R::RxWindow,
        "TXFI" | "TXB" | "TXID1" | "TXID2" | "TXDATA" => R::TxBuffer,
        "RMC" => R::Rmc,
        "RBSA" => R::Rbsa,
        "CDR" => R::Cdr,
        "RXFIFO" => R::RxFifoRam,
        "TXBUF" => R::TxBufRam,
        "RAMFREE" => R::RamFree,
        _ => R::Unknown,
    }
}

/// Bits of a register that read as a constant: outside every field, never
/// writable, with a defined hardware reset value (e.g. CR.5
/// reads 1, BasicCAN IR.7..5 read 1, MOD.7..5 read 0).
fn constant_bits(r: &Register) -> (u8, u8) {
    let fields = r.fields.iter().fold(0u8, |m, f| m | f.mask());
    let mut writable = 0u8;
    for op in OpMode::ALL {
        for a in r.addr..r.addr.saturating_add(r.len) {
            if let Some(v) = regmap::lookup(r.mode, op, Access::Write, a)
                && v.register().is_some_and(|x| std::ptr::eq(x, r))
            {
                writable |= v.write_mask;
            }
        }
    }
    // A bit nothing can write keeps its hardware reset value, unless
    // entering reset mode defines another one.
    let rm_agrees = !r.reset_rm.defined | !(r.reset_hw.value ^ r.reset_rm.value);
    let mask = !fields & !writable & r.reset_hw.defined & rm_agrees;
    (mask, r.reset_hw.value & mask)
}

/// `mask` if `on`, else 0.
#[inline]
pub(crate) const fn bit(on: bool, mask: u8) -> u8 {
    if on { mask } else { 0 }
}

fn reg_of(mode: Mode, name: &str) -> &'static Register {
    regmap::register(mode, name).expect("register present in regmap")
}

/// One (view, op mode, direction, address) decoded once from `regmap`,
/// with what the model needs per access precomputed.
#[derive(Clone, Copy, Debug)]
struct Decoded {
    view: &'static RegisterView,
    r: R,
    /// Constant bits of the register reached ([`constant_bits`]).
    cmask: u8,
    cval: u8,
    /// All field bits of the register reached.
    fields: u8,
}

const ADDRS: usize = 128;

fn index(mode: Mode, op: OpMode, access: Access, addr: usize) -> usize {
    let m = (mode == Mode::PeliCan) as usize;
    let o = (op == OpMode::Operating) as usize;
    let a = (access == Access::Write) as usize;
    ((m * 2 + o) * 2 + a) * ADDRS + addr
}

/// The decode table, derived from `regmap` on first use.
fn decode_table() -> &'static [Option<Decoded>] {
    static TABLE: OnceLock<Vec<Option<Decoded>>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = vec![None; 8 * ADDRS];
        for mode in Mode::ALL {
            for op in OpMode::ALL {
                for access in Access::ALL {
                    for addr in 0..ADDRS {
                        let Some(view) = regmap::lookup(mode, op, access, addr as u8) else {
                            continue;
                        };
                        let (r, (cmask, cval), fields) = match view.register() {
                            Some(reg) => (
                                classify(reg),
                                constant_bits(reg),
                                reg.fields.iter().fold(0u8, |m, f| m | f.mask()),
                            ),
                            None => (R::Unknown, (0, 0), 0),
                        };
                        t[index(mode, op, access, addr)] = Some(Decoded {
                            view,
                            r,
                            cmask,
                            cval,
                            fields,
                        });
                    }
                }
            }
        }
        t
    })
}

#[inline]
fn decoded(mode: Mode, op: OpMode, access: Access, addr: u8) -> Result<&'static Decoded, RegError> {
    let d = if (addr as usize) < ADDRS {
        decode_table()[index(mode, op, access, addr as usize)].as_ref()
    } else {
        None
    };
    d.ok_or(RegError::OutOfRange { addr, mode })
}

// Interrupt flag masks (same positions in both views for the shared ones).
const RI: u8 = peli::ir::RI;
const TI: u8 = peli::ir::TI;
const EI: u8 = peli::ir::EI;
const DOI: u8 = peli::ir::DOI;
const WUI: u8 = peli::ir::WUI;
const EPI: u8 = peli::ir::EPI;
const ALI: u8 = peli::ir::ALI;
const BEI: u8 = peli::ir::BEI;

/// The SJA1000 golden model.
#[derive(Clone, Debug)]
pub struct Sja1000 {
    engine: Engine,
    /// SR.TS reads 0 during suspend transmission (a profile's
    /// `ts-in-suspend = "clear"`); kept across hardware resets.
    ts_clear_in_suspend: bool,
    /// A read of ECC clears it (a profile's `ecc-after-read = "cleared"`);
    /// kept across hardware resets.
    ecc_clear_on_read: bool,
    mode: Mode,
    // MOD / CR
    rm: bool,
    lom: bool,
    stm: bool,
    afm: bool,
    sleeping: bool,
    /// BasicCAN CR as written (enables and CR.6), RR excluded.
    cr: u8,
    ier: u8,
    /// Latched interrupt flags (all IR bits; RI follows the FIFO).
    ir: u8,
    // status
    tbs: bool,
    tcs: bool,
    /// CMR.AT written (operating mode) since the last TR/SRR.
    aborted: bool,
    dos: bool,
    es: bool,
    bs: bool,
    fault: FaultState,
    // configuration
    acr: [u8; 4],
    amr: [u8; 4],
    btr0: u8,
    btr1: u8,
    ocr: u8,
    test: u8,
    ewlr: u8,
    cdr: u8,
    // capture registers
    alc: u8,
    alc_locked: bool,
    ecc: u8,
    ecc_locked: bool,
    fifo: RxFifo,
    tx_buf: [u8; 13],
    ram_free: [u8; 3],
    pending_tx: Option<CanFrame>,
    // CLKOUT divider
    clk_cnt: u8,
    clkout: bool,
    scratch: Vec<Event>,
    journal: Option<Vec<NodeEvent>>,
}

impl Default for Sja1000 {
    fn default() -> Self {
        Self::new()
    }
}

impl Sja1000 {
    /// A controller just after a hardware reset: BasicCAN, reset mode.
    pub fn new() -> Self {
        let mut s = Sja1000::blank();
        s.hard_reset();
        s
    }

    /// Where the bit timing's phase starts from (an implementation
    /// freedom, see [`PhaseOrigin`]); kept across hardware resets. Set it
    /// right after [`Sja1000::new`] (before the first clock).
    pub fn set_phase_origin(&mut self, origin: PhaseOrigin) {
        self.engine.set_phase_origin(origin);
    }

    /// The DUT's declared segment lag (a profile's `segment-lag`, with the
    /// hardware-reset phase origin); kept across hardware resets. See
    /// [`Engine::set_segment_lag`].
    pub fn set_segment_lag(&mut self, lag: u32) {
        self.engine.set_segment_lag(lag);
    }

    /// SR.TS during suspend transmission (a profile's `ts-in-suspend`):
    /// `true` reads 0 there. The datasheet's TS is "transmitting a
    /// message" and says nothing of the 8 suspend bits, in which the node
    /// is still the transmitter (CAN 2.0B §4) but sends nothing: either
    /// reading is the datasheet's. Default: 1 (still the transmitter).
    pub fn set_ts_clear_in_suspend(&mut self, on: bool) {
        self.ts_clear_in_suspend = on;
    }

    /// ECC after the host has read it (a profile's `ecc-after-read`):
    /// `true` clears it, so it reads 0 until the next capture. The
    /// datasheet fixes ECC until the host has read it once and then re-arms
    /// the capture; it does not say what a second read returns. Default:
    /// the last code is kept.
    pub fn set_ecc_clear_on_read(&mut self, on: bool) {
        self.ecc_clear_on_read = on;
    }

    /// The declared segment lag ([`Sja1000::set_segment_lag`]).
    pub fn segment_lag(&self) -> u32 {
        self.engine.segment_lag()
    }

    /// Hardware reset (RST pin): hardware reset values from the register
    /// map; registers the data sheet leaves undefined read 0 here.
    pub fn hard_reset(&mut self) {
        let journal = self.journal.take().map(|mut j| {
            j.clear();
            j
        });
        let scratch = std::mem::take(&mut self.scratch);
        let origin = self.engine.phase_origin();
        let segment_lag = self.engine.segment_lag();
        let ts_clear_in_suspend = self.ts_clear_in_suspend;
        let ecc_clear_on_read = self.ecc_clear_on_read;
        *self = Sja1000 {
            engine: Engine::new(BusTiming::from_btr(0, 0), Options::default()),
            fifo: RxFifo::default(),
            scratch,
            journal,
            ts_clear_in_suspend,
            ecc_clear_on_read,
            ..Sja1000::blank()
        };
        // CDR first: it selects the view (hardware reset: BasicCAN).
        self.cdr = reg_of(Mode::PeliCan, "CDR").reset_hw.apply(0);
        self.mode = Mode::from_cdr(self.cdr);
        for mode in [Mode::PeliCan, Mode::BasicCan] {
            for r in regmap::registers(mode) {
                self.apply_reset_value(r, r.reset_hw);
            }
        }
        self.rm = true;
        self.engine.set_phase_origin(origin);
        self.engine.set_segment_lag(segment_lag);
        self.engine.set_reset_mode(true);
        self.push_engine_config();
        self.engine.take_events().for_each(drop);
        self.log(NodeEvent::ResetMode(true));
    }

    /// Either reset (tetanes-style `Reset`): [`ResetKind::Hardware`] is
    /// [`Sja1000::hard_reset`]; [`ResetKind::ResetMode`] is what setting
    /// MOD.RM / CR.RR does (a no-op if already in reset mode).
    pub fn reset(&mut self, kind: ResetKind) {
        match kind {
            ResetKind::Hardware => self.hard_reset(),
            ResetKind::ResetMode => {
                if !self.rm {
                    self.enter_reset_mode();
                    if self.engine.has_events() {
                        self.handle_events();
                    }
                }
            }
        }
    }

    /// All state zeroed; [`Sja1000::hard_reset`] then applies the map's values.
    fn blank() -> Sja1000 {
        Sja1000 {
            engine: Engine::new(BusTiming::from_btr(0, 0), Options::default()),
            ts_clear_in_suspend: false,
            ecc_clear_on_read: false,
            mode: Mode::BasicCan,
            rm: true,
            lom: false,
            stm: false,
            afm: false,
            sleeping: false,
            cr: 0,
            ier: 0,
            ir: 0,
            tbs: true,
            tcs: true,
            aborted: false,
            dos: false,
            es: false,
            bs: false,
            fault: FaultState::ErrorActive,
            acr: [0; 4],
            amr: [0; 4],
            btr0: 0,
            btr1: 0,
            ocr: 0,
            test: 0,
            ewlr: 96,
            cdr: 0,
            alc: 0,
            alc_locked: false,
            ecc: 0,
            ecc_locked: false,
            fifo: RxFifo::default(),
            tx_buf: [0; 13],
            ram_free: [0; 3],
            pending_tx: None,
            clk_cnt: 0,
            clkout: false,
            scratch: Vec::new(),
            journal: None,
        }
    }

    /// Applies one register's reset value (defined bits only) without side effects.
    fn apply_reset_value(&mut self, r: &Register, rv: ResetValue) {
        if r.len != 1 || rv.defined == 0 {
            return;
        }
        let old = self.raw_value(r, r.addr);
        let new = rv.apply(old);
        self.poke(r, new);
    }

    /// Sets the state behind a register from a raw value (reset only).
    fn poke(&mut self, r: &Register, v: u8) {
        match classify(r) {
            R::Mod => {
                self.rm = v & peli::r#mod::RM != 0;
                self.lom = v & peli::r#mod::LOM != 0;
                self.stm = v & peli::r#mod::STM != 0;
                self.afm = v & peli::r#mod::AFM != 0;
                self.sleeping = v & peli::r#mod::SM != 0;
            }
            R::Cr => {
                self.rm = v & basic::cr::RR != 0;
                self.cr = v & !basic::cr::RR;
            }
            R::Sr => {
                self.tbs = v & peli::sr::TBS != 0;
                self.tcs = v & peli::sr::TCS != 0;
                self.dos = v & peli::sr::DOS != 0;
                if v & peli::sr::RBS == 0 {
                    self.fifo.clear();
                }
            }
            R::Ir => {
                let fields = r.fields.iter().fold(0u8, |m, f| m | f.mask());
                self.ir = (self.ir & !fields) | (v & fields & !RI);
            }
            R::Ier => self.ier = v,
            R::Btr0 => self.btr0 = v,
            R::Btr1 => self.btr1 = v,
            R::Ocr => self.ocr = v,
            R::Test => self.test = v,
            R::Alc => self.alc = v,
            R::Ecc => self.ecc = v,
            R::Ewlr => self.ewlr = v,
            R::RxErr => self.engine.set_rec(v),
            R::TxErr => self.engine.set_tec(v),
            R::Acr(i) => self.acr[i] = v,
            R::Amr(i) => self.amr[i] = v,
            R::Rmc if v == 0 => self.fifo.clear(),
            R::Rbsa => self.fifo.set_rbsa(v),
            R::Cdr => {
                self.cdr = v;
                self.mode = Mode::from_cdr(v);
            }
            _ => {}
        }
    }

    // ------------------------------------------------------------------
    // Pins and state

    /// The register view selected by CDR.7.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Reset mode (MOD.RM / CR.RR) or operating mode.
    pub fn opmode(&self) -> OpMode {
        if self.rm {
            OpMode::Reset
        } else {
            OpMode::Operating
        }
    }

    /// True in reset mode.
    pub fn in_reset_mode(&self) -> bool {
        self.rm
    }

    /// True while sleeping (MOD.SM / CMR.GTS took effect).
    pub fn is_sleeping(&self) -> bool {
        self.sleeping
    }

    /// The protocol engine.
    pub fn engine(&self) -> &Engine {
        &self.engine
    }

    /// Interrupt pending (some IR flag set). The pin is `irq_on = !irq()`.
    pub fn irq(&self) -> bool {
        self.ir_flags() != 0
    }

    /// Messages lost to an RX FIFO overrun (SR.DOS's condition) since the
    /// FIFO was last emptied (reset mode, hardware reset); releases keep
    /// the count. Observed by the waivers' `after = "data-overrun"`.
    pub fn lost_messages(&self) -> u8 {
        self.fifo.lost()
    }

    /// Bus-off (SR.BS). The pin is `bus_off_on = !bus_off()`.
    pub fn bus_off(&self) -> bool {
        self.bs
    }

    /// The clock divider register as stored, without a register read's
    /// decoding: its CD (2..0) and clock-off (3) bits are what `peek(31)`
    /// shows in every view and mode, at the cost of a field load (a test
    /// bench asks for them every CAN clock).
    #[inline]
    pub fn cdr(&self) -> u8 {
        self.cdr
    }

    /// CLKOUT pin level (CDR.2..0 divider, CDR.3 clock off holds it high).
    /// With CD = 7 (fosc itself) the level within one clk_i period cannot
    /// be shown at one call per period; it reads high.
    pub fn clkout(&self) -> bool {
        if self.cdr & peli::cdr::CLKOFF != 0 || self.cdr & peli::cdr::CD == peli::cdr::CD {
            return true;
        }
        self.clkout
    }

    /// Level this node drives on the bus.
    #[inline]
    pub fn tx(&self) -> bool {
        self.engine.tx()
    }

    /// One period of the CAN clock clk_i with bus level `rx`; returns tx.
    #[inline]
    pub fn clock(&mut self, rx: bool) -> bool {
        let tx = self.engine.clock(rx);
        if self.engine.has_events() {
            self.handle_events();
        }
        self.tick_clkout();
        tx
    }

    /// Fast path: one whole bit time whose sampled level is `rx` (see
    /// [`Engine::sample_bit`]). CLKOUT does not advance on this path.
    #[inline(always)]
    pub fn sample_bit(&mut self, rx: bool) {
        self.engine.sample_bit(rx);
        if self.engine.has_events() {
            self.handle_events();
        }
    }

    /// `n` clocks with bus level `rx` in which the engine only counts
    /// ([`can_engine::Engine::quiet_clocks`]), so no event comes: what `n`
    /// calls of [`Sja1000::clock`] with `rx` do.
    pub fn quiet_clocks_run(&mut self, n: u32, rx: bool) {
        if n == 0 {
            return;
        }
        self.engine.quiet_run(n, rx);
        debug_assert!(!self.engine.has_events());
        // `tick_clkout` n times: a toggle every CD + 1 clocks (a count
        // already past a lowered CD toggles at the first).
        let period = u32::from(self.cdr & peli::cdr::CD) + 1;
        let mut left = n;
        if u32::from(self.clk_cnt) >= period {
            self.tick_clkout();
            left -= 1;
        }
        let total = u32::from(self.clk_cnt) + left;
        self.clk_cnt = (total % period) as u8;
        self.clkout ^= (total / period) % 2 == 1;
    }

    #[inline]
    fn tick_clkout(&mut self) {
        let cd = self.cdr & peli::cdr::CD;
        // fosc / (2 * (CD + 1)): toggle every CD + 1 clocks.
        self.clk_cnt += 1;
        if self.clk_cnt > cd {
            self.clk_cnt = 0;
            self.clkout = !self.clkout;
        }
    }

    /// Keeps a journal of [`NodeEvent`]s (the bus turns it on for accounting).
    pub fn set_journal(&mut self, on: bool) {
        self.journal = if on {
            Some(self.journal.take().unwrap_or_default())
        } else {
            None
        };
    }

    /// Drains the journal.
    pub fn take_journal(&mut self) -> Vec<NodeEvent> {
        self.journal
            .as_mut()
            .map(std::mem::take)
            .unwrap_or_default()
    }

    /// True if the journal has entries (cheap check).
    pub fn journal_pending(&self) -> bool {
        self.journal.as_ref().is_some_and(|j| !j.is_empty())
    }

    #[inline]
    fn log(&mut self, e: NodeEvent) {
        if let Some(j) = self.journal.as_mut() {
            j.push(e);
        }
    }

    /// Whether this node's acceptance filter takes `frame` (with the
    /// current ACR/AMR and MOD.AFM).
    pub fn accepts(&self, frame: &CanFrame) -> bool {
        match self.mode {
            Mode::BasicCan => match frame.id() {
                Id::Standard(s) => filter::basic_accepts(self.acr[0], self.amr[0], s.as_raw()),
                Id::Extended(_) => false,
            },
            Mode::PeliCan => {
                let m = if self.afm {
                    FilterMode::Single
                } else {
                    FilterMode::Dual
                };
                filter::pelican_accepts(m, self.acr, self.amr, frame)
            }
        }
    }

    // ------------------------------------------------------------------
    // Host access

    /// Host read with its side effects (IR clears, ALC/ECC re-arm).
    /// An address outside the view reads 0x00; see [`Sja1000::try_read`].
    pub fn read(&mut self, addr: u8) -> u8 {
        self.try_read(addr).unwrap_or(0)
    }

    /// Host read; an address outside the view is an error.
    pub fn try_read(&mut self, addr: u8) -> Result<u8, RegError> {
        let d = decoded(self.mode, self.opmode(), Access::Read, addr)?;
        Ok(match d.view.target {
            Target::Constant(c) => c,
            Target::Nothing => 0,
            Target::Register(r) => {
                let v = self.value(d, r, addr);
                match d.r {
                    R::Ir => {
                        // A read clears every flag except RI.
                        self.ir &= RI;
                    }
                    R::Alc => self.alc_locked = false,
                    R::Ecc => {
                        self.ecc_locked = false;
                        if self.ecc_clear_on_read {
                            self.ecc = 0;
                        }
                    }
                    _ => {}
                }
                v
            }
        })
    }

    /// Takes another device's error counters (lockstep resync after a
    /// waived divergence), in operating mode too, then re-evaluates the
    /// fault state now: error warning (EWL), error passive at 128. The
    /// datasheet TXERR/RXERR semantics hold: TEC 255 forces bus-off, a TEC
    /// while bus-off clears it, REC is ignored while bus-off.
    pub fn adopt_counters(&mut self, tec: Option<u8>, rec: Option<u8>) {
        if let Some(r) = rec {
            self.engine.set_rec(r);
        }
        if let Some(t) = tec {
            self.engine.set_tec(t);
        }
        if !self.engine.in_reset_mode() {
            // The engine defers warning/passive changes of a counter write
            // to leaving reset mode; re-applying its options re-evaluates
            // them at once (the only public path to that update).
            let o = self.engine.options();
            self.engine.set_options(o);
        }
        if self.engine.has_events() {
            self.handle_events();
        }
    }

    /// Sets a plain storage register (IER, OCR, TEST, ACR/AMR where the
    /// address reaches them now) to `value` without any other effect, so a
    /// reference can adopt a DUT's value; TXERR/RXERR go through
    /// [`Sja1000::adopt_counters`]. False (nothing changed) for derived or
    /// side-effecting registers (SR, IR, MOD, CMR, FIFO, ...) or when the
    /// register would not read back `value`.
    pub fn adopt_register(&mut self, addr: u8, value: u8) -> bool {
        let Ok(d) = decoded(self.mode, self.opmode(), Access::Read, addr) else {
            return false;
        };
        let Target::Register(r) = d.view.target else {
            return false;
        };
        match d.r {
            R::TxErr => self.adopt_counters(Some(value), None),
            R::RxErr => self.adopt_counters(None, Some(value)),
            R::Ier | R::Ocr | R::Test | R::Acr(_) | R::Amr(_) => self.poke(r, value),
            R::Sr => {
                // Only SR's latched flags are stored (TCS, DOS); the other
                // bits follow the engine, the FIFO and the TX buffer, so an
                // SR that differs there cannot be taken: nothing changes.
                let flags = peli::sr::TCS | peli::sr::DOS;
                if self.peek(addr) & !flags != value & !flags {
                    return false;
                }
                self.tcs = value & peli::sr::TCS != 0;
                self.dos = value & peli::sr::DOS != 0;
            }
            _ => return false,
        }
        self.peek(addr) == value
    }

    /// What a read would return, without side effects (diagnostics).
    pub fn peek(&self, addr: u8) -> u8 {
        match decoded(self.mode, self.opmode(), Access::Read, addr) {
            Err(_) => 0,
            Ok(d) => match d.view.target {
                Target::Constant(c) => c,
                Target::Nothing => 0,
                Target::Register(r) => self.value(d, r, addr),
            },
        }
    }

    /// The value a read of `addr` inside `r` returns (no side effects).
    fn value(&self, d: &Decoded, r: &Register, addr: u8) -> u8 {
        (self.raw_value_of(d.r, r, addr) & !d.cmask) | d.cval
    }

    fn raw_value(&self, r: &Register, addr: u8) -> u8 {
        self.raw_value_of(classify(r), r, addr)
    }

    fn raw_value_of(&self, kind: R, r: &Register, addr: u8) -> u8 {
        let off = addr.wrapping_sub(r.addr) as usize;
        match kind {
            R::Mod => {
                bit(self.rm, peli::r#mod::RM)
                    | bit(self.lom, peli::r#mod::LOM)
                    | bit(self.stm, peli::r#mod::STM)
                    | bit(self.afm, peli::r#mod::AFM)
                    | bit(self.sleeping, peli::r#mod::SM)
            }
            R::Cr => self.cr | bit(self.rm, basic::cr::RR),
            R::Cmr => 0,
            R::Sr => self.sr(r),
            R::Ir => {
                let fields = r.fields.iter().fold(0u8, |m, f| m | f.mask());
                self.ir_flags() & fields
            }
            R::Ier => self.ier,
            R::Btr0 => self.btr0,
            R::Btr1 => self.btr1,
            R::Ocr => self.ocr,
            R::Test => self.test,
            R::Alc => self.alc,
            R::Ecc => self.ecc,
            R::Ewlr => self.ewlr,
            R::RxErr => self.engine.rec(),
            R::TxErr => self.engine.tec(),
            R::Acr(i) => self.acr[i],
            R::Amr(i) => self.amr[i],
            R::RxWindow => self.fifo.window((addr - self.rx_window_base()) as usize),
            R::TxBuffer => self.tx_buf[(addr - self.tx_buffer_base()) as usize],
            R::Rmc => self.fifo.rmc(),
            R::Rbsa => self.fifo.rbsa(),
            R::Cdr => self.cdr,
            R::RxFifoRam => self.fifo.ram(off),
            R::TxBufRam => self.tx_buf[off.min(12)],
            R::RamFree => self.ram_free[off.min(2)],
            R::Unknown => 0,
        }
    }

    fn rx_window_base(&self) -> u8 {
        match self.mode {
            Mode::PeliCan => peli::RXFI,
            Mode::BasicCan => basic::RXID1,
        }
    }

    fn tx_buffer_base(&self) -> u8 {
        match self.mode {
            Mode::PeliCan => peli::TXFI,
            Mode::BasicCan => basic::TXID1,
        }
    }

    fn sr(&self, r: &Register) -> u8 {
        use peli::sr;
        let mut v = bit(self.bs, sr::BS)
            | bit(self.es, sr::ES)
            | bit(self.engine.is_transmitting() && !(self.ts_clear_in_suspend && self.engine.in_suspend()), sr::TS)
            | bit(self.engine.is_receiving(), sr::RS)
            | bit(self.tcs, sr::TCS)
            | bit(self.tbs, sr::TBS)
            | bit(self.dos, sr::DOS)
            | bit(self.fifo.rmc() > 0, sr::RBS);
        if self.rm {
            // In reset mode the bits the reset defines hold their reset value
            // (PeliCAN: TS = RS = 1, waiting for bus-free).
            v = r.reset_rm.apply(v);
        } else if self.waiting_for_bus_free() {
            // Reset mode left, bus-free not reached yet (11 recessive bits
            // after reset mode, 128 x 11 in the bus-off recovery): TS and RS
            // keep their reset-mode value ("waiting to become idle again",
            // SR note 3 of the datasheet).
            let ts_rs = sr::TS | sr::RS;
            v = (v & !(ts_rs & r.reset_rm.defined)) | (r.reset_rm.value & ts_rs);
        }
        v
    }

    /// Operating mode, waiting to become idle: reset mode was left and the
    /// engine has not yet seen bus-free, or it is counting the bus-off
    /// recovery (datasheet SR note 3: after bus-off "idle" takes 128
    /// occurrences of 11 recessive bits; TS = RS = 1 until then).
    fn waiting_for_bus_free(&self) -> bool {
        if self.rm || self.sleeping {
            return false;
        }
        self.bs || (self.engine.field() == Field::BusIdle && !self.engine.is_bus_idle())
    }

    /// IR flags now: the latched ones and RI, restricted to the view.
    fn ir_flags(&self) -> u8 {
        let v = self.ir;
        match self.mode {
            Mode::PeliCan => v,
            Mode::BasicCan => v & (RI | TI | EI | DOI | WUI),
        }
    }

    /// Host write.
    /// An address outside the view has no effect; see [`Sja1000::try_write`].
    pub fn write(&mut self, addr: u8, data: u8) -> WriteOutcome {
        self.try_write(addr, data)
            .unwrap_or(WriteOutcome::IgnoredReserved)
    }

    /// Host write; an address outside the view is an error.
    pub fn try_write(&mut self, addr: u8, data: u8) -> Result<WriteOutcome, RegError> {
        let op = self.opmode();
        let d = decoded(self.mode, op, Access::Write, addr)?;
        let r = match d.view.target {
            Target::Register(r) => r,
            _ => return Ok(self.why_ignored(op, addr)),
        };
        let outcome = self.write_reg(d, r, addr, data);
        if self.engine.has_events() {
            self.handle_events();
        }
        Ok(outcome)
    }

    /// Explains a write that reaches nothing in the current op mode.
    fn why_ignored(&self, op: OpMode, addr: u8) -> WriteOutcome {
        let other = match op {
            OpMode::Reset => OpMode::Operating,
            OpMode::Operating => OpMode::Reset,
        };
        if let Some(r) =
            regmap::lookup(self.mode, other, Access::Write, addr).and_then(|v| v.register())
        {
            return match op {
                OpMode::Operating => WriteOutcome::IgnoredNotInResetMode { reg: r.name },
                OpMode::Reset => WriteOutcome::IgnoredInResetMode { reg: r.name },
            };
        }
        if let Some(r) =
            regmap::lookup(self.mode, op, Access::Read, addr).and_then(|v| v.register())
        {
            return WriteOutcome::IgnoredReadOnly { reg: r.name };
        }
        WriteOutcome::IgnoredReserved
    }

    fn write_reg(&mut self, d: &Decoded, r: &'static Register, addr: u8, data: u8) -> WriteOutcome {
        let mask = d.view.write_mask;
        let off = addr.wrapping_sub(r.addr) as usize;
        let old = self.raw_value_of(d.r, r, addr);
        let fields = d.fields;
        let v = (old & !mask) | (data & mask);
        // Field bits the host tried to change but the mode forbids.
        let blocked = (data ^ old) & !mask & fields;
        let partly = |reg: &'static str, op: OpMode| match op {
            OpMode::Operating => WriteOutcome::BitsIgnoredNotInResetMode { reg, bits: blocked },
            OpMode::Reset => WriteOutcome::BitsIgnoredInResetMode { reg, bits: blocked },
        };
        let op = self.opmode();
        let mut outcome = if blocked != 0 {
            partly(r.name, op)
        } else {
            WriteOutcome::Applied
        };
        match d.r {
            R::Mod => {
                use peli::r#mod as m;
                if self.rm {
                    self.lom = v & m::LOM != 0;
                    self.stm = v & m::STM != 0;
                    self.afm = v & m::AFM != 0;
                }
                let want_sleep = v & m::SM != 0;
                if v & m::RM != 0 {
                    if !self.rm {
                        self.enter_reset_mode();
                    }
                } else {
                    if self.rm {
                        self.leave_reset_mode();
                    }
                    if let Some(o) = self.set_sleep(want_sleep, "SM") {
                        outcome = o;
                    }
                }
                self.push_engine_config();
            }
            R::Cr => {
                self.cr = v & !basic::cr::RR;
                if v & basic::cr::RR != 0 {
                    if !self.rm {
                        self.enter_reset_mode();
                    }
                } else if self.rm {
                    self.leave_reset_mode();
                }
                self.update_ri();
            }
            R::Cmr => outcome = self.command(data & mask),
            R::Ier => {
                self.ier = v;
                self.update_ri();
            }
            R::Btr0 => {
                self.btr0 = v;
                self.push_engine_config();
            }
            R::Btr1 => {
                self.btr1 = v;
                self.push_engine_config();
            }
            R::Ocr => self.ocr = v,
            R::Test => self.test = v,
            R::Ewlr => {
                self.ewlr = v;
                self.push_engine_config();
            }
            R::RxErr => self.engine.set_rec(v),
            R::TxErr => self.engine.set_tec(v),
            R::Acr(i) => self.acr[i] = v,
            R::Amr(i) => self.amr[i] = v,
            R::TxBuffer => {
                if !self.tbs {
                    return WriteOutcome::IgnoredTxBufferLocked { reg: r.name };
                }
                self.tx_buf[(addr - self.tx_buffer_base()) as usize] = v;
            }
            R::Rbsa => self.fifo.set_rbsa(v),
            R::Cdr => {
                self.cdr = v;
                let mode = Mode::from_cdr(v);
                if mode != self.mode {
                    self.mode = mode;
                    self.push_engine_config();
                }
            }
            R::RxFifoRam => self.fifo.set_ram(off, v),
            R::TxBufRam => self.tx_buf[off.min(12)] = v,
            R::RamFree => self.ram_free[off.min(2)] = v,
            R::Sr | R::Ir | R::Alc | R::Ecc | R::Rmc | R::RxWindow | R::Unknown => {
                return WriteOutcome::IgnoredReadOnly { reg: r.name };
            }
        }
        outcome
    }

    /// Sends configuration to the engine: timing, listen only, self test, EWL.
    fn push_engine_config(&mut self) {
        let peli = self.mode == Mode::PeliCan;
        // BTR0/BTR1 are written in reset mode only: re-apply the timing only
        // when it changed, so an operating-mode MOD write (a sleep request
        // refused during a frame) does not restart the bit timing mid-frame.
        let timing = BusTiming::from_btr(self.btr0, self.btr1);
        if self.engine.timing() != timing {
            self.engine.set_timing(timing);
        }
        self.engine.set_options(Options {
            listen_only: peli && self.lom,
            self_test: peli && self.stm,
            ewl: if peli { self.ewlr } else { 96 },
        });
    }

    /// CMR: TR, AT, RRB, CDO, and SRR (PeliCAN) or GTS (BasicCAN).
    fn command(&mut self, c: u8) -> WriteOutcome {
        use peli::cmr;
        let mut outcome = WriteOutcome::Applied;
        if c & cmr::RRB != 0 && self.fifo.release() {
            // RI is cleared by the release, then set again if more messages wait.
            self.ir &= !RI;
            self.update_ri();
        }
        if c & cmr::CDO != 0 {
            self.dos = false;
        }
        let (srr, gts) = match self.mode {
            Mode::PeliCan => (c & cmr::SRR != 0, None),
            Mode::BasicCan => (false, Some(c & basic::cmr::GTS != 0)),
        };
        if let Some(gts) = gts
            && !self.rm
            && let Some(o) = self.set_sleep(gts, "GTS")
        {
            outcome = o;
        }
        let tr = c & cmr::TR != 0;
        let at = c & cmr::AT != 0;
        if tr || srr {
            let name = if srr { "SRR" } else { "TR" };
            if self.rm {
                return WriteOutcome::CommandIgnored {
                    command: name,
                    reason: "reset mode",
                };
            }
            if !self.tbs {
                return WriteOutcome::CommandIgnored {
                    command: name,
                    reason: "a transmission is pending (TBS = 0)",
                };
            }
            let frame = self.tx_frame();
            self.tbs = false;
            self.tcs = false;
            self.aborted = false;
            self.pending_tx = Some(frame);
            // TR + AT (or SRR + AT): single shot.
            self.engine.request_tx(frame, at, srr);
        } else if at {
            if !self.rm {
                self.aborted = true;
            }
            if !self.tbs {
                self.engine.abort_tx();
            }
        }
        outcome
    }

    /// True when the host's last word on a transmission was CMR.AT (in
    /// operating mode, since the last TR or SRR): observed by the waivers'
    /// `after-abort`, for a core that shows an aborted request otherwise.
    pub fn aborted_since_request(&self) -> bool {
        self.aborted
    }

    /// The frame described by the TX buffer (PeliCAN frame information
    /// layout, or the BasicCAN two-byte descriptor).
    pub fn tx_frame(&self) -> CanFrame {
        let b = &self.tx_buf;
        let (id, rtr, dlc, data): (Id, bool, u8, &[u8]) = match self.mode {
            Mode::PeliCan => {
                let fi = b[0];
                let rtr = fi & peli::rxfi::RTR != 0;
                let dlc = fi & peli::rxfi::DLC;
                if fi & peli::rxfi::FF != 0 {
                    let raw = (b[1] as u32) << 21
                        | (b[2] as u32) << 13
                        | (b[3] as u32) << 5
                        | (b[4] as u32) >> 3;
                    (CanFrame::ext_id(raw).expect("29 bits"), rtr, dlc, &b[5..13])
                } else {
                    let raw = (b[1] as u16) << 3 | (b[2] as u16) >> 5;
                    (CanFrame::std_id(raw).expect("11 bits"), rtr, dlc, &b[3..11])
                }
            }
            Mode::BasicCan => {
                let raw = (b[0] as u16) << 3
                    | ((b[1] & basic::txid2::ID) as u16) >> basic::txid2::lsb::ID;
                let rtr = b[1] & basic::txid2::RTR != 0;
                let dlc = b[1] & basic::txid2::DLC;
                (CanFrame::std_id(raw).expect("11 bits"), rtr, dlc, &b[2..10])
            }
        };
        let n = if rtr { 0 } else { dlc.min(8) as usize };
        CanFrame::with_dlc(id, rtr, dlc, &data[..n]).expect("DLC and length consistent")
    }

    /// The bytes the RX FIFO stores for `frame` in the current view.
    fn rx_bytes(&self, frame: &CanFrame, out: &mut [u8; 13]) -> usize {
        let rtr = frame.is_remote_frame();
        let dlc = frame.dlc_raw();
        let data = frame.data();
        let head = match (self.mode, frame.id()) {
            (Mode::BasicCan, id) => {
                let raw = match id {
                    Id::Standard(s) => s.as_raw(),
                    Id::Extended(e) => (e.as_raw() >> 18) as u16,
                };
                out[0] = (raw >> 3) as u8;
                out[1] =
                    ((raw as u8 & 7) << basic::txid2::lsb::ID) | bit(rtr, basic::txid2::RTR) | dlc;
                2
            }
            (Mode::PeliCan, Id::Standard(s)) => {
                let raw = s.as_raw();
                out[0] = bit(rtr, peli::rxfi::RTR) | dlc;
                out[1] = (raw >> 3) as u8;
                // ID.20..18 in bits 7..5, RTR copied in bit 4.
                out[2] = ((raw as u8 & 7) << 5) | (rtr as u8) << 4;
                3
            }
            (Mode::PeliCan, Id::Extended(e)) => {
                let raw = e.as_raw();
                out[0] = peli::rxfi::FF | bit(rtr, peli::rxfi::RTR) | dlc;
                out[1] = (raw >> 21) as u8;
                out[2] = (raw >> 13) as u8;
                out[3] = (raw >> 5) as u8;
                // ID.4..0 in bits 7..3, RTR copied in bit 2.
                out[4] = ((raw as u8 & 0x1F) << 3) | (rtr as u8) << 2;
                5
            }
        };
        out[head..head + data.len()].copy_from_slice(data);
        head + data.len()
    }

    /// Lockstep resync for a DUT that waits for one more bus-free sequence
    /// (11 recessive bits) after bus-on before it may start a frame (the
    /// opencores core, deviation D10g): see
    /// [`can_engine::Engine::wait_bus_free_after_bus_on`]. Only within 3
    /// bits of the bus-on; a pending transmission is then held for at most
    /// 2 bits past the 11th, for the DUT's start of frame.
    pub fn wait_bus_free_after_bus_on(&mut self) -> bool {
        !self.rm && self.engine.wait_bus_free_after_bus_on(3, 2)
    }

    /// A transmission held by [`Sja1000::wait_bus_free_after_bus_on`].
    pub fn tx_held(&self) -> bool {
        self.engine.tx_held()
    }

    /// Starts the held transmission now (the DUT's SOF edge was seen).
    pub fn start_held_tx_now(&mut self) -> bool {
        self.engine.start_held_tx_now()
    }

    /// Leaves sleep with no wake-up interrupt (lockstep resync for a DUT
    /// that has no sleep mode: it never slept, so nothing woke it). True if
    /// the model was asleep.
    pub fn skip_sleep(&mut self) -> bool {
        if !self.sleeping {
            return false;
        }
        self.sleeping = false;
        self.engine.cancel_sleep();
        self.log(NodeEvent::Sleep(false));
        true
    }

    /// Enters or leaves sleep; `None` when it took effect or nothing changed.
    fn set_sleep(&mut self, on: bool, command: &'static str) -> Option<WriteOutcome> {
        if on && !self.sleeping {
            // §6.4.3: sleep is entered only with no interrupt pending and no bus
            // activity; a refused request raises WUI (datasheet note on SM/GTS:
            // a wake-up interrupt is also generated then).
            if self.irq() {
                self.raise(WUI);
                return Some(WriteOutcome::CommandIgnored {
                    command,
                    reason: "an interrupt is pending",
                });
            }
            // A requested transmission not yet on the wire is bus activity
            // about to start (SR.TBS = 0): refused as well, whichever side
            // of the request's SOF the write falls on.
            if self.engine.is_receiving() || self.engine.is_transmitting() || self.engine.tx_pending() {
                self.raise(WUI);
                return Some(WriteOutcome::CommandIgnored {
                    command,
                    reason: "the bus is active",
                });
            }
            // CMR.4 note 1: after reset mode is left, sleep can be set only
            // once bus-free has been seen again (also after a wake-up,
            // which waits for bus-free too); refused like bus activity.
            if self.waiting_for_bus_free() {
                self.raise(WUI);
                return Some(WriteOutcome::CommandIgnored {
                    command,
                    reason: "bus-free not yet seen",
                });
            }
            self.sleeping = true;
            self.engine.set_sleep(true);
            self.log(NodeEvent::Sleep(true));
        } else if !on && self.sleeping {
            // Clearing SM/GTS is a wake-up: WUI, as for bus activity (GTS note).
            self.sleeping = false;
            self.engine.set_sleep(false);
            self.log(NodeEvent::Sleep(false));
            self.raise(WUI);
        }
        None
    }

    /// Reset mode entered by software or by bus-off: reset values from the map.
    fn enter_reset_mode(&mut self) {
        self.rm = true;
        if self.sleeping {
            self.sleeping = false;
            self.engine.set_sleep(false);
        }
        self.engine.set_reset_mode(true);
        // Transmission requests die with reset mode.
        self.pending_tx = None;
        let mode = self.mode;
        for r in regmap::registers(mode) {
            self.apply_reset_value(r, r.reset_rm);
        }
        self.tbs = true;
        self.fifo.clear();
        self.ir &= !RI;
        self.log(NodeEvent::ResetMode(true));
    }

    fn leave_reset_mode(&mut self) {
        self.rm = false;
        self.push_engine_config();
        self.engine.set_reset_mode(false);
        self.log(NodeEvent::ResetMode(false));
    }

    fn enabled(&self, flag: u8) -> bool {
        match self.mode {
            Mode::PeliCan => self.ier & flag != 0,
            Mode::BasicCan => {
                let cr = self.cr;
                match flag {
                    RI => cr & basic::cr::RIE != 0,
                    TI => cr & basic::cr::TIE != 0,
                    EI => cr & basic::cr::EIE != 0,
                    DOI => cr & basic::cr::OIE != 0,
                    // BasicCAN has no enable bit for the wake-up interrupt.
                    WUI => true,
                    _ => false,
                }
            }
        }
    }

    #[inline]
    fn raise(&mut self, flag: u8) {
        if self.enabled(flag) {
            self.ir |= flag;
        }
    }

    /// RI is set while the FIFO holds a message and RI is enabled.
    fn update_ri(&mut self) {
        if self.fifo.rmc() > 0 && self.enabled(RI) {
            self.ir |= RI;
        }
    }

    fn release_tx_buffer(&mut self) {
        self.pending_tx = None;
        if !self.tbs {
            self.tbs = true;
            // TI: TBS went from 0 to 1.
            self.raise(TI);
        }
    }

    #[cold]
    fn handle_events(&mut self) {
        // An event handler can call into the engine (bus-off enters reset
        // mode), which can queue more events: loop, bounded.
        for _ in 0..8 {
            let mut evs = std::mem::take(&mut self.scratch);
            evs.extend(self.engine.take_events());
            if evs.is_empty() {
                self.scratch = evs;
                return;
            }
            for ev in evs.drain(..) {
                self.on_event(ev);
            }
            self.scratch = evs;
        }
    }

    fn on_event(&mut self, ev: Event) {
        match ev {
            Event::Received { frame, own } => {
                if self.rm {
                    return;
                }
                let outcome = if !self.accepts(&frame) {
                    if self.mode == Mode::BasicCan && frame.is_extended() {
                        RxOutcome::ExtendedInBasicCan
                    } else {
                        RxOutcome::Filtered
                    }
                } else {
                    let mut buf = [0u8; 13];
                    let n = self.rx_bytes(&frame, &mut buf);
                    if self.fifo.push(&buf[..n]) {
                        self.update_ri();
                        RxOutcome::Stored
                    } else {
                        if !self.dos {
                            self.dos = true;
                            self.raise(DOI);
                        }
                        RxOutcome::Overrun
                    }
                };
                self.log(NodeEvent::Received {
                    frame,
                    own,
                    outcome,
                });
            }
            Event::TxComplete => {
                if let Some(f) = self.pending_tx {
                    self.log(NodeEvent::Sent(f));
                }
                self.tcs = true;
                self.release_tx_buffer();
            }
            Event::TxAborted => self.release_tx_buffer(),
            Event::ArbitrationLost { alc } => {
                self.log(NodeEvent::ArbitrationLost { alc });
                if !self.alc_locked {
                    self.alc = alc;
                    self.alc_locked = true;
                    self.raise(ALI);
                }
            }
            Event::BusError { ecc, .. } => {
                self.log(NodeEvent::BusError { ecc });
                if !self.ecc_locked {
                    self.ecc = ecc;
                    self.ecc_locked = true;
                    self.raise(BEI);
                }
            }
            Event::ErrorWarning(on) => {
                if self.es != on {
                    self.es = on;
                    self.raise(EI);
                }
            }
            Event::FaultState(s) => {
                let prev = self.fault;
                self.fault = s;
                self.log(NodeEvent::FaultState(s));
                match (prev, s) {
                    (FaultState::ErrorActive, FaultState::ErrorPassive)
                    | (FaultState::ErrorPassive, FaultState::ErrorActive) => self.raise(EPI),
                    (_, FaultState::BusOff) if !self.bs => {
                        self.bs = true;
                        self.raise(EI);
                        // Bus-off sets MOD.RM (data sheet §6.4.3).
                        if !self.rm {
                            self.enter_reset_mode();
                        }
                    }
                    (FaultState::BusOff, _) => {
                        self.bs = false;
                        self.raise(EI);
                    }
                    _ => {}
                }
            }
            Event::WakeUp => {
                if self.sleeping {
                    self.sleeping = false;
                    self.engine.set_sleep(false);
                    self.log(NodeEvent::Sleep(false));
                }
                self.raise(WUI);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every register regmap defines has a behaviour here: a new register
    /// in the map fails this test until the model handles it.
    #[test]
    fn every_regmap_register_is_handled() {
        for mode in Mode::ALL {
            for r in regmap::registers(mode) {
                assert_ne!(
                    classify(r),
                    R::Unknown,
                    "{mode} {} has no behaviour",
                    r.name
                );
            }
        }
    }

    /// Constant bits derived from the map: CR.5 reads 1, CR.7 reads 0,
    /// BasicCAN IR.7..5 read 1, MOD.7..5 read 0, CDR.4 reads 0.
    #[test]
    fn constant_bits_from_the_map() {
        assert_eq!(constant_bits(reg_of(Mode::BasicCan, "CR")), (0xA0, 0x20));
        assert_eq!(constant_bits(reg_of(Mode::BasicCan, "IR")), (0xE0, 0xE0));
        assert_eq!(constant_bits(reg_of(Mode::PeliCan, "MOD")), (0xE0, 0x00));
        assert_eq!(constant_bits(reg_of(Mode::PeliCan, "CDR")).0 & 0x10, 0x10);
    }
}
