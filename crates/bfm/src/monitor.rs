//! Passive protocol monitors: Wishbone classic and Avalon-MM.
//!
//! A monitor is fed, once per host cycle, the master's pins `m` for that
//! cycle and the slave's outputs after the cycle's edge (the pair the kernel
//! holds, see the crate docs). It pairs `m_k` with `s_{k-1}`, the values on
//! the wires during cycle `k`, and checks the rules on that wire state.

use std::fmt;

use crate::{AvMasterOut, AvSlaveOut, AvalonTiming, WbMasterOut, WbSlaveOut};

/// The rule a violation breaks. Stable names for the diagnoser.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Rule {
    /// Wishbone: `stb` high while `cyc` is low.
    StbWithoutCyc,
    /// Wishbone: `cyc` fell while a transfer waited for `ack`.
    CycDroppedBeforeAck,
    /// Wishbone: `stb` fell (with `cyc` high) while a transfer waited for `ack`.
    StbDroppedBeforeAck,
    /// Wishbone: `adr`, `we` or write `dat` changed while waiting for `ack`.
    ChangedWhileWaiting,
    /// Wishbone: `ack`/`err`/`rty` while no transfer is requested.
    AckWithoutRequest,
    /// Wishbone: no `ack` within the monitor's limit.
    NoAck,
    /// Avalon: `read` and `write` asserted together.
    ReadAndWrite,
    /// Avalon: `address`, `byteenable`, `read`/`write` or `writedata` changed
    /// while the request was held off (by `waitrequest` or fixed wait states).
    ChangedWhileWaitrequest,
    /// Avalon: the request disappeared before it was accepted.
    WithdrawnWhileWaitrequest,
    /// Avalon: `readdatavalid` with no outstanding read.
    ReaddatavalidWithoutRead,
    /// Avalon: `waitrequest` held beyond the monitor's limit.
    WaitrequestStuck,
    /// Avalon: an accepted pipelined read got no `readdatavalid` within the limit.
    NoReaddatavalid,
    /// Avalon: `begintransfer` missing from a transfer's first cycle, or
    /// present in another cycle.
    BegintransferMisplaced,
    /// 8051 bus: ALE, RD or WR asserted fewer cycles than the slave needs.
    StrobeTooShort,
    /// 8051 bus: the address after ALE, or the write data around WR, not
    /// held (changed or released too early).
    DataNotHeld,
    /// 8051 bus: master and slave drive the shared port together.
    PortContention,
    /// 8051 bus: the slave drives the port outside an RD strobe with chip
    /// select (beyond its float time).
    ReadOutsideStrobe,
    /// AXI: a VALID fell before its READY (APB: PSEL or PENABLE fell
    /// before PREADY).
    ValidDroppedBeforeReady,
    /// AXI: a channel's payload changed while its VALID waited for READY
    /// (APB: address, direction or data changed during a transfer).
    ChangedWhileValid,
    /// AXI: VALID waited for READY beyond the monitor's limit (APB: PREADY
    /// low beyond it).
    HandshakeStuck,
    /// AXI: a B or R response with no accepted request to answer.
    ResponseWithoutRequest,
    /// AXI: a response other than OKAY (APB: PSLVERR).
    ErrorResponse,
    /// APB: the phases out of order (PENABLE without a setup phase, or
    /// in the setup phase's cycle).
    PhaseOrder,
    /// Motorola bus: a read's E ended and the slave never drove the port.
    NoReadData,
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Rule::StbWithoutCyc => "stb without cyc",
            Rule::CycDroppedBeforeAck => "cyc dropped before ack",
            Rule::StbDroppedBeforeAck => "stb dropped before ack",
            Rule::ChangedWhileWaiting => "master changed adr/we/dat while waiting for ack",
            Rule::AckWithoutRequest => "ack without request",
            Rule::NoAck => "no ack",
            Rule::ReadAndWrite => "read and write together",
            Rule::ChangedWhileWaitrequest => "request changed while held off",
            Rule::WithdrawnWhileWaitrequest => "request withdrawn before acceptance",
            Rule::ReaddatavalidWithoutRead => "readdatavalid without read",
            Rule::WaitrequestStuck => "waitrequest stuck",
            Rule::NoReaddatavalid => "no readdatavalid",
            Rule::BegintransferMisplaced => "begintransfer misplaced",
            Rule::StrobeTooShort => "strobe too short",
            Rule::DataNotHeld => "address/data not held",
            Rule::PortContention => "port contention",
            Rule::ReadOutsideStrobe => "slave drives outside RD",
            Rule::ValidDroppedBeforeReady => "valid dropped before ready",
            Rule::ChangedWhileValid => "payload changed while waiting",
            Rule::HandshakeStuck => "handshake stuck",
            Rule::ResponseWithoutRequest => "response without request",
            Rule::ErrorResponse => "error response",
            Rule::PhaseOrder => "phases out of order",
            Rule::NoReadData => "no read data",
        })
    }
}

/// One protocol violation.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Violation {
    /// Host cycle during which the offending values were on the wires.
    pub cycle: u64,
    /// The rule broken.
    pub rule: Rule,
    /// What happened, in signal names and values.
    pub message: String,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "cycle {}: {}: {}", self.cycle, self.rule, self.message)
    }
}

fn dir(we: bool) -> &'static str {
    if we { "write" } else { "read" }
}

/// Wishbone classic protocol checker (the slave's view, `can_top` names).
pub struct WishboneMonitor {
    name: String,
    ack_timeout: u64,
    prev_s: WbSlaveOut,
    prev_m: WbMasterOut,
    /// The previous wire state held a transfer that had not ended.
    pending: bool,
    /// Cycle the pending transfer appeared on the wires.
    started: u64,
    waited: u64,
    noack_reported: bool,
    /// The slave has taken the pending transfer (the bench knows when its
    /// core latches an access, from the core's profile).
    latched: bool,
}

impl WishboneMonitor {
    /// Tells the monitor, before [`WishboneMonitor::observe`], whether the
    /// slave has already taken the transfer on the wires (it latches an
    /// access some clocks after cyc & stb, before its ack). A transfer
    /// dropped after that is not abandoned: the slave acted on it and its
    /// ack was only missed; one dropped before it still is.
    pub fn set_latched(&mut self, latched: bool) {
        self.latched = latched;
    }

    /// A monitor that reports [`Rule::NoAck`] when a transfer waits more than
    /// `ack_timeout` cycles.
    pub fn new(name: &str, ack_timeout: u64) -> Self {
        log::info!(
            "{name}: Wishbone classic monitor, adr 8 bits, dat 8 bits, checks stb/cyc, \
             cyc/stb held until ack, adr/we/dat stable, ack only on request, ack within {ack_timeout} cycles"
        );
        Self {
            name: name.to_owned(),
            ack_timeout,
            prev_s: WbSlaveOut::default(),
            prev_m: WbMasterOut::default(),
            pending: false,
            started: 0,
            waited: 0,
            noack_reported: false,
            latched: false,
        }
    }

    /// Check one cycle: `m` = master pins during `cycle`, `s_after` = slave
    /// outputs after that cycle's edge.
    pub fn observe(&mut self, cycle: u64, m: &WbMasterOut, s_after: &WbSlaveOut) -> Vec<Violation> {
        let s = std::mem::replace(&mut self.prev_s, *s_after);
        let mut v = Vec::new();
        let mut flag = |rule, message: String| {
            v.push(Violation {
                cycle,
                rule,
                message,
            });
        };
        let ended = s.ack || s.err || s.rty;
        if m.stb && !m.cyc {
            flag(
                Rule::StbWithoutCyc,
                format!("wb_stb_i=1 while wb_cyc_i=0 (adr 0x{:02X})", m.adr),
            );
        }
        if ended && !m.request() {
            let which = if s.ack {
                "wb_ack_o"
            } else if s.err {
                "err"
            } else {
                "rty"
            };
            flag(
                Rule::AckWithoutRequest,
                format!(
                    "{which}=1 while cyc={} stb={}: no transfer to acknowledge",
                    m.cyc as u8, m.stb as u8
                ),
            );
        }
        let pm = self.prev_m;
        let mut continues = false;
        if self.pending {
            // Built only when a rule fires: this runs every waiting cycle.
            let started = self.started;
            let what = || format!("{} at 0x{:02X} started at cycle {started}", dir(pm.we), pm.adr);
            if !m.request() && self.latched {
                // Taken by the slave before the master let go: not abandoned.
            } else if !m.cyc {
                flag(
                    Rule::CycDroppedBeforeAck,
                    format!(
                        "wb_cyc_i fell while the {} waited for wb_ack_o (transfer abandoned)",
                        what()
                    ),
                );
            } else if !m.stb {
                flag(
                    Rule::StbDroppedBeforeAck,
                    format!("wb_stb_i fell while the {} waited for wb_ack_o", what()),
                );
            } else {
                continues = true;
                let mut changed = Vec::new();
                if m.adr != pm.adr {
                    changed.push(format!("adr 0x{:02X}->0x{:02X}", pm.adr, m.adr));
                }
                if m.we != pm.we {
                    changed.push(format!("we {}->{}", pm.we as u8, m.we as u8));
                }
                if m.we && pm.we && m.dat != pm.dat {
                    changed.push(format!("dat 0x{:02X}->0x{:02X}", pm.dat, m.dat));
                }
                if !changed.is_empty() {
                    flag(
                        Rule::ChangedWhileWaiting,
                        format!(
                            "{} while the {} waited for wb_ack_o",
                            changed.join(", "),
                            what()
                        ),
                    );
                }
            }
        }
        if m.request() {
            if continues {
                self.waited += 1;
            } else {
                self.started = cycle;
                self.waited = 1;
                self.noack_reported = false;
            }
            if !ended && self.waited > self.ack_timeout && !self.noack_reported {
                self.noack_reported = true;
                flag(
                    Rule::NoAck,
                    format!(
                        "{} at 0x{:02X} started at cycle {} has waited {} cycles for wb_ack_o (limit {})",
                        dir(m.we),
                        m.adr,
                        self.started,
                        self.waited,
                        self.ack_timeout
                    ),
                );
            }
        }
        self.pending = m.request() && !ended;
        self.prev_m = *m;
        for x in &v {
            log::warn!("{}: {x}", self.name);
        }
        v
    }
}

/// Options of an [`AvalonMonitor`]: the interface as the component declares it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AvalonMonitorConfig {
    /// Transfer timing of the slave interface.
    pub timing: AvalonTiming,
    /// The interface has `begintransfer`: check it marks each first cycle.
    pub begintransfer: bool,
    /// Cycles a request may be held off (or a pipelined read wait for its
    /// data) before it is reported.
    pub timeout_cycles: u64,
}

/// Avalon-MM protocol checker (slave interface view).
pub struct AvalonMonitor {
    name: String,
    cfg: AvalonMonitorConfig,
    prev_s: AvSlaveOut,
    prev_m: AvMasterOut,
    /// The previous wire state held a request not yet accepted.
    pending: bool,
    /// Cycles the current request has been on the wires.
    held: u64,
    started: u64,
    stuck_reported: bool,
    outstanding: u32,
    data_wait: u64,
    data_reported: bool,
}

impl AvalonMonitor {
    /// A monitor for an interface with the given options.
    pub fn new(name: &str, cfg: AvalonMonitorConfig) -> Self {
        log::info!(
            "{name}: Avalon-MM monitor, address 8 bits, data 8 bits, {:?}, begintransfer {}, limit {} cycles",
            cfg.timing,
            if cfg.begintransfer {
                "checked"
            } else {
                "absent"
            },
            cfg.timeout_cycles
        );
        Self {
            name: name.to_owned(),
            cfg,
            // Before the first edge nothing has been accepted.
            prev_s: AvSlaveOut {
                waitrequest: !matches!(cfg.timing, AvalonTiming::FixedWaitStates { .. }),
                ..Default::default()
            },
            prev_m: AvMasterOut::default(),
            pending: false,
            held: 0,
            started: 0,
            stuck_reported: false,
            outstanding: 0,
            data_wait: 0,
            data_reported: false,
        }
    }

    fn wait_states(&self, m: &AvMasterOut) -> Option<u64> {
        match self.cfg.timing {
            AvalonTiming::FixedWaitStates { read, write } => {
                Some(if m.write { write as u64 } else { read as u64 })
            }
            _ => None,
        }
    }

    /// Check one cycle: `m` = master pins during `cycle`, `s_after` = slave
    /// outputs after that cycle's edge.
    pub fn observe(&mut self, cycle: u64, m: &AvMasterOut, s_after: &AvSlaveOut) -> Vec<Violation> {
        let s = std::mem::replace(&mut self.prev_s, *s_after);
        let mut v = Vec::new();
        let mut flag = |rule, message: String| {
            v.push(Violation {
                cycle,
                rule,
                message,
            });
        };
        if m.chipselect && m.read && m.write {
            flag(
                Rule::ReadAndWrite,
                format!(
                    "read=1 and write=1 with chipselect at address 0x{:02X}",
                    m.address
                ),
            );
        }
        let pm = self.prev_m;
        let held_by = if self.wait_states(&pm).is_some() {
            "fixed wait states"
        } else {
            "waitrequest"
        };
        let mut continues = false;
        if self.pending {
            // Built only when a rule fires: this runs every waiting cycle.
            let started = self.started;
            let what = || {
                format!(
                    "{} at 0x{:02X} started at cycle {started}",
                    if pm.write { "write" } else { "read" },
                    pm.address
                )
            };
            if !m.request() {
                flag(
                    Rule::WithdrawnWhileWaitrequest,
                    format!(
                        "the {} was withdrawn after {} cycles, still held off by {held_by}",
                        what(),
                        self.held
                    ),
                );
            } else {
                continues = true;
                let mut changed = Vec::new();
                if m.address != pm.address {
                    changed.push(format!("address 0x{:02X}->0x{:02X}", pm.address, m.address));
                }
                if m.read != pm.read || m.write != pm.write {
                    changed.push(format!(
                        "read/write {}{}->{}{}",
                        pm.read as u8, pm.write as u8, m.read as u8, m.write as u8
                    ));
                }
                if m.byteenable != pm.byteenable {
                    changed.push(format!(
                        "byteenable 0x{:X}->0x{:X}",
                        pm.byteenable, m.byteenable
                    ));
                }
                if m.write && pm.write && m.writedata != pm.writedata {
                    changed.push(format!(
                        "writedata 0x{:02X}->0x{:02X}",
                        pm.writedata, m.writedata
                    ));
                }
                if !changed.is_empty() {
                    flag(
                        Rule::ChangedWhileWaitrequest,
                        format!(
                            "{} while the {} was held off by {held_by}",
                            changed.join(", "),
                            what()
                        ),
                    );
                }
            }
        }
        if self.cfg.begintransfer {
            let first = m.request() && !continues;
            if first && !m.begintransfer {
                flag(
                    Rule::BegintransferMisplaced,
                    format!(
                        "transfer at 0x{:02X} started without begintransfer",
                        m.address
                    ),
                );
            } else if m.begintransfer && !first {
                flag(
                    Rule::BegintransferMisplaced,
                    format!(
                        "begintransfer=1 outside the first cycle of a transfer (chipselect={} read={} write={})",
                        m.chipselect as u8, m.read as u8, m.write as u8
                    ),
                );
            }
        }
        // Read data of earlier pipelined reads.
        if self.cfg.timing == AvalonTiming::Pipelined {
            if s.readdatavalid {
                if self.outstanding == 0 {
                    flag(
                        Rule::ReaddatavalidWithoutRead,
                        format!(
                            "readdatavalid=1 (readdata 0x{:02X}) with no read outstanding",
                            s.readdata
                        ),
                    );
                } else {
                    self.outstanding -= 1;
                    self.data_wait = 0;
                    self.data_reported = false;
                }
            } else if self.outstanding > 0 {
                self.data_wait += 1;
                if self.data_wait > self.cfg.timeout_cycles && !self.data_reported {
                    self.data_reported = true;
                    flag(
                        Rule::NoReaddatavalid,
                        format!(
                            "{} accepted read(s) without readdatavalid for {} cycles (limit {})",
                            self.outstanding, self.data_wait, self.cfg.timeout_cycles
                        ),
                    );
                }
            }
        }
        let mut accepted = false;
        if m.request() {
            if continues {
                self.held += 1;
            } else {
                self.held = 1;
                self.started = cycle;
                self.stuck_reported = false;
            }
            accepted = match self.wait_states(m) {
                Some(w) => self.held > w,
                None => !s.waitrequest,
            };
            if accepted && m.read && self.cfg.timing == AvalonTiming::Pipelined {
                self.outstanding += 1;
            }
            if !accepted
                && self.wait_states(m).is_none()
                && self.held > self.cfg.timeout_cycles
                && !self.stuck_reported
            {
                self.stuck_reported = true;
                flag(
                    Rule::WaitrequestStuck,
                    format!(
                        "waitrequest held {} cycles on the {} at 0x{:02X} started at cycle {} (limit {})",
                        self.held,
                        if m.write { "write" } else { "read" },
                        m.address,
                        self.started,
                        self.cfg.timeout_cycles
                    ),
                );
            }
        }
        self.pending = m.request() && !accepted;
        self.prev_m = *m;
        for x in &v {
            log::warn!("{}: {x}", self.name);
        }
        v
    }
}
