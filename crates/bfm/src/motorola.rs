//! Motorola-mode multiplexed host bus, the SJA1000's other host mode (MODE
//! pin low), as 68xx and ColdFire-style hosts drive it: the master puts the
//! register address on the shared port (`AD7..AD0`) while AS is high, the
//! slave latches it, then one E pulse with chip select moves the data over
//! the same port, its direction given by R/W (high = read), which is set
//! before E rises and held until after E falls.
//!
//! The access has the same phases as the Intel-mode (8051) one, with E in
//! place of RD or WR, so the master is an [`I8051Master`] whose pins are
//! renamed ([`MotorolaOut::from_intel`]) and whose R/W comes from the
//! access in progress; the monitor checks the Intel view of the wires
//! ([`MotorolaOut::intel_view`]) with the 8051 rules, plus the two rules of
//! its own: R/W steady while E is high, and the slave answering a read
//! before E falls (a read of the pull-ups is a bus that stopped answering).
//! Pins are active high, as on our `can_top_mcu` (the chip's /CS is low;
//! put an inverter in front).

use crate::i8051::{I8051Config, I8051Master, I8051Monitor, I8051MonitorConfig, I8051Polarity, I8051SlaveOut, I8051Timing};
use crate::{BfmError, HostMaster, I8051Out, OpHandle, OpKind, OpResult, Rule, Violation};

/// What the master drives during one host cycle (wire levels, active high).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct MotorolaOut {
    /// Address strobe.
    pub as_: bool,
    /// Chip select.
    pub cs: bool,
    /// Enable (the data strobe).
    pub e: bool,
    /// Direction: high = read, low = write.
    pub rw: bool,
    /// What the master drives on the port (meaningful with `ad_oe`).
    pub ad: u8,
    /// The master drives the port.
    pub ad_oe: bool,
}

impl Default for MotorolaOut {
    /// Idle wires: nothing asserted, R/W high (read), the port released.
    fn default() -> Self {
        MotorolaOut { as_: false, cs: false, e: false, rw: true, ad: 0, ad_oe: false }
    }
}

impl MotorolaOut {
    /// The Motorola wires of an Intel-mode access (active-high pins):
    /// AS = ALE, E = RD or WR, R/W low from the start of a write access
    /// (`write`) to its end, so it is steady around E.
    pub fn from_intel(i: &I8051Out, write: bool) -> Self {
        MotorolaOut { as_: i.ale, cs: i.cs, e: i.rd || i.wr, rw: !write, ad: i.ad, ad_oe: i.ad_oe }
    }
    /// The same wires named as an Intel-mode bus (active high): ALE = AS,
    /// RD = E with R/W high, WR = E with R/W low. This is the decoding
    /// `can_top_mcu` does in Motorola mode.
    pub fn intel_view(&self) -> I8051Out {
        I8051Out { ale: self.as_, cs: self.cs, rd: self.e && self.rw, wr: self.e && !self.rw, ad: self.ad, ad_oe: self.ad_oe }
    }
}

/// Phase lengths of a Motorola-mode access, nanoseconds (each a minimum the
/// master holds, rounded up to host cycles by [`MotorolaAcTiming::cycles`]).
///
/// Where the numbers come from: the SJA1000 data sheet's AC characteristics
/// table (Motorola mode) was not in any source we could search, so no value
/// here is the data sheet's. The defaults are the kit's own: the 8051
/// defaults ([`crate::I8051AcTiming`]) phase for phase (AS as ALE, E as RD
/// or WR), since our `can_top_mcu` samples both modes the same way and a
/// 68xx E cycle at a few MHz is of that order. A user with the table enters
/// its minimums here.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MotorolaAcTiming {
    /// AS pulse width, the address driven (and set up) meanwhile.
    pub as_ns: u32,
    /// Address hold after AS falls.
    pub addr_hold_ns: u32,
    /// Read: port released (R/W high) before E rises.
    pub read_float_ns: u32,
    /// Write: data and R/W low set up before E rises.
    pub data_setup_ns: u32,
    /// E pulse width of a read.
    pub e_read_ns: u32,
    /// E pulse width of a write.
    pub e_write_ns: u32,
    /// Write: data, R/W and CS held after E falls.
    pub data_hold_ns: u32,
    /// Idle time after an access.
    pub recovery_ns: u32,
}

impl Default for MotorolaAcTiming {
    fn default() -> Self {
        let i = crate::I8051AcTiming::default();
        MotorolaAcTiming {
            as_ns: i.ale_ns,
            addr_hold_ns: i.addr_hold_ns,
            read_float_ns: i.read_float_ns,
            data_setup_ns: i.data_setup_ns,
            e_read_ns: i.rd_ns,
            e_write_ns: i.wr_ns,
            data_hold_ns: i.data_hold_ns,
            recovery_ns: i.recovery_ns,
        }
    }
}

impl MotorolaAcTiming {
    /// Host cycles at `host_hz` (AS in the `ale` field, E in `rd`/`wr`),
    /// each phase rounded up, at least one cycle.
    pub fn cycles(&self, host_hz: u64) -> I8051Timing {
        crate::I8051AcTiming {
            ale_ns: self.as_ns,
            addr_hold_ns: self.addr_hold_ns,
            read_float_ns: self.read_float_ns,
            data_setup_ns: self.data_setup_ns,
            rd_ns: self.e_read_ns,
            wr_ns: self.e_write_ns,
            data_hold_ns: self.data_hold_ns,
            recovery_ns: self.recovery_ns,
        }
        .cycles(host_hz)
    }
}

/// Motorola-mode master: one access at a time, fixed length (the phases of
/// [`I8051Timing`], AS in `ale`, E in `rd`/`wr`).
pub struct MotorolaMaster {
    inner: I8051Master,
}

impl MotorolaMaster {
    /// A master with these cycle counts and per-operation timeout.
    pub fn new(name: &str, timing: I8051Timing, timeout_cycles: u64) -> Self {
        log::info!("{name}: Motorola-mode bus master (AS, E, R/W, CS active high, R/W high = read); phases as below, AS in ALE's place, E in RD's or WR's");
        MotorolaMaster {
            inner: I8051Master::new(name, I8051Config { polarity: I8051Polarity::ACTIVE_HIGH, timing, timeout_cycles }),
        }
    }
    /// Cycle counts.
    pub fn timing(&self) -> I8051Timing {
        self.inner.config().timing
    }
    /// Host cycles one access takes on the wires, recovery included.
    pub fn access_cycles(&self, kind: OpKind) -> u64 {
        self.inner.access_cycles(kind)
    }
}

impl HostMaster for MotorolaMaster {
    type Out = MotorolaOut;
    type In = I8051SlaveOut;

    fn outputs(&self) -> MotorolaOut {
        let i = self.inner.outputs();
        MotorolaOut::from_intel(&i, self.inner.active_write() && i.cs)
    }
    fn on_edge(&mut self, slave: &I8051SlaveOut) {
        self.inner.on_edge(slave)
    }
    fn start_write(&mut self, addr: u8, data: u8) -> OpHandle {
        self.inner.start_write(addr, data)
    }
    fn start_read(&mut self, addr: u8) -> OpHandle {
        self.inner.start_read(addr)
    }
    fn poll(&mut self, handle: OpHandle) -> Option<Result<OpResult, BfmError>> {
        self.inner.poll(handle)
    }
    fn reset(&mut self) {
        self.inner.reset()
    }
    fn set_reset(&mut self, asserted: bool) {
        self.inner.set_reset(asserted)
    }
    fn set_timeout(&mut self, cycles: u64) {
        self.inner.set_timeout(cycles)
    }
    fn in_flight(&self) -> usize {
        self.inner.in_flight()
    }
    fn drain_bound(&self) -> u64 {
        self.inner.drain_bound()
    }
}

/// Passive checker of the Motorola-mode bus: the 8051 rules on its Intel
/// view (AS width, address hold, E widths, write data set-up and hold,
/// contention, the slave driving outside a read's E), R/W steady while E is
/// high, and a read's E ending with the port never driven by the slave.
pub struct MotorolaMonitor {
    name: String,
    intel: I8051Monitor,
    prev: MotorolaOut,
    /// Read E cycles so far, and whether the slave drove the port in them.
    read_e: Option<(u64, bool)>,
    addr: u8,
}

impl MotorolaMonitor {
    /// A monitor whose minimums are the master's `t` (see
    /// [`I8051MonitorConfig::for_timing`]).
    pub fn new(name: &str, t: &I8051Timing) -> Self {
        log::info!("{name}: Motorola-mode bus monitor: R/W steady while E is high, a read answered before E falls, and the 8051 rules on AS/E below");
        MotorolaMonitor {
            name: name.to_owned(),
            intel: I8051Monitor::new(name, I8051MonitorConfig::for_timing(I8051Polarity::ACTIVE_HIGH, t)),
            prev: MotorolaOut::default(),
            read_e: None,
            addr: 0,
        }
    }

    /// Check one cycle: `m` = master pins during `cycle`, `s_after` = slave
    /// outputs after that cycle's edge.
    pub fn observe(&mut self, cycle: u64, m: &MotorolaOut, s_after: &I8051SlaveOut) -> Vec<Violation> {
        let mut own = Vec::new();
        let p = std::mem::replace(&mut self.prev, *m);
        if m.as_ && m.ad_oe {
            self.addr = m.ad;
        }
        if m.cs && m.e && p.cs && p.e && m.rw != p.rw {
            own.push(Violation {
                cycle,
                rule: Rule::DataNotHeld,
                message: format!("R/W changed to {} while E was high", if m.rw { "read (high)" } else { "write (low)" }),
            });
        }
        // The slave's answer to a read, seen after this cycle's edge; a
        // registered slave answers by the edge that ends E.
        if m.cs && m.e && m.rw {
            let (n, drove) = self.read_e.unwrap_or((0, false));
            self.read_e = Some((n + 1, drove || s_after.ad_oe));
        } else if let Some((n, drove)) = self.read_e.take() {
            if !drove {
                own.push(Violation {
                    cycle,
                    rule: Rule::NoReadData,
                    message: format!(
                        "read of register 0x{:02X}: E high for {n} host cycles and the slave never drove AD (the master read the pull-ups, 0xFF)",
                        self.addr
                    ),
                });
            }
        }
        for x in &own {
            log::warn!("{}: {x}", self.name);
        }
        let mut v = self.intel.observe(cycle, &m.intel_view(), s_after);
        // The 8051 rules' sentences, in this bus's pin names.
        for x in &mut v {
            x.message = motorola_names(&x.message);
        }
        v.extend(own);
        v
    }
}

fn motorola_names(s: &str) -> String {
    [
        ("RD and WR asserted together", "E decoded as read and write together"),
        ("RD asserted", "E (read) asserted"),
        ("WR asserted", "E (write) asserted"),
        ("WR was released", "E fell"),
        ("WR released", "E fell"),
        ("before WR", "before E"),
        ("the last RD", "the last read's E"),
        ("no RD ever", "no read E ever"),
        ("ALE", "AS"),
    ]
    .iter()
    .fold(s.to_owned(), |s, (a, b)| s.replace(a, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_intel_view_decodes_e_by_rw() {
        let w = MotorolaOut { as_: false, cs: true, e: true, rw: false, ad: 0x12, ad_oe: true };
        let i = w.intel_view();
        assert!(i.wr && !i.rd && i.cs && !i.ale);
        assert_eq!(MotorolaOut::from_intel(&i, true), w);
        let r = MotorolaOut { rw: true, ad_oe: false, ad: 0, ..w };
        assert!(r.intel_view().rd && !r.intel_view().wr);
    }

    #[test]
    fn the_ns_defaults_are_the_8051_ones_and_scale_with_the_clock() {
        assert_eq!(MotorolaAcTiming::default().cycles(50_000_000), I8051Timing::default());
        let t = MotorolaAcTiming { e_read_ns: 1000, ..MotorolaAcTiming::default() };
        assert_eq!(t.cycles(8_000_000).rd, 8);
        assert_eq!(t.cycles(10_000_000).rd, 10);
    }
}

/// The slave logic of `can_top_mcu` in Motorola mode, in Rust, onto a
/// Wishbone slave (the golden model as DUT): the address latched while AS
/// is high, a read started when E rises with R/W high, a write when E falls
/// with R/W low, one Wishbone access at a time (writes first), the read
/// byte on the port while E, R/W and CS are high once it is there. It
/// samples the wires directly, where the RTL puts two flops first.
#[derive(Debug, Clone, Copy, Default)]
pub struct MotorolaBridge {
    adr: u8,
    wdat: u8,
    rd_d: bool,
    wr_d: bool,
    rd_pend: bool,
    wr_pend: Option<u8>,
    /// The Wishbone access in progress: (write, address, data).
    busy: Option<(bool, u8, u8)>,
    rdata: u8,
    rvalid: bool,
}

impl MotorolaBridge {
    /// The Wishbone wires (registered: the access in progress).
    pub fn to_wishbone(&self) -> crate::WbMasterOut {
        match self.busy {
            Some((we, adr, dat)) => crate::WbMasterOut { cyc: true, stb: true, we, adr, dat },
            None => crate::WbMasterOut::default(),
        }
    }

    /// What the slave drives on the port with the master's pins `m`.
    pub fn to_port(&self, m: &MotorolaOut) -> I8051SlaveOut {
        let oe = m.cs && m.e && m.rw && self.rvalid;
        I8051SlaveOut { ad: if oe { self.rdata } else { 0 }, ad_oe: oe }
    }

    /// The bridge's registers at a rising edge: `m` and `s` are the wires
    /// during the cycle that ends (`s` the Wishbone slave's outputs then).
    pub fn clock(&mut self, m: &MotorolaOut, s: &crate::WbSlaveOut) {
        let i = m.intel_view();
        let (rd, wr) = (i.cs && i.rd, i.cs && i.wr);
        let ad = if i.ad_oe { i.ad } else { 0xFF };
        let mut rvalid = self.rvalid && rd;
        let (mut rd_pend, mut wr_pend) = (self.rd_pend, self.wr_pend);
        if rd && !self.rd_d {
            rd_pend = true;
            rvalid = false;
        }
        if !wr && self.wr_d {
            wr_pend = Some(self.adr);
        }
        match self.busy {
            Some((we, ..)) if s.ack => {
                self.busy = None;
                if !we {
                    self.rdata = s.dat;
                    // a read whose strobe already ended is dropped
                    rvalid = rd;
                }
            }
            Some(_) => {}
            None => {
                if let Some(a) = self.wr_pend {
                    self.busy = Some((true, a, self.wdat));
                    wr_pend = None;
                } else if self.rd_pend {
                    self.busy = Some((false, self.adr, 0));
                    rd_pend = false;
                }
            }
        }
        if i.ale {
            self.adr = ad;
        }
        if wr {
            self.wdat = ad;
        }
        self.rd_d = rd;
        self.wr_d = wr;
        self.rd_pend = rd_pend;
        self.wr_pend = wr_pend;
        self.rvalid = rvalid;
    }
}
