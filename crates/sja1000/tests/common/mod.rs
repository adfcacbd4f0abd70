//! Fixtures shared by the integration tests.
#![allow(dead_code)]

use regmap::peli;
use sja1000::host::{self, Config};
use sja1000::{Bus, Sja1000};

/// After a hardware reset: BasicCAN, reset mode.
pub fn basic_reset() -> Sja1000 {
    Sja1000::new()
}

/// Hardware reset, then CDR.7 = 1 (PeliCAN), still in reset mode.
pub fn pelican_reset() -> Sja1000 {
    let mut n = Sja1000::new();
    n.write(peli::CDR, peli::cdr::CANMODE);
    n
}

/// PeliCAN, accept all, operating mode, with `ier` enabled.
pub fn pelican_operating(ier: u8) -> Sja1000 {
    let mut n = Sja1000::new();
    host::configure(
        &mut n,
        &Config {
            interrupts: ier,
            ..Config::pelican()
        },
    );
    n
}

/// A bus of `n` nodes with the given configs.
pub fn bus_of(cfgs: &[Config]) -> Bus {
    let mut bus = Bus::new();
    for c in cfgs {
        let mut n = Sja1000::new();
        host::configure(&mut n, c);
        bus.add_node(n);
    }
    bus
}

/// Standard data frame.
pub fn std_frame(id: u16, data: &[u8]) -> can_proto::CanFrame {
    use can_proto::FrameTrait;
    can_proto::CanFrame::new(can_proto::CanFrame::std_id(id).unwrap(), data).unwrap()
}

/// Extended data frame.
pub fn ext_frame(id: u32, data: &[u8]) -> can_proto::CanFrame {
    use can_proto::FrameTrait;
    can_proto::CanFrame::new(can_proto::CanFrame::ext_id(id).unwrap(), data).unwrap()
}
