#!/bin/sh
# Our rtl/'s mutant 22 of seed 1 (`mutate -mode inv -module can_top -cell
# $flatten\u_cdc.$procmux$6885 -port B -portbit 0`, rtl/can_wb_cdc.v:93): the
# cell is the HOLD mux of `dat_q` (the latched write data) in the
# `busy && ack_edge` branch, so the mutant inverts dat_q[0] at every ack.
# (Not the `served` flop: with ACK_LEVEL = 0 that branch assigns no `served`,
# there is no such mux; the flattened design.il names $procmux$6885 with
# B = \u_cdc.dat_q.)
#
# Three checks with yosys + ABC's PDR (both clocks free inputs through
# clk2fflogic, registers from zero), run from the repository root:
#  1. can_wb_cdc, original against mutant, wb_rst_i confined to one pulse at
#     the start: every output equal, and acc_wdat equal whenever acc_stb is
#     high. PROVED (PDR finds an inductive invariant).
#     Control: the same harness with bit 0 of the launch load (dat_q <=
#     wb_dat_i) inverted instead: a counterexample (6 frames).
#  2. can_top, its bridge's acc_wdat replaced by a free value whenever
#     acc_stb is low, against can_top: equivalent (yosys equiv_induct: every
#     register and output matched by name). So the core reads acc_wdat only
#     with acc_stb, and 1 + 2 make the mutant equal to the core at can_top's
#     ports in every run whose wb_rst_i is one pulse at the start.
#     Control: the free value at acc_stb too (never the write data) is not
#     equivalent.
#  3. The same as 1 with wb_rst_i free: a COUNTEREXAMPLE (PDR frame 37-38). Two
#     wb_rst_i pulses close together: the second request is cleared by the
#     first reset's feedback (rst_fb_s still high), the wishbone side launches
#     an access while the clk_i side is still being reset, and a stale ack
#     toggle ends it before its strobe; the mutant's flipped bit 0 is then
#     written. The original misbehaves there too (the access acknowledged
#     before it is done): a reset-handshake defect of can_wb_cdc, reported
#     to the lead; no scenario can kill mutant 22 without it.
# Prints one verdict line per check; exit 0 when every verdict is as above.
set -e
root=$(pwd)
test -f "$root/rtl/can_wb_cdc.v" || { echo "run from the repository root" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

# ---- 1 and 3: the bridge alone ----
miter() { # $1 = cell to mutate, $2 = its B input wire, $3 = one reset (1/0), $4 = output
cat > m.ys <<EOF
read_verilog $root/rtl/can_wb_cdc.v
hierarchy -top can_wb_cdc
proc
select -assert-count 1 w:$2 %co:+[B] c:$1 %i
copy can_wb_cdc cdc_mut
mutate -mode inv -module cdc_mut -cell $1 -port B -portbit 0
read_verilog <<EOT
module miter(input wb_clk_i, input wb_rst_i, input [7:0] wb_dat_i, input wb_cyc_i, input wb_stb_i,
             input wb_we_i, input [7:0] wb_adr_i, input clk_i, input [7:0] acc_rdat, output bad);
  wire [7:0] g_dat_o, m_dat_o, g_adr, m_adr, g_wdat, m_wdat;
  wire g_ack, m_ack, g_rst, m_rst, g_stb, m_stb, g_we, m_we;
  // one reset pulse at the start: once a wb_clk_i edge saw wb_rst_i low, it stays low
  reg after_reset = 1'b0;
  always @(posedge wb_clk_i) if (!wb_rst_i) after_reset <= 1'b1;
  wire rst = wb_rst_i & !(after_reset & $3);
  can_wb_cdc g(.wb_clk_i(wb_clk_i), .wb_rst_i(rst), .wb_dat_i(wb_dat_i), .wb_dat_o(g_dat_o),
    .wb_cyc_i(wb_cyc_i), .wb_stb_i(wb_stb_i), .wb_we_i(wb_we_i), .wb_adr_i(wb_adr_i), .wb_ack_o(g_ack),
    .clk_i(clk_i), .rst_o(g_rst), .acc_stb(g_stb), .acc_we(g_we), .acc_adr(g_adr), .acc_wdat(g_wdat), .acc_rdat(acc_rdat));
  cdc_mut m(.wb_clk_i(wb_clk_i), .wb_rst_i(rst), .wb_dat_i(wb_dat_i), .wb_dat_o(m_dat_o),
    .wb_cyc_i(wb_cyc_i), .wb_stb_i(wb_stb_i), .wb_we_i(wb_we_i), .wb_adr_i(wb_adr_i), .wb_ack_o(m_ack),
    .clk_i(clk_i), .rst_o(m_rst), .acc_stb(m_stb), .acc_we(m_we), .acc_adr(m_adr), .acc_wdat(m_wdat), .acc_rdat(acc_rdat));
  assign bad = !(g_dat_o == m_dat_o && g_ack == m_ack && g_rst == m_rst && g_stb == m_stb && g_we == m_we
                 && g_adr == m_adr && (!g_stb || g_wdat == m_wdat));
endmodule
EOT
hierarchy -top miter
proc
flatten
opt_clean
clk2fflogic
opt_clean
setundef -zero -init
techmap
aigmap
opt_clean
setundef -zero
write_aiger -zinit $4
EOF
yosys -q -s m.ys
yosys-abc -c "read_aiger $4; pdr" | grep -E "Property proved|was asserted" || echo "no verdict"
}

ok=0
v=$(miter '$procmux$76' dat_q 1 m22.aig)
echo "1. mutant 22, one reset at the start: $v"
case "$v" in *"Property proved"*) ;; *) ok=1 ;; esac
v=$(miter '$procmux$73' wb_dat_i 1 control.aig)
echo "1. control (launch load bit 0 inverted), one reset: $v"
case "$v" in *"was asserted"*) ;; *) ok=1 ;; esac
v=$(miter '$procmux$76' dat_q 0 m22free.aig)
echo "3. mutant 22, wb_rst_i free: $v"
case "$v" in *"was asserted"*) ;; *) ok=1 ;; esac

# ---- 2: the core reads acc_wdat only with acc_stb ----
files="$root/rtl/can_top.v $root/rtl/can_wb_cdc.v $root/rtl/can_regs.v $root/rtl/can_btl.v $root/rtl/can_bsp.v $root/rtl/can_fce.v $root/rtl/can_acf.v $root/rtl/can_rxfifo.v"
wrapper() { # $1 = acc_wdat expression (w: the bridge's, junk: a free value)
cat <<EOF
read_verilog -I$root/rtl $files
rename can_wb_cdc can_wb_cdc_core
read_verilog <<EOT
module can_wb_cdc #(parameter ACK_LEVEL = 0) (
    input wb_clk_i, input wb_rst_i, input [7:0] wb_dat_i, output [7:0] wb_dat_o, input wb_cyc_i,
    input wb_stb_i, input wb_we_i, input [7:0] wb_adr_i, output wb_ack_o, input clk_i, output rst_o,
    output acc_stb, output acc_we, output [7:0] acc_adr, output [7:0] acc_wdat, input [7:0] acc_rdat);
  wire [7:0] w;
  (* anyseq *) wire [7:0] junk;
  can_wb_cdc_core #(.ACK_LEVEL(ACK_LEVEL)) c(.wb_clk_i(wb_clk_i), .wb_rst_i(wb_rst_i), .wb_dat_i(wb_dat_i),
    .wb_dat_o(wb_dat_o), .wb_cyc_i(wb_cyc_i), .wb_stb_i(wb_stb_i), .wb_we_i(wb_we_i), .wb_adr_i(wb_adr_i),
    .wb_ack_o(wb_ack_o), .clk_i(clk_i), .rst_o(rst_o), .acc_stb(acc_stb), .acc_we(acc_we), .acc_adr(acc_adr),
    .acc_wdat(w), .acc_rdat(acc_rdat));
  assign acc_wdat = $1;
endmodule
EOT
hierarchy -top can_top
proc
flatten
memory
opt_clean
EOF
}
masked() { # $1 = the gate's acc_wdat expression
{
  wrapper "$1"; echo "rename can_top gate"; echo "design -stash gate"
  wrapper "w"; echo "rename can_top gold"
  cat <<EOF
design -copy-from gate -as gate gate
clk2fflogic
opt_clean
equiv_make -blacklist blacklist.txt gold gate equiv
hierarchy -top equiv
async2sync
equiv_simple -seq 2
equiv_induct -seq 2
tee -o status.txt equiv_status
EOF
} > e.ys
# The nets that carry acc_wdat are not matched: they differ by design while
# acc_stb is low, and equiv_induct assumes every matched point equal in the
# previous steps. Every register and every port of can_top is matched.
printf 'acc_wdat\nu_cdc.acc_wdat\nu_fce.wdat\nu_fifo.wdat\nu_regs.acc_wdat\nu_regs.sleep_d\n' > blacklist.txt
yosys -q -s e.ys >/dev/null 2>&1 || true
grep -E "Of those cells" status.txt | sed 's/^ *//'
}
v=$(masked 'acc_stb ? w : junk')
echo "2. can_top with acc_wdat free while acc_stb is low: $v"
case "$v" in *" and 0 are unproven"*) ;; *) ok=1 ;; esac
v=$(masked 'junk')
echo "2. control (acc_wdat always free): $v"
case "$v" in *" and 0 are unproven"*|"") ok=1 ;; *) ;; esac
exit $ok
