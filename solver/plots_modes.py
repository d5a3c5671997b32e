"""The resonance (Campbell) diagram of a model's modes against its mesh frequency."""

from __future__ import annotations

import numpy as np

from .analysis.modes import Modes
from .plots_style import plt

__all__ = ["campbell_figure"]

_STYLE = {
    "torsional": ("tab:blue", "-"),
    "translational": ("tab:green", "--"),
    "axial": ("tab:purple", "-."),
    "coupled": ("tab:red", ":"),
}


def campbell_figure(
    result: Modes,
    speeds_rpm: tuple[float, float],
    harmonics: int = 3,
    scene_rpm: float | None = None,
):
    """Natural frequencies (flat: no speed dependence in this model) and the mesh-frequency
    harmonics ``h z n / 60`` against the reference driver's speed (rpm, from
    ``speeds_rpm[0]`` to ``speeds_rpm[1]``); a dot where they meet.  ``result``: a
    :class:`~.analysis.modes.Modes`; returns the ``Figure`` (nothing saved)."""
    fig, ax = plt.subplots(figsize=(8, 5))
    n = np.linspace(speeds_rpm[0], speeds_rpm[1], 2)
    z = result.reference_teeth
    top = harmonics * z * speeds_rpm[1] / 60.0
    shown = set()
    for mode in result.modes:
        if mode.label == "rigid-body" or mode.frequency_hz > 1.05 * top:
            continue
        colour, style = _STYLE[mode.label]
        label = mode.label if mode.label not in shown else None
        shown.add(mode.label)
        ax.plot(n, [mode.frequency_hz] * 2, color=colour, ls=style, lw=1.2, label=label)
    for h in range(1, harmonics + 1):
        ax.plot(n, h * z * n / 60.0, color="black", lw=0.8 + 0.4 * (h == 1))
        ax.annotate(
            f"{h}× mesh",
            (n[1], h * z * n[1] / 60.0),
            fontsize=8,
            xytext=(3, 0),
            textcoords="offset points",
            va="center",
        )
    for r in result.resonances(speeds_rpm, harmonics):
        f = r["harmonic"] * z * r["speed_rpm"] / 60.0
        ax.plot(r["speed_rpm"], f, "o", ms=4, color="black")
    if scene_rpm is not None and speeds_rpm[0] <= scene_rpm <= speeds_rpm[1]:
        ax.axvline(scene_rpm, color="grey", lw=0.8, ls="--", label="the scene's speed")
    ax.set_xlim(speeds_rpm)
    ax.set_ylim(0, 1.05 * top)
    ax.set_xlabel(
        f"speed of gear {result.reference_driver}, the first mesh's driver (rpm, {z} teeth)"
    )
    ax.set_ylabel("frequency (Hz)")
    ax.set_title(f"{result.model}: natural frequencies and mesh-frequency harmonics")
    ax.legend(
        title="mode (kinetic energy)",
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=8,
        frameon=False,
    )
    return fig
