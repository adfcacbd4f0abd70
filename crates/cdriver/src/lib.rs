//! The C driver of `crates/regmap/c/` (written against the generated
//! `can_sja_regs.h` only), compiled with `cc` and run on the host against
//! the simulated core: its `IORD`/`IOWR` go through the callback stand-in
//! for `io.h` into a host BFM that drives our RTL or the golden model,
//! with a golden-model node on the CAN bus.
//!
//! ```no_run
//! use cdriver::{BenchHost, CDriver, Config, View};
//! use cosim::{DutChoice, HostBfm};
//! let host = BenchHost::with_model_node(DutChoice::Model, HostBfm::Wishbone, View::Peli).unwrap();
//! let mut drv = CDriver::new(host);
//! drv.init(View::Peli, &Config::accept_all()).unwrap();
//! ```
#![warn(missing_docs)]

mod driver;
mod ffi;
pub mod sim;

pub use driver::{CAN_BASE, CDriver, CDriverError, Capture, Config, Direct, ErrorStatus, Host, Pio, PioHost, ViaPio, View, Wiring, ecc_kind, pio_reg};
pub use sim::{BenchHost, PioBench, SimHost, model_node};
