"""Figures of a regime map (``sweep.atlas``): motion type, exponent, attractor count,
extremes and meshing regime over the two parameters.

Each figure shows the dominant attractor of every grid point (the one most initial states
reached; ties go to the forward start) and says so, with the fixed values and the initial
states in its caption line.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import BoundaryNorm, ListedColormap  # noqa: E402
from matplotlib.patches import Patch, Rectangle  # noqa: E402

from .sweep.maps_result import RegimeMap  # noqa: E402

__all__ = [
    "BIFURCATIONS",
    "BRANCHES",
    "CONTACT",
    "MESHING_CLASSES",
    "MOTION_CLASSES",
    "OUTCOMES",
    "SWEEPS",
    "map_figures",
    "motion_class",
    "operating_point",
]

# The package's palettes: one meaning, one colour, in every figure (these maps, the
# bifurcation and point figures of ``plots``, the responses, the studies' figures).  The
# area palettes (motion, meshing, outcomes) share no colour, so a cell's colour means one
# thing whichever map it is in; a test holds that.
OUTCOMES = (  # what a run that has no motion type became
    ("undetermined", "#c7c7c7"),
    ("divergent", "#000000"),
    ("left the valid range", "#9467bd"),
)
MOTION_CLASSES = (  # (label, colour) in legend order
    ("period-1", "#2ca02c"),
    ("period-2", "#bcbd22"),
    ("period-3", "#ff7f0e"),
    ("period-n (n > 3)", "#8c564b"),
    ("quasi-periodic", "#1f77b4"),
    ("chaotic", "#d62728"),
    *OUTCOMES,
)
MESHING_CLASSES = (
    ("no impact", "#9edae5"),
    ("single-sided impact", "#e377c2"),
    ("double-sided impact", "#7b0051"),
    ("no contact", "#ffed6f"),
    # a force law loaded inside the gap (the study's polynomial): it reverses, never lifts
    ("single-sided force reversal", "#fdb462"),
    ("double-sided force reversal", "#8c510a"),
    ("inside the outer zeros, loaded", "#b3de69"),
    *OUTCOMES,
)
# Marker families: a sweep's direction (filled dots over open rings: both stay visible
# where they agree), a mesh's contact state, a bifurcation's kind.
SWEEPS = {
    "forward": {"color": "#08519c", "marker": "o", "ms": 3.0, "mew": 0.0},
    "backward": {"color": "#e6550d", "marker": "o", "ms": 6.0, "mfc": "none", "mew": 1.0},
    "independent": {"color": "#08519c", "marker": "o", "ms": 3.0, "mew": 0.0},
}
CONTACT = {"forward": "#1b7837", "separated": "#878787", "backward": "#762a83"}
BIFURCATIONS = {
    "fold": ("s", "#e41a1c"),
    "period-doubling": ("D", "#984ea3"),
    "neimark-sacker": ("o", "#4daf4a"),
}
# continued branches, by period multiple (1, 2, 3, more): dark lines over the sweeps' dots
BRANCHES = ("#252525", "#31a354", "#756bb1", "#8c6d31")
_OUTCOME_COLOUR = dict(OUTCOMES)


def period_colour(n: int) -> str:
    """The colour of a continued period-n branch (:data:`BRANCHES`)."""
    return BRANCHES[min(max(int(n), 1), len(BRANCHES)) - 1]


def motion_class(motion: str, status: str = "ok") -> str:
    """The legend class of a motion label (a run that did not end normally: its status)."""
    if status in ("left the valid range", "invalid"):
        return "left the valid range"
    if status == "divergent" or motion == "divergent":
        return "divergent"
    if motion in ("period-1", "period-2", "period-3"):
        return motion
    if motion.startswith("period-"):
        return "period-n (n > 3)"
    known = {label for label, _ in MOTION_CLASSES}
    return motion if motion in known else "undetermined"


def sweep_marker(direction: str) -> dict:
    """Keyword arguments of ``ax.plot`` for a sweep's points (:data:`SWEEPS`)."""
    return dict(SWEEPS.get(direction, SWEEPS["independent"]))


def operating_point(system, parameter: str | None = None, values=None) -> str:
    """The operating point in words: ω̄, each static load and the backlash model, e.g.
    ``ω̄ = 0.5; f_u = 0.1, f_v = -0 to -0.1 over lambda 0 to 1; polynomial backlash``.
    Over a sweep of ``parameter`` (``values``), what it changes is given at both ends."""
    c = system.contract
    ends = None
    if parameter is not None and values is not None and len(values):
        lo, hi = float(np.min(values)), float(np.max(values))
        ends = [system.with_values(**{parameter: v}) for v in (lo, hi)]

    def text(name: str, shown: str) -> str:
        a, b = (system, system) if ends is None else ends
        a, b = a.parameter(name) + 0.0, b.parameter(name) + 0.0  # no "-0"
        return f"{shown} = {a:.4g}" if a == b else f"{shown} = {a:.4g} to {b:.4g}"

    loads = ", ".join(text(name, name) for name in c.loads.values())
    out = text(c.forcing_frequency, "ω̄") + (f"; {loads}" if loads else "")
    if ends is not None:
        out += f" over {parameter} {lo:.4g} to {hi:.4g}"
    backlash = getattr(system.module, "FEATURES", {}).get("backlash")
    return out + (f"; {backlash} backlash" if backlash else "")


def categorical(ax, x_edges, y_edges, labels, classes) -> None:
    """Cells coloured by class (``classes``: (label, colour) pairs), with a legend of the
    classes present outside the axes, to the right."""
    names = [c for c, _ in classes]
    codes = np.vectorize(lambda s: names.index(s))(np.asarray(labels, dtype=object))
    cmap = ListedColormap([c for _, c in classes])
    norm = BoundaryNorm(np.arange(len(classes) + 1) - 0.5, cmap.N)
    ax.pcolormesh(x_edges, y_edges, codes.astype(float), cmap=cmap, norm=norm)
    present = [k for k in range(len(classes)) if np.any(codes == k)]
    ax.legend(
        handles=[Patch(color=classes[k][1], label=classes[k][0]) for k in present],
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=8,
        frameon=False,
    )


def legend_below(fig, axes, caption: str = "") -> None:
    """One legend for the whole figure, below it (each label once, whichever panels
    carry it), and ``caption`` under the legend."""
    seen: dict = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            seen.setdefault(label, handle)
    fig.tight_layout()
    bottom = 0.0
    if seen:
        legend = fig.legend(
            seen.values(),
            seen.keys(),
            loc="upper center",
            bbox_to_anchor=(0.5, 0.0),
            ncol=min(3, len(seen)),
            fontsize=8,
            frameon=False,
        )
        renderer = fig.canvas.get_renderer()
        box = legend.get_window_extent(renderer).transformed(fig.transFigure.inverted())
        bottom = box.y0
    if caption:
        fig.text(0.01, bottom - 0.01, caption, fontsize=7, ha="left", va="top", wrap=True)


def not_ok_marks(ax, values, statuses) -> None:
    """A cross on the panel's lower edge at each value whose run did not end normally
    (its outcome's colour): such runs have no Poincaré points to draw."""
    bad: dict = {}
    for value, status in zip(values, statuses, strict=True):
        if status != "ok":
            bad.setdefault(motion_class("", status), []).append(value)
    for label, xs in bad.items():
        ax.plot(
            xs,
            np.zeros(len(xs)),
            "x",
            ms=7,
            mew=1.5,
            color=_OUTCOME_COLOUR.get(label, "#c7c7c7"),
            transform=ax.get_xaxis_transform(),
            clip_on=False,
            label=f"run {label} (no Poincaré points)",
        )


def _uneven(v) -> bool:
    """Values whose steps differ by more than a factor two: drawn at equal spacing."""
    steps = np.diff(np.asarray(v, float))
    return steps.size > 1 and np.max(np.abs(steps)) > 2 * np.min(np.abs(steps))


def _edges(v) -> np.ndarray:
    v = np.asarray(v, float)
    if _uneven(v):
        return np.arange(v.size + 1) - 0.5
    if v.size == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = (v[1:] + v[:-1]) / 2
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def _label(ax, m: RegimeMap, ticks: dict | None = None) -> None:
    """Axis names; an unevenly spaced axis gets one tick per value (cells of equal size);
    ``ticks`` names the values of an axis that stands for text (``{axis: [label, ...]}``)."""
    ticks = ticks or {}
    for values, name, axis in ((m.x_values, m.x, ax.xaxis), (m.y_values, m.y, ax.yaxis)):
        if name in ticks:
            axis.set_label_text(name)
            axis.set_ticks(np.asarray(values, float), list(ticks[name]))
            continue
        axis.set_label_text(name + (" (unevenly spaced values)" if _uneven(values) else ""))
        if _uneven(values):
            axis.set_ticks(np.arange(len(values)), [f"{v:g}" for v in values])


def _caption(m: RegimeMap, title: str | None = None, shown: str = "dominant") -> str:
    """The caption line; ``shown``: what a cell stands for (``dominant``: the attractor
    most initial states reached; ``all``: every attractor of the point)."""
    fixed = ", ".join(f"{k} = {v:g}" for k, v in m.values.items() if k not in (m.x, m.y))
    s = m.settings
    k = s["initial_states"]
    starts = ["forward", "backward"][: min(k, 2)] + ([f"{k - 2} random"] if k > 2 else [])
    what = {
        "dominant": "each cell: the dominant attractor (most starts; ties: the forward start)",
        "all": "each cell: every attractor its starts reached, counted",
    }[shown]
    return (
        f"{title or m.model}{'; ' + fixed if fixed else ''}; {k} initial states per point "
        f"({', '.join(starts)}; seed {s['seed']}); {s['transient']} + {s['periods']} periods, "
        f"continued to settle the verdict up to {s.get('budget', 0):,} (borders 8,000), "
        f"{s['method']} rtol {s['rtol']:g}; {what}"
    )


def _outcomes(m: RegimeMap, every: bool = False) -> np.ndarray:
    """(ny, nx) outcome label of the cells whose dominant run (``every``: any run) did
    not end normally, "" elsewhere."""
    out = np.full((len(m.y_values), len(m.x_values)), "", dtype=object)
    for ix, column in enumerate(m.cells):
        for iy, cell in enumerate(column):
            runs = cell.attractors if every else cell.attractors[:1]
            bad = [a.run.status for a in runs if a.run.status != "ok"]
            if bad:
                out[iy, ix] = motion_class("", bad[0])
    return out


def _hatch(ax, m: RegimeMap, outcomes: np.ndarray, what: str) -> None:
    """Hatch the cells of runs that did not end normally (their outcome's colour) and
    say so in a legend outside the axes: such runs have no value to colour."""
    xe, ye = _edges(m.x_values), _edges(m.y_values)
    shown = {}
    for (iy, ix), label in np.ndenumerate(outcomes):
        if not label:
            continue
        colour = _OUTCOME_COLOUR.get(label, "#c7c7c7")
        ax.add_patch(
            Rectangle(
                (xe[ix], ye[iy]),
                xe[ix + 1] - xe[ix],
                ye[iy + 1] - ye[iy],
                fill=False,
                hatch="xx",
                edgecolor=colour,
                lw=0.0,
            )
        )
        shown[label] = colour
    if shown:
        ax.legend(
            handles=[
                Patch(facecolor="white", edgecolor=c, hatch="xx", label=f"{label} ({what})")
                for label, c in shown.items()
            ],
            loc="upper left",
            bbox_to_anchor=(0.0, -0.15),
            fontsize=8,
            frameon=False,
        )


def _save(fig, path: Path, caption: str) -> Path:
    fig.tight_layout()
    # the caption under everything drawn (axis labels, legends below the axes)
    box = fig.get_tightbbox(fig.canvas.get_renderer())
    bottom = box.y0 / fig.get_figheight()
    fig.text(0.01, bottom - 0.01, caption, fontsize=7, ha="left", va="top", wrap=True)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


FIGURES = ("motion", "lyapunov", "attractors", "extremes", "meshing")


def map_figures(
    m: RegimeMap,
    folder,
    prefix: str = "map",
    ticks: dict | None = None,
    title: str | None = None,
    kinds: tuple = FIGURES,
) -> list[Path]:
    """Write the figures of a map into ``folder`` (the meshing regime only for models
    with contact edges); return their paths.  ``ticks``: ``{axis: [label per value]}`` for
    an axis whose values stand for text (a load reading, a backlash model); ``title``
    opens the caption instead of the model's name (say what a derived variant is);
    ``kinds``: which of :data:`FIGURES` to write.  Colours: :data:`MOTION_CLASSES` and
    :data:`MESHING_CLASSES` (no colour in both); runs that left the valid range or
    diverged are a class of their own in the categorical maps and hatched in the others."""
    unknown = sorted(set(kinds) - set(FIGURES))
    if unknown:
        raise ValueError(f"kinds: {', '.join(unknown)} unknown; known: {', '.join(FIGURES)}")
    folder = Path(folder)
    caption = _caption(m, title)
    out = []
    coords, nc = m.coordinates, len(m.coordinates)
    xe, ye = _edges(m.x_values), _edges(m.y_values)
    status = m.grid("status")
    failed = _outcomes(m)

    def categorical_panel(ax, labels, classes, text):
        categorical(ax, xe, ye, labels, classes)
        _label(ax, m, ticks)
        ax.set_title(text)

    if "motion" in kinds:
        grids = [np.vectorize(motion_class)(m.grid("motion", c), status) for c in coords]
        # one verdict per attractor: the coordinates share it (maps from before that
        # carried one per coordinate get a panel each)
        one = all(np.array_equal(g, grids[0]) for g in grids)
        panels = (
            [(grids[0], "motion of the attractor")]
            if one
            else list(zip(grids, coords, strict=True))
        )
        k = len(panels)
        fig, axes = plt.subplots(1, k, figsize=(5.2 * k + 1.5, 4.2), squeeze=False)
        for ax, (labels, c) in zip(axes[0], panels, strict=True):
            categorical_panel(ax, labels, MOTION_CLASSES, c if one else f"motion of {c}")
        out.append(_save(fig, folder / f"{prefix}-motion.png", caption))

    if "lyapunov" in kinds:
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        lam = m.grid("lyapunov")
        lim = np.nanmax(np.abs(lam)) if np.any(np.isfinite(lam)) else 1.0
        im = ax.pcolormesh(xe, ye, lam, cmap="RdBu_r", vmin=-lim, vmax=lim)
        fig.colorbar(im, ax=ax, label="largest Lyapunov exponent (per unit τ)")
        _label(ax, m, ticks)
        _hatch(ax, m, failed, "no exponent")
        ax.set_title("largest Lyapunov exponent (> 0: chaos); blank: no estimate")
        out.append(_save(fig, folder / f"{prefix}-lyapunov.png", caption))

    if "attractors" in kinds:
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        count = m.grid("attractors")
        top = max(int(np.nanmax(count)), 1)
        cmap = plt.get_cmap("viridis", top + 1)
        im = ax.pcolormesh(xe, ye, count, cmap=cmap, vmin=-0.5, vmax=top + 0.5)
        fig.colorbar(im, ax=ax, ticks=range(0, top + 1), label="attractors found")
        _label(ax, m, ticks)
        _hatch(ax, m, _outcomes(m, every=True), "some starts; not counted")
        ax.set_title(f"attractors found from {m.settings['initial_states']} initial states")
        out.append(_save(fig, folder / f"{prefix}-attractors.png", _caption(m, title, "all")))

    if "extremes" in kinds:
        fig, axes = plt.subplots(2, nc, figsize=(5.2 * nc, 8), squeeze=False)
        for k, c in enumerate(coords):
            for row, field in enumerate(("max", "min")):
                ax = axes[row][k]
                im = ax.pcolormesh(xe, ye, m.grid(field, c), cmap="viridis")
                fig.colorbar(im, ax=ax, label=f"{field.capitalize()}({c}) / half backlash")
                _label(ax, m, ticks)
                _hatch(ax, m, failed, "extremes up to the exit")
                ax.set_title(f"{field.capitalize()}({c}) over the sampled window")
        out.append(_save(fig, folder / f"{prefix}-extremes.png", caption))

    meshes = m.meshes
    if not meshes or "meshing" not in kinds:
        return out
    fig, axes = plt.subplots(1, len(meshes), figsize=(5.2 * len(meshes) + 2, 4.2), squeeze=False)
    for ax, c in zip(axes[0], meshes, strict=True):
        regime = m.grid("meshing", c)
        pick = np.vectorize(lambda f, r: f or r or "undetermined", otypes=[object])
        labels = pick(failed, regime)
        categorical_panel(
            ax, labels, MESHING_CLASSES, f"meshing regime of {c} (by the sign of its force)"
        )
    out.append(_save(fig, folder / f"{prefix}-meshing.png", caption))
    return out
