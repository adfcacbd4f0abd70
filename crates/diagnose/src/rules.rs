//! The rules, one small function each. A rule returns `None` when the record
//! holds no evidence for its cause. [`all`] runs them in priority order.

use crate::record::*;
use crate::{Category, Figures, Finding};
use can_engine::ErrorKind;
use can_proto::Field;
use can_proto::timing::BusTiming;

/// Rules about the program's register accesses as the model named and
/// judged them (register view, ignored writes).
const PROGRAM_RULES: [fn(&RunRecord) -> Option<Finding>; 3] =
    [address_mode_confusion, config_write_outside_reset, tx_buffer_write_while_locked];

/// Every finding, in priority order (the first is the diagnosis).
///
/// The first divergence leads: a program error (wrong register view,
/// ignored write) only comes before it if the access came before it; the
/// same rules on later accesses, which the model named and judged after it
/// had derailed from the DUT, come after every other finding, marked as
/// later symptoms in the model's view.
pub fn all(r: &RunRecord) -> Vec<Finding> {
    let Some(d) = &r.divergence else {
        return in_order(r);
    };
    let before = RunRecord {
        host_ops: r.host_ops.iter().filter(|o| o.time_ps < d.time_ps).cloned().collect(),
        ..r.clone()
    };
    let mut v = in_order(&before);
    // `before` differs from `r` only in the host ops: the other rules give
    // the same findings on both.
    for rule in PROGRAM_RULES {
        let (Some(mut later), early) = (rule(r), rule(&before)) else { continue };
        if early.is_some() {
            continue;
        }
        later.what_happened = format!(
            "after the first divergence ({} at {} ps{}), in the model's view of the registers, which may no longer be the DUT's: {}",
            kind_name(d.kind),
            d.time_ps,
            d.bit.map(|b| format!(", bit {b}")).unwrap_or_default(),
            later.what_happened
        );
        later.root_cause = format!("a later symptom, not the cause: {}", later.root_cause);
        v.push(later);
    }
    v
}

fn kind_name(k: DivergenceKind) -> &'static str {
    match k {
        DivergenceKind::TxBit => "tx bit",
        DivergenceKind::RegisterRead => "register read",
        DivergenceKind::Irq => "irq_on",
        DivergenceKind::BusOff => "bus_off_on",
        DivergenceKind::Clkout => "clkout_o",
    }
}

/// The rules in priority order on `r`.
fn in_order(r: &RunRecord) -> Vec<Finding> {
    // A divergence that happens before the model itself sees any bus error
    // cannot be explained by the wiring (the model shares it): HDL bug first.
    let early_divergence = r.divergence.as_ref().is_some_and(|d| {
        match (d.bit, r.first_bus_error(Side::Model)) {
            (Some(b), Some((e, _, _))) => b < e.bit,
            (_, None) => true,
            (None, Some(_)) => d.kind == DivergenceKind::RegisterRead,
        }
    });
    let mut rules: Vec<fn(&RunRecord) -> Option<Finding>> = vec![host_bus_timeout, host_bus_violation, run_error];
    rules.extend(PROGRAM_RULES);
    if early_divergence {
        rules.push(dut_deviates);
    }
    rules.extend([rx_not_following_tx, no_acknowledge, bit_timing_mismatch] as [fn(&RunRecord) -> Option<Finding>; 3]);
    if !early_divergence {
        rules.push(dut_deviates);
    }
    rules.extend([expectation_failed, stuck_transfer, repeated_access_note, pio_handshake_note] as [fn(&RunRecord) -> Option<Finding>; 4]);
    rules.iter().filter_map(|f| f(r)).collect()
}

/// The DUT's TEC trace when the record has one; else the model's up to
/// the first divergence (in lockstep the two agree up to there; after it
/// the model's counts say nothing about the DUT), and `true`: the model's.
pub fn tec_trace_for_dut(r: &RunRecord) -> (Vec<TecStep>, bool) {
    let d = r.tec_of(Side::Dut);
    if !d.is_empty() {
        return (d, false);
    }
    let mut m = r.tec_of(Side::Model);
    if let Some(b) = r.divergence.as_ref().and_then(|d| d.bit) {
        m.retain(|t| t.bit < b);
    }
    let from_model = !m.is_empty();
    (m, from_model)
}

/// Figures every finding starts from: final DUT status and the TEC trace.
pub fn base_figures(r: &RunRecord) -> Figures {
    // The DUT's own counters when known, else the model's before the first
    // divergence, marked as the model's.
    let (dut, from_model) = tec_trace_for_dut(r);
    let mut f = Figures { counts_from_model: from_model, ..Figures::default() };
    if let Some(fr) = r.final_dut {
        // Counters the record took from the model are marked as the
        // model's, and say nothing about the DUT after a divergence.
        if !fr.counters_from_model || r.divergence.is_none() {
            f.tec = Some(fr.tec);
            f.rec = Some(fr.rec);
            f.tec_from_model = fr.counters_from_model;
        }
        f.sr = Some(fr.sr);
    } else if let Some(s) = r.stuck {
        f.sr = Some(s.sr);
    }
    if let Some(first) = dut.first() {
        f.first_attempt_tec = Some(first.tec);
    }
    if !dut.is_empty() {
        f.attempts = Some(dut.len() as u32);
        if f.tec.is_none() {
            f.tec = dut.last().map(|t| t.tec);
            f.tec_from_model = from_model;
        }
    } else if let Some(s) = r.stuck {
        f.attempts = Some(s.attempts);
    }
    f.bus_off_attempt = dut.iter().find(|t| t.bus_off || t.tec > 255).map(|t| t.attempt);
    f
}

fn level(b: bool) -> String {
    if b { "recessive (1)".into() } else { "dominant (0)".into() }
}

fn finding(category: Category, what: String, cause: &str, fix: &str, figures: Figures) -> Finding {
    Finding { category, what_happened: what, root_cause: cause.into(), fix: fix.into(), figures, advisory: false }
}

/// A sentence about attempts, TEC and bus-off from the figures.
fn attempts_sentence(f: &Figures) -> String {
    let mut s = String::new();
    // Counts from the model's trace are said to be the model's.
    let who = if f.counts_from_model { "The model (in lockstep with the DUT up to then)" } else { "The controller" };
    if let Some(t) = f.first_attempt_tec {
        s += &format!(" {}TEC was {t} after the first attempt.", if f.counts_from_model { "The model's " } else { "" });
    }
    if let Some(a) = f.attempts {
        s += &format!(" {who} made {a} attempt(s).");
    }
    if let Some(b) = f.bus_off_attempt {
        s += &format!(" {who} went bus-off (TEC > 255) during attempt {b}, dropped the request and keeps tx_o recessive: a logic analyser sees only 1s.");
    } else if let Some(t) = f.tec {
        s += &format!(" {}TEC is {t}.", if f.tec_from_model { "The model's " } else { "" });
    }
    if let Some(sr) = f.sr {
        s += &format!(" SR = {}.", sr::describe(sr));
    }
    s
}

/// The run stopped on an error of its own (DUT build, simulator, timeout).
pub fn run_error(r: &RunRecord) -> Option<Finding> {
    let e = r.error.as_ref()?;
    Some(finding(
        Category::RunError,
        format!("the run stopped: {e}"),
        "the test bench could not complete the run; no CAN conclusion can be drawn",
        "fix the reported error (DUT sources, ports, simulator) and run again",
        base_figures(r),
    ))
}

/// A host access that was never acknowledged.
pub fn host_bus_timeout(r: &RunRecord) -> Option<Finding> {
    let op = r.host_ops.iter().find(|o| o.error.is_some())?;
    // The missed-pulse explanation holds only if the DUT did answer.
    let pio = op.bfm == HostBus::Pio && op.acks_seen > 0;
    let mut f = base_figures(r);
    f.addr = Some(op.addr);
    f.register = op.reg.clone();
    Some(finding(
        Category::HostBusTimeout,
        format!(
            "the {:?} {:?} at address {} ({}) never completed: {} (after {} host cycles)",
            op.bfm,
            op.access,
            op.addr,
            op.reg.as_deref().unwrap_or("?"),
            op.error.as_deref().unwrap_or(""),
            op.cycles
        ),
        if pio {
            "the master polls wb_ack_o through a GPIO (PIO) and drops cyc/stb only after it has seen ack: a slave that answers with a one-cycle wb_ack_o pulse is missed between two polls, and while the strobe stays high the slave may start (and the master abandon) a second transfer"
        } else {
            "the DUT never raised wb_ack_o for this access: it is not clocked (wb_clk_i), held in reset (wb_rst_i), or cyc/stb do not reach it together"
        },
        if pio {
            "give a PIO-polled slave a level acknowledge (four-phase handshake: ack stays high until cyc/stb fall; our RTL's ACK_LEVEL = 1), or connect the core through the Avalon wrapper instead of PIO"
        } else {
            "check wb_clk_i and wb_rst_i, and that wb_cyc_i and wb_stb_i are both high for the whole access; with Avalon, use the bundled wrapper so waitrequest follows ack"
        },
        f,
    ))
}

/// Wishbone monitor findings that PIO bit-banging causes on every access:
/// the program leaves cyc/stb high long after ack (it polls ack through a
/// GPIO), so a Wishbone slave sees a second transfer that the program then
/// abandons.
fn pio_handshake(r: &RunRecord, v: &Violation) -> bool {
    r.host_bus == HostBus::Pio && (v.rule.ends_with("cyc_dropped_before_ack") || v.rule.ends_with("ack_without_request"))
}

/// Accesses the core performed more than once because the master held its
/// request past the ack (advisory: the reference performed them as often,
/// so they explain differences from the scenario, not from the model).
pub fn repeated_access_note(r: &RunRecord) -> Option<Finding> {
    let ops: Vec<&HostOp> = r.host_ops.iter().filter(|o| o.repeats > 0).collect();
    let first = *ops.first()?;
    let side = ops.iter().filter(|o| o.addr == 1 && o.access == Access::Write || o.addr == 3 && o.access == Access::Read).count();
    let mut f = finding(
        Category::HostBusViolation,
        format!(
            "the core performed {} host access(es) more than once ({} extra in all, {side} of them a CMR write or IR read), the first a {:?} of address {} ({}) at {} ps: the {:?} master held cyc/stb past the core's ack",
            ops.len(),
            ops.iter().map(|o| o.repeats).sum::<u32>(),
            first.access,
            first.addr,
            first.reg.as_deref().unwrap_or("?"),
            first.time_ps,
            first.bfm
        ),
        "a Wishbone slave takes stb still high after its ack as the next transfer; a master that polls a one-cycle ack through a GPIO misses it and keeps the strobe up, so the core repeats the access: a repeated CMR (release receive buffer, abort, transmit, clear overrun) or IR read repeats its side effect, e.g. one release frees two messages",
        "drop cyc/stb within the core's hold-off after its ack (a level acknowledge, or the Avalon wrapper); the golden model repeated the accesses too, so scenario expectations that fail here fail for the host program, not the core",
        base_figures(r),
    );
    f.advisory = true;
    Some(f)
}

/// PIO handshake remarks (advisory: the accesses completed).
pub fn pio_handshake_note(r: &RunRecord) -> Option<Finding> {
    let n = r.violations.iter().filter(|v| pio_handshake(r, v)).count();
    let v = r.violations.iter().find(|v| pio_handshake(r, v))?;
    let mut f = finding(
        Category::HostBusViolation,
        format!(
            "{n} Wishbone handshake remark(s) from PIO bit-banging, first at host cycle {}: {} ({})",
            v.cycle, v.message, v.rule
        ),
        "through PIO the program raises cyc/stb, polls ack through a GPIO and drops cyc/stb later: the slave acks again meanwhile (a second transfer the program abandons)",
        "harmless for plain registers; a repeated read of IR (read-clears) or write of CMR repeats its side effect. The Avalon wrapper avoids it",
        base_figures(r),
    );
    f.advisory = true;
    Some(f)
}

/// Host-bus protocol violations (Wishbone / Avalon / PIO monitors).
pub fn host_bus_violation(r: &RunRecord) -> Option<Finding> {
    let n = r.violations.iter().filter(|v| !pio_handshake(r, v)).count();
    let v = r.violations.iter().find(|v| !pio_handshake(r, v))?;
    let rule = v.rule.to_ascii_lowercase();
    let (cause, fix) = if rule.contains("begintransfer") || rule.contains("cyc") && rule.contains("stb") && r.host_bus == HostBus::Avalon {
        (
            "wb_cyc_i is driven from Avalon begintransfer, a one-cycle pulse at the start of each transfer, so the core sees stb without cyc for the rest of the access; and wb_ack_o is exported on a conduit, so the Avalon fabric never learns when the slave answered (no waitrequest): reads return whatever readdata holds, writes may be lost",
            "map chipselect to both wb_cyc_i and wb_stb_i, and drive waitrequest = chipselect & ~wb_ack_o (the bundled Avalon wrapper does this); do not export ack on a conduit",
        )
    } else if rule.contains("stb") && rule.contains("cyc") {
        (
            "Wishbone requires cyc to be high whenever stb is: the core ignores a strobe outside a cycle",
            "drive wb_cyc_i and wb_stb_i together for the whole access and release them after wb_ack_o",
        )
    } else if rule.contains("ack") {
        (
            "the master did not wait for the slave's acknowledge (or changed the request before it)",
            "hold address, data and we stable until wb_ack_o is seen, then drop cyc/stb",
        )
    } else {
        (
            "the host bus does not follow its protocol, so register accesses cannot be trusted",
            "fix the host interface so the monitor reports no violation",
        )
    };
    let mut f = base_figures(r);
    f.seen = Some(v.rule.clone());
    Some(finding(
        Category::HostBusViolation,
        format!(
            "{} host-bus violation(s); the first at host cycle {}: {} ({})",
            n,
            v.cycle,
            v.message,
            v.rule
        ),
        cause,
        fix,
        f,
    ))
}

/// The PeliCAN-only register names, for telling the modes apart.
const PELICAN_ONLY: &[&str] = &[
    "IER", "ALC", "ECC", "EWLR", "RXERR", "TXERR", "TXFI", "RXFI", "TX_FRAME_INFO", "RX_FRAME_INFO", "ACR0", "ACR1", "ACR2",
    "ACR3", "AMR0", "AMR1", "AMR2", "AMR3", "RMC", "RBSA",
];

/// The program used a register of the other mode (e.g. IER at address 4 in
/// BasicCAN, where address 4 is ACR).
pub fn address_mode_confusion(r: &RunRecord) -> Option<Finding> {
    let op = r.host_ops.iter().find(|o| match (&o.intended, &o.reg) {
        (Some(i), Some(g)) => !i.eq_ignore_ascii_case(g),
        (Some(i), None) => o.mode == CanMode::BasicCan && PELICAN_ONLY.iter().any(|p| p.eq_ignore_ascii_case(i)),
        _ => false,
    })?;
    let intended = op.intended.clone().unwrap_or_default();
    let got = op.reg.clone().unwrap_or_else(|| "an unrelated register".into());
    let mut f = base_figures(r);
    f.addr = Some(op.addr);
    f.register = Some(got.clone());
    f.expected = Some(intended.clone());
    f.seen = Some(got.clone());
    let mode = match op.mode {
        CanMode::BasicCan => "BasicCAN",
        CanMode::PeliCan => "PeliCAN",
    };
    let ignored = match &op.outcome {
        Some(o) if o.is_ignored() => format!(" The model ignored the access ({o:?})."),
        _ => String::new(),
    };
    Some(finding(
        Category::AddressModeConfusion,
        format!(
            "the program {} {intended} at address {} (0x{:02X}) in {mode} mode{}, where that address is {got}.{ignored}",
            if op.access == Access::Write { format!("wrote 0x{:02X} to", op.data) } else { "read".into() },
            op.addr,
            op.addr,
            if op.reset_mode { " (reset mode)" } else { "" },
        ),
        "the SJA1000 has two register maps: BasicCAN (CDR.7 = 0, the default) and PeliCAN (CDR.7 = 1); addresses from one are used in the other. In BasicCAN the interrupt enables are bits of CR (address 0) and address 4 is ACR; in PeliCAN address 4 is IER and 16 is TX frame info on write, RX frame info on read in operating mode but ACR0 in reset mode",
        "take the address from the register map of the mode the controller is in (set CDR.7 first, in reset mode, before using PeliCAN addresses); use the generated *_regs.h names rather than hand-typed numbers",
        f,
    ))
}

const CONFIG_REGS: &[&str] = &[
    "BTR0", "BTR1", "ACR", "AMR", "OCR", "ACR0", "ACR1", "ACR2", "ACR3", "AMR0", "AMR1", "AMR2", "AMR3", "EWLR", "RXERR",
    "TXERR",
];

/// Configuration registers written in operating mode: the SJA1000 ignores them.
pub fn config_write_outside_reset(r: &RunRecord) -> Option<Finding> {
    let bad: Vec<&HostOp> = r
        .host_ops
        .iter()
        .filter(|o| o.access == Access::Write)
        .filter(|o| match &o.outcome {
            Some(WriteOutcome::IgnoredNotInResetMode) => true,
            Some(_) => false,
            None => !o.reset_mode && o.reg.as_deref().is_some_and(|n| CONFIG_REGS.contains(&n)),
        })
        .collect();
    let op = *bad.first()?;
    let names: Vec<String> = bad
        .iter()
        .map(|o| format!("{}=0x{:02X}", o.reg.clone().unwrap_or_else(|| format!("@{}", o.addr)), o.data))
        .collect();
    let mut f = base_figures(r);
    f.addr = Some(op.addr);
    f.register = op.reg.clone();
    f.expected = Some(format!("0x{:02X}", op.data));
    Some(finding(
        Category::ConfigWriteOutsideReset,
        format!("{} configuration write(s) were ignored because the controller was in operating mode: {}", bad.len(), names.join(", ")),
        "ACR/AMR, BTR0/BTR1, OCR (and in PeliCAN EWLR, RXERR, TXERR) are writable in reset mode only (MOD.RM / CR.RR = 1); in operating mode the SJA1000 silently keeps the old values",
        "write MOD/CR = 0x01 (reset request) and read it back until bit 0 is 1, write the configuration, then leave reset mode",
        f,
    ))
}

/// TX buffer written while a transmission is pending.
pub fn tx_buffer_write_while_locked(r: &RunRecord) -> Option<Finding> {
    let bad: Vec<&HostOp> =
        r.host_ops.iter().filter(|o| matches!(o.outcome, Some(WriteOutcome::IgnoredTxBufferLocked))).collect();
    let op = *bad.first()?;
    let mut f = base_figures(r);
    f.addr = Some(op.addr);
    f.register = op.reg.clone();
    f.expected = Some(format!("0x{:02X}", op.data));
    Some(finding(
        Category::TxBufferWriteWhileLocked,
        format!(
            "{} write(s) to the TX buffer were ignored because it was locked (SR.TBS = 0, a transmission pending); the first at address {} (0x{:02X})",
            bad.len(),
            op.addr,
            op.data
        ),
        "while a transmission request is pending the TX buffer is locked (SR.TBS = 0) and the SJA1000 ignores writes to it; the frame on the wire is the old one",
        "poll SR until TBS = 1 (or wait for the transmit interrupt) before filling the TX buffer; abort with CMR.AT if the old frame must be replaced",
        f,
    ))
}

/// rx_i does not follow tx_o: the first dominant bit (SOF) reads back recessive.
pub fn rx_not_following_tx(r: &RunRecord) -> Option<Finding> {
    let bits_evidence = r.bus_bits.iter().find(|b| b.dut_tx == can_proto::DOMINANT && b.dut_rx == can_proto::RECESSIVE);
    let wiring_says = !r.wiring.rx_follows_tx();
    let tx_tried = r.first_bus_error(Side::Dut).is_some()
        || r.first_bus_error(Side::Model).is_some()
        || r.stuck.is_some()
        || !r.tec_trace.is_empty();
    if !(wiring_says && tx_tried || bits_evidence.is_some() && !r.wiring.rx_follows_tx()) {
        return None;
    }
    if r.wiring.rx == RxWiring::TiedDominant {
        let mut f = base_figures(r);
        f.expected = Some(level(true));
        f.seen = Some(level(false));
        return Some(finding(
            Category::RxNotFollowingTx,
            "rx_i is tied dominant: the controller sees a permanently busy bus (or a stream of errors) and never starts its frame".into(),
            "rx_i is tied to 0 instead of following the bus through a transceiver",
            "connect rx_i to the transceiver's RXD (idle level recessive = 1)",
            f,
        ));
    }
    let mut f = base_figures(r);
    let err = r.first_bus_error(Side::Dut).or_else(|| r.first_bus_error(Side::Model));
    if let Some((e, _, field)) = err {
        f.bit = Some(e.bit);
        f.field = Some(field);
    } else if let Some(b) = bits_evidence {
        f.bit = Some(b.bit);
        f.field = b.field;
    } else {
        f.field = Some(Field::Sof);
    }
    f.frame = Some(1);
    f.expected = Some(level(false));
    f.seen = Some(level(true));
    let how = match r.wiring.rx {
        RxWiring::TiedRecessive => "rx_i is tied to 1 (recessive)",
        _ => "tx_o does not reach the bus that rx_i reads (no transceiver loopback)",
    };
    let field = f.field.unwrap_or(Field::Sof);
    let (trace, from_model) = tec_trace_for_dut(r);
    let trace: Vec<u16> = trace.iter().map(|t| t.tec).collect();
    let counts = explain_tied_counts(&trace)
        .map(|e| if from_model { format!(" The model's counts: {e}") } else { format!(" {e}") })
        .unwrap_or_default();
    let what = format!(
        "frame 1: the DUT sent {} in the {field} at bit {} and read {} back on rx_i: bit error (CAN 2.0B §7.1, bit monitoring). Its active error flag (six dominant bits) reads back recessive too, so every flag bit is another bit error (+8 each).{}{counts}",
        level(false),
        f.bit.map(|b| b.to_string()).unwrap_or_else(|| "?".into()),
        level(true),
        attempts_sentence(&f)
    );
    Some(finding(
        Category::RxNotFollowingTx,
        what,
        &format!(
            "{how}. A CAN transmitter reads back every bit it sends; on a real bus the transceiver loops tx to rx through the wire. With rx held recessive the first dominant bit (SOF) fails, the frame never gets past SOF, the controller retries until bus-off. The controller reported the request as accepted (SR.TBS = 0, SR.TS = 1 while retrying), which is why the program printed that the frame was sent. The core is not broken: the wiring is."
        ),
        "connect tx_o and rx_i to a CAN transceiver on a bus with at least one other powered node at the same bit rate (it acknowledges); for a bench test without a second node, loop tx_o to rx_i and use PeliCAN self-test mode (CDR = 0x80, MOD = 0x04 with STM, then CMR = 0x10 self reception request)",
        f,
    ))
}

/// rx follows tx but nobody acknowledges and the DUT is not in self-test mode.
pub fn no_acknowledge(r: &RunRecord) -> Option<Finding> {
    if !r.wiring.rx_follows_tx() || r.wiring.self_test || r.wiring.ack_nodes() > 0 {
        return None;
    }
    let ack = r.events_of(Side::Dut).chain(r.events_of(Side::Model)).find(|e| {
        matches!(e.kind, crate::EventKind::BusError { kind: ErrorKind::Ack, .. })
    });
    if ack.is_none() && r.stuck.is_none() {
        return None;
    }
    let mut f = base_figures(r);
    if let Some(e) = ack {
        f.bit = Some(e.bit);
    }
    f.field = Some(Field::AckSlot);
    f.frame = Some(1);
    f.expected = Some(level(false));
    f.seen = Some(level(true));
    let plateau = r.tec_of(Side::Dut).iter().map(|t| t.tec).max().or(f.tec);
    // Said to be the model's when it is.
    let pw = if r.tec_of(Side::Dut).is_empty() && f.tec_from_model { "the model's " } else { "" };
    if let Some(p) = plateau {
        f.tec = Some(p);
    }
    let sr_txt = f.sr.map(sr::describe).unwrap_or_else(|| "?".into());
    // SR.TBS = 1 with SR.TS = 0 at the end: the request did not live on, an
    // abort (CMR.AT) or single shot ended it; say so instead of "forever".
    let released = f.sr.is_some_and(|s| s & 0x04 != 0 && s & 0x20 == 0);
    let aborted = r.host_ops.iter().any(|o| {
        o.access == Access::Write && o.addr == 1 && o.data & 0x02 != 0 && o.error.is_none()
    });
    let outcome = if released {
        format!(
            "{pw}TEC reached {} and the retransmissions ended when {}: SR = {sr_txt}, i.e. TBS = 1 (buffer released) and TS = 0; the frame was never sent",
            plateau.map(|p| p.to_string()).unwrap_or_else(|| "?".into()),
            if aborted { "the host aborted the request (CMR.AT)" } else { "the request was dropped (single shot, CMR.AT with TR)" }
        )
    } else {
        format!(
            "From then on {pw}TEC stays at {} and the controller retransmits forever: SR = {sr_txt}, i.e. TBS = 0 (buffer locked, 'full') and TS = 1 (transmission in progress)",
            plateau.map(|p| p.to_string()).unwrap_or_else(|| "128".into())
        )
    };
    Some(finding(
        Category::NoAcknowledge,
        format!(
            "every attempt reached the ACK slot, which stayed {} because no other node acknowledges: ACK error (CAN 2.0B §7.1), TEC +8 per attempt up to 128 (error passive). {outcome}.{}",
            level(true),
            f.attempts.map(|a| format!(" {a} attempts seen.")).unwrap_or_default()
        ),
        "a CAN frame is only complete when another node writes a dominant bit in the ACK slot; alone on the bus (and not in self-test mode) the transmitter never succeeds. CAN 2.0B §8 rule 3, exception 1: an error-passive transmitter that sees an ACK error and no dominant bit during its passive error flag does not increment TEC, so it neither succeeds nor goes bus-off",
        "add a second node at the same bit rate that is in operating mode and not listen-only (it acknowledges), or for a lone bench test use PeliCAN self-test mode (MOD.STM = 1, CMR = 0x10 self reception request)",
        f,
    ))
}

/// Finds BTR values for `clk` giving `rate` with the sample point closest to `sp`.
pub fn suggest_btr(clk: f64, rate: f64, sp: f64) -> Option<(u8, u8)> {
    let mut best: Option<(f64, (u8, u8))> = None;
    for brp in 0u8..64 {
        for tseg1 in 1u8..16 {
            for tseg2 in 1u8..8 {
                let t = BusTiming { brp, sjw: 0, tseg1, tseg2, sam: false };
                if ((t.bit_rate(clk) - rate) / rate).abs() > 1e-9 {
                    continue;
                }
                let d = (t.sample_point() - sp).abs();
                if best.is_none_or(|(bd, _)| d < bd) {
                    let sjw = tseg2.min(3);
                    best = Some((d, BusTiming { sjw, ..t }.to_btr()));
                }
            }
        }
    }
    best.map(|(_, b)| b)
}

/// Nodes on the bus do not share a bit rate (or sample points differ widely).
pub fn bit_timing_mismatch(r: &RunRecord) -> Option<Finding> {
    let me = r.timing;
    let (rate, sp) = (me.bit_rate(), me.sample_point());
    // A node with its own oscillator (a clock tolerance test) is no mismatch
    // while both timings absorb the difference (CAN 2.0B section 10).
    let node = r.wiring.nodes.iter().find(|n| {
        let (nr, ns) = (n.timing.bit_rate(), n.timing.sample_point());
        let same_btr = (n.timing.btr0, n.timing.btr1) == (me.btr0, me.btr1);
        let allowed = if same_btr { me.bus_timing().oscillator_tolerance() + n.timing.bus_timing().oscillator_tolerance() } else { 0.0 };
        ((nr - rate) / rate).abs() > allowed.max(0.005) || (ns - sp).abs() > 0.15
    })?;
    let (nr, ns) = (node.timing.bit_rate(), node.timing.sample_point());
    let mut f = base_figures(r);
    f.expected = Some(format!("{:.0} bit/s, sample point {:.1} %", nr, ns * 100.0));
    f.seen = Some(format!("{:.0} bit/s, sample point {:.1} %", rate, sp * 100.0));
    if let Some((e, _, field)) = r.first_bus_error(Side::Dut) {
        f.bit = Some(e.bit);
        f.field = Some(field);
    }
    let suggestion = suggest_btr(me.can_clock_hz, nr, ns)
        .map(|(b0, b1)| format!(" For the DUT's {:.3} MHz clock, BTR0 = 0x{b0:02X}, BTR1 = 0x{b1:02X} gives {:.0} bit/s.", me.can_clock_hz / 1e6, nr))
        .unwrap_or_else(|| format!(" No BTR setting of the DUT's {:.3} MHz clock gives exactly {:.0} bit/s: change the clock.", me.can_clock_hz / 1e6, nr));
    Some(finding(
        Category::BitTimingMismatch,
        format!(
            "the DUT runs at {:.0} bit/s (BTR0 = 0x{:02X}, BTR1 = 0x{:02X}, {:.3} MHz, sample point {:.1} %) but node '{}' at {:.0} bit/s (BTR0 = 0x{:02X}, BTR1 = 0x{:02X}, {:.3} MHz, sample point {:.1} %)",
            rate, me.btr0, me.btr1, me.can_clock_hz / 1e6, sp * 100.0, node.name, nr, node.timing.btr0, node.timing.btr1,
            node.timing.can_clock_hz / 1e6, ns * 100.0
        ),
        "all nodes of a CAN bus must use the same nominal bit rate (and close sample points): resynchronisation only absorbs a phase error of SJW time quanta per edge, so different rates give stuff, form and CRC errors, and no valid frame",
        &format!("program the same bit rate on every node (bit rate = f_clk / (2 (BRP+1) (3 + TSEG1 + TSEG2))).{suggestion}"),
        f,
    ))
}

/// The DUT deviates from the golden model: an HDL bug, with field context.
pub fn dut_deviates(r: &RunRecord) -> Option<Finding> {
    let d = r.divergence.as_ref()?;
    let mut f = base_figures(r);
    f.bit = d.bit;
    f.field = d.field;
    // In lockstep the model is clocked with the bus before the comparison,
    // so a wrong DUT bit shows as a bit error of the model at that very bit
    // and the recorded field is already the error flag; the ECC segment of
    // that bus error names the field the bit belonged to.
    if d.kind == DivergenceKind::TxBit
        && let Some(bit) = d.bit
        && let Some(field) = r.events_of(Side::Model).find_map(|e| match e.kind {
            EventKind::BusError { ecc, .. } if e.bit == bit || e.bit + 1 == bit => field_from_ecc(ecc),
            _ => None,
        })
    {
        f.field = Some(field);
    }
    let d = &Divergence { field: f.field, ..d.clone() };
    f.frame = d.frame;
    f.register = d.register.clone();
    let what = match d.kind {
        DivergenceKind::TxBit => {
            f.expected = Some(level(d.expected != 0));
            f.seen = Some(level(d.seen != 0));
            format!(
                "tx_o differs from the golden model at bit {} (frame {}, {}): the model sends {}, the DUT {}.",
                d.bit.map(|b| b.to_string()).unwrap_or_else(|| "?".into()),
                d.frame.map(|b| b.to_string()).unwrap_or_else(|| "?".into()),
                d.field.map(|x| x.to_string()).unwrap_or_else(|| "unknown field".into()),
                level(d.expected != 0),
                level(d.seen != 0)
            )
        }
        DivergenceKind::RegisterRead => {
            f.expected = Some(format!("0x{:02X}", d.expected));
            f.seen = Some(format!("0x{:02X}", d.seen));
            let reg = d.register.as_deref().unwrap_or("register");
            let extra = if reg == "SR" { format!(" (model {}, DUT {})", sr::describe(d.expected as u8), sr::describe(d.seen as u8)) } else { String::new() };
            format!("a read of {reg} returned 0x{:02X} where the model has 0x{:02X}{extra}.", d.seen, d.expected)
        }
        DivergenceKind::Irq => {
            f.expected = Some(format!("irq_on = {}", d.expected));
            f.seen = Some(format!("irq_on = {}", d.seen));
            format!("irq_on differs from the model: model {}, DUT {} (active low).", d.expected, d.seen)
        }
        DivergenceKind::BusOff => {
            f.expected = Some(format!("bus_off_on = {}", d.expected));
            f.seen = Some(format!("bus_off_on = {}", d.seen));
            format!("bus_off_on differs from the model: model {}, DUT {}.", d.expected, d.seen)
        }
        DivergenceKind::Clkout => {
            f.expected = Some(format!("clkout_o {}", d.expected));
            f.seen = Some(format!("clkout_o {}", d.seen));
            "clkout_o does not follow the clock divider register (CDR) as the model's does.".into()
        }
    };
    let ctx = if d.context.is_empty() { String::new() } else { format!(" Context: {}", d.context) };
    let where_ = match (d.kind, d.field) {
        (DivergenceKind::TxBit, Some(field)) => format!("the RTL's handling of the {field} (the bit stream processor state for that field)"),
        (DivergenceKind::RegisterRead, _) => format!("the RTL's {} read path or the state bits it reflects", d.register.as_deref().unwrap_or("register")),
        (DivergenceKind::Irq, _) => "the RTL's interrupt logic (IR/IER and irq_on)".into(),
        (DivergenceKind::BusOff, _) => "the RTL's fault confinement (TEC/REC rules, bus-off entry and recovery)".into(),
        (DivergenceKind::Clkout, _) => "the RTL's clock divider (CDR.2..0 divider, CDR.3 clock off, sleep) and clkout_o".into(),
        _ => "the RTL at that time".into(),
    };
    Some(finding(
        Category::DutDeviatesFromModel,
        format!("{what}{ctx}"),
        &format!("the DUT does not behave as the SJA1000 / CAN 2.0B golden model does: look at {where_}"),
        &format!(
            "open the waveform at {} ps{}; compare the RTL with the datasheet behaviour the model implements, fix it and rerun the regression",
            d.time_ps,
            d.bit.map(|b| format!(" (bit {b})")).unwrap_or_default()
        ),
        f,
    ))
}

/// Failed scenario expectations.
pub fn expectation_failed(r: &RunRecord) -> Option<Finding> {
    let failed: Vec<&Expectation> = r.expectations.iter().filter(|e| !e.passed).collect();
    let e = *failed.first()?;
    let mut f = base_figures(r);
    f.expected = Some(e.expected.clone());
    f.seen = Some(e.seen.clone());
    Some(finding(
        Category::ExpectationFailed,
        format!("{} expectation(s) failed; the first, step {}: {} expected {}, seen {}", failed.len(), e.step, e.what, e.expected, e.seen),
        "the DUT and the model agree, but not with what the scenario expects: the scenario's expectation or the program it plays is wrong",
        "check the expected value against the datasheet; if the expectation is right, the program (register values, order) is not",
        f,
    ))
}

/// A transmission that never completed, with no other explanation.
pub fn stuck_transfer(r: &RunRecord) -> Option<Finding> {
    let s = r.stuck?;
    let mut f = base_figures(r);
    f.sr = Some(s.sr);
    Some(finding(
        Category::StuckTransfer,
        format!(
            "the transmission requested at bit {} did not complete within {} bit times; SR = {} (TS = {}, TBS = {})",
            s.requested_bit,
            s.waited_bits,
            sr::describe(s.sr),
            s.ts() as u8,
            s.tbs() as u8
        ),
        "no rule matched: the request stayed pending without a bus error the record explains",
        "record the bus bits and engine events (cosim --vcd) and inspect the frame around the request",
        f,
    ))
}

/// The CAN 2.0B TEC after each attempt when rx reads recessive only:
/// +8 for the bit error in SOF (rule 3), +8 for each bit error while sending
/// an active error flag (rule 4). CAN 2.0B §8: "an error condition letting a
/// node become error passive causes the node to send an active error flag",
/// so the error that takes TEC to 128 still starts an active flag, whose
/// first bit fails once more: 136 after attempt 1. From then on the flags
/// are passive (recessive, no bit error): +8 per attempt, bus-off
/// (TEC > 255) during attempt 16.
pub fn strict_tied_recessive_trace() -> Vec<u16> {
    let mut v = Vec::new();
    let mut tec: u16 = 0;
    loop {
        let mut active = tec < 128; // state before the error picks the flag
        tec += 8; // rule 3: bit error in SOF
        while active && tec <= 255 {
            active = tec < 128;
            tec += 8; // rule 4: the active flag bit reads back recessive
        }
        v.push(tec);
        if tec > 255 {
            return v;
        }
    }
}

/// Why the first attempt of a transmitter with rx held recessive ends at 136
/// and bus-off comes in attempt 16, in words, from a TEC trace.
pub fn explain_tied_counts(trace: &[u16]) -> Option<String> {
    let first = *trace.first()?;
    let off = trace.iter().position(|&t| t > 255).map(|p| p + 1);
    let mut s = format!(
        "TEC {first} after attempt 1: +8 for the bit error in SOF (CAN 2.0B §8 rule 3), +8 for each active error flag bit that reads back recessive (rule 4)"
    );
    if first == 136 {
        s += "; the error that takes TEC to 128 (error passive) still starts an active error flag (§8: \"an error condition letting a node become error passive causes the node to send an active error flag\"), whose first bit fails once more: 128 + 8 = 136";
    }
    s += ". Later attempts send passive (recessive) error flags: +8 per attempt";
    if let Some(o) = off {
        s += &format!(", bus-off (TEC > 255) during attempt {o}");
    }
    s.push('.');
    Some(s)
}

/// Where the DUT's TEC counts differ from the strict CAN 2.0B counts, which
/// rule makes the difference. Uses the model's trace, or the analytic strict
/// counts when rx is tied recessive and the model's trace is missing.
pub fn counts_note(r: &RunRecord) -> Option<String> {
    let dut: Vec<u16> = r.tec_of(Side::Dut).iter().map(|t| t.tec).collect();
    if dut.is_empty() {
        return None;
    }
    let model: Vec<u16> = {
        let m: Vec<u16> = r.tec_of(Side::Model).iter().map(|t| t.tec).collect();
        if m.is_empty() && r.wiring.rx == RxWiring::TiedRecessive { strict_tied_recessive_trace() } else { m }
    };
    if model.is_empty() {
        return None;
    }
    let i = (0..dut.len().min(model.len())).find(|&i| dut[i] != model[i]);
    let bus_off = |v: &[u16]| v.iter().position(|&t| t > 255).map(|p| p + 1);
    let (db, mb) = (bus_off(&dut), bus_off(&model));
    if i.is_none() && db == mb {
        return None;
    }
    let mut s = String::new();
    if let Some(i) = i {
        s += &format!("attempt {}: DUT TEC {}, model (CAN 2.0B) TEC {}. ", i + 1, dut[i], model[i]);
        let prev_equal = i == 0 || dut[i - 1] == model[i - 1];
        if prev_equal && model[i] == 136 && dut[i] == 128 {
            s += "CAN 2.0B §8: \"an error condition letting a node become error passive causes the node to send an active error flag\"; the DUT switched to a passive error flag as soon as TEC reached 128, so it missed the last +8 (rule 4: bit error while sending an active error flag). ";
        } else if prev_equal && model[i] == 136 && dut[i] > 136 {
            s += &format!(
                "CAN 2.0B §8: a node is error passive once TEC >= 128 and sends passive (recessive) error flags after the one active flag that the error reaching 128 starts; the DUT counted {} more bit error(s): it kept sending active error flags while error passive. ",
                (dut[i] - 136) / 8
            );
        } else if r.wiring.ack_nodes() == 0 && !r.wiring.self_test && dut[i] > 128 && model[i] == 128 {
            s += "CAN 2.0B §8 rule 3, exception 1: an error-passive transmitter that detects an ACK error and no dominant bit while sending its passive error flag does not increment TEC; the DUT does. ";
        } else {
            s += "CAN 2.0B §8 rules involved: rule 3 (+8 when a transmitter sends an error flag), rule 4 (+8 for a bit error while sending an active error flag), error passive at TEC >= 128, bus-off at TEC > 255. ";
        }
    }
    match (db, mb) {
        (Some(d), Some(m)) if d != m => {
            s += &format!("Bus-off (TEC > 255, §8) in attempt {d} on the DUT, in attempt {m} under CAN 2.0B.");
        }
        (Some(d), None) => s += &format!("The DUT went bus-off in attempt {d}; the model did not."),
        (None, Some(m)) if dut.len() >= m => s += &format!("The model went bus-off in attempt {m}; the DUT did not."),
        _ => {}
    }
    Some(s.trim().to_string())
}
