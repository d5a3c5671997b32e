"""Matplotlib figures: bifurcation diagrams, time series, spectra, phase portraits, maps.

Every function takes data (a result object of the API) and returns a matplotlib ``Figure``
(Agg back end, no display needed); saving is the caller's choice (:func:`save_figure`).
Axes are labelled with their units: the model's (half backlashes, τ) by default,
``units="physical"`` for µm and the speed in rpm beside omega (``solver/units.py``).
One meaning has one colour in every figure of the package: the palettes are in
:mod:`.plots_style`; markers are at least 3 px, legends sit outside the axes, and a figure
of one operating point says that point (ω̄, loads, backlash model) and its verdict in its title.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .plots_point import point_figure  # noqa: E402
from .plots_style import (  # noqa: E402
    BIFURCATIONS,
    MOTION_CLASSES,
    categorical,
    legend_below,
    motion_class,
    not_ok_marks,
    operating_point,
    period_colour,
    save_figure,
    sweep_marker,
)
from .sweep import SweepResult  # noqa: E402
from .units import Units, parameter_axis, secondary_axis, state_factors, state_unit  # noqa: E402

__all__ = [
    "bifurcation_diagram",
    "branch_figure",
    "map_figure",
    "multipliers_figure",
    "point_figure",
    "save_figure",
]


def _distinct(pts: np.ndarray, lo: float, cell: float) -> np.ndarray:
    """A periodic orbit's points repeat: each place once (closer than ``cell``: one)."""
    pts = pts[np.isfinite(pts)]
    _, first = np.unique(np.round((pts - lo) / cell), return_index=True)
    return pts[np.sort(first)]


def bifurcation_diagram(
    sweeps: list[SweepResult],
    states: list[str],
    title: str = "",
    *,
    system=None,
    units: str = "model",
):
    """Poincaré points of each state against the swept parameter, one panel per state.

    Forward and backward sweeps are both visible where they agree: the backward sweep's
    points are open circles (6 px across) drawn first, the forward sweep's filled dots
    (3.5 px) on top; hysteresis shows as rings and dots apart.  Points whose run did not
    end normally (diverged, left the valid range) are crosses on the panel's lower edge.
    Behind a mesh coordinate's points: the range its runs covered over their sampled
    periods (the forward sweep's, a light band) and the contact edges (dashed), so that
    teeth parting between two Poincaré points shows.
    ``system``: the model the sweeps ran on; the title then states ω̄ and the loads (from
    the sweep's first to its last value).  ``units``: ``model`` (half backlashes, and per
    unit τ for velocities) or ``physical`` (needs ``system``: deflections in µm, with the
    half backlash at each value; omega or the speed with the other on a top axis).
    """
    if units == "physical" and system is None:
        raise ValueError("units='physical' needs the system the sweeps ran on (system=)")
    fig, axes = plt.subplots(
        len(states), 1, figsize=(7.5, 2.8 * len(states)), sharex=True, squeeze=False
    )
    order = sorted(sweeps, key=lambda sw: sw.direction != "backward")  # backward first
    for ax, state in zip(axes[:, 0], states, strict=True):
        finite = [p[np.isfinite(p)] for sw in sweeps for p in sw.poincare(state)]
        finite = np.concatenate(finite) if finite else np.zeros(0)
        lo = finite.min() if finite.size else 0.0
        cell = max(float(np.ptp(finite)) if finite.size else 0.0, 1e-12) * 1e-4
        if sweeps:  # where the state went between its Poincaré points, and the contact edges
            _range_and_edges(ax, order[-1], state, system, units)
        for sw in order:
            xs, ys = [], []
            scale, unit = state_factors(system, units, sw.parameter, sw.values, state)
            for value, pts, k in zip(sw.values, sw.poincare(state), scale, strict=True):
                pts = _distinct(np.asarray(pts, float), lo, cell)
                xs.append(np.full(pts.size, value))
                ys.append(pts * k)
            ax.plot(
                np.concatenate(xs) if xs else [],
                np.concatenate(ys) if ys else [],
                ls="none",
                label=f"{sw.direction} sweep",
                **sweep_marker(sw.direction),
            )
            not_ok_marks(ax, sw.values, [p.status for p in sw.points])
        ax.set_ylabel(f"{state} (Poincaré), {unit}" if sweeps else state)
        ax.grid(alpha=0.3)
    _parameter_axis(axes, system, units, sweeps[0].parameter if sweeps else "")
    head = title
    if system is not None:
        head += ("\n" if head else "") + operating_point(
            system, sweeps[0].parameter, sweeps[0].values
        )
    if head:
        axes[0, 0].set_title(head, fontsize=10)
    legend_below(fig, axes.ravel())
    return fig


def _range_and_edges(ax, sw: SweepResult, state: str, system, units: str) -> None:
    """Behind a mesh coordinate's Poincaré points (``system`` given): its range over each
    run's sampled periods, a light bar at the run's value (the teeth part where it crosses
    an edge between two Poincaré points; nothing is drawn between runs), and the model's
    contact edges, dashed, in the panel's units."""
    if system is None or state not in system.coordinates:
        return
    scale, _ = state_factors(system, units, sw.parameter, sw.values, state)
    ax.vlines(
        sw.values,
        sw.minima(state) * scale,
        sw.maxima(state) * scale,
        color="0.8",
        lw=3,
        zorder=0,
        label=f"range of each {sw.direction} sweep run over its sampled periods",
    )
    polynomial = system.backlash == "polynomial"
    for n, edge in enumerate(system.contract.contact.get(state, ())):
        label = (
            "backlash edges ±b (the polynomial fit carries load inside them)"
            if polynomial
            else "contact edges ±b (teeth touch beyond them)"
        )
        ax.plot(
            sw.values,
            edge * scale,
            ls="--",
            lw=0.8,
            color="grey",
            zorder=1,
            label=None if n else label,
        )


def _parameter_axis(axes, system, units: str, name: str) -> None:
    """The bottom panel's x label in ``units``; a physical omega or speed gets the other
    on the top panel's secondary axis (``units.parameter_axis``)."""
    if system is None:
        axes[-1, 0].set_xlabel(name)
        return
    label, top = parameter_axis(Units.of(system, units), name)
    axes[-1, 0].set_xlabel(label)
    secondary_axis(axes[0, 0], top)


def map_figure(
    f_values,
    lam_values,
    max_u,
    min_v,
    motion_v,
    title: str = "",
    *,
    names: tuple[str, str, str, str],
):
    """Maps over two parameters (``names[0]`` on the y axis, ``names[1]`` on x): the max of
    state ``names[2]``, the min of state ``names[3]`` (half backlashes) and the motion
    type of ``names[3]`` in the package's motion palette (:data:`MOTION_CLASSES`)."""
    fig, axes = plt.subplots(1, 3, figsize=(16, 4))

    def edges(v):  # cells centred on the sampled values
        v = np.asarray(v, dtype=float)
        if v.size == 1:
            return np.array([v[0] - 0.5, v[0] + 0.5])
        mid = (v[1:] + v[:-1]) / 2
        return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])

    xe, ye = edges(lam_values), edges(f_values)
    for ax, data, label in (
        (axes[0], max_u, f"Max({names[2]}) (half backlashes)"),
        (axes[1], min_v, f"Min({names[3]}) (half backlashes)"),
    ):
        im = ax.pcolormesh(xe, ye, np.asarray(data, float), cmap="viridis")
        fig.colorbar(im, ax=ax, label=label)
        ax.set_xlabel(names[1])
        ax.set_ylabel(names[0])
        ax.set_title(label.split(" (")[0])
    labels = np.vectorize(motion_class)(np.asarray(motion_v, dtype=object))
    categorical(axes[2], xe, ye, labels, MOTION_CLASSES)
    axes[2].set_xlabel(names[1])
    axes[2].set_ylabel(names[0])
    axes[2].set_title(f"motion of {names[3]}")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def _drawable(branches) -> tuple[list, list]:
    """Branches with an extent in the parameter, and those without (a continuation asked
    to go from a value to itself returns its start twice: nothing to draw)."""
    keep, empty = [], []
    for br in branches:
        lam = np.asarray(br.values, float)
        (keep if lam.size > 1 and np.ptp(lam) > 0 else empty).append(br)
    return keep, empty


def branch_figure(
    branches, state=None, sweeps=None, title: str = "", *, system=None, units: str = "model"
):
    """Continuation branches over the brute-force diagram: stable solid, unstable dashed,
    bifurcations marked; the Poincaré points of brute-force sweeps behind them (in the
    sweeps' palette).

    ``state``: one state name (one panel), a sequence of names (one panel each: a jump
    may show in one coordinate only), or None (the branches' first state).  One legend
    for the figure, below it.  Branches without extent in the parameter are not drawn
    and the title says how many.  ``system``: the model, for ω̄ and loads in the title.
    ``units``: as :func:`bifurcation_diagram`'s (``physical`` needs ``system``).
    """
    if units == "physical" and system is None:
        raise ValueError("units='physical' needs the system the branches belong to (system=)")
    drawn, empty = _drawable(branches)
    if state is None:
        state = branches[0].state_names[0] if branches else "x"
    names = [state] if isinstance(state, str) else list(state)
    fig, axes = plt.subplots(
        len(names), 1, figsize=(8.5, 3.6 * len(names)), sharex=True, squeeze=False
    )
    for ax, name in zip(axes[:, 0], names, strict=True):
        for sw in sorted(sweeps or [], key=lambda sw: sw.direction != "backward"):
            xs, ys = [], []
            scale, _ = state_factors(system, units, sw.parameter, sw.values, name)
            for value, pts, k in zip(sw.values, sw.poincare(name), scale, strict=True):
                xs.append(np.full(np.size(pts), value))
                ys.append(np.asarray(pts, float) * k)
            if xs:
                style = sweep_marker(sw.direction) | {"alpha": 0.5}
                label = f"brute force, {sw.direction} sweep (Poincaré points)"
                ax.plot(np.concatenate(xs), np.concatenate(ys), ls="none", label=label, **style)
        for br in drawn:
            index = br.state_names.index(name)
            lam = np.asarray(br.values)
            scale, _ = state_factors(system, units, br.parameter, lam, name)
            y = np.array([s[index] for s in br.states]) * scale
            stable = np.asarray(br.stable)
            for flag, style in ((True, "-"), (False, "--")):
                if not np.any(stable == flag):
                    continue  # no legend entry for a kind of point the branch does not have
                ax.plot(
                    lam,
                    np.where(stable == flag, y, np.nan),
                    style,
                    color=period_colour(br.n),
                    lw=1.4,
                    label=f"period-{br.n} {'stable' if flag else 'unstable'} (continuation)",
                )
            for b in br.bifurcations:
                marker, colour = BIFURCATIONS[br.named(b)]
                k = state_factors(system, units, br.parameter, [b.value], name)[0][0]
                ax.plot(b.value, b.x0[index] * k, marker, color=colour, ms=7, mfc="none", mew=1.5)
                ax.plot([], [], marker, color=colour, ms=7, mfc="none", mew=1.5, label=br.named(b))
        unit = state_unit(system, units, name) or "half backlashes"
        ax.set_ylabel(f"{name} at τ = 0 mod nT\n({unit})")
        ax.grid(alpha=0.3)
    _parameter_axis(axes, system, units, branches[0].parameter if branches else "")
    head = [title] if title else []
    if system is not None and drawn:
        span = np.concatenate([np.asarray(br.values, float) for br in drawn])
        head.append(operating_point(system, drawn[0].parameter, span))
    if empty:
        head.append(
            f"{len(empty)} branch(es) without extent in the parameter not drawn "
            "(continued from a value to itself)"
        )
    if head:
        axes[0, 0].set_title("\n".join(head), fontsize=10)
    legend_below(fig, axes.ravel())
    return fig


def multipliers_figure(multipliers, title: str = ""):
    """Floquet multipliers in the complex plane with the unit circle."""
    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    th = np.linspace(0, 2 * np.pi, 400)
    ax.plot(np.cos(th), np.sin(th), color="0.5", lw=0.8, label="|μ| = 1")
    mu = np.asarray(multipliers)
    ax.plot(mu.real, mu.imag, "x", ms=8, mew=1.5, color="#e6550d", label="multipliers")
    ax.set_aspect("equal")
    ax.axhline(0, color="0.8", lw=0.5)
    ax.axvline(0, color="0.8", lw=0.5)
    ax.set_xlabel("Re μ")
    ax.set_ylabel("Im μ")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    if title:
        ax.set_title(title, fontsize=9)
    return fig
