//! Writes every generated file into a directory: `cargo run -p regmap
//! --example regmap_gen -- <dir> [byte|word]` (the `cancosim gen`
//! subcommand does the same from the CLI).
use regmap::generate::{write_all, GenOptions, HeaderOptions, Spacing};

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(dir) = args.next() else {
        eprintln!("usage: regmap_gen <dir> [byte|word]");
        std::process::exit(2);
    };
    let spacing = match args.next().map(|s| s.parse::<Spacing>()) {
        None => Spacing::Byte,
        Some(Ok(s)) => s,
        Some(Err(e)) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let opts = GenOptions { header: HeaderOptions { spacing, ..Default::default() }, ..Default::default() };
    match write_all(std::path::Path::new(&dir), &opts) {
        Ok(paths) => {
            for p in paths {
                println!("{}", p.display());
            }
        }
        Err(e) => {
            eprintln!("cannot write into {dir}: {e}");
            std::process::exit(1);
        }
    }
}
