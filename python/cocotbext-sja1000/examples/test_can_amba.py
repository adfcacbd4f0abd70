"""cocotb bench of rtl/can_axi4lite and rtl/can_apb (can_top behind an
AXI4-Lite slave or an APB completer, one register per 32-bit word) with the
golden SJA1000 as scoreboard, fed by the AXI4-Lite or APB monitor.

Run by examples/run.py --top can_axi4lite or --top can_apb; the top
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
    ApbMaster,
    ApbMonitor,
    Axi4LiteMaster,
    Axi4LiteMonitor,
    CanBus,
    CanFrame,
    CanMonitor,
    ProtocolViolation,
    Sja1000Scoreboard,
)

CAN_HZ = 24e6
CAN_PERIOD_PS = 41_666

# Per top: the host clock, its active-low reset, the agents, and the bus
# as the run record names it.
BUSES = {
    "can_axi4lite": ("s_axi_aclk", "s_axi_aresetn", Axi4LiteMaster, Axi4LiteMonitor, "s_axi_", "Axi4Lite"),
    "can_apb": ("pclk", "presetn", ApbMaster, ApbMonitor, "", "Apb"),
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
    """50 MHz host clock, 24 MHz CAN clock, the host reset held (active low)."""
    clk, rst, *_ = bus_of(dut)
    cocotb.start_soon(clock(getattr(dut, clk), 20_000).start())
    await Timer(3001, "ps")  # no CAN edge on a host edge
    cocotb.start_soon(clock(dut.clk_i, CAN_PERIOD_PS).start())
    getattr(dut, rst).value = 0


async def release_reset(dut):
    clk, rst, *_ = bus_of(dut)
    await ClockCycles(getattr(dut, clk), 4)
    getattr(dut, rst).value = 1
    await ClockCycles(getattr(dut, clk), 4)


async def start(dut, name):
    """Clocks, reset, CAN bus, the bus master, and the scoreboard fed by the
    bus monitor on the same pins."""
    clk, rst, master_cls, monitor_cls, prefix, _ = bus_of(dut)
    await clocks_and_reset(dut)
    host = master_cls(dut, prefix)
    bus = CanBus(dut)
    mon = CanMonitor(dut)
    reads = Path(report_dir()) / f"{name}.reads.txt"
    reads.parent.mkdir(parents=True, exist_ok=True)
    reads.write_text("")

    def log_read(a) -> None:
        if not a.launch and not a.write:
            with reads.open("a") as f:
                f.write(f"{round(get_sim_time('ps'))} {a.addr} {a.data}\n")

    monitor = monitor_cls(dut, prefix)
    monitor.add_callback(log_read)
    sb = Sja1000Scoreboard(
        dut, profile="rtl", can_hz=CAN_HZ, name=name, report_dir=report_dir(), monitor=monitor,
        reset=rst, reset_active_low=True,
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
    want = bus_of(dut)[5]
    assert record["host_bus"] == want and len(record["host_ops"]) == monitor.accesses, \
        (record["host_bus"], want, len(record["host_ops"]), monitor.accesses)
    assert not monitor.violations, monitor.violations


@cocotb.test()
async def amba_self_test_frame(dut):
    """PeliCAN self-test over the top's bus: the DUT sends a frame to itself;
    the scoreboard sees every access through the bus monitor."""
    name = "amba_self_test_frame"
    host, bus, mon, sb, monitor = await start(dut, name)
    clk = getattr(dut, bus_of(dut)[0])
    await pelican(host, 0x04)
    await send(host, 0x123, b"\xA5\x5A", 0x10)  # self reception request
    await wait_sr(host, clk, 0x09)  # TCS and RBS
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
async def amba_frame_exchange_with_a_model_node(dut):
    """The DUT sends to a model node, which answers; the DUT receives it."""
    name = "amba_frame_exchange_with_a_model_node"
    host, bus, mon, sb, monitor = await start(dut, name)
    clk = getattr(dut, bus_of(dut)[0])
    node = bus.add_node("node")
    await pelican(host, 0x00)
    await send(host, 0x2A5, b"\x01\x02\x03", 0x01)  # transmission request
    f = await node.recv()
    assert f.arbitration_id == 0x2A5 and bytes(f.data) == b"\x01\x02\x03", f
    node.send_nowait(CanFrame(0x0F0, b"\xCA\xFE"))
    await wait_sr(host, clk, 0x01)
    got = await read_rx(host)
    assert got == CanFrame(0x0F0, b"\xCA\xFE"), got
    assert mon.count == 2 and not mon.errors and not mon.error_frames, (mon.count, mon.errors, mon.error_frames)
    await sb.finish()
    assert sb.model.compared_bits >= 100, sb.model.compared_bits
    check_record(dut, sb, monitor, name)


async def axi_violations(dut, monitor):
    """ARVALID withdrawn before ARREADY; WDATA changed while WVALID waits."""
    await FallingEdge(dut.s_axi_aclk)
    dut.s_axi_araddr.value, dut.s_axi_arvalid.value = 2 * 4, 1
    await FallingEdge(dut.s_axi_aclk)
    dut.s_axi_arvalid.value = 0  # the slave needs more than one cycle: no ARREADY yet
    await ClockCycles(dut.s_axi_aclk, 40)  # the read the DUT started ends
    await FallingEdge(dut.s_axi_aclk)
    dut.s_axi_awaddr.value, dut.s_axi_wdata.value, dut.s_axi_wstrb.value = 4 * 4, 0x11, 1
    dut.s_axi_awvalid.value, dut.s_axi_wvalid.value = 1, 1
    await FallingEdge(dut.s_axi_aclk)
    dut.s_axi_wdata.value = 0x22
    await ClockCycles(dut.s_axi_aclk, 3)
    return ["ARVALID fell before ARREADY", "the W payload (WDATA, WSTRB) changed while WVALID waited for WREADY"]


async def apb_violations(dut, monitor):
    """PSEL and PENABLE raised together; PENABLE dropped before PREADY."""
    await FallingEdge(dut.pclk)
    dut.paddr.value, dut.pwrite.value, dut.psel.value, dut.penable.value = 2 * 4, 0, 1, 1
    await FallingEdge(dut.pclk)
    dut.psel.value, dut.penable.value = 0, 0  # the completer needs more than one cycle: no PREADY yet
    await ClockCycles(dut.pclk, 3)
    return ["PENABLE high without a setup phase", "PSEL or PENABLE fell before PREADY"]


@cocotb.test()
async def amba_monitor_flags_protocol_violations(dut):
    """The bus monitor names a handshake the requester broke, in one sentence each."""
    _, _, master_cls, monitor_cls, prefix, _ = bus_of(dut)
    await clocks_and_reset(dut)
    master_cls(dut, prefix)  # the pins idle
    monitor = monitor_cls(dut, prefix, strict=False)
    await release_reset(dut)
    want = await (axi_violations if dut._name == "can_axi4lite" else apb_violations)(dut, monitor)
    assert len(monitor.violations) == len(want), monitor.violations
    for got, text in zip(monitor.violations, want):
        assert text in got and "protocol violation at" in got, (got, text)


@cocotb.test(expect_error=ProtocolViolation)
async def amba_strict_monitor_fails_the_test_at_a_violation(dut):
    """A monitor left strict (the default) fails the running test at the
    first violation with the sentence; the test must not get past it."""
    _, _, master_cls, monitor_cls, prefix, _ = bus_of(dut)
    await clocks_and_reset(dut)
    master_cls(dut, prefix)
    monitor_cls(dut, prefix)
    await release_reset(dut)
    await (axi_violations if dut._name == "can_axi4lite" else apb_violations)(dut, None)
    await ClockCycles(dut.clk_i, 10)
    raise AssertionError("no ProtocolViolation from the strict monitor")
