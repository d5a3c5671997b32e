"""The bifurcations harmonic balance flags on a non-smooth model, confirmed and typed by the
monodromy of a located time integration.

Hill's multipliers inherit a piecewise model's discontinuous Jacobian (the jump is
resolved to 1/N of the period, ``docs/analysis.md``): on the dead zone they stay 2e-4 to
5e-3 from the monodromy, enough to flag Neimark-Sacker crossings where no multiplier
leaves the circle and to see a real multiplier through -1 as a complex pair.  So each
flagged event is checked on the flow, which locates the kinks (``flow.py``, located DOP853
on the variational equations):

1. the monodromy ``M`` at the harmonic-balance state of the branch points on either side of
   the event, ``phi_{nT}`` from the state at tau = 0 (the state is the truncated series',
   so ``M`` is off by about its error, far below the sign changes that matter);
2. the test functions of ``floquet.py`` there (``det(M - I)``, ``det(M + I)``, the product
   of ``|mu|^2 - 1`` over the complex pairs, whose number must not change);
3. a test that changes sign between the two sides confirms the event and types it:
   through +1 a fold, through -1 a period doubling, a complex pair a Neimark-Sacker point.
   Where none does, the bracket of a period doubling or Neimark-Sacker flag (located on
   Hill's multipliers) widens a branch point on each side at a time, up to :data:`WINDOW`
   of the parameter from the event (Hill's multipliers place a dead-zone period doubling
   4e-3 from shooting's at H = 15) and :data:`MAX_WIDEN` points; a fold, located on the
   branch's tangent as closely as the series resolves the orbit, keeps its own bracket;
4. a flag that no bracket confirms is dropped, and counted; two flags confirmed by the
   same crossing (the same kind, overlapping brackets) are one event.

A fold where the branch turns (its tangent's parameter component changes sign) is a
property of the solution curve, located without Hill's multipliers: it is kept as it is
(its evidence still compares Hill with the monodromy there).

Monodromies are computed only where flags are, and shared by overlapping brackets.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from .engine import FAILURES
from .floquet import KINDS, bifurcation_tests
from .flow import FlowMap, StroboscopicMap
from .records import CRITICAL, Bifurcation, Branch

__all__ = ["MAX_WIDEN", "RTOL", "WINDOW", "Screening", "located_monodromy", "screen"]

WINDOW = 0.01  # widest bracket: this share of max(1, |parameter|) on each side
MAX_WIDEN = 6  # branch points added on each side at most
RTOL = 1e-9  # the located integration's (multipliers to about 1e-8: docs/deadzone-multipliers.md)


@dataclass(frozen=True)
class Screening:
    """What the monodromy made of the flagged events of one branch.

    ``branch``: the branch with its turning folds and the confirmed events only (typed by
    the monodromy, each with its evidence) and a note saying what was dropped;
    ``flagged`` the events Hill's test functions located; ``confirmed`` and ``dropped``
    the events (``dropped`` keep Hill's kind); ``retyped`` how many confirmed events
    changed kind; ``monodromies`` the located integrations it took and ``wall_time`` (s)
    their time."""

    branch: Branch
    flagged: int
    confirmed: tuple[Bifurcation, ...]
    dropped: tuple[Bifurcation, ...]
    retyped: int
    monodromies: int
    wall_time: float

    def describe(self) -> dict:
        """The counts, and every dropped event as :meth:`Bifurcation.to_dict` gives it."""
        return {
            "method": "monodromy of a located time integration (DOP853, variational, "
            f"rtol {RTOL:g}) at the branch points around each flag",
            "flagged": self.flagged,
            "confirmed": len(self.confirmed),
            "dropped": len(self.dropped),
            "retyped": self.retyped,
            "monodromies": self.monodromies,
            "wall_time_s": self.wall_time,
            "dropped_events": [b.to_dict() for b in self.dropped],
        }

    to_dict = describe


def located_monodromy(smap: StroboscopicMap, system, parameter: str, value: float, x0):
    """The monodromy (n_states, n_states) of ``phi_{nT}`` from ``x0`` at tau = 0 with
    ``parameter = value``, by the located variational equations of ``smap``'s flow."""
    p = system.parameters_with(**{parameter: float(value)})
    return smap.jacobian(np.asarray(x0, float), p, method="variational")[1]


def _turn(b: Bifurcation, pts) -> bool:
    """Whether ``b`` is a fold where the branch turns (the tangent's parameter component
    changes sign across it): located on the curve itself, not on Hill's multipliers."""
    if b.kind != "fold":
        return False
    if b.index >= len(pts) or b.index < 1:
        return True
    return pts[b.index - 1].tangent_sign != pts[b.index].tangent_sign


def _bracket(index: int, size: int) -> tuple[int, int]:
    """The branch points on either side of an event recorded before point ``index``."""
    right = min(max(index, 1), size - 1)
    return max(right - 1, 0), max(right, 0)


def _kinds_changed(a, b) -> list[str]:
    """The kinds whose test function (``bifurcation_tests``) changes sign from ``a`` to
    ``b`` (a Neimark-Sacker product only with the same number of complex pairs)."""
    out = []
    for k, kind in enumerate(KINDS):
        if np.sign(a[k]) == np.sign(b[k]):
            continue
        if kind == "neimark-sacker" and a[3] != b[3]:
            continue
        out.append(kind)
    return out


def _critical(mu, kind: str) -> complex:
    """The multiplier of ``mu`` nearest to where ``kind`` crosses the unit circle."""
    if kind in CRITICAL:
        return complex(mu[np.argmin(np.abs(mu - CRITICAL[kind]))])
    pairs = mu[np.abs(mu.imag) > 1e-9]
    pool = pairs if pairs.size else mu
    return complex(pool[np.argmin(np.abs(np.abs(pool) - 1.0))])


def _distance(mu, kind: str) -> float:
    """How far ``kind``'s critical multiplier is from where it crosses."""
    c = _critical(mu, kind)
    return abs(c - CRITICAL[kind]) if kind in CRITICAL else abs(abs(c) - 1.0)


def screen(
    system,
    branch: Branch,
    monodromies: dict | None = None,
    *,
    window: float = WINDOW,
    max_widen: int = MAX_WIDEN,
) -> Screening:
    """Confirm and type each event of ``branch`` (a harmonic-balance branch of ``system``)
    by the located monodromy (the module text).  ``monodromies``: matrices already
    computed at the events, keyed by the event's parameter value (the continuation's
    evidence computes them there, ``hb_continuation.py``)."""
    started = time.perf_counter()
    flow = FlowMap(system, rtol=RTOL, atol=RTOL * 1e-2, locate=True)
    smap = StroboscopicMap(system, branch.n, flow=flow)
    pts, par = branch.points, branch.parameter
    known = dict(monodromies or {})
    tests: dict[int, np.ndarray] = {}
    count = 0

    def test_at(i: int) -> np.ndarray:
        nonlocal count
        if i not in tests:
            M = located_monodromy(smap, system, par, pts[i].value, pts[i].x0)
            tests[i] = bifurcation_tests(M)
            count += 1
        return tests[i]

    def mu_at(b: Bifurcation) -> np.ndarray:
        nonlocal count
        if b.value not in known:
            known[b.value] = located_monodromy(smap, system, par, b.value, b.x0)
            count += 1
        return np.linalg.eigvals(known[b.value])

    found: list[tuple[Bifurcation, tuple[int, int]]] = []
    dropped: list[Bifurcation] = []
    turns = [b for b in branch.bifurcations if _turn(b, pts)]
    flags = [b for b in branch.bifurcations if not _turn(b, pts)]
    for b in flags:
        reach = window * max(1.0, abs(b.value))
        left, right = _bracket(b.index, len(pts))
        kinds: list[str] = []
        # a branch point (+1 without a turn) is located on Hill's multipliers too, but a
        # multiplier through +1 moves far along the branch: its own bracket only
        for _ in range(1 if b.kind == "fold" else max_widen + 1):
            if left == right:
                break
            try:
                kinds = _kinds_changed(test_at(left), test_at(right))
            except FAILURES:  # a located integration failed there: no confirmation
                break
            if kinds:
                break
            # widen by a point on each side that stays within reach of the event
            wl, wr = max(left - 1, 0), min(right + 1, len(pts) - 1)
            wl = wl if abs(pts[wl].value - b.value) <= reach else left
            wr = wr if abs(pts[wr].value - b.value) <= reach else right
            if (wl, wr) == (left, right):
                break
            left, right = wl, wr
        if not kinds:
            evidence = dict(b.evidence) | {"monodromy_confirmed": 0.0, "monodromy_window": reach}
            dropped.append(replace(b, evidence=evidence))
            continue
        mu = mu_at(b)
        kind = min(kinds, key=lambda k: _distance(mu, k))
        lo, hi = sorted((pts[left].value, pts[right].value))
        evidence = dict(b.evidence) | {
            "max_monodromy_multiplier": float(np.max(np.abs(mu))),
            "monodromy_confirmed": 1.0,
            "monodromy_bracket_low": float(lo),
            "monodromy_bracket_high": float(hi),
            "hill_retyped": float(kind != b.kind),
        }
        typed = replace(b, kind=kind, multiplier=_critical(mu, kind), evidence=evidence)
        found.append((typed, (left, right)))
    confirmed = _merge(found, dropped)
    retyped = sum(b.evidence["hill_retyped"] > 0 for b in confirmed)
    flagged = len(flags)
    note = (
        f"harmonic balance flagged {flagged} bifurcation(s) by Hill's multipliers; the "
        f"monodromy of a located time integration confirmed {len(confirmed)} "
        f"({retyped} retyped) and dropped {len(dropped)}; the {len(turns)} fold(s) where "
        "the branch turns are kept as located on its tangent (hb_confirm.py)"
    )
    kept = sorted([*turns, *confirmed], key=lambda b: b.index)
    out = replace(branch, bifurcations=tuple(kept), notes=(*branch.notes, note))
    wall = time.perf_counter() - started
    return Screening(out, flagged, tuple(confirmed), tuple(dropped), retyped, count, wall)


def _merge(found, dropped: list) -> list[Bifurcation]:
    """One event per crossing: of the confirmed events of one kind whose brackets overlap,
    the one whose critical monodromy multiplier is nearest its crossing is kept, the others
    join ``dropped`` (flags that the same crossing confirmed)."""
    kept: list[tuple[Bifurcation, tuple[int, int]]] = []
    for b, (lo, hi) in found:
        twin = next(
            (k for k, (c, (a, z)) in enumerate(kept) if c.kind == b.kind and lo <= z and a <= hi),
            None,
        )
        if twin is None:
            kept.append((b, (lo, hi)))
            continue
        other = kept[twin][0]
        if _off(b) < _off(other):
            kept[twin] = (b, (lo, hi))
            b = other
        dropped.append(replace(b, evidence=dict(b.evidence) | {"monodromy_confirmed": 0.0}))
    return sorted((b for b, _ in kept), key=lambda b: b.index)


def _off(b: Bifurcation) -> float:
    """How far the recorded critical multiplier of ``b`` is from its crossing."""
    mu = complex(b.multiplier)
    return abs(mu - CRITICAL[b.kind]) if b.kind in CRITICAL else abs(abs(mu) - 1.0)
