"""Figures a gear-dynamics reader expects beside the bifurcation diagrams: meshing state
and largest Lyapunov exponent against lambda, the backlash polynomial against the dead zone,
and the mesh stiffness of both meshes with their phase."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = [
    "backlash_figure",
    "floquet_figure",
    "response_figure",
    "stiffness_figure",
    "sweep_state_figure",
]


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _caption(fig, text: str) -> None:
    fig.text(0.01, 0.01, text, fontsize=7, ha="left", va="bottom")


def sweep_state_figure(sweeps, path: Path, title: str, caption: str) -> Path:
    """Share of the sampled window each mesh spends in forward contact, separated and in
    backward contact, and the largest Lyapunov exponent with its uncertainty, against
    lambda, for the forward and backward sweeps."""
    plt = _plt()
    coords = list(sweeps[0].points[0].classification)
    fig, axes = plt.subplots(1, len(coords) + 1, figsize=(5 * (len(coords) + 1), 4.2))
    colors = {"forward": "tab:green", "separated": "tab:gray", "backward": "tab:red"}
    for ax, c in zip(axes, coords, strict=False):
        for sw, style in zip(sweeps, ("-", "--"), strict=False):
            lam = np.array(sw.values, float)
            for state, col in colors.items():
                share = [p.meshing_states.get(c, {}).get(state, np.nan) for p in sw.points]
                ax.plot(lam, share, style, color=col, label=f"{state} ({sw.direction} sweep)")
        ax.set_xlabel("lambda")
        ax.set_ylabel(f"share of time, mesh {c}")
        ax.set_ylim(-0.02, 1.02)
        ax.set_title(f"meshing state of {c} (|{c}| ≤ 1: separated)")
        ax.legend(fontsize=7)
    ax = axes[-1]
    for sw, mark in zip(sweeps, ("o", "s"), strict=False):
        lam = np.array(sw.values, float)
        exp = [np.nan if p.lyapunov is None else p.lyapunov["exponent"] for p in sw.points]
        err = [
            np.nan if p.lyapunov is None else p.lyapunov.get("uncertainty", np.nan)
            for p in sw.points
        ]
        ax.errorbar(lam, exp, yerr=err, fmt=mark, ms=3, capsize=2, label=f"{sw.direction} sweep")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_xlabel("lambda")
    ax.set_ylabel("largest Lyapunov exponent (per unit τ)")
    ax.set_title("> 0: chaos; bars: estimated uncertainty")
    ax.legend(fontsize=7)
    fig.suptitle(title)
    _caption(fig, caption)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def backlash_figure(system, path: Path, caption: str) -> Path:
    """The model's backlash polynomial g(x) against the exact dead zone, contact edges
    x = ±1 and the polynomial's valid range marked."""
    plt = _plt()
    g = [system.parameter(k) for k in ("g1", "g3", "g5", "g7")]
    x = np.linspace(-3.2, 3.2, 641)
    poly = g[0] * x + g[1] * x**3 + g[2] * x**5 + g[3] * x**7
    dead = np.where(x > 1, x - 1, np.where(x < -1, x + 1, 0.0))
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ax.plot(x, dead, "k-", label="dead zone (exact, unit half backlash)")
    ax.plot(x, poly, "tab:blue", label="7th-order polynomial g(x) of the model")
    for edge in (-1, 1):
        ax.axvline(edge, color="tab:red", ls=":", lw=1)
    ax.axvline(-1, color="tab:red", ls=":", lw=1, label="contact edges x = ±1")
    ax.axvspan(-3.2, -3.0, color="0.85")
    ax.axvspan(3.0, 3.2, color="0.85", label="outside the fit's valid range |x| ≤ 3")
    ax.set_xlabel("x (deflection / half backlash)")
    ax.set_ylabel("g(x)")
    ax.set_title(f"backlash: g'(0) = {g[0]:.3f} < 0 (unloaded origin unstable)")
    ax.legend(fontsize=8)
    _caption(fig, caption)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


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
    ax.legend(fontsize=8)
    _caption(fig, caption)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def floquet_figure(branches, path: Path, title: str, caption: str) -> Path:
    """Moduli of the Floquet multipliers along each continued branch against lambda (the
    orbit is stable while all lie inside the unit circle), and the bifurcations found."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, br in enumerate(branches):
        if not br.multipliers:
            continue
        lam = np.array(br.values, float)
        mods = np.sort(np.abs(np.array([np.asarray(m) for m in br.multipliers])), axis=1)
        col = colors[k % len(colors)]
        for j in range(mods.shape[1]):
            label = f"branch {k + 1} (period-{br.n}), all multipliers" if j == 0 else None
            ax.plot(lam, mods[:, j], ".", ms=2.5, color=col, label=label)
        for b in br.bifurcations:
            ax.axvline(float(b.value), color=col, ls=":", lw=0.8)
    ax.axhline(1.0, color="k", lw=1, label="|μ| = 1 (unit circle)")
    ax.set_yscale("log")
    ax.set_xlabel("lambda")
    ax.set_ylabel("|Floquet multiplier|")
    ax.set_title(title + "; dotted: bifurcations located")
    ax.legend(fontsize=7)
    _caption(fig, caption)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def response_figure(responses: dict, path: Path, title: str, caption: str, mark: float) -> Path:
    """Amplitude (half peak-to-peak) of each mesh coordinate over the forcing frequency,
    one colour per load ratio, stable solid and unstable dashed, folds marked, the
    study's operating frequency ``mark`` as a vertical line."""
    from gearsym.solver.plots_response import _segments

    plt = _plt()
    first = next(iter(responses.values()))
    coords = first.system.coordinates
    fig, axes = plt.subplots(
        len(coords), 1, figsize=(10, 3.0 * len(coords) + 0.6), sharex=True, squeeze=False
    )
    for ax, c in zip(axes[:, 0], coords, strict=True):
        for k, (lam, resp) in enumerate(responses.items()):
            curve = resp.curves[0]
            x, y, st = curve.values, curve.stats[c]["amplitude"], curve.stable
            colour = f"C{k}"
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
                if e.kind == "fold":
                    i = min(max(e.index - 1, 0), len(x) - 1)
                    ax.plot(
                        e.value,
                        y[i],
                        "s",
                        color="tab:red",
                        mfc="none",
                        ms=6,
                        label="fold (a slow sweep jumps here)",
                    )
        ax.axvline(mark, color="0.3", lw=0.8, ls=":", label=f"the study's ω̄ = {mark}")
        ax.set_ylabel(f"half peak-to-peak of {c}\n(half backlashes)")
        ax.grid(alpha=0.3)
        handles, labels = ax.get_legend_handles_labels()
        unique = dict(zip(labels, handles, strict=True))
        ax.legend(
            unique.values(),
            unique.keys(),
            fontsize=7,
            loc="upper left",
            bbox_to_anchor=(1.01, 1.0),
            frameon=False,
        )
    axes[-1, 0].set_xlabel("ω̄ (mesh frequency over ω_n)")
    axes[0, 0].set_title(title, fontsize=10)
    fig.text(0.01, 0.005, caption, fontsize=7, ha="left", va="bottom", wrap=True)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
