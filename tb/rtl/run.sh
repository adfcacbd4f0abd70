#!/bin/sh
# Icarus self-checks for rtl/ (can_top, can_avalon, can_top_8051). Exits non-zero on failure.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
rtl="$here/../../rtl"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
src="$rtl/can_top.v $rtl/can_wb_cdc.v $rtl/can_regs.v $rtl/can_btl.v $rtl/can_bsp.v $rtl/can_fce.v $rtl/can_acf.v $rtl/can_rxfifo.v"
for tb in tb_can tb_avalon tb_8051; do
    [ -f "$here/$tb.v" ] || continue
    case "$tb" in
        tb_avalon) extra="$rtl/can_avalon.v" ;;
        tb_8051) extra="$rtl/can_top_8051.v" ;;
        *) extra="" ;;
    esac
    iverilog -g2005 -I "$rtl" -o "$out/$tb.vvp" "$here/$tb.v" $src $extra
    vvp -n "$out/$tb.vvp" | tee "$out/$tb.log"
    grep -q '^PASS' "$out/$tb.log" || { echo "$tb: FAILED" >&2; exit 1; }
done
echo "rtl self-checks: all passed"
