"""Avalon-MM host bus (8-bit data, one transfer at a time): a master that
drives it and a monitor that watches it, as separate roles.

Both bind ``dut.<prefix>{address, chipselect, read, write, writedata,
readdata}`` and, when the interface has them, ``waitrequest``,
``readdatavalid``, ``begintransfer`` and ``byteenable``; the clock and
reset are Platform Designer interfaces of their own, so they are named
without the prefix (or given as handles). The transfer timing is the
interface's, as the kit's Avalon BFM supports it (``crates/bfm``,
``AvalonTiming``):

- ``waitrequest``: a transfer ends at the first rising edge with
  ``waitrequest`` low; read data is sampled then;
- ``readdatavalid`` (pipelined reads): ``waitrequest`` ends the command,
  the read data comes later with ``readdatavalid`` (one read outstanding);
- neither: fixed wait states, the request held ``read_wait + 1`` (reads)
  or ``write_wait + 1`` (writes) cycles, read data sampled at the last.

Both agents act on falling edges of the clock and judge a rising edge by
the pins as they settle after the falling edge before it (``ReadOnly``),
which is what that edge samples: the master drives on a falling edge and
holds a request through the rising edge that ends it (as the kit's BFM
does); the monitor reports each rising edge's launch or completion at the
falling edge after it.
"""

import logging
from typing import Any, List, NamedTuple, Optional, Tuple, Union

import cocotb
from cocotb.triggers import FallingEdge, ReadOnly

from ._monitor import AccessMonitor
from ._signals import bind, level, value


class AvalonAccess(NamedTuple):
    """One Avalon-MM access as the monitor saw it. ``launch`` is True at
    the first clock edge that presents it (``data`` = write data, 0 for a
    read), False when it completes (``data`` = read data, or the write
    data); ``cycles``: host cycles from the launch to that edge."""

    write: bool
    addr: int
    data: int
    launch: bool
    cycles: int = 0


_REQUIRED = ("address", "chipselect", "read", "write", "writedata", "readdata")
_OPTIONAL = ("waitrequest", "readdatavalid", "begintransfer", "byteenable")


class AvalonBus:
    """The pins of one Avalon-MM slave interface, bound by name:
    ``dut.<prefix><name>``; optional signals are None when absent."""

    def __init__(self, dut: Any, prefix: str = "") -> None:
        self.prefix = prefix
        for s in _REQUIRED:
            setattr(self, s, bind(dut, prefix, s))
        for s in _OPTIONAL:
            setattr(self, s, getattr(dut, prefix + s, None))

    def describe(self) -> str:
        """Which optional signals the interface has, for the log."""
        have = [s for s in _OPTIONAL if getattr(self, s) is not None]
        missing = [s for s in _OPTIONAL if getattr(self, s) is None]
        return f"has {', '.join(have) or 'none'}; lacks {', '.join(missing) or 'none'}"


def _handle(dut: Any, sig: Union[str, Any, None]) -> Any:
    """A clock or reset given by name (on ``dut``, no prefix) or as a handle."""
    if sig is None or not isinstance(sig, str):
        return sig
    return bind(dut, "", sig)


class _Timing:
    """The interface's transfer timing (see the module's docs)."""

    def __init__(self, bus: AvalonBus, read_wait: Optional[int], write_wait: Optional[int]) -> None:
        self.pipelined = bus.readdatavalid is not None
        self.waitrequest = bus.waitrequest is not None
        if not self.waitrequest and (read_wait is None or write_wait is None):
            raise ValueError(
                f"Avalon interface '{bus.prefix}*' has no waitrequest: give read_wait and write_wait "
                "(its fixed wait states)")
        if self.pipelined and not self.waitrequest:
            raise ValueError(
                f"Avalon interface '{bus.prefix}*' has readdatavalid without waitrequest: "
                "pipelined reads with a fixed latency are not supported")
        self.read_wait = read_wait or 0
        self.write_wait = write_wait or 0

    def describe(self) -> str:
        if self.pipelined:
            return "waitrequest + readdatavalid (pipelined reads)"
        if self.waitrequest:
            return "waitrequest"
        return f"fixed wait states (read {self.read_wait}, write {self.write_wait})"

    def accepted(self, waitrequest: bool, write: bool, cycles: int) -> bool:
        """A request on the wires at its ``cycles``-th rising edge (1: the
        first), with ``waitrequest`` as that edge samples it, ends its
        command phase there."""
        if self.waitrequest:
            return not waitrequest
        return cycles > (self.write_wait if write else self.read_wait)


class AvalonMaster:
    """Drives an Avalon-MM slave: ``await write(addr, data)``, ``await
    read(addr)``; one transfer at a time, each given up after ``timeout``
    host cycles (:class:`TimeoutError`). Signals change on falling edges of
    ``clock``; ``begintransfer`` (if the interface has it) marks the first
    cycle, ``byteenable`` is 1."""

    def __init__(
        self,
        dut: Any,
        prefix: str = "",
        *,
        clock: Union[str, Any] = "clk",
        read_wait: Optional[int] = None,
        write_wait: Optional[int] = None,
        timeout: int = 10_000,
    ) -> None:
        self.log = logging.getLogger(f"cocotb.{dut._name}.avmaster")
        self.bus = AvalonBus(dut, prefix)
        self.clock = _handle(dut, clock)
        self.timing = _Timing(self.bus, read_wait, write_wait)
        self.timeout = timeout
        self._idle()
        self.log.info("Avalon-MM master on '%s*', 8-bit data, %s; %s", prefix, self.timing.describe(),
                      self.bus.describe())

    def _idle(self) -> None:
        b = self.bus
        for s in (b.chipselect, b.read, b.write, b.address, b.writedata):
            s.value = 0
        if b.begintransfer is not None:
            b.begintransfer.value = 0
        if b.byteenable is not None:
            b.byteenable.value = 1

    async def _access(self, write: bool, addr: int, data: int) -> int:
        b = self.bus
        what = f"Avalon {'write' if write else 'read'} of address {addr}"
        await FallingEdge(self.clock)
        b.chipselect.value, b.address.value = 1, addr
        b.read.value, b.write.value = int(not write), int(write)
        b.writedata.value = data if write else 0
        if b.begintransfer is not None:
            b.begintransfer.value = 1
        cycles = 0
        while True:
            await ReadOnly()  # what the next rising edge samples
            cycles += 1
            done = self.timing.accepted(b.waitrequest is not None and level(b.waitrequest), write, cycles)
            got = value(b.readdata)
            await FallingEdge(self.clock)  # that edge has passed
            if b.begintransfer is not None:
                b.begintransfer.value = 0
            if done:
                break
            if cycles >= self.timeout:
                self._idle()
                raise TimeoutError(f"{what}: held off for {self.timeout} cycles")
        b.chipselect.value, b.read.value, b.write.value = 0, 0, 0
        if write:
            return data
        if not self.timing.pipelined:
            return got
        # The data comes at a later edge (read latency 1 or more).
        while True:
            await ReadOnly()
            cycles += 1
            valid, got = level(b.readdatavalid), value(b.readdata)
            await FallingEdge(self.clock)
            if valid:
                return got
            if cycles >= self.timeout:
                raise TimeoutError(f"{what}: no readdatavalid in {self.timeout} cycles")

    async def write(self, addr: int, data: int) -> None:
        """One write transfer; returns when the slave has accepted it."""
        await self._access(True, addr, data)

    async def read(self, addr: int) -> int:
        """One read transfer; the read data."""
        return await self._access(False, addr, 0)


class AvalonMonitor(AccessMonitor):
    """Watches an Avalon-MM slave interface (the pins of
    :class:`AvalonBus`) and calls each callback with an
    :class:`AvalonAccess` at the launch and at the completion of every
    transfer; ``await recv()`` gives completed accesses in order.

    It drives nothing. A request is launched at the first edge it is on
    the wires (``chipselect`` and ``read`` or ``write``); it completes at
    the edge its command phase ends (writes; reads with ``waitrequest`` or
    fixed wait states) or at the edge with ``readdatavalid`` (pipelined
    reads). While ``reset`` is high nothing is launched and an access in
    flight is dropped."""

    #: The host bus's name, for the scoreboard (the profile's ``[access.avalon]``).
    host_bus = "avalon"

    def __init__(
        self,
        dut: Any,
        prefix: str = "",
        *,
        clock: Union[str, Any] = "clk",
        reset: Union[str, Any, None] = "reset",
        read_wait: Optional[int] = None,
        write_wait: Optional[int] = None,
    ) -> None:
        self.log = logging.getLogger(f"cocotb.{dut._name}.avmonitor")
        self.bus = AvalonBus(dut, prefix)
        self.clock = _handle(dut, clock)
        self.reset = _handle(dut, reset)
        self.timing = _Timing(self.bus, read_wait, write_wait)
        self._init_monitor()
        self.log.info("Avalon-MM monitor on '%s*', %s; %s", prefix, self.timing.describe(), self.bus.describe())
        self._task = cocotb.start_soon(self._run())

    def _sample(self) -> Tuple[bool, bool, bool, bool, int, int, int, bool, bool]:
        """The pins as the next rising edge samples them: reset,
        chipselect, read, write, address, writedata, readdata, waitrequest,
        readdatavalid."""
        b = self.bus
        return (
            self.reset is not None and level(self.reset),
            level(b.chipselect), level(b.read), level(b.write),
            value(b.address), value(b.writedata), value(b.readdata),
            b.waitrequest is not None and level(b.waitrequest),
            b.readdatavalid is not None and level(b.readdatavalid),
        )

    async def _run(self) -> None:
        t = self.timing
        # The access in flight: [write, addr, data, cycles, waiting for readdatavalid].
        cur: Optional[List[Any]] = None
        edge = None
        while True:
            await FallingEdge(self.clock)
            if edge is not None:
                cur = self._edge(edge, cur, t)
            await ReadOnly()
            edge = self._sample()

    def _edge(self, e: Tuple[bool, bool, bool, bool, int, int, int, bool, bool],
              cur: Optional[List[Any]], t: "_Timing") -> Optional[List[Any]]:
        """One rising edge, from the pins it sampled; the access still in flight."""
        reset, cs, rd, wr, addr, wdata, rdata, waitrequest, rdvalid = e
        if reset:
            return None
        if cur is not None and cur[4]:
            cur[3] += 1
            if rdvalid:
                self._emit(AvalonAccess(False, cur[1], rdata, False, cur[3]))
                return None
            return cur  # one read outstanding: nothing new until its data
        if cur is None and cs and (rd or wr):
            cur = [wr, addr, wdata if wr else 0, 0, False]
            self._emit(AvalonAccess(wr, addr, cur[2], True, 0))
        if cur is not None:
            cur[3] += 1
            if t.accepted(waitrequest, cur[0], cur[3]):
                if cur[0]:
                    self._emit(AvalonAccess(True, cur[1], cur[2], False, cur[3]))
                    return None
                if t.pipelined:
                    cur[4] = True
                    return cur
                self._emit(AvalonAccess(False, cur[1], rdata, False, cur[3]))
                return None
        return cur
