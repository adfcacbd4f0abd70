//! AXI4-Lite and APB masters against their RAM targets, with their
//! monitors watching, and the monitors against planted violations.

use bfm::{
    ApbConfig, ApbMaster, ApbMasterOut, ApbMonitor, ApbRam, ApbSlaveOut, Axi4LiteConfig, Axi4LiteMaster,
    Axi4LiteMonitor, Axi4LiteRam, AxiMasterOut, AxiSlaveOut, BfmError, HostBusTarget, HostMaster, Rule,
};

fn axi_run(m: &mut Axi4LiteMaster, ram: &mut Axi4LiteRam, mon: &mut Axi4LiteMonitor, h: bfm::OpHandle, cycle: &mut u64) -> Result<bfm::OpResult, BfmError> {
    for _ in 0..5000 {
        if let Some(r) = m.poll(h) {
            return r;
        }
        let o = m.outputs();
        let s = ram.cycle(&o);
        m.on_edge(&s);
        let v = mon.observe(*cycle, &o, &s);
        assert!(v.is_empty(), "a correct master and slave: {v:?}");
        *cycle += 1;
    }
    panic!("never completed");
}

#[test]
fn axi4lite_writes_and_reads_back_at_every_stride_lane_and_channel_order() {
    for (stride, lane) in [(4, 0), (4, 3), (1, 0), (2, 1)] {
        for (aw, w) in [(0, 0), (3, 0), (0, 3)] {
            let cfg = Axi4LiteConfig { stride, byte_lane: lane, aw_delay: aw, w_delay: w, ready_delay: 2, ..Default::default() };
            let (mut m, mut ram) = (Axi4LiteMaster::new("axi", cfg), Axi4LiteRam::new(cfg));
            let mut mon = Axi4LiteMonitor::new("mon", 100);
            let mut c = 0;
            for reg in [4u8, 31, 0] {
                let h = m.start_write(reg, reg ^ 0x5A);
                axi_run(&mut m, &mut ram, &mut mon, h, &mut c).unwrap();
                assert_eq!(ram.mem()[reg as usize], reg ^ 0x5A);
                let h = m.start_read(reg);
                let r = axi_run(&mut m, &mut ram, &mut mon, h, &mut c).unwrap();
                assert_eq!(r.data, reg ^ 0x5A, "stride {stride} lane {lane}");
            }
        }
    }
}

#[test]
fn an_axi_slave_that_never_raises_bvalid_times_out_saying_where_it_stopped() {
    let cfg = Axi4LiteConfig { timeout_cycles: 100, period_ps: 20_000, ..Default::default() };
    let (mut m, mut ram) = (Axi4LiteMaster::new("axi", cfg), Axi4LiteRam::new(cfg));
    ram.never_bvalid = true;
    let h = m.start_write(4, 1);
    let r = bfm::run_op(&mut m, h, |o| ram.cycle(o));
    let Err(e @ BfmError::Stopped { .. }) = r else { panic!("{r:?}") };
    let s = e.to_string();
    assert!(s.contains("AW accepted at 60 ns, W at 60 ns, BVALID never raised"), "{s}");
}

#[test]
fn the_axi_monitor_names_each_broken_rule() {
    let mut mon = Axi4LiteMonitor::new("mon", 3);
    let idle = AxiSlaveOut::default();
    let aw = AxiMasterOut { awvalid: true, awaddr: 16, ..Default::default() };
    // Cycle 0: AWVALID without AWREADY; cycle 1: address changes; cycle 2: AWVALID drops.
    assert!(mon.observe(0, &aw, &idle).is_empty());
    let v = mon.observe(1, &AxiMasterOut { awaddr: 20, ..aw }, &idle);
    assert_eq!(v.iter().map(|x| x.rule).collect::<Vec<_>>(), vec![Rule::ChangedWhileValid]);
    let v = mon.observe(2, &AxiMasterOut::default(), &AxiSlaveOut { bvalid: true, ..idle });
    assert_eq!(v.iter().map(|x| x.rule).collect::<Vec<_>>(), vec![Rule::ValidDroppedBeforeReady]);
    assert!(v[0].message.starts_with("AWVALID fell before AWREADY"), "{}", v[0].message);
    // Cycle 3: BVALID on the wires (driven after cycle 2) with no write accepted.
    let v = mon.observe(3, &AxiMasterOut { bready: true, ..Default::default() }, &idle);
    assert!(v.iter().any(|x| x.rule == Rule::ResponseWithoutRequest), "{v:?}");
    // ARVALID waiting more than 3 cycles.
    let ar = AxiMasterOut { arvalid: true, ..Default::default() };
    let mut all = Vec::new();
    for c in 4..10 {
        all.extend(mon.observe(c, &ar, &idle));
    }
    assert_eq!(all.iter().filter(|x| x.rule == Rule::HandshakeStuck).count(), 1, "{all:?}");
    // An error response is named.
    let mut mon = Axi4LiteMonitor::new("mon", 100);
    mon.observe(0, &ar, &AxiSlaveOut { arready: true, ..idle });
    mon.observe(1, &ar, &AxiSlaveOut { rvalid: true, rresp: 2, ..idle });
    let v = mon.observe(2, &AxiMasterOut { rready: true, ..Default::default() }, &idle);
    assert!(v.iter().any(|x| x.rule == Rule::ErrorResponse && x.message.contains("SLVERR")), "{v:?}");
}

fn apb_run(m: &mut ApbMaster, ram: &mut ApbRam, mon: &mut ApbMonitor, h: bfm::OpHandle, cycle: &mut u64) -> bfm::OpResult {
    for _ in 0..5000 {
        if let Some(r) = m.poll(h) {
            return r.unwrap();
        }
        let o = m.outputs();
        let s = ram.cycle(&o);
        m.on_edge(&s);
        let v = mon.observe(*cycle, &o, &s);
        assert!(v.is_empty(), "a correct requester and completer: {v:?}");
        *cycle += 1;
    }
    panic!("never completed");
}

#[test]
fn apb3_and_apb4_write_and_read_back_with_wait_states() {
    for apb4 in [false, true] {
        for (wait, lane, stride) in [(0, 0, 4), (3, 2, 4), (1, 0, 1)] {
            let cfg = ApbConfig { apb4, byte_lane: lane, stride, idle_cycles: 1, ..Default::default() };
            let (mut m, mut ram) = (ApbMaster::new("apb", cfg), ApbRam::new(cfg));
            ram.wait = wait;
            let mut mon = ApbMonitor::new("mon", apb4, 100);
            let mut c = 0;
            for reg in [1u8, 17, 30] {
                let h = m.start_write(reg, 0xC0 | reg);
                let w = apb_run(&mut m, &mut ram, &mut mon, h, &mut c);
                // Setup, access with `wait` wait states, the PREADY cycle.
                assert!(w.cycles >= 2 + wait as u64, "{w:?}");
                let h = m.start_read(reg);
                assert_eq!(apb_run(&mut m, &mut ram, &mut mon, h, &mut c).data, 0xC0 | reg);
            }
        }
    }
}

#[test]
fn an_apb_slave_holding_pready_low_times_out_in_the_access_phase() {
    let cfg = ApbConfig { timeout_cycles: 1000, ..Default::default() };
    let (mut m, mut ram) = (ApbMaster::new("apb", cfg), ApbRam::new(cfg));
    ram.stuck = true;
    let mut mon = ApbMonitor::new("mon", true, 500);
    let h = m.start_read(3);
    let mut viol = Vec::new();
    let mut c = 0;
    let r = bfm::run_op(&mut m, h, |o| {
        let s = ram.cycle(o);
        viol.extend(mon.observe(c, o, &s));
        c += 1;
        s
    });
    let Err(e) = r else { panic!("{r:?}") };
    assert!(e.to_string().contains("APB access phase (from cycle 2): PREADY low for 999 host clocks"), "{e}");
    assert!(viol.iter().any(|v| v.rule == Rule::HandshakeStuck && v.message.starts_with("APB access phase: PREADY low for 500 host clocks")), "{viol:?}");
}

#[test]
fn the_apb_monitor_names_each_broken_rule() {
    let idle = ApbSlaveOut::default();
    let setup = ApbMasterOut { psel: true, paddr: 8, pwrite: true, pwdata: 1, pstrb: 1, ..Default::default() };
    let access = ApbMasterOut { penable: true, ..setup };
    let rules = |v: Vec<bfm::Violation>| v.into_iter().map(|x| x.rule).collect::<Vec<_>>();
    let mut mon = ApbMonitor::new("mon", true, 100);
    assert_eq!(rules(mon.observe(0, &access, &idle)), vec![Rule::PhaseOrder]);
    let mut mon = ApbMonitor::new("mon", true, 100);
    assert!(mon.observe(0, &setup, &idle).is_empty());
    assert_eq!(rules(mon.observe(1, &ApbMasterOut { pwdata: 2, ..access }, &idle)), vec![Rule::ChangedWhileValid]);
    assert_eq!(rules(mon.observe(2, &ApbMasterOut::default(), &idle)), vec![Rule::ValidDroppedBeforeReady]);
    let mut mon = ApbMonitor::new("mon", true, 100);
    mon.observe(0, &setup, &ApbSlaveOut { pready: true, pslverr: true, ..idle });
    assert_eq!(rules(mon.observe(1, &access, &idle)), vec![Rule::ErrorResponse]);
    let mut mon = ApbMonitor::new("mon", true, 100);
    let read = ApbMasterOut { pwrite: false, pstrb: 1, ..setup };
    assert_eq!(rules(mon.observe(0, &read, &idle)), vec![Rule::ChangedWhileValid]);
    // APB3 has no PSTRB: not checked.
    let mut mon = ApbMonitor::new("mon", false, 100);
    assert!(mon.observe(0, &read, &idle).is_empty());
}
