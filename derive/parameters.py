"""The parameters of a model's non-dimensional equations: their order, values and meanings.

``model_parameters(scene, nd, displacements)`` gives every parameter the features need, in
the order of the generated code (``derive_model`` then drops those no term uses):

1. ``omega`` -- excitation frequency of the reference mesh over ``omega_n``;
2. ``f_<i>`` -- static load of each coordinate;
3. ``xi_<i>_<j>`` -- damping coefficients (off-diagonal only with damping coupling);
4. ``kappa_<i>_<j>`` -- mean stiffness coefficients ``K_ij`` (structural zeros omitted);
5. ``kc_<j>_<h>``, ``ks_<j>_<h>`` -- stiffness harmonics of mesh j over its mean;
6. ``phi_<j>`` -- stiffness/TE phase lag of mesh j (mesh phase on, non-reference meshes);
7. ``E_<j>_<h>``, ``psi_<j>_<h>`` -- transmission-error harmonics over ``b_j``, and phases;
8. backlash parameters (``g1, g3, ...`` or ``eps_g``).

Every value is non-dimensional (a phase in rad) and comes from the closed forms of ``nd``
(``derive/equations/nondim.py``, or ``structure.py`` beyond torsion), the scene and the
topology; a value that is not finite is refused with the data to check.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import sympy as sp

from .input.reader import InputError
from .input.scene import Scene, limit_text

__all__ = ["ModelParameters", "Parameter", "model_parameters"]


@dataclass(frozen=True)
class Parameter:
    """One parameter of the emitted model: name, value, meaning and LaTeX symbol."""

    name: str
    value: float
    meaning: str
    latex: str


@dataclass(frozen=True)
class ModelParameters:
    """Every parameter in emitted order, and the symbols by role.

    ``loads`` holds the load symbol of each displacement (0 where a translation has none);
    ``xi`` and ``kappa`` are keyed by ``(equation i, displacement j)``, ``kc``, ``ks``,
    ``te_amp`` and ``te_phase`` by ``(mesh j, harmonic h)``, ``phi`` by mesh j; ``signs``
    is the sign of each mesh coordinate's load (from a load reading, else +1).
    """

    parameters: tuple[Parameter, ...]
    omega: sp.Symbol
    omega_value: float
    signs: dict[str, int]
    loads: tuple[sp.Expr, ...]
    xi: dict
    kappa: dict
    kc: dict
    ks: dict
    phi: dict
    te_amp: dict
    te_phase: dict


def model_parameters(scene: Scene, nd, displacements: tuple[str, ...]) -> ModelParameters:
    """The parameters of ``scene``'s model (see the module docstring for the order).

    ``nd`` holds the closed forms and their values (``value``, ``omega_n_expr``, ``load``,
    ``xi``, ``kappa``); ``displacements`` names every coordinate: the meshes', then any
    shafts and translations.
    """
    topo = scene.topology
    feats = scene.features
    meshes = topo.meshes
    m = len(meshes)
    coords = tuple(me.coordinate for me in meshes)
    disp = displacements
    N = len(disp)

    params: list[Parameter] = []

    def param(name: str, value: float, meaning: str, latex: str) -> sp.Symbol:
        if not math.isfinite(value):
            raise InputError(
                topo.source,
                "mesh",
                f"the data give {name} = {value}, which is not finite; check the stiffness, "
                "backlash and inertia values for extreme magnitudes",
            )
        params.append(Parameter(name, float(value), meaning, latex))
        return sp.Symbol(name, real=True)

    omega_value = scene.omega
    if omega_value is None:  # a topology: from its operating speed and omega_n
        omega_n = nd.value(nd.omega_n_expr)
        omega_value = topo.reference_mesh_frequency() / omega_n
        if (why := limit_text("omega", omega_value)) is not None:
            raise InputError(
                topo.source,
                "operating.speed_rpm",
                f"gives omega = mesh frequency / omega_n = {omega_value:.3g} (omega_n = "
                f"{omega_n:.3g} rad/s from the stiffness and inertias), and omega {why}; check "
                "the speed, the stiffness and the inertias",
            )
    omega = param(
        "omega",
        omega_value,
        "excitation (mesh) frequency of the reference mesh over omega_n",
        r"\bar\omega",
    )
    # Static loads.
    signs = {c: 1 for c in coords}
    if scene.load_reading is not None and scene.loads is not None:  # sizes; signs derived
        from .input.readings import load_signs

        for c, (_, slope, sigma) in load_signs(nd, topo, scene.load_reading, scene.source).items():
            signs[c] = slope * sigma
    if scene.loads is not None:
        f_values = [signs[c] * scene.loads[c] for c in coords]
        f_meaning = "static load (from the scene's [loads])"
        if scene.load_reading is not None:
            f_meaning = f"static load (size from [loads], sign from reading {scene.load_reading})"
    else:
        f_values = [nd.value(nd.load[i]) for i in range(m)]
        f_meaning = "static load (from the topology's torques)"
    f = [param(f"f_{c}", f_values[i], f_meaning, f"f_{{{c}}}") for i, c in enumerate(coords)]
    # Beyond the meshes: a shaft's load from the torques; none on a translation.
    for i in range(m, N):
        load = nd.value(nd.load[i])
        meaning = "static load (from the topology's torques)"
        f.append(
            param(f"f_{disp[i]}", load, meaning, f"f_{{{disp[i]}}}") if load else sp.Integer(0)
        )
    f = tuple(f)

    def what(j: int) -> str:
        return f"g({disp[j]})" if j < m else disp[j]

    xi = {}
    for i in range(N):
        for j in range(N):
            if nd.xi[i, j] == 0 or (i != j and not feats.damping_coupling):
                continue
            xi[i, j] = param(
                f"xi_{disp[i]}_{disp[j]}",
                nd.value(nd.xi[i, j]),
                f"damping coefficient of d{disp[j]} in the {disp[i]} equation",
                rf"\xi_{{{disp[i]}{disp[j]}}}",
            )
    kappa = {}
    for i in range(N):
        for j in range(N):
            if nd.kappa[i, j] == 0:
                continue
            kappa[i, j] = param(
                f"kappa_{disp[i]}_{disp[j]}",
                nd.value(nd.kappa[i, j]),
                f"mean stiffness coefficient of {what(j)} in the {disp[i]} equation",
                rf"K_{{{disp[i]}{disp[j]}}}",
            )
    H = feats.stiffness_harmonics
    kc, ks = {}, {}
    for j, me in enumerate(meshes):
        if H > me.stiffness.harmonics:
            raise InputError(
                scene.source,
                "features.stiffness_harmonics",
                f"asks for {H} harmonics but mesh '{me.id}' of {topo.source} gives only "
                f"{me.stiffness.harmonics}; lower it or give more harmonics",
            )
        cs, ss = me.stiffness.normalised(H)
        for h in range(1, H + 1):
            kc[j, h] = param(
                f"kc_{coords[j]}_{h}",
                cs[h - 1],
                f"cosine stiffness harmonic {h} of mesh {me.id} over its mean",
                rf"\alpha_{{{coords[j]},{h}}}",
            )
            ks[j, h] = param(
                f"ks_{coords[j]}_{h}",
                ss[h - 1],
                f"sine stiffness harmonic {h} of mesh {me.id} over its mean",
                rf"\beta_{{{coords[j]},{h}}}",
            )
    phi = {}
    if feats.mesh_phase:
        for j, me in enumerate(meshes[1:], start=1):
            phi[j] = param(
                f"phi_{coords[j]}",
                me.phase,
                f"stiffness/TE phase lag of mesh {me.id}, rad ({me.phase_source})",
                rf"\varphi_{{{coords[j]}}}",
            )
    te_amp, te_phase = {}, {}
    if feats.transmission_error:
        for j, me in enumerate(meshes):
            te = me.transmission_error
            if not any(a != 0 for a in te.amplitudes):
                continue
            for h, (a, ph) in enumerate(zip(te.amplitudes, te.phases, strict=True), start=1):
                te_amp[j, h] = param(
                    f"E_{coords[j]}_{h}",
                    a / me.half_backlash,
                    f"transmission-error harmonic {h} of mesh {me.id} over its half backlash",
                    rf"E_{{{coords[j]},{h}}}",
                )
                te_phase[j, h] = param(
                    f"psi_{coords[j]}_{h}",
                    ph,
                    f"transmission-error phase {h} of mesh {me.id}, rad",
                    rf"\psi_{{{coords[j]},{h}}}",
                )
    # The backlash expression refers to its parameters by name; register them in order.
    for pname, value, meaning in feats.backlash.parameters():
        param(pname, value, meaning, _latex_backlash(pname))
    return ModelParameters(
        tuple(params), omega, omega_value, signs, f, xi, kappa, kc, ks, phi, te_amp, te_phase
    )


def _latex_backlash(name: str) -> str:
    if name == "eps_g":
        return r"\varepsilon_g"
    return f"a_{{{name[1:]}}}"
