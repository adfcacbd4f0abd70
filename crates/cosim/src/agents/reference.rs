//! The reference agent: the model the DUT is compared with (the golden
//! model, or the Rust twin of a fixture) together with what the bench knows
//! of the DUT's declared timing: when its CAN side takes a host access
//! ([`RefTiming`], from the core profile or the bench's knowledge of our
//! tops) and where its bit timing starts (the profile's phase origin, given
//! to the model). It also carries the one resync that outlives a clock: a
//! frame held until the DUT's start of frame.

use crate::dut::EchoModel;
use crate::model::{AnyRef, ModelRef};
use crate::profile::{AccessTiming, PhaseOrigin, Profile};
use crate::types::RefView;
use waivers::Resync;

/// The reference of a lockstep run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReferenceChoice {
    /// The golden model.
    Model,
    /// The Rust twin of the echo fixture.
    Echo,
}

/// When the DUT's CAN-clock side takes a host access, counted from the
/// host edge that first presents it (the launch edge). The reference takes
/// the same access at the same CAN clock: the bit timing starts counting
/// when reset mode is left, so a reference that left it a few CAN clocks
/// apart from the DUT would place its time quanta (and see short glitches)
/// differently.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RefTiming {
    /// Unknown: the reference takes the access when the BFM sees the ack.
    AtAck,
    /// At the launch edge itself, after any CAN clock at the same instant
    /// (the golden model as a Wishbone slave, [`crate::ModelDut`]).
    LaunchEdge,
    /// After the n-th CAN rising edge strictly after the launch edge: a
    /// read sees the registers as of `read`, a write lands at `write`, a
    /// command (CMR) at `command` (rtl/can_wb_cdc.v: a 2-flop synchroniser
    /// and a registered strobe; can_regs captures read data and writes
    /// registers at the 4th edge; its command pulses are registered once
    /// more, but the bit stream processor also acts on a sample point one
    /// clock after the bit timing finds it, so a TR taken at the 4th edge
    /// is in time for a sample point at the 5th, as for the model).
    CanEdges {
        /// Reads.
        read: u32,
        /// Writes other than CMR.
        write: u32,
        /// CMR (address 1).
        command: u32,
    },
}

/// The DUT kinds and host buses [`RefTiming::for_dut`] tells apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DutKind {
    /// The golden model as DUT.
    Model,
    /// Our RTL (`DutChoice::Rtl`).
    Rtl,
    /// A core given by path.
    External,
    /// Anything else (bundled fixtures, echo, caller-built).
    Other,
}

/// The host bus, as [`RefTiming::for_dut`] needs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HostKind {
    /// Wishbone.
    Wishbone,
    /// Avalon through a bridge or natively.
    Avalon,
    /// Avalon with the DE2 thesis wiring (cyc from begintransfer).
    AvalonSeed000,
    /// PIO bit-banging.
    Pio,
    /// The 8051 bus.
    I8051,
    /// AXI4-Lite.
    Axi4Lite,
    /// APB.
    Apb,
    /// A plain register port.
    Regport,
    /// The Motorola bus (as the 8051 bus unless the profile's
    /// `[access.motorola]` says when an access takes effect).
    Motorola,
}

impl RefTiming {
    /// When the reference takes a host access on this DUT, host and profile.
    pub fn for_dut(dut: DutKind, host: HostKind, profile: Option<&Profile>) -> RefTiming {
        let from_profile = |a: AccessTiming| match a {
            AccessTiming::AtAck => RefTiming::AtAck,
            AccessTiming::CanEdges { read, write, command } => RefTiming::CanEdges { read, write, command },
        };
        match (dut, host, profile) {
            // An external Motorola core as its `[access.motorola]` says,
            // counted from the host edge raising E.
            (DutKind::External, HostKind::Motorola, Some(p)) if p.motorola.timing.is_some() => from_profile(p.motorola.timing.unwrap_or(AccessTiming::AtAck)),
            // Else as on the 8051 bus (can_top_mcu is can_top_8051 behind a
            // combinational decoder).
            (_, HostKind::Motorola, _) => RefTiming::for_dut(dut, HostKind::I8051, profile),
            // The seed 000 Avalon wiring (cyc from begintransfer) has no
            // well-defined launch.
            (_, HostKind::AvalonSeed000, _) => RefTiming::AtAck,
            // The golden model as DUT takes an access at its launch edge.
            (DutKind::Model, ..) => RefTiming::LaunchEdge,
            // can_top_8051 (rtl/can_top_8051.v), from the host edge that
            // raises RD or releases WR: 2 sampling flops, the strobe edge
            // registered, the Wishbone request registered (CAN edge 4),
            // can_top's own launch at edge 5 (its wb_clk_i is clk_i), then
            // can_top's 3 (read) or 4 (write, CMR) edges.
            (DutKind::Rtl, HostKind::I8051, _) => RefTiming::CanEdges { read: 8, write: 9, command: 9 },
            // An external 8051 core is taken to act at the first clk_i edge
            // of the strobe, with the port as it is then (the opencores
            // 8051 build: rd_i/wr_i registered once, the access on the
            // rising edge of the strobe, writes included).
            (DutKind::External, HostKind::I8051, Some(Profile { i8051: Some(a), .. })) => from_profile(*a),
            (DutKind::External, HostKind::I8051, _) => RefTiming::CanEdges { read: 1, write: 1, command: 1 },
            // Any other DUT as its profile says, else at the ack.
            (_, HostKind::Wishbone, Some(p)) => from_profile(p.wishbone),
            (_, HostKind::Avalon, Some(p)) => from_profile(p.avalon),
            (_, HostKind::Pio, Some(p)) => from_profile(p.pio),
            // AXI4-Lite and APB: counted from the first host edge that
            // presents the request (AW and W, or AR; the access phase), as
            // the profile's `[access.axi4-lite]`/`[access.apb]` says, else
            // as its Wishbone timing (our wrappers are can_top behind a
            // combinational request).
            (_, HostKind::Axi4Lite, Some(p)) => from_profile(p.axi4lite.unwrap_or(p.wishbone)),
            (_, HostKind::Apb, Some(p)) => from_profile(p.apb.unwrap_or(p.wishbone)),
            // The register port: from the clock edge that presents a
            // strobe, as the profile's Wishbone timing (our can_regport is
            // can_top behind a combinational request, on one clock).
            (_, HostKind::Regport, Some(p)) => from_profile(p.regport.timing.unwrap_or(p.wishbone)),
            _ => RefTiming::AtAck,
        }
    }

    /// CAN edges after the launch edge at which an access to `addr` is
    /// taken (0 unless [`RefTiming::CanEdges`]).
    #[inline]
    pub fn due_edges(&self, write: bool, addr: u8) -> u32 {
        match *self {
            RefTiming::CanEdges { read, write: w, command } => {
                if !write {
                    read
                } else if addr == 1 {
                    command
                } else {
                    w
                }
            }
            _ => 0,
        }
    }
}

/// The reference model of a run and the DUT's declared timing.
pub struct ReferenceAgent {
    /// The model, if the run is in lockstep.
    pub model: Option<AnyRef>,
    timing: RefTiming,
    /// A `model-waits-bus-free-after-bus-on` resync holds the model's next
    /// frame: start it at the DUT's next tx falling edge (its SOF).
    await_dut_sof: bool,
    /// The DUT's tx at the last CAN edge, while `await_dut_sof`.
    await_prev_dut_tx: bool,
}

impl ReferenceAgent {
    /// The reference `choice` (none: no lockstep), its bit timing starting
    /// where `profile` says, taking host accesses as `timing` says.
    pub fn new(choice: Option<ReferenceChoice>, profile: Option<&Profile>, timing: RefTiming) -> ReferenceAgent {
        let model = choice.map(|c| match c {
            // The profile's segment lag goes to the model's bit timing: a BTR
            // write that lands within it after a quantum's end redoes that
            // quantum, as the core's segment logic does.
            ReferenceChoice::Model => AnyRef::Model(
                ModelRef::with_phase_origin(profile.map_or(PhaseOrigin::ResetModeExit, |p| p.phase_origin))
                    .with_segment_lag(profile.map_or(0, |p| p.segment_lag))
                    .with_ts_clear_in_suspend(profile.is_some_and(|p| p.ts_clear_in_suspend))
                    .with_ecc_clear_on_read(profile.is_some_and(|p| p.ecc_clear_on_read)),
            ),
            ReferenceChoice::Echo => AnyRef::Other(Box::new(EchoModel::new())),
        });
        ReferenceAgent { model, timing, await_dut_sof: false, await_prev_dut_tx: true }
    }

    /// CAN edges after the launch edge at which the reference takes an
    /// access to `addr` ([`RefTiming::due_edges`] of [`Self::timing`]).
    /// (A core's segment lag acts in the model's bit timing, not here:
    /// [`ModelRef::with_segment_lag`].)
    #[inline]
    pub fn due_edges(&self, write: bool, addr: u8) -> u32 {
        self.timing().due_edges(write, addr)
    }

    /// When the reference takes a host access: the declared timing in
    /// lockstep, at the ack (nothing to take it) otherwise.
    #[inline]
    pub fn timing(&self) -> RefTiming {
        match &self.model {
            Some(_) => self.timing,
            None => RefTiming::AtAck,
        }
    }

    /// The declared timing, lockstep or not (the host monitor's latch).
    #[inline]
    pub fn declared_timing(&self) -> RefTiming {
        self.timing
    }

    /// A frame is held for the DUT's start of frame.
    #[inline]
    pub fn awaiting_dut_sof(&self) -> bool {
        self.await_dut_sof
    }

    /// One CAN clock with the DUT's rx, after the DUT's eval: first a held
    /// frame starts if the DUT's tx (`dut_tx`, after the eval) just went
    /// dominant, then everything read from the reference this clock, in
    /// one call.
    #[inline(always)]
    pub fn can_edge(&mut self, dut_rx: bool, dut_tx: bool) -> Option<RefView> {
        if self.await_dut_sof {
            self.start_held_frame_at_dut_sof(dut_tx);
        }
        self.model.as_mut().map(|r| r.step(dut_rx))
    }

    /// `model-waits-bus-free-after-bus-on`: hold the model's next frame
    /// until the DUT's next start of frame (`dut_tx`: its tx now). False
    /// if the model cannot.
    pub fn hold_frame_for_dut_sof(&mut self, dut_tx: bool) -> bool {
        let Some(r) = &mut self.model else { return false };
        let held = r.wait_bus_free_after_bus_on();
        if held {
            self.await_dut_sof = true;
            self.await_prev_dut_tx = dut_tx;
        }
        held
    }

    /// Applies one resync step of a waiver that acts on the reference
    /// (adopt the DUT's counter or register, skip sleep, hold the next
    /// frame for the DUT's SOF; `dut_tx`: its tx now). `None` for a step
    /// that is not the reference's (skipping bits, adopting a counter at its
    /// next read: the comparator's); else whether the reference could.
    pub fn resync(&mut self, step: &Resync, dut_tx: bool) -> Option<bool> {
        let applied = match *step {
            Resync::SkipBits(_) | Resync::AdoptTec(None) | Resync::AdoptRec(None) => return None,
            Resync::ModelWaitsBusFreeAfterBusOn => return Some(self.hold_frame_for_dut_sof(dut_tx)),
            _ if self.model.is_none() => false,
            Resync::AdoptTec(Some(v)) => self.model.as_mut().is_some_and(|r| r.adopt_counters(Some(v), None)),
            Resync::AdoptRec(Some(v)) => self.model.as_mut().is_some_and(|r| r.adopt_counters(None, Some(v))),
            Resync::AdoptRegister { addr, value } => self.model.as_mut().is_some_and(|r| r.adopt_register(addr, value)),
            Resync::ModelSkipsSleep => self.model.as_mut().is_some_and(|r| r.skip_sleep()),
        };
        Some(applied)
    }

    /// The reference's name (for notes).
    pub fn name(&self) -> String {
        self.model.as_ref().map_or_else(|| "no reference".into(), |r| r.name())
    }

    /// At the DUT's first tx falling edge after the resync, the model starts
    /// the frame it holds (if it holds one: its hold is bounded, see the
    /// resync) in the same clock.
    fn start_held_frame_at_dut_sof(&mut self, dut_tx: bool) {
        if self.await_prev_dut_tx && !dut_tx {
            self.await_dut_sof = false;
            if let Some(r) = &mut self.model {
                r.start_held_tx_now();
            }
        }
        self.await_prev_dut_tx = dut_tx;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::types::{Reference, SR_ADDR};

    #[test]
    fn the_declared_timing_follows_the_dut_the_host_and_the_profile() {
        let rtl = Profile::rtl();
        let rtl_wb = RefTiming::for_dut(DutKind::Rtl, HostKind::Wishbone, Some(&rtl));
        assert_eq!(rtl_wb, RefTiming::CanEdges { read: 3, write: 4, command: 4 });
        assert_eq!((rtl_wb.due_edges(false, 1), rtl_wb.due_edges(true, 4), rtl_wb.due_edges(true, 1)), (3, 4, 4));
        assert_eq!(RefTiming::for_dut(DutKind::Model, HostKind::Pio, None), RefTiming::LaunchEdge);
        assert_eq!(
            RefTiming::for_dut(DutKind::Rtl, HostKind::I8051, None),
            RefTiming::CanEdges { read: 8, write: 9, command: 9 }
        );
        assert_eq!(
            RefTiming::for_dut(DutKind::External, HostKind::I8051, None),
            RefTiming::CanEdges { read: 1, write: 1, command: 1 }
        );
        // The seed 000 wiring has no launch, whatever the profile.
        assert_eq!(RefTiming::for_dut(DutKind::Rtl, HostKind::AvalonSeed000, Some(&rtl)), RefTiming::AtAck);
        // No profile: unknown, at the ack.
        assert_eq!(RefTiming::for_dut(DutKind::Other, HostKind::Wishbone, None), RefTiming::AtAck);
        assert_eq!(RefTiming::AtAck.due_edges(true, 1), 0);
    }

    #[test]
    fn without_lockstep_the_access_is_taken_at_the_ack_and_nothing_is_stepped() {
        let t = RefTiming::CanEdges { read: 3, write: 4, command: 4 };
        let mut r = ReferenceAgent::new(None, None, t);
        assert_eq!((r.timing(), r.declared_timing()), (RefTiming::AtAck, t));
        assert_eq!(r.can_edge(true, true), None);
        assert!(!r.hold_frame_for_dut_sof(true));
        let mut r = ReferenceAgent::new(Some(ReferenceChoice::Model), None, t);
        assert_eq!(r.timing(), t);
        let v = r.can_edge(true, true).expect("a view each clock");
        assert_eq!(v.sr, r.model.as_ref().unwrap().peek(SR_ADDR));
    }

    #[test]
    fn a_held_frame_starts_at_the_dut_start_of_frame_and_bits_are_not_the_reference_s() {
        let mut r = ReferenceAgent::new(Some(ReferenceChoice::Model), None, RefTiming::AtAck);
        // Skipping bits and adopting a counter at the next read are not the reference's.
        assert_eq!(r.resync(&Resync::SkipBits(3), true), None);
        assert_eq!(r.resync(&Resync::AdoptTec(None), true), None);
        // No bus-on lately: nothing to hold, and the golden model says so.
        assert_eq!(r.resync(&Resync::ModelWaitsBusFreeAfterBusOn, true), Some(false));
        assert!(!r.awaiting_dut_sof());
        // The golden model adopts a counter.
        assert_eq!(r.resync(&Resync::AdoptRec(Some(9)), true), Some(true));
        assert_eq!(r.model.as_ref().unwrap().counters(), Some((0, 9)));
        // The echo model cannot.
        let mut e = ReferenceAgent::new(Some(ReferenceChoice::Echo), None, RefTiming::AtAck);
        assert_eq!(e.resync(&Resync::AdoptRec(Some(9)), true), Some(false));
    }

    #[test]
    fn the_segment_lag_goes_to_the_model_not_to_the_access_timing() {
        let oc = Profile::find("opencores-can").expect("shipped profile");
        let t = RefTiming::for_dut(DutKind::External, HostKind::Wishbone, Some(&oc));
        assert_eq!(t, RefTiming::CanEdges { read: 3, write: 3, command: 3 });
        let r = ReferenceAgent::new(Some(ReferenceChoice::Model), Some(&oc), t);
        // Every access as declared, BTR1 (7) included.
        assert_eq!((r.due_edges(true, 7), r.due_edges(true, 6), r.due_edges(false, 7), r.due_edges(true, 1)), (3, 3, 3, 3));
        let lag = |r: &ReferenceAgent| match &r.model {
            Some(AnyRef::Model(m)) => m.model().segment_lag(),
            _ => panic!("a model reference"),
        };
        assert_eq!(lag(&r), 2);
        // Our RTL declares none.
        let rtl = Profile::rtl();
        let t = RefTiming::for_dut(DutKind::Rtl, HostKind::Wishbone, Some(&rtl));
        assert_eq!(lag(&ReferenceAgent::new(Some(ReferenceChoice::Model), Some(&rtl), t)), 0);
    }

    #[test]
    fn the_phase_origin_of_the_profile_reaches_the_model() {
        // opencores-can's profile starts the bit timing at the hardware
        // reset, ours at reset-mode exit.
        let p = Profile::find("opencores-can").expect("shipped profile");
        let r = ReferenceAgent::new(Some(ReferenceChoice::Model), Some(&p), RefTiming::AtAck);
        let AnyRef::Model(m) = r.model.as_ref().unwrap() else { panic!("the golden model") };
        assert_eq!(m.model().engine().phase_origin(), PhaseOrigin::HardwareReset);
        let r = ReferenceAgent::new(Some(ReferenceChoice::Model), None, RefTiming::AtAck);
        let AnyRef::Model(m) = r.model.as_ref().unwrap() else { panic!("the golden model") };
        assert_eq!(m.model().engine().phase_origin(), PhaseOrigin::ResetModeExit);
        let r = ReferenceAgent::new(Some(ReferenceChoice::Echo), Some(&p), RefTiming::AtAck);
        assert_eq!(r.model.as_ref().unwrap().name(), EchoModel::new().name());
    }
}
