//! `crates/regmap/generated/` holds the generated files (default options)
//! for people who want them without running Rust: Quartus projects, the
//! Nios software, the C driver's FFI shim. This test fails if they are
//! stale. Update switch: `REGMAP_BLESS=1 cargo test -p regmap --test checked_in`.

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
            panic!("{}: {e}; regenerate with REGMAP_BLESS=1 cargo test -p regmap --test checked_in", p.display())
        });
        assert!(
            on_disk == text,
            "{} is stale; regenerate with REGMAP_BLESS=1 cargo test -p regmap --test checked_in",
            p.display()
        );
    }
}
