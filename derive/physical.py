"""The quantities an engineer varies, in their own units, kept symbolic into ``parameters()``.

A generated model's parameters are non-dimensional (``derive/parameters.py``); an engineer
thinks in rpm, N m, um and kg m^2.  :func:`physical_layer` gives, for one model, the
physical quantities a user may set by name and the closed forms that turn them into the
model's parameters -- the same closed forms the audit page prints
(``derive/equations/nondim.py``): ``omega_n = sqrt(k_m,1 W_11)``,
``kappa_ij = W_ij b_j k_m,j / (b_i omega_n^2)``, ``xi_ij``, ``f_i = (C A I^-1 T)_i /
(b_i omega_n^2)``, ``E_jh = e_jh / b_j``, the layout phase ``2 pi frac(z psi / 360)``.
The generated ``parameters()`` evaluates them, so a sweep over the speed or a torque needs
no new derivation.

Quantities (``<gear>``, ``<mesh>``: the topology's ids):

========================================  ============================================
``speed_rpm``                             speed of the operating gear (the topology's
                                          ``[operating]`` gear, else the reference
                                          mesh's driver), rpm
``torque_Nm_<gear>``                      external torque on a gear, N m
``attached_inertia_kg_m2_<gear>``         inertia attached to a gear, kg m^2
``half_backlash_um_<mesh>``               half backlash of a mesh, um
``stiffness_scale_<mesh>``                factor on the mesh's whole stiffness k(t)
``stiffness_harmonic_scale_<mesh>``       factor on its stiffness harmonics only
``te_amplitude_um_<mesh>``                first transmission-error harmonic, um
``te_phase_deg_<mesh>``                   its phase, deg
``layout_angle_deg_<mesh>``               angle from the reference mesh round the
                                          shared gear, deg (meshes phased by layout)
========================================  ============================================

with aliases for every mesh (``half_backlash_um``, ``stiffness_scale``,
``stiffness_harmonic_scale``, ``te_amplitude_um``, ``te_phase_deg``, ``layout_angle_deg``)
and ``flywheel_inertia_kg_m2`` (the one gear with an attached inertia).  Inertias, stiffness
scales and backlash enter ``omega_n`` and the coupling terms, so they are offered on
torsional models with mesh damping; a model with bearings or modal damping offers the
speed, the transmission error, the phases and the harmonic scale, and its other quantities
are open values (a new derivation, ``derive/input/open_values.py``).

What a scene states is held: a scene that states ``omega`` keeps ``omega`` when an inertia
changes (the speed follows), and one whose loads are non-dimensional (``[loads]``) keeps
them; setting ``speed_rpm`` or any ``torque_Nm_<gear>`` switches that quantity to its
physical form, and setting both forms of one quantity is refused (``replaces``).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import sympy as sp

__all__ = ["PhysicalLayer", "Quantity", "physical_layer"]

MICRO = sp.Rational(1, 10**6)


@dataclass(frozen=True)
class Quantity:
    """One physical quantity: its name, default (the scene's value), unit, meaning and the
    interval it must lie in (``high`` None: no upper bound; ``low_open``: low excluded)."""

    name: str
    value: float
    unit: str
    meaning: str
    low: float
    high: float | None
    low_open: bool = False


@dataclass(frozen=True)
class PhysicalLayer:
    """The physical quantities of one model and the closed forms of its parameters.

    ``always`` maps a model parameter to its expression in the quantities' symbols (and
    ``zeta``, the damping ratio), evaluated whenever a physical value is given; ``speed``
    holds omega's (used when ``speed_rpm`` is given, or always when ``omega_from_speed``),
    ``loads`` the static loads' (when a torque is given, or always when
    ``loads_from_torques``); ``phases`` maps a phase parameter to (teeth of the shared
    gear, the layout angle's quantity).  ``scales`` gives omega_n (rad/s), each mesh's half
    backlash (m) and mean stiffness (N/m) as expressions, for results in physical units.
    """

    quantities: tuple[Quantity, ...]
    symbols: tuple[sp.Symbol, ...]
    zeta: sp.Symbol
    aliases: dict[str, tuple[str, ...]]
    replaces: dict[str, tuple[str, ...]]
    always: dict[str, sp.Expr]
    speed: dict[str, sp.Expr]
    loads: dict[str, sp.Expr]
    phases: dict[str, tuple[float, str]]
    scales: dict[str, sp.Expr]
    omega_from_speed: bool
    loads_from_torques: bool
    speed_gear: str
    mesh_rad_per_rpm: float  # the reference mesh's frequency (rad/s) per rpm of speed_gear

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(q.name for q in self.quantities)


def physical_layer(scene, nd, pars, names: tuple[str, ...], sources: dict) -> PhysicalLayer:
    """The physical layer of a model (module docstring): ``nd`` its closed forms
    (``NonDim`` or ``Structure``), ``pars`` its :class:`~.parameters.ModelParameters`,
    ``names`` the parameters its equations use, ``sources`` how the scene's parameters set
    them (``Model.parameter_sources``: Python source in ``s['<scene parameter>']``)."""
    topo = scene.topology
    meshes = topo.meshes
    coords = tuple(me.coordinate for me in meshes)
    torsional = hasattr(nd, "equations")
    full = torsional and nd.damping == "mesh"
    quantities: list[Quantity] = []
    symbols: list[sp.Symbol] = []

    def add(name, value, unit, meaning, low, high, low_open=False) -> sp.Symbol:
        quantities.append(Quantity(name, float(value), unit, meaning, low, high, low_open))
        symbols.append(sp.Symbol(f"_q{len(symbols)}", real=True))
        return symbols[-1]

    omega_n_value = nd.value(nd.omega_n_expr)
    ref = topo.reference
    gear = topo.operating.gear if topo.operating is not None else ref.driver
    ratio = topo.speed_ratios(gear)
    # rad/s of the reference mesh per rad/s of the operating gear
    mesh_per_gear = float(topo.gear(ref.driver).teeth * ratio[ref.driver])
    speed_value = _round(pars.omega_value * omega_n_value / mesh_per_gear * 30.0 / math.pi)
    speed = add(
        "speed_rpm",
        speed_value,
        "rpm",
        f"speed of gear '{gear}'",
        0.0,
        1e6,
        True,
    )
    subs: dict = {}
    if full:
        eq = nd.equations
        torques = _scene_torques(scene, nd, pars, ratio)
        for k, g in enumerate(topo.gears):
            torque = add(
                f"torque_Nm_{g.id}",
                torques[k],
                "N m",
                f"external torque on gear '{g.id}'",
                -1e9,
                1e9,
            )
            attached = add(
                f"attached_inertia_kg_m2_{g.id}",
                g.attached_inertia,
                "kg m^2",
                f"inertia attached to gear '{g.id}'",
                0.0,
                1e9,
            )
            subs[eq.torque[k]] = torque
            subs[eq.inertia[k]] = sp.Float(g.gear_inertia, 17) + attached
        for i, me in enumerate(meshes):
            b = add(
                f"half_backlash_um_{me.id}",
                _round(me.half_backlash * 1e6),
                "um",
                f"half backlash of mesh '{me.id}'",
                0.0,
                1e5,
                True,
            )
            scale = add(
                f"stiffness_scale_{me.id}",
                1.0,
                "1",
                f"factor on the stiffness of mesh '{me.id}' (mean and harmonics)",
                0.0,
                1e3,
                True,
            )
            subs[eq.half_backlash[i]] = b * MICRO
            subs[eq.mean_stiffness[i]] = sp.Float(me.stiffness.mean, 17) * scale
    fixed = {k: sp.Float(v, 17) for k, v in nd.values.items() if k not in subs and k != nd.zeta}

    def closed(expr) -> sp.Expr:
        return sp.sympify(expr).xreplace(subs).xreplace(fixed)

    omega_n = closed(nd.omega_n_expr)
    always: dict[str, sp.Expr] = {}
    if full:
        for (i, j), sym in pars.kappa.items():
            always[sym.name] = closed(nd.kappa[i, j])
        for (i, j), sym in pars.xi.items():
            always[sym.name] = closed(nd.xi[i, j])
    te_names = {}
    for (j, h), sym in pars.te_amp.items():
        me = meshes[j]
        b = subs.get(nd.equations.half_backlash[j], None) if full else None
        b = b if b is not None else sp.Float(me.half_backlash, 17)
        if h == 1:
            a = add(
                f"te_amplitude_um_{me.id}",
                _round(me.transmission_error.amplitudes[0] * 1e6),
                "um",
                f"first transmission-error harmonic of mesh '{me.id}'",
                0.0,
                1e4,
            )
            te_names[j] = f"te_amplitude_um_{me.id}"
        else:
            a = sp.Float(_round(me.transmission_error.amplitudes[h - 1] * 1e6), 17)
        always[sym.name] = a * MICRO / b
    for (j, h), sym in pars.te_phase.items():
        if h != 1:
            continue
        me = meshes[j]
        ph = add(
            f"te_phase_deg_{me.id}",
            math.degrees(me.transmission_error.phases[0]),
            "deg",
            f"phase of the first transmission-error harmonic of mesh '{me.id}'",
            -360.0,
            360.0,
        )
        always[sym.name] = ph * sp.Float(math.pi / 180, 17)
    by_mesh_harmonics: dict[int, list] = {}
    for (j, _h), sym in list(pars.kc.items()) + list(pars.ks.items()):
        by_mesh_harmonics.setdefault(j, []).append(sym)
    for j, syms in by_mesh_harmonics.items():
        me = meshes[j]
        base = me.stiffness.harmonic_scale
        if base <= 0:  # the harmonics are gone: nothing to scale
            continue
        s = add(
            f"stiffness_harmonic_scale_{me.id}",
            base,
            "1",
            f"factor on the stiffness harmonics of mesh '{me.id}' (the mean kept)",
            0.0,
            1e3,
        )
        for sym in syms:
            value = pars_value(pars, sym.name)
            always[sym.name] = sp.Float(value / base, 17) * s
    phases: dict[str, tuple[float, str]] = {}
    for j, sym in pars.phi.items():
        me = meshes[j]
        if me.layout_angle is None:
            continue
        teeth, angle = me.layout_angle
        add(
            f"layout_angle_deg_{me.id}",
            angle,
            "deg",
            f"angle of mesh '{me.id}' from the reference mesh round the shared gear",
            -360.0,
            360.0,
        )
        phases[sym.name] = (float(teeth), f"layout_angle_deg_{me.id}")
    speed_expr = speed * sp.Float(mesh_per_gear * math.pi / 30, 17) / omega_n
    loads = {}
    if full:
        for i in range(len(coords)):
            loads[pars.loads[i].name] = closed(nd.load[i])
    keep = set(names) | {"omega"}
    q_names = [q.name for q in quantities]

    def present(prefix: str) -> tuple[str, ...]:
        return tuple(n for n in q_names if n.startswith(prefix))

    aliases = {
        "half_backlash_um": present("half_backlash_um_"),
        "stiffness_scale": present("stiffness_scale_"),
        "stiffness_harmonic_scale": present("stiffness_harmonic_scale_"),
        "te_amplitude_um": present("te_amplitude_um_"),
        "te_phase_deg": present("te_phase_deg_"),
        "layout_angle_deg": present("layout_angle_deg_"),
    }
    carriers = [g.id for g in topo.gears if g.attached_inertia > 0]
    if full and len(carriers) == 1:
        aliases["flywheel_inertia_kg_m2"] = (f"attached_inertia_kg_m2_{carriers[0]}",)
    aliases = {k: v for k, v in aliases.items() if v and k not in q_names}
    # What a torque replaces: the loads, and the scene parameters that set them.
    load_keys = set(loads)
    for name in loads:
        load_keys |= set(re.findall(r"s\['([A-Za-z_][A-Za-z0-9_]*)'\]", sources.get(name, "")))
    load_keys = sorted(load_keys)
    replaces = {"speed_rpm": ("omega",)}
    for n in q_names:
        if n.startswith("torque_Nm_"):
            replaces[n] = tuple(load_keys)
    for j, n in te_names.items():
        replaces[n] = (f"E_{coords[j]}_1",)
        replaces[f"te_phase_deg_{meshes[j].id}"] = (f"psi_{coords[j]}_1",)
    for name, (_, q) in phases.items():
        replaces[q] = (name,)
    scales = {"omega_n_rad_per_s": omega_n}
    for i, me in enumerate(meshes):
        if full:
            scales[f"half_backlash_m_{me.coordinate}"] = subs[nd.equations.half_backlash[i]]
            scales[f"mean_stiffness_N_per_m_{me.coordinate}"] = subs[nd.equations.mean_stiffness[i]]
        else:
            scales[f"half_backlash_m_{me.coordinate}"] = sp.Float(me.half_backlash, 17)
            scales[f"mean_stiffness_N_per_m_{me.coordinate}"] = sp.Float(me.stiffness.mean, 17)
    return PhysicalLayer(
        quantities=tuple(quantities),
        symbols=tuple(symbols),
        zeta=nd.zeta,
        aliases=aliases,
        replaces={k: tuple(c for c in v if c) for k, v in replaces.items()},
        always={k: v for k, v in always.items() if k in keep},
        speed={"omega": speed_expr},
        loads={k: v for k, v in loads.items() if k in keep},
        phases={k: v for k, v in phases.items() if k in keep},
        scales=scales,
        omega_from_speed=scene.omega is None,
        loads_from_torques=scene.loads is None,
        speed_gear=gear,
        mesh_rad_per_rpm=mesh_per_gear * math.pi / 30.0,
    )


def pars_value(pars, name: str) -> float:
    """The value of model parameter ``name`` in ``pars``."""
    for p in pars.parameters:
        if p.name == name:
            return p.value
    raise KeyError(name)


def _round(x: float) -> float:
    """``x`` to 15 significant digits: 50 um, not 49.99999999999999 (a unit conversion's
    last bit), as the user wrote it."""
    return float(f"{x:.15g}")


def _scene_torques(scene, nd, pars, ratio) -> list[float]:
    """The torques (N m) of the scene's operating point: the topology's, or, for a scene
    whose loads are non-dimensional (``[loads]``), the steady torques that give them --
    ``f(T) = f_scene`` with no power into the rigid-body rotation, ``sum T_k w_k = 0``
    (one solution: the load map's null space is that rotation)."""
    import numpy as np

    topo = scene.topology
    gears = topo.gears
    if scene.loads is None:
        return [topo.torques.get(g.id, 0.0) for g in gears]
    eq = nd.equations
    m = len(topo.meshes)
    rows = [
        [nd.value(sp.diff(nd.load[i], eq.torque[k])) for k in range(len(gears))] for i in range(m)
    ]
    rows.append([float(ratio[g.id]) for g in gears])
    target = [pars_value(pars, pars.loads[i].name) for i in range(m)] + [0.0]
    solved = np.linalg.solve(np.array(rows), np.array(target))
    return [_round(float(t)) for t in solved]
