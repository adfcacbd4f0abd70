//! Port roles from the top's port table: names first (a role whose name
//! matches two ports is a question for the user, never a guess), then
//! behaviour for the polarities the names cannot tell (irq and bus-off:
//! their level in bus idle after a reset is the inactive one).

use cosim::bridge::PortDir;
use cosim::profile::{Pin, PortBus, PortMap};
use cosim::{Model, PortInfo};
use scenario::HostBfm;

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

/// A port of the top as the role rules see it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PortSig {
    /// Its name.
    pub name: String,
    /// Its direction.
    pub dir: PortDir,
    /// Its width in bits.
    pub width: u32,
}

impl PortSig {
    /// `name`, `dir`, `width`.
    pub fn new(name: &str, dir: PortDir, width: u32) -> PortSig {
        PortSig { name: name.into(), dir, width }
    }
}

/// A model's ports as the role rules see them.
pub fn sigs(ports: &[PortInfo]) -> Vec<PortSig> {
    ports.iter().map(|p| PortSig { name: p.name.clone(), dir: p.dir, width: p.width }).collect()
}

/// Roles named on the command line (`--port ROLE=NAME[:low|high]`; a
/// host bus's role as `BUS.ROLE`, e.g. `apb.psel`).
pub type Overrides = Vec<(String, String)>;

/// The bus whose `[ports.<bus>]` roles the host drives; None: the
/// Wishbone roles of `[ports]` (Wishbone, and Avalon and PIO through the
/// kit's bridges to a Wishbone top).
pub fn bus_of(host: HostBfm) -> Result<Option<PortBus>, InferError> {
    match host {
        HostBfm::Wishbone | HostBfm::Avalon { .. } | HostBfm::Pio | HostBfm::PioEdgeCapture => Ok(None),
        HostBfm::Axi4Lite => Ok(Some(PortBus::Axi4Lite)),
        HostBfm::Apb | HostBfm::Apb3 => Ok(Some(PortBus::Apb)),
        HostBfm::Regport => Ok(Some(PortBus::Regport)),
        HostBfm::Motorola => Ok(Some(PortBus::Motorola)),
        HostBfm::I8051 => Err(InferError::Ports("--host i8051: the 8051 bus's ports have fixed names (can_top_8051's), no role to find; use wishbone, avalon, pio, axi4-lite, apb, apb3, regport or motorola".into())),
    }
}

/// The CAN-side roles, found the same way on every host.
const CAN_SIDE: &[&str] = &["clkout", "can-clock", "rx", "tx", "irq", "bus-off"];

/// Finds the port of every role: the user's overrides, else the one port
/// whose direction, width and name fit. Two candidates for a role, or
/// none, is an error that lists them and says how to choose. With a host
/// bus (`bus`), that bus's roles and the CAN-side ones; the Wishbone roles
/// keep their defaults (no such port is bound on that host).
pub fn find_roles(ports: &[PortSig], overrides: &Overrides, bus: Option<PortBus>) -> Result<PortMap, InferError> {
    find(ports, overrides, bus).map_err(|e| match (e, bus) {
        // A top without the Wishbone roles may be on another bus.
        (InferError::Ports(m), None) if m.starts_with("no port") => InferError::Ports(format!("{m} (a top on another host bus: --host axi4-lite, apb, apb3, regport or motorola)")),
        (e, _) => e,
    })
}

fn find(ports: &[PortSig], overrides: &Overrides, bus: Option<PortBus>) -> Result<PortMap, InferError> {
    let mut map = PortMap::default();
    let mut taken: Vec<String> = Vec::new();
    let mut can_overrides: Overrides = Vec::new();
    let mut bus_overrides: Overrides = Vec::new();
    for (role, name) in overrides {
        let bare = name.split(':').next().unwrap_or(name);
        let (known, is_bus) = match (bus, role.split_once('.')) {
            (Some(b), Some((k, r))) if k == b.key() => (bus_rules(b).iter().any(|x| x.role == r), true),
            (Some(b), None) if !CAN_SIDE.contains(&role.as_str()) => (bus_rules(b).iter().any(|x| x.role == role), true),
            (_, None) => (RULES.iter().any(|r| r.role == role), false),
            (_, Some(_)) => (false, false),
        };
        if !known {
            let roles: Vec<String> = match bus {
                None => RULES.iter().map(|r| r.role.to_string()).collect(),
                Some(b) => CAN_SIDE.iter().map(|r| r.to_string()).chain(bus_rules(b).iter().map(|r| format!("{}.{}", b.key(), r.role))).collect(),
            };
            return Err(InferError::Ports(format!("--port {role}={name}: no such role on this host; roles: {}", roles.join(", "))));
        }
        if !ports.iter().any(|p| p.name == bare) {
            return Err(InferError::Ports(format!("--port {role}={name}: the top has no port {bare} (it has: {})", names(ports))));
        }
        taken.push(bare.to_string());
        let short = role.rsplit('.').next().unwrap_or(role).to_string();
        if is_bus { bus_overrides.push((short, name.clone())) } else { can_overrides.push((short, name.clone())) }
    }
    let mut bus_clock: Option<String> = None;
    if let Some(b) = bus {
        bus_clock = find_bus_roles(ports, &bus_overrides, b, &mut map, &mut taken)?;
    }
    for rule in RULES {
        if bus.is_some() && !CAN_SIDE.contains(&rule.role) {
            continue;
        }
        let pin = pin_mut(&mut map, rule.role);
        if let Some((_, name)) = can_overrides.iter().find(|(r, _)| r == rule.role) {
            let (bare, level) = name.split_once(':').unwrap_or((name, ""));
            pin.name = bare.to_string();
            pin.active_high = level_of(rule.role, name, level, !name_says_active_low(bare))?;
            continue;
        }
        let fits: Vec<&PortSig> = ports
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
                let clocks: Vec<&PortSig> = ports
                    .iter()
                    .filter(|p| p.dir == PortDir::In && p.width == 1 && !taken.contains(&p.name))
                    .filter(|p| {
                        let n = p.name.to_ascii_lowercase();
                        let other = if rule.role == "can-clock" { HOST_CLOCK } else { CAN_CLOCK };
                        (n.contains("clk") || n.contains("clock")) && !n.contains("clkout") && !other.iter().any(|w| n.contains(w))
                    })
                    .collect();
                match (clocks.as_slice(), &bus_clock) {
                    ([one], _) => one.name.clone(),
                    // One clock for the bus and the core: the CAN clock is the bus clock.
                    ([], Some(c)) => c.clone(),
                    ([], None) => return Err(missing(rule.role, ports)),
                    (many, _) => return Err(ambiguous(rule.role, many)),
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

/// `:low` / `:high` after an override's name, or the level the name says.
fn level_of(role: &str, name: &str, level: &str, by_name: bool) -> Result<bool, InferError> {
    match level {
        "" => Ok(by_name),
        "low" => Ok(false),
        "high" => Ok(true),
        other => Err(InferError::Ports(format!("--port {role}={name}: `{other}`: expected low or high"))),
    }
}

/// How a bus role's active level is found.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Level {
    /// No polarity.
    None,
    /// From the name (`_n`, `n` before or after the word: active low).
    Name,
    /// Fixed: R/W's active level is a read (high on the chip), MODE's
    /// Motorola mode (low on the chip).
    Fixed(bool),
}

/// A role of a host bus: its `[ports.<bus>]` key, direction, width (None:
/// any, the bus binds any width), the words its name ends with (after a
/// prefix such as `s_axi_` or `apb_`, before `_i`/`_o`/`_n`), words that
/// rule a port out, and its level.
struct BusRule {
    role: &'static str,
    dir: PortDir,
    width: Option<u32>,
    words: &'static [&'static str],
    not: &'static [&'static str],
    level: Level,
}

const fn br(role: &'static str, dir: PortDir, width: Option<u32>, words: &'static [&'static str], level: Level) -> BusRule {
    BusRule { role, dir, width, words, not: &[], level }
}

use PortDir::{In, Out};

const AXI_RULES: &[BusRule] = &[
    br("clock", In, Some(1), &["aclk"], Level::None),
    br("reset", In, Some(1), &["areset", "reset", "rst"], Level::Name),
    br("awvalid", In, None, &["awvalid"], Level::None),
    br("awready", Out, None, &["awready"], Level::None),
    br("awaddr", In, None, &["awaddr"], Level::None),
    br("awprot", In, None, &["awprot"], Level::None),
    br("wvalid", In, None, &["wvalid"], Level::None),
    br("wready", Out, None, &["wready"], Level::None),
    br("wdata", In, None, &["wdata"], Level::None),
    br("wstrb", In, None, &["wstrb"], Level::None),
    br("bvalid", Out, None, &["bvalid"], Level::None),
    br("bready", In, None, &["bready"], Level::None),
    br("bresp", Out, None, &["bresp"], Level::None),
    br("arvalid", In, None, &["arvalid"], Level::None),
    br("arready", Out, None, &["arready"], Level::None),
    br("araddr", In, None, &["araddr"], Level::None),
    br("arprot", In, None, &["arprot"], Level::None),
    br("rvalid", Out, None, &["rvalid"], Level::None),
    br("rready", In, None, &["rready"], Level::None),
    br("rdata", Out, None, &["rdata"], Level::None),
    br("rresp", Out, None, &["rresp"], Level::None),
];

const APB_RULES: &[BusRule] = &[
    br("clock", In, Some(1), &["pclk"], Level::None),
    br("reset", In, Some(1), &["preset", "reset", "rst"], Level::Name),
    br("psel", In, None, &["psel"], Level::None),
    br("penable", In, None, &["penable"], Level::None),
    br("pwrite", In, None, &["pwrite"], Level::None),
    br("paddr", In, None, &["paddr"], Level::None),
    br("pwdata", In, None, &["pwdata"], Level::None),
    br("pstrb", In, None, &["pstrb"], Level::None),
    br("pprot", In, None, &["pprot"], Level::None),
    br("prdata", Out, None, &["prdata"], Level::None),
    br("pready", Out, None, &["pready"], Level::None),
    br("pslverr", Out, None, &["pslverr"], Level::None),
];

const WR_ADR: &[&str] = &["wr_adr", "wr_addr", "wadr", "waddr", "write_addr", "wr_address"];
const RD_ADR: &[&str] = &["rd_adr", "rd_addr", "radr", "raddr", "read_addr", "rd_address"];

const REGPORT_RULES: &[BusRule] = &[
    br("reset", In, Some(1), &["rst", "reset"], Level::Name),
    br("wr", In, Some(1), &["wr", "we", "write", "wr_stb", "wr_en"], Level::Name),
    br("rd", In, Some(1), &["rd", "re", "read", "rd_stb", "rd_en"], Level::Name),
    BusRule { not: &["wr_adr", "wr_addr", "wadr", "waddr", "write_addr", "wr_address", "rd_adr", "rd_addr", "radr", "raddr", "read_addr", "rd_address"], ..br("adr", In, Some(8), &["adr", "addr", "address"], Level::None) },
    br("wr-adr", In, Some(8), WR_ADR, Level::None),
    br("rd-adr", In, Some(8), RD_ADR, Level::None),
    br("wdat", In, Some(8), &["wdat", "wdata", "din", "data_in", "dat", "data", "di"], Level::None),
    br("rdat", Out, Some(8), &["rdat", "rdata", "dout", "data_out", "dat", "data", "do", "q"], Level::None),
];

const MOTOROLA_RULES: &[BusRule] = &[
    br("reset", In, Some(1), &["rst", "reset"], Level::Name),
    br("mode", In, Some(1), &["mode"], Level::Fixed(false)),
    br("as", In, Some(1), &["as", "ale_as"], Level::Name),
    br("cs", In, Some(1), &["cs", "cs_can", "ce"], Level::Name),
    br("e", In, Some(1), &["e", "rd_e", "ds"], Level::Name),
    br("rw", In, Some(1), &["rw", "r_w", "rnw", "r_nw", "wr_rw"], Level::Fixed(true)),
    br("ad-i", In, Some(8), &["ad", "ad_in", "adin", "port_0", "port0"], Level::None),
    br("ad-o", Out, Some(8), &["ad", "ad_out", "adout", "port_0", "port0"], Level::None),
    br("ad-oe", Out, Some(1), &["oe", "ad_oe", "drive", "ad_drive", "ad_en", "port_0_oe"], Level::Name),
];

fn bus_rules(b: PortBus) -> &'static [BusRule] {
    match b {
        PortBus::Axi4Lite => AXI_RULES,
        PortBus::Apb => APB_RULES,
        PortBus::Regport => REGPORT_RULES,
        PortBus::Motorola => MOTOROLA_RULES,
    }
}

/// A name's stem and whether its tail says active low: `_i`, `_o`, `_io`
/// dropped, `_n`, `_b`, `_l`, `_ni`, `_on`, `_bn` dropped as active low.
fn stem(name: &str) -> (String, bool) {
    let mut parts: Vec<&str> = name.split('_').filter(|t| !t.is_empty()).collect();
    let mut low = false;
    while parts.len() > 1 {
        match *parts.last().expect("more than one") {
            "i" | "o" | "io" => {}
            "n" | "b" | "l" | "ni" | "no" | "on" | "bn" | "nb" => low = true,
            _ => break,
        }
        parts.pop();
    }
    (parts.join("_"), low)
}

/// Whether the stem `s` is `w` or ends with `_w` (any prefix before).
fn ends_with_word(s: &str, w: &str) -> bool {
    s == w || s.strip_suffix(w).is_some_and(|head| head.ends_with('_'))
}

/// Some(active low) when `name` plays a role with `words`; with a level by
/// name, `wN`/`nW` forms too (`presetn`, `aresetn`, `nrst`: active low).
fn name_fits(name: &str, words: &[&str], by_name: bool) -> Option<bool> {
    let (s, low) = stem(&name.to_ascii_lowercase());
    for w in words {
        if ends_with_word(&s, w) {
            return Some(low);
        }
        if by_name && (ends_with_word(&s, &format!("{w}n")) || ends_with_word(&s, &format!("n{w}"))) {
            return Some(true);
        }
    }
    None
}

/// The bus's roles by name; returns the bus clock's port, if the bus has one.
fn find_bus_roles(ports: &[PortSig], overrides: &Overrides, b: PortBus, map: &mut PortMap, taken: &mut Vec<String>) -> Result<Option<String>, InferError> {
    let key = b.key();
    let mut found: Vec<(&'static str, Pin)> = Vec::new();
    for rule in bus_rules(b) {
        if let Some((_, name)) = overrides.iter().find(|(r, _)| r == rule.role) {
            let (bare, level) = name.split_once(':').unwrap_or((name, ""));
            let by_name = match rule.level {
                Level::Fixed(h) => h,
                Level::None if !level.is_empty() => return Err(InferError::Ports(format!("--port {key}.{}={name}: this role has no polarity", rule.role))),
                Level::None => true,
                Level::Name => name_fits(bare, rule.words, true).map_or(!name_says_active_low(bare), |low| !low),
            };
            let high = level_of(&format!("{key}.{}", rule.role), name, level, by_name)?;
            found.push((rule.role, Pin { name: bare.to_string(), active_high: high }));
            continue;
        }
        let by_name = rule.level == Level::Name;
        let fits: Vec<(&PortSig, bool)> = ports
            .iter()
            .filter(|p| p.dir == rule.dir && rule.width.is_none_or(|w| p.width == w) && !taken.contains(&p.name))
            .filter(|p| name_fits(&p.name, rule.not, false).is_none())
            .filter_map(|p| name_fits(&p.name, rule.words, by_name).map(|low| (p, low)))
            .collect();
        let (port, low) = match fits.as_slice() {
            [one] => *one,
            [] if rule.role == "clock" => {
                // No bus clock by its name: the one clock input the CAN
                // clock's names do not claim.
                let clocks: Vec<&PortSig> = ports
                    .iter()
                    .filter(|p| p.dir == In && p.width == 1 && !taken.contains(&p.name))
                    .filter(|p| {
                        let n = p.name.to_ascii_lowercase();
                        (n.contains("clk") || n.contains("clock")) && !n.contains("clkout") && !CAN_CLOCK.iter().any(|w| n.contains(w))
                    })
                    .collect();
                match clocks.as_slice() {
                    [one] => (*one, false),
                    [] => return Err(missing(&format!("{key}.clock"), ports)),
                    many => return Err(ambiguous(&format!("{key}.clock"), many)),
                }
            }
            [] if is_optional(b, rule.role) => continue,
            [] => return Err(missing(&format!("{key}.{}", rule.role), ports)),
            many => return Err(ambiguous(&format!("{key}.{}", rule.role), &many.iter().map(|m| m.0).collect::<Vec<_>>())),
        };
        let high = match rule.level {
            Level::None => true,
            Level::Name => !low,
            Level::Fixed(h) => h,
        };
        found.push((rule.role, Pin { name: port.name.clone(), active_high: high }));
        taken.push(port.name.clone());
    }
    if b == PortBus::Regport {
        let has = |r: &str| found.iter().any(|f| f.0 == r);
        let (one, two) = (has("adr"), has("wr-adr") && has("rd-adr"));
        if !one && !two {
            return Err(InferError::Ports(format!(
                "no address port of the register port by its name: one (`adr`) or a write and a read address (`wr-adr`, `rd-adr`) (the top has: {}); name it with --port regport.adr=NAME, or --port regport.wr-adr=NAME --port regport.rd-adr=NAME",
                names(ports)
            )));
        }
        if has("adr") && (has("wr-adr") || has("rd-adr")) {
            let list: Vec<&str> = found.iter().filter(|f| f.0.ends_with("adr")).map(|f| f.1.name.as_str()).collect();
            return Err(InferError::Ports(format!("the register port has one address or two, not both: {}; say which with --port regport.adr=NAME (or regport.wr-adr and regport.rd-adr)", list.join(", "))));
        }
    }
    let clock = found.iter().find(|f| f.0 == "clock").map(|f| f.1.name.clone());
    let target = bus_ports_mut(map, b);
    for (role, pin) in found {
        target.set(role, pin).map_err(InferError::Ports)?;
    }
    Ok(clock)
}

fn is_optional(b: PortBus, role: &str) -> bool {
    cosim::profile::BusPorts::default_for(b).optional(role)
}

/// The `[ports.<bus>]` of `b` in `m`.
pub fn bus_ports_mut(m: &mut PortMap, b: PortBus) -> &mut cosim::profile::BusPorts {
    match b {
        PortBus::Axi4Lite => &mut m.axi4lite,
        PortBus::Apb => &mut m.apb,
        PortBus::Regport => &mut m.regport,
        PortBus::Motorola => &mut m.motorola,
    }
}

/// The `[ports.<bus>]` of `b` in `m`.
pub fn bus_ports(m: &PortMap, b: PortBus) -> &cosim::profile::BusPorts {
    match b {
        PortBus::Axi4Lite => &m.axi4lite,
        PortBus::Apb => &m.apb,
        PortBus::Regport => &m.regport,
        PortBus::Motorola => &m.motorola,
    }
}

fn names(ports: &[PortSig]) -> String {
    ports.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(" ")
}

fn missing(role: &str, ports: &[PortSig]) -> InferError {
    InferError::Ports(format!("no port of the top plays `{role}` by its name, direction and width (it has: {}); name it with --port {role}=NAME", names(ports)))
}

fn ambiguous(role: &str, many: &[&PortSig]) -> InferError {
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
/// named the polarity. With a host bus, its clock (if it has one) and its
/// reset, its strobes held inactive.
pub fn polarities(model: &mut Model, map: &mut PortMap, bus: Option<PortBus>, overrides: &Overrides) -> Result<IdleLevels, InferError> {
    let port = |m: &Model, n: &str| m.port_by_name(n).map_err(|e| InferError::Ports(e.to_string()));
    let (hclk, reset) = match bus {
        None => (Some(map.host_clock.name.clone()), map.reset.clone()),
        Some(b) => {
            let bp = bus_ports(map, b);
            let clock = bp.roles().contains(&"clock").then(|| bp.pin("clock").name.clone());
            (clock, bp.pin("reset").clone())
        }
    };
    // Idle levels of the bus's 1-bit inputs: strobes inactive, R/W at a
    // read and MODE at Motorola (their active levels), the rest low.
    let mut hold: Vec<(cosim::Port, u64)> = Vec::new();
    if let Some(b) = bus {
        let bp = bus_ports(map, b);
        for rule in bus_rules(b).iter().filter(|r| r.dir == In && r.role != "reset" && r.role != "clock") {
            if !bp.named(rule.role) {
                continue;
            }
            let pin = bp.pin(rule.role);
            let v = match rule.level {
                Level::None => false,
                Level::Name => !pin.active_high,
                Level::Fixed(_) => pin.active_high,
            };
            hold.push((port(model, &pin.name)?, u64::from(v)));
        }
    }
    let hclk = hclk.filter(|h| *h != map.can_clock.name).map(|h| port(model, &h)).transpose()?;
    let (cclk, rst, rx) = (port(model, &map.can_clock.name)?, port(model, &reset.name)?, port(model, &map.rx.name)?);
    let (irq, bo) = (port(model, &map.irq.name)?, port(model, &map.bus_off.name)?);
    model.set(rx, 1);
    for (p, v) in &hold {
        model.set(*p, *v);
    }
    for cycle in 0..400u64 {
        let in_reset = cycle < 40;
        model.set(rst, u64::from(in_reset == reset.active_high));
        for (h, c) in [(1, 1), (0, 1), (1, 0), (0, 0)] {
            if let Some(hclk) = hclk {
                model.set(hclk, h);
            }
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

    fn can_side() -> Vec<PortSig> {
        vec![PortSig::new("rx_i", In, 1), PortSig::new("tx_o", Out, 1), PortSig::new("irq_on", Out, 1), PortSig::new("bus_off_on", Out, 1), PortSig::new("clkout_o", Out, 1)]
    }

    #[test]
    fn bus_roles_under_prefixes_and_polarities_by_name() {
        let mut top = can_side();
        top.extend([("apb_pclk", In, 1), ("apb_presetn", In, 1), ("apb_psel", In, 1), ("apb_penable", In, 1), ("apb_pwrite", In, 1), ("apb_paddr", In, 12), ("apb_pwdata", In, 32), ("apb_prdata", Out, 32), ("apb_pready", Out, 1), ("apb_pslverr", Out, 1), ("can_clk", In, 1)].map(|(n, d, w)| PortSig::new(n, d, w)));
        let m = find_roles(&top, &Vec::new(), Some(PortBus::Apb)).unwrap();
        assert_eq!(m.apb.pin("psel").name, "apb_psel");
        assert_eq!((m.apb.pin("reset").name.as_str(), m.apb.pin("reset").active_high), ("apb_presetn", false));
        assert!(!m.apb.named("pstrb"), "APB3: no PSTRB, left unnamed");
        assert_eq!(m.can_clock.name, "can_clk");
        assert_eq!(m.host_clock, PortMap::default().host_clock, "no Wishbone role is looked for");

        let mut top = can_side();
        top.extend([("clk", In, 1), ("nrst", In, 1), ("wr_n", In, 1), ("rd", In, 1), ("wr_addr", In, 8), ("rd_addr", In, 8), ("wdata", In, 8), ("rdata", Out, 8)].map(|(n, d, w)| PortSig::new(n, d, w)));
        let m = find_roles(&top, &Vec::new(), Some(PortBus::Regport)).unwrap();
        let r = &m.regport;
        assert_eq!((r.pin("wr").active_high, r.pin("rd").active_high, r.pin("reset").active_high), (false, true, false));
        assert_eq!((r.pin("wr-adr").name.as_str(), r.pin("rd-adr").name.as_str(), r.named("adr")), ("wr_addr", "rd_addr", false));
        assert_eq!(m.can_clock.name, "clk", "the one clock is the CAN clock");
    }

    #[test]
    fn one_clock_for_the_bus_and_the_core() {
        let mut top = can_side();
        let axi = ["awvalid", "awaddr", "awprot", "wvalid", "wdata", "wstrb", "bready", "arvalid", "araddr", "arprot", "rready"].map(|n| PortSig::new(&format!("S_AXI_{}", n.to_uppercase()), In, 1));
        let outs = ["awready", "wready", "bvalid", "bresp", "arready", "rvalid", "rdata", "rresp"].map(|n| PortSig::new(&format!("S_AXI_{}", n.to_uppercase()), Out, 1));
        top.extend(axi.into_iter().chain(outs));
        top.extend([PortSig::new("S_AXI_ACLK", In, 1), PortSig::new("S_AXI_ARESETN", In, 1)]);
        let m = find_roles(&top, &Vec::new(), Some(PortBus::Axi4Lite)).unwrap();
        assert_eq!((m.axi4lite.pin("clock").name.as_str(), m.can_clock.name.as_str()), ("S_AXI_ACLK", "S_AXI_ACLK"));
    }

    #[test]
    fn short_words_are_words() {
        assert!(has_word("wb_we_i", "we") && !has_word("power", "we"));
        assert!(has_word("can_rx", "rx") && has_word("rx_i", "rx") && !has_word("rxerr_cnt", "rx"));
        assert!(has_word("bus_off_on", "bus_off") && !has_word("bonus", "bo"));
    }
}
