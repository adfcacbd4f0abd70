"""The wired-AND CAN bus as a cocotb agent, with golden-model nodes."""

import logging
from typing import Any, List, Optional, Union

import cocotb
from cocotb.queue import Queue
from cocotb.triggers import FallingEdge

from ._native import Faults, Node
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

    Faults, with the command line's semantics (``[[fault]]`` of a scenario):
    :meth:`flip` inverts a bit, :meth:`glitch` puts a pulse of some CAN
    clocks inside a bit, :meth:`stuck` holds a level for some bits. Each is
    placed in frame ``frame`` (counted from 1, the first SOF on the bus) at
    wire bit ``bit`` (SOF = 0, stuff bits counted, as ``bit_in_frame``), or
    at bit ``bit`` of ``field`` (``"crc"``, ``"data"``, ``"ack_slot"``...;
    stuff bits not counted). ``target`` says who receives the fault:
    ``"bus"`` (everyone, the DUT included), ``"dut-rx"`` (the DUT only) or a
    model node's name. Positions are the bench's: its bit clock and decoder
    on the wired-AND level, bits counted from bit boundary to boundary.
    :meth:`force` holds the bus at a level for some clocks from now;
    ``rx_tied`` ties the DUT's rx (the DE2 thesis wiring) while the model
    nodes still see the wired-AND.
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
        # Kept from the start, so frames are counted from the first SOF.
        self._faults = Faults(btr0, btr1)
        self._node_rx: Optional[List[bool]] = None
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

    @property
    def clocks_per_bit(self) -> int:
        """CAN clocks per bit of the bus's BTR0/BTR1."""
        tq = 2 * ((self.btr0 & 0x3F) + 1)
        return tq * (3 + (self.btr1 & 0x0F) + ((self.btr1 >> 4) & 0x07))

    def _target(self, target: str) -> Optional[int]:
        if target == "bus":
            return None
        if target in ("dut-rx", "dut"):
            return 0
        for i, n in enumerate(self.nodes):
            if n.name == target:
                return 1 + i
        names = ", ".join(repr(n.name) for n in self.nodes) or "none yet"
        raise ValueError(f"fault target {target!r} is neither 'bus', 'dut-rx' nor a node name (nodes: {names})")

    def _fault_list(self) -> Faults:
        return self._faults

    def flip(self, *, frame: int, bit: int, field: Optional[str] = None, target: str = "bus") -> None:
        """Inverts one bit: wire bit ``bit`` of frame ``frame``, or bit
        ``bit`` of ``field`` in that frame, for ``target``."""
        self._fault_list().flip(frame, bit, field, self._target(target))

    def glitch(
        self,
        *,
        frame: int,
        bit: int,
        field: Optional[str] = None,
        offset: Optional[int] = None,
        width: Optional[int] = None,
        level: Union[None, bool, str] = None,
        target: str = "bus",
    ) -> None:
        """A pulse of ``width`` CAN clocks starting ``offset`` clocks into the
        bit (default: 1/8 of a bit, 1/4 into it, as the command line), of the
        inverted level, or of ``level`` ("dominant"/"recessive") if given."""
        cpb = self.clocks_per_bit
        off = cpb // 4 if offset is None else offset
        w = max(cpb // 8, 1) if width is None else width
        lv = None if level is None else _level(level)
        self._fault_list().glitch(frame, bit, off, w, field, lv, self._target(target))

    def stuck(
        self,
        level: Union[bool, str],
        bits: int,
        *,
        frame: Optional[int] = None,
        bit: int = 0,
        field: Optional[str] = None,
        target: str = "bus",
    ) -> None:
        """The bus stuck at ``level`` ("dominant"/"recessive", or True for
        recessive) for ``bits`` bit times, from a frame bit or (no
        ``frame``) from the next CAN clock."""
        self._fault_list().stuck(_level(level), bits, frame, bit, field, self._target(target))

    @property
    def faults_applied(self) -> int:
        """CAN clocks at which a fault changed what some receiver got (0:
        no fault has acted yet)."""
        return self._faults.applied

    @property
    def faults_waiting(self) -> int:
        """Faults placed by field whose bit has not come yet."""
        return self._faults.waiting

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
            node_rx = self._node_rx
            for i, n in enumerate(self.nodes):
                r = node_rx[i] if node_rx is not None and i < len(node_rx) else rx
                bus = n._clock(r) and bus
            if self._force_left > 0:
                self._force_left -= 1
                bus = self._force_level
            self.level = bus
            dut_rx = bus
            got = self._faults.clock(bus, 1 + len(self.nodes))
            if got is not None:
                dut_rx, self._node_rx = got[0], got[1:]
            self.rx.value = int(dut_rx if self.rx_tied is None else self.rx_tied)


def _level(level: Union[bool, str]) -> bool:
    """A bus level: "dominant" / "recessive", or a bool (True = recessive)."""
    if isinstance(level, str):
        if level not in ("dominant", "recessive"):
            raise ValueError(f"level {level!r}: use 'dominant' or 'recessive'")
        return level == "recessive"
    return bool(level)
