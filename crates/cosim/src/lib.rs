//! Co-simulation of HDL CAN controllers against the golden model: a thin
//! Verilator bridge of our own ([`bridge`], see the README's design notes),
//! a simulation kernel with two independent clocks ([`kernel`]), DUTs
//! (Verilated RTL, the golden model itself, or a Rust twin of a fixture:
//! [`dut`]), a bit clock, a lockstep comparator ([`compare`]), a VCD
//! writer ([`wave`]) and the [`Testbench`] that ties them together.
#![warn(missing_docs)]

pub mod bitclock;
pub mod candump;
pub mod bridge;
pub mod compare;
pub mod coverage;
pub mod dut;
pub mod gtkw;
pub mod holdoff;
pub mod kernel;
pub mod model;
pub mod perf;
pub mod profile;
pub mod shimgen;
pub mod testbench;
pub mod wave;

pub use bridge::{BridgeError, CompiledCore, ExternalCore, Model, Port, PortInfo, bundled_tops};
pub use compare::{Comparator, CompareConfig, Reference};
pub use dut::{
    CanPins, Dut, EchoModel, HostPort, I8051_SHELL_TOP, VerilatedDut, i8051_inout_shell,
};
pub use kernel::{Kernel, KernelError, Tick};
pub use model::{ModelDut, ModelRef};
pub use profile::{AccessTiming, PhaseOrigin, PortMap, Profile, ProfileError};
pub use testbench::{
    AvalonWiring, CustomDut, DutChoice, HostBfm, NodeConfig, ReferenceChoice, TbConfig, TbError,
    Testbench, i8051_timing_for_rtl,
};
/// The waivers crate the test bench takes (`TbConfig::waivers`) and reports
/// with (`Testbench::waiver_report`), for callers without their own dependency.
pub use waivers;
