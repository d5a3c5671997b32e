"""A planetary set's nonlinear model in the API: backlash in every mesh (issue 26, point 5).

``dynamics`` gives the model as a System, which every analysis takes; ``contact`` reads each
mesh's time apart from a run; ``mesh_response`` sweeps the mesh frequency up and down and
gives each kind of mesh's deflection, dynamic factor and where its teeth separate.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["contact", "dynamics", "loaded_state", "mesh_response", "shaft_torques"]


def dynamics(target, **values):
    """The nonlinear model of a planetary set with a ``[planetary.dynamics]`` table (backlash
    in every mesh: ``derive.equations.planetary_dynamics``) as a
    :class:`~gearsym.solver.system.System` at ``values`` (``omega``, ``f_s``, ``zeta``, or
    ``mesh_frequency_hz``, ``sun_force_N``, ``damping_ratio``), derived once into the
    model cache; every analysis of a System takes it (``simulate``, ``sweep``, ``shoot``),
    and so does every command (``gearsym simulate SET``).  Raises ``InputError`` (one
    line) where the set's file cannot give one.  A gear train with closed loops (a
    ``[train]`` file: ``derive.equations.train``) is taken too, its values ``omega``, ``f``,
    ``zeta`` or ``mesh_frequency_hz``, ``load_factor``, ``damping_ratio``."""
    from gearsym.derive.input.planetary import is_planetary
    from gearsym.derive.input.scene import resolve_target
    from gearsym.derive.input.train import is_train
    from gearsym.resolve import planetary_system

    path = resolve_target(target)
    if not (is_planetary(path) or is_train(path)):
        raise ValueError(
            f"{target}: not a planetary set or a gear train with closed loops (a file with "
            "a [planetary] or [train] table)"
        )
    return planetary_system(path, **values)


def loaded_state(system):
    """The loaded equilibrium of a planetary set's nonlinear model at its mean stiffness
    (each mesh in contact on its loaded side, at rest): the start of a run that begins
    where the set operates.  ``ValueError`` when no contact pattern balances the load."""
    x = system.module.static_state(system.p)
    if x is None:
        raise ValueError(
            f"{system.name}: no unique loaded equilibrium: at this load the meshes' teeth "
            "stay apart (the bodies free inside the backlash), or no contact pattern "
            "balances it; raise the load"
        )
    return x


def contact(tr) -> dict:
    """Each mesh's share of the samples of trajectory ``tr`` (a planetary set's nonlinear
    model, or a gear train's) with its teeth apart (``|u| <= 1``), in contact on its loaded
    flank (``loaded_flank``; ``loaded_side``: the sign of ``u`` there, :func:`loaded_sides`)
    and on its back flank (``back_flank``), ``u`` its deflection with its transmission
    error where it has one (a train's mesh); its deflection's extremes in its half
    backlashes, and its force's extremes over its mean stiffness times its half backlash
    (``(1 + v(tau)) g(u)``, the stiffness variation included); read from the samples
    (``samples_per_period`` of the run), so a contact loss shorter than a sample can be
    missed."""
    from gearsym.solver.analysis.meshing import (
        body_mesh_deflections,
        loaded_sides,
        meshing_states,
    )

    module = tr.system.module
    omega = tr.system.p[list(module.PARAMETERS).index("omega")]
    tau = np.asarray(tr.t, dtype=float)
    sides = loaded_sides(tr.system)
    shares = meshing_states(tr)  # the shares every record of the run carries
    out = {}
    for mesh, u in body_mesh_deflections(tr).items():
        v = sum(
            c * np.cos(h * omega * tau) + s * np.sin(h * omega * tau)
            for h, c, s in module.MESHES[mesh]["wave"]
        )
        force = (1.0 + v) * np.where(u > 1.0, u - 1.0, np.where(u < -1.0, u + 1.0, 0.0))
        out[mesh] = {
            "apart": shares[mesh]["separated"],
            "loaded_side": sides[mesh],
            "half_backlash_um": 1e6 * float(module.MESHES[mesh]["half_backlash_m"]),
            "loaded_flank": shares[mesh]["forward"],
            "back_flank": shares[mesh]["backward"],
            "min": float(u.min()),
            "max": float(u.max()),
            "force_min": float(force.min()),
            "force_max": float(force.max()),
            "samples": int(u.size),
        }
    return out


def shaft_torques(tr) -> dict:
    """Each shaft's torque over trajectory ``tr`` of a gear train's nonlinear model (N m):
    ``k (theta_a - theta_b - f Delta)``, ``a`` and ``b`` its bodies in the file's order and
    ``Delta`` its assembly twist, so a shaft of a loaded loop carries its share of the
    locked-in torque; its mean, least and largest over the samples.  Empty for a model
    without shafts (a planetary set's)."""
    module = tr.system.module
    f = tr.system.p[1]  # the load factor
    x = np.asarray(tr.x, dtype=float)[: len(module.COORDINATES)]
    out = {}
    for shaft, v in getattr(module, "SHAFTS", {}).items():
        torque = v["stiffness_Nm_per_rad"] * (
            np.tensordot(np.asarray(v["row"]), x, axes=1) - f * v["assembly_twist_rad"]
        )
        out[shaft] = {
            "mean_Nm": float(torque.mean()),
            "min_Nm": float(torque.min()),
            "max_Nm": float(torque.max()),
            "bodies": list(v["bodies"]),
        }
    return out


def _point(system, x0, transient: int, periods: int) -> tuple:
    """One run of a stepped sweep: its trajectory and each mesh's contact (``contact``)."""
    from gearsym.solver.integrate import simulate

    tr = simulate(system, x0, transient=transient, periods=periods, samples_per_period=64)
    return tr, (contact(tr) if tr.status == "ok" else None)


def mesh_response(
    target, lo_hz: float, hi_hz: float, num: int = 81, *, transient=200, periods=50, **values
) -> dict:
    """The frequency response of a planetary set's meshes (its nonlinear model: backlash in
    every mesh), JSON-ready: the mesh frequency stepped from ``lo_hz`` to ``hi_hz`` in
    ``num`` points and back, each run from the previous one's end state (the first from the
    loaded equilibrium), ``transient`` + ``periods`` mesh periods, 64 samples a period.  For
    each direction and kind of mesh (sun-planet, ring-planet) at each frequency: the
    largest and smallest deflection over the set's meshes of that kind (half backlashes:
    ``|u| <= 1`` the teeth apart), the largest share of samples a mesh spends apart, and
    the dynamic factor (the largest mesh force, its stiffness variation included, over its
    static force at the mean stiffness, ``max (1 + v) (u - 1) / (u_static - 1)``).
    ``band_hz``: the frequencies where a mesh's teeth separate in either direction
    (``band_hz_by_kind``: each kind's); ``natural_hz``: the linear model's elastic natural
    frequencies (every mesh in contact, its mean stiffness);
    ``resonances``: where a harmonic ``l`` of the stiffness variation meets one,
    ``l f_mesh = f_k``, in the range.  ``values``: the
    model's (``sun_force_N``, ``damping_ratio``, ...)."""
    from gearsym.derive.equations.planetary import derive_planetary
    from gearsym.derive.input.planetary import is_planetary, load_planetary
    from gearsym.derive.input.scene import resolve_target
    from gearsym.solver.analysis.modes import planetary_modes

    if not (0 < lo_hz < hi_hz and math.isfinite(hi_hz)) or int(num) < 2:
        raise ValueError(
            f"mesh frequencies {lo_hz:g} to {hi_hz:g} Hz ({num}): give 0 < LO < HI, NUM >= 2"
        )
    if not is_planetary(resolve_target(target)):
        raise ValueError(
            f"{target}: mesh_response steps a planetary set's mesh frequency (its sun and ring "
            "meshes); for a gear train sweep mesh_frequency_hz (gearsym.sweep) and read each "
            "run's meshes with gearsym.planetary.contact"
        )
    system = dynamics(target, **values)
    static = system.module.mesh_deflections(loaded_state(system))
    freqs = np.linspace(lo_hz, hi_hz, int(num))
    kinds = {k: v["kind"] for k, v in system.module.MESHES.items()}
    out = {}
    for direction, order in (("up", freqs), ("down", freqs[::-1])):
        rows = {
            kind: {"u_max": [], "u_min": [], "apart": [], "dynamic_factor": []}
            for kind in sorted(set(kinds.values()))
        }
        status = []
        x0 = loaded_state(system)
        for f in order:
            s = system.with_values(mesh_frequency_hz=float(f))
            tr, c = _point(s, x0, transient, periods)
            status.append(tr.status)
            if c is None:
                x0 = loaded_state(system)
                for r in rows.values():
                    for key in r:
                        r[key].append(None)
                continue
            x0 = tr.x_final
            for kind, r in rows.items():
                here = [m for m, k in kinds.items() if k == kind]
                r["u_max"].append(max(c[m]["max"] for m in here))
                r["u_min"].append(min(c[m]["min"] for m in here))
                r["apart"].append(max(c[m]["apart"] for m in here))
                r["dynamic_factor"].append(
                    max(c[m]["force_max"] / (float(static[m]) - 1.0) for m in here)
                )
        if direction == "down":
            status = status[::-1]
            for r in rows.values():
                for key in r:
                    r[key] = r[key][::-1]
        out[direction] = {"status": status, **rows}

    def apart(which) -> list:
        return [
            any((out[d][kind]["apart"][i] or 0) > 0 for d in out for kind in which)
            for i in range(len(freqs))
        ]

    every = sorted(set(kinds.values()))
    ps = load_planetary(resolve_target(target))
    structure = derive_planetary(ps).as_structure()
    natural = sorted(
        {round(m.frequency_hz, 6) for m in planetary_modes(structure, ps.name).modes} - {0.0}
    )
    harmonics = ps.variation.harmonics if ps.variation is not None else 1
    resonances = [
        {"natural_hz": fk, "harmonic": h, "mesh_hz": fk / h}
        for fk in natural
        for h in range(1, harmonics + 1)
        if lo_hz <= fk / h <= hi_hz
    ]
    return {
        "model": system.name,
        "frequencies_hz": freqs.tolist(),
        "values": dict(system.values),
        "sun_force_N": float(system.p[1] * system.module.K_REF * system.module.LENGTH_M),
        "static_deflection": {k: float(v) for k, v in static.items()},
        "runs": {"transient": transient, "periods": periods, "samples_per_period": 64},
        "up": out["up"],
        "down": out["down"],
        "band_hz": _bands(freqs, apart(every)),
        "band_hz_by_kind": {kind: _bands(freqs, apart([kind])) for kind in every},
        "natural_hz": natural,
        "resonances": sorted(resonances, key=lambda r: r["mesh_hz"]),
    }


def _bands(freqs, flags) -> list:
    """[lo, hi] of each run of consecutive frequencies where ``flags`` holds."""
    out, start = [], None
    for k, on in enumerate(flags):
        if on and start is None:
            start = k
        if start is not None and (not on or k == len(flags) - 1):
            end = k if on else k - 1
            out.append([float(freqs[start]), float(freqs[end])])
            start = None
    return out
