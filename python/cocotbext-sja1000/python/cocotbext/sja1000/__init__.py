"""CAN for cocotb: a wired-AND bus agent with golden-model nodes, a bus
monitor, and the golden SJA1000 as a scoreboard whose failures carry the
diagnoser's text.

- :class:`CanBus`: drives the DUT's rx from the wired-AND of its tx and the
  model nodes' (:class:`CanNode`), takes faults (a forced level).
- :class:`CanMonitor`: decodes the bus into frames, errors, fields and stuff
  bits; ``await recv()``, callbacks.
- :class:`Sja1000Scoreboard`: the golden SJA1000 shadowing the DUT, fed by
  its own Wishbone monitor or by ``request``/``read_data`` from any bus;
  compares register reads, tx bits and the irq/bus-off pins with the
  command line's tolerances; raises :class:`Sja1000Mismatch` with the
  diagnosis.
- :class:`WishboneMaster`, :class:`WishboneMonitor`: a classic Wishbone
  driver and monitor (8-bit data), enough for an SJA1000-style core.
- :class:`AvalonMaster`, :class:`AvalonMonitor`: an Avalon-MM driver and
  monitor (8-bit data; waitrequest, pipelined reads with readdatavalid, or
  fixed wait states); the monitor feeds the scoreboard (``monitor=``).
- :class:`Axi4LiteMaster`, :class:`Axi4LiteMonitor`, :class:`ApbMaster`,
  :class:`ApbMonitor`: AXI4-Lite and APB (APB3, APB4) drivers and monitors
  (32-bit data, register n at byte n * stride); the monitors feed the
  scoreboard and flag the protocol violations they see
  (:class:`ProtocolViolation`).
- :class:`RegportMaster`, :class:`RegportMonitor`: a plain register port
  (read and write strobes, no acknowledge, read data a fixed number of
  clocks after the strobe); :class:`MotorolaMaster`,
  :class:`MotorolaMonitor`: the SJA1000's Motorola mode (AS, E, R/W, CS,
  multiplexed AD, phases in ns). Their monitors feed the scoreboard and
  flag violations the same way.
"""

from ._monitor import ProtocolViolation
from ._native import Decoder, Model, Node
from .apb import ApbAccess, ApbBus, ApbMaster, ApbMonitor
from .avalon import AvalonAccess, AvalonBus, AvalonMaster, AvalonMonitor
from .axi4lite import Axi4LiteAccess, Axi4LiteBus, Axi4LiteMaster, Axi4LiteMonitor
from .bus import CanBus, CanNode
from .frame import CanFrame
from .monitor import CanMonitor, BusEvent
from .motorola import MotorolaAccess, MotorolaBus, MotorolaMaster, MotorolaMonitor, MotorolaTiming
from .regport import RegportAccess, RegportBus, RegportMaster, RegportMonitor
from .scoreboard import HostAccess, HostMonitor, Sja1000Mismatch, Sja1000Scoreboard
from .wishbone import WishboneMaster, WishboneMonitor, WishboneAccess

__all__ = [
    "ApbAccess",
    "ApbBus",
    "ApbMaster",
    "ApbMonitor",
    "AvalonAccess",
    "AvalonBus",
    "AvalonMaster",
    "AvalonMonitor",
    "Axi4LiteAccess",
    "Axi4LiteBus",
    "Axi4LiteMaster",
    "Axi4LiteMonitor",
    "BusEvent",
    "CanBus",
    "CanFrame",
    "CanMonitor",
    "CanNode",
    "Decoder",
    "HostAccess",
    "HostMonitor",
    "Model",
    "MotorolaAccess",
    "MotorolaBus",
    "MotorolaMaster",
    "MotorolaMonitor",
    "MotorolaTiming",
    "Node",
    "ProtocolViolation",
    "RegportAccess",
    "RegportBus",
    "RegportMaster",
    "RegportMonitor",
    "Sja1000Mismatch",
    "Sja1000Scoreboard",
    "WishboneAccess",
    "WishboneMaster",
    "WishboneMonitor",
]
__version__ = "0.1.0"
