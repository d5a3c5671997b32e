"""A planetary set's transmission errors in its linear model (issue 26): which modes each
harmonic excites, with the planets' mesh phases, and the meshes' dynamic forces over the
mesh frequency (``solver.analysis.forced``).

    import gearsym

    table = gearsym.planetary.te_excitation("lin-parker-1999-3-phased")
    table["harmonics"][0]["groups"]          # each mode group: excited or suppressed
    resp = gearsym.planetary.te_response("marine-stage-3", 100, 3000)

The same as ``gearsym modes SET --te``.  The errors are the file's
(``[planetary.dynamics]``: ``sun_planet_transmission_error``,
``ring_planet_transmission_error``), or, where it states none, 1 µm at phase 0 in each of
the harmonics 1 to N (N planets) on every mesh: enough to show every pattern the phasing
gives (Parker, 2000: it repeats with l Z_s mod N).
"""

from __future__ import annotations

import math

__all__ = ["te_errors", "te_excitation", "te_response"]

UNIT_M = 1e-6  # the unit error where the file states none


def _set(target):
    """The derived set (a ``PlanetaryStructure``, or a built-in name or ``.toml`` path)."""
    if not hasattr(target, "as_structure"):
        from gearsym.derive.equations.planetary import derive_planetary
        from gearsym.derive.input.planetary import is_planetary, load_planetary
        from gearsym.derive.input.scene import resolve_target

        path = resolve_target(target)
        if not is_planetary(path):
            raise ValueError(f"{target}: not a planetary set (a file with a [planetary] table)")
        target = derive_planetary(load_planetary(path))
    st = target
    if st.phases is None:
        raise ValueError(
            f"{st.planetary.source}: the meshes' phases need sun_teeth and ring_teeth in "
            "[planetary]; give them"
        )
    if st.carrier_speed_rad_s:  # UnstableAtSpeed (a ValueError) where the set cannot run
        from gearsym.solver.analysis.modes import rotating_modes

        s = st.as_structure()
        rotating_modes(s)
    return st


def te_errors(st, only: str | None = None):
    """``(Errors, stated)``: the set's meshes' transmission errors as
    ``solver.analysis.forced.Errors`` and whether the file states them (else the unit
    error of the module text); ``only`` ``"s"`` or ``"r"``: the sun or the ring meshes
    alone.  A ring mesh's phase is its own plus the variation's ``ring_sun_phase`` where
    the file gives one, as its stiffness's (the nonlinear model's convention)."""
    from gearsym.solver.analysis.forced import Errors

    ps = st.planetary
    d = ps.dynamics
    stated = d is not None and (d.error_sun is not None or d.error_ring is not None)
    unit = tuple((UNIT_M, 0.0) for _ in range(ps.planets))
    offset = ps.variation.ring_sun_phase if ps.variation is not None else 0.0
    rows, phases, waves = [], [], []
    for j, (name, kind) in enumerate(zip(st.springs, st.kinds, strict=True)):
        if kind != "mesh" or (only is not None and name[0] != only):
            continue
        sun, ring = st.phases[int(name[2:]) - 1]
        if stated:
            te = d.error_sun if name.startswith("s") else d.error_ring
            if te is None:
                continue
            wave = tuple(zip(te.amplitudes, te.phases, strict=True))
        else:
            wave = unit
        rows.append(j)
        phases.append(sun if name.startswith("s") else (ring + offset) % 1.0)
        waves.append(wave)
    return Errors(tuple(rows), tuple(phases), tuple(waves)), stated


def te_excitation(target) -> dict:
    """Per harmonic of the meshes' transmission error, each group of modes at one natural
    frequency (type, multiplicity, Hz), the mesh frequency where the harmonic meets it
    (Hz) and whether the harmonic excites it or the phasing suppresses it, JSON-ready;
    ``l Z_s mod N`` beside each harmonic (Parker, 2000, read the pattern from it)."""
    from gearsym.solver.analysis.forced import excitation
    from gearsym.solver.analysis.modes import planetary_modes

    st = _set(target)
    ps = st.planetary
    errors, stated = te_errors(st)
    # the file's errors act together; a unit error, each kind of mesh's alone: a sun and a
    # ring error of one phase can cancel in a mode (a planet's rotation strains the two
    # meshes with opposite signs), which says nothing of what the phasing allows
    sources = (
        {"stated": errors}
        if stated
        else {"sun-planet": te_errors(st, "s")[0], "ring-planet": te_errors(st, "r")[0]}
    )
    typed = planetary_modes(st.as_structure(), ps.name).modes
    flexible = [m for m in typed if m.label != "rigid-body"]  # as forced.excitation counts
    labels = [m.label for m in flexible]
    found = {name: excitation(st.as_structure(), e) for name, e in sources.items()}
    out = []
    for l in range(1, errors.harmonics + 1):  # noqa: E741
        groups = []
        for i, r in enumerate(found[next(iter(found))]):
            if r["harmonic"] != l:
                continue
            by = [name for name, rows in found.items() if rows[i]["excited"]]
            groups.append(
                {
                    "type": labels[r["modes"][0]],
                    "modes": [flexible[m].index for m in r["modes"]],  # as `modes` lists
                    "multiplicity": len(r["modes"]),
                    "natural_hz": r["natural_rad_s"] / (2 * math.pi),
                    "mesh_frequency_hz": r["natural_rad_s"] / (2 * math.pi * l),
                    "excited": bool(by),
                    "excited_by": by,
                    "modal_force": {name: rows[i]["force"] for name, rows in found.items()},
                }
            )
        out.append({"harmonic": l, "residue": l * ps.sun_teeth % ps.planets, "groups": groups})
    return {
        "model": ps.name,
        "planets": ps.planets,
        "carrier_speed_rpm": ps.carrier_speed_rpm,
        "equally_spaced": ps.equally_spaced,
        "sun_teeth": ps.sun_teeth,
        "ring_teeth": ps.ring_teeth,
        "errors": "the file's"
        if stated
        else "1 µm at phase 0 in harmonics 1 to N, on the sun meshes and on the ring meshes apart",
        "harmonics": out,
    }


def te_response(
    target, lo_hz: float, hi_hz: float, num: int = 200, damping_ratio=None, *, log=False
) -> dict:
    """The meshes' largest dynamic force (N, about the static force) over a mesh period
    at ``num`` mesh frequencies from ``lo_hz`` to ``hi_hz`` (evenly spaced, or on a log
    scale with ``log``), JSON-ready: each kind of mesh's largest over its meshes
    (``sun_planet_N``, ``ring_planet_N``).  ``damping_ratio``: of every spring on its own
    mass (default: the file's ``[planetary.dynamics]``, else 0.03)."""
    import numpy as np
    from gearsym.solver.analysis.forced import response

    if not (0 < lo_hz < hi_hz and math.isfinite(hi_hz)) or int(num) < 2:
        raise ValueError(
            f"mesh frequencies {lo_hz:g} to {hi_hz:g} Hz ({num}): give 0 < LO < HI, NUM >= 2"
        )
    st = _set(target)
    d = st.planetary.dynamics
    zeta = damping_ratio if damping_ratio is not None else (d.damping_ratio if d else 0.03)
    errors, stated = te_errors(st)
    freqs = (np.geomspace if log else np.linspace)(lo_hz, hi_hz, int(num))
    force = response(st.as_structure(), errors, zeta, 2 * np.pi * freqs)
    sun = np.array([st.springs[j].startswith("s") for j in errors.rows])
    out = {"model": st.planetary.name, "damping_ratio": zeta, "mesh_frequency_hz": list(freqs)}
    for key, mask in (("sun_planet_N", sun), ("ring_planet_N", ~sun)):
        out[key] = list(force[:, mask].max(axis=1)) if mask.any() else None
    out["errors"] = "the file's" if stated else "1 µm at phase 0 in harmonics 1 to N"
    return out
