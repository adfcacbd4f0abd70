//! Why a test-bench call failed: one error type for building the DUT
//! (bridge, coverage build), the clocks, host accesses and the run.

use bfm::BfmError;

use crate::bridge::BridgeError;
use crate::kernel::KernelError;

/// Why a test-bench call failed. Each prints as one paragraph.
#[derive(Debug, thiserror::Error)]
pub enum TbError {
    /// Building or binding the DUT failed.
    #[error(transparent)]
    Bridge(#[from] BridgeError),
    /// Bad clocks.
    #[error(transparent)]
    Kernel(#[from] KernelError),
    /// A configuration that cannot work.
    #[error("test bench configuration: {0}")]
    Config(String),
    /// A host access did not complete.
    #[error("host {op} at 0x{addr:02X}: {error}{monitor}")]
    Host {
        /// "read" or "write".
        op: &'static str,
        /// Address.
        addr: u8,
        /// The BFM's error.
        error: BfmError,
        /// What the protocol monitor saw, if anything.
        monitor: String,
    },
    /// Something awaited did not happen in time.
    #[error("timeout after {bits} bit times waiting for {what}")]
    Timeout {
        /// What.
        what: String,
        /// How long.
        bits: u64,
    },
    /// The comparator found a divergence; the run stopped there.
    #[error("DUT diverged from the reference: {0}")]
    Diverged(String),
    /// Writing the VCD failed.
    #[error("VCD: {0}")]
    Io(#[from] std::io::Error),
}

