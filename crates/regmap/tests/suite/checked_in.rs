//! `crates/regmap/generated/` holds the generated files (default options)
//! for people who want them without running Rust: Quartus projects, the
//! Nios software, the C driver's FFI shim. This test fails if they are
//! stale. Update switch: `REGMAP_BLESS=1 cargo test -p regmap --test suite checked_in::`.

use regmap::generate::{all_files, GenOptions};
use std::path::Path;

#[test]
fn checked_in_generated_files_are_up_to_date() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("generated");
    let bless = std::env::var_os("REGMAP_BLESS").is_some();
    if bless {
        std::fs::create_dir_all(&dir).unwrap();
    }
    for (name, text) in all_files(&GenOptions::default()) {
        let p = dir.join(&name);
        if bless {
            std::fs::write(&p, &text).unwrap();
            continue;
        }
        let on_disk = std::fs::read_to_string(&p).unwrap_or_else(|e| {
            panic!("{}: {e}; regenerate with REGMAP_BLESS=1 cargo test -p regmap --test suite checked_in::", p.display())
        });
        assert!(
            on_disk == text,
            "{} is stale; regenerate with REGMAP_BLESS=1 cargo test -p regmap --test suite checked_in::",
            p.display()
        );
    }
}

/// The `_hw.tcl` file set must carry every RTL file `can_avalon` needs, or
/// Platform Designer cannot elaborate the component: compare it with `rtl/`
/// (every file but the `can_top_pio`, `can_top_8051`, `can_top_mcu`, `can_regport`, `can_axi4lite` and `can_apb` variants, which the
/// wrapper does not use).
#[test]
fn hw_tcl_file_set_is_the_rtl_directory() {
    let rtl = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../rtl");
    let mut on_disk: Vec<String> = std::fs::read_dir(&rtl)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .filter(|n| (n.ends_with(".v") || n.ends_with(".vh")) && !["can_top_pio.v", "can_top_8051.v", "can_top_mcu.v", "can_regport.v", "can_axi4lite.v", "can_apb.v"].contains(&n.as_str()))
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = regmap::generate::RTL_FILES.iter().map(|s| s.to_string()).collect();
    listed.sort();
    assert_eq!(listed, on_disk, "regmap::generate::RTL_FILES and rtl/ disagree");
    let tcl = regmap::generate::hw_tcl(&regmap::generate::TclOptions::default());
    for f in regmap::generate::RTL_FILES {
        assert!(tcl.contains(&format!("add_fileset_file {f} ")), "{f} missing from the _hw.tcl");
    }
    assert!(tcl.contains("add_fileset_file sja1000_addr.vh VERILOG_INCLUDE"));
}
