"""APB host bus (APB3, or APB4 with PSTRB and PPROT; 32-bit data, one
register per ``stride`` bytes in byte lane ``byte_lane``): a master that
drives it and a monitor that watches it, as separate roles.

Both bind ``dut.<prefix>{psel, penable, pwrite, paddr, pwdata, prdata}``
and, when the interface has them, ``pready`` (without it every access
phase lasts one cycle), ``pslverr``, ``pstrb`` and ``pprot``; the clock and
the active-low reset are ``dut.<prefix>pclk`` and ``dut.<prefix>presetn``
unless named (or given as handles). Register ``n`` sits at byte address
``n * stride`` and its byte in lane ``byte_lane`` of the data bus (the
profile's ``[access.apb]`` layout; ``can_apb``: stride 4, lane 0).

Both agents act on falling edges of the clock and judge a rising edge by
the pins as they settle after the falling edge before it (``ReadOnly``),
which is what that edge samples.
"""

import logging
from typing import Any, Dict, NamedTuple, Optional, Union

import cocotb
from cocotb.triggers import FallingEdge, ReadOnly

from ._monitor import AccessMonitor
from ._signals import bind, level, value
from .axi4lite import _handle, _layout


class ApbAccess(NamedTuple):
    """One APB access as the monitor saw it. ``launch`` is True at the
    first clock edge of its access phase (PSEL and PENABLE), ``data`` = the
    write byte, 0 for a read; False at the edge with PREADY, ``data`` = the
    read byte or the write byte, ``slverr`` = PSLVERR then. ``addr`` is the
    register number (byte address / stride); ``cycles``: host cycles of the
    access phase."""

    write: bool
    addr: int
    data: int
    launch: bool
    cycles: int = 0
    slverr: bool = False


_REQUIRED = ("psel", "penable", "pwrite", "paddr", "pwdata", "prdata")
_OPTIONAL = ("pready", "pslverr", "pstrb", "pprot")


class ApbBus:
    """The pins of one APB completer, bound by name: ``dut.<prefix><name>``;
    optional signals are None when absent."""

    def __init__(self, dut: Any, prefix: str = "") -> None:
        self.prefix = prefix
        for s in _REQUIRED:
            setattr(self, s, bind(dut, prefix, s))
        for s in _OPTIONAL:
            setattr(self, s, getattr(dut, prefix + s, None))
        self.apb4 = self.pstrb is not None or self.pprot is not None

    def describe(self) -> str:
        have = [s for s in _OPTIONAL if getattr(self, s) is not None]
        return f"{'APB4' if self.apb4 else 'APB3'}, has {', '.join(have) or 'none of pready, pslverr, pstrb, pprot'}"


class ApbMaster:
    """Drives an APB completer: ``await write(reg, data)``, ``await
    read(reg)`` at register numbers; one access at a time (a setup phase,
    then the access phase until PREADY), given up after ``timeout`` host
    cycles (:class:`TimeoutError`). PSTRB (APB4) has the byte lane's bit on
    writes, none on reads; PPROT is ``pprot``. PSLVERR raises
    :class:`IOError`."""

    def __init__(
        self,
        dut: Any,
        prefix: str = "",
        *,
        clock: Union[str, Any] = "pclk",
        stride: int = 4,
        byte_lane: int = 0,
        pprot: int = 0,
        timeout: int = 10_000,
    ) -> None:
        _layout(stride, byte_lane)
        self.log = logging.getLogger(f"cocotb.{dut._name}.apbmaster")
        self.bus = ApbBus(dut, prefix)
        self.clock = _handle(dut, prefix, clock)
        self.stride, self.lane, self.pprot = stride, byte_lane, pprot
        self.timeout = timeout
        self._idle()
        self.log.info("APB master on '%s*', register n at byte n*%d, lane %d; %s",
                      prefix, stride, byte_lane, self.bus.describe())

    def _idle(self) -> None:
        b = self.bus
        for s in (b.psel, b.penable, b.pwrite, b.paddr, b.pwdata, b.pstrb, b.pprot):
            if s is not None:
                s.value = 0

    async def _access(self, write: bool, reg: int, data: int) -> int:
        b = self.bus
        await FallingEdge(self.clock)  # setup phase
        b.psel.value, b.penable.value, b.pwrite.value = 1, 0, int(write)
        b.paddr.value = reg * self.stride
        b.pwdata.value = (data & 0xFF) << (8 * self.lane) if write else 0
        if b.pstrb is not None:
            b.pstrb.value = (1 << self.lane) if write else 0
        if b.pprot is not None:
            b.pprot.value = self.pprot
        await FallingEdge(self.clock)  # access phase
        b.penable.value = 1
        for _ in range(self.timeout):
            await ReadOnly()
            ready = b.pready is None or level(b.pready)
            got = value(b.prdata)
            err = b.pslverr is not None and level(b.pslverr)
            await FallingEdge(self.clock)
            if ready:
                break
        else:
            self._idle()
            raise TimeoutError(f"APB {'write' if write else 'read'} of register {reg}: "
                               f"no PREADY in {self.timeout} cycles")
        b.psel.value, b.penable.value = 0, 0
        if err:
            raise IOError(f"APB {'write' if write else 'read'} of register {reg}: PSLVERR")
        return (got >> (8 * self.lane)) & 0xFF

    async def write(self, reg: int, data: int) -> None:
        """One write; returns after the edge with PREADY."""
        await self._access(True, reg, data)

    async def read(self, reg: int) -> int:
        """One read; the register's byte."""
        return await self._access(False, reg, 0)


class ApbMonitor(AccessMonitor):
    """Watches an APB completer and calls each callback with an
    :class:`ApbAccess` at the launch and at the completion of every
    access; ``await recv()`` gives completed accesses in order. It drives
    nothing.

    It also checks the phase rules: PENABLE only after a setup phase (PSEL
    without PENABLE), the access phase right after the setup phase, PSEL and
    PENABLE held until PREADY, the address, direction, write data (and
    APB4's PSTRB and PPROT) unchanged from the setup phase to PREADY, no
    PSTRB bit on an APB4 read. A violation is a
    :class:`ProtocolViolation` raised from the monitor's task (which fails
    the running test), or with ``strict=False`` a log error; either way its
    sentence is kept in :attr:`violations`. An access phase without a
    setup phase is still reported as an access (the completer acts on it).
    While the reset (active low) is asserted nothing is launched and an
    access in flight is dropped."""

    #: The host bus's name, for the scoreboard (the profile's ``[access.apb]``).
    host_bus = "apb"
    protocol = "APB"

    def __init__(
        self,
        dut: Any,
        prefix: str = "",
        *,
        clock: Union[str, Any] = "pclk",
        reset: Union[str, Any, None] = "presetn",
        reset_active_low: bool = True,
        stride: int = 4,
        byte_lane: int = 0,
        strict: bool = True,
    ) -> None:
        _layout(stride, byte_lane)
        self.log = logging.getLogger(f"cocotb.{dut._name}.apbmonitor")
        self.bus = ApbBus(dut, prefix)
        self.clock = _handle(dut, prefix, clock)
        self.reset = _handle(dut, prefix, reset)
        self.reset_active_low = reset_active_low
        self.stride, self.lane = stride, byte_lane
        self._init_monitor(strict)
        self.log.info("APB monitor on '%s*', register n at byte n*%d, lane %d; %s",
                      prefix, stride, byte_lane, self.bus.describe())
        self._task = cocotb.start_soon(self._run())

    def _sample(self) -> Dict[str, int]:
        """The pins as the next rising edge samples them (absent PREADY: 1)."""
        b = self.bus
        pins = {s: value(getattr(b, s)) for s in _REQUIRED}
        pins.update({s: value(getattr(b, s)) if getattr(b, s) is not None else 0 for s in _OPTIONAL})
        if b.pready is None:
            pins["pready"] = 1
        pins["reset"] = int(self.reset is not None and level(self.reset) != self.reset_active_low)
        return pins

    @staticmethod
    def _control(e: Dict[str, int]) -> tuple:
        """What must hold from the setup phase to PREADY."""
        return (e["paddr"], e["pwrite"], e["pwdata"] if e["pwrite"] else 0, e["pstrb"], e["pprot"])

    async def _run(self) -> None:
        # "idle", "setup" (the last edge was a setup phase) or "access" (waiting for PREADY).
        state = "idle"
        held: Optional[tuple] = None
        cur: Optional[ApbAccess] = None
        edge = None
        while True:
            await FallingEdge(self.clock)
            if edge is not None:
                if edge["reset"]:
                    state, held, cur = "idle", None, None
                else:
                    state, held, cur = self._edge(edge, state, held, cur)
            await ReadOnly()
            edge = self._sample()

    def _edge(self, e: Dict[str, int], state: str, held: Optional[tuple],
              cur: Optional[ApbAccess]) -> tuple:
        """One rising edge, from the pins it sampled: the next state."""
        sel, en = e["psel"], e["penable"]
        ctl = self._control(e)
        if self.bus.apb4 and sel and not e["pwrite"] and e["pstrb"]:
            self._violation(f"PSTRB=0x{e['pstrb']:X} on a read (APB4: all low on reads)")
        if state == "access" and cur is not None:
            if not (sel and en):
                self._violation("PSEL or PENABLE fell before PREADY: the requester abandoned the transfer")
                state, cur = "idle", None
            else:
                if ctl != held:
                    self._violation("PADDR, PWRITE, PWDATA, PSTRB or PPROT changed in the access phase before PREADY")
                    held = ctl
                cur = cur._replace(cycles=cur.cycles + 1)
                return self._ready(e, cur, held)
        if sel and en:
            if state == "setup" and ctl != held:
                self._violation("PADDR, PWRITE, PWDATA, PSTRB or PPROT changed between the setup and the access phase")
            elif state != "setup":
                self._violation("PENABLE high without a setup phase (PSEL and PENABLE rose together)")
            write = bool(e["pwrite"])
            cur = ApbAccess(write, e["paddr"] // self.stride,
                            (e["pwdata"] >> (8 * self.lane)) & 0xFF if write else 0, True, 1)
            self._emit(cur)
            return self._ready(e, cur, ctl)
        if en:
            self._violation("PENABLE high without PSEL")
        elif state == "setup" and not sel:
            self._violation("the setup phase was not followed by an access phase (PSEL fell with PENABLE low)")
        if sel and not en:
            if state == "setup":
                self._violation("a second setup phase in a row: PENABLE did not rise after the setup phase")
            return "setup", ctl, None
        return "idle", None, None

    def _ready(self, e: Dict[str, int], cur: ApbAccess, held: tuple) -> tuple:
        if not e["pready"]:
            return "access", held, cur
        data = cur.data if cur.write else (e["prdata"] >> (8 * self.lane)) & 0xFF
        self._emit(cur._replace(data=data, launch=False, slverr=bool(e["pslverr"])))
        return "idle", None, None
