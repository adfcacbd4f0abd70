//! A core that hands each host access across into its CAN clock domain with
//! a request/acknowledge handshake takes no new request until the
//! handshake of the previous access has returned to idle. A host that
//! starts the next access right after an ack (every BFM does) is then seen
//! later than the profile's "n CAN edges after the access starts": the
//! reference must take the access as late as the core does.
//!
//! The profile declares the hold-off as three counts (`busy-after-ack`):
//! after the ack rises, `can` CAN edges (the core stops seeing the old
//! request), then `host` host edges (its acknowledge falls back), then
//! `can_again` CAN edges (the block is lifted); the next CAN edge is the
//! first that can see a new request. Each count is of edges strictly after
//! the previous stage's last one (two edges at one instant: the later stage
//! does not see the earlier's edge, as with registers clocked together).

use crate::kernel::Tick;

/// The `busy-after-ack` counts of a profile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BusyAfterAck {
    /// CAN edges after the ack until the core no longer sees the request.
    pub can: u32,
    /// Host edges after that until its acknowledge is back to idle.
    pub host: u32,
    /// CAN edges after that until a new request can be seen.
    pub can_again: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    Ready,
    Can,
    Host,
    CanAgain,
}

/// Tracks the hold-off from the DUT's ack and the clock edges.
#[derive(Clone, Debug)]
pub struct AckHoldoff {
    spec: BusyAfterAck,
    stage: Stage,
    left: u32,
    prev_ack: bool,
}

impl AckHoldoff {
    /// Ready, no ack seen.
    pub fn new(spec: BusyAfterAck) -> Self {
        AckHoldoff {
            spec,
            stage: Stage::Ready,
            left: 0,
            prev_ack: false,
        }
    }

    /// True when the core can see a request at the next CAN edge.
    pub fn ready(&self) -> bool {
        self.stage == Stage::Ready
    }

    /// One simulation instant (after the DUT's eval): its clock edges and
    /// the ack level now. At most one stage ends per instant.
    pub fn on_tick(&mut self, t: &Tick, ack: bool) {
        let edge = match self.stage {
            Stage::Ready => false,
            Stage::Can | Stage::CanAgain => t.can_rise,
            Stage::Host => t.host_rise,
        };
        if edge {
            self.left = self.left.saturating_sub(1);
            if self.left == 0 {
                self.advance();
            }
        }
        if ack && !self.prev_ack {
            self.stage = Stage::Can;
            self.left = self.spec.can;
            if self.left == 0 {
                self.advance();
            }
        }
        self.prev_ack = ack;
    }

    /// Moves to the next stage, skipping stages of zero edges.
    fn advance(&mut self) {
        loop {
            let (next, n) = match self.stage {
                Stage::Ready => return,
                Stage::Can => (Stage::Host, self.spec.host),
                Stage::Host => (Stage::CanAgain, self.spec.can_again),
                Stage::CanAgain => (Stage::Ready, 0),
            };
            self.stage = next;
            self.left = n;
            if n != 0 || next == Stage::Ready {
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tick(can: bool, host: bool) -> Tick {
        Tick {
            t_ps: 0,
            host_rise: host,
            host_fall: false,
            can_rise: can,
            can_fall: false,
        }
    }

    #[test]
    fn ready_again_after_the_three_stages_and_not_before() {
        let mut h = AckHoldoff::new(BusyAfterAck { can: 3, host: 3, can_again: 2 });
        assert!(h.ready());
        h.on_tick(&tick(false, true), true); // ack rises
        assert!(!h.ready());
        // host edges do not count while CAN edges are due
        for _ in 0..5 {
            h.on_tick(&tick(false, true), false);
        }
        for _ in 0..3 {
            assert!(!h.ready());
            h.on_tick(&tick(true, false), false);
        }
        // a CAN edge together with the stage's end: not a host edge yet
        for _ in 0..3 {
            h.on_tick(&tick(true, false), false);
        }
        for _ in 0..3 {
            assert!(!h.ready());
            h.on_tick(&tick(false, true), false);
        }
        h.on_tick(&tick(true, false), false);
        assert!(!h.ready(), "one CAN edge of two");
        h.on_tick(&tick(true, false), false);
        assert!(h.ready());
    }

    #[test]
    fn an_instant_with_both_edges_ends_one_stage_only() {
        let mut h = AckHoldoff::new(BusyAfterAck { can: 1, host: 1, can_again: 1 });
        h.on_tick(&tick(false, true), true);
        h.on_tick(&tick(true, true), true); // ends `can`; its host edge is not the next stage's
        assert!(!h.ready());
        h.on_tick(&tick(true, true), false); // ends `host`; its CAN edge is not counted
        assert!(!h.ready());
        h.on_tick(&tick(true, false), false);
        assert!(h.ready());
    }
}
