#!/bin/sh
# Our rtl/'s mutant 12 of today's seed-1 sample (rtl at b8f2c75 and
# after): `mutate -mode const1 -module can_top -cell $flatten\u_cdc.$procmux$6953
# -port A -portbit 4 -wire wb_dat_o -wirebit 4`, rtl/can_wb_cdc.v:93. In the
# flattened design.il that cell is the mux with A = \u_cdc.wb_dat_o (HOLD),
# B = \u_cdc.rdat_x (LOAD), S = busy && ack_edge: the mutant loads 1 into
# wb_dat_o[4] at every wb_clk_i edge that does not register read data (the
# read data itself is loaded correctly). So wb_dat_o[4] turns 1 one clock
# after the load, i.e. in the clock after the one-clock ack pulse.
#
# Wishbone B4 (classic cycle, §3.2/§3.3): the master takes DAT_I at the rising
# CLK_I edge where it sees ACK_I asserted; outside the ACK clock DAT_I has no
# meaning. With ACK_LEVEL = 0 (can_top's default, the campaign's netlist:
# `if (ACK_LEVEL != 0)` is elaborated away) wb_ack_o = ack_q, which is set
# only in the clock right after the branch that loads wb_dat_o. Claim: no
# legal master can tell the mutant from the original.
#
# Checks (yosys + ABC's PDR; both clocks free inputs through clk2fflogic,
# registers from zero, wb_rst_i FREE at every step, every other input free,
# so every master behaviour, legal or not, is covered), run from the
# repository root:
#  1. can_wb_cdc, original against mutant (the same `mutate -mode const1
#     -port A -portbit 4` on the standalone module's mux, asserted to be the
#     one with A = wb_dat_o, B = rdat_x): wb_ack_o, rst_o, acc_stb, acc_we,
#     acc_adr, acc_wdat equal at every step, wb_dat_o equal at every step
#     where wb_ack_o is high. Expected: PROVED.
#  2. Control: the same with wb_dat_o compared at every step: a
#     COUNTEREXAMPLE (the mutant is real; it shows only outside the ack).
#  3. Control: ACK_LEVEL = 1 (can_top_pio, the level ack held while STB
#     stays high), the same ack-gated compare as 1: a COUNTEREXAMPLE (a master
#     that samples during a held level ack sees bit 4 = 1: the gated compare
#     is not vacuous, and the mutant's twin in can_top_pio is observable).
# Prints one verdict line per check; exit 0 when every verdict is as above.
# KEEP_WORK=DIR keeps the yosys scripts and AIGER files in DIR.
set -e
root=$(pwd)
test -f "$root/rtl/can_wb_cdc.v" || { echo "run from the repository root" >&2; exit 2; }
work=${KEEP_WORK:-$(mktemp -d)}
[ -n "$KEEP_WORK" ] || trap 'rm -rf "$work"' EXIT
cd "$work"

miter() { # $1 = ACK_LEVEL, $2 = 1: compare wb_dat_o only while wb_ack_o, 0: always; $3 = output
cat > m.ys <<EOF
read_verilog $root/rtl/can_wb_cdc.v
chparam -set ACK_LEVEL $1 can_wb_cdc
hierarchy -top can_wb_cdc
proc
select -set hold w:rdat_x %co:+[B] t:\$mux %i w:wb_dat_o %co:+[A] %i
select -assert-count 1 @hold
copy can_wb_cdc cdc_mut
select -module cdc_mut -assert-count 1 w:rdat_x %co:+[B] t:\$mux %i w:wb_dat_o %co:+[A] %i
select -clear
EOF
# the cell's name in the copy is the original's
cell=$(yosys -p "read_verilog $root/rtl/can_wb_cdc.v; chparam -set ACK_LEVEL $1 can_wb_cdc; hierarchy -top can_wb_cdc; proc; select -list w:rdat_x %co:+[B] t:\$mux %i w:wb_dat_o %co:+[A] %i" 2>/dev/null | sed -n 's/^can_wb_cdc\/\(\$procmux\$[0-9]*\)$/\1/p')
test -n "$cell" || { echo "the wb_dat_o mux was not found" >&2; exit 2; }
cat >> m.ys <<EOF
mutate -mode const1 -module cdc_mut -cell $cell -port A -portbit 4
read_verilog <<EOT
module miter(input wb_clk_i, input wb_rst_i, input [7:0] wb_dat_i, input wb_cyc_i, input wb_stb_i,
             input wb_we_i, input [7:0] wb_adr_i, input clk_i, input [7:0] acc_rdat, output bad);
  wire [7:0] g_dat_o, m_dat_o, g_adr, m_adr, g_wdat, m_wdat;
  wire g_ack, m_ack, g_rst, m_rst, g_stb, m_stb, g_we, m_we;
  can_wb_cdc g(.wb_clk_i(wb_clk_i), .wb_rst_i(wb_rst_i), .wb_dat_i(wb_dat_i), .wb_dat_o(g_dat_o),
    .wb_cyc_i(wb_cyc_i), .wb_stb_i(wb_stb_i), .wb_we_i(wb_we_i), .wb_adr_i(wb_adr_i), .wb_ack_o(g_ack),
    .clk_i(clk_i), .rst_o(g_rst), .acc_stb(g_stb), .acc_we(g_we), .acc_adr(g_adr), .acc_wdat(g_wdat), .acc_rdat(acc_rdat));
  cdc_mut m(.wb_clk_i(wb_clk_i), .wb_rst_i(wb_rst_i), .wb_dat_i(wb_dat_i), .wb_dat_o(m_dat_o),
    .wb_cyc_i(wb_cyc_i), .wb_stb_i(wb_stb_i), .wb_we_i(wb_we_i), .wb_adr_i(wb_adr_i), .wb_ack_o(m_ack),
    .clk_i(clk_i), .rst_o(m_rst), .acc_stb(m_stb), .acc_we(m_we), .acc_adr(m_adr), .acc_wdat(m_wdat), .acc_rdat(acc_rdat));
  assign bad = !(g_ack == m_ack && g_rst == m_rst && g_stb == m_stb && g_we == m_we && g_adr == m_adr
                 && g_wdat == m_wdat && ((!g_ack && $2) || g_dat_o == m_dat_o));
endmodule
EOT
hierarchy -top miter
proc
flatten
hierarchy -top miter
opt_clean
clk2fflogic
opt_clean
setundef -zero -init
techmap
aigmap
opt_clean
setundef -zero
write_aiger -zinit $3
EOF
yosys -q -s m.ys
yosys-abc -c "read_aiger $3; pdr" | grep -E "Property proved|was asserted" || echo "no verdict"
}

ok=0
v=$(miter 0 1 m12.aig)
echo "1. mutant 12, ACK_LEVEL = 0, wb_dat_o compared while wb_ack_o: $v"
case "$v" in *"Property proved"*) ;; *) ok=1 ;; esac
v=$(miter 0 0 always.aig)
echo "2. control: wb_dat_o compared at every step: $v"
case "$v" in *"was asserted"*) ;; *) ok=1 ;; esac
v=$(miter 1 1 level.aig)
echo "3. control: ACK_LEVEL = 1 (level ack), compared while wb_ack_o: $v"
case "$v" in *"was asserted"*) ;; *) ok=1 ;; esac
exit $ok
