"""Figures a gear-dynamics reader expects beside the bifurcation diagrams: meshing state
and largest Lyapunov exponent against lambda, the backlash polynomial against the dead zone,
the mesh stiffness of both meshes with their phase, the Floquet multipliers along the
continued branches and the frequency responses; and :func:`figure_list`, the report's list
of the figures a run wrote.

Colours and markers come from the solver's palettes (``gearsym.solver.plots_maps``): one
meaning, one colour, in every figure; legends sit outside the axes, once per figure.
"""

from __future__ import annotations

import fnmatch
from pathlib import Path

import numpy as np
from gearsym.solver.plots_maps import (
    BIFURCATIONS,
    CONTACT,
    legend_below,
    not_ok_marks,
    period_colour,
    sweep_marker,
)

__all__ = [
    "CAPTIONS",
    "backlash_figure",
    "branch_png",
    "call",
    "figure_list",
    "floquet_figure",
    "map_png",
    "response_figure",
    "stiffness_figure",
    "sweep_state_figure",
]

# one colour per load ratio of a frequency-response figure (in the order given)
LOAD_RATIOS = ("#a6611a", "#018571", "#5e3c99", "#4d4d4d")


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def sweep_state_figure(sweeps, path: Path, title: str, caption: str) -> Path:
    """Share of the sampled window the model's force on each mesh is forward, zero
    (separated) or backward (``analysis.meshing``; a colour per state, :data:`CONTACT`;
    solid: forward sweep, dashed: backward), and the largest Lyapunov exponent with its
    uncertainty (per unit τ; the sweeps' markers), against lambda.  Points whose run did
    not end normally are crosses on the lower edge.  One legend, below the panels."""
    plt = _plt()
    coords = list(sweeps[0].points[0].classification)
    fig, axes = plt.subplots(1, len(coords) + 1, figsize=(5 * (len(coords) + 1), 4.2))
    for ax, c in zip(axes, coords, strict=False):
        for sw in sweeps:
            style = "--" if sw.direction == "backward" else "-"
            lam = np.array(sw.values, float)
            for state, col in CONTACT.items():
                share = [p.meshing_states.get(c, {}).get(state, np.nan) for p in sw.points]
                name = "zero force (separated)" if state == "separated" else f"{state} force"
                ax.plot(lam, share, style, color=col, label=f"{name} ({sw.direction} sweep)")
            not_ok_marks(ax, sw.values, [p.status for p in sw.points])
        ax.set_xlabel("lambda")
        ax.set_ylabel(f"share of time, mesh {c}")
        ax.set_ylim(-0.02, 1.02)
        ax.set_title(f"sign of the model's mesh force on {c} (zero: separated)")
    ax = axes[-1]
    for sw in sorted(sweeps, key=lambda sw: sw.direction != "backward"):
        lam = np.array(sw.values, float)
        exp = [_get(p, "lyapunov_exponent") for p in sw.points]
        err = [_get(p, "lyapunov_uncertainty") for p in sw.points]
        style = sweep_marker(sw.direction)
        ax.errorbar(
            lam,
            exp,
            yerr=err,
            fmt=style.pop("marker"),
            capsize=2,
            ecolor=style["color"],
            label=f"exponent ({sw.direction} sweep)",
            **style,
        )
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("lambda")
    ax.set_ylabel("largest Lyapunov exponent (per unit τ)")
    ax.set_title("> 0: chaos; bars: estimated uncertainty")
    fig.suptitle(title)
    legend_below(fig, axes, caption)
    return _save(fig, path)


def _get(point, name: str) -> float:
    value = getattr(point, name, None)
    return np.nan if value is None else float(value)


def _save(fig, path: Path) -> Path:
    plt = _plt()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path


def backlash_figure(system, path: Path, caption: str) -> Path:
    """The model's backlash polynomial g(x) against the exact dead zone: the contact
    edges x = ±1 of the dead zone, the polynomial's own zeros (where its force changes
    sign) and its valid range marked.  x in half backlashes, g(x) non-dimensional."""
    plt = _plt()
    g = [system.parameter(k) for k in ("g1", "g3", "g5", "g7")]
    x = np.linspace(-3.2, 3.2, 641)
    poly = g[0] * x + g[1] * x**3 + g[2] * x**5 + g[3] * x**7
    dead = np.where(x > 1, x - 1, np.where(x < -1, x + 1, 0.0))
    roots = np.roots([g[3], 0, g[2], 0, g[1], 0, g[0], 0])
    zeros = np.sort(roots[(np.abs(roots.imag) < 1e-9) & (np.abs(roots.real) <= 3.0)].real)
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ax.plot(x, dead, "k-", label="dead zone (exact, unit half backlash)")
    ax.plot(x, poly, color="#08519c", label="7th-order polynomial g(x) of the model")
    ax.plot(
        zeros,
        np.zeros_like(zeros),
        "o",
        ms=5,
        mfc="none",
        color="#08519c",
        label="zeros of g: " + ", ".join(f"{z:+.3f}" for z in zeros),
    )
    for k, edge in enumerate((-1, 1)):
        label = None if k else "contact edges of the dead zone x = ±1"
        ax.axvline(edge, color="grey", ls="--", lw=0.8, label=label)
    ax.axvspan(-3.2, -3.0, color="0.85")
    ax.axvspan(3.0, 3.2, color="0.85", label="outside the fit's valid range |x| ≤ 3")
    ax.set_xlabel("x (deflection / half backlash)")
    ax.set_ylabel("g(x)")
    origin = "unstable" if g[0] < 0 else "stable"
    sign = "<" if g[0] < 0 else "≥"
    ax.set_title(f"backlash: g'(0) = {g[0]:.3f} {sign} 0 (unloaded origin {origin})")
    legend_below(fig, [ax], caption)
    return _save(fig, path)


def stiffness_figure(system, path: Path, caption: str) -> Path:
    """k(τ)/k_m of both meshes over two mesh periods: each mesh's Fourier harmonics
    (the model's kc/ks parameters), the second lagging by its phase phi."""
    plt = _plt()
    omega = system.omega
    tau = np.linspace(0.0, 2 * 2 * np.pi / omega, 800)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    have = set(system.contract.parameters)
    for c in system.coordinates:
        phi = system.parameter(f"phi_{c}") if f"phi_{c}" in have else 0.0
        k, j = np.ones_like(tau), 1
        while f"kc_{c}_{j}" in have:
            arg = j * (omega * tau - phi)
            k += system.parameter(f"kc_{c}_{j}") * np.cos(arg)
            k += system.parameter(f"ks_{c}_{j}") * np.sin(arg)
            j += 1
        ax.plot(tau, k, label=f"mesh {c}: phase lag {np.degrees(phi):.1f}° ({j - 1} harmonics)")
    ax.set_xlabel("τ (two mesh periods)")
    ax.set_ylabel("k(τ) / k_m")
    ax.set_title("mesh stiffness of both meshes over their mean")
    legend_below(fig, [ax], caption)
    return _save(fig, path)


def floquet_figure(branches, path: Path, title: str, caption: str) -> Path:
    """Moduli of the Floquet multipliers along each continued branch against lambda (the
    orbit is stable while all lie inside the unit circle), and the bifurcations found
    (dotted lines).  A branch's colour is its period's (as in the continuation figure);
    branches without extent in lambda (continued from a value to itself) are not drawn
    and the title says how many."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    empty = 0
    for br in branches:
        lam = np.array(br.values, float)
        if not br.multipliers or lam.size < 2 or np.ptp(lam) == 0:
            empty += bool(br.multipliers)
            continue
        mods = np.sort(np.abs(np.array([np.asarray(m) for m in br.multipliers])), axis=1)
        col = period_colour(br.n)
        label = f"period-{br.n} branch, every multiplier"
        for j in range(mods.shape[1]):
            ax.plot(lam, mods[:, j], "o", ms=3, mew=0, color=col, label=label)
        for b in br.bifurcations:
            marker, mc = BIFURCATIONS.get(br.named(b), ("x", "k"))
            ax.axvline(float(b.value), color=mc, ls=":", lw=1.0, label=f"{br.named(b)} located")
    ax.axhline(1.0, color="0.4", lw=1, label="|μ| = 1 (unit circle)")
    ax.set_yscale("log")
    ax.set_xlabel("lambda")
    ax.set_ylabel("|Floquet multiplier|")
    if empty:
        title += f"\n{empty} branch(es) without extent in lambda not drawn"
    ax.set_title(title, fontsize=10)
    legend_below(fig, [ax], caption)
    return _save(fig, path)


def response_figure(responses: dict, path: Path, title: str, caption: str, mark: float) -> Path:
    """Amplitude (half peak-to-peak, half backlashes) of each mesh coordinate over the
    forcing frequency, one colour per load ratio (:data:`LOAD_RATIOS`), stable solid and
    unstable dashed, folds marked in each panel, the study's operating frequency
    ``mark`` as a vertical line; one legend below the panels."""
    from gearsym.solver.plots_response import _segments, event_point

    plt = _plt()
    first = next(iter(responses.values()))
    coords = first.system.coordinates
    fig, axes = plt.subplots(
        len(coords), 1, figsize=(9, 3.0 * len(coords) + 0.6), sharex=True, squeeze=False
    )
    fold_marker, fold_colour = BIFURCATIONS["fold"]
    for ax, c in zip(axes[:, 0], coords, strict=True):
        for k, (lam, resp) in enumerate(responses.items()):
            curve = resp.curves[0]
            x, y, st = curve.values, curve.stats[c]["amplitude"], curve.stable
            colour = LOAD_RATIOS[k % len(LOAD_RATIOS)]
            for xs, ys, stable in _segments(x, y, st):
                ax.plot(
                    xs,
                    ys,
                    "-" if stable else "--",
                    color=colour,
                    lw=1.3 if stable else 1.0,
                    label=f"λ = {lam}, {'stable' if stable else 'unstable'}",
                )
            for e in curve.events:
                if e.jump:
                    i = event_point(curve.values, e)
                    ax.plot(
                        e.value,
                        y[i],
                        fold_marker,
                        color=fold_colour,
                        mfc="none",
                        ms=6,
                        label="fold (a slow sweep jumps here)",
                    )
        ax.axvline(mark, color="0.3", lw=0.8, ls=":", label=f"the study's ω̄ = {mark}")
        ax.set_ylabel(f"half peak-to-peak of {c}\n(half backlashes)")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("ω̄ (mesh frequency over ω_n)")
    axes[0, 0].set_title(title, fontsize=10)
    legend_below(fig, axes.ravel(), caption)
    return _save(fig, path)


# The captions of the figures ``gearsym reproduce`` writes: (file pattern, caption), in
# the report's order.  :func:`figure_list` lists the files a run wrote, with these.
CAPTIONS = (
    (
        "bifurcation_*.png",
        "Poincaré points of u and v against λ; forward sweep filled dots, backward sweep "
        "open rings (both visible where they agree); ω̄ and the loads in the title.",
    ),
    (
        "point_*.png",
        "one operating point: time series with the contact edges, phase portrait with "
        "Poincaré points, spectrum (amplitude in half backlashes, to 6.5 ω̄); verdict and "
        "its evidence in the title.",
    ),
    ("map_f1_lambda.png", "Max(u), Min(v) and the motion of v over (f1, λ)."),
    (
        "continuation_*.png",
        "continued branches (stable solid, unstable dashed, bifurcations marked) over the "
        "brute-force Poincaré points, one panel per coordinate.",
    ),
    (
        "floquet_*.png",
        "moduli of the Floquet multipliers along each continued branch against λ, the "
        "unit circle and the bifurcations located.",
    ),
    (
        "meshing_lyapunov_*.png",
        "share of time the model's own force on each mesh is forward, zero (separated) or "
        "backward (the study's polynomial is zero only at 0 and ±0.770, so it never "
        "separates), and the largest Lyapunov exponent with its uncertainty, against λ, "
        "both sweeps.",
    ),
    (
        "response_*.png",
        "period-1 response over ω̄ by harmonic balance, one colour per λ, stable solid, "
        "unstable dashed, folds marked.",
    ),
    (
        "backlash.png",
        "the model's polynomial g(x) against the exact dead zone, with g's zeros, the "
        "dead zone's contact edges ±1 and the fit's valid range.",
    ),
    ("stiffness.png", "k(τ)/k_m of both meshes over two mesh periods, with their phase lag."),
    ("bearings_*.png", "the λ sweeps on bearings beside the torsional model."),
    ("sensitivity/*-motion.png", "regime maps: motion of u and v over λ by each open value."),
    (
        "sensitivity/*-lyapunov.png",
        "regime maps: largest Lyapunov exponent over λ by each open value.",
    ),
    (
        "sensitivity/*-attractors.png",
        "regime maps: how many attractors the initial states reached (every attractor "
        "counted, not the dominant one's).",
    ),
    (
        "sensitivity/*-meshing.png",
        "regime maps: meshing regime of each mesh over λ by each open value.",
    ),
    ("sensitivity/*-extremes.png", "regime maps: Max and Min of each coordinate."),
)


def figure_list(folder, captions=CAPTIONS) -> str:
    """The Markdown list of the figures (``*.png``) under ``folder``, exactly those that
    exist: one line per caption whose pattern (``fnmatch``, relative to ``folder``, ``/``
    as separator) matches at least one file, naming every file it matches; files no
    caption matches are listed last, as such.  ``captions``: (pattern, caption) pairs in
    the order wanted, or a dict."""
    folder = Path(folder)
    files = sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*.png"))
    pairs = list(captions.items()) if isinstance(captions, dict) else list(captions)
    lines, used = [], set()
    for pattern, caption in pairs:
        hits = [f for f in files if f not in used and fnmatch.fnmatchcase(f, pattern)]
        if not hits:
            continue
        used.update(hits)
        lines.append("- " + ", ".join(f"`{f}`" for f in hits) + f": {caption}")
    rest = [f for f in files if f not in used]
    if rest:
        lines.append("- " + ", ".join(f"`{f}`" for f in rest) + ": (no caption)")
    return "\n".join(lines) if lines else "(no figures were written)"


def call(job: tuple):
    """Worker: ``fn(*args)`` of a ``(fn, args)`` pair (a figure of the results)."""
    fn, args = job
    return fn(*args)


def map_png(f1, lam, max_u, min_v, motion_v, path: Path) -> Path:
    """The (f1, lambda) map of the light scene: Max(u), Min(v) and the motion of v."""
    from gearsym.solver import plots

    fig = plots.map_figure(
        f1,
        lam,
        max_u,
        min_v,
        motion_v,
        title="light-load scene with f1 varied",
        names=("f1", "lambda", "u", "v"),
    )
    return plots.save_figure(fig, path)


def branch_png(branches, sweeps, title: str, system, stem: Path) -> Path:
    """The continued periodic branches of one load case over its sweeps."""
    from gearsym.solver import plots

    fig = plots.branch_figure(branches, ("u", "v"), sweeps=sweeps, title=title, system=system)
    return plots.save_figure(fig, stem.parent / f"continuation_{stem.name}.png")
