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
from matplotlib.patches import Patch  # noqa: E402

from .sweep.maps_result import RegimeMap  # noqa: E402

__all__ = ["MOTION_CLASSES", "map_figures", "motion_class"]

# (label, colour) in legend order
MOTION_CLASSES = (
    ("period-1", "#2ca02c"),
    ("period-2", "#bcbd22"),
    ("period-3", "#ff7f0e"),
    ("period-n (n > 3)", "#8c564b"),
    ("quasi-periodic", "#1f77b4"),
    ("chaotic", "#d62728"),
    ("undetermined", "#c7c7c7"),
    ("divergent", "#000000"),
    ("left the valid range", "#9467bd"),
)
MESHING_CLASSES = (
    ("no impact", "#2ca02c"),
    ("single-sided impact", "#ff7f0e"),
    ("double-sided impact", "#d62728"),
    ("no contact", "#1f77b4"),
    ("undetermined", "#c7c7c7"),
)


def motion_class(motion: str, status: str = "ok") -> str:
    """The legend class of a motion label."""
    if status == "left the valid range":
        return "left the valid range"
    if motion in ("period-1", "period-2", "period-3"):
        return motion
    if motion.startswith("period-"):
        return "period-n (n > 3)"
    known = {label for label, _ in MOTION_CLASSES}
    return motion if motion in known else "undetermined"


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


def _caption(m: RegimeMap, title: str | None = None) -> str:
    fixed = ", ".join(f"{k} = {v:g}" for k, v in m.values.items() if k not in (m.x, m.y))
    s = m.settings
    k = s["initial_states"]
    starts = ["forward", "backward"][: min(k, 2)] + ([f"{k - 2} random"] if k > 2 else [])
    return (
        f"{title or m.model}{'; ' + fixed if fixed else ''}; {k} initial states per point "
        f"({', '.join(starts)}; seed {s['seed']}); {s['transient']} + {s['periods']} periods, "
        f"{s['method']} rtol {s['rtol']:g}; dominant attractor shown"
    )


def _categorical(ax, fig, m: RegimeMap, labels, classes, title: str, ticks=None) -> None:
    names = [c for c, _ in classes]
    codes = np.vectorize(lambda s: names.index(s))(labels).astype(float)
    cmap = ListedColormap([c for _, c in classes])
    norm = BoundaryNorm(np.arange(len(classes) + 1) - 0.5, cmap.N)
    ax.pcolormesh(_edges(m.x_values), _edges(m.y_values), codes, cmap=cmap, norm=norm)
    present = [k for k in range(len(classes)) if np.any(codes == k)]
    ax.legend(
        handles=[Patch(color=classes[k][1], label=classes[k][0]) for k in present],
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=8,
        frameon=False,
    )
    _label(ax, m, ticks)
    ax.set_title(title)


def _save(fig, path: Path, caption: str) -> Path:
    fig.text(0.01, 0.005, caption, fontsize=7, ha="left", va="bottom", wrap=True)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
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
    ``kinds``: which of :data:`FIGURES` to write."""
    unknown = sorted(set(kinds) - set(FIGURES))
    if unknown:
        raise ValueError(f"kinds: {', '.join(unknown)} unknown; known: {', '.join(FIGURES)}")
    folder = Path(folder)
    caption = _caption(m, title)
    out = []
    coords, nc = m.coordinates, len(m.coordinates)
    xe, ye = _edges(m.x_values), _edges(m.y_values)
    status = m.grid("status")

    if "motion" in kinds:
        fig, axes = plt.subplots(1, nc, figsize=(5.2 * nc + 1.5, 4.2), squeeze=False)
        for ax, c in zip(axes[0], coords, strict=True):
            motion = m.grid("motion", c)
            labels = np.vectorize(motion_class)(motion, status)
            _categorical(ax, fig, m, labels, MOTION_CLASSES, f"motion of {c}", ticks)
        out.append(_save(fig, folder / f"{prefix}-motion.png", caption))

    if "lyapunov" in kinds:
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        lam = m.grid("lyapunov")
        lim = np.nanmax(np.abs(lam)) if np.any(np.isfinite(lam)) else 1.0
        im = ax.pcolormesh(xe, ye, lam, cmap="RdBu_r", vmin=-lim, vmax=lim)
        fig.colorbar(im, ax=ax, label="largest Lyapunov exponent (per unit τ)")
        _label(ax, m, ticks)
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
        ax.set_title(
            f"attractors found from {m.settings['initial_states']} initial states\n"
            "(runs that diverged or left the valid range are not counted)"
        )
        out.append(_save(fig, folder / f"{prefix}-attractors.png", caption))

    if "extremes" in kinds:
        fig, axes = plt.subplots(2, nc, figsize=(5.2 * nc, 8), squeeze=False)
        for k, c in enumerate(coords):
            for row, field in enumerate(("max", "min")):
                ax = axes[row][k]
                im = ax.pcolormesh(xe, ye, m.grid(field, c), cmap="viridis")
                fig.colorbar(im, ax=ax, label=f"{field.capitalize()}({c}) / half backlash")
                _label(ax, m, ticks)
                ax.set_title(f"{field.capitalize()}({c}) over the sampled window")
        out.append(_save(fig, folder / f"{prefix}-extremes.png", caption))

    meshes = m.meshes
    if not meshes or "meshing" not in kinds:
        return out
    fig, axes = plt.subplots(1, len(meshes), figsize=(5.2 * len(meshes) + 2, 4.2), squeeze=False)
    for ax, c in zip(axes[0], meshes, strict=True):
        regime = m.grid("meshing", c)
        labels = np.vectorize(lambda r: r if r else "undetermined")(regime)
        _categorical(
            ax,
            fig,
            m,
            labels,
            MESHING_CLASSES,
            f"meshing regime of {c} (Kahraman & Singh)",
            ticks,
        )
    out.append(_save(fig, folder / f"{prefix}-meshing.png", caption))
    return out
