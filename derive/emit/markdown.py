"""The audit pages' two Markdown helpers: a display-math block and a number."""

from __future__ import annotations

__all__ = ["math_block", "number"]


def math_block(*lines: str) -> str:
    """A fenced ```` ```math ```` block, which Git hosts render as LaTeX."""
    return "```math\n" + "\n".join(lines) + "\n```\n"


def number(v: float, digits: int = 6) -> str:
    """``v`` to ``digits`` significant digits, and 0 as ``0``."""
    return "0" if v == 0 else f"{v:.{digits}g}"
