//! A sleep request refused because a frame is on the bus (a MOD write in
//! operating mode) must leave the receiver's bit timing alone: BTR0/BTR1
//! are written in reset mode only, so nothing about the timing changes and
//! the frame under way is still received (found by the tb/ sleep scenario
//! driven through a slow PIO host: the request landed where a restarted bit
//! timing lost the frame).

use crate::common;
use common::*;

use regmap::peli;
use sja1000::WriteOutcome;
use sja1000::host::{self, Config};

#[test]
fn refused_sleep_request_mid_frame_keeps_the_bit_timing() {
    let frame = std_frame(0x124, &[0x02, 0x5A]);
    // Every clock phase of a 40-clock bit, at two places in the frame.
    for bits_in in [12u64, 27] {
        for phase in 0..40u64 {
            let mut bus = bus_of(&[Config::pelican(), Config::pelican(), Config::pelican()]);
            bus.run_clocks(15 * 40);
            host::transmit(bus.node_mut(0), &frame, peli::cmr::TR).unwrap();
            for _ in 0..80 {
                if bus.node(1).engine().is_receiving() {
                    break;
                }
                bus.run_clocks(1);
            }
            bus.run_clocks(bits_in * 40 + phase);
            assert!(bus.node(1).engine().is_receiving());
            let o = bus.node_mut(1).write(peli::MOD, peli::r#mod::SM);
            assert!(matches!(o, WriteOutcome::CommandIgnored { .. }), "{o:?}");
            bus.run_clocks(80 * 40);
            let got: Vec<_> = std::iter::from_fn(|| host::receive(bus.node_mut(1))).collect();
            assert_eq!(got, vec![frame], "bit {bits_in}, phase {phase}");
            assert_eq!(bus.node(1).engine().rec(), 0, "bit {bits_in}, phase {phase}");
        }
    }
}
