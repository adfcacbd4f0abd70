//! Platform Designer (Qsys) component description for the Avalon wrapper.

use super::stamp;
use crate::Mode;
use std::fmt::Write;

/// Options of the `_hw.tcl` generator.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TclOptions {
    /// Module (and component) name: `can_avalon`, the RTL top of the wrapper.
    pub name: String,
    /// Width of `address`: 8 covers the PeliCAN map (128 registers) with room
    /// for the mirror the RTL may decode; 7 is the minimum.
    pub address_width: u8,
    /// Verilog files of the component, relative to the `_hw.tcl`; the first
    /// one holds the top level.
    pub files: Vec<String>,
}

impl Default for TclOptions {
    fn default() -> Self {
        TclOptions { name: "can_avalon".to_string(), address_width: 8, files: RTL_FILES.iter().map(|f| f.to_string()).collect() }
    }
}

/// The files of our Avalon component, top level first: every `rtl/` file
/// `can_avalon` needs (a test checks this list against the directory).
pub const RTL_FILES: &[&str] = &[
    "can_avalon.v",
    "can_top.v",
    "can_wb_cdc.v",
    "can_regs.v",
    "can_btl.v",
    "can_bsp.v",
    "can_fce.v",
    "can_acf.v",
    "can_rxfifo.v",
    "sja1000_addr.vh",
];

/// The ports of the wrapper: (interface, port, role, direction, width).
/// The RTL's `can_avalon.v` uses exactly these names.
pub fn ports(opts: &TclOptions) -> Vec<(&'static str, &'static str, &'static str, &'static str, u8)> {
    vec![
        ("clock", "clk", "clk", "Input", 1),
        ("reset", "reset", "reset", "Input", 1),
        ("avalon_slave", "address", "address", "Input", opts.address_width),
        ("avalon_slave", "chipselect", "chipselect", "Input", 1),
        ("avalon_slave", "read", "read", "Input", 1),
        ("avalon_slave", "write", "write", "Input", 1),
        ("avalon_slave", "writedata", "writedata", "Input", 8),
        ("avalon_slave", "readdata", "readdata", "Output", 8),
        ("avalon_slave", "waitrequest", "waitrequest", "Output", 1),
        ("irq", "irq", "irq", "Output", 1),
        ("can", "can_clk", "can_clk", "Input", 1),
        ("can", "rx", "rx", "Input", 1),
        ("can", "tx", "tx", "Output", 1),
        ("can", "bus_off_on", "bus_off_on", "Output", 1),
        ("can", "clkout", "clkout", "Output", 1),
    ]
}

/// `<name>_hw.tcl`: an Avalon-MM slave (8-bit data, addressUnits WORDS so
/// register n is byte n, waitrequest-controlled reads and writes), clock
/// and reset sinks, an active-high interrupt sender tied to the slave, and
/// a `can` conduit exporting the CAN clock, rx, tx, bus_off_on and clkout.
pub fn hw_tcl(opts: &TclOptions) -> String {
    let n = &opts.name;
    let span = 1u32 << opts.address_width;
    let mut o = String::new();
    let _ = writeln!(o, "# {n}_hw.tcl: Platform Designer component for the SJA1000-compatible CAN controller.");
    let _ = writeln!(o, "# {}", stamp());
    let _ = writeln!(o, "#");
    let _ = writeln!(o, "# Registers: one byte each, register n at byte offset n from the slave base");
    let _ = writeln!(o, "# ({} addresses in the PeliCAN view, {} in BasicCAN); use the generated", Mode::PeliCan.addr_limit(), Mode::BasicCan.addr_limit());
    let _ = writeln!(o, "# *_regs.h with byte spacing (IORD_8DIRECT/IOWR_8DIRECT).");
    let _ = writeln!(o);
    let _ = writeln!(o, "package require -exact qsys 16.1\n");
    for (k, v) in [
        ("DESCRIPTION", "\"SJA1000-compatible CAN 2.0B controller (BasicCAN and PeliCAN), Avalon-MM slave\""),
        ("NAME", n.as_str()),
        ("VERSION", env!("CARGO_PKG_VERSION")),
        ("INTERNAL", "false"),
        ("OPAQUE_ADDRESS_MAP", "true"),
        ("GROUP", "\"Interface Protocols/CAN\""),
        ("DISPLAY_NAME", "\"SJA1000-compatible CAN controller\""),
        ("INSTANTIATE_IN_SYSTEM_MODULE", "true"),
        ("EDITABLE", "false"),
        ("REPORT_TO_TALKBACK", "false"),
        ("ALLOW_GREYBOX_GENERATION", "false"),
        ("REPORT_HIERARCHY", "false"),
    ] {
        let _ = writeln!(o, "set_module_property {k} {v}");
    }
    let _ = writeln!(o);
    for fs in ["QUARTUS_SYNTH", "SIM_VERILOG"] {
        let _ = writeln!(o, "add_fileset {fs} {fs} \"\" \"\"");
        let _ = writeln!(o, "set_fileset_property {fs} TOP_LEVEL {n}");
        let _ = writeln!(o, "set_fileset_property {fs} ENABLE_RELATIVE_INCLUDE_PATHS false");
        for (i, f) in opts.files.iter().enumerate() {
            let top = if i == 0 { " TOP_LEVEL_FILE" } else { "" };
            let kind = if f.ends_with(".vh") { "VERILOG_INCLUDE" } else { "VERILOG" };
            let _ = writeln!(o, "add_fileset_file {f} {kind} PATH {f}{top}");
        }
        let _ = writeln!(o);
    }
    let _ = writeln!(o, "# Clock and reset of the host bus side.");
    let _ = writeln!(o, "add_interface clock clock end");
    let _ = writeln!(o, "set_interface_property clock clockRate 0");
    let _ = writeln!(o, "set_interface_property clock ENABLED true\n");
    let _ = writeln!(o, "add_interface reset reset end");
    let _ = writeln!(o, "set_interface_property reset associatedClock clock");
    let _ = writeln!(o, "set_interface_property reset synchronousEdges DEASSERT");
    let _ = writeln!(o, "set_interface_property reset ENABLED true\n");
    let _ = writeln!(o, "# Avalon-MM slave: 8-bit registers, waitrequest holds the master until the");
    let _ = writeln!(o, "# core answers (its register file runs on the CAN clock domain).");
    let _ = writeln!(o, "add_interface avalon_slave avalon end");
    for (k, v) in [
        ("addressUnits", "WORDS".to_string()),
        ("associatedClock", "clock".to_string()),
        ("associatedReset", "reset".to_string()),
        ("bitsPerSymbol", "8".to_string()),
        ("burstOnBurstBoundariesOnly", "false".to_string()),
        ("burstcountUnits", "WORDS".to_string()),
        ("explicitAddressSpan", span.to_string()),
        ("holdTime", "0".to_string()),
        ("linewrapBursts", "false".to_string()),
        ("maximumPendingReadTransactions", "0".to_string()),
        ("maximumPendingWriteTransactions", "0".to_string()),
        ("readLatency", "0".to_string()),
        ("readWaitTime", "0".to_string()),
        ("setupTime", "0".to_string()),
        ("timingUnits", "Cycles".to_string()),
        ("writeWaitTime", "0".to_string()),
        ("ENABLED", "true".to_string()),
    ] {
        let _ = writeln!(o, "set_interface_property avalon_slave {k} {v}");
    }
    let _ = writeln!(o, "set_interface_assignment avalon_slave embeddedsw.configuration.isFlash 0");
    let _ = writeln!(o, "set_interface_assignment avalon_slave embeddedsw.configuration.isMemoryDevice 0");
    let _ = writeln!(o, "set_interface_assignment avalon_slave embeddedsw.configuration.isNonVolatileStorage 0");
    let _ = writeln!(o, "set_interface_assignment avalon_slave embeddedsw.configuration.isPrintableDevice 0\n");
    let _ = writeln!(o, "# Interrupt: active high, level, tied to the slave.");
    let _ = writeln!(o, "add_interface irq interrupt end");
    let _ = writeln!(o, "set_interface_property irq associatedAddressablePoint avalon_slave");
    let _ = writeln!(o, "set_interface_property irq associatedClock clock");
    let _ = writeln!(o, "set_interface_property irq associatedReset reset");
    let _ = writeln!(o, "set_interface_property irq bridgedReceiverOffset \"\"");
    let _ = writeln!(o, "set_interface_property irq bridgesToReceiver \"\"");
    let _ = writeln!(o, "set_interface_property irq irqScheme NONE");
    let _ = writeln!(o, "set_interface_property irq ENABLED true\n");
    let _ = writeln!(o, "# CAN side, exported: CAN clock (clk_i of the core), bus pins, status, CLKOUT.");
    let _ = writeln!(o, "add_interface can conduit end");
    let _ = writeln!(o, "set_interface_property can associatedClock \"\"");
    let _ = writeln!(o, "set_interface_property can associatedReset \"\"");
    let _ = writeln!(o, "set_interface_property can ENABLED true\n");
    let _ = writeln!(o, "# Ports: interface, name, role, direction, width.");
    for (iface, port, role, dir, w) in ports(opts) {
        let _ = writeln!(o, "add_interface_port {iface} {port} {role} {dir} {w}");
    }
    o
}
