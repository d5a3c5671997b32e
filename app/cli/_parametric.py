"""``gearsym modes SET --parametric``: the primary parametric instabilities of a planetary
set from its meshes' stiffness variation and phases (``solver.analysis.parametric``)."""

from __future__ import annotations

import math
import sys

__all__ = ["parametric_table", "print_parametric"]

SHOWN = 10  # combination bands printed (the widest, relative to their centre)


def parametric_table(st, modes, *, floquet: bool = False) -> dict:
    """The bands of every primary instability (``l Omega = 2 omega``, ``l`` up to the
    file's harmonics) as a JSON-ready mapping: each band's harmonic, the type of its modes,
    their natural frequency, the band of the mesh frequency in Hz (first order) and, with
    ``floquet``, its edges by the Floquet multipliers."""
    from gearsym.derive.equations.planetary import planetary_meshes
    from gearsym.solver.analysis.parametric import (
        Meshes,
        combination_instabilities,
        floquet_band,
        primary_instabilities,
    )

    v = st.planetary.variation
    structure = st.as_structure()
    meshes = Meshes(*planetary_meshes(st))
    labels = [m.label for m in modes.modes if m.label != "rigid-body"]
    found = primary_instabilities(structure, meshes, v.harmonics)
    bands = []
    if floquet:
        todo = sum(not ins.suppressed for ins in found)
        print(f"confirming {todo} bands by the Floquet multipliers", file=sys.stderr)
    for ins in found:
        band = {
            "harmonic": ins.l,
            "modes": [i + 1 for i in ins.modes],
            "type": labels[ins.modes[0]],
            "natural_hz": ins.omega / (2 * math.pi),
            "centre_hz": ins.centre / (2 * math.pi),
            "lower_hz": ins.lower / (2 * math.pi),
            "upper_hz": ins.upper / (2 * math.pi),
            "suppressed": ins.suppressed,
        }
        if floquet and not ins.suppressed:
            try:
                lo, hi = floquet_band(structure, meshes, ins)
                band["floquet_hz"] = [lo / (2 * math.pi), hi / (2 * math.pi)]
            except ValueError as err:
                band["floquet_hz"] = None
                band["floquet_note"] = str(err)
        bands.append(band)
    combinations = [
        {
            "harmonic": ins.l,
            "modes": [i + 1 for i in ins.modes],
            "partner": [i + 1 for i in ins.partner],
            "types": [labels[ins.modes[0]], labels[ins.partner[0]]],
            "natural_hz": [ins.omega / (2 * math.pi), ins.omega_partner / (2 * math.pi)],
            "centre_hz": ins.centre / (2 * math.pi),
            "lower_hz": ins.lower / (2 * math.pi),
            "upper_hz": ins.upper / (2 * math.pi),
            "suppressed": ins.suppressed,
        }
        for ins in combination_instabilities(structure, meshes, v.harmonics)
    ]
    return {
        "method": "first order (multiple scales): primary instabilities l Omega = 2 omega "
        "and combination instabilities l Omega = omega_1 + omega_2",
        "sun_planet": {"contact_ratio": v.sun[0], "amplitude": v.sun[1]},
        "ring_planet": {"contact_ratio": v.ring[0], "amplitude": v.ring[1]},
        "ring_sun_phase": v.ring_sun_phase,
        "harmonics": v.harmonics,
        "sun_teeth": st.planetary.sun_teeth,
        "bands": bands,
        "combinations": combinations,
    }


def print_parametric(table: dict) -> None:
    """The table of :func:`parametric_table`, for the terminal."""
    s, r = table["sun_planet"], table["ring_planet"]
    print(
        "parametric instabilities, first order (primary, l x mesh frequency = 2 x natural): "
        f"rectangular mesh stiffness, sun-planet contact ratio {s['contact_ratio']:g} "
        f"amplitude {s['amplitude']:g}, ring-planet {r['contact_ratio']:g} amplitude "
        f"{r['amplitude']:g}; ring meshes {table['ring_sun_phase']:g} mesh periods after "
        "their sun meshes"
    )
    print(f"  {'l':>2}  {'type':<13}  {'natural Hz':>10}  mesh frequency band (Hz)")
    for b in table["bands"]:
        head = f"  {b['harmonic']:2d}  {b['type']:<13}  {b['natural_hz']:10.1f}  "
        if b["suppressed"]:
            print(head + "suppressed by the phasing")
            continue
        # enough decimals to show the band's width (some are a hundredth of a hertz)
        width = b["upper_hz"] - b["lower_hz"]
        places = max(1, 1 - math.floor(math.log10(width))) if width > 0 else 1
        line = head + f"{b['lower_hz']:.{places}f} to {b['upper_hz']:.{places}f}"
        if "floquet_hz" in b:
            f = b["floquet_hz"]
            line += (
                f"; Floquet {f[0]:.{places}f} to {f[1]:.{places}f}"
                if f
                else f"; Floquet: undetermined ({b['floquet_note']})"
            )
        print(line)
    kept = [c for c in table["combinations"] if not c["suppressed"]]
    if not kept:
        return
    widest = sorted(kept, key=lambda c: -(c["upper_hz"] - c["lower_hz"]) / c["centre_hz"])
    print(
        f"combination instabilities (l x mesh frequency = natural 1 + natural 2): {len(kept)} "
        f"of {len(table['combinations'])} not suppressed by the phasing; the "
        f"{min(len(kept), SHOWN)} widest (every one in --json and --out):"
    )
    print(f"  {'l':>2}  {'types':<27}  {'natural Hz':>19}  mesh frequency band (Hz)")
    for c in widest[:SHOWN]:
        types = " + ".join(c["types"])
        pair = " + ".join(f"{f:.1f}" for f in c["natural_hz"])
        width = c["upper_hz"] - c["lower_hz"]
        places = max(1, 1 - math.floor(math.log10(width)))
        print(
            f"  {c['harmonic']:2d}  {types:<27}  {pair:>19}  "
            f"{c['lower_hz']:.{places}f} to {c['upper_hz']:.{places}f}"
        )
