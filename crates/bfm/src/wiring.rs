//! Connecting an Avalon-MM master to a Wishbone slave (`can_top`).
//!
//! Seed 000 (Tableau 3.2) declared `can_top` as an Avalon slave with
//! `wb_cyc_i` on `begintransfer`, `wb_stb_i` on `chipselect`, `wb_we_i` on
//! `write`, `wb_ack_o` exported to a conduit and no `waitrequest`. Since
//! `begintransfer` is high only in a transfer's first cycle, `cyc` falls
//! while `stb` is still high and before the synchronised `ack` can come: the
//! Wishbone monitor flags "cyc dropped before ack" (and "stb without cyc").
//! [`Wiring::Bridge`] is the correct mapping.

use crate::{AvMasterOut, AvSlaveOut, HostBusTarget, WbMasterOut, WbSlaveOut};

/// How Avalon slave signals are tied to the Wishbone pins.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wiring {
    /// Seed 000: cyc = begintransfer, stb = chipselect, we = write, ack
    /// unconnected (no waitrequest; the component uses fixed wait states).
    Seed000,
    /// cyc = stb = chipselect & (read | write), we = write,
    /// waitrequest = !ack (needs a waitrequest-mode master).
    Bridge,
}

impl Wiring {
    /// The Wishbone pins an Avalon master's pins produce.
    pub fn to_wishbone(self, m: &AvMasterOut) -> WbMasterOut {
        match self {
            Wiring::Seed000 => WbMasterOut {
                cyc: m.begintransfer,
                stb: m.chipselect,
                we: m.write,
                adr: m.address,
                dat: m.writedata,
            },
            Wiring::Bridge => WbMasterOut {
                cyc: m.request(),
                stb: m.request(),
                we: m.write,
                adr: m.address,
                dat: m.writedata,
            },
        }
    }

    /// The Avalon slave outputs the Wishbone slave's pins produce.
    pub fn to_avalon(self, s: &WbSlaveOut) -> AvSlaveOut {
        match self {
            Wiring::Seed000 => AvSlaveOut {
                readdata: s.dat,
                waitrequest: false,
                readdatavalid: false,
            },
            Wiring::Bridge => AvSlaveOut {
                readdata: s.dat,
                waitrequest: !s.ack,
                readdatavalid: false,
            },
        }
    }
}

/// A Wishbone target seen through Avalon wiring; remembers the last
/// Wishbone-side pins so a [`crate::WishboneMonitor`] can watch them.
pub struct AvalonOverWishbone<T> {
    inner: T,
    wiring: Wiring,
    last_m: WbMasterOut,
    last_s: WbSlaveOut,
}

impl<T> AvalonOverWishbone<T> {
    /// Wrap a Wishbone target.
    pub fn new(inner: T, wiring: Wiring) -> Self {
        log::info!("Avalon-over-Wishbone adapter, wiring {wiring:?}");
        Self {
            inner,
            wiring,
            last_m: WbMasterOut::default(),
            last_s: WbSlaveOut::default(),
        }
    }

    /// Wishbone pins of the last cycle: (master pins, slave outputs after the edge).
    pub fn last_wishbone(&self) -> (WbMasterOut, WbSlaveOut) {
        (self.last_m, self.last_s)
    }

    /// The wrapped target.
    pub fn inner(&self) -> &T {
        &self.inner
    }
}

impl<T: HostBusTarget> HostBusTarget<AvMasterOut, AvSlaveOut> for AvalonOverWishbone<T> {
    fn cycle(&mut self, m: &AvMasterOut) -> AvSlaveOut {
        self.last_m = self.wiring.to_wishbone(m);
        self.last_s = self.inner.cycle(&self.last_m);
        self.wiring.to_avalon(&self.last_s)
    }
}
