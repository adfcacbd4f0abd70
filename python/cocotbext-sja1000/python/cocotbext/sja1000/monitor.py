"""A CAN bus monitor: frames, errors, fields and stuff bits from one pin."""

import logging
from typing import Any, Callable, List, NamedTuple, Optional, Tuple

import cocotb
from cocotb.queue import Queue
from cocotb.triggers import FallingEdge

from ._native import Decoder
from ._signals import bind, level, stop_task
from .frame import CanFrame


_FLAGS = {
    "active error flag": "error_frame",
    "passive error flag": "error_frame",
    "overload flag": "overload_frame",
}


class BusEvent(NamedTuple):
    """One decoded event. ``kind``:

    - "frame": a data or remote frame completed (``frame``, ``ack``);
    - "error_frame": an error flag began (``field`` = "active error flag" or
      "passive error flag"; ``error`` = the error the decoder saw before it,
      "Stuff", "Crc", "Form" or "Acknowledge", or None when only a
      transmitter could see it: a bit error);
    - "overload_frame": an overload flag began;
    - "error": the decoder detected an error (``error``, ``field`` where);
    - "field" and "stuff" (only with ``fields=True``): a field began, a
      stuff bit.

    ``bit`` counts the monitor's sample points from its start.
    """

    kind: str
    bit: int
    frame: Optional[CanFrame] = None
    ack: bool = False
    error: Optional[str] = None
    field: Optional[str] = None


class CanMonitor:
    """Decodes the bus level on ``dut.<prefix><pin>`` (default the DUT's rx,
    which is the bus) with the bench's bit clock for ``btr0``/``btr1``.

    ``await recv()`` gives the next complete frame; ``await recv_event()``
    the next frame, error frame or overload frame as a :class:`BusEvent`;
    callbacks see every :class:`BusEvent`. ``errors`` lists the decoder's
    error events, ``error_frames`` and ``overload_frames`` the flags seen."""

    def __init__(
        self,
        dut: Any,
        *,
        prefix: str = "",
        pin: str = "rx_i",
        clk: str = "clk_i",
        clock: Any = None,
        btr0: int = 0x41,
        btr1: int = 0x25,
        fields: bool = False,
    ) -> None:
        self.log = logging.getLogger(f"cocotb.{dut._name}.canmonitor")
        self.pin = bind(dut, prefix, pin)
        self.clock = clock if clock is not None else bind(dut, prefix, clk)
        self.decoder = Decoder(btr0, btr1)
        self.fields = fields
        self.frames: "Queue[CanFrame]" = Queue()
        self.events: "Queue[BusEvent]" = Queue()
        self.errors: List[BusEvent] = []
        self.error_frames: List[BusEvent] = []
        self.overload_frames: List[BusEvent] = []
        self._last_error: Optional[BusEvent] = None
        self.count = 0
        self._callbacks: List[Callable[[BusEvent], None]] = []
        self._task = cocotb.start_soon(self._run())

    def add_callback(self, fn: Callable[[BusEvent], None]) -> None:
        """Calls ``fn(event)`` for every event (fields and stuff bits only with ``fields=True``)."""
        self._callbacks.append(fn)

    async def recv(self) -> Any:
        """The next complete frame (a python-can ``Message`` if available)."""
        f = await self.frames.get()
        return f.to_message()

    async def recv_event(self) -> BusEvent:
        """The next frame, error frame or overload frame."""
        return await self.events.get()

    def stop(self) -> None:
        stop_task(self._task)

    def _event(self, e: Tuple[Any, ...]) -> Optional[BusEvent]:
        kind = e[0]
        if kind == "frame":
            f = CanFrame.from_native(e[1])
            self.count += 1
            self.frames.put_nowait(f)
            self.log.info("frame id 0x%X data %s%s", f.arbitration_id, f.data.hex(), "" if e[2] else " (no ack)")
            self._last_error = None
            ev = BusEvent("frame", e[4], frame=f, ack=e[2])
            self.events.put_nowait(ev)
            return ev
        if kind == "error":
            ev = BusEvent("error", e[3], error=e[1], field=e[2])
            self.errors.append(ev)
            self._last_error = ev
            return ev
        if kind == "field" and e[1] in _FLAGS:
            cause = self._last_error
            self._last_error = None
            ev = BusEvent(_FLAGS[e[1]], e[2], field=e[1], error=cause.error if cause is not None else None)
            (self.error_frames if ev.kind == "error_frame" else self.overload_frames).append(ev)
            self.events.put_nowait(ev)
            self.log.info("%s at bit %d%s", ev.kind.replace("_", " "), ev.bit, f" ({ev.error} error)" if ev.error else "")
            return ev
        if not self.fields:
            return None
        if kind == "field":
            return BusEvent("field", e[2], field=e[1])
        return BusEvent("stuff", e[1])

    async def _run(self) -> None:
        while True:
            await FallingEdge(self.clock)
            for e in self.decoder.clock(level(self.pin)):
                ev = self._event(e)
                if ev is not None:
                    for cb in self._callbacks:
                        cb(ev)
