//! Wishbone block cycles through the test bench (`Testbench::begin_block`):
//! the golden model as a correct slave passes them; a slave that keeps its
//! ack high while STB stays up (the model's level ack, which is what our
//! rtl/'s mutant 22 does) acknowledges the next transfer without doing it,
//! and the lockstep comparison catches it; the same accesses done singly
//! (STB dropped between them) do not show it. A slave that stops
//! acknowledging inside a block ends in a timeout with a diagnosis.

use std::sync::Arc;

use bfm::{BfmError, WbMasterOut, WbSlaveOut};
use cosim::model::ModelDut;
use cosim::{
    CanPins, CompareConfig, CustomDut, Dut, DutChoice, HostBfm, ReferenceChoice, TbConfig,
    TbError, Testbench,
};

// BasicCAN, reset mode: acceptance code and mask.
const CR: u8 = 0;
const ACR: u8 = 4;
const AMR: u8 = 5;

fn bench(name: &str, make: Arc<dyn Fn() -> Box<dyn Dut> + Send + Sync>) -> Testbench {
    Testbench::new(TbConfig {
        scenario: name.into(),
        dut: DutChoice::Custom(CustomDut { name: name.into(), make }),
        host: HostBfm::Wishbone,
        lockstep: Some((ReferenceChoice::Model, CompareConfig::default())),
        op_timeout_cycles: 200,
        ..TbConfig::default()
    })
    .expect("test bench")
}

fn model() -> Arc<dyn Fn() -> Box<dyn Dut> + Send + Sync> {
    Arc::new(|| Box::new(ModelDut::new()))
}

fn level_ack_model() -> Arc<dyn Fn() -> Box<dyn Dut> + Send + Sync> {
    Arc::new(|| Box::new(ModelDut::with_level_ack()))
}

/// Reset mode, then ACR and AMR written and read back, as one block cycle
/// or singly; the two values read (or the first error).
fn write_and_read_back(tb: &mut Testbench, block: bool) -> Result<(u8, u8), TbError> {
    tb.write(CR, 0x01)?;
    if block {
        let queued = tb.begin_block(&[(true, ACR, 0x5A), (true, AMR, 0xC3), (false, ACR, 0), (false, AMR, 0)])?;
        assert!(queued, "the Wishbone host does block cycles");
    }
    tb.write(ACR, 0x5A)?;
    tb.write(AMR, 0xC3)?;
    Ok((tb.read(ACR)?, tb.read(AMR)?))
}

#[test]
fn a_correct_slave_passes_a_block_cycle() {
    let mut tb = bench("model", model());
    assert_eq!(write_and_read_back(&mut tb, true).unwrap(), (0x5A, 0xC3));
    let r = tb.record();
    assert!(r.divergence.is_none(), "{:?}", r.divergence);
    assert!(r.violations.is_empty(), "{:?}", r.violations);
}

#[test]
fn a_slave_that_acks_the_next_transfer_without_doing_it_is_caught_in_a_block_only() {
    // Singly: STB falls after every ack, the level ack falls with it.
    let mut tb = bench("level-ack model", level_ack_model());
    assert_eq!(write_and_read_back(&mut tb, false).unwrap(), (0x5A, 0xC3));
    assert!(tb.record().divergence.is_none());
    // In a block: AMR's write and the reads are acknowledged at once, not done.
    let mut tb = bench("level-ack model", level_ack_model());
    let r = write_and_read_back(&mut tb, true);
    let record = tb.record();
    assert!(
        record.divergence.is_some() || r.as_ref().is_ok_and(|v| *v != (0x5A, 0xC3)),
        "a transfer acknowledged without being done went unnoticed: {r:?}"
    );
    assert!(record.divergence.is_some(), "the lockstep comparison reports it: {r:?}");
}

/// The golden model that acknowledges its first transfer only (a slave that
/// hangs inside a block).
struct AckOnce {
    inner: ModelDut,
    acked: bool,
    ack_seen: bool,
}

impl Dut for AckOnce {
    fn name(&self) -> String {
        "golden model, one ack only".into()
    }
    fn set_reset(&mut self, on: bool) {
        self.inner.set_reset(on);
    }
    fn set_wb(&mut self, m: &WbMasterOut) {
        self.inner.set_wb(m);
    }
    fn wb(&self) -> WbSlaveOut {
        let o = self.inner.wb();
        WbSlaveOut { ack: o.ack && !self.acked, ..o }
    }
    fn set_rx(&mut self, rx: bool) {
        self.inner.set_rx(rx);
    }
    fn can(&self) -> CanPins {
        self.inner.can()
    }
    fn eval(&mut self, host_clk: bool, can_clk: bool) {
        // An ack shown, then gone: no more acks from then on.
        let shown = self.inner.wb().ack && !self.acked;
        self.inner.eval(host_clk, can_clk);
        if self.ack_seen && !shown {
            self.acked = true;
        }
        self.ack_seen |= shown;
    }
}

#[test]
fn a_slave_that_stops_acknowledging_inside_a_block_times_out_with_a_diagnosis() {
    let make: Arc<dyn Fn() -> Box<dyn Dut> + Send + Sync> =
        Arc::new(|| Box::new(AckOnce { inner: ModelDut::new(), acked: false, ack_seen: false }));
    let mut tb = bench("one ack only", make);
    assert!(tb.begin_block(&[(true, CR, 0x01), (true, ACR, 0x11), (true, AMR, 0x22)]).unwrap());
    tb.write(CR, 0x01).expect("the first transfer is acknowledged");
    match tb.write(ACR, 0x11) {
        Err(TbError::Host { error: BfmError::Timeout { addr, .. }, monitor, .. }) => {
            assert_eq!(addr, ACR);
            assert!(monitor.is_empty() || monitor.contains("wb_ack_o"), "{monitor}");
        }
        other => panic!("expected a timeout, got {other:?}"),
    }
    let r = tb.record();
    let e = r.error.as_deref().unwrap_or_default();
    assert!(e.contains("timed out") && e.contains("0x04"), "the record says which access: {e}");
    // The rest of the block was given up: a new access is a cycle of its
    // own (and times out on this slave too), not the abandoned AMR write.
    match tb.read(AMR) {
        Err(TbError::Host { op: "read", addr: AMR, error: BfmError::Timeout { .. }, .. }) => {}
        other => panic!("expected the read's own timeout, got {other:?}"),
    }
}
