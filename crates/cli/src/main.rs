//! `cancosim`: the command line of the SJA1000 verification kit.
//!
//! Every subcommand prints a short, plain result and exits non-zero on a
//! failure, so it can sit in a CI job or a regression script: 1 when a
//! check failed, 2 for bad usage or input (clap's own code for usage).

use clap::{Parser, Subcommand};

mod cmd;

/// Co-simulate SJA1000-compatible CAN cores against a golden model, and explain why they fail.
#[derive(Parser)]
#[command(
    name = "cancosim",
    version,
    about,
    long_about = None,
    after_help = "Exit codes: 0 passed; 1 a check failed (a scenario failed or diverged, a setting has problems); 2 bad usage or input (arguments, files, an --external directory without the core), reported once before anything runs. regress: 125 when an external core does not build (its directory missing or without the core, Verilator/GHDL errors), so `git bisect run` skips that revision; a scenario that does not load is 2"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Compute or check SJA1000 bit timing (BTR0/BTR1).
    #[command(after_help = "Examples:\n  cancosim bittiming --clock 24MHz --rate 500k            (registers for a rate)\n  cancosim bittiming --clock 16MHz --btr0 0x03 --btr1 0xBB  (the rate those registers give)\n  cancosim bittiming --clock 16MHz --rate 125k --btr0 0x03 --btr1 0xBB  (their deviation from 125k)")]
    Bittiming(cmd::bittiming::Args),
    /// Annotate a bit list or a VCD signal with CAN fields, frames and errors.
    #[command(after_help = "Examples:\n  cancosim decode --bits 11111111111010100101001000001010101010001...\n  cancosim decode out/de2-thesis.vcd --signal tx_o --clock 24MHz --btr0 0x41 --btr1 0x25")]
    Decode(cmd::decode::Args),
    /// Write the Nios _regs.h, PIO header, Platform Designer _hw.tcl, register docs and Verilog include; `gen reference`: this tool's reference pages.
    #[command(after_help = "Examples:\n  cancosim gen --out out/gen\n  cancosim gen --out ip/can --prefix MY_CAN --spacing word\n  cancosim gen reference --out docs/reference")]
    Gen(cmd::generate::Args),
    /// Play a scenario on its DUT in lockstep with the golden model and print the diagnosis.
    #[command(after_help = "Examples:\n  cancosim run tb/de2-thesis.toml\n  cancosim run tb/de2-thesis.toml --dut model --vcd out/thesis.vcd\n  cancosim run tb/pelican-error-kinds.toml --host avalon\n  cancosim run tb/de2-with-ack-node.toml --external ~/can/rtl/verilog --define CAN_WISHBONE_IF --include ~/can/rtl/verilog --profile opencores-can\n\nAn external core needs --profile (tb/profiles/NAME.toml or a file): its bit timing's phase origin, when host accesses take effect, tolerances, port map.")]
    Run(cmd::run::Args),
    /// Same as run, for an external core given by path (co-simulation against the golden model).
    #[command(after_help = "Examples:\n  cancosim cosim tb/de2-with-ack-node.toml --external ~/can/rtl/verilog --top can_top --define CAN_WISHBONE_IF --include ~/can/rtl/verilog --profile opencores-can --vcd out/upstream.vcd\n  cancosim cosim tb/de2-thesis.toml --external ~/mycore --top my_can --profile ~/mycore/profile.toml")]
    Cosim(cmd::run::Args),
    /// Run every scenario of a list against one or more DUTs: table, JUnit, shards.
    #[command(after_help = "Examples:\n  cancosim regress\n  cancosim regress tb/regression.list --dut rtl --dut model --junit out/junit.xml\n  cancosim regress tb/regression.list --dut rtl --host avalon\n  cancosim regress --external upstream=/tmp/can/rtl/verilog --profile opencores-can --shard 1/2\n  cancosim regress --external a=/tmp/can/rtl/verilog@opencores-can --external b=/tmp/mine@/tmp/mine/profile.toml\n\nEach --external NAME=DIR needs a profile: its own NAME=DIR@PROFILE, else --profile (for every external without one).")]
    Regress(cmd::regress::Args),
    /// Core profiles: `profile infer` measures an external core's freedoms from probe runs and writes its profile.
    #[command(after_help = "Examples:\n  cancosim profile infer --external /tmp/mycore --top my_can --out mycore.toml\n  cancosim profile infer --external ~/can/rtl/verilog --out oc.toml --port host-clock=wb_clk_i\n\nExit: 0 written; 1 written with candidate deviations (printed, each entry at its bound); 2 bad input or no build.")]
    Profile(cmd::profile::Args),
    /// Explain a saved run record (from run --record).
    #[command(after_help = "Examples:\n  cancosim run tb/de2-thesis.toml --record out/thesis.json\n  cancosim diagnose out/thesis.json --json")]
    Diagnose(cmd::diagnose::Args),
    /// Performance: golden model, co-simulation, raw C++ Verilator harness and Icarus, ratios in one run.
    #[command(after_help = "Examples:\n  cancosim bench --smoke\n  cancosim bench --frames 1000 --json")]
    Bench(cmd::bench::Args),
    /// Constrained-random co-simulation against any core: random bus and host programs, a scoreboard, failures shrunk to scenarios.
    #[command(after_help = "Examples:\n  cancosim campaign --frames 500 --seed 7\n  cancosim campaign --external oc=/path/to/can@opencores-can --waivers tb/waivers/opencores-upstream.toml --minutes 10 --save-failures out/found\n  cancosim campaign --frames 2000 --shard 2/4 --json shard2.json")]
    Campaign(cmd::campaign::Args),
    /// Mutation testing: yosys mutants behind one run-time select, verilated once, killed by the first failing scenario.
    #[command(after_help = "Examples:\n  cancosim mutate tb/regression.list --count 200 --seed 1 --jobs 2\n  cancosim mutate --shard 1/4 --out out/mutate     (run again to resume after an interruption)\n  cancosim mutate --external /path/to/rtl --profile opencores-can --waivers tb/waivers/opencores-upstream.toml\n\nExit: 0 no survivor, 1 survivors or timed-out mutants (listed), 2 bad input or no build.")]
    Mutate(cmd::mutate::Args),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Bittiming(a) => cmd::bittiming::run(a),
        Command::Decode(a) => cmd::decode::run(a),
        Command::Gen(a) => cmd::generate::run(a),
        Command::Run(a) | Command::Cosim(a) => cmd::run::run_cmd(a),
        Command::Regress(a) => cmd::regress::run(a),
        Command::Profile(a) => cmd::profile::run(a),
        Command::Diagnose(a) => cmd::diagnose::run(a),
        Command::Bench(a) => cmd::bench::run_cmd(a),
        Command::Campaign(a) => cmd::campaign::run_cmd(a),
        Command::Mutate(a) => cmd::mutate::run(a),
    };
    match result {
        Ok(code) => std::process::exit(code),
        Err(e) => {
            eprintln!("cancosim: {e:#}");
            std::process::exit(2);
        }
    }
}
