//! `gen`: write the files derived from the one register map (Nios `_regs.h`,
//! PIO access header, Platform Designer `_hw.tcl`, Markdown reference,
//! Verilog include) into a directory; `gen devicetree`: a device-tree node
//! for Linux's sja1000 driver; `gen reference`: the reference pages of the
//! command line and file formats ([`super::reference`]).

use anyhow::Context;
use regmap::generate::{dt_node, write_all, DtOptions, GenOptions, HeaderOptions, Spacing, TclOptions};
use std::path::{Path, PathBuf};

/// Where the registers sit on the host bus: `--stride`/`--byte-lane`, or
/// the `[access.<bus>]` table of a core profile.
#[derive(clap::Args, Clone, Debug)]
pub struct LayoutArgs {
    /// Bytes from one register to the next: 1, 2 or 4 (register n at base + n * stride). Overrides the profile's.
    #[arg(long, value_parser = ["1", "2", "4"])]
    stride: Option<String>,
    /// Byte lane of the register's data inside its stride (0 = bits 7..0). Overrides the profile's.
    #[arg(long)]
    byte_lane: Option<u32>,
    /// Read `stride` and `byte-lane` from this core profile's `[access.<host>]` table.
    #[arg(long, value_name = "FILE", requires = "host")]
    profile: Option<PathBuf>,
    /// The host bus whose `[access.<host>]` table of --profile to read (e.g. axi4-lite, wishbone).
    #[arg(long, requires = "profile")]
    host: Option<String>,
}

impl LayoutArgs {
    /// Stride and lane: the options, else the profile's, else 1 and 0.
    fn resolve(&self, default: Spacing) -> anyhow::Result<(Spacing, u32)> {
        let (mut stride, mut lane) = (None, None);
        if let (Some(p), Some(h)) = (&self.profile, &self.host) {
            (stride, lane) = profile_layout(p, h)?;
        }
        if let Some(s) = &self.stride {
            stride = Some(s.parse().expect("clap checked 1, 2 or 4"));
        }
        if self.byte_lane.is_some() {
            lane = self.byte_lane;
        }
        let spacing = match stride {
            Some(s) => Spacing::from_stride(s)?,
            None => default,
        };
        Ok((spacing, lane.unwrap_or(0)))
    }
}

/// `stride` and `byte-lane` of a profile's `[access.<host>]` table (either may be absent).
fn profile_layout(path: &Path, host: &str) -> anyhow::Result<(Option<u32>, Option<u32>)> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading the profile {}", path.display()))?;
    let doc: toml::Table = text.parse().with_context(|| format!("{} is not valid TOML", path.display()))?;
    let Some(table) = doc.get("access").and_then(|a| a.get(host)) else {
        anyhow::bail!("{} has no [access.{host}] table (its stride and byte lane)", path.display());
    };
    let key = |k: &str| -> anyhow::Result<Option<u32>> {
        match table.get(k) {
            None => Ok(None),
            Some(toml::Value::Integer(n)) if (0..=u32::MAX as i64).contains(n) => Ok(Some(*n as u32)),
            Some(v) => anyhow::bail!("{}: [access.{host}] {k} = {v} is not a whole number", path.display()),
        }
    };
    Ok((key("stride")?, key("byte-lane")?))
}

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
    /// Register spacing on the host bus: `byte` (IORD_8DIRECT, matches can_avalon) or `word` (IORD, 4-byte stride); --stride says the same for any stride.
    #[arg(long, default_value = "byte", value_parser = ["byte", "word"])]
    spacing: String,
    #[command(flatten)]
    layout: LayoutArgs,
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
    /// Write a device-tree node for Linux's sja1000 platform driver (compatible "nxp,sja1000"): reg and reg-io-width from the base and stride, the interrupt, and the clock and output properties from OCR, CDR and the clock.
    #[command(after_help = "Examples:\n  cancosim gen devicetree --base 0xff200000 --interrupts \"0 40 4\" --interrupt-parent intc\n  cancosim gen devicetree --stride 4 --clock 50MHz --ocr 0x1A --cdr 0x81 --out can.dtsi\n  cancosim gen devicetree --profile tb/profiles/mycore.toml --host axi4-lite --btr0 0x00 --btr1 0x1C")]
    Devicetree(DtArgs),
}

/// Arguments of `cancosim gen devicetree`.
#[derive(clap::Args)]
pub struct DtArgs {
    /// Write the node here (default: standard output).
    #[arg(long, short)]
    out: Option<PathBuf>,
    /// Bus address of register 0 (32 bits).
    #[arg(long, default_value = "0", value_parser = parse_address)]
    base: u32,
    /// Node name before the @.
    #[arg(long, default_value = "can")]
    name: String,
    /// The `interrupts` cells, space-separated, as the interrupt controller wants them.
    #[arg(long, default_value = "0")]
    interrupts: String,
    /// Label of the interrupt controller (`interrupt-parent = <&LABEL>`); none: inherited.
    #[arg(long)]
    interrupt_parent: Option<String>,
    /// The core's clock input (the SJA1000's oscillator), e.g. 24MHz.
    #[arg(long, default_value = "24MHz", value_parser = super::parse_si)]
    clock: u32,
    /// Output control register (OCR) value: nxp,tx-output-mode and nxp,tx-output-config.
    #[arg(long, default_value = "0xDA", value_parser = super::parse_byte)]
    ocr: u8,
    /// Clock divider register (CDR) value: nxp,clock-out-frequency, nxp,no-comparator-bypass.
    #[arg(long, default_value = "0xC8", value_parser = super::parse_byte)]
    cdr: u8,
    /// BTR0 of the chosen bit timing (with --btr1): the bit rate, said in a comment.
    #[arg(long, value_parser = super::parse_byte, requires = "btr1")]
    btr0: Option<u8>,
    /// BTR1 of the chosen bit timing (with --btr0).
    #[arg(long, value_parser = super::parse_byte, requires = "btr0")]
    btr1: Option<u8>,
    #[command(flatten)]
    layout: LayoutArgs,
}

/// "0xff200000" or a decimal address.
fn parse_address(s: &str) -> Result<u32, String> {
    let t = s.trim().replace('_', "");
    let r = match t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        Some(h) => u32::from_str_radix(h, 16),
        None => t.parse(),
    };
    r.map_err(|_| format!("'{s}' is not a 32-bit address (decimal or 0x..)"))
}

fn devicetree(a: DtArgs) -> anyhow::Result<i32> {
    let (spacing, lane) = a.layout.resolve(Spacing::Byte)?;
    let interrupts = a
        .interrupts
        .split_whitespace()
        .map(|c| c.parse::<u32>().map_err(|_| anyhow::anyhow!("--interrupts '{}': '{c}' is not a cell (a whole number)", a.interrupts)))
        .collect::<anyhow::Result<Vec<u32>>>()?;
    if interrupts.is_empty() {
        anyhow::bail!("--interrupts is empty: the binding requires the interrupt (e.g. \"0 40 4\")");
    }
    let o = DtOptions {
        name: a.name,
        base: a.base,
        spacing,
        lane: u8::try_from(lane).unwrap_or(u8::MAX),
        interrupts,
        interrupt_parent: a.interrupt_parent,
        clock_hz: a.clock,
        ocr: a.ocr,
        cdr: a.cdr,
        btr: a.btr0.zip(a.btr1),
    };
    let text = dt_node(&o)?;
    match &a.out {
        Some(p) => {
            std::fs::write(p, &text).with_context(|| format!("writing {}", p.display()))?;
            println!("wrote {}", p.display());
        }
        None => print!("{text}"),
    }
    Ok(0)
}

/// Runs the subcommand; returns the exit code.
pub fn run(a: Args) -> anyhow::Result<i32> {
    match a.what {
        Some(What::Reference(r)) => return super::reference::run(r),
        Some(What::Devicetree(d)) => return devicetree(d),
        None => {}
    }
    let default = if a.spacing == "word" { Spacing::Word } else { Spacing::Byte };
    let (spacing, lane) = a.layout.resolve(default)?;
    let header = HeaderOptions::new(&a.prefix, spacing)
        .map_err(|_| anyhow::anyhow!("--prefix '{}' must be an upper-case C identifier such as CAN_SJA", a.prefix))?
        .with_lane(lane)?;
    let opts = GenOptions { header, tcl: TclOptions { name: a.component, ..TclOptions::default() } };
    let files = write_all(&a.out, &opts).with_context(|| format!("writing into {}", a.out.display()))?;
    for f in files {
        println!("wrote {}", f.display());
    }
    Ok(0)
}
