"""``gearsym modes SET --parametric``: the primary parametric instabilities of a planetary
set from its meshes' stiffness variation and phases (``solver.analysis.parametric``)."""

from __future__ import annotations

import math
import sys

__all__ = ["parametric_table", "print_parametric"]

SHOWN = 10  # combination bands printed (the widest, relative to their centre)


def parametric_table(st, modes, *, floquet: bool = False) -> dict:
    """The bands of :func:`gearsym.planetary.parametric_instabilities` (``modes`` is not
    needed again: kept for the caller's order of work); a line on stderr first when the
    Floquet check runs (a second or two a band)."""
    from gearsym.planetary import parametric_instabilities

    if floquet:
        print("confirming each band by the Floquet multipliers", file=sys.stderr)
    return parametric_instabilities(st, floquet=floquet)


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
