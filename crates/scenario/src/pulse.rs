//! A pulse placed in a bit that forces a level on what its target receives
//! (`level` on a placed glitch). A plain glitch inverts the wire's level,
//! which turns back into the opposite level as soon as the DUT drives the
//! wire itself inside the pulse (an early edge before the DUT's own ACK bit):
//! a forced pulse stays what the scenario says.

use sja1000::{BusContext, FaultInjector, Target};

pub(crate) use sja1000::ForcedPulse;

/// A pulse counted on the nominal bit grid from its frame's start of frame
/// (`grid = "sof"`): bit `bit` starts `bit` bit times after the SOF edge,
/// whatever resynchronisation happened since: the lower tester's grid, which
/// stays put when the DUT's own edge (an early ACK) restarts the bench's.
/// `level` forces a level; `None` inverts the wire's.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SofGridPulse {
    pub(crate) frame: u64,
    pub(crate) bit: u32,
    pub(crate) offset: u32,
    pub(crate) width: u32,
    pub(crate) level: Option<bool>,
    pub(crate) target: Target,
    /// The CAN clock of the frame's SOF edge, once seen.
    sof: Option<u64>,
}

impl SofGridPulse {
    pub(crate) fn new(frame: u64, bit: u32, offset: u32, width: u32, level: Option<bool>, target: Target) -> SofGridPulse {
        SofGridPulse { frame, bit, offset, width, level, target, sof: None }
    }
}

impl FaultInjector for SofGridPulse {
    fn apply(&mut self, ctx: &BusContext, node: usize, level: bool) -> bool {
        // The frame number comes at the SOF's sample point; the bench's grid
        // restarted at its edge, so the edge is `frame_bit` bits and `sub`
        // clocks back (frame_bit is 0 then).
        if self.sof.is_none() && ctx.frame == Some(self.frame) {
            let back = u64::from(ctx.frame_bit) * u64::from(ctx.clocks_per_bit) + u64::from(ctx.sub);
            self.sof = Some(ctx.clock.saturating_sub(back));
        }
        let hits = match self.target {
            Target::All => true,
            Target::Node(n) => n == node,
        };
        let inside = self.sof.is_some_and(|sof| {
            let from = sof + u64::from(self.bit) * u64::from(ctx.clocks_per_bit) + u64::from(self.offset);
            ctx.clock >= from && ctx.clock < from + u64::from(self.width)
        });
        match (inside && hits, self.level) {
            (true, Some(l)) => l,
            (true, None) => !level,
            (false, _) => level,
        }
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

    #[test]
    fn a_sof_grid_pulse_stays_on_the_grid_of_the_sof_when_the_bench_grid_restarts() {
        // Frame 2's SOF edge at clock 1000 (seen at its sample point, sub 27);
        // 40 clocks per bit. Bit 46, clocks 36..40 of it: clocks 2876..2880,
        // even when the bench's bit 46 restarts 8 clocks early (a DUT's early ACK).
        let mut p = SofGridPulse::new(2, 46, 36, 4, Some(can_proto::DOMINANT), Target::Node(1));
        let at = |clock: u64, frame_bit: u32, sub: u32| BusContext { clock, frame: Some(2), frame_bit, sub, clocks_per_bit: 40 };
        assert_eq!(p.apply(&at(1027, 0, 27), 1, true), true, "the SOF bit: not yet");
        assert_eq!(p.apply(&at(2875, 46, 3), 1, true), true, "the bench's bit 46 at sub 3: one clock early");
        for c in 2876..2880 {
            assert_eq!(p.apply(&at(c, 46, (c - 2872) as u32), 1, true), can_proto::DOMINANT, "clock {c}");
        }
        assert_eq!(p.apply(&at(2880, 46, 8), 1, true), true, "its end");
        assert_eq!(p.apply(&at(2877, 46, 5), 0, true), true, "another node");
        // Without a level it inverts; another frame's bit 46 is not it.
        let mut q = SofGridPulse::new(2, 46, 0, 1, None, Target::Node(1));
        q.apply(&at(1027, 0, 27), 1, true);
        assert_eq!(q.apply(&at(2840, 45, 40), 1, false), true);
        let mut r = SofGridPulse::new(3, 46, 0, 1, None, Target::Node(1));
        assert_eq!(r.apply(&at(2840, 46, 0), 1, false), false, "frame 3 never started");
    }
}
