"""AXI4-Lite host bus (32-bit data, one register per ``stride`` bytes in
byte lane ``byte_lane``): a master that drives it and a monitor that
watches it, as separate roles.

Both bind ``dut.<prefix>{awvalid, awready, awaddr, wvalid, wready, wdata,
bvalid, bready, arvalid, arready, araddr, rvalid, rready, rdata}`` and,
when the interface has them, ``awprot``, ``wstrb``, ``bresp``, ``arprot``
and ``rresp``; the clock and the active-low reset are
``dut.<prefix>aclk`` and ``dut.<prefix>aresetn`` unless named (or given
as handles). Register ``n`` sits at byte address ``n * stride`` and its
byte in lane ``byte_lane`` of the data bus (the profile's
``[access.axi4-lite]`` layout; ``can_axi4lite``: stride 4, lane 0).

Both agents act on falling edges of the clock and judge a rising edge by
the pins as they settle after the falling edge before it (``ReadOnly``),
which is what that edge samples.
"""

import logging
from typing import Any, Callable, Dict, NamedTuple, Optional, Union

import cocotb
from cocotb.triggers import FallingEdge, ReadOnly

from ._monitor import AccessMonitor
from ._signals import bind, level, value


class Axi4LiteAccess(NamedTuple):
    """One AXI4-Lite access as the monitor saw it. ``launch`` is True at
    the first clock edge with AWVALID and WVALID presented (a write) or
    ARVALID (a read), ``data`` = the write byte, 0 for a read; False at
    its response (B or R handshake), ``data`` = the read byte or the write
    byte, ``resp`` = BRESP/RRESP. ``addr`` is the register number (byte
    address / stride); ``cycles``: host cycles from the launch."""

    write: bool
    addr: int
    data: int
    launch: bool
    cycles: int = 0
    resp: int = 0


_REQUIRED = ("awvalid", "awready", "awaddr", "wvalid", "wready", "wdata", "bvalid", "bready",
             "arvalid", "arready", "araddr", "rvalid", "rready", "rdata")
_OPTIONAL = ("awprot", "wstrb", "bresp", "arprot", "rresp")
RESP = ("OKAY", "EXOKAY", "SLVERR", "DECERR")


class Axi4LiteBus:
    """The pins of one AXI4-Lite slave interface, bound by name:
    ``dut.<prefix><name>``; optional signals are None when absent."""

    def __init__(self, dut: Any, prefix: str = "s_axi_") -> None:
        self.prefix = prefix
        for s in _REQUIRED:
            setattr(self, s, bind(dut, prefix, s))
        for s in _OPTIONAL:
            setattr(self, s, getattr(dut, prefix + s, None))

    def describe(self) -> str:
        missing = [s for s in _OPTIONAL if getattr(self, s) is None]
        return f"lacks {', '.join(missing)}" if missing else "all optional signals"


def _handle(dut: Any, prefix: str, sig: Union[str, Any, None]) -> Any:
    """A clock or reset given by name (``dut.<prefix><name>``, else
    ``dut.<name>``) or as a handle."""
    if sig is None or not isinstance(sig, str):
        return sig
    h = getattr(dut, prefix + sig, None)
    return h if h is not None else bind(dut, "", sig)


def _layout(stride: int, byte_lane: int) -> None:
    if stride not in (1, 2, 4) or not 0 <= byte_lane < 4:
        raise ValueError(f"stride {stride}, byte lane {byte_lane}: stride is 1, 2 or 4, the lane 0 to 3")


class Axi4LiteMaster:
    """Drives an AXI4-Lite slave: ``await write(reg, data)``, ``await
    read(reg)`` at register numbers; one access at a time, given up after
    ``timeout`` host cycles (:class:`TimeoutError`). AWVALID and WVALID rise
    together on a falling edge and each falls after its own handshake;
    BREADY and RREADY stay high. An error response (SLVERR, DECERR) raises
    :class:`IOError`."""

    def __init__(
        self,
        dut: Any,
        prefix: str = "s_axi_",
        *,
        clock: Union[str, Any] = "aclk",
        stride: int = 4,
        byte_lane: int = 0,
        timeout: int = 10_000,
    ) -> None:
        _layout(stride, byte_lane)
        self.log = logging.getLogger(f"cocotb.{dut._name}.aximaster")
        self.bus = Axi4LiteBus(dut, prefix)
        self.clock = _handle(dut, prefix, clock)
        self.stride, self.lane = stride, byte_lane
        self.timeout = timeout
        b = self.bus
        for s in (b.awvalid, b.awaddr, b.wvalid, b.wdata, b.arvalid, b.araddr, b.awprot, b.arprot, b.wstrb):
            if s is not None:
                s.value = 0
        b.bready.value, b.rready.value = 1, 1
        self.log.info("AXI4-Lite master on '%s*', register n at byte n*%d, lane %d; %s",
                      prefix, stride, byte_lane, b.describe())

    async def _wait(self, what: str, sample: Callable[[], Optional[Any]]) -> Any:
        """Waits for the rising edge at which ``sample()`` (on the pins
        that edge samples) is not None; returns it at the falling edge
        after that edge."""
        for _ in range(self.timeout):
            await ReadOnly()
            got = sample()
            await FallingEdge(self.clock)
            if got is not None:
                return got
        raise TimeoutError(f"AXI4-Lite {what}: no handshake in {self.timeout} cycles")

    def _resp(self, sig: Any) -> int:
        return value(sig) if sig is not None else 0

    async def write(self, reg: int, data: int) -> None:
        """One write; returns at its B handshake."""
        b = self.bus
        what = f"write of register {reg}"
        await FallingEdge(self.clock)
        b.awaddr.value, b.wdata.value = reg * self.stride, (data & 0xFF) << (8 * self.lane)
        if b.wstrb is not None:
            b.wstrb.value = 1 << self.lane
        b.awvalid.value, b.wvalid.value = 1, 1
        aw_done = w_done = False
        for _ in range(self.timeout):
            await ReadOnly()
            aw = not aw_done and level(b.awready)
            w = not w_done and level(b.wready)
            await FallingEdge(self.clock)
            if aw:
                aw_done, b.awvalid.value = True, 0
            if w:
                w_done, b.wvalid.value = True, 0
            if aw_done and w_done:
                break
        else:
            b.awvalid.value, b.wvalid.value = 0, 0
            raise TimeoutError(f"AXI4-Lite {what}: AW or W not accepted in {self.timeout} cycles")
        resp = await self._wait(what, lambda: self._resp(b.bresp) if level(b.bvalid) else None)
        if resp >= 2:
            raise IOError(f"AXI4-Lite {what}: answered {RESP[resp]}")

    async def read(self, reg: int) -> int:
        """One read; the register's byte at its R handshake."""
        b = self.bus
        what = f"read of register {reg}"
        await FallingEdge(self.clock)
        b.araddr.value, b.arvalid.value = reg * self.stride, 1
        try:
            await self._wait(what, lambda: True if level(b.arready) else None)
        finally:
            b.arvalid.value = 0
        data, resp = await self._wait(
            what, lambda: (value(b.rdata), self._resp(b.rresp)) if level(b.rvalid) else None)
        if resp >= 2:
            raise IOError(f"AXI4-Lite {what}: answered {RESP[resp]}")
        return (data >> (8 * self.lane)) & 0xFF


# Per channel: its VALID, READY and the payload that must hold while VALID waits.
_CHANNELS = (
    ("AW", "awvalid", "awready", ("awaddr", "awprot"), "master"),
    ("W", "wvalid", "wready", ("wdata", "wstrb"), "master"),
    ("B", "bvalid", "bready", ("bresp",), "slave"),
    ("AR", "arvalid", "arready", ("araddr", "arprot"), "master"),
    ("R", "rvalid", "rready", ("rdata", "rresp"), "slave"),
)


class Axi4LiteMonitor(AccessMonitor):
    """Watches an AXI4-Lite slave interface and calls each callback with
    an :class:`Axi4LiteAccess` at the launch and at the response of every
    access (one write and one read in flight at a time); ``await recv()``
    gives completed accesses in order. It drives nothing.

    It also checks the handshake rules it can see on every channel: a
    VALID must stay high, and its payload unchanged, until the edge of its
    READY. A violation is a :class:`ProtocolViolation` raised from the
    monitor's task (which fails the running test), or with
    ``strict=False`` a log error; either way its sentence is kept in
    :attr:`violations`. While the reset (active low) is asserted nothing
    is launched and accesses in flight are dropped."""

    #: The host bus's name, for the scoreboard (the profile's ``[access.axi4-lite]``).
    host_bus = "axi4-lite"
    protocol = "AXI4-Lite"

    def __init__(
        self,
        dut: Any,
        prefix: str = "s_axi_",
        *,
        clock: Union[str, Any] = "aclk",
        reset: Union[str, Any, None] = "aresetn",
        reset_active_low: bool = True,
        stride: int = 4,
        byte_lane: int = 0,
        strict: bool = True,
    ) -> None:
        _layout(stride, byte_lane)
        self.log = logging.getLogger(f"cocotb.{dut._name}.aximonitor")
        self.bus = Axi4LiteBus(dut, prefix)
        self.clock = _handle(dut, prefix, clock)
        self.reset = _handle(dut, prefix, reset)
        self.reset_active_low = reset_active_low
        self.stride, self.lane = stride, byte_lane
        self._init_monitor(strict)
        self.log.info("AXI4-Lite monitor on '%s*', register n at byte n*%d, lane %d; %s",
                      prefix, stride, byte_lane, self.bus.describe())
        self._task = cocotb.start_soon(self._run())

    def _sample(self) -> Dict[str, int]:
        """The pins as the next rising edge samples them (absent ones 0)."""
        b = self.bus
        pins = {s: value(getattr(b, s)) for s in _REQUIRED}
        pins.update({s: value(getattr(b, s)) if getattr(b, s) is not None else 0 for s in _OPTIONAL})
        pins["reset"] = int(self.reset is not None and level(self.reset) != self.reset_active_low)
        return pins

    def _byte(self, word: int) -> int:
        return (word >> (8 * self.lane)) & 0xFF

    async def _run(self) -> None:
        # Per channel, the payload of a VALID that waited for READY at the last edge.
        waiting: Dict[str, Optional[tuple]] = {c[0]: None for c in _CHANNELS}
        # The write in flight: presented AW address, W data, handshakes, launched, cycles.
        wr: Optional[Dict[str, Any]] = None
        # The read in flight: address, AR handshake, cycles.
        rd: Optional[Dict[str, Any]] = None
        edge = None
        while True:
            await FallingEdge(self.clock)
            if edge is not None:
                if edge["reset"]:
                    waiting = {c[0]: None for c in _CHANNELS}
                    wr = rd = None
                else:
                    self._check(edge, waiting)
                    wr = self._write(edge, wr)
                    rd = self._read(edge, rd)
            await ReadOnly()
            edge = self._sample()

    def _check(self, e: Dict[str, int], waiting: Dict[str, Optional[tuple]]) -> None:
        for name, v, r, payload, who in _CHANNELS:
            held = waiting[name]
            now = tuple(e[p] for p in payload)
            if held is not None:
                if not e[v]:
                    waiting[name] = None
                    self._violation(f"{name}VALID fell before {name}READY: the {who} withdrew a transfer "
                                    f"(VALID must stay high until its handshake)")
                    continue
                if now != held:
                    waiting[name] = now
                    self._violation(f"the {name} payload ({', '.join(p.upper() for p in payload)}) changed "
                                    f"while {name}VALID waited for {name}READY")
                    continue
            waiting[name] = now if e[v] and not e[r] else None

    def _write(self, e: Dict[str, int], wr: Optional[Dict[str, Any]]) -> Optional[Dict[str, Any]]:
        if wr is None:
            if not (e["awvalid"] or e["wvalid"]):
                return None
            wr = {"addr": None, "data": None, "aw": False, "w": False, "launched": False, "cycles": 0}
        if wr["addr"] is None and e["awvalid"]:
            wr["addr"] = e["awaddr"] // self.stride
        if wr["data"] is None and e["wvalid"]:
            wr["data"] = self._byte(e["wdata"])
        if wr["launched"]:
            wr["cycles"] += 1
        elif wr["addr"] is not None and wr["data"] is not None:
            wr["launched"], wr["cycles"] = True, 1
            self._emit(Axi4LiteAccess(True, wr["addr"], wr["data"], True, 0))
        wr["aw"] = wr["aw"] or bool(e["awvalid"] and e["awready"])
        wr["w"] = wr["w"] or bool(e["wvalid"] and e["wready"])
        if wr["aw"] and wr["w"] and e["bvalid"] and e["bready"]:
            self._emit(Axi4LiteAccess(True, wr["addr"], wr["data"], False, wr["cycles"], e["bresp"]))
            return None
        return wr

    def _read(self, e: Dict[str, int], rd: Optional[Dict[str, Any]]) -> Optional[Dict[str, Any]]:
        if rd is None:
            if not e["arvalid"]:
                return None
            rd = {"addr": e["araddr"] // self.stride, "ar": False, "cycles": 0}
            self._emit(Axi4LiteAccess(False, rd["addr"], 0, True, 0))
        rd["cycles"] += 1
        rd["ar"] = rd["ar"] or bool(e["arvalid"] and e["arready"])
        if rd["ar"] and e["rvalid"] and e["rready"]:
            self._emit(Axi4LiteAccess(False, rd["addr"], self._byte(e["rdata"]), False, rd["cycles"], e["rresp"]))
            return None
        return rd
