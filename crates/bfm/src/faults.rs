//! Broken targets, as middleware: each wraps any target (a RAM, or a DUT in
//! `cosim`) and breaks one protocol rule, so the monitors can be shown to
//! catch it.

use crate::{AvMasterOut, AvSlaveOut, HostBusTarget, WbMasterOut, WbSlaveOut};

/// Wishbone slave that never acknowledges (`ack` forced low).
pub struct NeverAck<T>(pub T);

impl<T: HostBusTarget> HostBusTarget for NeverAck<T> {
    fn cycle(&mut self, m: &WbMasterOut) -> WbSlaveOut {
        let mut s = self.0.cycle(m);
        s.ack = false;
        s
    }
}

/// Wishbone slave that raises `ack` for one cycle after every `period` idle
/// cycles (no request on the wires): an acknowledge without a request.
pub struct SpuriousAck<T> {
    inner: T,
    period: u64,
    idle: u64,
}

impl<T> SpuriousAck<T> {
    /// Wrap `inner`; `period` idle cycles between spurious acks (at least 1).
    pub fn new(inner: T, period: u64) -> Self {
        log::info!("fault: spurious wb_ack_o every {period} idle cycles");
        Self {
            inner,
            period: period.max(1),
            idle: 0,
        }
    }
}

impl<T: HostBusTarget> HostBusTarget for SpuriousAck<T> {
    fn cycle(&mut self, m: &WbMasterOut) -> WbSlaveOut {
        let mut s = self.inner.cycle(m);
        if m.request() {
            self.idle = 0;
        } else {
            self.idle += 1;
            if self.idle >= self.period {
                self.idle = 0;
                s.ack = true;
            }
        }
        s
    }
}

/// Wishbone slave whose every `ack` lasts two cycles: the second one
/// acknowledges whatever is (or is not) on the wires next.
pub struct DoubleAck<T> {
    inner: T,
    last: bool,
}

impl<T> DoubleAck<T> {
    /// Wrap `inner`.
    pub fn new(inner: T) -> Self {
        log::info!("fault: every wb_ack_o stretched to two cycles");
        Self { inner, last: false }
    }
}

impl<T: HostBusTarget> HostBusTarget for DoubleAck<T> {
    fn cycle(&mut self, m: &WbMasterOut) -> WbSlaveOut {
        let mut s = self.inner.cycle(m);
        let this = s.ack;
        s.ack |= self.last;
        self.last = this;
        s
    }
}

/// Avalon slave whose `waitrequest` never falls.
pub struct StuckWaitrequest<T>(pub T);

impl<T: HostBusTarget<AvMasterOut, AvSlaveOut>> HostBusTarget<AvMasterOut, AvSlaveOut>
    for StuckWaitrequest<T>
{
    fn cycle(&mut self, m: &AvMasterOut) -> AvSlaveOut {
        let mut s = self.0.cycle(m);
        s.waitrequest = true;
        s.readdatavalid = false;
        s
    }
}

/// Avalon slave that pulses `readdatavalid` every `period` cycles whatever
/// was asked.
pub struct SpuriousReaddatavalid<T> {
    inner: T,
    period: u64,
    count: u64,
}

impl<T> SpuriousReaddatavalid<T> {
    /// Wrap `inner`; a pulse every `period` cycles (at least 1).
    pub fn new(inner: T, period: u64) -> Self {
        log::info!("fault: spurious readdatavalid every {period} cycles");
        Self {
            inner,
            period: period.max(1),
            count: 0,
        }
    }
}

impl<T: HostBusTarget<AvMasterOut, AvSlaveOut>> HostBusTarget<AvMasterOut, AvSlaveOut>
    for SpuriousReaddatavalid<T>
{
    fn cycle(&mut self, m: &AvMasterOut) -> AvSlaveOut {
        let mut s = self.inner.cycle(m);
        self.count += 1;
        if self.count >= self.period {
            self.count = 0;
            s.readdatavalid = true;
        }
        s
    }
}
