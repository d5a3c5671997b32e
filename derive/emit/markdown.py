"""The audit pages' Markdown helpers: LaTeX of an expression, a display-math block and a
number."""

from __future__ import annotations

import sympy as sp

__all__ = ["latex", "math_block", "number"]


def latex(expr, names: dict | None = None) -> str:
    """LaTeX of a SymPy expression, with ``names`` mapping symbols to their LaTeX."""
    return sp.latex(expr, symbol_names=names or {}, long_frac_ratio=3)


def math_block(*lines: str) -> str:
    """A fenced ```` ```math ```` block, which Git hosts render as LaTeX."""
    return "```math\n" + "\n".join(lines) + "\n```\n"


def number(v: float, digits: int = 6) -> str:
    """``v`` to ``digits`` significant digits, and 0 as ``0``."""
    return "0" if v == 0 else f"{v:.{digits}g}"
