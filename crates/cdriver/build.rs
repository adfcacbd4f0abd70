//! Compiles the C driver of `crates/regmap/c` (unchanged, against the
//! checked-in generated headers) with the run-time callback stand-in for
//! `io.h`, plus our PIO shim that runs the generated `can_sja_pio.h`
//! accessors, into one static library linked into this crate.

use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let regmap_c = manifest.join("../regmap/c");
    let generated = manifest.join("../regmap/generated");
    let ours = manifest.join("c");
    for p in [
        regmap_c.join("can_driver.c"),
        regmap_c.join("can_driver.h"),
        regmap_c.join("host_io_callback.c"),
        regmap_c.join("host_io_callback.h"),
        regmap_c.join("io.h"),
        regmap_c.join("altera_avalon_pio_regs.h"),
        generated.join("can_sja_regs.h"),
        generated.join("can_sja_pio.h"),
        ours.join("pio_shim.c"),
    ] {
        println!("cargo:rerun-if-changed={}", p.display());
    }
    cc::Build::new()
        .std("c99")
        .include(&regmap_c)
        .include(&generated)
        .file(regmap_c.join("can_driver.c"))
        .file(regmap_c.join("host_io_callback.c"))
        .file(ours.join("pio_shim.c"))
        .warnings(true)
        .extra_warnings(true)
        .warnings_into_errors(true)
        .flag("-pedantic")
        .compile("cdriver_c");
}
