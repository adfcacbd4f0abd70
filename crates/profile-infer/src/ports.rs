//! Port roles from the top's port table: names first (a role whose name
//! matches two ports is a question for the user, never a guess), then
//! behaviour for the polarities the names cannot tell (irq and bus-off:
//! their level in bus idle after a reset is the inactive one).

use cosim::bridge::PortDir;
use cosim::profile::{Pin, PortMap};
use cosim::{Model, PortInfo};

use crate::InferError;

/// The roles of [`PortMap`] with how a port is recognised: direction,
/// width, and words of its name (lower case); the first role listed wins
/// a port that two roles' words match (`clkout` before the clocks).
struct Rule {
    role: &'static str,
    dir: PortDir,
    width: u32,
    words: &'static [&'static str],
    not: &'static [&'static str],
}

const HOST_CLOCK: &[&str] = &["wb_clk", "host_clk", "bus_clk", "sys_clk", "clk_host", "clk_wb", "clk_sys", "cpu_clk", "hclk"];
const CAN_CLOCK: &[&str] = &["can_clk", "clk_can", "osc", "xtal", "clk_i", "core_clk"];

const RULES: &[Rule] = &[
    Rule { role: "clkout", dir: PortDir::Out, width: 1, words: &["clkout", "clk_out"], not: &[] },
    Rule { role: "can-clock", dir: PortDir::In, width: 1, words: CAN_CLOCK, not: HOST_CLOCK },
    Rule { role: "host-clock", dir: PortDir::In, width: 1, words: HOST_CLOCK, not: &[] },
    Rule { role: "reset", dir: PortDir::In, width: 1, words: &["rst", "reset"], not: &[] },
    Rule { role: "dat-i", dir: PortDir::In, width: 8, words: &["dat", "data", "din", "wdata"], not: &[] },
    Rule { role: "dat-o", dir: PortDir::Out, width: 8, words: &["dat", "data", "dout", "rdata"], not: &[] },
    Rule { role: "adr", dir: PortDir::In, width: 8, words: &["adr", "addr"], not: &[] },
    Rule { role: "cyc", dir: PortDir::In, width: 1, words: &["cyc"], not: &[] },
    Rule { role: "stb", dir: PortDir::In, width: 1, words: &["stb", "strobe"], not: &[] },
    Rule { role: "we", dir: PortDir::In, width: 1, words: &["we"], not: &[] },
    Rule { role: "ack", dir: PortDir::Out, width: 1, words: &["ack"], not: &[] },
    Rule { role: "rx", dir: PortDir::In, width: 1, words: &["rx"], not: &[] },
    Rule { role: "tx", dir: PortDir::Out, width: 1, words: &["tx"], not: &[] },
    Rule { role: "irq", dir: PortDir::Out, width: 1, words: &["irq", "int"], not: &[] },
    Rule { role: "bus-off", dir: PortDir::Out, width: 1, words: &["bus_off", "busoff", "bo"], not: &[] },
];

/// `we` must be a word of the name, not a letter pair inside one (`power`);
/// the short words of the other roles too (`rx`, `tx`, `bo`, `int`).
fn has_word(name: &str, w: &str) -> bool {
    if w.contains('_') || w.len() > 3 {
        return name.contains(w);
    }
    name.split('_').any(|t| t == w || (t.starts_with(w) && t.len() <= w.len() + 1 && w != "we" && w != "bo" && w != "int"))
}

/// A name that says active low: `_n`, `_b`, `_l` or `n` around the word.
pub fn name_says_active_low(name: &str) -> bool {
    let n = name.to_ascii_lowercase();
    let parts: Vec<&str> = n.split('_').collect();
    parts.iter().any(|t| matches!(*t, "n" | "b" | "l" | "ni" | "on" | "bn"))
        || parts.iter().any(|t| (t.starts_with("rst") || t.starts_with("reset")) && t.ends_with('n') && *t != "rstn_i")
        || parts.iter().any(|t| *t == "rstn" || *t == "resetn" || *t == "nrst" || *t == "nreset")
}

/// Roles named on the command line (`--port ROLE=NAME[:low|high]`).
pub type Overrides = Vec<(String, String)>;

/// Finds the port of every role: the user's overrides, else the one port
/// whose direction, width and name fit. Two candidates for a role, or
/// none, is an error that lists them and says how to choose.
pub fn find_roles(ports: &[PortInfo], overrides: &Overrides) -> Result<PortMap, InferError> {
    let mut map = PortMap::default();
    let mut taken: Vec<String> = Vec::new();
    for (role, name) in overrides {
        if !RULES.iter().any(|r| r.role == role) {
            return Err(InferError::Ports(format!(
                "--port {role}={name}: no such role; roles: {}",
                RULES.iter().map(|r| r.role).collect::<Vec<_>>().join(", ")
            )));
        }
        let bare = name.split(':').next().unwrap_or(name);
        if !ports.iter().any(|p| p.name == bare) {
            return Err(InferError::Ports(format!("--port {role}={name}: the top has no port {bare} (it has: {})", names(ports))));
        }
        taken.push(bare.to_string());
    }
    for rule in RULES {
        let pin = pin_mut(&mut map, rule.role);
        if let Some((_, name)) = overrides.iter().find(|(r, _)| r == rule.role) {
            let (bare, level) = name.split_once(':').unwrap_or((name, ""));
            pin.name = bare.to_string();
            match level {
                "" => pin.active_high = !name_says_active_low(bare),
                "low" => pin.active_high = false,
                "high" => pin.active_high = true,
                other => return Err(InferError::Ports(format!("--port {}={name}: `{other}`: expected low or high", rule.role))),
            }
            continue;
        }
        let fits: Vec<&PortInfo> = ports
            .iter()
            .filter(|p| p.dir == rule.dir && p.width == rule.width && !taken.contains(&p.name))
            .filter(|p| {
                let n = p.name.to_ascii_lowercase();
                rule.words.iter().any(|w| has_word(&n, w)) && !rule.not.iter().any(|w| n.contains(w))
            })
            .collect();
        let chosen = match fits.as_slice() {
            [one] => one.name.clone(),
            [] if rule.role == "can-clock" || rule.role == "host-clock" => {
                // Two clocks, one of them recognised: the other is the other clock.
                let clocks: Vec<&PortInfo> = ports
                    .iter()
                    .filter(|p| p.dir == PortDir::In && p.width == 1 && !taken.contains(&p.name))
                    .filter(|p| {
                        let n = p.name.to_ascii_lowercase();
                        let other = if rule.role == "can-clock" { HOST_CLOCK } else { CAN_CLOCK };
                        (n.contains("clk") || n.contains("clock")) && !n.contains("clkout") && !other.iter().any(|w| n.contains(w))
                    })
                    .collect();
                match clocks.as_slice() {
                    [one] => one.name.clone(),
                    [] => return Err(missing(rule.role, ports)),
                    many => return Err(ambiguous(rule.role, many)),
                }
            }
            [] => return Err(missing(rule.role, ports)),
            many => return Err(ambiguous(rule.role, many)),
        };
        pin.name = chosen.clone();
        pin.active_high = !(rule.role == "reset" && name_says_active_low(&chosen));
        taken.push(chosen);
    }
    Ok(map)
}

fn names(ports: &[PortInfo]) -> String {
    ports.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(" ")
}

fn missing(role: &str, ports: &[PortInfo]) -> InferError {
    InferError::Ports(format!("no port of the top plays `{role}` by its name, direction and width (it has: {}); name it with --port {role}=NAME", names(ports)))
}

fn ambiguous(role: &str, many: &[&PortInfo]) -> InferError {
    let list: Vec<&str> = many.iter().map(|p| p.name.as_str()).collect();
    InferError::Ports(format!(
        "{} ports could play `{role}`: {}; say which with --port {role}={}",
        list.len(),
        list.join(", "),
        list[0]
    ))
}

fn pin_mut<'a>(m: &'a mut PortMap, role: &str) -> &'a mut Pin {
    match role {
        "host-clock" => &mut m.host_clock,
        "reset" => &mut m.reset,
        "dat-i" => &mut m.dat_i,
        "dat-o" => &mut m.dat_o,
        "cyc" => &mut m.cyc,
        "stb" => &mut m.stb,
        "we" => &mut m.we,
        "adr" => &mut m.adr,
        "ack" => &mut m.ack,
        "can-clock" => &mut m.can_clock,
        "rx" => &mut m.rx,
        "tx" => &mut m.tx,
        "irq" => &mut m.irq,
        "bus-off" => &mut m.bus_off,
        _ => &mut m.clkout,
    }
}

/// What the idle levels showed, for the evidence lines.
pub struct IdleLevels {
    /// irq's level in bus idle after the reset (its inactive level).
    pub irq: bool,
    /// bus-off's level in bus idle after the reset (on the bus: inactive).
    pub bus_off: bool,
}

/// Sets the irq and bus-off polarities from their levels after a reset
/// with the bus idle (no interrupt is enabled after a hardware reset, and
/// a node starts on the bus: both pins are inactive). Unless the user
/// named the polarity.
pub fn polarities(model: &mut Model, map: &mut PortMap, overrides: &Overrides) -> Result<IdleLevels, InferError> {
    let port = |m: &Model, n: &str| m.port_by_name(n).map_err(|e| InferError::Ports(e.to_string()));
    let (hclk, cclk, rst, rx) = (port(model, &map.host_clock.name)?, port(model, &map.can_clock.name)?, port(model, &map.reset.name)?, port(model, &map.rx.name)?);
    let (irq, bo) = (port(model, &map.irq.name)?, port(model, &map.bus_off.name)?);
    model.set(rx, 1);
    for cycle in 0..400u64 {
        let in_reset = cycle < 40;
        model.set(rst, u64::from(in_reset == map.reset.active_high));
        for (h, c) in [(1, 1), (0, 1), (1, 0), (0, 0)] {
            model.set(hclk, h);
            model.set(cclk, c);
            model.eval();
        }
    }
    let levels = IdleLevels { irq: model.get(irq) != 0, bus_off: model.get(bo) != 0 };
    let named = |role: &str| overrides.iter().any(|(r, n)| r == role && n.contains(':'));
    if !named("irq") {
        map.irq.active_high = !levels.irq;
    }
    if !named("bus-off") {
        map.bus_off.active_high = !levels.bus_off;
    }
    Ok(levels)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn active_low_names() {
        for n in ["rst_n", "reset_n", "rstn", "nrst", "rst_ni", "wb_rst_b"] {
            assert!(name_says_active_low(n), "{n}");
        }
        for n in ["wb_rst_i", "rst", "reset", "rst_i"] {
            assert!(!name_says_active_low(n), "{n}");
        }
    }

    #[test]
    fn short_words_are_words() {
        assert!(has_word("wb_we_i", "we") && !has_word("power", "we"));
        assert!(has_word("can_rx", "rx") && has_word("rx_i", "rx") && !has_word("rxerr_cnt", "rx"));
        assert!(has_word("bus_off_on", "bus_off") && !has_word("bonus", "bo"));
    }
}
