"""The immutable non-dimensional Model of one scene.

``derive_model(scene)`` runs the whole derivation (Newton -> reduced -> non-dimensional)
and returns a :class:`Model`: first-order right-hand side ``dX/dtau = F(tau, X, p)`` and
its state Jacobian as SymPy expressions, the ordered state and parameter names, the
scene's parameter values, the scales, and the derivation objects for the audit.

State order: the mesh coordinates ``u_1..u_m`` in mesh order, then their derivatives
``du_1..du_m``.  Parameter order: ``derive/parameters.py`` (omega, loads, damping, mean
stiffness, stiffness harmonics, phases, transmission error, backlash), only the ones the
features need and the equations use.

:attr:`Model.contract` states, as plain Python literals, what a solver needs to know about
the model (format :data:`CONTRACT_FORMAT`); every generated module carries it as
``CONTRACT``.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from functools import cached_property

import sympy as sp

from ._version import EMITTED_FORMAT, __version__
from .contract import CONTRACT_FORMAT, model_contract
from .equations.nondim import NonDim, nondimensionalise
from .equations.structure import derive_structure
from .equations.torsion import derive_equations
from .input.reader import InputError, expression_source
from .input.scene import Features, Scene
from .parameters import Parameter, model_parameters
from .physical import PhysicalLayer, physical_layer

__all__ = ["CONTRACT_FORMAT", "Model", "Parameter", "derive_model", "operation_count"]


def operation_count(expressions) -> int:
    """Arithmetic operations (SymPy's count_ops) after common-subexpression elimination."""
    replacements, reduced = sp.cse(list(expressions), symbols=sp.numbered_symbols("_t"))
    return int(
        sum(sp.count_ops(e) for _, e in replacements) + sum(sp.count_ops(e) for e in reduced)
    )


@dataclass(frozen=True)
class Model:
    """One scene's non-dimensional model (immutable)."""

    name: str
    scene: Scene
    coordinates: tuple[str, ...]
    states: tuple[str, ...]
    parameters: tuple[Parameter, ...]
    forcing_frequency: str  # the parameter omega: excitation period 2 pi / omega
    load_parameters: dict[str, str]  # coordinate -> its static-load parameter
    tau: sp.Symbol
    state_symbols: tuple[sp.Symbol, ...]
    parameter_symbols: tuple[sp.Symbol, ...]
    rhs: tuple[sp.Expr, ...]
    jacobian: sp.ImmutableMatrix
    accelerations: tuple[sp.Expr, ...]
    mesh_forces: tuple[sp.Expr, ...]  # each mesh's dynamic force over its k_m b
    static_kappa: sp.ImmutableMatrix  # kappa at the mean stiffness: kappa F_static = f
    loads: tuple[sp.Symbol, ...]  # f of each coordinate
    kappa_t: sp.ImmutableMatrix  # kappa_ij(tau) in parameter symbols
    displacements: tuple[str, ...]  # every coordinate: the meshes', then shafts, translations
    structure: object  # derive.structure.Structure of a model beyond torsion, else None
    ebar: tuple[sp.Expr, ...]
    nondim: NonDim
    scales: dict
    frequency_ratios: tuple[sp.Rational, ...]
    scene_parameters: dict[str, float]
    parameter_sources: dict[str, str]  # model parameter -> Python source in s['<scene name>']
    inputs_hash: str
    physical: PhysicalLayer | None = None  # the quantities in SI-based units (physical.py)

    @property
    def features(self) -> Features:
        return self.scene.features

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    @property
    def defaults(self) -> tuple[float, ...]:
        return tuple(p.value for p in self.parameters)

    @property
    def valid_range(self) -> float | None:
        return self.features.backlash.valid_range

    @property
    def contract(self) -> dict:
        """What a solver needs to know about this model, as plain Python literals (a new
        dict on each call): see :func:`.contract.model_contract`."""
        return model_contract(self)

    @cached_property
    def operations(self) -> dict[str, int]:
        """Operation counts of the emitted code after common-subexpression elimination."""
        return {
            "rhs": operation_count(self.rhs),
            "rhs_and_jacobian": operation_count(list(self.rhs) + list(self.jacobian)),
        }


def inputs_hash(scene: Scene) -> str:
    """sha256 of everything the generated files depend on: the input files' parsed
    contents (scene and topology), the resolved parameters, the generator's version and
    SymPy's (term order in the emitted code may change with SymPy)."""
    import tomllib
    from pathlib import Path

    payload = {
        "gearsym": __version__,
        "format": EMITTED_FORMAT,
        "sympy": sp.__version__,
        "parameters": scene.parameters,
        "kind": scene.kind,
    }
    if scene.variations:  # a variant of the files (derive.scene.variant)
        payload["variant"] = {"name": scene.name, "features": scene.variations}
    from .input.supports import load_topology_data

    payload["scene"] = tomllib.loads(Path(scene.source).read_text(encoding="utf-8"))
    payload["topology"] = load_topology_data(scene.topology.source)
    text = json.dumps(payload, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def derive_model(scene: Scene, name: str | None = None) -> Model:
    """Derive the non-dimensional model of ``scene`` (see module docstring)."""
    topo = scene.topology
    feats = scene.features
    meshes = topo.meshes
    m = len(meshes)
    coords = tuple(me.coordinate for me in meshes)
    structure = None
    if feats.degrees_of_freedom == "torsional" and not topo.shafts:
        eq = derive_equations(topo)
        nd = nondimensionalise(topo, scene.damping_ratio, eq, scene.damping_normalisation)
        orientation = eq.orientation
        disp = coords
    else:  # bearings or shafts: derive/equations/structure.py
        structure = derive_structure(
            topo, feats.degrees_of_freedom, scene.damping_ratio, scene.source
        )
        _check_structural_scene(scene)
        nd = structure
        orientation = tuple(me.orientation for me in meshes)
        disp = structure.names
    N = len(disp)
    tau = sp.Symbol("tau", real=True)
    u = tuple(sp.Symbol(c, real=True) for c in disp)
    du = tuple(sp.Symbol(f"d{c}", real=True) for c in disp)
    ratios = topo.mesh_frequency_ratios()
    freq = tuple(sp.Rational(ratios[me.id].numerator, ratios[me.id].denominator) for me in meshes)

    pars = model_parameters(scene, nd, disp)
    omega, omega_value, signs, f = pars.omega, pars.omega_value, pars.signs, pars.loads
    xi, kappa, kc, ks, phi = pars.xi, pars.kappa, pars.kc, pars.ks, pars.phi
    te_amp, te_phase = pars.te_amp, pars.te_phase
    H = feats.stiffness_harmonics

    # Assemble the non-dimensional equations.
    phase_arg = [freq[j] * omega * tau - phi.get(j, 0) for j in range(m)]
    khat = [
        1
        + sum(
            kc[j, h] * sp.cos(h * phase_arg[j]) + ks[j, h] * sp.sin(h * phase_arg[j])
            for h in range(1, H + 1)
        )
        for j in range(m)
    ]
    ebar = tuple(
        orientation[j]
        * sum(
            (
                te_amp[j, h] * sp.cos(h * phase_arg[j] + te_phase[j, h])
                for (jj, h) in te_amp
                if jj == j
            ),
            sp.Integer(0),
        )
        for j in range(m)
    ) + (sp.Integer(0),) * (N - m)
    khat += [sp.Integer(1)] * (N - m)
    gexpr = [feats.backlash.expression(u[j]) for j in range(m)] + list(u[m:])
    kappa_t = sp.ImmutableMatrix(N, N, lambda i, j: kappa[i, j] * khat[j] if (i, j) in kappa else 0)
    acc = tuple(
        f[i]
        + sp.diff(ebar[i], tau, 2)
        - sum(2 * xi[i, j] * du[j] for j in range(N) if (i, j) in xi)
        - sum(kappa_t[i, j] * gexpr[j] for j in range(N) if (i, j) in kappa)
        for i in range(N)
    )
    # The dynamic mesh force of each mesh over its k_m b: the elastic part k_hat g(u) and,
    # with one damper per mesh ("mesh" damping), the viscous part c u', whose ratio to the
    # stiffness is 2 xi_jj / kappa_jj in the model's own parameters.  With "modal" damping
    # the damper couples the meshes and only the elastic part is a mesh's own.
    mesh_forces = tuple(
        khat[j] * gexpr[j]
        + (
            2 * xi[j, j] / kappa[j, j] * du[j]
            if nd.damping == "mesh" and (j, j) in xi and (j, j) in kappa
            else 0
        )
        for j in range(m)
    )
    static_kappa = sp.ImmutableMatrix(N, N, lambda i, j: kappa.get((i, j), 0))
    states = disp + tuple(f"d{c}" for c in disp)
    state_symbols = u + du
    rhs = du + acc
    jac = sp.ImmutableMatrix(rhs).jacobian(state_symbols)

    used = set().union(*(e.free_symbols for e in rhs))
    # A parameter no term uses (a phase with constant stiffness and no transmission
    # error, say) is not emitted; omega stays: it sets the forcing period for the solver.
    params = [
        p for p in pars.parameters if p.name == "omega" or sp.Symbol(p.name, real=True) in used
    ]
    names = [p.name for p in params]
    stray = used - set(state_symbols) - {sp.Symbol(n, real=True) for n in names} - {tau}
    if stray:
        raise AssertionError(f"right-hand side uses undeclared symbols {sorted(map(str, stray))}")
    clash = set(names) & set(states)
    if clash or len(set(names)) != len(names):
        raise AssertionError(f"name clash between states and parameters: {sorted(clash)}")

    # How the scene's named parameters set the model's: a sweep over lambda or the damping
    # ratio changes these entries and nothing else.
    scene_parameters = dict(scene.parameters) | {"omega": omega_value}
    sources = {"omega": "s['omega']"}
    if scene.loads is not None:
        for c in coords:
            source = expression_source(scene.load_expressions[c])
            sources[f"f_{c}"] = source if signs[c] > 0 else f"-({source})"
    for i, j in xi:
        if j >= m:  # a bearing's or shaft's own damper: not set by the damping ratio
            continue
        unit = nd.value(nd.xi[i, j].subs(nd.zeta, 1))
        sources[f"xi_{disp[i]}_{disp[j]}"] = f"{float(f'{unit:.15g}')!r} * s['damping_ratio']"

    sources = {k: v for k, v in sources.items() if k in names}
    physical = physical_layer(scene, nd, pars, tuple(names), sources)
    om = nd.value(nd.omega_n_expr)
    scales = {
        "omega_n_rad_per_s": om,
        "time_unit_s": 1.0 / om,
        "half_backlash_m": {me.coordinate: me.half_backlash for me in meshes},
        "mean_stiffness_N_per_m": {me.coordinate: me.stiffness.mean for me in meshes},
        "damping_N_s_per_m": {
            me.coordinate: nd.value(nd.damping_expr[j]) for j, me in enumerate(meshes)
        },
        "mesh_frequency_ratio": {me.coordinate: str(freq[j]) for j, me in enumerate(meshes)},
    }
    return Model(
        name=name or scene.name.replace("-", "_"),
        scene=scene,
        coordinates=coords,
        states=states,
        parameters=tuple(params),
        forcing_frequency=omega.name,
        load_parameters={c: s.name for c, s in zip(coords, f[:m], strict=True)},
        tau=tau,
        state_symbols=state_symbols,
        parameter_symbols=tuple(sp.Symbol(n, real=True) for n in names),
        rhs=tuple(rhs),
        jacobian=jac,
        accelerations=acc,
        mesh_forces=mesh_forces,
        static_kappa=static_kappa,
        loads=f,
        kappa_t=kappa_t,
        displacements=disp,
        structure=structure,
        ebar=ebar,
        nondim=nd,
        scales=scales,
        frequency_ratios=freq,
        scene_parameters=scene_parameters,
        parameter_sources=sources,
        inputs_hash=inputs_hash(scene),
        physical=physical,
    )


def _check_structural_scene(scene: Scene) -> None:
    """What a model with bearings or shafts does not take (one line each)."""
    where = f"{scene.source} [open]"
    if scene.damping_normalisation != "mesh":
        raise InputError(
            where,
            "damping_normalisation",
            f"'{scene.damping_normalisation}' applies to torsional models only; bearings and "
            "shafts bring their own dampers, so use 'mesh'",
        )
    if scene.loads is not None and scene.topology.shafts:
        raise InputError(
            scene.source,
            "loads",
            "a train with shafts takes its loads from the topology's torques (a shaft's "
            "twist needs them too); remove [loads]",
        )
