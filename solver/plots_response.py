"""The frequency-response figure: amplitude (half peak-to-peak) of every mesh coordinate
against the parameter, stable branches solid and unstable dashed, one colour per method,
folds (where a sweep jumps) and other stability changes marked, the up and down sweeps of
time integration as triangles."""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .plots_style import BIFURCATIONS, SWEEPS, legend_below  # noqa: E402

__all__ = ["METHODS", "event_point", "frequency_response_figure", "mesh_response_figure"]

METHODS = {"hb": "#1b9e77", "shooting": "#7570b3"}  # one colour per method, every figure
_NAMES = {"hb": "harmonic balance", "shooting": "shooting", "integration": "integration"}
# the up and down sweeps of time integration: the sweeps' palette, triangles pointing
# the way the sweep went
_SWEPT = {"up": ("forward", "^"), "down": ("backward", "v")}


def event_point(values, e) -> int:
    """The curve point an event is drawn at: of the two points it lies between, the one
    nearer its parameter value (a fold has two sides at nearly one value, so the nearest
    value over the whole curve would not do; the point before it alone sat a grid step
    along the curve from a sharp fold, off its turn)."""
    values = np.asarray(values, dtype=float)
    if e.index < 0:
        return int(np.argmin(np.abs(values - e.value)))
    around = [k for k in (e.index - 1, e.index) if 0 <= k < len(values)]
    if not around:
        return len(values) - 1
    return min(around, key=lambda k: abs(values[k] - e.value))


def _segments(x, y, stable):
    """Runs of equal stability, each sharing its end point with the next (no gaps)."""
    start = 0
    for k in range(1, len(x) + 1):
        if k == len(x) or stable[k] != stable[start]:
            stop = min(k + 1, len(x))
            yield x[start:stop], y[start:stop], bool(stable[start])
            start = k


def frequency_response_figure(resp, physical: bool = False, title: str = ""):
    """One panel per mesh coordinate of a :class:`~.sweep.frequency.FrequencyResponse`;
    returns the ``Figure`` (nothing saved).  ``physical``: the dynamic transmission
    error's amplitude in µm (with the half backlash at each value of the parameter), over
    the mesh frequency in Hz where the parameter is the forcing frequency (or a model's
    own mesh frequency in Hz: a planetary set's or a train's ``mesh_frequency_hz``), over
    the speed in rpm with the mesh frequency on a top axis where it is ``speed_rpm``, and
    over any other parameter as it is."""
    from .units import Units, parameter_axis, secondary_axis, state_factors

    system = resp.system
    coords = system.coordinates
    scales = system.scales()
    forcing = system.contract.forcing_frequency
    # a model's own name for the forcing frequency in Hz (a planetary set's or a train's
    # mesh_frequency_hz): the axis is Hz already
    in_hz = getattr(system.module, "PHYSICAL", {}).get(resp.parameter) == forcing
    hz = physical and resp.parameter == forcing
    fx = scales["omega_n_rad_per_s"] / (2 * math.pi) if hz else 1.0
    xlabel, top = resp.parameter, None
    if hz or (physical and in_hz):
        xlabel = "mesh frequency (Hz)"
    elif physical:
        xlabel, top = parameter_axis(Units.of(system, "physical"), resp.parameter)
    kind = "physical" if physical else "model"
    fig, axes = plt.subplots(
        len(coords), 1, figsize=(8, 3.2 * len(coords)), sharex=True, squeeze=False
    )
    for ax, c in zip(axes[:, 0], coords, strict=True):
        unit = "half backlashes"
        for curve in resp.curves:
            x = curve.values * fx
            fy, unit = state_factors(system, kind, resp.parameter, curve.values, c)
            y = curve.stats[c]["amplitude"] * fy
            colour = METHODS.get(curve.method, "k")
            if curve.method == "integration":
                way = "up" if curve.details.get("direction") == "up" else "down"
                direction, marker = _SWEPT[way]
                ax.plot(
                    x,
                    y,
                    marker,
                    color=SWEEPS[direction]["color"],
                    ms=4,
                    mfc="none",
                    lw=0,
                    label=f"integration, {way} sweep",
                )
                continue
            shown = set()
            for xs, ys, st in _segments(x, y, curve.stable):
                label = f"{_NAMES[curve.method]}, {'stable' if st else 'unstable'}"
                ax.plot(
                    xs,
                    ys,
                    "-" if st else "--",
                    color=colour,
                    lw=1.3 if st else 1.0,
                    label=None if label in shown else label,
                )
                shown.add(label)
            for e in curve.events:
                marker, mc = BIFURCATIONS.get(e.name, ("x", "k"))
                v = e.value
                k = event_point(curve.values, e)
                ax.plot(
                    v * fx,
                    y[k],
                    marker,
                    color=mc,
                    ms=6,
                    mfc="none",
                    label=f"{e.name}" + (" (a sweep jumps here)" if e.jump else ""),
                )
        ax.set_ylabel(f"half peak-to-peak of {c} ({unit})")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel(xlabel)
    secondary_axis(axes[0, 0], top)
    if title:
        axes[0, 0].set_title(title, fontsize=10)
    legend_below(fig, axes.ravel())  # one legend: each entry once, not once per panel
    return fig


def mesh_response_figure(resp: dict):
    """A planetary set's mesh frequency response (``gearsym.planetary.mesh_response``): one
    panel per kind of mesh, the largest and smallest deflection over its meshes (half
    backlashes) against the mesh frequency, the up sweep and the down sweep; the teeth
    apart (``|u| <= 1``) shaded grey, the frequencies where a mesh of the panel's kind
    separates shaded red, and each resonance ``l f_mesh = f_k`` of a natural frequency
    with the stiffness variation's harmonics dotted (labelled ``f_k/l`` where there is
    room).  Returns the
    ``Figure`` (nothing saved)."""
    kinds = [k for k in ("sun-planet", "ring-planet") if k in resp["up"]]
    f = np.asarray(resp["frequencies_hz"])
    fig, axes = plt.subplots(len(kinds), 1, figsize=(8, 3.2 * len(kinds)), sharex=True)
    axes = np.atleast_1d(axes)
    step = (f[1] - f[0]) / 2 if f.size > 1 else 0.0
    for ax, kind in zip(axes, kinds, strict=True):
        seen = []
        for direction in ("up", "down"):
            style, marker = _SWEPT[direction]
            row = resp[direction][kind]
            for key, ls in (("u_max", "-"), ("u_min", "--")):
                y = np.array([np.nan if v is None else v for v in row[key]], dtype=float)
                seen.append(y)
                ax.plot(
                    f,
                    y,
                    ls,
                    marker=marker,
                    ms=3,
                    lw=1.0,
                    color=SWEEPS[style]["color"],
                    label=f"{'largest' if key == 'u_max' else 'smallest'} deflection, "
                    f"{direction} sweep",
                )
        data = np.concatenate(seen)
        lo, hi = np.nanmin(data), np.nanmax(data)
        pad = 0.1 * max(hi - lo, 0.02)
        ax.set_ylim(min(lo - pad, 1.0 - pad), hi + pad)
        ax.axhspan(-1.0, 1.0, color="0.85", zorder=0, label="|u| <= 1: the teeth apart")
        for a, b in resp.get("band_hz_by_kind", {}).get(kind, resp["band_hz"]):
            ax.axvspan(
                a - step,
                b + step,
                color="#d62728",
                alpha=0.15,
                zorder=0,
                label="a mesh of this kind separates (either sweep)",
            )
        for r in resp.get("resonances", ()):
            ax.axvline(r["mesh_hz"], color="0.5", ls=":", lw=0.7, zorder=0)
        ax.set_ylabel(f"{kind} mesh deflection\n(half backlashes)")
        ax.grid(alpha=0.3)
    room, last = 0.025 * (f[-1] - f[0]), -np.inf
    for r in resp.get("resonances", ()):
        if r["mesh_hz"] - last < room:
            continue
        last = r["mesh_hz"]
        axes[0].annotate(
            f"{r['natural_hz']:.0f}/{r['harmonic']}",
            (r["mesh_hz"], 1.0),
            xycoords=("data", "axes fraction"),
            rotation=90,
            fontsize=7,
            va="bottom",
            ha="center",
            color="0.3",
        )
    axes[-1].set_xlabel("mesh frequency (Hz)")
    runs = resp["runs"]
    legend_below(
        fig,
        axes,
        f"{resp['model']}: sun force {resp['sun_force_N']:.4g} N; each point "
        f"{runs['transient']} + {runs['periods']} mesh periods from the previous point's end "
        "(the first from the loaded equilibrium); dotted: a natural frequency over a "
        "harmonic of the stiffness variation (Hz/l, every mesh in contact)",
    )
    return fig
