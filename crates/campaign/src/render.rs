//! A plan written in the scenario format: the one way a plan runs (the
//! text is parsed by `scenario` like any `tb/*.toml`) and the way a shrunk
//! failure is saved, so `cancosim run` replays exactly what the campaign ran.

use crate::plan::{CAN_HZ, FaultPlace, FaultWhat, HOST_HZ, HostOp, INTEGRATION_BITS, Plan, PlanFrame};
use std::fmt::Write as _;

/// Register names of the reads a program makes (PeliCAN view).
fn read_name(addr: u8, pelican: bool) -> String {
    let n = match (addr, pelican) {
        (2, _) => "SR",
        (3, _) => "IR",
        (11, true) => "ALC",
        (12, true) => "ECC",
        (13, true) => "EWLR",
        (14, true) => "RXERR",
        (15, true) => "TXERR",
        (29, true) => "RMC",
        (30, true) => "RBSA",
        _ => return addr.to_string(),
    };
    format!("\"{n}\"")
}

fn frame_fields(f: &PlanFrame) -> String {
    let mut s = format!("id = 0x{:X}", f.id);
    if f.extended {
        s += ", extended = true";
    }
    if f.rtr {
        s += ", rtr = true";
    }
    if f.rtr || f.dlc as usize != f.data.len() {
        write!(s, ", dlc = {}", f.dlc).unwrap();
    }
    if f.dlc > 8 {
        s += ", raw_dlc = true";
    }
    if !f.data.is_empty() {
        let d: Vec<String> = f.data.iter().map(|b| format!("0x{b:02X}")).collect();
        write!(s, ", data = [{}]", d.join(", ")).unwrap();
    }
    s
}

fn describe_frame(f: &PlanFrame) -> String {
    format!(
        "{} {} 0x{:X} DLC {}",
        if f.extended { "EFF" } else { "SFF" },
        if f.rtr { "remote" } else { "data" },
        f.id,
        f.dlc
    )
}

/// The configuration steps: reset mode, the register view, filters, bit
/// timing, then operating mode and bus integration.
fn config_steps(p: &Plan) -> Vec<String> {
    let c = &p.config;
    let mut v = vec!["{ write = \"CR\", value = 0x01, note = \"reset mode\" }".to_string()];
    if c.pelican {
        v.push("{ write = \"CDR\", value = 0x80, note = \"PeliCAN\" }".into());
        v.push(format!("{{ write = \"MOD\", value = 0x{:02X} }}", c.reset_mode_byte()));
        v.push(format!("{{ write = \"IER\", value = 0x{:02X} }}", c.ier));
        for i in 0..4 {
            v.push(format!("{{ write = \"ACR{i}\", value = 0x{:02X} }}", c.acr[i]));
        }
        for i in 0..4 {
            v.push(format!("{{ write = \"AMR{i}\", value = 0x{:02X} }}", c.amr[i]));
        }
        if let Some(e) = c.ewl {
            v.push(format!("{{ write = \"EWLR\", value = 0x{e:02X} }}"));
        }
    } else {
        v.push(format!("{{ write = \"CR\", value = 0x{:02X} }}", c.reset_mode_byte()));
        v.push(format!("{{ write = \"ACR\", value = 0x{:02X} }}", c.acr[0]));
        v.push(format!("{{ write = \"AMR\", value = 0x{:02X} }}", c.amr[0]));
    }
    let t = p.timing();
    v.push(format!("{{ write = \"BTR0\", value = 0x{:02X}, note = \"BRP {} SJW {}\" }}", c.btr.0, t.brp, t.sjw));
    v.push(format!(
        "{{ write = \"BTR1\", value = 0x{:02X}, note = \"TSEG1 {} TSEG2 {} SAM {}: {} tq, {:.0} bit/s\" }}",
        c.btr.1,
        t.tseg1,
        t.tseg2,
        t.sam as u8,
        t.tq_per_bit(),
        t.bit_rate(CAN_HZ)
    ));
    v.push("{ write = \"OCR\", value = 0xDA }".into());
    let (reg, what) = if c.pelican { ("MOD", "operating mode") } else { ("CR", "operating mode") };
    v.push(format!("{{ write = \"{reg}\", value = 0x{:02X}, note = \"{what}\" }}", c.operating_mode_byte()));
    v.push(format!("{{ wait_bits = {INTEGRATION_BITS}, note = \"bus integration\" }}"));
    v
}

fn op_steps(p: &Plan, op: &HostOp) -> Vec<String> {
    let c = &p.config;
    let mode_reg = if c.pelican { "MOD" } else { "CR" };
    match op {
        HostOp::Wait(b) => vec![format!("{{ wait_bits = {b} }}")],
        HostOp::WaitIrq(b) => vec![format!("{{ wait_irq = true, timeout_bits = {b}, optional = true }}")],
        HostOp::Transmit { frame, command } => vec![format!(
            "{{ transmit = {{ {} }}, command = 0x{command:02X}, timeout_bits = 600, note = \"{}\" }}",
            frame_fields(frame),
            describe_frame(frame)
        )],
        HostOp::Abort => vec!["{ write = \"CMR\", value = 0x02, note = \"abort\" }".into()],
        HostOp::Drain(n) => vec![format!("{{ drain = {n} }}")],
        HostOp::Release(n) => vec![format!("{{ release = {n} }}")],
        HostOp::ClearOverrun => vec!["{ write = \"CMR\", value = 0x08, note = \"clear data overrun\" }".into()],
        HostOp::Read(a) => vec![format!("{{ read = {} }}", read_name(*a, c.pelican))],
        HostOp::ResetToggle { bits, txerr, rxerr, ewl } => {
            let mut v = vec![format!("{{ write = \"{mode_reg}\", value = 0x{:02X}, note = \"reset mode while the bus runs\" }}", c.reset_mode_byte())];
            for (name, val) in [("TXERR", txerr), ("RXERR", rxerr), ("EWLR", ewl)] {
                if let Some(x) = val {
                    v.push(format!("{{ write = \"{name}\", value = 0x{x:02X} }}"));
                }
            }
            v.push(format!("{{ wait_bits = {bits} }}"));
            v.push(format!("{{ write = \"{mode_reg}\", value = 0x{:02X}, note = \"operating mode\" }}", c.operating_mode_byte()));
            v
        }
        HostOp::Sleep { bits } => {
            if c.pelican {
                vec![
                    format!("{{ write = \"MOD\", value = 0x{:02X}, note = \"sleep\" }}", c.operating_mode_byte() | 0x10),
                    format!("{{ wait_bits = {bits} }}"),
                    format!("{{ write = \"MOD\", value = 0x{:02X}, note = \"wake up\" }}", c.operating_mode_byte()),
                ]
            } else {
                vec![
                    "{ write = \"CMR\", value = 0x10, note = \"go to sleep\" }".into(),
                    format!("{{ wait_bits = {bits} }}"),
                    "{ write = \"CMR\", value = 0x00, note = \"wake up\" }".into(),
                ]
            }
        }
    }
}

/// A one-line summary of the plan (nodes, frames, timing, program).
pub fn summary(p: &Plan) -> String {
    let t = p.timing();
    format!(
        "{} DUT, {} model node(s), {} frame(s), {} host operation(s), {} fault(s); BTR0/1 0x{:02X}/0x{:02X} ({} tq of {} clocks{})",
        if p.config.pelican { "PeliCAN" } else { "BasicCAN" },
        p.nodes.len(),
        p.frame_count(),
        p.op_count(),
        p.faults.len(),
        p.config.btr.0,
        p.config.btr.1,
        t.tq_per_bit(),
        t.clocks_per_tq(),
        if t.sam { ", triple sampling" } else { "" }
    )
}

/// [`to_toml`] with an `[expect]` category (a saved failure expects what
/// the golden model does with the same plan).
pub fn to_toml_expecting(p: &Plan, purpose: &str, header: &[String], category: diagnose::Category) -> String {
    let mut s = to_toml(p, purpose, header);
    write!(s, "\n[expect]\ncategory = \"{category:?}\"\n").unwrap();
    s
}

/// The plan as a scenario file. `purpose` is its first line of meaning
/// (the divergence, for a saved failure); `header` is written as comments
/// above it.
pub fn to_toml(p: &Plan, purpose: &str, header: &[String]) -> String {
    let mut s = String::new();
    for h in header {
        writeln!(s, "# {h}").unwrap();
    }
    writeln!(s, "name = \"campaign-s{}-r{}\"", p.seed, p.index).unwrap();
    writeln!(s, "purpose = {}", toml_str(purpose)).unwrap();
    writeln!(s, "sequence = [{}]", toml_str(&summary(p))).unwrap();
    s += "step = [\n";
    for st in config_steps(p).into_iter().chain(p.program.iter().flat_map(|o| op_steps(p, o))) {
        writeln!(s, "    {st},").unwrap();
    }
    s += "]\n\n[clocks]\n";
    writeln!(s, "host_mhz = {:.1}\ncan_mhz = {:.1}\n", HOST_HZ / 1e6, CAN_HZ / 1e6).unwrap();
    writeln!(s, "[run]\nmax_bits = {}", p.max_bits()).unwrap();
    for (i, n) in p.nodes.iter().enumerate() {
        writeln!(s, "\n[[node]]\nname = \"n{}\"\nmode = \"peli\"", i + 1).unwrap();
        writeln!(s, "btr0 = 0x{:02X}\nbtr1 = 0x{:02X}", p.config.btr.0, p.config.btr.1).unwrap();
        if n.ppm != 0 {
            writeln!(s, "can_mhz = {:.6}  # {:+} ppm", CAN_HZ * (1.0 + n.ppm as f64 * 1e-6) / 1e6, n.ppm).unwrap();
        }
        s += "send = [\n";
        for (at, f) in &n.frames {
            writeln!(s, "    {{ {}, at_bit = {at} }},", frame_fields(f)).unwrap();
        }
        s += "]\n";
    }
    for f in &p.faults {
        s += "\n[[fault]]\n";
        let kind = match f.what {
            FaultWhat::Flip => "flip",
            FaultWhat::StuckDominant { .. } => "stuck-dominant",
            FaultWhat::Glitch { .. } => "glitch",
        };
        writeln!(s, "kind = \"{kind}\"\nframe = {}\nbit_in_frame = {}", f.frame, f.bit).unwrap();
        match f.what {
            FaultWhat::StuckDominant { bits } => writeln!(s, "duration_bits = {bits}").unwrap(),
            FaultWhat::Glitch { offset, width } => writeln!(s, "offset_clocks = {offset}\nwidth_clocks = {width}").unwrap(),
            FaultWhat::Flip => {}
        }
        if f.place == FaultPlace::DutRx {
            s += "target = \"dut-rx\"\n";
        }
    }
    s
}

/// A TOML basic string.
fn toml_str(s: &str) -> String {
    let mut o = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => o += "\\\"",
            '\\' => o += "\\\\",
            '\n' => o += "\\n",
            c if (c as u32) < 0x20 => write!(o, "\\u{:04X}", c as u32).unwrap(),
            c => o.push(c),
        }
    }
    o.push('"');
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{DrawLimits, draw};

    #[test]
    fn every_drawn_plan_is_a_valid_scenario_that_keeps_its_contents() {
        for (seed, i) in [11u64, 100, 2026].into_iter().flat_map(|s| (0..400).map(move |i| (s, i))) {
            let p = draw(seed, i, &DrawLimits { fault_rate: 0.5, ..DrawLimits::default() });
            let text = to_toml(&p, "a \"quoted\" purpose", &["header".into()]);
            let s = scenario::Scenario::parse(&text, format!("campaign/r{i}.toml")).unwrap_or_else(|e| panic!("seed {seed} run {i}: {e}\n{text}"));
            assert_eq!(s.nodes.len(), p.nodes.len());
            assert_eq!(s.faults.len(), p.faults.len());
            assert_eq!(s.purpose, "a \"quoted\" purpose");
            let sent: usize = s.nodes.iter().map(|n| n.traffic.len()).sum();
            assert_eq!(sent, p.nodes.iter().map(|n| n.frames.len()).sum::<usize>());
            let tx = s.steps.iter().filter(|st| matches!(st.action, scenario::Action::Transmit { .. })).count();
            assert_eq!(tx, p.program.iter().filter(|o| matches!(o, HostOp::Transmit { .. })).count());
            assert_eq!(s.dut_timing(), p.config.btr);
        }
    }
}
