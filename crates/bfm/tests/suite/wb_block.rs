//! Wishbone block cycles (B4 §3.3, classic): the master holds CYC and STB
//! from the first transfer to the last ack, puts each next transfer on the
//! wires at the edge that samples the previous ack, and gives up the block
//! when a transfer fails; the cycle shape is checked pin by pin.

use bfm::{
    AckMode, BfmError, BlockAccess, HostBusTarget, HostMaster, OpHandle, OpKind, WbMasterOut,
    WbSlaveOut, WishboneMaster, WishboneMonitor, WishboneRam,
};

/// One host cycle of the record: the master's pins and the slave's outputs
/// after that cycle's edge.
type Cycle = (WbMasterOut, WbSlaveOut);

/// Steps `m` against `t` (the crate's stepping contract) until every handle
/// has a result, at most `limit` cycles; returns the results and the cycles.
/// The Wishbone monitor must see no violation.
fn run<T: HostBusTarget>(
    m: &mut WishboneMaster,
    t: &mut T,
    handles: &[OpHandle],
    limit: usize,
) -> (Vec<Result<bfm::OpResult, BfmError>>, Vec<Cycle>) {
    let (r, trace, v) = run_watched(m, t, handles, limit);
    assert!(v.is_empty(), "the monitor flags a block cycle: {v:?}");
    (r, trace)
}

/// [`run`], returning the monitor's violations.
fn run_watched<T: HostBusTarget>(
    m: &mut WishboneMaster,
    t: &mut T,
    handles: &[OpHandle],
    limit: usize,
) -> (Vec<Result<bfm::OpResult, BfmError>>, Vec<Cycle>, Vec<bfm::Violation>) {
    let mut violations = Vec::new();
    let mut mon = WishboneMonitor::new("wbmon", 100);
    let mut results: Vec<Option<Result<bfm::OpResult, BfmError>>> = vec![None; handles.len()];
    let mut trace = Vec::new();
    for cycle in 0..limit {
        for (h, r) in handles.iter().zip(results.iter_mut()) {
            if r.is_none() {
                *r = m.poll(*h);
            }
        }
        if results.iter().all(Option::is_some) {
            break;
        }
        let pins = m.outputs();
        let s = t.cycle(&pins);
        violations.extend(mon.observe(cycle as u64, &pins, &s));
        m.on_edge(&s);
        trace.push((pins, s));
    }
    let results = results.into_iter().map(|r| r.expect("every transfer ends")).collect();
    (results, trace, violations)
}

/// The cycles from the first with STB to the last ack (inclusive).
fn block_span(trace: &[Cycle]) -> &[Cycle] {
    let first = trace.iter().position(|(m, _)| m.stb).expect("a transfer was driven");
    let last = trace.iter().rposition(|(_, s)| s.ack).expect("an ack came");
    &trace[first..=last]
}

#[test]
fn a_block_holds_cyc_and_stb_and_changes_the_transfer_after_each_ack() {
    let mut m = WishboneMaster::new("wb");
    let mut ram = WishboneRam::new("ram");
    ram.mem_mut()[0x20] = 0x5A;
    let block = [
        BlockAccess::write(0x10, 0xA1),
        BlockAccess::write(0x11, 0xB2),
        BlockAccess::read(0x20),
        BlockAccess::read(0x10),
        BlockAccess::write(0x12, 0xC3),
    ];
    let handles = m.start_block(&block);
    let (results, trace) = run(&mut m, &mut ram, &handles, 100);
    let data: Vec<u8> = results.iter().map(|r| r.as_ref().unwrap().data).collect();
    assert_eq!(data, [0xA1, 0xB2, 0x5A, 0xA1, 0xC3], "each transfer did its own access");
    assert_eq!(&ram.mem()[0x10..0x13], &[0xA1, 0xB2, 0xC3]);
    assert_eq!(ram.accesses(), 5, "one access per transfer");

    let span = block_span(&trace);
    assert!(span.iter().all(|(p, _)| p.cyc && p.stb), "CYC and STB held through the block: {span:?}");
    let acks: Vec<usize> = span.iter().enumerate().filter(|(_, (_, s))| s.ack).map(|(i, _)| i).collect();
    assert_eq!(acks.len(), 5, "one ack per transfer");
    // `s` is the slave's output after its cycle's edge, so the ack of entry
    // `j` is on the wires during cycle `j + 1`; the master samples it at the
    // edge ending that cycle and drives the next transfer from cycle `j + 2`:
    // the transfer changes exactly there, and at no other time.
    let mut expected = 0;
    for (i, (p, _)) in span.iter().enumerate() {
        if i > 1 && acks.contains(&(i - 2)) {
            expected += 1;
        }
        let b = block[expected];
        assert_eq!((p.we, p.adr), (b.write, b.addr), "cycle {i} of the block");
        if b.write {
            assert_eq!(p.dat, b.data, "cycle {i} of the block");
        }
    }
    assert_eq!(expected, 4);
    // Afterwards the bus is released.
    let idle = m.outputs();
    assert!(!idle.cyc && !idle.stb);
}

#[test]
fn single_accesses_drop_stb_between_transfers_a_block_does_not() {
    // The same two writes queued one at a time after each other completed
    // (what the scenario runner does outside a block): an idle cycle between.
    let mut m = WishboneMaster::new("wb");
    let mut ram = WishboneRam::new("ram");
    let mut trace = Vec::new();
    for (a, d) in [(1u8, 2u8), (3, 4)] {
        let h = m.start_write(a, d);
        let (_, t) = run(&mut m, &mut ram, &[h], 20);
        trace.extend(t);
    }
    let first = trace.iter().position(|(p, _)| p.stb).unwrap();
    let last = trace.iter().rposition(|(p, _)| p.stb).unwrap();
    assert!(
        trace[first..=last].iter().any(|(p, _)| !p.stb),
        "single accesses leave STB low between transfers"
    );
}

#[test]
fn a_slave_that_keeps_ack_high_acknowledges_the_next_transfer_without_doing_it() {
    // AckMode::Level serves once per STB assertion and keeps ack high while
    // STB stays up: right for a four-phase GPIO handshake, wrong inside a
    // block. The block shows it (the second write never lands, the read
    // returns the first transfer's data); single accesses would not.
    let mut m = WishboneMaster::new("wb");
    let mut ram = WishboneRam::new("ram").with_ack_mode(AckMode::Level);
    ram.mem_mut()[0x30] = 0x77;
    let handles = m.start_block(&[BlockAccess::read(0x30), BlockAccess::write(0x31, 0x99), BlockAccess::read(0x32)]);
    let (results, trace) = run(&mut m, &mut ram, &handles, 100);
    assert!(results.iter().all(Result::is_ok), "every transfer is acknowledged: {results:?}");
    assert_eq!(ram.mem()[0x31], 0x00, "the second transfer was acknowledged but never done");
    assert_eq!(ram.accesses(), 1, "one access for three acks");
    assert_eq!(results[2].as_ref().unwrap().data, 0x77, "the third read returns stale data");
    let span = block_span(&trace);
    assert!(span.iter().all(|(p, _)| p.cyc && p.stb));
}

#[test]
fn a_slave_that_stops_acknowledging_inside_a_block_ends_in_a_timeout_and_the_rest_is_abandoned() {
    /// Acks the first transfer, never another (a hung slave).
    struct AckOnce(WishboneRam, bool);
    impl HostBusTarget for AckOnce {
        fn cycle(&mut self, m: &WbMasterOut) -> WbSlaveOut {
            let s = self.0.cycle(m);
            if s.ack && self.1 {
                return WbSlaveOut { ack: false, ..s };
            }
            self.1 |= s.ack;
            s
        }
    }
    let mut m = WishboneMaster::new("wb").with_timeout(40);
    let mut t = AckOnce(WishboneRam::new("ram"), false);
    let handles = m.start_block(&[BlockAccess::write(1, 1), BlockAccess::write(2, 2), BlockAccess::read(3)]);
    let after = m.start_write(4, 4);
    let mut all = handles.clone();
    all.push(after);
    let (results, _, violations) = run_watched(&mut m, &mut t, &all, 500);
    // The monitor reports the abandoned transfer (and the later one's).
    assert!(
        violations.iter().any(|v| v.rule == bfm::Rule::CycDroppedBeforeAck && v.message.contains("write at 0x02")),
        "{violations:?}"
    );
    assert!(results[0].is_ok());
    assert_eq!(results[1], Err(BfmError::Timeout { op: OpKind::Write, addr: 2, cycles: 40 }));
    assert_eq!(results[2], Err(BfmError::BlockAbandoned { op: OpKind::Read, addr: 3 }));
    assert!(
        results[2].as_ref().unwrap_err().to_string().contains("earlier transfer of its block cycle failed"),
        "the diagnosis names the block"
    );
    // An access queued after the block is a new cycle, and times out too.
    assert!(matches!(results[3], Err(BfmError::Timeout { addr: 4, .. })));
    assert_eq!(m.in_flight(), 0);
}

#[test]
fn a_reset_flushes_a_block() {
    let mut m = WishboneMaster::new("wb");
    let mut ram = WishboneRam::new("ram");
    let handles = m.start_block(&[BlockAccess::write(1, 1), BlockAccess::write(2, 2)]);
    let s = ram.cycle(&m.outputs());
    m.on_edge(&s);
    m.reset();
    for h in handles {
        assert!(matches!(m.poll(h), Some(Err(BfmError::Flushed { .. }))));
    }
    // A later block starts afresh.
    let handles = m.start_block(&[BlockAccess::write(5, 6), BlockAccess::read(5)]);
    let (results, _) = run(&mut m, &mut ram, &handles, 50);
    assert_eq!(results[1].as_ref().unwrap().data, 6);
}

#[test]
fn the_pause_generator_idles_before_a_block_never_inside_it() {
    let mut m = WishboneMaster::new("wb");
    m.set_pause(Some(bfm::cycle_pause()));
    let mut ram = WishboneRam::new("ram");
    let handles = m.start_block(&[BlockAccess::write(1, 1), BlockAccess::write(2, 2), BlockAccess::write(3, 3)]);
    let (results, trace) = run(&mut m, &mut ram, &handles, 100);
    assert!(results.iter().all(Result::is_ok));
    assert!(block_span(&trace).iter().all(|(p, _)| p.cyc && p.stb), "no idle cycle inside the block");
    // The same writes one by one do get idle cycles between them.
    let mut trace = Vec::new();
    for a in 4..7u8 {
        let h = m.start_write(a, a);
        trace.extend(run(&mut m, &mut ram, &[h], 50).1);
    }
    let first = trace.iter().position(|(p, _)| p.stb).unwrap();
    assert!(trace[first..].iter().filter(|(p, _)| !p.stb).count() >= 3);
}
