//! The comparator as it was before its per-clock work was made cheaper
//! (a deque entry per clock for the tx window, the tx histories and the
//! status history), kept for the differential test in `super::tests`.

use std::collections::VecDeque;

use can_proto::Field;
use diagnose::{Divergence, DivergenceKind};

use super::{CompareConfig, DiffKey, IR_ADDR, Latch, Listed, SR_ADDR, Stamp, reg_label};
use crate::types::CanPins;

#[derive(Clone, Copy, Debug)]
struct OldTxSample {
    /// Inside a start-of-frame grace window: not compared.
    excused: bool,
    ref_tx: bool,
    dut_tx: bool,
    sample: bool,
    stamp: Stamp,
}

struct OldPendingRead {
    addr: u8,
    dut: u8,
    model: u8,
    clocks_left: u32,
    stamp: Stamp,
}

/// The comparator's state.
pub struct OldComparator {
    cfg: CompareConfig,
    window: VecDeque<OldTxSample>,
    sr_hist: VecDeque<u8>,
    ir_hist: VecDeque<u8>,
    prev_ref_tx: bool,
    prev_dut_tx: bool,
    prev_idle: bool,
    sof_grace: u32,
    grace_count: u32,
    grace_by_ref: bool,
    ref_off: usize,
    dut_off: usize,
    ref_hist: VecDeque<bool>,
    dut_hist: VecDeque<bool>,
    irq_bad: u32,
    irq_since: Stamp,
    bus_bad: u32,
    bus_since: Stamp,
    pending: Vec<OldPendingRead>,
    divergence: Option<Divergence>,
    found: VecDeque<Divergence>,
    halted: bool,
    last_kind: Option<DivergenceKind>,
    latch_info: Option<Latch>,
    found_latch: VecDeque<Latch>,
    tx_latch_frame: Option<u32>,
    listed: Listed,
    skip_until_bit: u64,
    tx_latched: bool,
    irq_latched: bool,
    bus_latched: bool,
    /// Reads and sample points compared (for the report).
    pub compared_bits: u64,
    /// Register reads compared.
    pub compared_reads: u64,
    /// Reads accepted only thanks to the status tolerance.
    pub tolerated_reads: u64,
    pub repeated: u64,
    pub cascade: u64,
}

impl OldComparator {
    /// A comparator with these tolerances.
    pub fn new(cfg: CompareConfig) -> OldComparator {
        OldComparator {
            cfg,
            window: VecDeque::with_capacity(2 * cfg.tx_edge_tolerance as usize + 2),
            sr_hist: VecDeque::new(),
            ir_hist: VecDeque::new(),
            prev_ref_tx: true,
            prev_dut_tx: true,
            prev_idle: false,
            sof_grace: 0,
            grace_count: 0,
            grace_by_ref: false,
            ref_off: 0,
            dut_off: 0,
            ref_hist: VecDeque::new(),
            dut_hist: VecDeque::new(),
            irq_bad: 0,
            irq_since: Stamp::default(),
            bus_bad: 0,
            bus_since: Stamp::default(),
            pending: Vec::new(),
            divergence: None,
            found: VecDeque::new(),
            halted: false,
            last_kind: None,
            latch_info: None,
            found_latch: VecDeque::new(),
            tx_latch_frame: None,
            listed: Listed::default(),
            skip_until_bit: 0,
            tx_latched: false,
            irq_latched: false,
            bus_latched: false,
            compared_bits: 0,
            compared_reads: 0,
            tolerated_reads: 0,
            repeated: 0,
            cascade: 0,
        }
    }

    /// The tolerances.
    pub fn config(&self) -> &CompareConfig {
        &self.cfg
    }

    /// The first divergence, once found.
    pub fn divergence(&self) -> Option<&Divergence> {
        self.divergence.as_ref()
    }

    /// The next divergence not yet taken (each divergence once, in order).
    pub fn take_divergence(&mut self) -> Option<Divergence> {
        let d = self.found.pop_front();
        if d.is_some() {
            self.latch_info = self.found_latch.pop_front();
        }
        d
    }

    /// True while a divergence halts the comparison (until [`Comparator::resume`]).
    pub fn halted(&self) -> bool {
        self.halted
    }

    /// Compares again after the last divergence was handled.
    ///
    /// `skip_to_bit`: no tx or pin comparison before this bit index (a
    /// waiver's `SkipBits(n)` after a divergence at bit `b` gives `b + n`).
    /// `latch`: the divergence (the one last taken) was not waived (collect
    /// mode): the same difference is not listed again while it lasts, so a
    /// lasting deviation counts once: tx for the rest of its frame (until
    /// tx agrees at a sample point of a later frame; before the first
    /// frame, until it agrees), irq/bus-off until the pins agree, a
    /// register read while the same address reads the same DUT and model
    /// values again (any other value, or an agreeing read, ends it: the
    /// next read is compared afresh). Repeats are counted in `repeated`.
    /// Not latched after a waived one, so a waiver's bounds see every bit
    /// of the deviation.
    pub fn resume(&mut self, skip_to_bit: Option<u64>, latch: bool) {
        self.halted = false;
        if let Some(b) = skip_to_bit {
            self.skip_until_bit = self.skip_until_bit.max(b);
        }
        if latch {
            match self.latch_info {
                Some(Latch::Tx(frame, key)) => {
                    self.tx_latched = true;
                    self.tx_latch_frame = frame;
                    // Only a difference whose field is known is one to recognise again.
                    if matches!(key, DiffKey::Tx { field: Some(_), .. }) {
                        self.listed.add(key);
                    }
                }
                Some(Latch::Irq) => self.irq_latched = true,
                Some(Latch::BusOff) => self.bus_latched = true,
                Some(Latch::Read(key)) => self.listed.add(key),
                Some(Latch::Clkout) | None => {}
            }
        }
        self.irq_bad = 0;
        self.bus_bad = 0;
    }

    fn diverge(
        &mut self,
        kind: DivergenceKind,
        s: Stamp,
        register: Option<String>,
        expected: u32,
        seen: u32,
        context: String,
    ) {
        let d = Divergence {
            kind,
            time_ps: s.t_ps,
            bit: Some(s.bit),
            frame: s.frame,
            field: s.field,
            register,
            expected,
            seen,
            context: format!("{context}; tolerances: {}", self.cfg.describe()),
        };
        if self.divergence.is_none() {
            self.divergence = Some(d.clone());
        }
        self.found.push_back(d);
        self.halted = true;
        self.last_kind = Some(kind);
        let latch = match kind {
            DivergenceKind::Irq => Some(Latch::Irq),
            DivergenceKind::BusOff => Some(Latch::BusOff),
            DivergenceKind::RegisterRead => None,
            _ => Some(Latch::Tx(
                s.frame,
                DiffKey::Tx {
                    field: s.field,
                    model: expected != 0,
                    dut: seen != 0,
                },
            )),
        };
        if let Some(l) = latch {
            self.found_latch.push_back(l);
            self.latch_info = Some(l);
        }
    }

    /// A register read divergence (latched by its address and values).
    fn diverge_read(&mut self, s: Stamp, addr: u8, dut: u8, model: u8, label: String, context: String) {
        self.diverge(DivergenceKind::RegisterRead, s, Some(label), model as u32, dut as u32, context);
        let l = Latch::Read(DiffKey::Read { addr, dut, model });
        self.found_latch.push_back(l);
        self.latch_info = Some(l);
    }

    /// Was this read difference listed already (a repeat, counted, not listed)?
    fn read_repeats(&mut self, addr: u8, dut: u8, model: u8) -> bool {
        let r = self.listed.repeat(DiffKey::Read { addr, dut, model });
        self.repeated += r as u64;
        r
    }


    /// One CAN clock, after both sides were clocked: `sample` says whether
    /// it is a sample point; `sr`/`ir` are the reference's peeks.
    #[inline]
    pub fn can_clock(
        &mut self,
        stamp: Stamp,
        sample: bool,
        reference: &CanPins,
        dut: &CanPins,
        sr: u8,
        ir: u8,
    ) {
        if self.halted {
            return;
        }
        let skipping = stamp.bit < self.skip_until_bit;
        // tx with an edge-tolerance window centred on the checked clock.
        let tol = self.cfg.tx_edge_tolerance as usize;
        // Start of frame from bus idle: either side may go first, and the
        // shadow model never hard-synchronises on the DUT's SOF (it is not
        // on the bus), so the lag measured at the SOF is kept for the whole
        // frame: the earlier side's tx is delayed by it before comparing.
        let idle_now = matches!(
            stamp.field,
            Some(Field::BusIdle | Field::Intermission | Field::SuspendTransmission)
        );
        let cap = self.cfg.sof_tolerance as usize + 1;
        self.ref_hist.push_back(reference.tx);
        self.dut_hist.push_back(dut.tx);
        if self.ref_hist.len() > cap {
            self.ref_hist.pop_front();
            self.dut_hist.pop_front();
        }
        if self.sof_grace > 0 {
            self.grace_count += 1;
            if reference.tx == dut.tx {
                self.sof_grace = 0;
                if !reference.tx {
                    if self.grace_by_ref {
                        self.ref_off = self.grace_count as usize;
                    } else {
                        self.dut_off = self.grace_count as usize;
                    }
                }
            } else {
                self.sof_grace -= 1;
            }
        } else {
            let sof_edge = (self.prev_ref_tx && !reference.tx) || (self.prev_dut_tx && !dut.tx);
            if sof_edge
                && (self.prev_idle || stamp.field == Some(Field::Sof))
                && reference.tx != dut.tx
                && self.cfg.sof_tolerance > 0
            {
                self.sof_grace = self.cfg.sof_tolerance;
                self.grace_count = 0;
                self.grace_by_ref = !reference.tx;
                self.ref_off = 0;
                self.dut_off = 0;
            } else if idle_now && reference.tx && dut.tx {
                self.ref_off = 0;
                self.dut_off = 0;
            }
        }
        let excused = self.sof_grace > 0;
        self.prev_ref_tx = reference.tx;
        self.prev_dut_tx = dut.tx;
        self.prev_idle = idle_now;
        let n = self.ref_hist.len();
        let ref_tx = self.ref_hist[n - 1 - self.ref_off.min(n - 1)];
        let dut_tx = self.dut_hist[n - 1 - self.dut_off.min(n - 1)];
        self.window.push_back(OldTxSample {
            excused,
            ref_tx,
            dut_tx,
            sample,
            stamp,
        });
        if self.window.len() > 2 * tol + 1 {
            self.window.pop_front();
        }
        if self.window.len() == 2 * tol + 1 {
            let mid = self.window[tol];
            if mid.sample && !mid.excused && mid.stamp.bit >= self.skip_until_bit {
                let stable = self.window.iter().all(|w| w.ref_tx == mid.ref_tx);
                if stable {
                    self.compared_bits += 1;
                    if self.tx_latched
                        && mid.dut_tx == mid.ref_tx
                        && (self.tx_latch_frame.is_none() || mid.stamp.frame != self.tx_latch_frame)
                    {
                        self.tx_latched = false;
                    }
                    let key = DiffKey::Tx {
                        field: mid.stamp.field,
                        model: mid.ref_tx,
                        dut: mid.dut_tx,
                    };
                    if mid.dut_tx != mid.ref_tx && self.tx_latched {
                        self.cascade += 1;
                    } else if mid.dut_tx != mid.ref_tx && self.listed.repeat(key) {
                        // Listed before, in an earlier frame: latch this frame too.
                        self.repeated += 1;
                        self.tx_latched = true;
                        self.tx_latch_frame = mid.stamp.frame;
                    } else if mid.dut_tx != mid.ref_tx {
                        let lvl = |b: bool| if b { "recessive" } else { "dominant" };
                        self.diverge(
                            DivergenceKind::TxBit,
                            mid.stamp,
                            None,
                            mid.ref_tx as u32,
                            mid.dut_tx as u32,
                            format!(
                                "at the sample point the model drives {} and the DUT's tx_o is {}",
                                lvl(mid.ref_tx),
                                lvl(mid.dut_tx)
                            ),
                        );
                    }
                }
            }
        }
        // Status history for tolerant reads.
        let depth = self.cfg.status_tolerance as usize + 1;
        self.sr_hist.push_back(sr);
        self.ir_hist.push_back(ir);
        if self.sr_hist.len() > depth {
            self.sr_hist.pop_front();
            self.ir_hist.pop_front();
        }
        // Pending SR reads: look forward.
        let mut k = 0;
        while k < self.pending.len() {
            let p = &mut self.pending[k];
            if p.addr == SR_ADDR && sr == p.dut {
                self.tolerated_reads += 1;
                self.pending.swap_remove(k);
                continue;
            }
            if p.clocks_left == 0 {
                let p = self.pending.swap_remove(k);
                if !self.read_repeats(p.addr, p.dut, p.model) {
                    self.diverge_read(
                        p.stamp,
                        p.addr,
                        p.dut,
                        p.model,
                        reg_label(p.addr),
                        format!(
                            "read of address {} returned 0x{:02X}, the model 0x{:02X}",
                            p.addr, p.dut, p.model
                        ),
                    );
                }
                continue;
            }
            p.clocks_left -= 1;
            k += 1;
        }
        // Pins: a mismatch may last pin_tolerance clocks.
        if self.irq_latched && reference.irq_n == dut.irq_n {
            self.irq_latched = false;
        }
        if self.bus_latched && reference.bus_on == dut.bus_on {
            self.bus_latched = false;
        }
        if self.cfg.compare_irq && !skipping && !self.irq_latched {
            if reference.irq_n != dut.irq_n {
                if self.irq_bad == 0 {
                    self.irq_since = stamp;
                }
                self.irq_bad += 1;
                if self.irq_bad > self.cfg.pin_tolerance {
                    let s = self.irq_since;
                    self.diverge(
                        DivergenceKind::Irq,
                        s,
                        None,
                        reference.irq_n as u32,
                        dut.irq_n as u32,
                        format!(
                            "irq_on (active low) differs for more than {} CAN clocks",
                            self.cfg.pin_tolerance
                        ),
                    );
                }
            } else {
                self.irq_bad = 0;
            }
        }
        if self.cfg.compare_bus_off && !skipping && !self.bus_latched {
            if reference.bus_on != dut.bus_on {
                if self.bus_bad == 0 {
                    self.bus_since = stamp;
                }
                self.bus_bad += 1;
                if self.bus_bad > self.cfg.pin_tolerance {
                    let s = self.bus_since;
                    self.diverge(
                        DivergenceKind::BusOff,
                        s,
                        None,
                        reference.bus_on as u32,
                        dut.bus_on as u32,
                        format!(
                            "bus_off_on (high = on the bus) differs for more than {} CAN clocks",
                            self.cfg.pin_tolerance
                        ),
                    );
                }
            } else {
                self.bus_bad = 0;
            }
        }
    }

    /// A register read completed on both sides: `dut` from the DUT, `model`
    /// from the reference at the same edge.
    pub fn read(&mut self, stamp: Stamp, addr: u8, dut: u8, model: u8, name: Option<String>) {
        if self.halted {
            return;
        }
        self.compared_reads += 1;
        if dut == model {
            return;
        }
        let hist = match addr {
            SR_ADDR => Some(&self.sr_hist),
            IR_ADDR => Some(&self.ir_hist),
            _ => None,
        };
        if let Some(h) = hist {
            if h.iter().any(|v| *v == dut) {
                self.tolerated_reads += 1;
                return;
            }
            if addr == SR_ADDR && self.cfg.status_tolerance > 0 {
                self.pending.push(OldPendingRead {
                    addr,
                    dut,
                    model,
                    clocks_left: self.cfg.status_tolerance,
                    stamp,
                });
                return;
            }
        }
        if self.read_repeats(addr, dut, model) {
            return;
        }
        let label = name.unwrap_or_else(|| reg_label(addr));
        let context = format!(
            "read of {label} (address {addr}) returned 0x{dut:02X}, the model 0x{model:02X}"
        );
        self.diverge_read(stamp, addr, dut, model, label, context);
    }

    /// Reads still waiting for their tolerance window to close.
    pub fn pending_reads(&self) -> usize {
        self.pending.len()
    }
}
