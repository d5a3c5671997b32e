"""Figures of a regime map (``sweep.atlas``): motion type, exponent, attractor count,
extremes and meshing regime over the two parameters.

Each figure shows the dominant attractor of every grid point (the one most initial states
reached; ties go to the forward start) and says so, with the fixed values and the initial
states in its caption line.  The palettes are in :mod:`.plots_style` (re-exported here).
"""

from __future__ import annotations

import weakref
from pathlib import Path

import numpy as np
from matplotlib.patches import Patch, Rectangle
from matplotlib.transforms import Bbox

from .plots_style import (
    _OUTCOME_COLOUR,
    BIFURCATIONS,
    BRANCHES,
    CONTACT,
    MESHING_CLASSES,
    MOTION_CLASSES,
    OUTCOMES,
    SWEEPS,
    categorical,
    legend_below,
    motion_class,
    not_ok_marks,
    operating_point,
    period_colour,
    plt,
    put_caption,
    save_figure,
    sweep_marker,
)
from .sweep.maps_result import RegimeMap
from .units import Units, at, parameter_axis, secondary_axis

__all__ = [
    "BIFURCATIONS",
    "BRANCHES",
    "CONTACT",
    "FIGURES",
    "MESHING_CLASSES",
    "MOTION_CLASSES",
    "OUTCOMES",
    "SWEEPS",
    "legend_below",
    "map_figures",
    "motion_class",
    "not_ok_marks",
    "operating_point",
    "period_colour",
    "save_figure",
    "sweep_marker",
    "write_map_figures",
]


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


def _label(ax, m: RegimeMap, ticks: dict | None = None, units: Units | None = None) -> None:
    """Axis names; an unevenly spaced axis gets one tick per value (cells of equal size);
    ``ticks`` names the values of an axis that stands for text (``{axis: [label, ...]}``).
    ``units`` (physical): omega or the speed says the other (``units.parameter_axis``): on
    a top axis for x, in the label for y (the colour bar holds the right side)."""
    ticks = ticks or {}
    for values, name, axis in ((m.x_values, m.x, ax.xaxis), (m.y_values, m.y, ax.yaxis)):
        if name in ticks:
            axis.set_label_text(name)
            axis.set_ticks(np.asarray(values, float), list(ticks[name]))
            continue
        label, top = name, None
        if units is not None:
            label, top = parameter_axis(units, name)
        uneven = _uneven(values)
        if top is not None and axis is ax.yaxis:  # short lines: the axis is 3 inches
            label = f"{label.split(' (')[0]}\n{top[0]} = {top[1](1.0):.5g} × {name}"
        elif top is not None and not uneven:
            secondary_axis(ax, top)
        axis.set_label_text(label + (" (unevenly spaced values)" if uneven else ""))
        if uneven:
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


# figure -> its tight box with the caption (inches), measured when it was captioned, for
# write_map_figures: saving with it skips the layout pass of savefig's "tight" box (a
# third of the cost of saving a map's figure); a figure changed afterwards is not saved
# with it (map_figures' caller gets plain figures)
_BOXES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _captioned(fig, caption: str):
    fig.tight_layout()
    # the caption under everything drawn (axis labels, legends below the axes)
    renderer = fig.canvas.get_renderer()
    box = fig.get_tightbbox(renderer)
    bottom = box.y0 / fig.get_figheight()
    put_caption(fig, bottom - 0.01, caption)
    text = fig.texts[-1].get_window_extent(renderer).transformed(fig.dpi_scale_trans.inverted())
    _BOXES[fig] = Bbox.union([box, text])
    return fig


def _cell_units(m: RegimeMap, system, units: str) -> np.ndarray:
    """(ny, nx) :class:`Units` of the cells (each with its x and y values set)."""
    out = np.empty((len(m.y_values), len(m.x_values)), dtype=object)
    for iy, y in enumerate(m.y_values):
        for ix, x in enumerate(m.x_values):
            out[iy, ix] = at(system, units, {m.x: float(x), m.y: float(y)})
    return out


FIGURES = ("motion", "lyapunov", "attractors", "extremes", "meshing")


def write_map_figures(
    m: RegimeMap,
    folder,
    prefix: str = "map",
    ticks: dict | None = None,
    title: str | None = None,
    kinds: tuple = FIGURES,
    *,
    system=None,
    units: str = "model",
) -> list[Path]:
    """:func:`map_figures` written into ``folder`` as ``<prefix>-<kind>.png``; the paths."""
    figures = map_figures(m, ticks=ticks, title=title, kinds=kinds, system=system, units=units)
    return [
        save_figure(fig, Path(folder) / f"{prefix}-{k}.png", box=_BOXES.pop(fig, None))
        for k, fig in figures.items()
    ]


def map_figures(
    m: RegimeMap,
    *,
    ticks: dict | None = None,
    title: str | None = None,
    kinds: tuple = FIGURES,
    system=None,
    units: str = "model",
) -> dict:
    """The figures of a map, ``{kind: Figure}`` in the order of :data:`FIGURES` (the
    meshing regime only for models with contact edges), each with its caption line;
    nothing is saved (:func:`save_figure`).  ``ticks``: ``{axis: [label per value]}`` for
    an axis whose values stand for text (a load reading, a backlash model); ``title``
    opens the caption instead of the model's name (say what a derived variant is);
    ``kinds``: which of :data:`FIGURES` to write.  Colours: :data:`MOTION_CLASSES` and
    :data:`MESHING_CLASSES` (no colour in both); runs that left the valid range or
    diverged are a class of their own in the categorical maps and hatched in the others.
    ``units="physical"`` (needs ``system``, the map's model): extremes of the mesh
    deflections in µm and the exponent per second, each cell with its own scales; omega or
    the speed with the other (``units.parameter_axis``)."""
    unknown = sorted(set(kinds) - set(FIGURES))
    if unknown:
        raise ValueError(f"kinds: {', '.join(unknown)} unknown; known: {', '.join(FIGURES)}")
    if units == "physical" and system is None:
        raise ValueError("units='physical' needs the map's system (system=)")
    phys = Units.of(system, units) if units == "physical" else None
    cells = _cell_units(m, system, units) if phys else None
    caption = _caption(m, title)
    if phys and not {m.x, m.y} & {"speed_rpm", phys.forcing}:  # else an axis says it
        caption += f"; {phys.operating_point()}"
    elif phys and phys.forcing in (m.x, m.y):
        caption += f"; mesh frequency = {phys.frequency(1.0):.5g} Hz × {phys.forcing}"
    out = {}
    coords, nc = m.coordinates, len(m.coordinates)
    xe, ye = _edges(m.x_values), _edges(m.y_values)
    status = m.grid("status")
    failed = _outcomes(m)

    def categorical_panel(ax, labels, classes, text):
        categorical(ax, xe, ye, labels, classes)
        _label(ax, m, ticks, phys)
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
        out["motion"] = _captioned(fig, caption)

    if "lyapunov" in kinds:
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        lam = m.grid("lyapunov")
        per = "per unit τ"
        if phys:
            lam = lam * np.vectorize(lambda u: u.scales["omega_n_rad_per_s"])(cells)
            per = "per second: per unit τ × ω_n"
        lim = np.nanmax(np.abs(lam)) if np.any(np.isfinite(lam)) else 1.0
        im = ax.pcolormesh(xe, ye, lam, cmap="RdBu_r", vmin=-lim, vmax=lim)
        fig.colorbar(im, ax=ax, label=f"largest Lyapunov exponent ({per})")
        _label(ax, m, ticks, phys)
        _hatch(ax, m, failed, "no exponent")
        ax.set_title("largest Lyapunov exponent (> 0: chaos); blank: no estimate")
        out["lyapunov"] = _captioned(fig, caption)

    if "attractors" in kinds:
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        count = m.grid("attractors")
        top = max(int(np.nanmax(count)), 1)
        cmap = plt.get_cmap("viridis", top + 1)
        im = ax.pcolormesh(xe, ye, count, cmap=cmap, vmin=-0.5, vmax=top + 0.5)
        fig.colorbar(im, ax=ax, ticks=range(0, top + 1), label="attractors found")
        _label(ax, m, ticks, phys)
        _hatch(ax, m, _outcomes(m, every=True), "some starts; not counted")
        ax.set_title(f"attractors found from {m.settings['initial_states']} initial states")
        out["attractors"] = _captioned(fig, _caption(m, title, "all"))

    if "extremes" in kinds:
        fig, axes = plt.subplots(2, nc, figsize=(5.2 * nc, 8), squeeze=False)
        for k, c in enumerate(coords):
            for row, field in enumerate(("max", "min")):
                ax = axes[row][k]
                grid, unit = m.grid(field, c), "/ half backlash"
                if phys:
                    grid = grid * np.vectorize(lambda u, c=c: u.deflection(c, 1.0))(cells)
                    unit = f"in {phys.deflection_unit(c)}"
                im = ax.pcolormesh(xe, ye, grid, cmap="viridis")
                fig.colorbar(im, ax=ax, label=f"{field.capitalize()}({c}) {unit}")
                _label(ax, m, ticks, phys)
                _hatch(ax, m, failed, "extremes up to the exit")
                ax.set_title(f"{field.capitalize()}({c}) over the sampled window")
        out["extremes"] = _captioned(fig, caption)

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
    out["meshing"] = _captioned(fig, caption)
    return out
