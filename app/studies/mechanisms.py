"""The mechanisms behind the motions at the study's operating points, named only where the
evidence shows them, and which coexisting solution a start from rest reaches.

* **Cross-well motion** (the polynomial only): at a light static force ``0 < |F| < F*``
  the polynomial ``g(x) = F`` has a second stable root on the unloaded side of the gap,
  separated from the loaded one by an unstable root, the barrier
  (``gearsym.derive.mesh.force_sign.static_equilibria``).  A coordinate whose Poincare
  points lie on both sides of the barrier moves between the two wells.
* **Slaved coordinate**: the verdict belongs to the attractor; a coordinate whose Poincare
  cloud is a small share (< :data:`SLAVED`) of the widest one's follows it through the
  coupling ``kappa_uv``, ``xi_uv`` rather than moving chaotically of its own.
* **Start from rest**: the operating point analysed again from the loaded rest state (the
  generated module's default), beside the run that continues the sweep.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SLAVED", "mechanisms_section"]

SLAVED = 0.05  # a coordinate's share of the widest Poincare cloud below which it is slaved
POWERS = (1, 3, 5, 7)


def _barrier(system, c: str) -> tuple[float, float] | None:
    """(barrier, spurious well) of coordinate ``c`` at the system's static force, or None
    (no spurious well: a dead zone, or a static force beyond F*)."""
    from gearsym.derive.mesh.force_sign import static_equilibria

    if system.backlash != "polynomial":
        return None
    F = np.asarray(system.module.static_mesh_force(system.p), float)[system.coordinates.index(c)]
    coef = [system.parameter(k) for k in ("g1", "g3", "g5", "g7")]
    eq = static_equilibria(coef, POWERS, float(F), system.module.VALID_RANGE)
    spurious = [e.x for e in eq if e.spurious]
    loaded = [e.x for e in eq if e.stable and not e.spurious]
    if not spurious or not loaded:
        return None
    s, lo = spurious[0], loaded[0]
    between = [e.x for e in eq if not e.stable and min(s, lo) < e.x < max(s, lo)]
    return (between[0], s) if between else None


def mechanisms(result) -> list[str]:
    """The mechanisms the evidence of one ``PointResult`` shows (sentences)."""
    system, v = result.trajectory.system, result.verdict
    out = []
    P = result.trajectory.poincare
    for c in system.coordinates:
        b = _barrier(system, c)
        if b is None:
            continue
        x = P[system.index(c)]
        side = x > b[0] if b[1] > b[0] else x < b[0]
        share = float(np.mean(side))
        if 0 < share < 1:
            out.append(
                f"cross-well motion of {c}: its Poincaré points lie on both sides of the "
                f"barrier x = {b[0]:+.3f} between the loaded well and the polynomial's "
                f"spurious well at x = {b[1]:+.3f} ({share:.0%} on the spurious side)"
            )
        elif share == 1:
            out.append(f"{c} sits in the polynomial's spurious well (x = {b[1]:+.3f})")
    spread = (v.evidence or {}).get("spread", {}) if v is not None else {}
    if v is not None and v.motion in ("chaotic", "quasi-periodic"):
        for c, e in spread.items():
            share = e.get("share")
            if share is not None and share < SLAVED:
                k = system.parameter(f"kappa_{c}_{_other(system, c)}")
                out.append(
                    f"{c} slaved through the coupling: its Poincaré cloud is {share:.1%} of "
                    f"the widest coordinate's (κ = {k:.3f}): it follows the {v.motion} "
                    f"{_other(system, c)} rather than moving of its own"
                )
    return out


def _other(system, c: str) -> str:
    return next(o for o in system.coordinates if o != c)


def _label(result) -> str:
    v, tr = result.verdict, result.trajectory
    u, w = tr.coordinate("u"), tr.coordinate("v")
    return f"{v.motion}, u ∈ [{u.min():.3f}, {u.max():.3f}], v ∈ [{w.min():.3f}, {w.max():.3f}]"


def _same(a, b, tol: float = 0.02) -> bool:
    """The same attractor: the same verdict and extremes of u and v within ``tol``."""
    if a.verdict.motion != b.verdict.motion:
        return False
    ta, tb = a.trajectory, b.trajectory
    return all(
        abs(ta.coordinate(c).min() - tb.coordinate(c).min()) < tol
        and abs(ta.coordinate(c).max() - tb.coordinate(c).max()) < tol
        for c in ("u", "v")
    )


def mechanisms_section(models: dict) -> str:
    """Markdown: per model ("polynomial", "dead zone") and operating point, the solution
    the sweep reaches, the one a start from rest reaches, and the mechanisms shown.

    ``models``: name -> (points from the sweep, points from rest), each (case, lambda)
    -> PointResult."""
    w = ["## Coexisting solutions and mechanisms at the operating points\n"]
    w.append(
        "Each operating point is run twice: continuing the forward sweep (from the end "
        "state of the run before it) and from the loaded rest state. Where they differ, two "
        "attractors coexist there and the study's answer depends on its start, which it "
        "does not state. Mechanisms are named only where the evidence shows them: "
        "cross-well motion in the polynomial's double well (Poincaré points on both sides "
        f"of the barrier), a coordinate slaved to a chaotic one (its Poincaré cloud under "
        f"{SLAVED:.0%} of the widest).\n"
    )
    w.append(
        "| model | load, λ | the sweep reaches | a start from rest reaches | "
        "same attractor | mechanisms |"
    )
    w.append("|---|---|---|---|---|---|")
    for name, (sweep, rest) in models.items():
        for key in sorted(rest):
            a, b = sweep[key], rest[key]
            seen = mechanisms(a) + [f"from rest: {m}" for m in mechanisms(b)]
            w.append(
                f"| {name} | {key[0]}, {key[1]:g} | {_label(a)} ({a.verdict.periods_run:,} "
                f"periods) | {_label(b)} ({b.verdict.periods_run:,} periods) | "
                f"{'yes' if _same(a, b) else '**no**'} | {'; '.join(seen) or 'none shown'} |"
            )
    w.append("")
    return "\n".join(w)
