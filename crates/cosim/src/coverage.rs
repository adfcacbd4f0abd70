//! Code coverage of a Verilated DUT (`regress --coverage`): the same DUT as
//! [`DutChoice`] names, built at run time with Verilator's coverage
//! (`ExternalCore::coverage`, a cache entry of its own) and instantiated so
//! that it writes its counters to a `.dat` when the test bench drops it.
//! Our RTL's bundled tops are rebuilt from `rtl/` for this; the normal,
//! faster bundled models are left as they are.

use std::path::{Path, PathBuf};

use crate::bridge::{BridgeError, ExternalCore};
use crate::dut::{DutChoice, HostPort, VerilatedDut};
use crate::profile::PortMap;
use crate::error::TbError;

/// Our RTL's directory (the sources the bundled tops were built from).
pub fn rtl_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../rtl");
    // Without `..`: the coverage report names files by this path.
    std::fs::canonicalize(&d).unwrap_or(d)
}

/// The core (with coverage on) and host port a DUT choice stands for, or
/// why it has no code coverage (the golden model and Rust DUTs).
pub fn coverage_core(choice: &DutChoice, host: HostPort) -> Result<(ExternalCore, HostPort), TbError> {
    let rtl = |top: &str| ExternalCore { dir: rtl_dir(), top: top.into(), coverage: true, ..ExternalCore::default() };
    Ok(match choice {
        DutChoice::Rtl if host == HostPort::I8051 => (rtl("can_top_8051"), HostPort::I8051),
        DutChoice::Rtl if host == HostPort::Axi4Lite => (rtl("can_axi4lite"), host),
        DutChoice::Rtl if host == HostPort::Apb => (rtl("can_apb"), host),
        DutChoice::Rtl if host == HostPort::Motorola => (rtl("can_top_mcu"), host),
        DutChoice::Rtl if host == HostPort::Regport => (rtl("can_regport"), host),
        DutChoice::Rtl => (rtl("can_top"), HostPort::Wishbone),
        DutChoice::RtlAvalon => (rtl("can_avalon"), HostPort::Avalon),
        DutChoice::Bundled(top) => (rtl(top), host),
        DutChoice::External(core) => (ExternalCore { coverage: true, ..core.clone() }, host),
        DutChoice::Model | DutChoice::Echo | DutChoice::Custom(_) => {
            return Err(TbError::Config(
                "code coverage needs a Verilated DUT (our RTL or an external core); the golden model and Rust DUTs have none".into(),
            ));
        }
    })
}

/// The DUT of `choice` built with coverage; it writes `dat` when dropped.
pub fn covered_dut(choice: &DutChoice, host: HostPort, ports: &PortMap, trace: bool, dat: &Path) -> Result<VerilatedDut, TbError> {
    let (core, host) = coverage_core(choice, host)?;
    let model = crate::verilated::build_external(&core)?.instantiate_with_coverage(trace, dat)?;
    // As `Testbench::new` binds the same choice without coverage.
    let dut = match choice {
        DutChoice::Rtl | DutChoice::RtlAvalon => VerilatedDut::new(model, host),
        _ => VerilatedDut::with_ports(model, host, ports),
    };
    dut.map_err(|e: BridgeError| e.into())
}
