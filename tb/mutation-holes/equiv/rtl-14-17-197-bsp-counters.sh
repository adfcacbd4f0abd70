#!/bin/sh
# Our rtl/'s mutants 14, 17 and 197 of seed 1 (rtl/can_bsp.v; the one-line
# mutation lines):
#   14  mutate -mode inv -cell $flatten\u_bsp.$procdff$7026 -port Q -portbit 0   (rcnt bit 0)
#   17  mutate -mode inv -cell $flatten\u_bsp.$procdff$7019 -port Q -portbit 0   (eq_cnt bit 0)
#   197 mutate -mode cnot1 -cell $flatten\u_bsp.$procmux$2833 -port Y -portbit 3 -ctrlbit 1
#
# Why no scenario kills them:
# - 14, 17: `inv` on a flop's Q inverts what every reader sees, the flop's own
#   hold path included (proc builds "not assigned" as D = the Q wire). So the
#   bit toggles on every clock the flop is not written. rcnt and eq_cnt are
#   read and written only at sample points. Samples come on time-quantum ticks:
#   tq is 2 (BRP + 1) clocks, and the prescaler restarts at every tick and on
#   every stop. So from one sample to the next, or from the S_OFF clock to the
#   first sample, is always an even number of clocks. The toggling cancels
#   out at every read. Per module (`sample` a free input) the mutants differ;
#   with can_btl driving `sample` they cannot.
# - 197: $procmux$2833 is cnt's `cnt == 5 ? cnt : cnt + 1` mux of an active
#   error flag and of an overload flag. The mutant counts 0, 1, 10, 3, 4, 5
#   (bit 3 is flipped in 2 and in 11): the flag has the same length. A stale 10
#   (run dropped in the flag's third bit) lives on only in states that do not
#   read cnt.
#
# Proofs: a miter of the original and the mutant, built the way the mutants
# are (read_verilog of every rtl/ file, prep of can_top: the same cell
# names). A reset is forced in the first clock; after that every input is free,
# rst and run included. The property is "an explicit relational invariant
# holds, and every output is equal". It is proved by 1-induction (yosys `sat
# -tempinduct`): it holds after the reset, and from any state that satisfies
# it, every input keeps it. The invariant is proved, never assumed, and no
# input is constrained, so it is sound for any environment.
#   197: can_bsp alone (stronger than any wider scope).
#   14, 17: can_bsp + can_btl wired as in can_top. rst, run, rm, BTR0/BTR1,
#   rx and the other modules' outputs are free and shared by both copies.
#   Every output of both modules is compared.
# Controls (each must give a counterexample from reset):
#   the invariant without its mutant clause (the mutant's register really
#   differs inside), the neighbour mutant -ctrlbit 0 of 197 (differs at the
#   ports), and 14 and 17 with `sample` free instead of can_btl (the kit's
#   per-module scope: differ at the ports).
# Run it from the repository root: `sh tb/mutation-holes/equiv/rtl-14-17-197-bsp-counters.sh`.
# It prints one verdict line per check and exits 0 when every verdict is as above
# (KEEP=1 keeps the miters and the yosys logs).
set -e
root=$(pwd)
test -f "$root/rtl/can_bsp.v" || { echo "run from the repository root" >&2; exit 2; }
command -v yosys >/dev/null || { echo "yosys not found on PATH" >&2; exit 2; }
work=$(mktemp -d)
if [ -n "$KEEP" ]; then echo "miters and logs kept in $work"; else trap 'rm -rf "$work"' EXIT; fi
cd "$work"
files="$root/rtl/can_top.v $root/rtl/can_wb_cdc.v $root/rtl/can_regs.v $root/rtl/can_btl.v $root/rtl/can_bsp.v $root/rtl/can_fce.v $root/rtl/can_acf.v $root/rtl/can_rxfifo.v"

# name:width lists of can_bsp's outputs and registers, can_btl's outputs and registers
BSP_OUT="tx_next:1 hard_en:1 rx_id:29 rx_ide:1 rx_rtr:1 rx_dlc:4 rx_data:64 rx_valid:1 tx_done:1 tx_drop:1 alc_evt:1 alc_val:5 err_evt:1 ecc_val:8 tec_add8:1 tec_sub1:1 rec_add1:1 rec_add8:1 rec_sub1:1 recov_tick:1 rs:1 ts:1 bus_idle:1 integrating:1"
BSP_REG="st:5 cnt:6 scnt:3 slast:1 crc:15 srtr:1 txr:1 req:1 req_single:1 req_self:1 abort_hold:1 crc_err:1 ack_pend:1 eq_cnt:3 eq_last:1 first:1 id_sr:29 align:3 flag_act:1 dom_cnt:3 rcnt:4"
BTL_OUT="sample:1 rx_bit:1 tx_o:1"
BTL_REG="pre:7 q:5 rx_tq:1 rx_tq2:1 last_bit:1 synced:1"
names() { for nw in "$@"; do printf '%s ' "${nw%%:*}"; done; }
decl() { p=$1; shift; for nw in "$@"; do echo "  wire [${nw##*:}-1:0] ${p}_${nw%%:*};"; done; }
conn() { p=$1; shift; for nw in "$@"; do printf ' .%s(%s_%s),' "${nw%%:*}" "$p" "${nw%%:*}"; done; }
# " && g_x == m_x" for every name but those in $1
eqall() { ex=" $1 "; shift; for nw in "$@"; do n=${nw%%:*}; case "$ex" in *" $n "*) ;; *) printf ' && g_%s == m_%s' "$n" "$n" ;; esac; done; }
BSP_IN=".rm(rm), .run(run), .lom(lom), .stm(stm), .passive(passive), .bus_off(bus_off), .tx_ide(tx_ide), .tx_rtr(tx_rtr), .tx_dlc(tx_dlc), .tx_id(tx_id), .tx_data(tx_data), .tx_req(tx_req), .tx_single(tx_single), .tx_self(tx_self), .tx_abort(tx_abort)"
HEAD="input clk, input rst, input rm, input run, input lom, input stm, input passive, input bus_off, input tx_ide, input tx_rtr,
  input [3:0] tx_dlc, input [28:0] tx_id, input [63:0] tx_data, input tx_req, input tx_single, input tx_self, input tx_abort"

# $1 = miter file, $2 = mutate command (on module bsp_mut), $3 = with can_btl (1/0), $4 = invariant
# (Verilog over g_*/m_*), $5 = register left out of the all-equal part, $6 = sat options
check() {
  if [ "$3" = 1 ]; then
    {
      echo "module miter($HEAD, input rx_i, input [7:0] btr0, input [7:0] btr1, output bad);"
      echo "  reg started = 1'b0;"
      echo "  always @(posedge clk) started <= 1'b1;"
      echo "  wire r = rst | !started;"
      decl g $BSP_OUT $BSP_REG $BTL_OUT $BTL_REG; decl m $BSP_OUT $BSP_REG $BTL_OUT $BTL_REG
      for s in g m; do
        b=can_bsp; [ $s = m ] && b=bsp_mut
        echo "  can_btl ${s}_btl(.clk(clk), .rst(r), .run(run), .brp(btr0[5:0]), .sjw(btr0[7:6]), .tseg1(btr1[3:0]), .tseg2(btr1[6:4]), .sam(btr1[7]), .rx(rx_i), .hard_en(${s}_hard_en),$(conn $s $BTL_OUT $BTL_REG) .tx_next(${s}_tx_next));"
        echo "  $b ${s}_bsp(.clk(clk), .rst(r), .sample(${s}_sample), .rx(${s}_rx_bit), .tx_cur(${s}_tx_o),$(conn $s $BSP_OUT $BSP_REG) $BSP_IN);"
      done
      echo "  wire same = 1'b1 $(eqall "$5" $BSP_OUT $BSP_REG $BTL_OUT $BTL_REG);"
      echo "  wire inv = same && $4;"
      echo "  assign bad = started && !inv;"
      echo "endmodule"
    } > "$1.v"
  else
    {
      echo "module miter($HEAD, input sample, input rx, input tx_cur, output bad);"
      echo "  reg started = 1'b0;"
      echo "  always @(posedge clk) started <= 1'b1;"
      echo "  wire r = rst | !started;"
      decl g $BSP_OUT $BSP_REG; decl m $BSP_OUT $BSP_REG
      echo "  can_bsp g(.clk(clk), .rst(r), .sample(sample), .rx(rx), .tx_cur(tx_cur),$(conn g $BSP_OUT $BSP_REG) $BSP_IN);"
      echo "  bsp_mut m(.clk(clk), .rst(r), .sample(sample), .rx(rx), .tx_cur(tx_cur),$(conn m $BSP_OUT $BSP_REG) $BSP_IN);"
      echo "  wire same = 1'b1 $(eqall "$5" $BSP_OUT $BSP_REG);"
      echo "  wire inv = same && $4;"
      echo "  assign bad = started && !inv;"
      echo "endmodule"
    } > "$1.v"
  fi
  cat > "$1.ys" <<EOF
read_verilog -I$root/rtl $files
hierarchy -top can_top
prep -top can_top
# the mutated cells are the listed ones
select -assert-count 1 can_bsp/w:rcnt %ci1:+[Q] can_bsp/c:\$procdff\$7026 %i
select -assert-count 1 can_bsp/w:eq_cnt %ci1:+[Q] can_bsp/c:\$procdff\$7019 %i
select -assert-count 1 can_bsp/w:cnt %co1:+[B] can_bsp/c:\$procmux\$2833 %i
copy can_bsp bsp_mut
$2
expose $(for n in $(names $BSP_REG); do printf 'can_bsp/w:%s bsp_mut/w:%s ' "$n" "$n"; done)
expose $(for n in $(names $BTL_REG); do printf 'can_btl/w:%s ' "$n"; done)
read_verilog $1.v
hierarchy -top miter
proc
flatten
opt_clean
sat $6 -prove bad 0 -set-init-zero
EOF
  yosys -q -l "$1.log" -s "$1.ys" >/dev/null 2>&1 || true
  if grep -q "Induction step proven: SUCCESS" "$1.log"; then echo "PROVED (1-induction)"
  elif grep -q "model found for base case" "$1.log"; then
    echo "counterexample from reset ($(grep -o 'induction with length [0-9]*' "$1.log" | tail -1 | grep -o '[0-9]*$') clocks)"
  elif grep -q "model found: FAIL" "$1.log"; then
    echo "counterexample from reset (outputs differ at clock $(awk '$2 == "\\bad" && $3 == 1 { print $1; exit }' "$1.log"))"
  elif grep -q "SAT proof finished - no model found: SUCCESS" "$1.log"; then echo "no counterexample within the bound"
  else echo "no verdict"; fi
}
ok=0
expect() { # $1 = label, $2 = verdict, $3 = expected prefix
  echo "$1: $2"
  case "$2" in "$3"*) ;; *) ok=1 ;; esac
}

# ---- 197: can_bsp alone ----
M197='mutate -mode cnot1 -module bsp_mut -cell $procmux$2833 -port Y -portbit 3 -ctrlbit 1'
# counting: an active error flag or an overload flag (cnt 0..5; the mutant's 10 stands for 2);
# quiet: off, integrating, idle, SOF, bus-off, error wait: cnt is not read there, and they are
# left only with cnt written or to another of them
COUNTING="((g_st == 5'd20 && g_flag_act) || g_st == 5'd23)"
QUIET="(g_st == 5'd0 || g_st == 5'd1 || g_st == 5'd2 || g_st == 5'd3 || g_st == 5'd24 || g_st == 5'd21)"
I197="($COUNTING ? (g_cnt <= 6'd5 && m_cnt == (g_cnt == 6'd2 ? 6'd10 : g_cnt)) : (m_cnt == g_cnt || ($QUIET && g_cnt == 6'd2 && m_cnt == 6'd10)))"
expect "197, can_bsp, every input free" "$(check m197 "$M197" 0 "$I197" cnt '-tempinduct -maxsteps 2')" PROVED
expect "197 control: the invariant without 'cnt 10 stands for 2'" \
  "$(check c197a "$M197" 0 "($COUNTING ? g_cnt <= 6'd5 : 1'b1) && m_cnt == g_cnt" cnt '-tempinduct -maxsteps 12')" counterexample
expect "197 control: the neighbour mutant -ctrlbit 0, outputs only" \
  "$(check c197b 'mutate -mode cnot1 -module bsp_mut -cell $procmux$2833 -port Y -portbit 3 -ctrlbit 0' 0 "1'b1" "$(names $BSP_REG)" '-seq 16')" counterexample

# ---- 14 and 17: can_bsp + can_btl ----
# The mutated bit toggles on every clock it is not written, as bit 0 of the prescaler
# does; samples come with pre = 0 only. Where the register is read, the bit is the gold one.
SAMPLE="(!g_sample || g_pre == 7'd0)"
M17='mutate -mode inv -module bsp_mut -cell $procdff$7019 -port Q -portbit 0'
R17="(g_st == 5'd20 && !g_flag_act && g_cnt != 6'd0)"
I17="g_eq_cnt[2:1] == m_eq_cnt[2:1] && $SAMPLE && (!$R17 || !(g_eq_cnt[0] ^ m_eq_cnt[0] ^ g_pre[0]))"
expect "17, can_bsp + can_btl, every other input free" "$(check m17 "$M17" 1 "$I17" eq_cnt '-tempinduct -maxsteps 2')" PROVED
expect "17 control: the invariant without the phase term" \
  "$(check c17a "$M17" 1 "g_eq_cnt == m_eq_cnt" eq_cnt '-tempinduct -maxsteps 12')" counterexample
expect "17 control: can_bsp alone (sample free), outputs only" \
  "$(check c17b "$M17" 0 "1'b1" "$(names $BSP_REG)" '-seq 16')" counterexample

M14='mutate -mode inv -module bsp_mut -cell $procdff$7026 -port Q -portbit 0'
# rcnt is read in integration and bus-off, entered only from S_OFF (rcnt written; pre = 0 there)
R14="(g_st == 5'd1 || g_st == 5'd24)"
I14="g_rcnt[3:1] == m_rcnt[3:1] && $SAMPLE && (g_st != 5'd0 || (g_pre == 7'd0 && !g_sample)) && (!$R14 || !(g_rcnt[0] ^ m_rcnt[0] ^ g_pre[0]))"
expect "14, can_bsp + can_btl, every other input free" "$(check m14 "$M14" 1 "$I14" rcnt '-tempinduct -maxsteps 2')" PROVED
expect "14 control: the invariant without the phase term" \
  "$(check c14a "$M14" 1 "g_rcnt == m_rcnt" rcnt '-tempinduct -maxsteps 12')" counterexample
expect "14 control: can_bsp alone (sample free), outputs only" \
  "$(check c14b "$M14" 0 "1'b1" "$(names $BSP_REG)" '-seq 16')" counterexample
exit $ok
