"""Classic Wishbone (8-bit data) driver and monitor."""

import logging
from typing import Any, Callable, List, NamedTuple

import cocotb
from cocotb.triggers import FallingEdge

from ._signals import bind, level, stop_task, value


class WishboneAccess(NamedTuple):
    """One access: ``launch`` is True at the host edge that first presents
    it (``data`` = write data), False at its ack (``data`` = read data)."""

    write: bool
    addr: int
    data: int
    launch: bool


_SIGNALS = ("clk_i", "cyc_i", "stb_i", "we_i", "adr_i", "dat_i", "dat_o", "ack_o")


class _Pins:
    def __init__(self, dut: Any, prefix: str) -> None:
        for s in _SIGNALS:
            setattr(self, s, bind(dut, prefix, s))


class WishboneMaster:
    """Drives ``dut.<prefix>{cyc_i,stb_i,we_i,adr_i,dat_i}`` on falling
    edges of ``<prefix>clk_i`` and waits for ``<prefix>ack_o``; one access
    at a time, ``timeout`` host cycles each."""

    def __init__(self, dut: Any, prefix: str = "wb_", timeout: int = 10_000) -> None:
        self.log = logging.getLogger(f"cocotb.{dut._name}.wbmaster")
        self.p = _Pins(dut, prefix)
        self.timeout = timeout
        for s in ("cyc_i", "stb_i", "we_i", "adr_i", "dat_i"):
            getattr(self.p, s).value = 0

    async def _access(self, write: bool, addr: int, data: int) -> int:
        p = self.p
        await FallingEdge(p.clk_i)
        p.cyc_i.value, p.stb_i.value, p.we_i.value, p.adr_i.value = 1, 1, int(write), addr
        if write:
            p.dat_i.value = data
        for _ in range(self.timeout):
            await FallingEdge(p.clk_i)
            if level(p.ack_o):
                got = value(p.dat_o)
                p.cyc_i.value, p.stb_i.value = 0, 0
                return got
        raise TimeoutError(f"Wishbone {'write' if write else 'read'} of address {addr}: no ack in {self.timeout} cycles")

    async def write(self, addr: int, data: int) -> None:
        await self._access(True, addr, data)

    async def read(self, addr: int) -> int:
        return await self._access(False, addr, 0)


class WishboneMonitor:
    """Watches the same pins (at falling edges of the host clock, so every
    value is the one the core sampled at the rising edge before) and calls
    each callback with a :class:`WishboneAccess` at the launch and at the
    ack of every access."""

    #: The host bus's name, for the scoreboard (the profile's ``[access.wishbone]``).
    host_bus = "wishbone"

    def __init__(self, dut: Any, prefix: str = "wb_", reset: str = "rst_i") -> None:
        self.p = _Pins(dut, prefix)
        self.reset = bind(dut, prefix, reset) if reset else None
        self._callbacks: List[Callable[[WishboneAccess], None]] = []
        self.accesses = 0
        self._task = cocotb.start_soon(self._run())

    def add_callback(self, fn: Callable[[WishboneAccess], None]) -> None:
        self._callbacks.append(fn)

    def stop(self) -> None:
        stop_task(self._task)

    async def _run(self) -> None:
        p = self.p
        active = False
        we = False
        adr = 0
        while True:
            await FallingEdge(p.clk_i)
            if self.reset is not None and level(self.reset):
                active = False
                continue
            if level(p.cyc_i) and level(p.stb_i) and not active:
                active, we, adr = True, level(p.we_i), value(p.adr_i)
                a = WishboneAccess(we, adr, value(p.dat_i) if we else 0, True)
                for cb in self._callbacks:
                    cb(a)
            if active and level(p.ack_o):
                active = False
                self.accesses += 1
                a = WishboneAccess(we, adr, value(p.dat_o), False)
                for cb in self._callbacks:
                    cb(a)
