"""cocotb bench of rtl/can_avalon (can_top behind an Avalon-MM slave with
waitrequest) with the golden SJA1000 as scoreboard, fed by an Avalon-MM
monitor.

Run by examples/run.py --top can_avalon (Icarus or Verilator). The
scoreboard writes its report and markers to REPORT_DIR; each test also
logs the simulator time of every read the bench's own monitor sees
(``<name>.reads.txt``: ps, address, data), which run.py holds the
scoreboard's divergence marker against.
"""

import json
import os
import tempfile
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, Timer

try:  # cocotb 2.x
    from cocotb.simtime import get_sim_time
except ImportError:  # cocotb 1.9
    from cocotb.utils import get_sim_time

from cocotbext.sja1000 import AvalonAccess, AvalonMaster, AvalonMonitor, CanBus, CanFrame, CanMonitor, Sja1000Scoreboard

CAN_HZ = 24e6
CAN_PERIOD_PS = 41_666


def clock(sig, period_ps):
    try:  # cocotb 2.x
        return Clock(sig, period_ps, unit="ps")
    except TypeError:  # cocotb 1.9
        return Clock(sig, period_ps, units="ps")


def report_dir() -> str:
    d = os.environ.get("REPORT_DIR")
    return d if d else tempfile.mkdtemp(prefix="cocotb-can-report-")


async def start(dut, name):
    """Clocks (50 MHz host, 24 MHz CAN), reset, bus, Avalon master, and the
    scoreboard fed by an Avalon monitor on the same pins."""
    cocotb.start_soon(clock(dut.clk, 20_000).start())
    await Timer(3001, "ps")  # no CAN edge on a host edge
    cocotb.start_soon(clock(dut.can_clk, CAN_PERIOD_PS).start())
    dut.reset.value = 1
    av = AvalonMaster(dut, "", clock="clk")
    bus = CanBus(dut, tx="tx", rx="rx", clk="can_clk")
    mon = CanMonitor(dut, pin="rx", clk="can_clk")
    reads = Path(report_dir()) / f"{name}.reads.txt"
    reads.parent.mkdir(parents=True, exist_ok=True)
    reads.write_text("")

    def log_read(a: AvalonAccess) -> None:
        if not a.launch and not a.write:
            with reads.open("a") as f:
                f.write(f"{round(get_sim_time('ps'))} {a.addr} {a.data}\n")

    host = AvalonMonitor(dut, "", clock="clk", reset="reset")
    host.add_callback(log_read)
    sb = Sja1000Scoreboard(
        dut, profile="rtl", can_hz=CAN_HZ, name=name, report_dir=report_dir(), monitor=host,
        clk="can_clk", rx="rx", tx="tx", irq="irq", irq_active_low=False, reset="reset",
    )
    await ClockCycles(dut.clk, 4)
    dut.reset.value = 0
    await ClockCycles(dut.clk, 4)
    return av, bus, mon, sb, host


async def pelican(av, mod):
    """PeliCAN, accept all, 600 kbit/s at 24 MHz, every interrupt, then MOD = mod."""
    for a, d in [(0, 0x01), (31, 0x80), (0, 0x01 | mod)] + [(a, 0x00) for a in range(16, 20)] \
            + [(a, 0xFF) for a in range(20, 24)] + [(6, 0x41), (7, 0x25), (8, 0x1A), (4, 0xFF), (0, mod)]:
        await av.write(a, d)


async def wait_sr(av, clk, mask, max_polls=400):
    for _ in range(max_polls):
        sr = await av.read(2)
        if sr & mask == mask:
            return sr
        await ClockCycles(clk, 80)
    raise AssertionError(f"SR & 0x{mask:02X} never set (last SR 0x{sr:02X})")


@cocotb.test()
async def avalon_self_test_frame(dut):
    """PeliCAN self-test over Avalon-MM: the DUT sends a frame to itself; the
    scoreboard sees every access through its Avalon monitor."""
    name = "avalon_self_test_frame"
    av, bus, mon, sb, host = await start(dut, name)
    await pelican(av, 0x04)
    for a, d in [(16, 0x02), (17, 0x123 >> 3), (18, (0x123 & 7) << 5), (19, 0xA5), (20, 0x5A), (1, 0x10)]:
        await av.write(a, d)
    await wait_sr(av, dut.clk, 0x09)  # TCS and RBS
    assert int(dut.irq.value) == 1, "no interrupt (irq is active high on can_avalon)"
    ir = await av.read(3)
    assert ir & 0x03 == 0x03, f"IR 0x{ir:02X}: not both the receive and transmit interrupts"
    got = CanFrame((await av.read(17)) << 3 | (await av.read(18)) >> 5, bytes([await av.read(19), await av.read(20)]))
    assert got == CanFrame(0x123, b"\xA5\x5A"), got
    await av.write(1, 0x04)  # release the receive buffer: RI, and irq, end
    await ClockCycles(dut.can_clk, 16)
    assert int(dut.irq.value) == 0, "irq still high with the receive buffer released"
    f = await mon.recv()
    assert f.arbitration_id == 0x123 and bytes(f.data) == b"\xA5\x5A", f
    await sb.finish()
    # Every access went through the monitor into the model, with Avalon's timing.
    assert host.accesses >= 30 and sb.model.compared_reads >= 10, (host.accesses, sb.model.compared_reads)
    assert sb.model.compared_bits >= 60, sb.model.compared_bits
    record = json.loads((Path(sb.report_dir) / f"{name}.record.json").read_text())
    assert record["host_bus"] == "Avalon" and len(record["host_ops"]) == host.accesses, \
        (record["host_bus"], len(record["host_ops"]), host.accesses)
    # No divergence: markers written, none set.
    assert sb.marker_ps is None
    vcd = (Path(sb.report_dir) / f"{name}.markers.vcd").read_text()
    assert "W:CMR=0x10" in vcd and "123#A55A" in vcd, vcd[:2000]
