"""Matplotlib figures: bifurcation diagrams, time series, spectra, phase portraits, maps.

Every function takes data and a path, writes one PNG (Agg back end, no display needed) and
returns the path.  Axes are labelled with their (non-dimensional) units.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .analysis import spectrum  # noqa: E402
from .integrate import Trajectory  # noqa: E402
from .sweep import SweepResult  # noqa: E402

__all__ = ["bifurcation_diagram", "map_figure", "point_figure"]

PORTRAIT_PERIODS = 500  # periods a phase portrait draws at most

_COLOURS = {"forward": "tab:blue", "backward": "tab:orange", "independent": "tab:blue"}


def _save(fig, path: Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def bifurcation_diagram(
    sweeps: list[SweepResult], states: list[str], path: Path, title: str = ""
) -> Path:
    """Poincare points of each state against the swept parameter, one panel per state;
    forward and backward continuation overlaid (hysteresis shows as two colours apart)."""
    fig, axes = plt.subplots(
        len(states), 1, figsize=(7, 2.8 * len(states)), sharex=True, squeeze=False
    )
    for ax, state in zip(axes[:, 0], states, strict=True):
        finite = [p[np.isfinite(p)] for sw in sweeps for p in sw.poincare(state)]
        finite = np.concatenate(finite) if finite else np.zeros(0)
        lo = finite.min() if finite.size else 0.0
        cell = max(float(np.ptp(finite)) if finite.size else 0.0, 1e-12) * 1e-4
        for sw in sweeps:
            xs, ys = [], []
            for value, pts in zip(sw.values, sw.poincare(state), strict=True):
                # a periodic orbit's points repeat: draw each place once (points closer
                # than 1e-4 of the panel's height, far below a pixel, are one place)
                pts = pts[np.isfinite(pts)]
                _, first = np.unique(np.round((pts - lo) / cell), return_index=True)
                pts = pts[np.sort(first)]
                xs.append(np.full(pts.size, value))
                ys.append(pts)
            ax.plot(
                np.concatenate(xs),
                np.concatenate(ys),
                ".",
                markersize=1.5,
                alpha=1.0,
                color=_COLOURS[sw.direction],
                label=f"{sw.direction} sweep",
            )
        ax.set_ylabel(f"{state} (Poincaré), half backlashes")
        ax.grid(alpha=0.3)
    axes[0, 0].legend(loc="best", markerscale=6, fontsize=8)
    axes[-1, 0].set_xlabel(sweeps[0].parameter)
    if title:
        axes[0, 0].set_title(title)
    return _save(fig, path)


def point_figure(tr: Trajectory, path: Path, title: str = "", periods_shown: int = 20) -> Path:
    """One operating point: time series, phase portrait with Poincare points, and spectrum
    of each mesh coordinate (one row per coordinate)."""
    coords = tr.system.coordinates
    fig, axes = plt.subplots(len(coords), 3, figsize=(13, 3.2 * len(coords)), squeeze=False)
    spp = tr.samples_per_period
    shown = slice(max(0, tr.t.size - periods_shown * spp), None)
    for row, c in enumerate(coords):
        u, du = tr.coordinate(c), tr.velocity(c)
        ax = axes[row, 0]
        ax.plot(tr.t[shown], u[shown], lw=0.8)
        for edge in tr.system.contract.contact.get(c, ()):
            ax.axhline(edge, color="grey", lw=0.6, ls="--")
        ax.set_xlabel("τ (non-dimensional time)")
        ax.set_ylabel(f"{c} (half backlashes)")
        ax.set_title(f"{c}: time series (last {periods_shown} periods)", fontsize=9)
        ax = axes[row, 1]
        # at most the last PORTRAIT_PERIODS periods (a path of every sample of a long run
        # takes matplotlib gigabytes); the Poincare points likewise
        tail = slice(max(0, tr.t.size - PORTRAIT_PERIODS * spp), None)
        ax.plot(u[tail], du[tail], lw=0.3, color="tab:blue", alpha=0.6)
        ax.plot(
            tr.poincare[tr.system.index(c)][-PORTRAIT_PERIODS:],
            tr.poincare[tr.system.velocity_index(c)][-PORTRAIT_PERIODS:],
            "o",
            ms=2.5,
            color="tab:red",
            label="Poincaré",
        )
        ax.set_xlabel(c)
        ax.set_ylabel(f"d{c}/dτ")
        shown_periods = min(PORTRAIT_PERIODS, tr.poincare.shape[1])
        ax.set_title(f"{c}: phase portrait (last {shown_periods} periods)", fontsize=9)
        ax.legend(fontsize=7, loc="upper right")
        ax = axes[row, 2]
        sp = spectrum(tr, c)
        keep = sp.frequency <= 6 * sp.omega
        ax.semilogy(sp.frequency[keep], np.maximum(sp.amplitude[keep], 1e-8), lw=0.8)
        ax.set_xlabel("frequency (rad per unit τ)")
        ax.set_ylabel("amplitude")
        ax.set_title(f"{c}: spectrum (ω̄ = {sp.omega:g})", fontsize=9)
        ax.grid(alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return _save(fig, path)


_MOTION_CODES = {
    "period-1": 1,
    "period-n": 2,
    "quasi-periodic": 3,
    "chaotic": 4,
    "undetermined": 5,
    "divergent": 6,
}


def motion_code(motion: str) -> int:
    if motion.startswith("period-") and motion != "period-1":
        return _MOTION_CODES["period-n"]
    return _MOTION_CODES.get(motion, 5)


def map_figure(
    f_values,
    lam_values,
    max_u,
    min_v,
    motion_v,
    path: Path,
    title: str = "",
    *,
    names: tuple[str, str, str, str],
) -> Path:
    """Maps over two parameters (``names[0]`` on the y axis, ``names[1]`` on x): the max of
    state ``names[2]``, the min of state ``names[3]`` and the motion type of ``names[3]``."""
    fig, axes = plt.subplots(1, 3, figsize=(15, 4))

    # Cells centred on the sampled values.
    def edges(v):
        v = np.asarray(v, dtype=float)
        half = (v[1] - v[0]) / 2 if v.size > 1 else 0.5
        return v[0] - half, v[-1] + half

    extent = [*edges(lam_values), *edges(f_values)]
    for ax, data, label in (
        (axes[0], max_u, f"Max({names[2]})"),
        (axes[1], min_v, f"Min({names[3]})"),
    ):
        im = ax.imshow(np.asarray(data), origin="lower", aspect="auto", extent=extent)
        fig.colorbar(im, ax=ax, label=label)
        ax.set_xlabel(names[1])
        ax.set_ylabel(names[0])
        ax.set_title(label)
    codes = np.vectorize(motion_code)(np.asarray(motion_v))
    cmap = matplotlib.colors.ListedColormap(
        ["tab:green", "tab:olive", "tab:blue", "tab:red", "lightgrey", "black"]
    )
    im = axes[2].imshow(
        codes, origin="lower", aspect="auto", extent=extent, cmap=cmap, vmin=0.5, vmax=6.5
    )
    cbar = fig.colorbar(im, ax=axes[2], ticks=range(1, 7))
    cbar.ax.set_yticklabels(
        ["period-1", "period-n", "quasi-periodic", "chaotic", "undetermined", "divergent"]
    )
    axes[2].set_xlabel(names[1])
    axes[2].set_ylabel(names[0])
    axes[2].set_title(f"motion of {names[3]}")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return _save(fig, path)


def branch_figure(
    branches, path: Path, state: str | None = None, sweeps=None, title: str = ""
) -> Path:
    """Continuation branches over the brute-force diagram: stable solid, unstable dashed,
    bifurcations marked; Poincare points of brute-force sweeps in the background."""
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for sw in sweeps or []:
        xs, ys = [], []
        for value, pts in zip(sw.values, sw.poincare(state), strict=True):
            xs.append(np.full(np.size(pts), value))
            ys.append(np.asarray(pts))
        if xs:
            ax.plot(
                np.concatenate(xs),
                np.concatenate(ys),
                ".",
                markersize=2,
                color="0.6",
                label="brute force ("
                + " and ".join(dict.fromkeys(w.direction for w in sweeps))
                + ")"
                if sw is sweeps[0]
                else None,
            )
    markers = {
        "fold": ("s", "tab:red"),
        "period-doubling": ("D", "tab:purple"),
        "neimark-sacker": ("o", "tab:green"),
    }
    if state is None and branches:
        state = branches[0].state_names[0]
    # One colour per period: branches of the same period share their legend entry.
    colours = {n: f"C{i}" for i, n in enumerate(sorted({br.n for br in branches}))}
    for br in branches:
        index = br.state_names.index(state)
        lam = np.asarray(br.values)
        y = np.array([s[index] for s in br.states])
        stable = np.asarray(br.stable)
        colour = colours[br.n]
        for flag, style in ((True, "-"), (False, "--")):
            if not np.any(stable == flag):
                continue  # no legend entry for a kind of point the branch does not have
            yy = np.where(stable == flag, y, np.nan)
            ax.plot(
                lam,
                yy,
                style,
                color=colour,
                lw=1.4,
                label=f"period-{br.n} {'stable' if flag else 'unstable'}",
            )
        for b in br.bifurcations:
            m, c = markers[b.kind]
            ax.plot(b.value, b.x0[index], m, color=c, ms=7, label=b.kind)
    handles, labels = ax.get_legend_handles_labels()
    seen: dict = {}
    for label, handle in zip(labels, handles, strict=True):
        seen.setdefault(label, handle)
    ax.legend(seen.values(), seen.keys(), fontsize=8, loc="best")
    ax.set_xlabel(branches[0].parameter if branches else "")
    ax.set_ylabel(f"{state} at τ = 0 mod nT (half backlashes)")
    ax.grid(alpha=0.3)
    if title:
        ax.set_title(title)
    return _save(fig, path)


def multipliers_figure(multipliers, path: Path, title: str = "") -> Path:
    """Floquet multipliers in the complex plane with the unit circle."""
    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    th = np.linspace(0, 2 * np.pi, 400)
    ax.plot(np.cos(th), np.sin(th), color="0.5", lw=0.8)
    mu = np.asarray(multipliers)
    ax.plot(mu.real, mu.imag, "x", ms=8, color="tab:red")
    ax.set_aspect("equal")
    ax.axhline(0, color="0.8", lw=0.5)
    ax.axvline(0, color="0.8", lw=0.5)
    ax.set_xlabel("Re μ")
    ax.set_ylabel("Im μ")
    if title:
        ax.set_title(title, fontsize=9)
    return _save(fig, path)
