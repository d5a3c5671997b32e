"""Planetary sets in the API: their linear model, its modes and the parametric
instabilities of their meshes' stiffness variation (issue 26).

    import gearsym

    modal = gearsym.planetary.modes("lin-parker-1999-4")       # typed, with multiplicities
    table = gearsym.planetary.parametric_instabilities("lin-parker-1999-3-phased")
    table["bands"][0]                                          # harmonic, type, band in Hz

The same as ``gearsym modes SET`` and ``gearsym modes SET --parametric``.
"""

from __future__ import annotations

import math

__all__ = ["load", "modes", "parametric_instabilities"]


def load(target):
    """The derived linear model of a planetary set (a built-in name or a ``.toml`` path):
    ``derive.equations.planetary.PlanetaryStructure``."""
    from gearsym.derive.equations.planetary import derive_planetary
    from gearsym.derive.input.planetary import is_planetary, load_planetary
    from gearsym.derive.input.scene import resolve_target

    path = resolve_target(target)
    if not is_planetary(path):
        raise ValueError(f"{target}: not a planetary set (a file with a [planetary] table)")
    return derive_planetary(load_planetary(path))


def modes(target):
    """The modes of a planetary set, typed rotational, translational or planet with their
    multiplicities (``solver.analysis.modes.planetary_modes``)."""
    from gearsym.solver.analysis.modes import planetary_modes as typed

    st = target if hasattr(target, "as_structure") else load(target)
    return typed(st.as_structure(), st.planetary.name)


def parametric_instabilities(target, *, floquet: bool = False) -> dict:
    """Every primary and combination instability of a planetary set's meshes' stiffness
    variation (its ``[planetary.variation]``), to first order, as a JSON-ready mapping:
    each band's harmonic, the types of its modes, their natural frequencies and the band
    of the mesh frequency in Hz, or ``suppressed`` by the phasing (to first order); with
    ``floquet``, each primary band's edges also by the Floquet multipliers, and for a
    suppressed one whether they stay on the unit circle at its centre
    (``solver.analysis.parametric``).
    Raises ``ValueError`` for a set without a variation or with a carrier speed."""
    from gearsym.derive.equations.planetary import planetary_meshes
    from gearsym.solver.analysis.parametric import (
        Meshes,
        combination_instabilities,
        floquet_band,
        multipliers,
        primary_instabilities,
        unstable,
    )

    st = target if hasattr(target, "as_structure") else load(target)
    if st.planetary.carrier_speed_rpm:
        raise ValueError(
            f"{st.planetary.name}: the parametric analysis is of the fixed-carrier model "
            "(no gyroscopic terms), and the set turns its carrier: remove carrier_speed_rpm "
            "for it"
        )
    v = st.planetary.variation
    if v is None or st.phases is None:
        raise ValueError(
            f"{st.planetary.source}: no [planetary.variation] table with sun_teeth and "
            "ring_teeth; add them (docs/user-guide.md, Planetary sets)"
        )
    structure = st.as_structure()
    meshes = Meshes(*planetary_meshes(st))
    labels = [m.label for m in modes(st).modes if m.label != "rigid-body"]

    def hz(w: float) -> float:
        return w / (2 * math.pi)

    bands = []
    for ins in primary_instabilities(structure, meshes, v.harmonics):
        band = {
            "harmonic": ins.l,
            "modes": [i + 1 for i in ins.modes],
            "type": labels[ins.modes[0]],
            "natural_hz": hz(ins.omega),
            "centre_hz": hz(ins.centre),
            "lower_hz": hz(ins.lower),
            "upper_hz": hz(ins.upper),
            "suppressed": ins.suppressed,
        }
        if floquet and ins.suppressed:
            # the first order cancels it; a higher order may leave a narrow band there
            band["floquet_stable_at_centre"] = not unstable(
                multipliers(structure, meshes, ins.centre)
            )
        elif floquet:
            try:
                band["floquet_hz"] = [hz(e) for e in floquet_band(structure, meshes, ins)]
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
            "natural_hz": [hz(ins.omega), hz(ins.omega_partner)],
            "centre_hz": hz(ins.centre),
            "lower_hz": hz(ins.lower),
            "upper_hz": hz(ins.upper),
            "suppressed": ins.suppressed,
        }
        for ins in combination_instabilities(structure, meshes, v.harmonics)
    ]
    return {
        "model": st.planetary.name,
        "method": "first order (multiple scales): primary instabilities l Omega = 2 omega "
        "and combination instabilities l Omega = omega_1 + omega_2",
        "sun_planet": {"contact_ratio": v.sun[0], "amplitude": v.sun[1]},
        "ring_planet": {"contact_ratio": v.ring[0], "amplitude": v.ring[1]},
        "ring_sun_phase": v.ring_sun_phase,
        "harmonics": v.harmonics,
        "sun_teeth": st.planetary.sun_teeth,
        "ring_teeth": st.planetary.ring_teeth,
        "bands": bands,
        "combinations": combinations,
    }
