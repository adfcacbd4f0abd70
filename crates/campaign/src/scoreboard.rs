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
//!    sleep, no release without a read, no bus-off, no fault, the DUT not
//!    the sender), every frame a model node sent that the filter accepts and
//!    that was complete before the program's final drain is read out,
//!    unless the run saw a data overrun (SR.DOS or IR.DOI read as 1: the
//!    model had it too, reads are compared).

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
            // Under faults the log can miss a repetition (see above): order
            // is judged on fault-free runs only.
            if plan.faults.is_empty() {
                problems.push(format!("message read at bit {bit}: {} out of bus order", show(f)));
            }
        } else if !planned.contains(f) {
            problems.push(format!("message read at bit {bit}: {} which the bus never carried whole and no node sent", show(f)));
        }
        last = Some(*f);
    }
    // Rule 2: nothing owed went missing.
    // A release without a read (`release`) discards messages unseen.
    let quiet = !plan.program.iter().any(|o| matches!(o, HostOp::ResetToggle { .. } | HostOp::Sleep { .. } | HostOp::Release(_)));
    let bus_off = record.events.iter().any(|e| matches!(e.kind, diagnose::EventKind::FaultState(sja1000::FaultState::BusOff)));
    let overrun = record.host_ops.iter().any(|o| {
        o.access == Access::Read && ((o.addr == 2 && o.data & 0x02 != 0) || (o.addr == 3 && o.data & 0x08 != 0))
    });
    // Owed: frames complete before the final drain began (the program's
    // tail: abort, wait, drain); a frame that ends later is not owed.
    let cutoff = final_drain_start(plan, record);
    if quiet && !bus_off && !overrun && plan.faults.is_empty()
        && let Some(cutoff) = cutoff
    {
        let dut_frames: Vec<CanFrame> = plan
            .program
            .iter()
            .filter_map(|o| match o {
                HostOp::Transmit { frame, .. } => Some(frame.to_can()),
                _ => None,
            })
            .collect();
        let node_frames: Vec<CanFrame> = plan.nodes.iter().flat_map(|n| n.frames.iter().map(|(_, f)| f.to_can())).collect();
        let owed: Vec<CanFrame> = bus_log
            .iter()
            .filter(|e| e.t_ps < cutoff)
            .filter_map(|e| match &e.kind {
                LogKind::Frame(f) if plan.config.accepts(f) => Some(*f),
                _ => None,
            })
            .collect();
        for f in &owed {
            let from_a_node = node_frames.contains(f) && !dut_frames.contains(f);
            if from_a_node && !delivered.iter().any(|(_, d)| d == f) {
                problems.push(format!("{} completed on the bus, passes the filter, and was never read out (no overrun seen)", show(f)));
            }
        }
    }
    problems
}

/// When the program's final drain began: the first host access after its
/// tail's abort (`crate::plan::TAIL`); `None` when the plan has no tail
/// (a shrunk plan may lose it), and then nothing is owed.
fn final_drain_start(plan: &Plan, record: &RunRecord) -> Option<u64> {
    if !crate::plan::has_tail(&plan.program) {
        return None;
    }
    let abort = record.host_ops.iter().rposition(|o| o.access == Access::Write && o.addr == 1 && o.data == 0x02)?;
    record.host_ops.get(abort + 1).map(|o| o.time_ps)
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
        p.program = crate::plan::TAIL.to_vec();
        p.faults.clear();
        p.nodes.truncate(1);
        p.nodes[0].frames = vec![(40, frame(0x10)), (300, frame(0x20))];
        p
    }

    /// A record whose final drain starts at t = 1000 ps (after the log's frames).
    fn drained() -> RunRecord {
        let mut r = RunRecord::default();
        r.host_ops.push(diagnose::HostOp { access: Access::Write, addr: 1, data: 0x02, time_ps: 10, ..Default::default() });
        r.host_ops.push(diagnose::HostOp { access: Access::Read, addr: 2, data: 0x0C, time_ps: 1000, ..Default::default() });
        r
    }

    fn log(frames: &[PlanFrame]) -> Vec<LogEntry> {
        frames.iter().enumerate().map(|(i, f)| LogEntry { t_ps: i as u64, kind: LogKind::Frame(f.to_can()) }).collect()
    }

    #[test]
    fn in_order_and_complete_is_clean() {
        let p = plan_open();
        let d = vec![(100, frame(0x10).to_can()), (400, frame(0x20).to_can())];
        assert!(check(&p, &log(&[frame(0x10), frame(0x20)]), &d, &drained()).is_empty());
    }

    #[test]
    fn a_lost_a_reordered_and_an_invented_message_are_each_caught() {
        let p = plan_open();
        let bus = log(&[frame(0x10), frame(0x20)]);
        let lost = check(&p, &bus, &[(100, frame(0x10).to_can())], &drained());
        assert!(lost.iter().any(|m| m.contains("never read out")), "{lost:?}");
        let swapped = check(&p, &bus, &[(100, frame(0x20).to_can()), (400, frame(0x10).to_can())], &drained());
        assert!(swapped.iter().any(|m| m.contains("out of bus order")), "{swapped:?}");
        let invented = check(&p, &bus, &[(100, frame(0x30).to_can())], &drained());
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
        assert!(check(&p, &bus, &[(100, frame(0x10).to_can())], &drained()).is_empty());
        let leak = check(&p, &bus, &[(100, frame(0x10).to_can()), (400, frame(0x20).to_can())], &drained());
        assert!(leak.iter().any(|m| m.contains("filter rejects")), "{leak:?}");
    }

    #[test]
    fn a_frame_after_the_final_drain_or_without_one_is_not_owed() {
        let p = plan_open();
        let mut late = log(&[frame(0x10), frame(0x20)]);
        late[1].t_ps = 5000;
        assert!(check(&p, &late, &[(100, frame(0x10).to_can())], &drained()).is_empty());
        let mut q = plan_open();
        q.program = vec![HostOp::Drain(64)];
        assert!(check(&q, &log(&[frame(0x10), frame(0x20)]), &[(100, frame(0x10).to_can())], &drained()).is_empty());
    }

    #[test]
    fn a_loss_under_an_overrun_is_allowed_and_a_repeat_is_not_a_fault() {
        let p = plan_open();
        let bus = log(&[frame(0x10), frame(0x20)]);
        let mut r = drained();
        r.host_ops.push(diagnose::HostOp { access: Access::Read, addr: 2, data: 0x03, time_ps: 2000, ..Default::default() });
        assert!(check(&p, &bus, &[(100, frame(0x10).to_can())], &r).is_empty());
        let twice = [(100, frame(0x10).to_can()), (101, frame(0x10).to_can()), (400, frame(0x20).to_can())];
        assert!(check(&p, &bus, &twice, &drained()).is_empty());
    }
}
