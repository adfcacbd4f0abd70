"""A CAN 2.0 frame as the agents pass it, and its python-can form."""

from typing import Any, NamedTuple, Optional, Sequence

try:  # python-can is optional
    import can as _pycan
except ImportError:  # pragma: no cover
    _pycan = None


class CanFrame(NamedTuple):
    """A CAN 2.0 frame: 11- or 29-bit id, remote flag, up to 8 data bytes."""

    arbitration_id: int
    data: bytes = b""
    is_extended_id: bool = False
    is_remote_frame: bool = False
    dlc: Optional[int] = None

    @classmethod
    def of(cls, msg: Any) -> "CanFrame":
        """From a python-can ``Message``, a ``CanFrame`` or an ``(id, data)`` pair."""
        if isinstance(msg, CanFrame):
            return msg
        if hasattr(msg, "arbitration_id"):
            return cls(msg.arbitration_id, bytes(msg.data), bool(msg.is_extended_id), bool(msg.is_remote_frame), msg.dlc)
        ident, data = msg
        return cls(int(ident), bytes(data))

    @classmethod
    def from_native(cls, t: Sequence[Any]) -> "CanFrame":
        ident, ext, remote, data = t
        return cls(ident, bytes(data), ext, remote)

    def to_message(self) -> Any:
        """A python-can ``Message`` if python-can is installed, else this frame."""
        if _pycan is None:
            return self
        return _pycan.Message(
            arbitration_id=self.arbitration_id,
            data=self.data,
            is_extended_id=self.is_extended_id,
            is_remote_frame=self.is_remote_frame,
            dlc=self.dlc if self.dlc is not None else len(self.data),
        )
