"""What every host-bus monitor shares: callbacks at each launch and
completion, a queue of completed accesses, its task, and (on buses with a
protocol check) the violations it saw."""

import logging
from typing import Any, Callable, List

from cocotb.queue import Queue

try:  # cocotb 2.x
    from cocotb.simtime import get_sim_time
except ImportError:  # cocotb 1.9
    from cocotb.utils import get_sim_time

from ._signals import stop_task


class ProtocolViolation(AssertionError):
    """A host-bus monitor saw the master or the slave break the bus's
    protocol; the message says what, in one sentence."""


class AccessMonitor:
    """The base of :class:`WishboneMonitor`-like monitors: a subclass sets
    ``protocol`` (its bus's name in a violation's sentence), calls
    :meth:`_init_monitor` and starts its ``_task``."""

    protocol = ""
    log: logging.Logger
    _task: Any

    def _init_monitor(self, strict: bool = True) -> None:
        self.strict = strict
        self.violations: List[str] = []
        self.accesses = 0
        self._callbacks: List[Callable[[Any], None]] = []
        self._queue: "Queue[Any]" = Queue()

    def add_callback(self, fn: Callable[[Any], None]) -> None:
        """``fn(access)`` at each launch and each completion."""
        self._callbacks.append(fn)

    async def recv(self) -> Any:
        """The next completed access."""
        return await self._queue.get()

    def stop(self) -> None:
        """Stops watching."""
        stop_task(self._task)

    def _emit(self, a: Any) -> None:
        if not a.launch:
            self.accesses += 1
            self._queue.put_nowait(a)
        for cb in self._callbacks:
            cb(a)

    def _violation(self, text: str) -> None:
        msg = f"{self.protocol} protocol violation at {get_sim_time('ns'):.0f} ns: {text}"
        self.violations.append(msg)
        if self.strict:
            raise ProtocolViolation(msg)
        self.log.error("%s", msg)
