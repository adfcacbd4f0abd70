#!/usr/bin/env python3
"""Waveform pictures of one write and one read per host bus for
docs/guide/host-buses.md, from the kit's own VCD (`cancosim run --vcd`),
rendered by GTKWave under Xvfb. Usage: scripts/host-bus-pictures.py [OUTDIR]
(default docs/guide/img). Needs gtkwave, xvfb-run, xwd and netpbm (xwdtopnm, pnmtopng)."""
import os, re, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "docs/guide/img")
CLI = os.path.join(ROOT, "target/release/cancosim")
SCENARIO = os.path.join(ROOT, "tb/basic-filter-frames.toml")
HOSTS = ["axi4-lite", "apb", "motorola", "regport"]
SIGNALS = ["wb_clk_i", "clk_i", "wb_cyc_i", "wb_stb_i", "wb_we_i", "wb_adr_i[7:0]", "wb_dat_i[7:0]", "wb_dat_o[7:0]", "wb_ack_o"]


def accesses(vcd):
    """(start, end) in ps of the first write and the first read after reset."""
    ids, t, val, starts = {}, 0, {}, []
    with open(vcd) as f:
        for line in f:
            if line.startswith("$var"):
                p = line.split()
                ids[p[3]] = p[4]
            elif line.startswith("#"):
                t = int(line[1:])
            elif line[:1] in "01" and ids.get(line[1:].strip()) in ("wb_stb_i", "wb_we_i", "wb_rst_i"):
                n = ids[line[1:].strip()]
                old = val.get(n, "0")
                val[n] = line[0]
                if n == "wb_stb_i" and old == "0" and line[0] == "1" and val.get("wb_rst_i") != "1":
                    starts.append([t, None, "0"])
                if n == "wb_stb_i" and line[0] == "0" and starts and starts[-1][1] is None:
                    starts[-1][1] = t
                # a write if WE was high at any time of the access
                if starts and (starts[-1][1] is None or starts[-1][1] == t) and val.get("wb_we_i") == "1":
                    starts[-1][2] = "1"
            if len(starts) > 40:
                break
    w = next(s for s in starts if s[2] == "1" and s[1])
    r = next(s for s in starts if s[2] == "0" and s[1] and s[0] > w[0])
    return (w[0], w[1]), (r[0], r[1])


def render(vcd, host, kind, span):
    a, b = span
    if host == "regport":
        # no acknowledge: show the read data coming, 14 CAN clocks later
        b = max(b, a + 700_000)
    pad = max((b - a) // 3, 20_000)
    gtkw = vcd + f".{kind}.gtkw"
    with open(gtkw, "w") as g:
        g.write(f'[dumpfile] "{vcd}"\n[size] 1200 420\n[signals_width] 170\n[sst_expanded] 0\n')
        g.write(f"@800200\n-{host}: one {kind} (kit's VCD, Wishbone names of the host side)\n")
        for s in SIGNALS:
            g.write(("@22\n" if "[" in s else "@28\n") + f"cosim.{s}\n")
        g.write("@1000200\n-\n")
    tcl = vcd + f".{kind}.tcl"
    png = os.path.join(OUT, f"{host}-{kind}.png")
    with open(tcl, "w") as t:
        t.write(f"gtkwave::setZoomRangeTimes {a - pad} {b + pad}\nafter 1500\n")
    cmd = (f"gtkwave -S {tcl} {vcd} {gtkw} >/dev/null 2>&1 & p=$!; sleep 6; "
           f"xwd -root -silent | xwdtopnm 2>/dev/null | pnmtopng > {png}; kill $p")
    subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1200x420x24", "sh", "-c", cmd], check=True)
    print(png)


def main():
    os.makedirs(OUT, exist_ok=True)
    tmp = tempfile.mkdtemp()
    for host in HOSTS:
        vcd = os.path.join(tmp, f"{host}.vcd")
        subprocess.run([CLI, "run", SCENARIO, "--dut", "rtl", "--host", host, "--vcd", vcd], check=True, stdout=subprocess.DEVNULL)
        w, r = accesses(vcd)
        render(vcd, host, "write", w)
        render(vcd, host, "read", r)


main()
