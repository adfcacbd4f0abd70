//! An external 8051-bus core whose shared port is an `inout` (the
//! opencores `can_top` without `CAN_WISHBONE_IF`), made bindable: its
//! sources plus the shell top of [`crate::i8051_inout_shell`], written once
//! into the build cache. Asked for by a profile's `[access.i8051]
//! inout-drive` (the condition under which the core drives the port).

use std::path::{Path, PathBuf};

use crate::bridge::{BridgeError, ExternalCore};
use crate::dut::{I8051_SHELL_TOP, i8051_inout_shell};

fn is_source(p: &Path) -> bool {
    matches!(p.extension().and_then(|e| e.to_str()), Some("v" | "sv" | "vhd" | "vhdl"))
}

/// `core` behind the shell: top [`I8051_SHELL_TOP`], files = its sources
/// (its `files`, else every `.v`/`.sv`/`.vhd`/`.vhdl` of its directory)
/// and the shell, whose `port_0_oe` is `drive_expr`.
pub fn wrap(core: &ExternalCore, drive_expr: &str, cache: &Path) -> Result<ExternalCore, BridgeError> {
    let io = |context: String| move |source| BridgeError::Io { context, source };
    let mut files: Vec<PathBuf> = if core.files.is_empty() {
        let mut v: Vec<PathBuf> = std::fs::read_dir(&core.dir)
            .map_err(io(format!("reading core directory {}", core.dir.display())))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| is_source(p))
            .collect();
        v.sort();
        v
    } else {
        core.files.iter().map(|f| if f.is_absolute() { f.clone() } else { core.dir.join(f) }).collect()
    };
    let text = i8051_inout_shell(&core.top, drive_expr);
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for b in text.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x100_0000_01b3);
    }
    let file = format!("{I8051_SHELL_TOP}.v");
    let entry = buildcache::build_once(&cache.join(format!("i8051-shell-{h:016x}")), &file, |work| {
        std::fs::write(work.join(&file), &text).map_err(io(format!("writing {file}")))
    })
    .map_err(|e| match e {
        buildcache::Error::Build(e) => e,
        buildcache::Error::Io { what, source } => BridgeError::Io { context: what, source },
    })?;
    files.push(entry.product);
    Ok(ExternalCore { top: I8051_SHELL_TOP.into(), files, ..core.clone() })
}
