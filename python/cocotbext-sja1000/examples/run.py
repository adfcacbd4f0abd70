"""Runs the cocotb bench of rtl/can_top (examples/test_can_top.py).

    python run.py --sim icarus                       # our rtl/: every test passes
    python run.py --sim icarus --mutant              # a one-line mutant: must fail with the diagnosis
    python run.py --sim icarus --no-scoreboard       # the same bench without the scoreboard

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


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sim", default="icarus", choices=["icarus", "verilator"])
    ap.add_argument("--mutant", action="store_true")
    ap.add_argument("--no-scoreboard", action="store_true")
    ap.add_argument("--tests", default=None, help="comma-separated test names")
    ap.add_argument("--build-dir", default=None)
    a = ap.parse_args()

    work = Path(a.build_dir or tempfile.mkdtemp(prefix="cocotb-can-"))
    rtl = mutant_rtl(work / "mutant-rtl") if a.mutant else ROOT / "rtl"
    sources = sorted(p for p in rtl.glob("can_*.v"))
    runner = get_runner(a.sim)
    build_dir = work / f"build-{a.sim}{'-mutant' if a.mutant else ''}"
    extra = ["-Wno-fatal", "-Wno-lint", "-Wno-style"] if a.sim == "verilator" else []
    runner.build(
        verilog_sources=sources, includes=[rtl], hdl_toplevel="can_top", build_dir=build_dir,
        timescale=("1ps", "1ps"), build_args=extra, always=True,
    ) if "verilog_sources" in runner.build.__code__.co_varnames else runner.build(
        sources=sources, includes=[rtl], hdl_toplevel="can_top", build_dir=build_dir,
        timescale=("1ps", "1ps"), build_args=extra, always=True,
    )
    reports = build_dir / "reports"
    shutil.rmtree(reports, ignore_errors=True)
    env = {"SCOREBOARD": "0" if a.no_scoreboard else "1", "REPORT_DIR": str(reports)}
    t0 = time.monotonic()
    xml = runner.test(
        hdl_toplevel="can_top", test_module="test_can_top", test_dir=HERE, build_dir=build_dir,
        extra_env=env, results_xml=str(build_dir / "results.xml"),
        **({"testcase": a.tests.split(",")} if a.tests else {}),
    )
    dt = time.monotonic() - t0
    fails = failures(Path(xml))
    print(f"run time {dt:.2f} s ({a.sim}, {'mutant' if a.mutant else 'rtl'}, scoreboard {'off' if a.no_scoreboard else 'on'})")
    if not a.mutant:
        for name, text in fails:
            print(f"FAILED {name}:\n{text}")
        return 1 if fails else 0
    # The mutant: the self-test must fail, and the scoreboard's diagnosis
    # (written to REPORT_DIR) must name SR and TCS.
    if "self_test_frame" not in [n for n, _ in fails]:
        print("the mutant was not caught by self_test_frame")
        return 1
    report = reports / "self_test_frame.diagnosis.txt"
    text = report.read_text() if report.is_file() else ""
    ok = "DutDeviatesFromModel" in text and "register SR" in text and "TCS" in text
    print(("mutant caught, diagnosis:\n" if ok else "mutant failed without the diagnosis:\n") + text)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
