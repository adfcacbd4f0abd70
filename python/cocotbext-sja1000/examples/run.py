"""Runs the cocotb bench of rtl/can_top (examples/test_can_top.py), of
rtl/can_avalon (examples/test_can_avalon.py, ``--top can_avalon``), of
rtl/can_axi4lite and rtl/can_apb (examples/test_can_amba.py, ``--top
can_axi4lite``, ``--top can_apb``) or of rtl/can_regport and
rtl/can_top_mcu in Motorola mode (examples/test_can_regport_motorola.py,
``--top can_regport``, ``--top can_top_mcu``).

    python run.py --sim icarus                       # our rtl/: every test passes
    python run.py --sim icarus --mutant              # a one-line mutant: must fail with the diagnosis
    python run.py --sim icarus --no-scoreboard       # the same bench without the scoreboard
    python run.py --sim icarus --top can_avalon [--mutant]
    python run.py --sim icarus --top can_apb [--mutant]   # also can_axi4lite
    python run.py --sim icarus --top can_top_mcu [--mutant]   # also can_regport
    python run.py --sim icarus --readme              # the package README's example, as written
    python run.py --sim icarus --top av_slave_pipe   # the Avalon agents on a small slave
                                                     # (also av_slave_wait, av_slave_fixed)

With ``--mutant`` on any top but can_top the scoreboard's
divergence marker (``<test>.markers.vcd`` and ``<test>.gtkw``) must also
sit at the failing SR read: within one CAN clock before the simulator time
at which the bench's own bus monitor saw that read complete.

Exit status 0 when the outcome is the expected one. Prints the wall time of
the test run (not the build) for the benchmark.
"""

import argparse
import os
import shutil
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

try:  # cocotb 2.x
    from cocotb_tools.runner import get_runner
except ImportError:  # cocotb 1.9
    from cocotb.runner import get_runner

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]

# A completed transmission no longer sets SR.TCS.
MUTANT_FROM = "if (tx_done) begin tbs <= 1'b1; tcs <= 1'b1; end"
MUTANT_TO = "if (tx_done) begin tbs <= 1'b1; end"


def mutant_rtl(dst: Path) -> Path:
    shutil.rmtree(dst, ignore_errors=True)  # a build directory used before
    shutil.copytree(ROOT / "rtl", dst)
    regs = dst / "can_regs.v"
    src = regs.read_text()
    if src.count(MUTANT_FROM) != 1:
        sys.exit(f"the line to mutate is not in {regs} exactly once")
    regs.write_text(src.replace(MUTANT_FROM, MUTANT_TO))
    return dst


def failures(xml: Path):
    """(test name, failure text) of every test case in a cocotb results file."""
    out = []
    for case in ET.parse(xml).iter("testcase"):
        for f in list(case.iter("failure")) + list(case.iter("error")):
            out.append((case.get("name"), (f.get("message") or "") + (f.text or "")))
    return out


# The test each mutant must fail, per top.
MUTANT_TEST = {
    "can_top": "self_test_frame",
    "can_avalon": "avalon_self_test_frame",
    "can_axi4lite": "amba_self_test_frame",
    "can_apb": "amba_self_test_frame",
    "can_regport": "bus_self_test_frame",
    "can_top_mcu": "bus_self_test_frame",
}
CAN_PERIOD_PS = 41_666


def divergence_marker(vcd: Path):
    """The time (ps) at which the marker VCD's ``divergence`` rises, or None."""
    ident, t = None, 0
    for line in vcd.read_text().splitlines():
        parts = line.split()
        if parts[:2] == ["$var", "wire"] and parts[4] == "divergence":
            ident = parts[3]
        elif line.startswith("#"):
            t = int(line[1:])
        elif ident is not None and line == "1" + ident:
            return t
    return None


def check_marker(reports: Path, test: str) -> str:
    """'' if the divergence marker sits at a read of SR the bench saw
    complete within one CAN clock after it, else what is wrong."""
    vcd, gtkw, reads = (reports / f"{test}{ext}" for ext in (".markers.vcd", ".gtkw", ".reads.txt"))
    if not vcd.is_file() or not gtkw.is_file():
        return f"no marker files ({vcd.name}, {gtkw.name})"
    t = divergence_marker(vcd)
    if t is None:
        return f"{vcd.name} has no divergence"
    marker = next((ln.split()[1] for ln in gtkw.read_text().splitlines() if ln.startswith("*")), None)
    if marker != str(t):
        return f"{gtkw.name}'s primary marker is {marker}, the divergence is at {t} ps"
    sr_reads = [int(ps) for ps, addr, _ in (ln.split() for ln in reads.read_text().splitlines()) if addr == "2"]
    if not any(0 <= ps - t < CAN_PERIOD_PS for ps in sr_reads):
        near = min(sr_reads, key=lambda ps: abs(ps - t)) if sr_reads else None
        return f"divergence marker at {t} ps, but no SR read completed within a CAN clock after it (nearest {near})"
    return ""


def readme_example(dst: Path) -> str:
    """Writes the package README's first Python example to ``dst`` as a
    test module, unchanged; its module name."""
    text = (HERE.parent / "README.md").read_text()
    start = text.index("```python\n") + len("```python\n")
    code = text[start:text.index("```", start)]
    if "@cocotb.test()" not in code:
        sys.exit("the README's first Python example is not a cocotb test")
    dst.mkdir(parents=True, exist_ok=True)
    (dst / "test_readme.py").write_text(code)
    return "test_readme"


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sim", default="icarus", choices=["icarus", "verilator"])
    ap.add_argument("--top", default="can_top",
                    choices=["can_top", "can_avalon", "can_axi4lite", "can_apb", "can_regport", "can_top_mcu",
                             "av_slave_wait", "av_slave_pipe", "av_slave_fixed"])
    ap.add_argument("--mutant", action="store_true")
    ap.add_argument("--no-scoreboard", action="store_true")
    ap.add_argument("--readme", action="store_true", help="run the package README's example (can_top)")
    ap.add_argument("--tests", default=None, help="comma-separated test names")
    ap.add_argument("--build-dir", default=None)
    a = ap.parse_args()

    work = Path(a.build_dir or tempfile.mkdtemp(prefix="cocotb-can-"))
    rtl = mutant_rtl(work / "mutant-rtl") if a.mutant else ROOT / "rtl"
    sources = sorted(p for p in rtl.glob("can_*.v"))
    if a.top.startswith("av_slave"):  # the Avalon agents alone, on small slaves
        sources = [HERE / "avalon_slaves.v"]
    runner = get_runner(a.sim)
    top = a.top
    module = {"can_top": "test_can_top", "can_avalon": "test_can_avalon",
              "can_axi4lite": "test_can_amba", "can_apb": "test_can_amba",
              "can_regport": "test_can_regport_motorola",
              "can_top_mcu": "test_can_regport_motorola"}.get(top, "test_avalon_agents")
    test_dir = HERE
    build_dir = work / f"build-{top}-{a.sim}{'-mutant' if a.mutant else ''}"
    if a.readme:
        if top != "can_top" or a.mutant:
            sys.exit("--readme runs the README's example on rtl/can_top only")
        # The bench's own build of rtl/ serves (same top, same sources).
        test_dir = work / "readme"
        module = readme_example(test_dir)
    extra = ["-Wno-fatal", "-Wno-lint", "-Wno-style"] if a.sim == "verilator" else []
    runner.build(
        verilog_sources=sources, includes=[rtl], hdl_toplevel=top, build_dir=build_dir,
        timescale=("1ps", "1ps"), build_args=extra, always=not a.readme,
    ) if "verilog_sources" in runner.build.__code__.co_varnames else runner.build(
        sources=sources, includes=[rtl], hdl_toplevel=top, build_dir=build_dir,
        timescale=("1ps", "1ps"), build_args=extra, always=not a.readme,
    )
    reports = build_dir / "reports"
    shutil.rmtree(reports, ignore_errors=True)
    env = {"SCOREBOARD": "0" if a.no_scoreboard else "1", "REPORT_DIR": str(reports)}
    t0 = time.monotonic()
    xml = runner.test(
        hdl_toplevel=top, test_module=module, test_dir=test_dir, build_dir=build_dir,
        extra_env=env, results_xml=str(build_dir / "results.xml"),
        **({"testcase": a.tests.split(",")} if a.tests else {}),
    )
    dt = time.monotonic() - t0
    fails = failures(Path(xml))
    ran = sum(1 for _ in ET.parse(xml).iter("testcase"))
    if ran == 0:
        print(f"no test ran ({module})")
        return 1
    print(f"run time {dt:.2f} s ({a.sim}, {'mutant' if a.mutant else 'rtl'}, scoreboard {'off' if a.no_scoreboard else 'on'})")
    if not a.mutant:
        for name, text in fails:
            print(f"FAILED {name}:\n{text}")
        return 1 if fails else 0
    # The mutant: the self-test must fail, and the scoreboard's diagnosis
    # (written to REPORT_DIR) must name SR and TCS.
    test = MUTANT_TEST[top]
    if test not in [n for n, _ in fails]:
        print(f"the mutant was not caught by {test}")
        return 1
    report = reports / f"{test}.diagnosis.txt"
    text = report.read_text() if report.is_file() else ""
    ok = "DutDeviatesFromModel" in text and "register SR" in text and "TCS" in text
    print(("mutant caught, diagnosis:\n" if ok else "mutant failed without the diagnosis:\n") + text)
    if ok and top != "can_top":
        wrong = check_marker(reports, test)
        print(f"marker: {wrong}" if wrong else "marker: the divergence marker sits at the failing SR read")
        ok = not wrong
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
