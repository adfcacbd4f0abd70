# Print an optspec for argparse to handle cmd's options that are independent of any subcommand.
function __fish_cancosim_global_optspecs
    string join \n h/help V/version
end

function __fish_cancosim_needs_command
    # Figure out if the current invocation already has a command.
    set -l cmd (commandline -opc)
    set -e cmd[1]
    argparse -s (__fish_cancosim_global_optspecs) -- $cmd 2>/dev/null
    or return
    if set -q argv[1]
        # Also print the command, so this can be used to figure out what it is.
        echo $argv[1]
        return 1
    end
    return 0
end

function __fish_cancosim_using_subcommand
    set -l cmd (__fish_cancosim_needs_command)
    test -z "$cmd"
    and return 1
    contains -- $cmd[1] $argv
end

complete -c cancosim -n "__fish_cancosim_needs_command" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_needs_command" -s V -l version -d 'Print version'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "bittiming" -d 'Compute or check SJA1000 bit timing (BTR0/BTR1)'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "decode" -d 'Annotate a bit list or a VCD signal with CAN fields, frames and errors'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "gen" -d 'Write the Nios _regs.h, PIO header, Platform Designer _hw.tcl, register docs and Verilog include; `gen reference`: this tool\'s reference pages'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "run" -d 'Play a scenario on its DUT in lockstep with the golden model and print the diagnosis'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "cosim" -d 'Same as run, for an external core given by path (co-simulation against the golden model)'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "regress" -d 'Run every scenario of a list against one or more DUTs: table, JUnit, shards'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "profile" -d 'Core profiles: `profile infer` measures an external core\'s freedoms from probe runs and writes its profile'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "diagnose" -d 'Explain a saved run record (from run --record)'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "bench" -d 'Performance: golden model, co-simulation, raw C++ Verilator harness and Icarus, ratios in one run'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "campaign" -d 'Constrained-random co-simulation against any core: random bus and host programs, a scoreboard, failures shrunk to scenarios'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "mutate" -d 'Mutation testing: yosys mutants behind one run-time select, verilated once, killed by the first failing scenario'
complete -c cancosim -n "__fish_cancosim_needs_command" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c cancosim -n "__fish_cancosim_using_subcommand bittiming" -l clock -d 'CAN clock (the SJA1000\'s XTAL / our clk_i), e.g. 24MHz' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bittiming" -l rate -d 'Target bit rate, e.g. 500k: list settings for it, or with --btr0/--btr1 check them against it' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bittiming" -l btr0 -d 'BTR0 to check (with --btr1)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bittiming" -l btr1 -d 'BTR1 to check (with --btr0)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bittiming" -l top -d 'How many candidates to list' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bittiming" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand decode" -l bits -d 'A bit list given inline, e.g. "11111111111 0101001010010000010101010..."' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand decode" -l signal -d 'VCD: the signal to decode (its reference name, e.g. tx_o or bus)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand decode" -l clock -d 'VCD: the CAN clock, to turn BTR0/BTR1 into a bit time' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand decode" -l btr0 -d 'VCD: BTR0 of the bus' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand decode" -l btr1 -d 'VCD: BTR1 of the bus' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand decode" -l verbose -d 'Show stuff bits and every field start, not only frames and errors'
complete -c cancosim -n "__fish_cancosim_using_subcommand decode" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -s o -l out -d 'Output directory (created if missing)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -l prefix -d 'Upper-case C identifier prefix; the header is `<prefix>_regs.h`' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -l spacing -d 'Register spacing on the host bus: `byte` (IORD_8DIRECT, matches can_avalon) or `word` (IORD, 4-byte stride); --stride says the same for any stride' -r -f -a "byte\t''
word\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -l stride -d 'Bytes from one register to the next: 1, 2 or 4 (register n at base + n * stride). Overrides the profile\'s' -r -f -a "1\t''
2\t''
4\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -l byte-lane -d 'Byte lane of the register\'s data inside its stride (0 = bits 7..0). Overrides the profile\'s' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -l profile -d 'Read `stride` and `byte-lane` from this core profile\'s `[access.<host>]` table' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -l host -d 'The host bus whose `[access.<host>]` table of --profile to read (e.g. axi4-lite, wishbone)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -l component -d 'Platform Designer component name (the wrapper\'s module name)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -f -a "reference" -d 'Write (or --check) the reference generated from the code: man pages, shell completions, the command line and the scenario, profile and waiver file formats in Markdown'
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -f -a "devicetree" -d 'Write a device-tree node for Linux\'s sja1000 platform driver (compatible "nxp,sja1000"): reg and reg-io-width from the base and stride, the interrupt, and the clock and output properties from OCR, CDR and the clock'
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and not __fish_seen_subcommand_from reference devicetree help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from reference" -s o -l out -d 'Directory to write into (created if missing); files it holds that the code no longer generates are removed' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from reference" -l check -d 'Write nothing: exit 1 and list the files that differ from what the code generates'
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from reference" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -s o -l out -d 'Write the node here (default: standard output)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l base -d 'Bus address of register 0 (32 bits)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l name -d 'Node name before the @' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l interrupts -d 'The `interrupts` cells, space-separated, as the interrupt controller wants them' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l interrupt-parent -d 'Label of the interrupt controller (`interrupt-parent = <&LABEL>`); none: inherited' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l clock -d 'The core\'s clock input (the SJA1000\'s oscillator), e.g. 24MHz' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l ocr -d 'Output control register (OCR) value: nxp,tx-output-mode and nxp,tx-output-config' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l cdr -d 'Clock divider register (CDR) value: nxp,clock-out-frequency, nxp,no-comparator-bypass' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l btr0 -d 'BTR0 of the chosen bit timing (with --btr1): the bit rate, said in a comment' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l btr1 -d 'BTR1 of the chosen bit timing (with --btr0)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l stride -d 'Bytes from one register to the next: 1, 2 or 4 (register n at base + n * stride). Overrides the profile\'s' -r -f -a "1\t''
2\t''
4\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l byte-lane -d 'Byte lane of the register\'s data inside its stride (0 = bits 7..0). Overrides the profile\'s' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l profile -d 'Read `stride` and `byte-lane` from this core profile\'s `[access.<host>]` table' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -l host -d 'The host bus whose `[access.<host>]` table of --profile to read (e.g. axi4-lite, wishbone)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from devicetree" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from help" -f -a "reference" -d 'Write (or --check) the reference generated from the code: man pages, shell completions, the command line and the scenario, profile and waiver file formats in Markdown'
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from help" -f -a "devicetree" -d 'Write a device-tree node for Linux\'s sja1000 platform driver (compatible "nxp,sja1000"): reg and reg-io-width from the base and stride, the interrupt, and the clock and output properties from OCR, CDR and the clock'
complete -c cancosim -n "__fish_cancosim_using_subcommand gen; and __fish_seen_subcommand_from help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l dut -d 'Bundled DUT instead of the scenario\'s: `rtl` (our can_top) or `model` (the golden model)' -r -f -a "rtl\t''
model\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l external -d 'An external core\'s directory (Verilog and/or VHDL files; the opencores can_top port list or the 8051 bus)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l top -d 'Top module of the external core' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l define -d 'Verilog define for the external core (repeatable), e.g. CAN_WISHBONE_IF' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l include -d 'Include directory for the external core (repeatable)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l name -d 'Name of the external core in reports (default "<profile name> (<dir>)")' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l profile -d 'Core profile (tb/profiles/NAME.toml or a file): when host accesses take effect, the bit timing\'s phase origin, tolerances, port map. Required with --external; our RTL and the model have their own (rtl.toml, launch edge)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l vcd -d 'Write a VCD (DUT ports, model, bus, decoded fields) here, and a GTKWave view next to it (.gtkw)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l record -d 'Save the run record (JSON) for `cancosim diagnose`' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l candump -d 'Write the bus traffic as a candump log (`candump -l` format, timestamps = simulated time)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l candump-iface -d 'Interface name in the candump log' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l max-bits -d 'Override the scenario\'s run length, in bit times' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l host -d 'Drive the DUT through this host instead of the scenario\'s own: `wishbone` (can_top), `avalon` (our can_avalon wrapper with the Avalon-MM BFM), `pio` (GPIO bit-banging, can_top_pio; the thesis\'s program polls ack as a level), `pio-edge` (the same program polling the ack PIO\'s edge capture register: for a core with a one-clock ack), `i8051` (the SJA1000\'s Intel-mode multiplexed bus, can_top_8051), `axi4-lite` (can_axi4lite), `apb` (APB4), `apb3` (can_apb), `motorola` (the SJA1000\'s Motorola-mode multiplexed bus, can_top_mcu with MODE low) or `regport` (a plain register port on the CAN clock, can_regport). Scenarios whose point is their host wiring (`[host] fixed`) are skipped' -r -f -a "wishbone\t''
avalon\t''
pio\t''
pio-edge\t''
i8051\t''
axi4-lite\t''
apb\t''
apb3\t''
motorola\t''
regport\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l waivers -d 'Waiver file (repeatable), added to the scenario\'s own `[run] waivers`' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l dut-revision -d 'DUT revision the waivers\' `revisions` ranges are matched against' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l json -d 'Print the diagnosis as JSON instead of text'
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l collect -d 'Keep comparing after an unwaived divergence to see them all (default: stop at the first)'
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -l stop-at-first -d 'Stop the comparison at the first unwaived divergence (the default)'
complete -c cancosim -n "__fish_cancosim_using_subcommand run" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l dut -d 'Bundled DUT instead of the scenario\'s: `rtl` (our can_top) or `model` (the golden model)' -r -f -a "rtl\t''
model\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l external -d 'An external core\'s directory (Verilog and/or VHDL files; the opencores can_top port list or the 8051 bus)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l top -d 'Top module of the external core' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l define -d 'Verilog define for the external core (repeatable), e.g. CAN_WISHBONE_IF' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l include -d 'Include directory for the external core (repeatable)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l name -d 'Name of the external core in reports (default "<profile name> (<dir>)")' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l profile -d 'Core profile (tb/profiles/NAME.toml or a file): when host accesses take effect, the bit timing\'s phase origin, tolerances, port map. Required with --external; our RTL and the model have their own (rtl.toml, launch edge)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l vcd -d 'Write a VCD (DUT ports, model, bus, decoded fields) here, and a GTKWave view next to it (.gtkw)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l record -d 'Save the run record (JSON) for `cancosim diagnose`' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l candump -d 'Write the bus traffic as a candump log (`candump -l` format, timestamps = simulated time)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l candump-iface -d 'Interface name in the candump log' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l max-bits -d 'Override the scenario\'s run length, in bit times' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l host -d 'Drive the DUT through this host instead of the scenario\'s own: `wishbone` (can_top), `avalon` (our can_avalon wrapper with the Avalon-MM BFM), `pio` (GPIO bit-banging, can_top_pio; the thesis\'s program polls ack as a level), `pio-edge` (the same program polling the ack PIO\'s edge capture register: for a core with a one-clock ack), `i8051` (the SJA1000\'s Intel-mode multiplexed bus, can_top_8051), `axi4-lite` (can_axi4lite), `apb` (APB4), `apb3` (can_apb), `motorola` (the SJA1000\'s Motorola-mode multiplexed bus, can_top_mcu with MODE low) or `regport` (a plain register port on the CAN clock, can_regport). Scenarios whose point is their host wiring (`[host] fixed`) are skipped' -r -f -a "wishbone\t''
avalon\t''
pio\t''
pio-edge\t''
i8051\t''
axi4-lite\t''
apb\t''
apb3\t''
motorola\t''
regport\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l waivers -d 'Waiver file (repeatable), added to the scenario\'s own `[run] waivers`' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l dut-revision -d 'DUT revision the waivers\' `revisions` ranges are matched against' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l json -d 'Print the diagnosis as JSON instead of text'
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l collect -d 'Keep comparing after an unwaived divergence to see them all (default: stop at the first)'
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -l stop-at-first -d 'Stop the comparison at the first unwaived divergence (the default)'
complete -c cancosim -n "__fish_cancosim_using_subcommand cosim" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l dut -d 'Bundled DUTs to run against (repeatable): rtl, model' -r -f -a "rtl\t''
model\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l external -d 'External core as NAME=DIR or NAME=DIR@PROFILE (repeatable; define CAN_WISHBONE_IF, DIR as include dir). Each needs a profile: its own @PROFILE, else --profile. DIR may be `git:REPO@REV[:SUBDIR]` (exported with git archive into the build cache)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l profile -d 'Core profile (tb/profiles/NAME.toml or a file) of every --external without @PROFILE (e.g. --profile opencores-can); the column is then named "<profile> (<dir>)"' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l top -d 'Top module of the external cores (the opencores `can_top` port list)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l baseline -d 'The old revision to compare the (one) --external with, NAME=DIR[@PROFILE] or NAME=git:REPO@REV[:SUBDIR]: per scenario fixed / broken / still failing / still passing; exit 1 only when something broke' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -s j -l jobs -d 'Worker threads (0 = one per core)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l shard -d 'Run only shard k of n (e.g. 2/4)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l junit -d 'Write JUnit XML here (an expected failure is a skipped testcase whose message names its entry)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l json -d 'Write the results as JSON here (counts, and per cell its status; an expected failure with its entry and verdict)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l record-expected-failures -d 'Run every scenario in collect mode and write, for each run that did not pass (or did not fail as its [[expected-failure]] entry records), an [[expected-failure]] entry with the signature it showed, to paste into a waiver file after filling in deviation, clause and reason. Never edits a waiver file' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l record-place -d 'How the recorded entries place a divergence: `bit` (its bit time) or `step` (the scenario step it happened in, so one entry holds on every host: `place = "step"`; an expected failure whose entry places by bit is then recorded too, to move it)' -r -f -a "bit\t''
step\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l html -d 'Write a self-contained HTML report (DIR/index.html, files of failed runs in DIR/runs/)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l coverage -d 'Code coverage: build each Verilated DUT with Verilator\'s line, toggle and branch coverage, merge the runs into DIR/<dut>/coverage.info and an HTML report (DIR/<dut>/html/index.html), print a summary per file' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l funcov-json -d 'Write the functional coverage bins per DUT as JSON here' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l max-bits -d 'Override every scenario\'s run length, in bit times' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l host -d 'Drive the DUT through this host instead of the scenario\'s own: `wishbone` (can_top), `avalon` (our can_avalon wrapper with the Avalon-MM BFM), `pio` (GPIO bit-banging, can_top_pio; the thesis\'s program polls ack as a level), `pio-edge` (the same program polling the ack PIO\'s edge capture register: for a core with a one-clock ack), `i8051` (the SJA1000\'s Intel-mode multiplexed bus, can_top_8051), `axi4-lite` (can_axi4lite), `apb` (APB4), `apb3` (can_apb), `motorola` (the SJA1000\'s Motorola-mode multiplexed bus, can_top_mcu with MODE low) or `regport` (a plain register port on the CAN clock, can_regport). Scenarios whose point is their host wiring (`[host] fixed`) are skipped' -r -f -a "wishbone\t''
avalon\t''
pio\t''
pio-edge\t''
i8051\t''
axi4-lite\t''
apb\t''
apb3\t''
motorola\t''
regport\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l waivers -d 'Waiver file (repeatable), added to the scenario\'s own `[run] waivers`' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l dut-revision -d 'DUT revision the waivers\' `revisions` ranges are matched against' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l funcov -d 'Print the functional coverage table (protocol and registers, seen from the golden model\'s side) per DUT; also printed with --coverage'
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l collect -d 'Keep comparing after an unwaived divergence to see them all (default: stop at the first)'
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -l stop-at-first -d 'Stop the comparison at the first unwaived divergence (the default)'
complete -c cancosim -n "__fish_cancosim_using_subcommand regress" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and not __fish_seen_subcommand_from infer help" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and not __fish_seen_subcommand_from infer help" -f -a "infer" -d 'Find an external core\'s port roles and measure each freedom of its profile from short probe runs'
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and not __fish_seen_subcommand_from infer help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from infer" -l external -d 'The core\'s source directory (Verilog; also an include directory)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from infer" -l top -d 'Its top module' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from infer" -l define -d 'Verilog define (repeatable; CAN_WISHBONE_IF is always defined)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from infer" -l include -d 'Extra include directory (repeatable)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from infer" -l host -d 'The host bus the probes drive. `wishbone`, `avalon`, `pio`: the top\'s Wishbone roles ([ports]), the timing written to all three; `axi4-lite`, `apb`, `apb3`, `regport`, `motorola`: that bus\'s roles ([ports.<bus>]) and its [access.<bus>] entry only' -r -f -a "wishbone\t''
avalon\t''
pio\t''
axi4-lite\t''
apb\t''
apb3\t''
regport\t''
motorola\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from infer" -l port -d 'A port role the names leave open, ROLE=NAME or ROLE=NAME:low|high (repeatable), e.g. --port host-clock=clk --port reset=nrst:low; a host bus\'s role as BUS.ROLE, e.g. --port apb.psel=SEL --port regport.wr=we_n:low' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from infer" -l read-latency -d 'The register port\'s read latency in clocks after the strobe (--host regport), when known; without it the least latency at which the probes\' reads agree is measured' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from infer" -l name -d 'The profile\'s name (default: the top\'s)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from infer" -l waivers -d 'Waiver file of deviations already known and accepted (repeatable): the probes run with it, as regress --waivers does; its `dut` globs match "<name> (<dir>)"' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from infer" -l out -d 'Where to write the profile' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from infer" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from help" -f -a "infer" -d 'Find an external core\'s port roles and measure each freedom of its profile from short probe runs'
complete -c cancosim -n "__fish_cancosim_using_subcommand profile; and __fish_seen_subcommand_from help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c cancosim -n "__fish_cancosim_using_subcommand diagnose" -l dut-revision -d 'DUT revision to put in the suggested waivers' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand diagnose" -l json -d 'Print JSON instead of text'
complete -c cancosim -n "__fish_cancosim_using_subcommand diagnose" -l suggest-waivers -d 'Print candidate waiver entries (TOML) for the record\'s divergence; nothing is written or applied'
complete -c cancosim -n "__fish_cancosim_using_subcommand diagnose" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l frames -d 'Frames of the self-test workload (model, co-simulation, raw C++ harness)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l icarus-frames -d 'Frames under Icarus (slow)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l seed -d 'Seed of every workload' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l repeat -d 'Interleaved runs of the co-sim and raw-harness rows; each keeps its least CPU time (default 3; 1 with --smoke)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l mutants -d 'Add the mutation rows: time per mutant for K mutants of our rtl/ in one `-ctrl` build (build shared by the K, plus each one\'s simulations) vs a build per mutant (measured on --rebuild of them; cold Verilator builds: minutes). `--mutants` alone: 200, the size of the README\'s campaign' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l rebuild -d 'Mutants rebuilt alone for the comparison (their mean per mutant is used)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l mutant-scenarios -d 'Scenario set every mutant runs on both paths (scenario files or lists, repeatable; default tb/de2-pelican-selftest.toml)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l campaign-frames -d 'Frames of the campaign rows (`cancosim campaign`, seed 1, quanta up to BRP 3, one job): frames per CPU second on our rtl/ and, with --campaign-external, on that core (0: no rows)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l campaign-external -d 'A second campaign row on this core: DIR@PROFILE (e.g. path/to/can@opencores-can; defines CAN_WISHBONE_IF, DIR as include dir)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l host -d 'A campaign row on our rtl/ through this host (repeatable): its wrapper and bus model' -r -f -a "wishbone\t''
avalon\t''
pio\t''
pio-edge\t''
i8051\t''
axi4-lite\t''
apb\t''
apb3\t''
motorola\t''
regport\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l smoke -d 'CI-sized run (seconds): tiny frame counts, same table'
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -l json -d 'Print JSON instead of the table'
complete -c cancosim -n "__fish_cancosim_using_subcommand bench" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l seed -d 'Seed of every random choice; a run is reproduced by (seed, index) alone' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l frames -d 'Stop once this many frames (the model nodes\' and the DUT\'s) were run' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l minutes -d 'Stop starting runs after this many minutes (with --frames: whichever comes first)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l first-index -d 'Index of the first run (a later part of a campaign)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l dut -d 'Bundled DUTs to run against (repeatable): rtl, model' -r -f -a "rtl\t''
model\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l external -d 'External core as NAME=DIR or NAME=DIR@PROFILE (repeatable; define CAN_WISHBONE_IF, DIR as include dir). Each needs a profile: its own @PROFILE, else --profile. DIR may be `git:REPO@REV[:SUBDIR]` (exported with git archive into the build cache)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l profile -d 'Core profile (tb/profiles/NAME.toml or a file) of every --external without @PROFILE (e.g. --profile opencores-can); the column is then named "<profile> (<dir>)"' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l top -d 'Top module of the external cores (the opencores `can_top` port list)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l host -d 'Drive the DUT through this host instead of the scenario\'s own: `wishbone` (can_top), `avalon` (our can_avalon wrapper with the Avalon-MM BFM), `pio` (GPIO bit-banging, can_top_pio; the thesis\'s program polls ack as a level), `pio-edge` (the same program polling the ack PIO\'s edge capture register: for a core with a one-clock ack), `i8051` (the SJA1000\'s Intel-mode multiplexed bus, can_top_8051), `axi4-lite` (can_axi4lite), `apb` (APB4), `apb3` (can_apb), `motorola` (the SJA1000\'s Motorola-mode multiplexed bus, can_top_mcu with MODE low) or `regport` (a plain register port on the CAN clock, can_regport). Scenarios whose point is their host wiring (`[host] fixed`) are skipped' -r -f -a "wishbone\t''
avalon\t''
pio\t''
pio-edge\t''
i8051\t''
axi4-lite\t''
apb\t''
apb3\t''
motorola\t''
regport\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l waivers -d 'Waiver file (repeatable), added to the scenario\'s own `[run] waivers`' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l dut-revision -d 'DUT revision the waivers\' `revisions` ranges are matched against' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -s j -l jobs -d 'Worker threads (0 = one per core)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l shard -d 'Run only shard k of n (e.g. 2/4): run indices first + k - 1 + j n' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l nodes -d 'Model nodes on the bus besides the DUT, as MIN..MAX' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l frames-per-run -d 'Frames per run, as MIN..MAX' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l fault-rate -d 'Probability that a frame of a run carries a fault (flip, stuck, glitch)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l max-brp -d 'Largest BRP drawn (0..63; a run\'s cost grows with the quantum)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l shrink-runs -d 'Plans tried when shrinking one failure (0: no shrinking)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l max-failures -d 'Stop after this many failing runs' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l save-failures -d 'Write each failure, shrunk, as a scenario here (`cancosim run` replays it)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l json -d 'Write the results as JSON here (totals, failures with their shrinking, waivers hit, every run)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l junit -d 'Write JUnit XML here (one testcase per run)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l html -d 'Write the HTML report here (DIR/index.html; each failing run, shrunk, with its waveform)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l collect -d 'Keep comparing after an unwaived divergence to see them all (default: stop at the first)'
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -l stop-at-first -d 'Stop the comparison at the first unwaived divergence (the default)'
complete -c cancosim -n "__fish_cancosim_using_subcommand campaign" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l external -d 'External core directory (default: this repository\'s rtl/, top can_top)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l profile -d 'Profile of the external core (tb/profiles/NAME.toml or a file); our rtl/ uses rtl' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l top -d 'Top module (our rtl/ on i8051, motorola, axi4-lite, apb, apb3 or regport: that host\'s wrapper, can_top_8051, can_top_mcu, can_axi4lite, can_apb or can_regport)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l define -d 'Verilog define of the external core (repeatable; CAN_WISHBONE_IF is always set for it)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l count -d 'Number of mutations sampled by `yosys mutate -list`' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l seed -d 'Seed of the sample (recorded in the report; same seed, same mutants)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l list -d 'A saved mutation list (lines of `mutate ...`) instead of a sample' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -s j -l jobs -d 'Worker threads (0 = one per core)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l shard -d 'Run only shard k of n of the mutants (e.g. 2/4)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l out -d 'Output directory (journal-<build>.jsonl to resume, report.json, report.md, skeletons/)' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l formal-steps -d 'Steps of the bounded formal check (and induction depth)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l host -d 'Host of every scenario (default wishbone: the mutated core is the can_top port list; on our rtl/ a host with its own wrapper mutates the wrapper with can_top)' -r -f -a "wishbone\t''
avalon\t''
pio\t''
pio-edge\t''
i8051\t''
axi4-lite\t''
apb\t''
apb3\t''
motorola\t''
regport\t''"
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l budget-factor -d 'A mutant times out when its scenarios take longer than this many times the baseline\'s total (raise it on a loaded machine)' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l campaign-frames -d 'Give each mutant that survives the scenarios a random campaign of this many frames (`cancosim campaign`\'s runs, on the same host and waivers); a failing run kills it' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l campaign-seed -d 'Seed of those campaigns' -r
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l waivers -d 'Waiver file (repeatable), added to the scenarios\' own' -r -F
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l fresh -d 'Start over: ignore the journal of an earlier run in --out'
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -l no-formal -d 'Skip the formal check of survivors'
complete -c cancosim -n "__fish_cancosim_using_subcommand mutate" -s h -l help -d 'Print help'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "bittiming" -d 'Compute or check SJA1000 bit timing (BTR0/BTR1)'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "decode" -d 'Annotate a bit list or a VCD signal with CAN fields, frames and errors'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "gen" -d 'Write the Nios _regs.h, PIO header, Platform Designer _hw.tcl, register docs and Verilog include; `gen reference`: this tool\'s reference pages'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "run" -d 'Play a scenario on its DUT in lockstep with the golden model and print the diagnosis'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "cosim" -d 'Same as run, for an external core given by path (co-simulation against the golden model)'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "regress" -d 'Run every scenario of a list against one or more DUTs: table, JUnit, shards'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "profile" -d 'Core profiles: `profile infer` measures an external core\'s freedoms from probe runs and writes its profile'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "diagnose" -d 'Explain a saved run record (from run --record)'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "bench" -d 'Performance: golden model, co-simulation, raw C++ Verilator harness and Icarus, ratios in one run'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "campaign" -d 'Constrained-random co-simulation against any core: random bus and host programs, a scoreboard, failures shrunk to scenarios'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "mutate" -d 'Mutation testing: yosys mutants behind one run-time select, verilated once, killed by the first failing scenario'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and not __fish_seen_subcommand_from bittiming decode gen run cosim regress profile diagnose bench campaign mutate help" -f -a "help" -d 'Print this message or the help of the given subcommand(s)'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and __fish_seen_subcommand_from gen" -f -a "reference" -d 'Write (or --check) the reference generated from the code: man pages, shell completions, the command line and the scenario, profile and waiver file formats in Markdown'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and __fish_seen_subcommand_from gen" -f -a "devicetree" -d 'Write a device-tree node for Linux\'s sja1000 platform driver (compatible "nxp,sja1000"): reg and reg-io-width from the base and stride, the interrupt, and the clock and output properties from OCR, CDR and the clock'
complete -c cancosim -n "__fish_cancosim_using_subcommand help; and __fish_seen_subcommand_from profile" -f -a "infer" -d 'Find an external core\'s port roles and measure each freedom of its profile from short probe runs'
