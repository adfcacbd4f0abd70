"""Pin binding and reading shared by the agents (cocotb 1.9 and 2.x)."""

from typing import Any


def bind(dut: Any, prefix: str, name: str) -> Any:
    """The handle ``dut.<prefix><name>``, with a clear error if absent."""
    full = prefix + name
    try:
        return getattr(dut, full)
    except AttributeError:
        raise AttributeError(f"{dut._name} has no signal {full!r} (prefix {prefix!r})") from None


def level(sig: Any) -> bool:
    """A one-bit signal as a bool; X or Z reads as 1 (recessive / inactive)."""
    try:
        return bool(int(sig.value))
    except ValueError:
        return True


def value(sig: Any) -> int:
    """A vector as an int; X or Z bits read as 0."""
    try:
        return int(sig.value)
    except ValueError:
        v = str(sig.value)
        return int("".join("1" if c == "1" else "0" for c in v), 2)


def stop_task(task: Any) -> None:
    """Ends a background task (``cancel`` in cocotb 2.x, ``kill`` in 1.9)."""
    import cocotb

    if int(cocotb.__version__.split(".")[0]) >= 2:
        task.cancel()
    else:
        task.kill()


def resolved(sig: Any) -> bool:
    """The signal has no X or Z bit."""
    try:
        int(sig.value)
        return True
    except ValueError:
        return False


def changed(sig: Any) -> Any:
    """A trigger on any change of ``sig`` (``value_change`` in cocotb 2.x,
    ``Edge`` in 1.9)."""
    vc = getattr(sig, "value_change", None)
    if vc is not None:
        return vc
    from cocotb.triggers import Edge

    return Edge(sig)
