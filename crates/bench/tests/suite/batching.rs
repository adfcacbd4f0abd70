//! The test bench's batches (instants made inside the Verilated model while
//! only the clocks and the DUT's own tx drive it, then replayed) change
//! nothing: the same run record, cycle for cycle, with and without them, on
//! the bench's self-test workload with the lockstep comparator, with one
//! clock and with the DE2's two clocks; and the comparator compared as
//! many sample points and reads.

use bench::cosim_run::{CLOCK_HZ, CosimHost, DE2_HOST_HZ};
use bench::workload;

type Counts = (u64, u64, u64, u64, u64);

fn run(host_hz: u64, batching: bool) -> (workload::SelfTestOutcome, (u64, u64), String, Counts) {
    let mut h = CosimHost::with_host_clock(true, host_hz).expect("bench test bench");
    h.set_batching(batching);
    let out = workload::run(&mut h, 3, 7).expect("self-test workload");
    let rec = serde_json::to_string(&h.record()).expect("record as JSON");
    let c = h.comparator().expect("lockstep");
    let counts = (c.compared_bits, c.compared_reads, c.tolerated_reads, c.repeated, c.cascade);
    (out, (h.cycles(), h.host_cycles()), rec, counts)
}

#[test]
fn batches_give_the_same_record_as_instant_by_instant() {
    for host_hz in [CLOCK_HZ, DE2_HOST_HZ] {
        let (a_out, a_cycles, a_rec, a_counts) = run(host_hz, true);
        let (b_out, b_cycles, b_rec, b_counts) = run(host_hz, false);
        assert_eq!(a_out.frames, 3);
        assert_eq!(a_out.errors, 0);
        assert_eq!((a_out, a_cycles), (b_out, b_cycles), "host clock {host_hz} Hz");
        assert!(
            a_rec.contains("\"host_ops\"") && a_rec.len() > 1000,
            "the record has content"
        );
        assert!(a_rec == b_rec, "host clock {host_hz} Hz: the records differ");
        // Every frame's sample points were compared, on both paths alike.
        assert!(a_counts.0 > 3 * 100, "host clock {host_hz} Hz: {a_counts:?}");
        assert_eq!(a_counts, b_counts, "host clock {host_hz} Hz: compared, tolerated, repeated, cascade");
    }
}
