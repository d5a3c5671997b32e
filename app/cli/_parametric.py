"""``gearsym modes SET --parametric``: the table of a planetary set's parametric
instabilities (``gearsym.planetary.parametric_instabilities``) for the terminal."""

from __future__ import annotations

import math

__all__ = ["print_parametric", "print_te", "te_response_around"]

SHOWN = 10  # combination bands printed (the widest, relative to their centre)


def _band(lo: float, hi: float, edges=None) -> str:
    """``lo to hi`` with enough decimals to show the band's width (some are a hundredth
    of a hertz), the same decimals for ``edges`` (the Floquet edges) if given."""
    width = hi - lo
    places = max(1, 1 - math.floor(math.log10(width))) if width > 0 else 1
    text = f"{lo:.{places}f} to {hi:.{places}f}"
    return (
        text if edges is None else f"{text}; Floquet {edges[0]:.{places}f} to {edges[1]:.{places}f}"
    )


def print_parametric(table: dict) -> None:
    """The mapping of :func:`gearsym.planetary.parametric_instabilities`, for the
    terminal: every primary band, then the widest combination bands."""
    s, r = table["sun_planet"], table["ring_planet"]
    print(
        "parametric instabilities, first order (primary, l x mesh frequency = 2 x natural): "
        f"rectangular mesh stiffness, sun-planet contact ratio {s['contact_ratio']:g} "
        f"amplitude {s['amplitude']:g}, ring-planet {r['contact_ratio']:g} amplitude "
        f"{r['amplitude']:g}; ring meshes {table['ring_sun_phase']:g} mesh periods after "
        "their sun meshes"
    )
    if table.get("carrier_speed_rpm"):
        print(
            f"  carrier at {table['carrier_speed_rpm']:g} rpm: the bands of the modes at that "
            "speed (gyroscopic and centripetal terms; each translational pair split in two)"
        )
    print(f"  {'l':>2}  {'type':<13}  {'natural Hz':>10}  mesh frequency band (Hz)")
    for b in table["bands"]:
        head = f"  {b['harmonic']:2d}  {b['type']:<13}  {b['natural_hz']:10.1f}  "
        if b["suppressed"]:
            line = head + "suppressed by the phasing (first order)"
            if "floquet_stable_at_centre" in b:
                if b["floquet_stable_at_centre"]:
                    line += "; Floquet: stable at its centre"
                elif b["floquet_inside"]:
                    line += f"; Floquet: unstable at its centre, inside {b['floquet_inside'][0]}"
                else:
                    line += (
                        "; Floquet: unstable at its centre, in no first-order band (a band "
                        "of higher order, or a kept band wider than first order says)"
                    )
            print(line)
            continue
        if "floquet_hz" in b and b["floquet_hz"] is None:
            line = head + _band(b["lower_hz"], b["upper_hz"])
            line += f"; Floquet: undetermined ({b['floquet_note']})"
        else:
            line = head + _band(b["lower_hz"], b["upper_hz"], b.get("floquet_hz"))
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
        band = _band(c["lower_hz"], c["upper_hz"])
        print(f"  {c['harmonic']:2d}  {types:<27}  {pair:>19}  {band}")


def print_te(table: dict) -> None:
    """The mapping of :func:`gearsym.planetary.te_excitation`, for the terminal: per
    harmonic, the natural frequencies (Hz) it excites and those the phasing suppresses,
    by type."""
    print(
        f"transmission error ({table['errors']}): what each harmonic l excites; it meets a "
        "mode at the mesh frequency natural / l"
    )
    if table.get("carrier_speed_rpm") and table["equally_spaced"] and table["planets"] >= 3:
        print(
            f"  (carrier at {table['carrier_speed_rpm']:g} rpm: each translational pair is "
            "split into two modes whirling in opposite senses, and a harmonic with l x "
            "sun_teeth mod N = 1 meets one of each pair, N - 1 the other)"
        )
    n = table["planets"]
    for h in table["harmonics"]:
        print(f"  l = {h['harmonic']} (l x sun_teeth mod {n} = {h['residue']}):")
        for word, keep in (("excites", True), ("suppressed", False)):
            kinds: dict = {}
            for g in h["groups"]:
                if g["excited"] == keep:
                    kinds.setdefault(g["type"], []).append(f"{g['natural_hz']:.0f}")
            if kinds:
                text = "; ".join(f"{t} {', '.join(f)} Hz" for t, f in kinds.items())
                print(f"    {word}: {text}")


def te_response_around(st, table: dict) -> dict:
    """``te_response`` of the set ``st`` over the mesh frequencies where its harmonics meet
    the modes they excite (``table``: ``te_excitation``'s), from half the lowest to one and
    a half times the highest, 600 frequencies on a log scale."""
    from gearsym.planetary import te_response

    from ._common import Fail

    met = [g["mesh_frequency_hz"] for h in table["harmonics"] for g in h["groups"] if g["excited"]]
    if not met:
        raise Fail(
            f"--te --plot: the errors of {table['model']} excite no mode (every harmonic's "
            "pattern cancels), so there is no resonance to draw; give the errors another "
            "phase or leave --plot out"
        )
    return te_response(st, 0.5 * min(met), 1.5 * max(met), 600, log=True)
