"""A gear train with closed loops in its bodies' rotations (issue 26, point 1).

Each body ``i`` turns by ``theta_i``; its coordinate is ``u_i = r_i theta_i`` (``r_i`` its base
radius), its mass ``I_i / r_i^2``, so a mesh's deflection along its line of action is a sum
of coordinates, as in a planetary set's torsional model (``planetary.py``).  Every rotation
is counted in one sense:

* external mesh of ``a`` and ``b``: ``delta = u_a + u_b`` (the gears turn in opposite
  senses, so a rigid rotation leaves ``u_a = -u_b``);
* internal mesh, ``b`` the ring: ``delta = u_a - u_b``;
* shaft from ``a`` to ``b``: its twist ``theta_a - theta_b = u_a / r_a - u_b / r_b``, its
  stiffness in N m/rad.

``M = diag(I_i / r_i^2)`` and ``K = R^T diag(k) R``.  **Rigid-body modes** come from the
kinematic graph the links draw, exactly from the teeth: going out from the first body, an
external mesh turns its second gear the other way at ``z_a / z_b`` of the first's speed,
an internal mesh the same way, a shaft alike.  A train that turns has one rigid-body
mode; a loop whose speeds do not come back to themselves (two pairs of unequal ratio in a
back-to-back rig) is locked and cannot turn, and its nonlinear model is refused; bodies in
groups no link joins are refused.  A gear's base radius is taken as its teeth times the
base pitch it shares with the gears it meshes with (their mean ``r / z``; the file's radii
may differ from it by rounding, by at most 1e-3, else the mesh is refused), so that
``R phi_0 = 0`` holds to round-off whatever the radii's rounding.

**The nonlinear model** (``[train.dynamics]``): ``body_dynamics.py`` with every mesh a dead
zone, its stiffness variation ``v_j = sum_l c_l cos(l (h_j omega tau - 2 pi gamma_j)) + s_l
sin(...)``, ``h_j`` its frequency over the first mesh's (whole, from the teeth and the rigid
rotation; a mesh turning at a fraction of the first one's is refused, so the model's forcing
period is the first mesh's) and ``gamma_j`` its ``phase`` in its own mesh periods. The load
per unit ``f`` (the ``load_factor``): each body's torque ``tau_i`` as the force ``tau_i /
r_i`` on ``u_i``, and each shaft's assembly twist ``Delta_j`` as ``R_j^T k_j Delta_j`` (its
spring ``k_j (delta_j - f Delta_j)``). The twists leave the rigid rotation unforced by
themselves (``R phi_0 = 0``); the torques must too (their power ``sum tau_i theta_i'`` zero,
no losses being modelled), else the train would speed up, and are refused (what is left of
their power by rounding, at most 1e-9 of it, is taken out along the rigid rotation).

**Transmission error** (``transmission_error``, as a tree's mesh states it): ``e_j(t) =
sum_l a_l cos(l (h_j omega tau - 2 pi gamma_j) + phi_l)`` is excess material on the loaded
flank, so it adds ``s_j e_j`` to the mesh's deflection, in its force and its damper, ``k (1 +
v) b g((delta + s e) / b) + c (delta' + s e')``: ``s_j`` the sign of the mesh's deflection in
the linear static solution at the file's load, every mesh's teeth touching
(``loaded_flanks``; +1 where it carries none).  The tree models' ``x = C A theta + s e``
differ: their ``s`` is the coordinate's orientation of the load reading, not its loaded
flank, so on a mesh loaded on its back flank (a braking pinion's) the two add the error
with opposite signs (``tests/derive/test_tree_as_train.py`` states it and bridges it).

**Locked-in torque** of a loop of two pairs of equal ratio ``i`` joined by two shafts (a
back-to-back rig), the meshes' teeth touching: going round the loop, the twists and the
deflections referred to the first shaft add up to its assembly twist,

    ``T (1/k_1 + i^2/k_2 + 1/(k_m1 r_1^2) + 1/(k_m2 r_3^2)) = Delta - b_1/r_1 - b_2/r_3``

(``r_1``, ``r_3`` the pinions' base radii on the first shaft, ``b`` the half backlashes the
loop's twist takes up first): the closed form the tests hold the model to.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..input.reader import InputError
from ..input.train import Train
from .body_dynamics import Bodies, BodyDynamics, build, structure_mapping

__all__ = ["TrainStructure", "derive_train", "derive_train_dynamics", "mesh_multiples"]


@dataclass(frozen=True)
class TrainStructure:
    train: Train
    physical: tuple[str, ...]  # u_1, ..., u_n in the order of [[train.body]]
    members: tuple[str, ...]  # each coordinate's body
    mass: tuple[float, ...]
    springs: tuple[str, ...]  # meshes, then shafts
    kinds: tuple[str, ...]  # "mesh" or "shaft"
    incidence: np.ndarray  # R (springs x q)
    stiffness: tuple[float, ...]
    rigid_body_modes: int
    rigid: np.ndarray | None  # phi_0 over q (one rigid-body mode), else None
    radius: tuple[float, ...] = ()  # m: each body's radius as used (a gear's: its pitch's)
    speeds: tuple[Fraction, ...] | None = None  # theta' over the first body's, from the teeth

    def as_structure(self, omega_n: float | None = None) -> dict:
        """The ``STRUCTURE`` mapping of a generated module (``solver.analysis.modes``)."""
        first = self.train.meshes[0]
        out = structure_mapping(self, ("rotation",) * len(self.physical)) | {
            "reference_teeth": self.train.bodies[self.members.index(first.bodies[0])].teeth,
            "reference_driver": first.bodies[0],
        }
        return out | ({"omega_n": omega_n} if omega_n is not None else {})


def _groups(ids, links) -> list[list[str]]:
    """The bodies ``ids`` in groups that ``links`` (meshes, shafts) join."""
    parent = {i: i for i in ids}

    def root(x: str) -> str:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for link in links:
        parent[root(link.bodies[0])] = root(link.bodies[1])
    groups: dict = {}
    for i in ids:
        groups.setdefault(root(i), []).append(i)
    return list(groups.values())


def _speeds(train: Train) -> tuple[Fraction, ...] | None:
    """Each body's speed over the first body's in the rigid rotation, exact from the teeth
    (an external mesh turns its gears the other way at the inverse ratio of their teeth,
    an internal one the same way, a shaft its two bodies alike); None where a loop does not
    close (the train is locked)."""
    ids = [b.id for b in train.bodies]
    teeth = {b.id: b.teeth for b in train.bodies}
    speed: dict = {ids[0]: Fraction(1)}
    links = [
        (m.bodies, Fraction(teeth[m.bodies[0]], teeth[m.bodies[1]]) * (1 if m.internal else -1))
        for m in train.meshes
    ] + [(s.bodies, Fraction(1)) for s in train.shafts]
    changed = True
    while changed:
        changed = False
        for (a, b), ratio in links:  # theta_b' = ratio theta_a'
            if a in speed and b in speed:
                if speed[b] != ratio * speed[a]:
                    return None
            elif a in speed:
                speed[b], changed = ratio * speed[a], True
            elif b in speed:
                speed[a], changed = speed[b] / ratio, True
    return tuple(speed[i] for i in ids)


def _radii(train: Train) -> tuple[float, ...]:
    """Each body's radius as the model uses it: a gear's base radius made exactly its
    teeth times the base pitch its meshing partners share (their mean over the gears that
    mesh together; the file's radii may differ from it by rounding, at most 1e-3 of it),
    so that the meshes' speed ratios are the teeth's; a body without teeth keeps its own."""
    body = {b.id: b for b in train.bodies}
    for m in train.meshes:
        a, b = (body[x] for x in m.bodies)
        pa, pb = a.radius / a.teeth, b.radius / b.teeth
        if abs(pa - pb) > 1e-3 * max(pa, pb):
            raise InputError(
                train.source,
                f"train.mesh {m.id}",
                f"gears {a.id!r} and {b.id!r} pass teeth at different rates: their teeth "
                f"({a.teeth}, {b.teeth}) and base radii ({a.radius * 1e3:g}, "
                f"{b.radius * 1e3:g} mm) disagree; a mesh's gears share a base pitch",
            )
    pitch = {}
    for group in _groups(list(body), train.meshes):  # the gears that mesh together
        gears = [body[g] for g in group if body[g].teeth is not None]
        p = sum(g.radius / g.teeth for g in gears) / len(gears) if gears else None
        pitch.update(dict.fromkeys(group, p))
    in_mesh = {x for m in train.meshes for x in m.bodies}
    return tuple(pitch[b.id] * b.teeth if b.id in in_mesh else b.radius for b in train.bodies)


def derive_train(train: Train) -> TrainStructure:
    """The linear model of ``train`` (module docstring)."""
    groups = _groups([b.id for b in train.bodies], (*train.meshes, *train.shafts))
    if len(groups) > 1:
        raise InputError(
            train.source,
            "train",
            f"the bodies form {len(groups)} groups that no mesh or shaft joins ("
            + "; ".join(", ".join(g) for g in groups)
            + "): join them, or describe each group in its own file",
        )
    ids = [b.id for b in train.bodies]
    radius = _radii(train)
    links = (*train.meshes, *train.shafts)
    R = np.zeros((len(links), len(ids)))
    for j, link in enumerate(links):
        a, b = (ids.index(x) for x in link.bodies)
        if link.kind == "mesh":
            R[j, a], R[j, b] = 1.0, (-1.0 if link.internal else 1.0)
        else:
            R[j, a], R[j, b] = 1.0 / radius[a], -1.0 / radius[b]
    speeds = _speeds(train)
    phi = None
    if speeds is not None:  # the rigid rotation in u = r theta
        phi = np.array([r * float(w) for r, w in zip(radius, speeds, strict=True)])
        phi /= np.linalg.norm(phi)
    return TrainStructure(
        train=train,
        physical=tuple(f"u_{i + 1}" for i in range(len(ids))),
        members=tuple(ids),
        mass=tuple(b.inertia / r**2 for b, r in zip(train.bodies, radius, strict=True)),
        springs=tuple(link.id for link in links),
        kinds=tuple(link.kind for link in links),
        incidence=R,
        stiffness=tuple(link.stiffness for link in links),
        rigid_body_modes=0 if speeds is None else 1,
        rigid=phi,
        radius=radius,
        speeds=speeds,
    )


def mesh_multiples(st: TrainStructure) -> tuple[Fraction, ...]:
    """Each mesh's frequency over the first mesh's in the rigid rotation, exact: ``z_a
    |theta_a'|`` of its first gear."""
    ids = list(st.members)
    teeth = {b.id: b.teeth for b in st.train.bodies}
    rates = [teeth[m.bodies[0]] * abs(st.speeds[ids.index(m.bodies[0])]) for m in st.train.meshes]
    return tuple(r / rates[0] for r in rates)


def _loaded(st: TrainStructure) -> np.ndarray:
    """F per unit load factor (N on each u): the torques over the radii and the shafts'
    assembly twists (module docstring); refused where the torques' power is not zero (to
    1e-9 of their largest; what is left of it is taken out along the rigid rotation)."""
    train = st.train
    tau = np.array([train.torques.get(b.id, 0.0) for b in train.bodies])
    power = sum(Fraction(t) * w for t, w in zip(tau, st.speeds, strict=True))
    if abs(power) > 1e-9 * max(abs(t * float(w)) for t, w in zip(tau, st.speeds, strict=True)):
        ratio = ", ".join(f"{b.id} {w}" for b, w in zip(train.bodies, st.speeds, strict=True))
        raise InputError(
            train.source,
            "train.torque",
            f"the torques do not balance at the train's speeds (relative speeds: {ratio}), "
            "so it would speed up; losses are not modelled: give torques whose power adds up "
            "to zero",
        )
    k = np.asarray(st.stiffness)
    twist = np.array([0.0] * len(train.meshes) + [s.twist for s in train.shafts])
    F = tau / np.asarray(st.radius) + st.incidence.T @ (k * twist)
    m_phi = np.asarray(st.mass) * st.rigid
    return F - (st.rigid @ F) / (st.rigid @ m_phi) * m_phi


def loaded_flanks(st: TrainStructure) -> tuple[int, ...]:
    """Each mesh's loaded flank at the file's load: the sign of its deflection in the
    linear static solution with every mesh's teeth touching (+1 where it carries none)."""
    K = st.incidence.T @ (np.asarray(st.stiffness)[:, None] * st.incidence)
    q = np.linalg.lstsq(K, _loaded(st), rcond=None)[0]  # the load leaves phi_0 unforced
    delta = st.incidence[: len(st.train.meshes)] @ q
    small = 1e-12 * max(1e-300, float(np.max(np.abs(delta))))
    return tuple(-1 if d < -small else 1 for d in delta)


def derive_train_dynamics(st: TrainStructure) -> BodyDynamics:
    """The nonlinear model of a train (module docstring); ``InputError`` where it cannot be
    built (no ``[train.dynamics]``, a locked loop, unbalanced torques, a mesh turning at a
    fraction of the first one's frequency)."""
    train = st.train
    if train.dynamics is None:
        raise InputError(
            train.source,
            "train.dynamics",
            "every command takes a train's model with its operating point: add a "
            "[train.dynamics] table (mesh_frequency_hz, damping_ratio)",
        )
    if st.rigid_body_modes == 0:
        raise InputError(
            train.source,
            "train",
            "the train cannot turn: going round its loop the speed ratios of its meshes and "
            "shafts do not come back to 1, so the loop is locked; check the teeth and base "
            "radii (a back-to-back rig's two pairs need one ratio)",
        )
    multiples = mesh_multiples(st)
    waves = {}
    for j, (m, h) in enumerate(zip(train.meshes, multiples, strict=True)):
        if m.variation and h.denominator != 1:
            raise InputError(
                train.source,
                f"train.mesh {m.id}",
                f"its mesh frequency is {h} times the first mesh's, not a whole multiple; "
                "list first the mesh of the lowest frequency, or give this one no variation",
            )
        terms = []
        for l_, (a, b) in enumerate(m.variation, start=1):
            phi = 2 * math.pi * l_ * m.phase
            c, s = math.cos(phi), math.sin(phi)
            terms.append((l_ * int(h), a * c - b * s, a * s + b * c))
        waves[j] = tuple(terms)
    errors = {}
    flank = loaded_flanks(st)
    for j, (m, h) in enumerate(zip(train.meshes, multiples, strict=True)):
        te = m.error
        if te is None or not te.amplitudes:
            continue
        if h.denominator != 1:
            raise InputError(
                train.source,
                f"train.mesh {m.id}",
                f"its mesh frequency is {h} times the first mesh's, not a whole multiple; "
                "list first the mesh of the lowest frequency, or give this one no "
                "transmission error",
            )
        terms = []
        for l_, (a, phi) in enumerate(zip(te.amplitudes, te.phases, strict=True), start=1):
            psi = 2 * math.pi * l_ * m.phase - phi  # a cos(l (h w t - 2 pi gamma) + phi)
            a *= flank[j]  # excess material presses the loaded flank
            terms.append((l_ * int(h), a * math.cos(psi), a * math.sin(psi)))
        errors[j] = tuple(terms)
    k_ref, b_ref = train.meshes[0].stiffness, train.meshes[0].half_backlash
    meshes = range(len(train.meshes))
    bodies = Bodies(
        physical=st.physical,
        mass=st.mass,
        springs=st.springs,
        kinds=st.kinds,
        incidence=st.incidence,
        stiffness=st.stiffness,
        rigid_body_modes=1,
        half_backlash_m={j: train.meshes[j].half_backlash for j in meshes},
        waves=waves,
        labels={j: "internal" if train.meshes[j].internal else "external" for j in meshes},
        load=_loaded(st) / (k_ref * b_ref),
        reference=0,
        errors=errors,
    )
    eq = build(bodies, ("omega", "f", "zeta"))
    T = eq["transform"]
    n_mesh = len(train.meshes)
    shafts = {
        s.id: {
            # its twist in rad = row . coordinates; its torque k (twist - f twist_0)
            "row": tuple(float(v) for v in b_ref * (st.incidence[n_mesh + i] @ T)),
            "stiffness_Nm_per_rad": s.stiffness,
            "assembly_twist_rad": s.twist,
            "bodies": s.bodies,
        }
        for i, s in enumerate(train.shafts)
    }
    d = train.dynamics
    return BodyDynamics(
        structure=st,
        name=train.name,
        description=train.description,
        source=train.source,
        title="gear train",
        parameters=(
            ("omega", 2 * math.pi * d.mesh_frequency_hz / eq["omega_n"]),
            ("f", 1.0),
            ("zeta", d.damping_ratio),
        ),
        physical=(
            ("mesh_frequency_hz", "omega", "hz", "positive", "the first mesh's frequency in Hz"),
            ("load_factor", "f", 1.0, "positive", "the load factor, 1 the file's load"),
            ("damping_ratio", "zeta", 1.0, "unit", "the damping ratio"),
        ),
        data={
            "shafts": shafts,
            "bodies": tuple(st.members),
            "structure": st.as_structure(eq["omega_n"]),
        },
        **eq,
    )
