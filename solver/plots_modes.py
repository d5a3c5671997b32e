"""The resonance (Campbell) diagram of a model's modes against its mesh frequency, and a
planetary set's parametric-instability diagram, its modes against the carrier's speed and
its meshes' dynamic forces under their transmission errors."""

from __future__ import annotations

import numpy as np

from .analysis.modes import Modes
from .plots_style import legend_below, plt

__all__ = ["campbell_figure", "carrier_figure", "parametric_figure", "te_figure"]

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
        ax.annotate(  # inside the axes, above the line's end: the legend sits outside
            f"{h}× mesh",
            (n[1], h * z * n[1] / 60.0),
            fontsize=8,
            xytext=(-4, 2),
            textcoords="offset points",
            ha="right",
            va="bottom",
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


_TYPES = {
    "rotational": "tab:blue",
    "translational": "tab:green",
    "planet": "tab:orange",
    "coupled": "tab:red",
}


def parametric_figure(table: dict):
    """The first-order instability wedges of a planetary set in the plane of the mesh
    frequency (Hz, log) and the stiffness variation's amplitude (as a share of the one its
    file states, 0 to 1): each band grows linearly from its centre at zero amplitude to
    its edges at the stated amplitude.  Primary bands coloured by the type of their modes,
    combination bands grey, and a ring on the axis at the centre of each band the phasing
    suppresses.  ``table``: the mapping of ``gearsym.planetary.parametric_instabilities``;
    returns the ``Figure`` (nothing saved)."""
    fig, ax = plt.subplots(figsize=(9, 5))
    kept = [b for b in table["combinations"] if not b["suppressed"]]
    for b in kept:
        ax.fill(
            [b["centre_hz"], b["lower_hz"], b["upper_hz"]],
            [0.0, 1.0, 1.0],
            color="0.6",
            alpha=0.5,
            lw=0.5,
            label="combination (sum of two natural frequencies)",
        )
    for b in table["bands"]:
        colour = _TYPES.get(b["type"], "black")
        if b["suppressed"]:
            ax.plot(
                b["centre_hz"],
                0.0,
                "o",
                mfc="none",
                mec=colour,
                ms=6,
                clip_on=False,
                label=f"{b['type']}, primary: suppressed by the phasing",
            )
            continue
        ax.fill(
            [b["centre_hz"], b["lower_hz"], b["upper_hz"]],
            [0.0, 1.0, 1.0],
            color=colour,
            alpha=0.8,
            lw=0.8,
            label=f"{b['type']}, primary",
        )
    ax.set_xscale("log")
    ax.set_ylim(0.0, 1.05)
    ax.set_xlabel("mesh frequency (Hz)")
    ax.set_ylabel("stiffness variation / the stated one")
    s, r = table["sun_planet"], table["ring_planet"]
    speed = table.get("carrier_speed_rpm")
    ax.set_title(
        f"{table['model']}: parametric instability, first order "
        f"(harmonics 1 to {table['harmonics']})"
        + (f"\ncarrier at {speed:g} rpm: the modes at that speed" if speed else "")
    )
    legend_below(
        fig,
        [ax],
        f"Stated variation: sun-planet contact ratio {s['contact_ratio']:g}, amplitude "
        f"{s['amplitude']:g}; ring-planet {r['contact_ratio']:g}, {r['amplitude']:g}; ring "
        f"meshes {table['ring_sun_phase']:g} mesh periods after their sun meshes; Z_s = "
        f"{table['sun_teeth']}, Z_r = {table['ring_teeth']}. A wedge is unstable inside (the "
        "first-order band widens linearly with the amplitude); a ring on the axis marks a "
        "primary instability the planets' phasing cancels. gearsym modes --parametric "
        "--floquet checks the primary bands by Floquet multipliers.",
    )
    return fig


def carrier_figure(sweep: dict, harmonics: int | None = None):
    """A planetary set's natural frequencies against its carrier's speed (the mapping of
    ``gearsym.planetary.carrier_sweep``): each track (the k-th lowest frequency) coloured
    by its mode's type, the mesh frequency's harmonics where the ring is held and its teeth
    known (``harmonics`` of them, default the sweep's), a dot where they meet a mode, the
    speeds without modes shaded; returns the ``Figure`` (nothing saved)."""
    harmonics = sweep.get("harmonics", 3) if harmonics is None else harmonics
    fig, ax = plt.subplots(figsize=(8, 5.5))
    n = np.asarray(sweep["speeds_rpm"])
    top = 0.0
    shown = set()
    for mode in sweep["modes"]:
        f, labels = mode["frequency_hz"], mode["label"]
        i = 0
        while i < len(n):  # one line for each run of the same type
            if f[i] is None:
                i += 1
                continue
            j = i
            while j + 1 < len(n) and f[j + 1] is not None and labels[j + 1] == labels[i]:
                j += 1
            stop = min(j + 2, len(n)) if j + 1 < len(n) and f[j + 1] is not None else j + 1
            xs, ys = n[i:stop], [v for v in f[i:stop]]
            label = labels[i] if labels[i] not in shown else None
            shown.add(labels[i])
            ax.plot(xs, ys, color=_TYPES.get(labels[i], "grey"), lw=1.3, label=label)
            top = max(top, max(ys))
            i = j + 1
    mesh = sweep["mesh"]
    if mesh is not None:
        for h in range(1, harmonics + 1):
            ax.plot(n, h * mesh["hz_per_rpm"] * n, color="black", lw=0.8 + 0.4 * (h == 1))
            end = min(n[-1], 1.05 * top / (h * mesh["hz_per_rpm"]))
            ax.annotate(
                f"{h}× mesh",
                (end, h * mesh["hz_per_rpm"] * end),
                fontsize=8,
                xytext=(3, 0),
                textcoords="offset points",
                va="center",
            )
        meet = [c for c in sweep["crossings"] if c["harmonic"] <= harmonics]
        if meet:
            ax.plot(
                [c["speed_rpm"] for c in meet],
                [c["frequency_hz"] for c in meet],
                "o",
                ms=4,
                color="black",
                label="a mesh harmonic meets a mode",
            )
    # each speed without modes shaded over half a step either side (runs merge)
    step = (n[-1] - n[0]) / (len(n) - 1)
    for k, u in enumerate(sweep["unstable"]):
        at = u["speed_rpm"]
        ax.axvspan(
            max(n[0], at - step / 2),
            min(n[-1], at + step / 2),
            color="0.85",
            lw=0,
            label="no modes at this speed (why: --json)" if k == 0 else None,
        )
    scene = sweep.get("scene_speed_rpm") or 0.0
    if scene and n[0] <= scene <= n[-1]:
        ax.axvline(scene, color="grey", lw=0.8, ls="--", label="the file's carrier speed")
    ax.set_xlim(n[0], n[-1])
    ax.set_ylim(0, 1.05 * top if top else 1.0)
    ax.set_xlabel("carrier speed (rpm)")
    seen = "seen from the carrier" if sweep["frame"].startswith("the carrier") else "torsional"
    ax.set_ylabel(f"natural frequency (Hz, {seen})")
    ax.set_title(f"{sweep['model']}: natural frequencies against the carrier's speed")
    caption = (
        f"mesh frequency = {mesh['ring_teeth']} x carrier rpm / 60 (the ring held)"
        if mesh is not None
        else f"no mesh-frequency lines: {sweep['mesh_why_not']}"
    )
    legend_below(fig, [ax], caption)
    return fig


def te_figure(response: dict, table: dict):
    """A planetary set's meshes' largest dynamic force over the mesh frequency under their
    transmission errors (``response``: the mapping of ``gearsym.planetary.te_response``),
    one curve for each kind of mesh, and a tick at the top for each mode a harmonic meets
    (its natural frequency over ``l``, coloured by its type; ``table``: the mapping of
    ``te_excitation``), the phasing's suppressed ones left out; returns the ``Figure``."""
    fig, ax = plt.subplots(figsize=(9, 5))
    f = np.asarray(response["mesh_frequency_hz"])
    for key, label, colour in (
        ("sun_planet_N", "sun-planet meshes", "black"),
        ("ring_planet_N", "ring-planet meshes", "tab:purple"),
    ):
        if response.get(key) is not None:
            ax.plot(f, response[key], color=colour, lw=1.4, label=label)
    top = ax.get_xaxis_transform()
    for h in table["harmonics"]:
        for g in h["groups"]:
            at = g["mesh_frequency_hz"]
            if g["excited"] and f[0] <= at <= f[-1]:
                colour = _TYPES.get(g["type"], "grey")
                ax.plot(
                    [at, at],
                    [0.94, 1.0],
                    transform=top,
                    color=colour,
                    lw=1.2,
                    label=f"{g['type']} mode met (natural / l)",
                )
                ax.annotate(
                    f"{h['harmonic']}",
                    (at, 0.93),
                    xycoords=top,
                    fontsize=7,
                    ha="center",
                    va="top",
                    color=colour,
                )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(f[0], f[-1])
    peaks = [max(response[k]) for k in ("sun_planet_N", "ring_planet_N") if response.get(k)]
    if peaks and max(peaks) > 0:
        ax.set_ylim(top=8.0 * max(peaks))  # headroom for the ticks above the curves
    ax.set_xlabel("mesh frequency (Hz)")
    ax.set_ylabel("largest dynamic mesh force over a period (N)")
    speed = table.get("carrier_speed_rpm") or 0.0
    where = f"carrier at {speed:g} rpm" if speed else "carrier held"
    ax.set_title(f"{response['model']}: response to the transmission errors ({where})")
    legend_below(
        fig,
        [ax],
        f"Errors: {response['errors']}; every mesh in contact (the linear model), damping "
        f"ratio {response['damping_ratio']:g} on every spring. Each kind of mesh's largest "
        "force over its meshes, about the static force. A tick marks a mode a harmonic l "
        "of the error meets (the number under it: l); the modes the planets' phasing "
        "suppresses get none.",
    )
    return fig
