"""cocotb bench of rtl/can_top with the golden SJA1000 as scoreboard.

Run by examples/run.py (Icarus or Verilator). SCOREBOARD=0 leaves the
scoreboard out (for the benchmark); everything else stays the same.
"""

import os
import tempfile
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, Timer

from cocotbext.sja1000 import CanBus, CanFrame, CanMonitor, Sja1000Mismatch, Sja1000Scoreboard, WishboneMaster

CAN_HZ = 24e6
WITH_SCOREBOARD = os.environ.get("SCOREBOARD", "1") != "0"


def clock(sig, period_ps):
    try:  # cocotb 2.x
        return Clock(sig, period_ps, unit="ps")
    except TypeError:  # cocotb 1.9
        return Clock(sig, period_ps, units="ps")


def report_dir():
    """Where the scoreboard writes its run record and candump log."""
    d = os.environ.get("REPORT_DIR")
    return d if d else tempfile.mkdtemp(prefix="cocotb-can-report-")


def candump(sb):
    """The scoreboard's candump log, read back with python-can."""
    import can

    path = Path(sb.report_dir) / f"{sb.name}.log"
    assert path.is_file(), f"no candump log at {path}"
    return list(can.CanutilsLogReader(str(path)))


async def start(dut, rx_tied=None, name=None):
    """Clocks (50 MHz host, 24 MHz CAN), reset, bus, monitor, scoreboard."""
    cocotb.start_soon(clock(dut.wb_clk_i, 20_000).start())
    await Timer(3001, "ps")  # no CAN edge on a host edge
    cocotb.start_soon(clock(dut.clk_i, 41_666).start())
    dut.wb_rst_i.value = 1
    wb = WishboneMaster(dut, "wb_")
    bus = CanBus(dut, rx_tied=rx_tied)
    mon = CanMonitor(dut)
    sb = None
    if WITH_SCOREBOARD:
        sb = Sja1000Scoreboard(dut, profile="rtl", can_hz=CAN_HZ, name=name, report_dir=report_dir())
    await ClockCycles(dut.wb_clk_i, 4)
    dut.wb_rst_i.value = 0
    await ClockCycles(dut.wb_clk_i, 4)
    return wb, bus, mon, sb


async def pelican(wb, mod):
    """PeliCAN, accept all, 600 kbit/s at 24 MHz, every interrupt, then MOD = mod."""
    await wb.write(0, 0x01)
    await wb.write(31, 0x80)
    await wb.write(0, 0x01 | mod)
    for a in range(16, 20):
        await wb.write(a, 0x00)
    for a in range(20, 24):
        await wb.write(a, 0xFF)
    await wb.write(6, 0x41)
    await wb.write(7, 0x25)
    await wb.write(8, 0x1A)
    await wb.write(4, 0xFF)
    await wb.write(0, mod)


async def send(wb, ident, data, cmd):
    await wb.write(16, len(data))
    await wb.write(17, ident >> 3)
    await wb.write(18, (ident & 7) << 5)
    for i, b in enumerate(data):
        await wb.write(19 + i, b)
    await wb.write(1, cmd)


async def wait_sr(wb, mask, max_polls=400):
    for _ in range(max_polls):
        sr = await wb.read(2)
        if sr & mask == mask:
            return sr
        await ClockCycles(wb.p.clk_i, 80)
    raise AssertionError(f"SR & 0x{mask:02X} never set (last SR 0x{sr:02X})")


async def read_rx(wb):
    info = await wb.read(16)
    ident = (await wb.read(17)) << 3 | (await wb.read(18)) >> 5
    data = bytes([await wb.read(19 + i) for i in range(info & 0x0F)])
    await wb.write(1, 0x04)  # release receive buffer
    return CanFrame(ident, data)


@cocotb.test()
async def self_test_frame(dut):
    """PeliCAN self-test: the DUT sends a frame to itself (rx = tx, no other node)."""
    wb, bus, mon, sb = await start(dut, name="self_test_frame")
    await pelican(wb, 0x04)
    await send(wb, 0x123, b"\xA5\x5A", 0x10)  # self reception request
    await wait_sr(wb, 0x09)  # TCS and RBS
    await wb.read(3)
    got = await read_rx(wb)
    assert got == CanFrame(0x123, b"\xA5\x5A"), got
    f = await mon.recv()
    assert f.arbitration_id == 0x123 and bytes(f.data) == b"\xA5\x5A", f
    if sb:
        await sb.finish()
        # The scoreboard compared something: every read, every sample point.
        assert sb.model.compared_reads >= 30, sb.model.compared_reads
        assert sb.model.compared_bits >= 60, sb.model.compared_bits


@cocotb.test()
async def frame_exchange_with_two_model_nodes(dut):
    """The DUT sends to two model nodes; one model node answers; the DUT receives it."""
    wb, bus, mon, sb = await start(dut, name="frame_exchange_with_two_model_nodes")
    a, b = bus.add_node("a"), bus.add_node("b")
    await pelican(wb, 0x00)
    await send(wb, 0x2A5, b"\x01\x02\x03", 0x01)  # transmission request
    for node in (a, b):
        f = await node.recv()
        assert f.arbitration_id == 0x2A5 and bytes(f.data) == b"\x01\x02\x03", f
    a.send_nowait(CanFrame(0x0F0, b"\xCA\xFE"))
    await wait_sr(wb, 0x01)
    got = await read_rx(wb)
    assert got == CanFrame(0x0F0, b"\xCA\xFE"), got
    f = await b.recv()
    assert f.arbitration_id == 0x0F0, f
    assert mon.count == 2 and not mon.errors, (mon.count, mon.errors)
    assert not mon.error_frames and not mon.overload_frames, (mon.error_frames, mon.overload_frames)
    if sb:
        await sb.finish()
        # The candump log the command line writes, read back by python-can.
        log = candump(sb)
        assert [(m.arbitration_id, bytes(m.data)) for m in log] == [(0x2A5, b"\x01\x02\x03"), (0x0F0, b"\xCA\xFE")], log
        assert not any(m.is_error_frame for m in log), log


@cocotb.test()
async def thesis_rx_tied_recessive_is_diagnosed(dut):
    """The DE2 thesis: BasicCAN, rx tied recessive; the frame never completes
    and the scoreboard says why (tb/de2-thesis.toml on the command line)."""
    wb, bus, mon, sb = await start(dut, rx_tied=True, name="thesis_rx_tied_recessive")
    for a, d in [(0, 0x01), (31, 0x00), (4, 0xFF), (5, 0xFF), (6, 0x41), (7, 0x25), (8, 0xDB), (0, 0x00),
                 (10, 0xA5), (11, 0x21), (12, 0x51)]:
        await wb.write(a, d)
    assert await wb.read(12) == 0x51
    await wb.write(1, 0x01)  # transmission request
    await ClockCycles(dut.clk_i, 200 * 40)
    sr = await wb.read(2)
    assert sr & 0x08 == 0, f"SR 0x{sr:02X}: TCS with rx tied?"
    if not sb:
        return
    try:
        await sb.finish()
    except Sja1000Mismatch as e:
        text = str(e)
        dut._log.info("diagnosis, as expected:\n%s", text)
        assert "RxNotFollowingTx" in text and "rx_i is tied to 1" in text, text
        assert "TEC after attempt 1 = 136" in text, text
    else:
        raise AssertionError("the scoreboard did not report the frame that never went out")


async def receive_with_errors(dut, name, place_faults):
    """Node a sends one frame to the DUT and node b; ``place_faults(bus)``
    disturbs it. Returns (wb, bus, mon, sb, a) once the DUT has it."""
    wb, bus, mon, sb = await start(dut, name=name)
    a, b = bus.add_node("a"), bus.add_node("b")
    place_faults(bus)
    await pelican(wb, 0x00)
    await ClockCycles(dut.clk_i, 20 * 40)  # the DUT integrates onto the bus (11 recessive bits)
    a.send_nowait(CanFrame(0x0F0, b"\xCA\xFE"))
    await wait_sr(wb, 0x01)
    got = await read_rx(wb)
    assert got == CanFrame(0x0F0, b"\xCA\xFE"), got
    f = await b.recv()
    assert f.arbitration_id == 0x0F0 and bytes(f.data) == b"\xCA\xFE", f
    assert bus.faults_waiting == 0 and bus.faults_applied > 0, "the fault never acted"
    return wb, bus, mon, sb, a


@cocotb.test()
async def crc_bit_flipped_for_the_dut_is_an_error_frame_and_a_retransmission(dut):
    """A flipped CRC bit on the DUT's rx only: the DUT, a receiver, flags a
    CRC error after the ACK delimiter; the sender counts a form error in its
    EOF (TEC 8) and sends again (TEC 7); the DUT keeps one copy."""
    wb, bus, mon, sb, a = await receive_with_errors(
        dut, "crc_bit_flipped", lambda bus: bus.flip(frame=1, field="crc", bit=3, target="dut-rx"))
    assert [e.error for e in mon.error_frames] == ["Crc"], mon.error_frames
    ecc = await wb.read(12)
    assert ecc & 0xE0 == 0xE0, f"ECC 0x{ecc:02X}: not an 'other' error while receiving"
    assert a.tec == 7, a.tec
    # RXERR: +1 (CRC error), +8 (the others' flags make the bit after its
    # own flag dominant, CAN 2.0B rule 2), -1 for the good copy.
    assert await wb.read(14) == 8
    assert await wb.read(2) & 0x01 == 0, "a second copy in the receive buffer"
    if sb:
        await sb.finish()
        log = candump(sb)
        assert any(m.is_error_frame for m in log), log
        assert [m.arbitration_id for m in log if not m.is_error_frame] == [0x0F0], log
        # python-can keeps no data of an error frame: the line itself.
        # CAN_ERR_PROT | CAN_ERR_BUSERROR | CAN_ERR_CNT, not while sending, RXERR 1.
        lines = (Path(sb.report_dir) / f"{sb.name}.log").read_text().splitlines()
        err = next(ln.split()[2] for ln in lines if ln.split()[2].startswith("2000"))
        assert err.startswith("20000288#0000") and err[9 + 4:9 + 6] == "00" and err.endswith("01"), lines


@cocotb.test()
async def glitch_over_the_sample_point_is_an_error_frame_and_a_retransmission(dut):
    """A pulse of 8 CAN clocks over the DUT's sample point of a data bit
    (clock 27 of 40 at BTR0 0x41, BTR1 0x25) on its rx only: the DUT reads
    the wrong level, the frame ends in one error frame and is sent again."""

    def faults(bus):
        assert bus.clocks_per_bit == 40
        # Data bit 4 of 0xCA is recessive: a dominant pulse, clocks 24..31.
        bus.glitch(frame=1, field="data", bit=4, offset=24, width=8, target="dut-rx")

    wb, bus, mon, sb, a = await receive_with_errors(dut, "glitch", faults)
    assert len(mon.error_frames) == 1, mon.error_frames
    assert a.tec == 7, a.tec
    assert bus.faults_applied == 8, bus.faults_applied
    if sb:
        await sb.finish()


@cocotb.test()
async def stuck_dominant_bus_costs_the_sender_and_a_dominant_intermission_is_an_overload_frame(dut):
    """The bus stuck dominant for 20 bits from the DUT's data field: a bit
    error (TEC 8), then 8 more dominant bits after its error flag (TEC + 8,
    CAN 2.0B rule 6); the resent frame goes out (TEC - 1). A
    dominant first intermission bit after it is an overload frame, no error."""
    wb, bus, mon, sb = await start(dut, name="stuck_bus")
    a = bus.add_node("a")
    bus.stuck("dominant", 20, frame=1, field="data", bit=0)
    bus.stuck("dominant", 1, frame=2, field="intermission", bit=0)
    await pelican(wb, 0x00)
    await send(wb, 0x2A5, b"\x7F\x01\x02", 0x01)
    f = await a.recv()
    assert f.arbitration_id == 0x2A5 and bytes(f.data) == b"\x7F\x01\x02", f
    await wait_sr(wb, 0x08)  # TCS
    while not mon.overload_frames:
        await mon.recv_event()
    assert bus.faults_waiting == 0 and bus.faults_applied > 0, bus.faults_applied
    assert len(mon.error_frames) == 1 and len(mon.overload_frames) == 1, (mon.error_frames, mon.overload_frames)
    tec = await wb.read(15)
    assert tec == 16 - 1, f"TXERR {tec}"
    if sb:
        await sb.finish()
