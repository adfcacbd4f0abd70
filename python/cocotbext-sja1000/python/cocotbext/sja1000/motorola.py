"""Motorola-mode multiplexed host bus, the SJA1000's other host mode (MODE
pin low), as 68xx and ColdFire-style hosts drive it: the register address
on the shared port (AD7..AD0) while AS is high, latched when AS falls,
then one E pulse with chip select moves the byte over the same port, its
direction given by R/W (high = read), set before E rises and held until
after E falls. A master that drives it and a monitor that watches it, as
separate roles.

The bus has no clock: the master times its phases in nanoseconds
(:class:`MotorolaTiming`) and the monitor judges the pins at each change.
Pins are bound by role, as the profile's ``[ports.motorola]`` names them:
``mode`` (optional: the MODE strap, driven low), ``as``, ``cs``, ``e``,
``rw``, ``ad-i`` (the port into the core), ``ad-o`` and ``ad-oe`` (the
core's read data and its output enable); each is ``dut.<prefix><name>``,
the name our ``can_top_mcu``'s (``mode_i``, ``ale_as_i``, ``cs_can_i``,
``rd_e_i``, ``wr_rw_i``, ``port_0_i``, ``port_0_o``, ``port_0_oe``)
unless ``names`` gives another. Pins are active high, as on
``can_top_mcu`` (the chip's /CS is low: put an inverter in front), and
the port is split: the master drives ``ad-i``, 0xFF (the pull-ups) when it
releases the port.
"""

import logging
from typing import Any, Dict, NamedTuple, Optional, Union

import cocotb
from cocotb.triggers import Event, ReadOnly, Timer

try:  # cocotb 2.x
    from cocotb.simtime import get_sim_time
except ImportError:  # cocotb 1.9
    from cocotb.utils import get_sim_time

from ._monitor import AccessMonitor
from ._signals import bind, changed, level, resolved, stop_task, value
from .axi4lite import _handle


class MotorolaTiming(NamedTuple):
    """Phase lengths of an access, nanoseconds: each a minimum the master
    holds and the monitor checks. The defaults are the kit's Rust Motorola
    BFM's (``bfm::MotorolaAcTiming::default()`` in
    ``crates/bfm/src/motorola.rs``), which are its 8051 defaults phase for
    phase (``bfm::I8051AcTiming``: one 12 MHz 80C51 ``MOVX`` cycle, E of a
    read stretched for ``can_top_8051``), not the data sheet's (its
    Motorola-mode AC table was not available): enter your host's here."""

    #: AS pulse width, the address driven meanwhile.
    as_ns: int = 120
    #: Address held on AD after AS falls.
    addr_hold_ns: int = 40
    #: Read: port released before E rises.
    read_float_ns: int = 160
    #: Write: data on AD (and R/W low) before E rises.
    data_setup_ns: int = 160
    #: E pulse width of a read (the master samples AD at its end).
    e_read_ns: int = 760
    #: E pulse width of a write.
    e_write_ns: int = 400
    #: Write: data, R/W and CS held after E falls.
    data_hold_ns: int = 40
    #: Idle time after an access (CS low, R/W high) before the next AS.
    recovery_ns: int = 260


class MotorolaAccess(NamedTuple):
    """One Motorola-mode access as the monitor saw it. ``launch`` is True
    when the core starts it (our ``can_top_mcu``: a read when E rises, a
    write when E falls), ``data`` = the write byte, 0 for a read; False when
    E falls, ``data`` = the read byte (as the core drove it in E) or the
    write byte. ``addr``: the address latched when AS fell; ``e_ns``: E's
    width."""

    write: bool
    addr: int
    data: int
    launch: bool
    e_ns: int = 0


#: Role -> our ``can_top_mcu``'s port (the profile's ``[ports.motorola]`` roles).
PORTS = {"mode": "mode_i", "as": "ale_as_i", "cs": "cs_can_i", "e": "rd_e_i", "rw": "wr_rw_i",
         "ad-i": "port_0_i", "ad-o": "port_0_o", "ad-oe": "port_0_oe"}
_ATTR = {"as": "as_", "ad-i": "ad_i", "ad-o": "ad_o", "ad-oe": "ad_oe"}


class MotorolaBus:
    """The pins of one Motorola-mode slave, bound by role (see the
    module's docs); ``mode`` is None when the top has no MODE strap."""

    def __init__(self, dut: Any, prefix: str = "", *, names: Optional[Dict[str, str]] = None) -> None:
        unknown = set(names or {}) - set(PORTS)
        if unknown:
            raise ValueError(f"Motorola bus roles {sorted(unknown)}: the roles are {', '.join(PORTS)}")
        self.names = {**PORTS, **(names or {})}
        self.prefix = prefix
        for r, n in self.names.items():
            a = _ATTR.get(r, r)
            setattr(self, a, getattr(dut, prefix + n, None) if r == "mode" else bind(dut, prefix, n))

    def describe(self) -> str:
        return "MODE strap driven low" if self.mode is not None else "no MODE strap (Motorola only)"


class MotorolaMaster:
    """Drives a Motorola-mode slave: ``await write(reg, data)``, ``await
    read(reg)``; one access at a time with the phases of ``timing``: AS
    with the address (R/W low from here for a write), the address hold, the
    port released (read) or the write data set up, E, then for a write the
    data hold, and the recovery with CS low. A read returns what the core
    drives on AD at the end of E (0xFF, the pull-ups, if it does not)."""

    def __init__(self, dut: Any, prefix: str = "", *, names: Optional[Dict[str, str]] = None,
                 timing: MotorolaTiming = MotorolaTiming()) -> None:
        self.log = logging.getLogger(f"cocotb.{dut._name}.motorolamaster")
        self.bus = MotorolaBus(dut, prefix, names=names)
        self.timing = timing
        b = self.bus
        if b.mode is not None:
            b.mode.value = 0
        b.as_.value, b.cs.value, b.e.value, b.rw.value, b.ad_i.value = 0, 0, 0, 1, 0xFF
        self.log.info("Motorola-mode master on '%s*', %s; %s", prefix, b.describe(),
                      ", ".join(f"{k} {v}" for k, v in timing._asdict().items()))

    async def _access(self, write: bool, reg: int, data: int) -> int:
        b, t = self.bus, self.timing
        b.as_.value, b.cs.value, b.rw.value, b.ad_i.value = 1, 1, 0 if write else 1, reg & 0xFF
        await Timer(t.as_ns, "ns")
        b.as_.value = 0
        await Timer(t.addr_hold_ns, "ns")
        b.ad_i.value = data & 0xFF if write else 0xFF
        await Timer(t.data_setup_ns if write else t.read_float_ns, "ns")
        b.e.value = 1
        await Timer(t.e_write_ns if write else t.e_read_ns, "ns")
        got = value(b.ad_o) if level(b.ad_oe) else 0xFF
        b.e.value = 0
        if write:
            await Timer(t.data_hold_ns, "ns")
        b.cs.value, b.rw.value, b.ad_i.value = 0, 1, 0xFF
        await Timer(t.recovery_ns, "ns")
        return got

    async def write(self, reg: int, data: int) -> None:
        """One write; returns after its recovery."""
        await self._access(True, reg, data)

    async def read(self, reg: int) -> int:
        """One read; the byte the core drove at the end of E."""
        return await self._access(False, reg, 0)


class MotorolaMonitor(AccessMonitor):
    """Watches a Motorola-mode slave at every change of its pins and calls
    each callback with a :class:`MotorolaAccess` at the launch and at the
    completion of every access (an E pulse with CS); ``await recv()`` gives
    completed accesses in order. It drives nothing.

    The launch is where the core counts the access from: a read when E
    rises, a write when E falls (our ``can_top_mcu``, the ``[access.i8051]``
    edges of ``rtl``); ``write_at_e_fall=False`` for a core that takes a
    write when E rises (a profile with ``[access.motorola]``).

    It also checks the bus's rules against ``timing`` (the master's
    minimums): the address driven when AS falls (it is latched then) and
    held ``addr_hold_ns`` after, AS and E at least their widths, AS never
    rising while E is high, CS steady while E is high, R/W set before E
    rises and steady while it is high, the write data set up before E and
    held after it (with CS), the recovery before the next AS, MODE low (if
    the top has it), and the core driving AD only in a read with CS, E and
    R/W high, and answering every read before E falls. A violation is a
    :class:`ProtocolViolation` raised from the monitor's task, or with
    ``strict=False`` a log error; its sentence is kept in
    :attr:`violations`. While the reset (active high) is asserted nothing
    is launched and an access in flight is dropped."""

    #: The host bus's name, for the scoreboard (the profile's
    #: ``[access.motorola]``, else the 8051 bus's timing).
    host_bus = "motorola"
    protocol = "Motorola bus"

    def __init__(
        self,
        dut: Any,
        prefix: str = "",
        *,
        names: Optional[Dict[str, str]] = None,
        reset: Union[str, Any, None] = "rst_i",
        reset_active_low: bool = False,
        timing: MotorolaTiming = MotorolaTiming(),
        write_at_e_fall: bool = True,
        strict: bool = True,
    ) -> None:
        self.log = logging.getLogger(f"cocotb.{dut._name}.motorolamonitor")
        self.bus = MotorolaBus(dut, prefix, names=names)
        self.reset = _handle(dut, prefix, reset)
        self.reset_active_low = reset_active_low
        self.timing = timing
        self.write_at_e_fall = write_at_e_fall
        self._init_monitor(strict)
        self._watchers: list = []
        self.log.info("Motorola-mode monitor on '%s*', %s, writes launched at E %s",
                      prefix, self.bus.describe(), "falling" if write_at_e_fall else "rising")
        self._task = cocotb.start_soon(self._run())

    def _pins(self):
        b = self.bus
        return [s for s in (b.mode, b.as_, b.cs, b.e, b.rw, b.ad_i, b.ad_o, b.ad_oe, self.reset) if s is not None]

    def _sample(self) -> Dict[str, int]:
        b = self.bus
        p = {"as": level(b.as_), "cs": level(b.cs), "e": level(b.e), "rw": level(b.rw),
             "ad": value(b.ad_i), "ad_ok": resolved(b.ad_i), "ado": value(b.ad_o), "oe": level(b.ad_oe),
             "mode": b.mode is not None and level(b.mode)}
        p["reset"] = self.reset is not None and level(self.reset) != self.reset_active_low
        return p

    async def _watch(self, sig: Any) -> None:
        while True:
            await changed(sig)
            self._changed.set()

    def stop(self) -> None:
        """Stops watching."""
        super().stop()
        for w in self._watchers:
            stop_task(w)

    async def _run(self) -> None:
        self._clear()
        # One watcher per pin, not First(): cocotb 2.1's First does not end
        # when its task is cancelled.
        self._changed = Event()
        self._watchers = [cocotb.start_soon(self._watch(s)) for s in self._pins()]
        await ReadOnly()
        self._changed.clear()
        prev = self._sample()
        while True:
            await self._changed.wait()
            await ReadOnly()
            self._changed.clear()  # nothing changes after ReadOnly in this step
            now = self._sample()
            if now["reset"]:
                self._clear()
            else:
                self._change(prev, now, round(get_sim_time("ps")))
            prev = now

    def _clear(self) -> None:
        self._addr = 0
        self._as_rise: Optional[int] = None
        self._as_fall: Optional[int] = None
        self._ad_change = 0
        # The access in E: (write, E rise ps); the read byte the core drove.
        self._cur: Optional[tuple] = None
        self._read: Optional[int] = None
        # The last E fall: (ps, write).
        self._e_fall: Optional[tuple] = None
        self._bad_oe = False

    def _change(self, p: Dict[str, Any], n: Dict[str, Any], t: int) -> None:
        tm = self.timing

        def short(since: Optional[int], ns: int) -> Optional[float]:
            """ns elapsed since ``since`` when shorter than ``ns``, else None."""
            return None if since is None or t - since >= ns * 1000 else (t - since) / 1000

        if n["as"] and not p["as"]:
            if n["e"]:
                self._violation("AS rose while E was high")
            if self._e_fall is not None and (d := short(self._e_fall[0], tm.recovery_ns)) is not None:
                self._violation(f"AS rose {d:g} ns after the last E fell (recovery {tm.recovery_ns} ns)")
            self._as_rise, self._as_fall = t, None
        elif p["as"] and not n["as"]:
            if (d := short(self._as_rise, tm.as_ns)) is not None:
                self._violation(f"AS high {d:g} ns (at least {tm.as_ns} ns)")
            if not p["ad_ok"]:
                self._violation("AD was not driven (X or Z) when AS fell: no address to latch")
            self._addr, self._as_fall = p["ad"], t  # the port as AS falls
        if n["ad"] != p["ad"] or n["ad_ok"] != p["ad_ok"]:
            if self._as_fall is not None and (d := short(self._as_fall, tm.addr_hold_ns)) is not None:
                self._violation(f"AD changed {d:g} ns after AS fell (address hold {tm.addr_hold_ns} ns)")
            if self._cur is not None and self._cur[0] and p["e"] and n["e"]:
                self._violation("the write data on AD changed while E was high")
            if self._e_fall is not None and self._e_fall[1] and (d := short(self._e_fall[0], tm.data_hold_ns)) is not None:
                self._violation(f"the write data on AD changed {d:g} ns after E fell (data hold {tm.data_hold_ns} ns)")
            self._ad_change = t
        if p["cs"] and not n["cs"] and self._e_fall is not None and self._e_fall[1] \
                and (d := short(self._e_fall[0], tm.data_hold_ns)) is not None:
            self._violation(f"CS fell {d:g} ns after a write's E fell (data hold {tm.data_hold_ns} ns)")
        if p["e"] and n["e"] and self._cur is not None:
            if n["cs"] != p["cs"]:
                self._violation(f"CS {'rose' if n['cs'] else 'fell'} while E was high")
            if n["rw"] != p["rw"]:
                self._violation(f"R/W changed to {'read (high)' if n['rw'] else 'write (low)'} while E was high")
        if n["e"] and not p["e"] and n["cs"]:
            self._e_rise(p, n, t)
        if self._cur is not None and p["e"] and not self._cur[0]:
            # Read data as the core drives it while E is high (its enable
            # falls with E, so the sample before E fell counts).
            if p["oe"]:
                self._read = p["ado"]
            if n["e"] and n["oe"]:
                self._read = n["ado"]
        if p["e"] and not n["e"] and self._cur is not None:
            self._e_end(p, t)
        bad = n["oe"] and not (n["cs"] and n["e"] and n["rw"])
        if bad and not self._bad_oe:
            self._violation("the core drove AD outside a read (CS, E and R/W high)")
        self._bad_oe = bad

    def _e_rise(self, p: Dict[str, Any], n: Dict[str, Any], t: int) -> None:
        tm = self.timing
        write = not n["rw"]
        if n["mode"]:
            self._violation("MODE is high (Intel mode): the core takes E as RD and R/W as WR")
        if n["rw"] != p["rw"]:
            self._violation("R/W changed as E rose (it must be set before E)")
        if write and t - self._ad_change < tm.data_setup_ns * 1000:
            self._violation(f"the write data was on AD {(t - self._ad_change) / 1000:g} ns before E rose "
                            f"(set-up {tm.data_setup_ns} ns)")
        self._cur, self._read = (write, t), None
        if not write or not self.write_at_e_fall:
            self._emit(MotorolaAccess(write, self._addr, n["ad"] if write else 0, True))

    def _e_end(self, p: Dict[str, Any], t: int) -> None:
        tm = self.timing
        write, rise = self._cur
        width = tm.e_write_ns if write else tm.e_read_ns
        e_ns = round((t - rise) / 1000)
        if t - rise < width * 1000:
            self._violation(f"E high {(t - rise) / 1000:g} ns in a {'write' if write else 'read'} "
                            f"(at least {width} ns)")
        if write:
            data = p["ad"]  # the port as E falls
            if self.write_at_e_fall:
                self._emit(MotorolaAccess(True, self._addr, data, True))
        elif self._read is None:
            self._violation(f"read of register {self._addr}: E high {e_ns} ns and the core never drove AD "
                            "(the master read the pull-ups, 0xFF)")
            data = 0xFF
        else:
            data = self._read
        self._emit(MotorolaAccess(write, self._addr, data, False, e_ns))
        self._cur, self._e_fall = None, (t, write)
