//! Register port: the master against a RAM port of a given read latency
//! (0 = combinational) under the monitor, with one or separate addresses;
//! a port whose data comes late is named.

use bfm::{HostMaster, RegportConfig, RegportIn, RegportMaster, RegportMonitor, RegportOut, Rule, Violation};

/// A 256-byte RAM port: writes at the strobe's edge, read data `latency`
/// clocks after the read strobe (0: combinational from `rd_adr`).
struct Ram {
    mem: [u8; 256],
    latency: u32,
    pipe: Vec<Option<u8>>,
    rdat: u8,
}

impl Ram {
    fn new(latency: u32) -> Self {
        Ram { mem: [0; 256], latency, pipe: vec![None; latency.saturating_sub(1) as usize], rdat: 0 }
    }
    /// One clock: the pins during it; returns the port after its edge.
    fn cycle(&mut self, m: &RegportOut) -> RegportIn {
        if m.wr {
            self.mem[m.wr_adr as usize] = m.wdat;
        }
        if self.latency == 0 {
            return RegportIn { rdat: self.mem[m.rd_adr as usize] };
        }
        self.pipe.push(m.rd.then(|| self.mem[m.rd_adr as usize]));
        if let Some(Some(d)) = Some(self.pipe.remove(0)) {
            self.rdat = d;
        }
        // the value registered `latency` edges after the strobe
        RegportIn { rdat: self.rdat }
    }
}

fn run(cfg: RegportConfig, ram_latency: u32, ops: &[(bool, u8, u8)]) -> (Vec<u8>, Vec<Violation>) {
    let mut m = RegportMaster::new("host", cfg);
    let mut mon = RegportMonitor::new("mon", cfg);
    let mut ram = Ram::new(ram_latency);
    let hs: Vec<_> = ops.iter().map(|&(w, a, d)| if w { m.start_write(a, d) } else { m.start_read(a) }).collect();
    let mut v = Vec::new();
    for c in 0..400 {
        let o = m.outputs();
        let s = ram.cycle(&o);
        m.on_edge(&s);
        v.extend(mon.observe(c, &o, &s));
    }
    let data = hs.into_iter().map(|h| m.poll(h).unwrap().unwrap().data).collect();
    (data, v)
}

const OPS: [(bool, u8, u8); 4] = [(true, 7, 0x5A), (true, 8, 0xC3), (false, 7, 0), (false, 8, 0)];

#[test]
fn reads_see_the_writes_at_every_latency_and_either_address_style() {
    for latency in [0u32, 1, 3, 10] {
        for separate_addr in [true, false] {
            for strobe in [1u32, 2] {
                let cfg = RegportConfig { read_latency: latency, separate_addr, strobe, gap: 1, ..Default::default() };
                let (d, v) = run(cfg, latency, &OPS);
                assert_eq!(&d[2..], &[0x5A, 0xC3], "latency {latency} separate {separate_addr} strobe {strobe}");
                assert!(v.is_empty(), "{v:?}");
            }
        }
    }
}

#[test]
fn a_port_slower_than_the_hosts_latency_is_named_in_one_sentence() {
    let cfg = RegportConfig { read_latency: 2, gap: 8, ..Default::default() };
    let (d, v) = run(cfg, 5, &OPS);
    assert_ne!(d[2], 0x5A, "sampled before the data");
    let late: Vec<&Violation> = v.iter().filter(|x| x.rule == Rule::ChangedWhileValid).collect();
    assert_eq!(
        late[0].message,
        "read data of register 0x07 changed from 0x00 to 0x5A 5 clocks after the strobe, later than its read latency of 2"
    );
}

#[test]
fn a_strobe_of_the_wrong_length_is_caught() {
    let host = RegportConfig { strobe: 2, ..Default::default() };
    let mut m = RegportMaster::new("host", host);
    let mut mon = RegportMonitor::new("mon", RegportConfig { strobe: 1, ..host });
    m.start_write(1, 2);
    let mut v = Vec::new();
    for c in 0..40 {
        let o = m.outputs();
        m.on_edge(&RegportIn::default());
        v.extend(mon.observe(c, &o, &RegportIn::default()));
    }
    assert!(v.iter().any(|x| x.rule == Rule::StrobeTooShort && x.message == "write strobe high 2 clocks (the port takes 1)"), "{v:?}");
}
