//! The probe scenarios: short, built here as scenario text, each meant to
//! make one freedom visible. All run at 600 kbit/s from a 24 MHz CAN clock
//! (BTR0 0x41, BTR1 0x25: 4 CAN clocks a quantum, 10 quanta a bit, SJW 2
//! quanta), PeliCAN, filters open.

/// CAN clocks in one bit of the probes' bit timing.
pub const BIT_CLOCKS: u32 = 40;
/// CAN clocks in the probes' resynchronisation jump width (SJW 2 tq).
pub const SJW_CLOCKS: u32 = 8;

/// One probe: a name for the evidence and the reports, and its scenario.
#[derive(Clone, Debug)]
pub struct Probe {
    /// Name (`phase+3`: the phase probe with 3 pad reads).
    pub name: String,
    /// The scenario.
    pub scenario: scenario::Scenario,
}

const CONFIG: &str = r#"
    { write = "CR", value = 0x01 },
    { write = "CDR", value = 0x80 },
    { write = "IER", value = 0x03 },
    { write = "ACR0", value = 0x00 },
    { write = "ACR1", value = 0x00 },
    { write = "ACR2", value = 0x00 },
    { write = "ACR3", value = 0x00 },
    { write = "AMR0", value = 0xFF },
    { write = "AMR1", value = 0xFF },
    { write = "AMR2", value = 0xFF },
    { write = "AMR3", value = 0xFF },
    { write = "BTR0", value = 0x41 },
    { write = "BTR1", value = 0x25 },
    { write = "OCR", value = 0xDA },"#;

fn text(purpose: &str, steps: &str, tail: &str, max_bits: u32) -> String {
    format!(
        "purpose = \"{purpose}\"\nverifies = [\"the core agrees with the golden model under the candidate profile\"]\n\
         sequence = [\"configure in reset mode, then the probe's own steps\"]\n\
         step = [{CONFIG}\n{steps}\n]\n\
         [clocks]\nhost_mhz = 50.0\ncan_mhz = 24.0\n[host]\nbfm = \"wishbone\"\n[dut]\nkind = \"rtl\"\n\
         [wiring]\nrx = \"bus\"\ntx_to_bus = true\n[run]\nmax_bits = {max_bits}\n{tail}\n[expect]\ncategory = \"Pass\"\n"
    )
}

fn pads(n: u32, reg: &str) -> String {
    (0..n).map(|_| format!("    {{ read = \"{reg}\" }},\n")).collect()
}

fn probe(name: String, t: String) -> Probe {
    let scenario = scenario::Scenario::parse(&t, format!("{name}.toml")).unwrap_or_else(|e| panic!("probe {name} parses (a fixed text): {e}"));
    Probe { name, scenario }
}

/// Phase: `pad` reads between the bit-timing writes and the reset-mode exit
/// (each moves the exit by about 6 CAN clocks against a bit timing that
/// started at the hardware reset), then a self-test frame with self
/// reception long after: its start of frame shows where the core's bit
/// timing started.
pub fn phase(pad: u32) -> Probe {
    let steps = format!(
        "{}    {{ write = \"MOD\", value = 0x04 }},\n    {{ wait_bits = 14 }},\n    {{ load_tx = {{ id = 0x529, data = [0x51] }} }},\n    \
         {{ write = \"CMR\", value = 0x10 }},\n    {{ wait_sr_set = 0x09, timeout_bits = 200 }},\n    {{ read = \"RXFI\", expect = 0x01 }},\n    {{ write = \"CMR\", value = 0x04 }},",
        pads(pad, "CDR")
    );
    probe(format!("phase+{pad}"), text("profile probe: where the bit timing starts (reset-mode exit moved by pad reads)", &steps, "", 260))
}

/// Grid: `pad` register writes (ACR0) before the bit-timing writes, so
/// BTR0 and BTR1 land at another clock of the running bit each time (a
/// core whose bit timing runs through reset mode takes them there; the
/// reset-value bit is 6 CAN clocks, a write about 6 to 7), then the phase
/// probe's self-test frame: its tx edges show where the BTR writes met
/// the core's quanta (`segment-lag`, and where an access's edges count
/// from).
pub fn grid(pad: u32) -> Probe {
    let steps = "    { write = \"MOD\", value = 0x04 },\n    { wait_bits = 14 },\n    { load_tx = { id = 0x529, data = [0x51] } },\n    \
         { write = \"CMR\", value = 0x10 },\n    { wait_sr_set = 0x09, timeout_bits = 200 },\n    { read = \"RXFI\", expect = 0x01 },\n    { write = \"CMR\", value = 0x04 },";
    let t = text("profile probe: where BTR writes in reset mode meet a running bit timing (register writes before them)", steps, "", 260);
    let anchor = "    { write = \"BTR0\", value = 0x41 },\n    { write = \"BTR1\", value = 0x25 },\n";
    let pads: String = (0..pad).map(|_| "    { write = \"ACR0\", value = 0x00 },\n").collect();
    let btr = "    { write = \"BTR0\", value = 0xC0 },\n    { write = \"BTR1\", value = 0x7F },\n";
    probe(format!("grid+{pad}"), t.replacen(anchor, &(pads + btr), 1))
}

/// Command: the transmission request `pad` reads after the TX buffer is
/// filled, so it lands at a different clock of the bit each time: the bit
/// the start of frame comes in shows when the core took the command.
pub fn command(pad: u32) -> Probe {
    let steps = format!(
        "    {{ write = \"MOD\", value = 0x04 }},\n    {{ wait_bits = 14 }},\n    {{ load_tx = {{ id = 0x529, data = [0x51] }} }},\n{}    \
         {{ write = \"CMR\", value = 0x10 }},\n    {{ wait_sr_set = 0x09, timeout_bits = 200 }},\n    {{ write = \"CMR\", value = 0x04 }},",
        pads(pad, "CDR")
    );
    probe(format!("command+{pad}"), text("profile probe: when a transmission request takes effect", &steps, "", 260))
}

/// Status: an 8-byte extended frame from a model node received, one sent
/// with self reception (acknowledged, and copied into the own RX FIFO: the
/// longest copy), SR polled through both, IR read at each interrupt: the
/// SR/IR latency around a received and a sent frame, and the irq pin.
pub fn status() -> Probe {
    let steps = "    { write = \"MOD\", value = 0x00 },\n    { wait_bits = 14 },\n    \
        { wait_sr_set = 0x10, timeout_bits = 120 },\n    { wait_sr_set = 0x01, wait_sr_clear = 0x10, timeout_bits = 300 },\n    \
        { read = \"IR\" },\n    { read = \"SR\" },\n    { read = \"RXFI\", expect = 0x88 },\n    { write = \"CMR\", value = 0x04 },\n    \
        { load_tx = { id = 0x0ABCDEF1, extended = true, data = [1, 2, 3, 4, 5, 6, 7, 8] } },\n    { write = \"CMR\", value = 0x10 },\n    \
        { wait_sr_set = 0x20, timeout_bits = 60 },\n    { wait_sr_set = 0x0D, wait_sr_clear = 0x20, timeout_bits = 300 },\n    \
        { read = \"IR\" },\n    { read = \"SR\" },\n    { write = \"CMR\", value = 0x04 },\n    { wait_bits = 4 },";
    let node = "[[node]]\nname = \"peer\"\nbtr0 = 0x41\nbtr1 = 0x25\nmode = \"peli\"\nsend = [ { id = 0x1234567, extended = true, data = [0xA5, 1, 2, 3, 4, 5, 6, 7], at_bit = 40 } ]\n";
    probe("status".into(), text("profile probe: SR/IR and the irq pin around a received and a sent frame", steps, node, 400))
}

/// Recovery: bus-off by bit errors (the core's rx stuck recessive), the
/// 128 x 11 recessive bits of the recovery, then a frame from bus idle: a
/// start of frame whose phase nothing synchronised since the recovery.
/// The error interrupt (EI) is enabled: the bus-off and its end on IR and
/// the irq pin.
pub fn recovery() -> Probe {
    let steps = "    { write = \"IER\", value = 0x07 },\n    { write = \"MOD\", value = 0x00 },\n    { wait_bits = 12 },\n    { load_tx = { id = 0x2AA, data = [0x99] } },\n    \
        { write = \"CMR\", value = 0x01 },\n    { wait_sr_set = 0x80, timeout_bits = 900 },\n    { wait_bits = 2 },\n    \
        { read = \"SR\" },\n    { read = \"IR\" },\n    { read = \"TXERR\" },\n    { wait_bits = 300 },\n    \
        { write = \"MOD\", value = 0x00 },\n    { wait_bits = 555 },\n    { read = \"TXERR\" },\n    \
        { wait_sr_clear = 0x80, timeout_bits = 1000 },\n    { wait_bits = 1 },\n    { read = \"IR\" },\n    \
        { write = \"CMR\", value = 0x01 },\n    { wait_sr_set = 0x08, timeout_bits = 300 },\n    { read = \"IR\" },";
    let tail = "[[node]]\nname = \"acker\"\nbtr0 = 0x41\nbtr1 = 0x25\nmode = \"peli\"\n\
        [[fault]]\nkind = \"stuck-recessive\"\nat_bit = 5\nduration_bits = 600\ntarget = \"dut-rx\"\n";
    probe("recovery".into(), text("profile probe: a start of frame from bus idle after a bus-off recovery", steps, tail, 3500))
}

/// Wake-up: sleep entered in bus idle and left by a peer's frame (WUI),
/// a sleep request refused while the next frame is on the bus (WUI at the
/// write), that frame received (RI), then sleep left by the host (WUI):
/// the wake-up interrupt's latency on IR and the irq pin.
pub fn wakeup() -> Probe {
    let steps = "    { write = \"IER\", value = 0x11 },\n    { write = \"MOD\", value = 0x00 },\n    { wait_bits = 12 },\n    \
        { write = \"MOD\", value = 0x10 },\n    { wait_irq = true, timeout_bits = 200 },\n    { read = \"IR\" },\n    \
        { wait_bits = 90 },\n    { wait_sr_set = 0x10, timeout_bits = 200 },\n    { write = \"MOD\", value = 0x10 },\n    \
        { wait_irq = true, timeout_bits = 200 },\n    { read = \"IR\" },\n    { wait_sr_set = 0x01, timeout_bits = 200 },\n    \
        { wait_bits = 2 },\n    { read = \"IR\" },\n    { write = \"CMR\", value = 0x04 },\n    { wait_bits = 15 },\n    \
        { write = \"MOD\", value = 0x10 },\n    { wait_bits = 20 },\n    { write = \"MOD\", value = 0x00 },\n    { read = \"IR\" },\n    { wait_bits = 20 },";
    let node = "[[node]]\nname = \"talker\"\nbtr0 = 0x41\nbtr1 = 0x25\nmode = \"peli\"\n\
        send = [ { id = 0x124, data = [0x01], at_bit = 60 }, { id = 0x124, data = [0x02], at_bit = 200 } ]\n";
    probe("wakeup".into(), text("profile probe: the wake-up interrupt (bus wake-up, refused request, host wake-up) on IR and the irq pin", steps, node, 420))
}

/// Passive: the core's rx stuck dominant inside a peer's frame (error
/// flags and rule 6 until RXERR passes EWL, then 127: EI, EPI), then a
/// frame received whole (rule 8: back under 128, EPI again): the error
/// interrupts' latency on IR and the irq pin, at an error and at a
/// successful reception.
pub fn passive() -> Probe {
    let steps = "    { write = \"IER\", value = 0x24 },\n    { write = \"EWLR\", value = 0x10 },\n    { write = \"MOD\", value = 0x00 },\n    \
        { wait_bits = 12 },\n    { wait_irq = true, timeout_bits = 300 },\n    { read = \"IR\" },\n    \
        { wait_irq = true, timeout_bits = 200 },\n    { read = \"IR\" },\n    { wait_bits = 60 },\n    \
        { wait_sr_set = 0x01, timeout_bits = 400 },\n    { read = \"IR\" },\n    { read = \"RXERR\" },\n    { write = \"CMR\", value = 0x04 },\n    { wait_bits = 4 },";
    let tail = "[[node]]\nname = \"sender\"\nbtr0 = 0x41\nbtr1 = 0x25\nmode = \"peli\"\n\
        send = [ { id = 0x3C3, data = [0x00], at_bit = 40 }, { id = 0x3C3, data = [0x01], at_bit = 500 } ]\n\
        [[node]]\nname = \"acker\"\nbtr0 = 0x41\nbtr1 = 0x25\nmode = \"peli\"\n\
        [[fault]]\nkind = \"stuck-dominant\"\nframe = 1\nbit_in_frame = 20\nduration_bits = 150\ntarget = \"dut-rx\"\n";
    probe("passive".into(), text("profile probe: error warning and error passive interrupts at errors and at a successful reception", steps, tail, 800))
}

/// First read: SR read as the first access after the reset, then the
/// configuration and a self-test frame whose reception is read back: the
/// read data of a first access (on a port that acknowledges through a
/// clock crossing, the slowest) and of reads in a running core.
pub fn first_read() -> Probe {
    let steps = "    { write = \"MOD\", value = 0x04 },\n    { wait_bits = 14 },\n    { load_tx = { id = 0x529, data = [0x51] } },\n    \
         { write = \"CMR\", value = 0x10 },\n    { wait_sr_set = 0x09, timeout_bits = 200 },\n    { read = \"RXFI\", expect = 0x01 },\n    { read = \"IR\" },\n    { write = \"CMR\", value = 0x04 },";
    let t = text("profile probe: read data of the first access after the reset and of a running core's reads", steps, "", 260);
    let first = "    { write = \"CR\", value = 0x01 },\n";
    probe("first-read".into(), t.replacen(first, &format!("    {{ read = \"SR\" }},\n{first}"), 1))
}
