"""``gearsym reproduce``: the reference study's lambda sweeps repeated on the DI-SO on
bearings (issue 15): what lateral and axial freedom change.

The scene ``diso-bearings-light`` is ``reference-light`` with every gear on bearings and
free to move across and along its axis (``scenes/topologies/diso-bearings.toml`` states
the bearing values and why); the heavy case is the same scene at f1 = 0.5, as
``reference-heavy`` is ``reference-light`` at f1 = 0.5.  Both models share the time scale
(``derive/equations/structure.py``), so the same omega is the same speed.  The sweeps run with the
torsional ones, at the same lambda values and settings, forward from the same kind of
start.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from gearsym.solver.analysis.modes import modes
from gearsym.solver.sweep import SweepJob
from gearsym.solver.system import System

__all__ = ["SCENE", "bearing_jobs", "bearings_section"]

SCENE = "diso_bearings_light"
_CASES = (("light", 0.1), ("heavy", 0.5))


def bearing_jobs(lam, settings) -> list[SweepJob]:
    """The forward lambda sweeps of the DI-SO on bearings, light then heavy."""
    from gearsym.resolve import module_for

    system = System.load(module_for(SCENE))
    return [
        SweepJob(system.with_values(f1=f1), "lambda", lam, settings=settings) for _, f1 in _CASES
    ]


def _difference(a, b, state: str) -> float:
    """Largest distance between the Poincare points of ``state`` of two points, each
    point of one set to the nearest of the other (the sets need not line up in time)."""
    pa, pb = np.asarray(a.poincare[state]), np.asarray(b.poincare[state])
    if not (pa.size and pb.size):
        return float("nan")
    d = np.abs(pa[:, None] - pb[None, :])
    return float(max(d.min(axis=1).max(), d.min(axis=0).max()))


def _figure(torsional, bearing, path: Path) -> Path:
    from gearsym.solver.plots import plt, save_figure

    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    for col, ((case, f1), tor, bea) in enumerate(zip(_CASES, torsional, bearing, strict=True)):
        for row, state in enumerate(("u", "v")):
            ax = axes[row, col]
            for sweep, colour, size, label in (
                (tor, "0.65", 16, "torsional (reference)"),
                (bea, "tab:red", 5, "on bearings, lateral-torsional-axial"),
            ):
                xs = [np.full(len(p.poincare[state]), p.value) for p in sweep.points]
                ys = [p.poincare[state] for p in sweep.points]
                ax.scatter(
                    np.concatenate(xs), np.concatenate(ys), s=size, color=colour, label=label, lw=0
                )
            ax.set_ylabel(f"{state} (half backlashes)")
            if row == 0:
                ax.set_title(f"{case} load, f1 = {f1}: Poincaré points against lambda")
            if row == 1:
                ax.set_xlabel("lambda = |f2/f1|")
    axes[0, 0].legend(loc="best", fontsize=8, markerscale=3)
    return save_figure(fig, path)


def bearings_section(torsional: list, bearing: list, out: Path) -> str:
    """The report's section: the modes of the DI-SO on bearings, and the forward lambda
    sweeps against the torsional ones (``torsional``: the light and heavy forward sweeps
    of the reference scenes; ``bearing``: :func:`bearing_jobs`' results)."""
    from gearsym.resolve import module_for

    _figure(torsional, bearing, out / "bearings_lambda.png")
    module = module_for(SCENE)
    result = modes(module)
    kappa = module.DEFAULTS[module.PARAMETERS.index("kappa_u_u")]
    lines = [
        "## On bearings: what lateral and axial freedom change\n",
        "The reference study's model is torsional; its own next step is the gears' lateral "
        "and axial motion. Scene `diso-bearings-light` puts every gear of the DI-SO on "
        "bearings (1e9 N/m radially, 5e8 N/m axially, about 3 % of critical damping; "
        "`scenes/topologies/diso-bearings.toml` gives the reasons) and lets it move across "
        "and along its axis: 11 coordinates instead of 2. Everything else is the reference "
        "scene's, and the time scale is the torsional model's, so each lambda below is the "
        "same operating point in both models. In the equation of u the gears' inverse "
        "masses along the line of action join the rotations' in W_uu, so the mean stiffness "
        f"coefficient is kappa_uu = {kappa:.3f} against 1 torsionally: free to translate, "
        "the gears would let the mesh ring faster; the bearings then hold them back through "
        "the coupling terms (kappa_u,xp and the others, docs/derivation/"
        f"{SCENE}.md), and the modes below are the result.\n",
        f"**Modes** (`gearsym modes {SCENE.replace('_', '-')}`; linear, time-averaged: mean "
        "stiffness, backlash closed, no damping). The mesh frequency at omega = 0.5 is "
        f"{result.mesh_frequency_hz:.0f} Hz.\n",
        "| mode | Hz | / mesh frequency | label | kinetic energy |",
        "|---|---|---|---|---|",
    ]
    for m in result.modes:
        shares = ", ".join(f"{k} {v:.2f}" for k, v in m.kinetic_shares.items() if v >= 0.005)
        lines.append(
            f"| {m.index} | {m.frequency_hz:.1f} | {result.over_mesh(m):.3f} | "
            f"{m.label} | {shares} |"
        )
    lines += [
        "",
        "**The lambda sweeps** (forward, the settings of the torsional sweeps above): "
        "![on bearings](bearings_lambda.png)\n",
    ]
    for (case, f1), tor, bea in zip(_CASES, torsional, bearing, strict=True):
        lines += _case_lines(case, f1, tor, bea)
    return "\n".join(lines) + "\n"


def _case_lines(case: str, f1: float, tor, bea) -> list[str]:
    rows, changed, unsettled = [], [], []
    du, dv = [], []
    for a, b in zip(tor.points, bea.points, strict=True):
        mt, mb = a.motion("v"), b.motion("v")
        if "undetermined" in (mt, mb) and mt != mb:
            unsettled.append(f"{a.value:g}")
        elif mt != mb:
            changed.append(f"{a.value:g} ({mt} → {mb})")
        du.append(_difference(a, b, "u"))
        dv.append(_difference(a, b, "v"))
        back_t = a.meshing_states.get("v", {}).get("backward", float("nan"))
        back_b = b.meshing_states.get("v", {}).get("backward", float("nan"))
        lateral = max(abs(b.max("xp")), abs(b.min("xp")), abs(b.max("yp")), abs(b.min("yp")))
        axial = max(abs(b.max("zp")), abs(b.min("zp")))
        rows.append(
            f"| {a.value:g} | {mt} | {mb} | {back_t:.2f} | {back_b:.2f} | {du[-1]:.3g} | "
            f"{dv[-1]:.3g} | {lateral:.3g} | {axial:.3g} |"
        )
    shift = np.nanmean(
        [
            np.mean(b.poincare["u"]) - np.mean(a.poincare["u"])
            for a, b in zip(tor.points, bea.points, strict=True)
            if len(a.poincare["u"]) and len(b.poincare["u"])
        ]
    )
    n = len(tor.points)
    jumps = [_jump(tor), _jump(bea)]
    backward = [_fully_backward(tor), _fully_backward(bea)]
    keep = {
        k
        for k, a in enumerate(tor.points)
        if n <= 11 or abs(a.value * 10 - round(a.value * 10)) < 1e-9
    }
    keep |= {k for j in jumps if j for k in (j[0], j[0] + 1)}
    rows = [r for k, r in enumerate(rows) if k in keep]
    worst = int(np.nanargmax(dv)) if np.isfinite(dv).any() else 0
    summary = (
        f"**{case.capitalize()} load, f1 = {f1}.** The motion of v differs at {len(changed)} of "
        f"{n} lambda values"
        + (": " + ", ".join(changed) if changed else "")
        + (
            f"; at {', '.join(unsettled)} one model's verdict is undetermined (not settled "
            "in the sampled window; a longer transient decides), which is not counted as a "
            "change"
            if unsettled
            else ""
        )
        + f". The Poincaré points move by up to {np.nanmax(du):.3g} half backlashes in u and "
        f"{np.nanmax(dv):.3g} in v (at lambda = {tor.points[worst].value:g}); the distance is "
        "each point's to the nearest point of the other model. On average u's Poincaré "
        f"points sit {abs(shift):.3g} half backlashes {'higher' if shift > 0 else 'lower'} "
        "on bearings. "
        + "Largest jump of v between neighbouring lambda values: "
        + "; ".join(
            f"{what}, "
            + (
                f"{j[1]:.3g} half backlashes from lambda = {j[2]:g} to {j[3]:g}"
                if j
                else "none above 0.2"
            )
            for what, j in zip(("torsional", "on bearings"), jumps, strict=True)
        )
        + ". v meshes backward throughout the window "
        + (
            "at no lambda in either model"
            if backward == [None, None]
            else "from lambda = "
            + " and ".join(
                f"{'no lambda' if b is None else f'{b:g}'} on ({what})"
                for what, b in zip(("torsional", "on bearings"), backward, strict=True)
            )
        )
        + ".\n"
    )
    head = (
        "| lambda | v torsional | v on bearings | v backward, torsional | v backward, on "
        "bearings | Δu | Δv | pinion p across its axis | p along its axis |\n"
        "|---|---|---|---|---|---|---|---|---|"
    )
    note = (
        "" if n <= 11 else "rows at every 0.1 and either side of each jump; all points in data/; "
    )
    return [
        summary,
        head,
        *rows,
        "",
        f"({note}Δ in half backlashes; p's displacements in half backlashes of 50 µm, "
        "over the sampled window.)\n",
    ]


def _jump(sweep):
    """(index, size, lambda before, lambda after) of the largest change of v's first
    Poincare point between neighbouring values, or None when it is below 0.2 half
    backlashes (a branch switch, not the steady drift of the points)."""
    v = np.array([p.poincare["v"][0] if len(p.poincare["v"]) else np.nan for p in sweep.points])
    if len(v) < 2 or not np.isfinite(np.diff(v)).any():
        return None
    k = int(np.nanargmax(np.abs(np.diff(v))))
    size = float(abs(v[k + 1] - v[k]))
    if size < 0.2:
        return None
    return k, size, sweep.points[k].value, sweep.points[k + 1].value


def _fully_backward(sweep):
    """The first lambda from which v meshes backward the whole window, or None."""
    shares = [p.meshing_states.get("v", {}).get("backward", 0.0) for p in sweep.points]
    for k in range(len(shares)):
        if all(s >= 0.995 for s in shares[k:]):
            return sweep.points[k].value
    return None
