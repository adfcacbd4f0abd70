//! `gen`: write the files derived from the one register map (Nios `_regs.h`,
//! PIO access header, Platform Designer `_hw.tcl`, Markdown reference,
//! Verilog include) into a directory; `gen reference`: the reference pages
//! of the command line and file formats ([`super::reference`]).

use anyhow::Context;
use regmap::generate::{GenOptions, HeaderOptions, Spacing, TclOptions, write_all};
use std::path::PathBuf;

/// Arguments of `cancosim gen`.
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct Args {
    #[command(subcommand)]
    what: Option<What>,
    /// Output directory (created if missing).
    #[arg(long, short, default_value = "out/gen")]
    out: PathBuf,
    /// Upper-case C identifier prefix; the header is `<prefix>_regs.h`.
    #[arg(long, default_value = "CAN_SJA")]
    prefix: String,
    /// Register spacing on the host bus: `byte` (IORD_8DIRECT, matches can_avalon) or `word` (IORD, 4-byte stride).
    #[arg(long, default_value = "byte", value_parser = ["byte", "word"])]
    spacing: String,
    /// Platform Designer component name (the wrapper's module name).
    #[arg(long, default_value = "can_avalon")]
    component: String,
}

/// What else `gen` writes.
#[derive(clap::Subcommand)]
enum What {
    /// Write (or --check) the reference generated from the code: man pages, shell completions, the command line and the scenario, profile and waiver file formats in Markdown.
    #[command(after_help = "Examples:\n  cancosim gen reference                 (rewrite docs/reference)\n  cancosim gen reference --check         (exit 1 if docs/reference differs from the code)")]
    Reference(super::reference::Args),
}

/// Runs the subcommand; returns the exit code.
pub fn run(a: Args) -> anyhow::Result<i32> {
    if let Some(What::Reference(r)) = a.what {
        return super::reference::run(r);
    }
    if a.prefix.is_empty() || !a.prefix.chars().all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_') {
        anyhow::bail!("--prefix '{}' must be an upper-case C identifier such as CAN_SJA", a.prefix);
    }
    let opts = GenOptions {
        header: HeaderOptions {
            prefix: a.prefix,
            spacing: if a.spacing == "word" { Spacing::Word } else { Spacing::Byte },
        },
        tcl: TclOptions { name: a.component, ..TclOptions::default() },
    };
    let files = write_all(&a.out, &opts).with_context(|| format!("writing into {}", a.out.display()))?;
    for f in files {
        println!("wrote {}", f.display());
    }
    Ok(0)
}
