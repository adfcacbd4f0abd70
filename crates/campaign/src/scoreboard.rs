//! The scoreboard: what the filters and the FIFO owe the host, judged
//! from the run's bus log and the messages the host read out, apart from
//! the lockstep comparator (which judges the DUT against the model, read
//! by read; the scoreboard also catches a model and a DUT wrong together).
//!
//! 1. Every message read out is one the DUT's filter accepts, and a frame
//!    the bus carried (the bus log's completed frames) or one a sender was
//!    asked to send; among the bus log's frames, in bus order. The same
//!    frame twice in a row is allowed (CAN 2.0B §7.2: a receiver takes a
//!    frame whose last EOF bit is dominant, the transmitter repeats it).
//!    A planned frame missing from the log is not a fault: the log is
//!    decoded from the wired-AND level before the fault injectors, so a
//!    flipped bit that every node saw can make the observer's decoder lose
//!    a frame the nodes received.
//! 2. Where nothing else can take a frame away (no reset-mode toggle, no
//!    sleep, no bus-off, no fault, the DUT not the sender), every frame a
//!    model node sent that the filter accepts is read out, unless the run
//!    saw a data overrun (SR.DOS or IR.DOI read as 1: the model had it too,
//!    reads are compared).

use crate::plan::{HostOp, Plan};
use can_proto::CanFrame;
use cosim::candump::{LogEntry, LogKind};
use diagnose::{Access, RunRecord};

/// What the scoreboard found wrong, in words.
pub fn check(plan: &Plan, bus_log: &[LogEntry], delivered: &[(u64, CanFrame)], record: &RunRecord) -> Vec<String> {
    let mut problems = Vec::new();
    let accepted: Vec<CanFrame> = bus_log
        .iter()
        .filter_map(|e| match &e.kind {
            LogKind::Frame(f) if plan.config.accepts(f) => Some(*f),
            _ => None,
        })
        .collect();
    // Rule 1: delivered frames, in bus order.
    let planned: Vec<CanFrame> = plan
        .nodes
        .iter()
        .flat_map(|n| n.frames.iter().map(|(_, f)| f.to_can()))
        .chain(plan.program.iter().filter_map(|o| match o {
            HostOp::Transmit { frame, .. } => Some(frame.to_can()),
            _ => None,
        }))
        .collect();
    let mut at = 0usize;
    let mut last: Option<CanFrame> = None;
    for (bit, f) in delivered {
        if !plan.config.accepts(f) {
            problems.push(format!("message read at bit {bit}: {} which the acceptance filter rejects", show(f)));
        } else if let Some(k) = accepted[at..].iter().position(|a| a == f) {
            at += k + 1;
        } else if last == Some(*f) {
            // The same frame again (repeated after an error in the last EOF bit).
        } else if accepted.contains(f) {
            problems.push(format!("message read at bit {bit}: {} out of bus order", show(f)));
        } else if !planned.contains(f) {
            problems.push(format!("message read at bit {bit}: {} which the bus never carried whole and no node sent", show(f)));
        }
        last = Some(*f);
    }
    // Rule 2: nothing owed went missing.
    let quiet = !plan.program.iter().any(|o| matches!(o, HostOp::ResetToggle { .. } | HostOp::Sleep { .. }));
    let bus_off = record.events.iter().any(|e| matches!(e.kind, diagnose::EventKind::FaultState(sja1000::FaultState::BusOff)));
    let overrun = record.host_ops.iter().any(|o| {
        o.access == Access::Read && ((o.addr == 2 && o.data & 0x02 != 0) || (o.addr == 3 && o.data & 0x08 != 0))
    });
    if quiet && !bus_off && !overrun && plan.faults.is_empty() {
        let dut_frames: Vec<CanFrame> = plan
            .program
            .iter()
            .filter_map(|o| match o {
                HostOp::Transmit { frame, .. } => Some(frame.to_can()),
                _ => None,
            })
            .collect();
        let node_frames: Vec<CanFrame> = plan.nodes.iter().flat_map(|n| n.frames.iter().map(|(_, f)| f.to_can())).collect();
        for f in &accepted {
            let from_a_node = node_frames.contains(f) && !dut_frames.contains(f);
            if from_a_node && !delivered.iter().any(|(_, d)| d == f) {
                problems.push(format!("{} completed on the bus, passes the filter, and was never read out (no overrun seen)", show(f)));
            }
        }
    }
    problems
}

fn show(f: &CanFrame) -> String {
    use can_proto::FrameTrait;
    let data: Vec<String> = f.data().iter().map(|b| format!("{b:02X}")).collect();
    format!(
        "{} 0x{:X}{} DLC {} [{}]",
        if f.is_extended() { "EFF" } else { "SFF" },
        f.raw_id(),
        if f.is_remote_frame() { " remote" } else { "" },
        f.dlc_raw(),
        data.join(" ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{DrawLimits, PlanFrame, draw};

    fn frame(id: u32) -> PlanFrame {
        PlanFrame { id, extended: false, rtr: false, dlc: 1, data: vec![id as u8] }
    }

    fn plan_open() -> Plan {
        let mut p = draw(1, 0, &DrawLimits::default());
        p.config.pelican = true;
        p.config.acr = [0; 4];
        p.config.amr = [0xFF; 4];
        p.program = vec![HostOp::Drain(64)];
        p.faults.clear();
        p.nodes.truncate(1);
        p.nodes[0].frames = vec![(40, frame(0x10)), (300, frame(0x20))];
        p
    }

    fn log(frames: &[PlanFrame]) -> Vec<LogEntry> {
        frames.iter().enumerate().map(|(i, f)| LogEntry { t_ps: i as u64, kind: LogKind::Frame(f.to_can()) }).collect()
    }

    #[test]
    fn in_order_and_complete_is_clean() {
        let p = plan_open();
        let d = vec![(100, frame(0x10).to_can()), (400, frame(0x20).to_can())];
        assert!(check(&p, &log(&[frame(0x10), frame(0x20)]), &d, &RunRecord::default()).is_empty());
    }

    #[test]
    fn a_lost_a_reordered_and_an_invented_message_are_each_caught() {
        let p = plan_open();
        let bus = log(&[frame(0x10), frame(0x20)]);
        let lost = check(&p, &bus, &[(100, frame(0x10).to_can())], &RunRecord::default());
        assert!(lost.iter().any(|m| m.contains("never read out")), "{lost:?}");
        let swapped = check(&p, &bus, &[(100, frame(0x20).to_can()), (400, frame(0x10).to_can())], &RunRecord::default());
        assert!(swapped.iter().any(|m| m.contains("out of bus order")), "{swapped:?}");
        let invented = check(&p, &bus, &[(100, frame(0x30).to_can())], &RunRecord::default());
        assert!(invented.iter().any(|m| m.contains("never carried")), "{invented:?}");
    }

    #[test]
    fn a_filtered_frame_must_not_be_delivered_and_is_not_owed() {
        let mut p = plan_open();
        p.config.single_filter = true;
        // Only identifier 0x10 passes: ACR0..1 hold ID.10..3 / ID.2..0, all compared but the data bytes.
        p.config.acr = [0x10 >> 3, (0x10 & 7) << 5, 0, 0];
        p.config.amr = [0x00, 0x1F, 0xFF, 0xFF];
        let bus = log(&[frame(0x10), frame(0x20)]);
        assert!(check(&p, &bus, &[(100, frame(0x10).to_can())], &RunRecord::default()).is_empty());
        let leak = check(&p, &bus, &[(100, frame(0x10).to_can()), (400, frame(0x20).to_can())], &RunRecord::default());
        assert!(leak.iter().any(|m| m.contains("filter rejects")), "{leak:?}");
    }

    #[test]
    fn a_loss_under_an_overrun_is_allowed_and_a_repeat_is_not_a_fault() {
        let p = plan_open();
        let bus = log(&[frame(0x10), frame(0x20)]);
        let mut r = RunRecord::default();
        r.host_ops.push(diagnose::HostOp { access: Access::Read, addr: 2, data: 0x03, ..Default::default() });
        assert!(check(&p, &bus, &[(100, frame(0x10).to_can())], &r).is_empty());
        let twice = [(100, frame(0x10).to_can()), (101, frame(0x10).to_can()), (400, frame(0x20).to_can())];
        assert!(check(&p, &bus, &twice, &RunRecord::default()).is_empty());
    }
}
