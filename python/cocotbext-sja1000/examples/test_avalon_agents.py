"""The Avalon-MM master and monitor on the three transfer timings
(examples/avalon_slaves.v): every access the master makes, the monitor
reports once launched and once completed, with its data; reads return what
was written. Run by examples/run.py --top av_slave_wait|av_slave_pipe|av_slave_fixed.
"""

import random
from typing import List, Tuple

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles

from cocotbext.sja1000 import AvalonAccess, AvalonMaster, AvalonMonitor

# Fixed wait states of av_slave_fixed (None: the interface has waitrequest).
WAITS = {"av_slave_fixed": (2, 1)}
# Host cycles from launch to completion the slave's design gives: (write, read).
CYCLES = {"av_slave_wait": (3, 3), "av_slave_pipe": (2, 4), "av_slave_fixed": (2, 3)}


@cocotb.test()
async def every_access_is_seen_launched_and_completed_with_its_data(dut):
    cocotb.start_soon(Clock(dut.clk, 20_000, "ps").start())
    dut.reset.value = 1
    read_wait, write_wait = WAITS.get(dut._name, (None, None))
    av = AvalonMaster(dut, "", clock="clk", read_wait=read_wait, write_wait=write_wait)
    mon = AvalonMonitor(dut, "", clock="clk", reset="reset", read_wait=read_wait, write_wait=write_wait)
    launches: List[AvalonAccess] = []
    mon.add_callback(lambda a: launches.append(a) if a.launch else None)
    await ClockCycles(dut.clk, 3)
    dut.reset.value = 0
    rng = random.Random(7)
    done: List[Tuple[bool, int, int]] = []
    mem = {}
    for _ in range(12):
        addr, data = rng.randrange(256), rng.randrange(256)
        await av.write(addr, data)
        mem[addr] = data
        done.append((True, addr, data))
    for addr in list(mem)[::2]:
        got = await av.read(addr)
        assert got == mem[addr], f"read of {addr}: 0x{got:02X}, written 0x{mem[addr]:02X}"
        done.append((False, addr, got))
    await ClockCycles(dut.clk, 4)
    seen = []
    cycles = set()
    while len(seen) < len(done):
        a = await mon.recv()
        seen.append((a.write, a.addr, a.data))
        cycles.add((a.write, a.cycles))
    assert seen == done, (seen, done)
    w, r = CYCLES[dut._name]
    assert cycles == {(True, w), (False, r)}, cycles
    assert mon.accesses == len(done)
    assert [(a.write, a.addr) for a in launches] == [(w, a) for w, a, _ in done]
    mon.stop()
