"""The wired-AND CAN bus as a cocotb agent, with golden-model nodes."""

import logging
from typing import Any, List, Optional

import cocotb
from cocotb.queue import Queue
from cocotb.triggers import FallingEdge

from ._native import Node
from ._signals import bind, level, stop_task
from .frame import CanFrame


class CanNode:
    """A golden SJA1000 node on a :class:`CanBus` (PeliCAN, accepts every
    frame, acknowledges unless listen-only). Made by :meth:`CanBus.add_node`."""

    def __init__(self, name: str, btr0: int, btr1: int, listen_only: bool = False) -> None:
        self.name = name
        self.model = Node(btr0, btr1, listen_only)
        self._rx: "Queue[CanFrame]" = Queue()
        self._pending: List[CanFrame] = []

    def send_nowait(self, msg: Any) -> None:
        """Queues a frame (python-can ``Message``, :class:`CanFrame` or ``(id, data)``)."""
        self._pending.append(CanFrame.of(msg))

    async def recv(self) -> Any:
        """The next frame this node received (a python-can ``Message`` if available)."""
        f = await self._rx.get()
        return f.to_message()

    @property
    def tec(self) -> int:
        return self.model.tec

    @property
    def rec(self) -> int:
        return self.model.rec

    def _clock(self, rx: bool) -> bool:
        if self._pending and not self.model.busy:
            f = self._pending.pop(0)
            self.model.send(f.arbitration_id, list(f.data), f.is_extended_id, f.is_remote_frame, f.dlc)
        tx = self.model.clock(rx)
        got = self.model.recv()
        if got is not None:
            self._rx.put_nowait(CanFrame.from_native(got))
        return tx


class CanBus:
    """The bus between the DUT's ``tx``/``rx`` pins and any number of model
    nodes: each CAN clock, every node and the DUT sample the same level, and
    the DUT's rx becomes the wired-AND of all transmitters.

    Pins are bound by name: ``dut.<prefix><tx>``, ``dut.<prefix><rx>`` and
    the CAN clock ``dut.<prefix><clk>`` (or ``clock``). The DUT's rx changes
    on falling edges of the CAN clock, so it is stable at every rising edge
    (for a core without an rx synchroniser, like our ``can_top`` with
    ``RX_SYNC = 0``).

    Faults: :meth:`force` holds the bus at a level for some clocks (a stuck
    bus or a glitch); ``rx_tied`` ties the DUT's rx (the DE2 thesis wiring)
    while the model nodes still see the wired-AND.
    """

    def __init__(
        self,
        dut: Any,
        *,
        prefix: str = "",
        tx: str = "tx_o",
        rx: str = "rx_i",
        clk: str = "clk_i",
        clock: Any = None,
        btr0: int = 0x41,
        btr1: int = 0x25,
        rx_tied: Optional[bool] = None,
    ) -> None:
        self.log = logging.getLogger(f"cocotb.{dut._name}.canbus")
        self.tx = bind(dut, prefix, tx)
        self.rx = bind(dut, prefix, rx)
        self.clock = clock if clock is not None else bind(dut, prefix, clk)
        self.btr0, self.btr1 = btr0, btr1
        self.rx_tied = rx_tied
        self.nodes: List[CanNode] = []
        self.level = True
        self.clocks = 0
        self._force_level = True
        self._force_left = 0
        self.rx.value = 1
        self.log.info(
            "CAN bus on %s/%s, clock %s, BTR0=0x%02X BTR1=0x%02X%s",
            self.tx._name, self.rx._name, self.clock._name, btr0, btr1,
            "" if rx_tied is None else f", rx tied {'recessive' if rx_tied else 'dominant'}",
        )
        self._task = cocotb.start_soon(self._run())

    def add_node(self, name: Optional[str] = None, listen_only: bool = False) -> CanNode:
        """A golden-model node on this bus, with the bus's bit timing."""
        node = CanNode(name or f"node{len(self.nodes)}", self.btr0, self.btr1, listen_only)
        self.nodes.append(node)
        return node

    def force(self, level: bool, clocks: int) -> None:
        """Holds the bus at ``level`` for the next ``clocks`` CAN clocks."""
        self._force_level, self._force_left = bool(level), int(clocks)

    def stop(self) -> None:
        stop_task(self._task)

    async def _run(self) -> None:
        while True:
            await FallingEdge(self.clock)
            self.clocks += 1
            rx = self.level  # what every node and the DUT sampled at the rising edge
            bus = level(self.tx)
            for n in self.nodes:
                bus = n._clock(rx) and bus
            if self._force_left > 0:
                self._force_left -= 1
                bus = self._force_level
            self.level = bus
            self.rx.value = int(bus if self.rx_tied is None else self.rx_tied)
