"""Sizes refused before they are allocated: the estimate of what a request needs, the
machine's memory, and one line naming the option that asks for it (issue 14)."""

from __future__ import annotations

import os

__all__ = ["MemoryRefused", "machine_bytes", "require"]


class MemoryRefused(ValueError):
    """A request that would need more memory than this machine has."""


def machine_bytes() -> int:
    """Physical memory of this machine (bytes); 16 GiB where the system does not say."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, OSError, ValueError):
        return 16 << 30


def require(nbytes: float, what: str, fix: str) -> None:
    """Refuse ``what`` when its estimate ``nbytes`` exceeds half the machine's memory
    (the rest is the interpreter, the libraries and the copies an analysis makes)."""
    have = machine_bytes()
    if nbytes > have / 2:
        raise MemoryRefused(
            f"{what} needs about {_size(nbytes)} of memory, more than half of this "
            f"machine's {_size(have)}; {fix}"
        )


def _size(n: float) -> str:
    for unit, scale in (("TiB", 1 << 40), ("GiB", 1 << 30), ("MiB", 1 << 20)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n / 1024:.3g} KiB"
