//! A pulse placed in a bit that forces a level on what its target receives
//! (`level` on a placed glitch). A plain glitch inverts the wire's level,
//! which turns back into the opposite level as soon as the DUT drives the
//! wire itself inside the pulse (an early edge before the DUT's own ACK bit):
//! a forced pulse stays what the scenario says.

use sja1000::{BusContext, FaultInjector, Target};

/// `width` CAN clocks of `level` from clock `offset` of wire bit `bit` of
/// frame `frame` (0 = the first SOF on the bus), counted like
/// [`sja1000::Glitch`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct ForcedPulse {
    pub(crate) frame: u64,
    pub(crate) bit: u32,
    pub(crate) offset: u32,
    pub(crate) width: u32,
    pub(crate) level: bool,
    pub(crate) target: Target,
}

impl FaultInjector for ForcedPulse {
    fn apply(&mut self, ctx: &BusContext, node: usize, level: bool) -> bool {
        let inside = ctx.frame == Some(self.frame) && ctx.frame_bit == self.bit && ctx.sub >= self.offset && ctx.sub < self.offset + self.width;
        let hits = match self.target {
            Target::All => true,
            Target::Node(n) => n == node,
        };
        if inside && hits { self.level } else { level }
    }

    fn needs_clocks(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx(sub: u32) -> BusContext {
        BusContext { clock: 0, frame: Some(2), frame_bit: 45, sub, clocks_per_bit: 40 }
    }

    #[test]
    fn forces_its_level_inside_the_pulse_whatever_the_wire_carries() {
        let mut p = ForcedPulse { frame: 2, bit: 45, offset: 32, width: 8, level: can_proto::DOMINANT, target: Target::Node(1) };
        for wire in [true, false] {
            assert_eq!(p.apply(&ctx(32), 1, wire), can_proto::DOMINANT);
            assert_eq!(p.apply(&ctx(39), 1, wire), can_proto::DOMINANT);
            // outside the pulse, or another node: the wire's level
            assert_eq!(p.apply(&ctx(31), 1, wire), wire);
            assert_eq!(p.apply(&ctx(40), 1, wire), wire);
            assert_eq!(p.apply(&ctx(35), 0, wire), wire);
        }
        // a plain glitch inverts instead: dominant on the wire becomes recessive
        let mut g = sja1000::Glitch { frame: 2, bit: 45, offset: 32, width: 8, target: Target::Node(1) };
        assert_eq!(g.apply(&ctx(35), 1, can_proto::DOMINANT), !can_proto::DOMINANT);
        assert!(p.needs_clocks());
    }
}
