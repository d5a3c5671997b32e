"""A continued branch resampled at the frequency response's parameter grid.

``frequency-response --param NAME=START:STOP:NUM`` promises NUM points for every method.
Pseudo-arclength continuation puts its points where the curve needs them (dense near a
resonance, sparse where it runs straight), so their number is not NUM.  The branch is
therefore continued first and then solved again, by the continuation's own corrector at a
fixed parameter (the problem's ``solve_at``: Newton in the harmonic-balance coefficients,
or shooting), at the NUM equally spaced values of ``linspace(START, STOP, NUM)``, on each
monotonic piece of the branch, from the state interpolated between the two continuation
points that bracket the value.  The turning points (the continuation point where the
parameter turns back, beside a fold) are kept as they are, so a branch that folds k times
returns its grid values covered once per piece plus k turning points.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..periodic.records import Branch, BranchPoint

__all__ = ["on_grid"]


def _pieces(signs) -> list[tuple[int, int]]:
    """(first, last) point indices of the monotonic runs of the branch, split where the
    sign of d(parameter)/d(arclength) changes (a fold); neighbouring runs share the
    first point past the fold (the turning point)."""
    turns = [i for i in range(1, len(signs)) if signs[i] != signs[i - 1]]
    ends = [0, *turns, len(signs) - 1]
    return [(a, b) for a, b in zip(ends[:-1], ends[1:], strict=True) if b > a]


def _guess(point: BranchPoint) -> np.ndarray:
    c = point.coefficients
    return np.asarray(point.x0 if c is None else c, float).ravel()


def on_grid(problem, branch: Branch, grid: np.ndarray) -> Branch:
    """``branch`` (of ``problem``, a harmonic-balance or shooting continuation problem)
    with its points replaced by solutions at the values of ``grid`` each monotonic piece
    covers, plus its turning points; bifurcations keep their place between the points.

    A value whose correction fails is left out and counted in the branch's notes."""
    pts = branch.points
    if len(pts) < 2:
        return branch
    lam = np.array([p.value for p in pts])
    out: list[tuple[float, BranchPoint]] = []  # (position along the old branch, point)
    failed = 0
    pieces = _pieces([p.tangent_sign for p in pts])
    for k, (a, b) in enumerate(pieces):
        lo, hi = lam[a : b + 1].min(), lam[a : b + 1].max()
        sign = pts[a].tangent_sign
        inside = grid[(grid >= lo) & (grid <= hi)][::sign]
        run = np.maximum.accumulate(lam[a : b + 1] * sign)  # increasing, despite rounding
        for g in inside:
            j = a + int(np.clip(np.searchsorted(run, g * sign) - 1, 0, b - a - 1))
            w = (g - lam[j]) / (lam[j + 1] - lam[j]) if lam[j + 1] != lam[j] else 0.0
            w = min(max(w, 0.0), 1.0)
            guess = (1 - w) * _guess(pts[j]) + w * _guess(pts[j + 1])
            try:
                out.append((j + w, problem.solve_at(float(g), guess, sign)))
            except (ArithmeticError, ValueError, RuntimeError, np.linalg.LinAlgError):
                failed += 1
        if k < len(pieces) - 1:  # the turning point between this piece and the next
            out.append((float(b), pts[b]))
    out.sort(key=lambda item: item[0])
    where = np.array([s for s, _ in out])
    # a bifurcation at old index i lies between old points i - 1 and i
    moved = tuple(
        replace(e, index=int(np.searchsorted(where, e.index - 0.5))) if e.index >= 0 else e
        for e in branch.bifurcations
    )
    notes = branch.notes
    if failed:
        notes += (f"{failed} of the grid's values on this branch did not converge; left out",)
    return replace(branch, points=tuple(p for _, p in out), bifurcations=moved, notes=notes)
