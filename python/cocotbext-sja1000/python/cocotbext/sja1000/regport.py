"""Plain register port, as forks of the core expose it: one-clock (or
``strobe``-clock) write and read strobes, one address for both or a write
and a read address, write data in, and read data out, valid ``read_latency``
clocks after the read strobe (0 = combinational, in the strobe's own
clock), with no acknowledge: the host times everything. A master that
drives it and a monitor that watches it, as separate roles.

Pins are bound by role, as the profile's ``[ports.regport]`` names them:
``wr``, ``rd``, ``adr`` (one address) or ``wr-adr`` and ``rd-adr``,
``wdat``, ``rdat``; each is ``dut.<prefix><name>``, the name our
``can_regport``'s (``wr_i``, ``rd_i``, ``adr_i``, ``wr_adr_i``,
``rd_adr_i``, ``wdat_i``, ``rdat_o``) unless ``names`` gives another. The
clock and the active-high reset are ``clk_i`` and ``rst_i`` unless named
(or given as handles). The defaults (strobe 1, read latency 14, 14 idle
clocks after each access, separate addresses) are the profile's
``[access.regport]`` defaults, ``bfm::RegportConfig::default()``: our
``can_regport`` measured (its data comes 10 clocks after the strobe, 14 for
the first access after reset).

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
from .axi4lite import _handle


class RegportAccess(NamedTuple):
    """One register-port access as the monitor saw it. ``launch`` is True
    at the first clock of its strobe, ``data`` = the write byte, 0 for a
    read; False at its completion: a read ``read_latency`` clocks after the
    strobe, ``data`` = the read byte; a write at the end of its strobe,
    ``data`` = the write byte. ``cycles``: clocks from the strobe."""

    write: bool
    addr: int
    data: int
    launch: bool
    cycles: int = 0


#: Role -> our ``can_regport``'s port (the profile's ``[ports.regport]`` roles).
PORTS = {"wr": "wr_i", "rd": "rd_i", "adr": "adr_i", "wr-adr": "wr_adr_i",
         "rd-adr": "rd_adr_i", "wdat": "wdat_i", "rdat": "rdat_o"}


class RegportBus:
    """The pins of one register port, bound by role (see the module's
    docs). ``addresses``: ``"one"`` (the ``adr`` port), ``"separate"``
    (``wr-adr`` and ``rd-adr``), or None: one when the port has ``adr``,
    else separate (as the profile's ``addresses`` key)."""

    def __init__(self, dut: Any, prefix: str = "", *, names: Optional[Dict[str, str]] = None,
                 addresses: Optional[str] = None) -> None:
        unknown = set(names or {}) - set(PORTS)
        if unknown:
            raise ValueError(f"register port roles {sorted(unknown)}: the roles are {', '.join(PORTS)}")
        self.names = {**PORTS, **(names or {})}
        self.prefix = prefix
        if addresses is None:
            addresses = "one" if getattr(dut, prefix + self.names["adr"], None) is not None else "separate"
        if addresses not in ("one", "separate"):
            raise ValueError(f"addresses {addresses!r}: \"one\" or \"separate\"")
        self.one_address = addresses == "one"
        roles = ["wr", "rd", "wdat", "rdat"] + (["adr"] if self.one_address else ["wr-adr", "rd-adr"])
        for r in roles:
            setattr(self, r.replace("-", "_"), bind(dut, prefix, self.names[r]))
        if self.one_address:
            self.wr_adr = self.rd_adr = self.adr
        else:
            self.adr = None

    def describe(self) -> str:
        return "one address" if self.one_address else "separate read and write addresses"


def _config(strobe: int, read_latency: int, gap: int) -> None:
    if not 1 <= strobe <= 64 or not 0 <= read_latency <= 256 or not 0 <= gap <= 256:
        raise ValueError(f"strobe {strobe}, read latency {read_latency}, gap {gap}: "
                         "strobe 1 to 64 clocks, read latency and gap 0 to 256")


class RegportMaster:
    """Drives a register port: ``await write(reg, data)``, ``await
    read(reg)``; one access at a time: the strobe for ``strobe`` clocks,
    a read's data taken ``read_latency`` clocks after its strobe, then
    ``gap`` idle clocks (the port has no acknowledge: a write completes
    meanwhile). With separate addresses the other address keeps its
    value."""

    def __init__(
        self,
        dut: Any,
        prefix: str = "",
        *,
        clock: Union[str, Any] = "clk_i",
        names: Optional[Dict[str, str]] = None,
        addresses: Optional[str] = None,
        strobe: int = 1,
        read_latency: int = 14,
        gap: int = 14,
    ) -> None:
        _config(strobe, read_latency, gap)
        self.log = logging.getLogger(f"cocotb.{dut._name}.regportmaster")
        self.bus = RegportBus(dut, prefix, names=names, addresses=addresses)
        self.clock = _handle(dut, prefix, clock)
        self.strobe, self.read_latency, self.gap = strobe, read_latency, gap
        b = self.bus
        for s in (b.wr, b.rd, b.wr_adr, b.rd_adr, b.wdat):
            s.value = 0
        self.log.info("register-port master on '%s*', strobe %d clock(s), read data %d clocks after "
                      "the strobe, %d idle clocks; %s", prefix, strobe, read_latency, gap, b.describe())

    async def _access(self, write: bool, reg: int, data: int) -> int:
        b = self.bus
        await FallingEdge(self.clock)
        if write:
            b.wr_adr.value, b.wdat.value, b.wr.value = reg, data & 0xFF, 1
        else:
            b.rd_adr.value, b.rd.value = reg, 1
        busy = self.strobe if write else max(self.strobe, self.read_latency + 1)
        got = 0
        for k in range(busy + self.gap):
            if k == self.strobe:
                b.wr.value, b.rd.value = 0, 0
            if not write and k == self.read_latency:
                await ReadOnly()  # the data of clock k, as the edge ending it samples it
                got = value(b.rdat)
            await FallingEdge(self.clock)
        b.wr.value, b.rd.value = 0, 0
        return got

    async def write(self, reg: int, data: int) -> None:
        """One write; returns after its strobe and the idle clocks."""
        await self._access(True, reg, data)

    async def read(self, reg: int) -> int:
        """One read; the byte on ``rdat`` ``read_latency`` clocks after the strobe."""
        return await self._access(False, reg, 0)


class RegportMonitor(AccessMonitor):
    """Watches a register port and calls each callback with a
    :class:`RegportAccess` at the launch and at the completion of every
    access; ``await recv()`` gives completed accesses in order. It drives
    nothing. A read completes ``read_latency`` clocks after its strobe with
    the byte on ``rdat`` then, which is what the scoreboard compares.

    It also checks the port's rules: never a read and a write strobe in the
    same clock, each strobe exactly ``strobe`` clocks, the address (and a
    write's data) unchanged while a strobe is held, no new strobe before a
    read's data is due, and the read data steady from the clock it is due
    until the next strobe (data that comes later than ``read_latency`` is
    named there). A violation is a :class:`ProtocolViolation` raised from
    the monitor's task, or with ``strict=False`` a log error; its sentence
    is kept in :attr:`violations`. While the reset (active high) is
    asserted nothing is launched and an access in flight is dropped."""

    #: The host bus's name, for the scoreboard (the profile's ``[access.regport]``).
    host_bus = "regport"
    protocol = "register port"

    def __init__(
        self,
        dut: Any,
        prefix: str = "",
        *,
        clock: Union[str, Any] = "clk_i",
        reset: Union[str, Any, None] = "rst_i",
        reset_active_low: bool = False,
        names: Optional[Dict[str, str]] = None,
        addresses: Optional[str] = None,
        strobe: int = 1,
        read_latency: int = 14,
        strict: bool = True,
    ) -> None:
        _config(strobe, read_latency, 0)
        self.log = logging.getLogger(f"cocotb.{dut._name}.regportmonitor")
        self.bus = RegportBus(dut, prefix, names=names, addresses=addresses)
        self.clock = _handle(dut, prefix, clock)
        self.reset = _handle(dut, prefix, reset)
        self.reset_active_low = reset_active_low
        self.strobe, self.read_latency = strobe, read_latency
        self._init_monitor(strict)
        self.log.info("register-port monitor on '%s*', strobe %d clock(s), read data %d clocks after "
                      "the strobe; %s", prefix, strobe, read_latency, self.bus.describe())
        self._task = cocotb.start_soon(self._run())

    def _sample(self) -> Dict[str, int]:
        b = self.bus
        e = {"wr": int(level(b.wr)), "rd": int(level(b.rd)), "wr_adr": value(b.wr_adr),
             "rd_adr": value(b.rd_adr), "wdat": value(b.wdat), "rdat": value(b.rdat)}
        e["reset"] = int(self.reset is not None and level(self.reset) != self.reset_active_low)
        return e

    async def _run(self) -> None:
        self._clear()
        edge = None
        while True:
            await FallingEdge(self.clock)
            if edge is not None:
                if edge["reset"]:
                    self._clear()
                else:
                    self._clock(edge)
            await ReadOnly()
            edge = self._sample()

    def _clear(self) -> None:
        # Clocks each strobe has been high, and what it presented first.
        self._run_len = {"wr": 0, "rd": 0}
        self._held: Dict[str, tuple] = {}
        self._write: Optional[RegportAccess] = None
        # The read in flight: its access, clocks since its strobe, and the
        # data once due (watched until the next strobe).
        self._read: Optional[RegportAccess] = None
        self._since_rd = 0
        self._due: Optional[int] = None

    def _clock(self, e: Dict[str, int]) -> None:
        """One rising edge, from the pins it sampled."""
        if e["rd"] and e["wr"]:
            self._violation("read and write strobes high in the same clock")
        for s, what in (("wr", "write"), ("rd", "read")):
            run = self._run_len[s]
            if e[s]:
                held = (e["wr_adr"], e["wdat"]) if s == "wr" else (e["rd_adr"],)
                if run == 0:
                    self._start(s == "wr", e)
                    self._held[s] = held
                elif held != self._held[s]:
                    self._violation(f"the {'address or write data' if s == 'wr' else 'address'} changed "
                                    f"while the {what} strobe was held")
                    self._held[s] = held
                self._run_len[s] = run + 1
                if run + 1 == self.strobe + 1:
                    self._violation(f"{what} strobe held longer than {self.strobe} clock"
                                    f"{'s' if self.strobe != 1 else ''} (the configured strobe)")
            elif run:
                if run < self.strobe:
                    self._violation(f"{what} strobe high {run} clock{'s' if run != 1 else ''}, "
                                    f"shorter than the configured {self.strobe}")
                self._run_len[s] = 0
                if s == "wr" and self._write is not None:
                    self._emit(self._write._replace(launch=False, cycles=run))
                    self._write = None
        self._read_data(e)

    def _start(self, write: bool, e: Dict[str, int]) -> None:
        if self._read is not None and self._due is None:
            self._violation(f"a {'write' if write else 'read'} strobe {self._since_rd} clock"
                            f"{'s' if self._since_rd != 1 else ''} after the read strobe of register "
                            f"{self._read.addr}, before its data is due (read latency {self.read_latency})")
        self._read, self._due = None, None
        if write:
            self._write = RegportAccess(True, e["wr_adr"], e["wdat"], True)
            self._emit(self._write)
        else:
            self._read = RegportAccess(False, e["rd_adr"], 0, True)
            self._since_rd = 0
            self._emit(self._read)

    def _read_data(self, e: Dict[str, int]) -> None:
        r = self._read
        if r is None:
            return
        if self._since_rd == self.read_latency:
            self._due = e["rdat"]
            self._emit(r._replace(data=e["rdat"], launch=False, cycles=self._since_rd))
        elif self._due is not None and e["rdat"] != self._due:
            self._violation(f"read data of register {r.addr} changed from 0x{self._due:02X} to "
                            f"0x{e['rdat']:02X} {self._since_rd} clocks after the strobe, later than "
                            f"its read latency of {self.read_latency}")
            self._due = e["rdat"]
        self._since_rd += 1
