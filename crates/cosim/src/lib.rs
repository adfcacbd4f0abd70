//! Co-simulation of HDL CAN controllers against the golden model: the
//! Verilator bridge (the `vbridge` crate, re-exported as [`bridge`]; our
//! tops and inner loop in [`verilated`]),
//! a simulation kernel with two independent clocks ([`kernel`]), DUTs
//! (Verilated RTL, the golden model itself, or a Rust twin of a fixture:
//! [`dut`]), a bit clock, a lockstep comparator ([`compare`]), a VCD
//! writer ([`wave`]) and the [`Testbench`] that ties them together.
#![warn(missing_docs)]

pub mod agents;
/// The lockstep comparator under its old path (now the comparator agent).
pub use agents::comparator as compare;
/// The CLKOUT checker under its path before the split (now in the comparator agent).
pub use agents::comparator::clkout;
mod batch_shim;
pub mod bitclock;
pub mod candump;
pub mod coverage;
pub mod dut;
pub mod error;
pub mod gtkw;
pub mod holdoff;
pub mod i8051_shell;
pub mod kernel;
pub mod model;
pub mod perf;
pub mod profile;
pub mod testbench;
pub mod types;
pub mod verilated;
pub mod wave;

/// The Verilator bridge (`vbridge`), under the name it had in this crate.
pub use vbridge as bridge;
/// GHDL lowering of VHDL sources (in `vbridge`, under its old name here).
pub use vbridge::vhdl;
pub use vbridge::{BridgeError, CompiledCore, ExternalCore, Model, Port, PortInfo};
pub use verilated::{build_external, bundled, bundled_tops, cache_dir};
pub use compare::{Comparator, CompareConfig, Reference};
pub use dut::{
    CanPins, Dut, EchoModel, HostPort, I8051_SHELL_TOP, VerilatedDut, i8051_inout_shell,
};
pub use kernel::{Kernel, KernelError, Tick};
pub use model::{ModelDut, ModelRef};
pub use profile::{AccessTiming, BusPorts, MotorolaAccess, PhaseOrigin, PortBus, PortMap, Profile, ProfileError, RegLayout, RegportAccess};
pub use testbench::{
    AvalonWiring, CustomDut, DutChoice, HostBfm, NodeConfig, ReferenceChoice, TbConfig, TbError,
    Testbench, i8051_timing_for_rtl,
};
/// The waivers crate the test bench takes (`TbConfig::waivers`) and reports
/// with (`Testbench::waiver_report`), for callers without their own dependency.
pub use waivers;
