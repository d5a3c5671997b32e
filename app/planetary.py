"""Planetary sets in the API: their linear model, its modes and the parametric
instabilities of their meshes' stiffness variation (issue 26).

    import gearsym

    modal = gearsym.planetary.modes("lin-parker-1999-4")       # typed, with multiplicities
    rig = gearsym.planetary.modes("back-to-back-rig")          # a train's, without dynamics too
    table = gearsym.planetary.parametric_instabilities("lin-parker-1999-3-phased")
    table["bands"][0]                                          # harmonic, type, band in Hz
    sweep = gearsym.planetary.carrier_sweep("lin-parker-1999-3", 0, 6000)  # vs carrier speed
    system = gearsym.planetary.dynamics("marine-stage-3")      # the nonlinear model
    tr = gearsym.simulate(system, gearsym.planetary.loaded_state(system))
    gearsym.planetary.contact(tr)                              # each mesh's time apart
    resp = gearsym.planetary.mesh_response("lin-parker-1999-3-backlash", 500, 4000)
    te = gearsym.planetary.te_excitation("lin-parker-1999-3-phased")  # each TE harmonic's modes

The same as ``gearsym modes SET``, ``gearsym modes SET --parametric``, ``gearsym modes SET
--speeds LO:HI`` and ``gearsym modes SET --te``.
"""

from __future__ import annotations

import math

from .planetary_dynamics import contact, dynamics, loaded_state, mesh_response, shaft_torques
from .planetary_te import te_excitation, te_response

__all__ = [
    "carrier_sweep",
    "contact",
    "dynamics",
    "loaded_state",
    "mesh_response",
    "load",
    "modes",
    "parametric_instabilities",
    "shaft_torques",
    "te_excitation",
    "te_response",
    "train_modes",
]


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
    multiplicities (``solver.analysis.modes.planetary_modes``); of a gear train's file (a
    ``[train]`` table), :func:`train_modes`."""
    from gearsym.derive.input.scene import resolve_target
    from gearsym.derive.input.train import is_train, load_train
    from gearsym.solver.analysis.modes import planetary_modes as typed

    if not hasattr(target, "as_structure"):
        path = resolve_target(target)
        if is_train(path):
            return train_modes(load_train(path))
    st = target if hasattr(target, "as_structure") else load(target)
    return typed(st.as_structure(), st.planetary.name)


def train_modes(train):
    """The modes of a gear train's linear model (``derive.input.train.Train``: mean mesh
    stiffness, no backlash, no damping) in its bodies' rotations, with each mode's share of
    the strain energy in every mesh and shaft; compared to the first mesh's frequency where
    ``[train.dynamics]`` states one.  No nonlinear model is derived, so a file without that
    table has its modes too."""
    from gearsym.derive.equations.train import derive_train
    from gearsym.solver.analysis.modes import structure_modes

    f = train.dynamics.mesh_frequency_hz if train.dynamics is not None else float("nan")
    return structure_modes(derive_train(train).as_structure(), train.name, f)


def parametric_instabilities(target, *, floquet: bool = False) -> dict:
    """Every primary and combination instability of a planetary set's meshes' stiffness
    variation (its ``[planetary.variation]``), to first order, as a JSON-ready mapping:
    each band's harmonic, the types of its modes, their natural frequencies and the band
    of the mesh frequency in Hz, or ``suppressed`` by the phasing (to first order); with
    ``floquet``, each primary band's edges also by the Floquet multipliers, and for a
    suppressed one whether they stay on the unit circle at its centre
    (``solver.analysis.parametric``).
    With a turning carrier, the bands of the set's modes at its speed (gyroscopic and
    centripetal terms: each translational pair split in two).
    Raises ``ValueError`` for a set without a variation, ``UnstableAtSpeed`` (a
    ``ValueError``) for one that cannot run at its carrier's speed."""
    from gearsym.derive.equations.planetary import planetary_meshes
    from gearsym.solver.analysis.parametric import (
        Meshes,
        combination_instabilities,
        floquet_band,
        holding,
        multipliers,
        primary_instabilities,
        unstable,
    )

    st = target if hasattr(target, "as_structure") else load(target)
    v = st.planetary.variation
    if v is None or st.phases is None:
        raise ValueError(
            f"{st.planetary.source}: no [planetary.variation] table with sun_teeth and "
            "ring_teeth; add them (docs/user-guide.md, Planetary sets)"
        )
    structure = st.as_structure()
    meshes = Meshes(*planetary_meshes(st))
    flexible = [m for m in modes(st).modes if m.label != "rigid-body"]
    labels = [m.label for m in flexible]

    def numbers(group) -> list[int]:
        """The modes of ``group`` (flexible indices) as ``gearsym modes`` numbers them."""
        return [flexible[i].index for i in group]

    def hz(w: float) -> float:
        return w / (2 * math.pi)

    primaries = primary_instabilities(structure, meshes, v.harmonics)
    pairs = combination_instabilities(structure, meshes, v.harmonics)

    def inside(Omega: float) -> list[str]:
        """The first-order bands kept by the phasing that hold ``Omega``, in words."""
        out = []
        for other in holding(primaries + pairs, Omega):
            sides = [numbers(g) for g in (other.modes, other.partner) if g]
            modes = " + ".join(", ".join(map(str, side)) for side in sides)
            plural = "s" if len(sides) > 1 or len(sides[0]) > 1 else ""
            freqs = " + ".join(f"{hz(w):.1f}" for w in (other.omega, other.omega_partner) if w)
            out.append(f"the l = {other.l} band of mode{plural} {modes} ({freqs} Hz)")
        return out

    bands = []
    for ins in primaries:
        band = {
            "harmonic": ins.l,
            "modes": numbers(ins.modes),
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
            # unstable there: inside another mode's band (at speed a split pair's bands
            # overlap), else a band of higher order
            band["floquet_inside"] = [] if band["floquet_stable_at_centre"] else inside(ins.centre)
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
            "modes": numbers(ins.modes),
            "partner": numbers(ins.partner),
            "types": [labels[ins.modes[0]], labels[ins.partner[0]]],
            "natural_hz": [hz(ins.omega), hz(ins.omega_partner)],
            "centre_hz": hz(ins.centre),
            "lower_hz": hz(ins.lower),
            "upper_hz": hz(ins.upper),
            "suppressed": ins.suppressed,
        }
        for ins in pairs
    ]
    return {
        "model": st.planetary.name,
        "carrier_speed_rpm": st.planetary.carrier_speed_rpm or 0.0,
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


def carrier_sweep(target, lo_rpm: float, hi_rpm: float, num: int = 41, harmonics: int = 3) -> dict:
    """The natural frequencies of a planetary set against its carrier's speed (a Campbell
    diagram, as Lin and Parker, 1999, give it), JSON-ready: at each of ``num`` speeds from
    ``lo_rpm`` to ``hi_rpm`` every elastic mode's frequency seen from the carrier (Hz,
    ascending: index k is the k-th lowest at each speed, so a track follows the envelope
    through a veering) and its type; the speeds where the stiffness is indefinite (no
    modes: the set diverges there) with the reason.  A lateral-torsional set gets the
    rotating frame's terms at each speed (``derive.equations.planetary_frame.at_speed``,
    the set derived once); a torsional model has none, so its frequencies do not move.

    With ``ring_teeth`` known and the ring the one member held in rotation (a torsional
    support on it alone: the carrier drives, the sun is driven or the reverse), the mesh
    frequency is ``ring_teeth x n_c / 60`` (n_c the carrier's speed in rpm) and the speeds
    where its first ``harmonics`` harmonics meet a mode are given (linear between two
    speeds of the sweep).  Raises ``ValueError`` for a range the model cannot take."""
    import numpy as np
    from gearsym.derive.equations.planetary_frame import at_speed
    from gearsym.derive.input.planetary import bearing_limit_rpm
    from gearsym.solver.analysis.modes import UnstableAtSpeed, planetary_modes

    st = target if hasattr(target, "as_structure") else load(target)
    ps = st.planetary
    if not (0 <= lo_rpm < hi_rpm and math.isfinite(hi_rpm)) or num < 2:
        raise ValueError(
            f"speeds {lo_rpm:g} to {hi_rpm:g} rpm ({num}): give 0 <= LO < HI, NUM >= 2"
        )
    turning = ps.dofs != "torsional"
    limit = bearing_limit_rpm(ps.members["planet"])
    if turning and hi_rpm >= limit:
        raise ValueError(
            f"{hi_rpm:g} rpm: the planets' bearings cannot hold them at or above "
            f"{limit:.6g} rpm (sqrt(k_p / m_p)); keep the speeds below it"
        )
    base = at_speed(st, 0.0)
    speeds = np.linspace(lo_rpm, hi_rpm, num)
    rows, labels, unstable = [], [], []
    fixed = None if turning else planetary_modes(base.as_structure(), ps.name)
    for n_c in speeds:
        try:
            res = fixed or planetary_modes(at_speed(base, float(n_c)).as_structure(), ps.name)
        except UnstableAtSpeed as err:
            rows.append(None)
            labels.append(None)
            unstable.append({"speed_rpm": float(n_c), "why": str(err)})
            continue
        elastic = [m for m in res.modes if m.label != "rigid-body"]
        rows.append([m.frequency_hz for m in elastic])
        labels.append([m.label for m in elastic])
    count = max((len(r) for r in rows if r is not None), default=0)
    modes_out = [
        {
            "index": k + 1,
            "frequency_hz": [None if r is None else r[k] for r in rows],
            "label": [None if lab is None else lab[k] for lab in labels],
        }
        for k in range(count)
    ]
    held = [j for j in ("carrier", "ring", "sun") if ps.members[j].torsional > 0]
    mesh, crossings = None, []
    if ps.ring_teeth is not None and held == ["ring"]:
        mesh = {"held": "ring", "ring_teeth": ps.ring_teeth, "hz_per_rpm": ps.ring_teeth / 60.0}
        for h in range(1, harmonics + 1):
            for mode in modes_out:
                f = mode["frequency_hz"]
                for i in range(num - 1):
                    if f[i] is None or f[i + 1] is None:
                        continue
                    a = f[i] - h * mesh["hz_per_rpm"] * speeds[i]
                    b = f[i + 1] - h * mesh["hz_per_rpm"] * speeds[i + 1]
                    # a meeting on a sample belongs to the segment it starts, or to the
                    # last segment before the end or a gap
                    last = i + 2 >= num or f[i + 2] is None
                    if a == 0 or a * b < 0 or (b == 0 and last):
                        n_x = (
                            speeds[i]
                            if a == 0
                            else speeds[i] + (speeds[i + 1] - speeds[i]) * a / (a - b)
                        )
                        crossings.append(
                            {
                                "harmonic": h,
                                "mode": mode["index"],
                                "label": mode["label"][i],
                                "speed_rpm": float(n_x),
                                "frequency_hz": float(h * mesh["hz_per_rpm"] * n_x),
                            }
                        )
        crossings.sort(key=lambda c: (c["speed_rpm"], c["harmonic"]))
    why = None
    if mesh is None:
        why = (
            "no ring_teeth in the file"
            if ps.ring_teeth is None
            else f"the members held in rotation are {held or 'none'}, not the ring alone"
        )
    return {
        "model": ps.name,
        "degrees_of_freedom": ps.dofs,
        "frame": "the carrier's (frequencies seen from it)" if turning else "none: torsional",
        "speeds_rpm": [float(v) for v in speeds],
        "modes": modes_out,
        "unstable": unstable,
        "mesh": mesh,
        "mesh_why_not": why,
        "crossings": crossings,
        "harmonics": harmonics,
        "scene_speed_rpm": ps.carrier_speed_rpm,
    }
