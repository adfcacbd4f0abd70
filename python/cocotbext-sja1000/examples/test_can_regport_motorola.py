"""cocotb bench of rtl/can_regport (can_top behind a plain register port on
clk_i) and rtl/can_top_mcu in Motorola mode (mode_i low: AS, E, R/W, CS
and the multiplexed AD port) with the golden SJA1000 as scoreboard, fed by
the register-port or Motorola monitor.

Run by examples/run.py --top can_regport or --top can_top_mcu; the top
chooses the bus. The scoreboard writes its report and markers to
REPORT_DIR; each test also logs the simulator time of every read the
bench's own monitor sees (``<name>.reads.txt``: ps, register, data), which
run.py holds the scoreboard's divergence marker against.
"""

import json
import os
import tempfile
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, Timer

try:  # cocotb 2.x
    from cocotb.simtime import get_sim_time
except ImportError:  # cocotb 1.9
    from cocotb.utils import get_sim_time

from cocotbext.sja1000 import (
    CanBus,
    CanFrame,
    CanMonitor,
    MotorolaMaster,
    MotorolaMonitor,
    ProtocolViolation,
    RegportMaster,
    RegportMonitor,
    Sja1000Scoreboard,
)

CAN_HZ = 24e6
CAN_PERIOD_PS = 41_666

# Per top: the agents and the bus as the run record names it. Both tops
# run on clk_i alone, reset rst_i (active high).
BUSES = {
    "can_regport": (RegportMaster, RegportMonitor, "Regport"),
    "can_top_mcu": (MotorolaMaster, MotorolaMonitor, "Motorola"),
}


def clock(sig, period_ps):
    try:  # cocotb 2.x
        return Clock(sig, period_ps, unit="ps")
    except TypeError:  # cocotb 1.9
        return Clock(sig, period_ps, units="ps")


def report_dir() -> str:
    d = os.environ.get("REPORT_DIR")
    return d if d else tempfile.mkdtemp(prefix="cocotb-can-report-")


def bus_of(dut):
    top = dut._name
    if top not in BUSES:
        raise ValueError(f"toplevel {top}: this bench runs on {', '.join(BUSES)}")
    return BUSES[top]


async def clocks_and_reset(dut):
    """24 MHz CAN clock, the reset held."""
    await Timer(3001, "ps")  # the Motorola master's ns steps never meet a CAN edge at 0
    cocotb.start_soon(clock(dut.clk_i, CAN_PERIOD_PS).start())
    dut.rst_i.value = 1


async def release_reset(dut):
    await ClockCycles(dut.clk_i, 4)
    dut.rst_i.value = 0
    await ClockCycles(dut.clk_i, 4)


async def start(dut, name):
    """Clock, reset, CAN bus, the bus master, and the scoreboard fed by the
    bus monitor on the same pins."""
    master_cls, monitor_cls, _ = bus_of(dut)
    await clocks_and_reset(dut)
    host = master_cls(dut)
    bus = CanBus(dut)
    mon = CanMonitor(dut)
    reads = Path(report_dir()) / f"{name}.reads.txt"
    reads.parent.mkdir(parents=True, exist_ok=True)
    reads.write_text("")

    def log_read(a) -> None:
        if not a.launch and not a.write:
            with reads.open("a") as f:
                f.write(f"{round(get_sim_time('ps'))} {a.addr} {a.data}\n")

    monitor = monitor_cls(dut)
    monitor.add_callback(log_read)
    sb = Sja1000Scoreboard(
        dut, profile="rtl", can_hz=CAN_HZ, name=name, report_dir=report_dir(), monitor=monitor, reset="rst_i",
    )
    await release_reset(dut)
    return host, bus, mon, sb, monitor


async def pelican(host, mod):
    """PeliCAN, accept all, 600 kbit/s at 24 MHz, every interrupt, then MOD = mod."""
    for a, d in [(0, 0x01), (31, 0x80), (0, 0x01 | mod)] + [(a, 0x00) for a in range(16, 20)] \
            + [(a, 0xFF) for a in range(20, 24)] + [(6, 0x41), (7, 0x25), (8, 0x1A), (4, 0xFF), (0, mod)]:
        await host.write(a, d)


async def send(host, ident, data, cmd):
    for a, d in [(16, len(data)), (17, ident >> 3), (18, (ident & 7) << 5)] \
            + [(19 + i, b) for i, b in enumerate(data)] + [(1, cmd)]:
        await host.write(a, d)


async def wait_sr(host, clk, mask, max_polls=400):
    for _ in range(max_polls):
        sr = await host.read(2)
        if sr & mask == mask:
            return sr
        await ClockCycles(clk, 80)
    raise AssertionError(f"SR & 0x{mask:02X} never set (last SR 0x{sr:02X})")


async def read_rx(host):
    info = await host.read(16)
    ident = (await host.read(17)) << 3 | (await host.read(18)) >> 5
    data = bytes([await host.read(19 + i) for i in range(info & 0x0F)])
    await host.write(1, 0x04)  # release the receive buffer
    return CanFrame(ident, data)


def check_record(dut, sb, monitor, name):
    """Every access went through the monitor into the model, as this bus."""
    record = json.loads((Path(sb.report_dir) / f"{name}.record.json").read_text())
    want = bus_of(dut)[2]
    assert record["host_bus"] == want and len(record["host_ops"]) == monitor.accesses, \
        (record["host_bus"], want, len(record["host_ops"]), monitor.accesses)
    assert not monitor.violations, monitor.violations


@cocotb.test()
async def bus_self_test_frame(dut):
    """PeliCAN self-test over the top's bus: the DUT sends a frame to itself;
    the scoreboard sees every access through the bus monitor."""
    name = "bus_self_test_frame"
    host, bus, mon, sb, monitor = await start(dut, name)
    await pelican(host, 0x04)
    await send(host, 0x123, b"\xA5\x5A", 0x10)  # self reception request
    await wait_sr(host, dut.clk_i, 0x09)  # TCS and RBS
    assert int(dut.irq_on.value) == 0, "no interrupt (irq_on is active low)"
    ir = await host.read(3)
    assert ir & 0x03 == 0x03, f"IR 0x{ir:02X}: not both the receive and transmit interrupts"
    got = await read_rx(host)
    assert got == CanFrame(0x123, b"\xA5\x5A"), got
    f = await mon.recv()
    assert f.arbitration_id == 0x123 and bytes(f.data) == b"\xA5\x5A", f
    await sb.finish()
    assert monitor.accesses >= 30 and sb.model.compared_reads >= 8, (monitor.accesses, sb.model.compared_reads)
    assert sb.model.compared_bits >= 60, sb.model.compared_bits
    check_record(dut, sb, monitor, name)
    assert sb.marker_ps is None


@cocotb.test()
async def bus_frame_exchange_with_a_model_node(dut):
    """The DUT sends to a model node, which answers; the DUT receives it."""
    name = "bus_frame_exchange_with_a_model_node"
    host, bus, mon, sb, monitor = await start(dut, name)
    node = bus.add_node("node")
    await pelican(host, 0x00)
    await send(host, 0x2A5, b"\x01\x02\x03", 0x01)  # transmission request
    f = await node.recv()
    assert f.arbitration_id == 0x2A5 and bytes(f.data) == b"\x01\x02\x03", f
    node.send_nowait(CanFrame(0x0F0, b"\xCA\xFE"))
    await wait_sr(host, dut.clk_i, 0x01)
    got = await read_rx(host)
    assert got == CanFrame(0x0F0, b"\xCA\xFE"), got
    assert mon.count == 2 and not mon.errors and not mon.error_frames, (mon.count, mon.errors, mon.error_frames)
    await sb.finish()
    assert sb.model.compared_bits >= 100, sb.model.compared_bits
    check_record(dut, sb, monitor, name)


async def regport_violations(dut):
    """Both strobes in one clock; a read strobe held two clocks with its
    address changed; a write strobe before a read's data is due."""
    clk = dut.clk_i
    await FallingEdge(clk)
    dut.wr_adr_i.value, dut.wdat_i.value, dut.rd_adr_i.value = 4, 0x00, 2
    dut.wr_i.value, dut.rd_i.value = 1, 1
    await FallingEdge(clk)
    dut.wr_i.value, dut.rd_i.value = 0, 0
    await ClockCycles(clk, 30)
    await FallingEdge(clk)
    dut.rd_i.value = 1
    await FallingEdge(clk)
    dut.rd_adr_i.value = 3
    await FallingEdge(clk)
    dut.rd_i.value = 0
    await ClockCycles(clk, 30)
    await FallingEdge(clk)
    dut.rd_adr_i.value, dut.rd_i.value = 2, 1
    await FallingEdge(clk)
    dut.rd_i.value = 0
    await ClockCycles(clk, 2)
    await FallingEdge(clk)
    dut.wr_i.value = 1
    await FallingEdge(clk)
    dut.wr_i.value = 0
    await ClockCycles(clk, 30)
    return ["read and write strobes high in the same clock",
            "the address changed while the read strobe was held",
            "read strobe held longer than 1 clock",
            "a write strobe 3 clocks after the read strobe of register 2, before its data is due (read latency 14)"]


async def motorola_violations(dut):
    """AS raised during a write's E; R/W flipped during a write's E; a read
    whose E is far too short for the core to answer."""

    async def pins(ns, **kw):
        for k, v in kw.items():
            getattr(dut, k).value = v
        await Timer(ns, "ns")

    # A write of 0x04 to register 4 with AS raised in its E (the core
    # latches 4 again: harmless).
    await pins(120, ale_as_i=1, cs_can_i=1, wr_rw_i=0, port_0_i=4)
    await pins(40, ale_as_i=0)
    await pins(160, port_0_i=0x04)
    await pins(200, rd_e_i=1)
    await pins(120, ale_as_i=1)
    await pins(80, ale_as_i=0)
    await pins(40, rd_e_i=0)
    await pins(1000, cs_can_i=0, wr_rw_i=1, port_0_i=0xFF)
    # A write whose R/W goes high 300 ns into E.
    await pins(120, ale_as_i=1, cs_can_i=1, wr_rw_i=0, port_0_i=4)
    await pins(40, ale_as_i=0)
    await pins(160, port_0_i=0x00)
    await pins(300, rd_e_i=1)
    await pins(100, wr_rw_i=1)
    await pins(40, rd_e_i=0)
    await pins(2000, cs_can_i=0, port_0_i=0xFF)
    # A read of SR with a 200 ns E.
    await pins(120, ale_as_i=1, cs_can_i=1, port_0_i=2)
    await pins(40, ale_as_i=0)
    await pins(160, port_0_i=0xFF)
    await pins(200, rd_e_i=1)
    await pins(1000, rd_e_i=0, cs_can_i=0)
    return ["AS rose while E was high",
            "R/W changed to read (high) while E was high",
            "E high 200 ns in a read (at least 760 ns)",
            "read of register 2: E high 200 ns and the core never drove AD"]


@cocotb.test()
async def bus_monitor_flags_protocol_violations(dut):
    """The bus monitor names a rule the host broke, in one sentence each."""
    master_cls, monitor_cls, _ = bus_of(dut)
    await clocks_and_reset(dut)
    master_cls(dut)  # the pins idle
    monitor = monitor_cls(dut, strict=False)
    await release_reset(dut)
    want = await (regport_violations if dut._name == "can_regport" else motorola_violations)(dut)
    assert len(monitor.violations) == len(want), monitor.violations
    for got, text in zip(monitor.violations, want):
        assert text in got and "protocol violation at" in got, (got, text)


@cocotb.test(expect_error=ProtocolViolation)
async def bus_strict_monitor_fails_the_test_at_a_violation(dut):
    """A monitor left strict (the default) fails the running test at the
    first violation with the sentence; the test must not get past it."""
    master_cls, monitor_cls, _ = bus_of(dut)
    await clocks_and_reset(dut)
    master_cls(dut)
    monitor_cls(dut)
    await release_reset(dut)
    await (regport_violations if dut._name == "can_regport" else motorola_violations)(dut)
    await ClockCycles(dut.clk_i, 10)
    raise AssertionError("no ProtocolViolation from the strict monitor")


@cocotb.test()
async def bus_monitor_names_a_configuration_the_pins_contradict(dut):
    """can_regport: a monitor told the read data comes 4 clocks after the
    strobe sees it come later; can_top_mcu: MODE high (Intel mode) during a
    Motorola access."""
    master_cls, monitor_cls, _ = bus_of(dut)
    await clocks_and_reset(dut)
    host = master_cls(dut)
    if dut._name == "can_regport":
        monitor = monitor_cls(dut, read_latency=4, strict=False)
        want = "later than its read latency of 4"
    else:
        monitor = monitor_cls(dut, strict=False)
        dut.mode_i.value = 1
        want = "MODE is high (Intel mode)"
    await release_reset(dut)
    await host.read(2)
    await ClockCycles(dut.clk_i, 20)
    assert monitor.violations and want in monitor.violations[0], monitor.violations
