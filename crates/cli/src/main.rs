//! `cancosim`: the command line of the SJA1000 verification kit.
//!
//! Every subcommand prints a short, plain result and exits non-zero on a
//! failure, so it can sit in a CI job or a regression script.

use clap::{Parser, Subcommand};

mod cmd;

/// Co-simulate SJA1000-compatible CAN cores against a golden model, and explain why they fail.
#[derive(Parser)]
#[command(name = "cancosim", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Compute or check SJA1000 bit timing (BTR0/BTR1).
    #[command(after_help = "Examples:\n  cancosim bittiming --clock 24MHz --rate 500k\n  cancosim bittiming --clock 16MHz --rate 125k --btr0 0x03 --btr1 0xBB")]
    Bittiming(cmd::bittiming::Args),
    /// Annotate a bit list or a VCD signal with CAN fields, frames and errors.
    #[command(after_help = "Examples:\n  cancosim decode --bits 11111111111010100101001000001010101010001...\n  cancosim decode out/de2-thesis.vcd --signal tx_o --clock 24MHz --btr0 0x41 --btr1 0x25")]
    Decode(cmd::decode::Args),
    /// Write the Nios _regs.h, PIO header, Platform Designer _hw.tcl, register docs and Verilog include.
    #[command(after_help = "Examples:\n  cancosim gen --out out/gen\n  cancosim gen --out ip/can --prefix MY_CAN --spacing word")]
    Gen(cmd::generate::Args),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Bittiming(a) => cmd::bittiming::run(a),
        Command::Decode(a) => cmd::decode::run(a),
        Command::Gen(a) => cmd::generate::run(a),
    };
    match result {
        Ok(code) => std::process::exit(code),
        Err(e) => {
            eprintln!("cancosim: {e:#}");
            std::process::exit(2);
        }
    }
}
