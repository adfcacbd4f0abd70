"""The golden SJA1000 shadowing a DUT: a scoreboard whose failure is the diagnosis."""

import logging
from pathlib import Path
from typing import Any, Callable, Optional, Protocol, Union

import cocotb
from cocotb.triggers import FallingEdge

try:  # cocotb 2.x
    from cocotb.simtime import get_sim_time
except ImportError:  # cocotb 1.9
    from cocotb.utils import get_sim_time

from ._native import Model
from ._signals import bind, level, stop_task
from .wishbone import WishboneMonitor


class HostAccess(Protocol):
    """What a host-bus monitor hands its callbacks (:class:`WishboneAccess`,
    :class:`AvalonAccess`, :class:`Axi4LiteAccess`, :class:`ApbAccess`,
    :class:`RegportAccess`, :class:`MotorolaAccess`): at the launch
    (``launch`` True, ``data`` = write data) and at the completion
    (``data`` = read data) of each access."""

    write: bool
    addr: int
    data: int
    launch: bool


class HostMonitor(Protocol):
    """A host-bus monitor the scoreboard can listen to
    (:class:`WishboneMonitor`, :class:`AvalonMonitor`,
    :class:`Axi4LiteMonitor`, :class:`ApbMonitor`,
    :class:`RegportMonitor`, :class:`MotorolaMonitor`, or your own):
    ``host_bus`` names the profile's timing (``"wishbone"``, ``"avalon"``,
    ``"pio"``, ``"axi4-lite"``, ``"apb"``, ``"regport"``,
    ``"motorola"``)."""

    host_bus: str

    def add_callback(self, fn: Callable[[Any], None]) -> None: ...

    def stop(self) -> None: ...


class Sja1000Mismatch(AssertionError):
    """The DUT diverged from the golden model (or a requested frame never
    went out); the message is the diagnoser's text: what happened, the
    figures (bit, field, expected, seen), the root cause and the fix."""


class Sja1000Scoreboard:
    """Shadows an SJA1000-compatible DUT with the golden model.

    Host side, one of:

    - a :class:`WishboneMonitor` on ``dut.<wb_prefix>*`` (the default);
    - ``monitor=``: a host-bus monitor made by the bench, such as
      :class:`AvalonMonitor`, :class:`Axi4LiteMonitor`,
      :class:`ApbMonitor`, :class:`RegportMonitor` or
      :class:`MotorolaMonitor` (its ``host_bus`` chooses the profile's
      access timing, ``[access.avalon]``, ``[access.axi4-lite]``,
      ``[access.apb]``, ``[access.regport]``, ``[access.motorola]``;
      without one, AXI4-Lite, APB and the register port take the Wishbone
      timing, Motorola the 8051 bus's);
      ``wb_prefix`` is then not used;
    - ``wb_prefix=None`` and calls to :meth:`request` / :meth:`read_data`
      from a monitor of any bus (a processor model...).

    CAN side: once per CAN clock (falling edge of ``<prefix><clk>``) the
    model takes the rx level the DUT sampled and compares the DUT's
    ``tx_o`` (at sample points), ``irq_on`` and ``bus_off_on``
    (``irq_active_low=False`` for an active-high interrupt such as
    ``can_avalon``'s ``irq``). ``reset`` (a name on ``dut`` or a handle)
    holds the model still while high (while low with
    ``reset_active_low=True``, as ``s_axi_aresetn`` or ``presetn``).

    Times in what it writes are the simulator's: the scoreboard measures
    the CAN clock's period and anchors its time line after each reset.

    Each access reaches the model at the CAN clock the core's ``profile``
    declares (``"rtl"``: our ``can_top``; ``"opencores-can"``; a .toml
    path). Tolerances are the profile's, as on the command line; the
    Wishbone monitor sees each launch half a host cycle late, which can move
    an access by one CAN clock (inside the tolerances).

    With ``report_dir``, the scoreboard writes there, named after ``name``,
    what ``cancosim run`` writes: the run record (``<name>.record.json``,
    which ``cancosim diagnose`` reads back), the bus log in can-utils
    ``candump -l`` format (``<name>.log``: frames on the DUT's rx and the
    error frames the Linux ``sja1000`` driver would raise for the DUT, from
    the model), and on a failure the diagnosis (``<name>.diagnosis.txt``).
    Beside them, its markers (:meth:`write_markers`): ``<name>.markers.vcd``
    (a ``divergence`` bit that rises at the first divergence, its kind, each
    host access as the model took it, the model's events and the frames, as
    text) and ``<name>.gtkw``, a GTKWave view with the primary marker on
    the divergence, as the command line writes next to its VCD:
    ``gtkwave dut.vcd <name>.gtkw`` puts that marker on the simulator's own
    waveform. It writes them at :meth:`finish` or at the first divergence.

    The first divergence raises :class:`Sja1000Mismatch` from the
    scoreboard's task (which fails the running test); ``await finish()`` at
    the end judges the last reads and reports a transmission that never
    completed.
    """

    def __init__(
        self,
        dut: Any,
        *,
        profile: str = "rtl",
        can_hz: float = 24e6,
        prefix: str = "",
        wb_prefix: Optional[str] = "wb_",
        monitor: Optional[HostMonitor] = None,
        clk: str = "clk_i",
        rx: str = "rx_i",
        tx: str = "tx_o",
        irq: Optional[str] = "irq_on",
        irq_active_low: bool = True,
        bus_off: Optional[str] = "bus_off_on",
        reset: Union[str, Any, None] = "wb_rst_i",
        reset_active_low: bool = False,
        name: Optional[str] = None,
        report_dir: Optional[str] = None,
        candump_iface: str = "can0",
    ) -> None:
        self.log = logging.getLogger(f"cocotb.{dut._name}.sja1000sb")
        self.name = name or dut._name
        self.model = Model(profile, can_hz, self.name)
        self.report_dir = report_dir
        self.candump_iface = candump_iface
        self._reported = False
        self.clock = bind(dut, prefix, clk)
        self.rx = bind(dut, prefix, rx)
        self.tx = bind(dut, prefix, tx)
        self.irq = bind(dut, prefix, irq) if irq else None
        self.bus_off = bind(dut, prefix, bus_off) if bus_off else None
        self.irq_active_low = irq_active_low
        self.reset = (bind(dut, "", reset) if isinstance(reset, str) else reset) if reset else None
        self.reset_active_low = reset_active_low
        self.monitor: Optional[HostMonitor] = monitor
        self.wishbone: Optional[WishboneMonitor] = None
        if monitor is None and wb_prefix is not None:
            self.wishbone = WishboneMonitor(dut, wb_prefix, reset="rst_i")
            self.monitor = self.wishbone
        host_bus = getattr(self.monitor, "host_bus", "wishbone") if self.monitor is not None else "wishbone"
        self.model.set_host_bus(host_bus)
        if self.monitor is not None:
            self.monitor.add_callback(self._on_access)
        self.log.info("golden SJA1000, profile %s, host bus %s%s; %s", profile, host_bus,
                      "" if self.monitor is not None else " (request/read_data hook)", self.model.tolerances)
        self._task = cocotb.start_soon(self._run())

    # The host-side hook, for a monitor of any bus.
    def request(self, write: bool, addr: int, data: int = 0) -> None:
        """An access presented to the DUT, at the host edge that first presents it."""
        self.model.request(write, addr, data)

    def read_data(self, addr: int, data: int) -> int:
        """The DUT's read data at the ack; returns the model's value."""
        v = self.model.compare_read(addr, data)
        self._check()
        return v

    def _on_access(self, a: HostAccess) -> None:
        if a.launch:
            self.request(a.write, a.addr, a.data)
        elif not a.write:
            self.read_data(a.addr, a.data)

    @property
    def failed(self) -> bool:
        """True once the DUT diverged (or :meth:`finish` found a frame that never went out)."""
        return self.model.failed

    @property
    def diagnosis(self) -> Optional[str]:
        """The diagnoser's text, or None."""
        return self.model.diagnosis

    @property
    def marker_ps(self) -> Optional[int]:
        """Simulator time (ps) of the first divergence (or of a
        transmission request that never completed), else None: where
        :meth:`write_markers` puts the primary marker."""
        return self.model.marker_ps

    def write_markers(self, vcd: Union[str, Path], gtkw: Union[str, Path, None] = None) -> None:
        """Writes the scoreboard's events as a VCD at ``vcd`` and, with
        ``gtkw``, a GTKWave save file with the primary marker at
        :attr:`marker_ps` (see the class's docs)."""
        self.model.write_markers(str(vcd), None if gtkw is None else str(gtkw))

    def _check(self) -> None:
        if self.model.failed:
            self._report()
            raise Sja1000Mismatch(self.model.diagnosis)

    def candump_log(self) -> str:
        """The bus log so far, in can-utils ``candump -l`` format."""
        return self.model.candump_log(self.candump_iface)

    def _report(self) -> None:
        """With ``report_dir``: the run record, the candump log and, on a
        failure, the diagnosis text (once)."""
        if self.report_dir is None or self._reported:
            return
        self._reported = True
        d = Path(self.report_dir)
        d.mkdir(parents=True, exist_ok=True)
        if self.model.failed:
            (d / f"{self.name}.diagnosis.txt").write_text(self.model.diagnosis or "")
        (d / f"{self.name}.record.json").write_text(self.model.record_json())
        (d / f"{self.name}.log").write_text(self.candump_log())
        self.write_markers(d / f"{self.name}.markers.vcd", d / f"{self.name}.gtkw")

    async def _run(self) -> None:
        m = self.model
        irq_invert = not self.irq_active_low
        # The simulator's time of the clock the model's time line was last
        # anchored at (None: anchor at the next clock, after a reset); the
        # period is measured once, between the first two clocks.
        anchor: Optional[int] = None
        measured = False
        while True:
            await FallingEdge(self.clock)
            if self.reset is not None and level(self.reset) != self.reset_active_low:
                anchor = None
                continue
            if anchor is None or not measured:
                now = round(get_sim_time("ps"))
                if anchor is None:
                    m.set_time_ps(now)
                    anchor = now
                else:
                    m.set_period_ps(now - anchor)
                    measured = True
            irq = None
            if self.irq is not None:
                irq = level(self.irq) != irq_invert
            m.clock(
                level(self.rx),
                level(self.tx),
                irq,
                level(self.bus_off) if self.bus_off is not None else None,
            )
            if m.failed:
                self._check()

    async def finish(self) -> None:
        """Runs the CAN clocks that still decide open comparisons, then the
        end-of-test check; raises :class:`Sja1000Mismatch` on a failure."""
        for _ in range(self.model.open_clocks + 2):
            await FallingEdge(self.clock)
        stop_task(self._task)
        if self.monitor is not None:
            self.monitor.stop()
        self.model.finish()
        self._check()
        self._report()
        self.log.info(
            "scoreboard: %d register reads and %d tx sample points compared, no divergence",
            self.model.compared_reads, self.model.compared_bits,
        )
