#!/bin/sh
# Our rtl/'s mutant 79 of seed 1 (`mutate -mode inv -module can_top -cell
# u_regs.txb -port WR_ADDR -portbit 5`, rtl/can_regs.v:90). The memory txb
# has 16 write ports of 4 address bits: ports 0..12 are the hardware-reset
# loop (txb[i] <= 0, constant addresses 0..12), 13..15 the host writes
# (lines 338, 343, 374). Bit 5 is bit 1 of port 1's constant address 1: the
# mutant's reset clears txb[3] (cleared by port 3 anyway) instead of txb[1],
# so TX buffer byte 1 keeps its value across a hardware reset.
# The datasheet leaves the TX buffer undefined after a hardware reset (the
# register map's TXB/TXBUF rows, hw "xxxx_xxxx" in crates/regmap); the kit's
# model reads 0 there as a choice, and no scenario may expect a value.
#
# Four checks on can_regs (the kit's per-module harness: every output
# compared, the reset forced in the first clock, registers from zero,
# yosys + ABC's PDR), run from the repository root:
#  1. original against mutant 79, rst free: a COUNTEREXAMPLE (write TX
#     buffer byte 1, reset again, the byte is still there).
#  2. original against mutant 79, rst only in the first clock (every kit
#     simulation has that one reset): PROVED.
#     Control: the same harness with bit 52 inverted instead (bit 0 of the
#     reset-mode TX RAM write address, line 338): a counterexample.
#  3. "spec" against mutant 79, rst free, where "spec" is rtl/can_regs.v
#     with the hardware-reset write of txb[1] left out (its reset value is
#     undefined in the datasheet): PROVED. So the mutant's only effect at
#     the ports is the reset value of a byte the datasheet leaves undefined.
#     Control: "spec" against the original, rst free: a counterexample (the
#     harness sees txb[1]'s reset value at the ports).
# Prints one verdict line per check; exit 0 when every verdict is as above.
set -e
root=$(pwd)
test -f "$root/rtl/can_regs.v" || { echo "run from the repository root" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
files="$root/rtl/can_top.v $root/rtl/can_wb_cdc.v $root/rtl/can_regs.v $root/rtl/can_btl.v $root/rtl/can_bsp.v $root/rtl/can_fce.v $root/rtl/can_acf.v $root/rtl/can_rxfifo.v"

# "spec": the reset loop of txb skips byte 1 (the check below fails if that line moved)
reset_loop='for (i = 0; i < 13; i = i + 1) txb\[i\] <= 8'"'"'h00;'
grep -q "$reset_loop" "$root/rtl/can_regs.v" || { echo "the txb reset loop moved" >&2; exit 2; }
sed -e 's/^module can_regs (/module regs_spec (/' \
    -e "s/$reset_loop/for (i = 0; i < 13; i = i + 1) if (i != 1) txb[i] <= 8'h00;/" \
    "$root/rtl/can_regs.v" > regs_spec.v
grep -q "if (i != 1) txb" regs_spec.v

# can_regs' ports: "dir width name" per line
sed -n '/^module can_regs (/,/^);/p' "$root/rtl/can_regs.v" | sed -e 's#//.*##' -e 's/,//' |
    awk '$1 == "input" || $1 == "output" { w = ($3 ~ /^\[/) ? $3 : ""; print $1, (w == "" ? "-" : w), $NF }' > ports
grep -q "^input - rst$" ports && grep -q "^output \[63:0\] tx_data$" ports

wrapper() { # $1 = gold module, $2 = gate module, $3 = 1: rst only in the first clock
    {
        echo "module miter ("
        awk '$1 == "input" { printf "    input wire %s in_%s,\n", ($2 == "-" ? "" : $2), $3 }' ports
        echo "    output wire trigger);"
        echo "    reg started = 1'b0;"
        echo "    always @(posedge in_clk) started <= 1'b1;"
        echo "    wire rst = ($3 == 1) ? !started : (in_rst | !started);"
        awk '$1 == "output" { printf "    wire %s gold_%s, gate_%s;\n", ($2 == "-" ? "" : $2), $3, $3 }' ports
        for side in gold gate; do
            if [ $side = gold ]; then m=$1; else m=$2; fi
            printf "    %s %s (" "$m" "$side"
            awk -v s=$side '{ if ($3 == "rst") c = ".rst(rst)"; else if ($1 == "input") c = sprintf(".%s(in_%s)", $3, $3);
                else c = sprintf(".%s(%s_%s)", $3, s, $3); printf "%s%s", (NR > 1 ? ", " : ""), c }' ports
            echo ");"
        done
        printf "    assign trigger = started && ({"
        awk '$1 == "output" { printf "%sgold_%s", (n++ ? ", " : ""), $3 }' ports
        printf "} != {"
        awk '$1 == "output" { printf "%sgate_%s", (n++ ? ", " : ""), $3 }' ports
        echo "});"
        echo "endmodule"
    } > wrapper.v
}

check() { # $1 = gold (orig/spec), $2 = gate (orig/mut), $3 = WR_ADDR bit of the gate's mutation, $4 = one reset (1/0), $5 = name
    wrapper cosim_gold cosim_gate "$4"
    if [ "$2" = mut ]; then mut="mutate -mode inv -module cosim_gate -cell txb -port WR_ADDR -portbit $3"; else mut=""; fi
    if [ "$1" = spec ]; then gold="read_verilog -I$root/rtl regs_spec.v
rename regs_spec cosim_gold"; else gold="copy cosim_gate cosim_gold"; fi
    cat > $5.ys <<EOF
read_verilog -I$root/rtl $files
hierarchy -top can_top
prep -top can_top
hierarchy -top can_regs
rename can_regs cosim_gate
$gold
$mut
read_verilog wrapper.v
proc
hierarchy -top miter
flatten
memory
setundef -anyseq
setundef -zero -init
opt_clean
async2sync
dffunmap
techmap
opt -fast
dffunmap
abc -fast -g AND
opt_clean
dffunmap
write_aiger -zinit $5.aig
EOF
    yosys -q -s $5.ys
    timeout 600 yosys-abc -c "read_aiger $5.aig; pdr" | grep -E "Property proved|was asserted" || echo "no verdict"
}

ok=0
v=$(check orig mut 5 0 m79free)
echo "1. original vs mutant 79, rst free: $v"
case "$v" in *"was asserted"*) ;; *) ok=1 ;; esac
v=$(check orig mut 5 1 m79once)
echo "2. original vs mutant 79, rst only in the first clock: $v"
case "$v" in *"Property proved"*) ;; *) ok=1 ;; esac
v=$(check orig mut 52 1 ctl52once)
echo "2. control (WR_ADDR bit 52, the reset-mode TX RAM write), rst only in the first clock: $v"
case "$v" in *"was asserted"*) ;; *) ok=1 ;; esac
v=$(check spec mut 5 0 spec79free)
echo "3. spec (txb[1] not reset) vs mutant 79, rst free: $v"
case "$v" in *"Property proved"*) ;; *) ok=1 ;; esac
v=$(check spec orig 5 0 specorigfree)
echo "3. control: spec vs original, rst free: $v"
case "$v" in *"was asserted"*) ;; *) ok=1 ;; esac
exit $ok
