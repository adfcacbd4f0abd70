//! Helpers shared by the ignored tests that run `cancosim` on the opencores
//! core (`CAN_UPSTREAM_DIR`): upstream, upstream_resync, upstream_lists.
#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};

/// The project's root (where `tb/` is).
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The core's directory from `CAN_UPSTREAM_DIR`, checked to hold `file`.
pub fn upstream_dir(file: &str) -> PathBuf {
    let d = std::env::var_os("CAN_UPSTREAM_DIR")
        .map(PathBuf::from)
        .expect("set CAN_UPSTREAM_DIR to the upstream core's directory (rtl/verilog files and timescale.v)");
    assert!(d.join(file).is_file(), "{}: no {file}", d.display());
    d
}

/// The `cancosim` built beside this test (`target/<profile>/cancosim`), or `$CANCOSIM`.
pub fn cancosim() -> PathBuf {
    if let Some(p) = std::env::var_os("CANCOSIM") {
        return PathBuf::from(p);
    }
    let exe = std::env::current_exe().unwrap();
    let bin = exe.parent().and_then(Path::parent).unwrap().join("cancosim");
    assert!(bin.is_file(), "{} missing: run `cargo build --release -p cancosim` first (or set CANCOSIM)", bin.display());
    bin
}
