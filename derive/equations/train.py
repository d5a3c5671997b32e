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

``M = diag(I_i / r_i^2)`` and ``K = R^T diag(k) R``.  **Rigid-body modes** are the null space
of ``R`` (relative tolerance 1e-10 of its largest singular value), found from the
kinematic graph the links draw: a train that turns has one.  A loop whose ratios do not
close (going round it the speeds do not come back to themselves) has none and cannot
turn: its nonlinear model is refused, its modes are those of the locked structure.  Bodies
in two unjoined groups are refused.

**The nonlinear model** (``[train.dynamics]``): ``body_dynamics.py`` with every mesh a dead
zone, its stiffness variation ``v_j = sum_l c_l cos(l (h_j omega tau - 2 pi gamma_j)) + s_l
sin(...)``, ``h_j`` its frequency over the first mesh's (whole, from the teeth and the
rigid rotation; a mesh turning at a fraction of the first one's is refused, so the model's
forcing period is the first mesh's) and ``gamma_j`` its ``phase``.  The load per unit
``f`` (the ``load_factor``): each body's torque ``tau_i`` as the force ``tau_i / r_i`` on
``u_i``, and each shaft's assembly twist ``Delta_j`` as ``R_j^T k_j Delta_j`` (its spring
``k_j (delta_j - f Delta_j)``).  The twists leave the rigid rotation unforced by
themselves (``R phi_0 = 0``); the torques must too (their power ``sum tau_i theta_i'`` zero,
no losses being modelled), else the train would speed up, and are refused.

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

import numpy as np

from ..input.reader import InputError
from ..input.train import Train
from .body_dynamics import Bodies, BodyDynamics, build

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

    def as_structure(self, omega_n: float | None = None) -> dict:
        """The ``STRUCTURE`` mapping of a generated module (``solver.analysis.modes``)."""
        first = self.train.meshes[0]
        out = {
            "physical": self.physical,
            "mass": self.mass,
            "coordinates": self.springs,
            "kinds": self.kinds,
            "incidence": tuple(tuple(float(v) for v in row) for row in self.incidence),
            "stiffness": self.stiffness,
            "members": self.members,
            "motions": ("rotation",) * len(self.physical),
            "reference_teeth": self.train.bodies[self._index(first.bodies[0])].teeth,
            "reference_driver": first.bodies[0],
        }
        return out | ({"omega_n": omega_n} if omega_n is not None else {})

    def _index(self, body: str) -> int:
        return [b.id for b in self.train.bodies].index(body)


def derive_train(train: Train) -> TrainStructure:
    """The linear model of ``train`` (module docstring)."""
    ids = [b.id for b in train.bodies]
    radius = {b.id: b.radius for b in train.bodies}
    links = (*train.meshes, *train.shafts)
    R = np.zeros((len(links), len(ids)))
    for j, link in enumerate(links):
        a, b = (ids.index(x) for x in link.bodies)
        if link.kind == "mesh":
            R[j, a], R[j, b] = 1.0, (-1.0 if link.internal else 1.0)
        else:
            R[j, a], R[j, b] = 1.0 / radius[link.bodies[0]], -1.0 / radius[link.bodies[1]]
    sv = np.linalg.svd(R, compute_uv=False)
    rank = int(np.sum(sv > 1e-10 * sv.max()))
    rigid = len(ids) - rank
    if rigid > 1:
        raise InputError(
            train.source,
            "train",
            f"the bodies form {rigid} groups that no mesh or shaft joins; join them (or "
            "describe each group in its own file)",
        )
    phi = np.linalg.svd(R)[2][-1] if rigid else None
    return TrainStructure(
        train=train,
        physical=tuple(f"u_{i + 1}" for i in range(len(ids))),
        members=tuple(ids),
        mass=tuple(b.inertia / b.radius**2 for b in train.bodies),
        springs=tuple(link.id for link in links),
        kinds=tuple(link.kind for link in links),
        incidence=R,
        stiffness=tuple(link.stiffness for link in links),
        rigid_body_modes=rigid,
        rigid=phi,
    )


def mesh_multiples(st: TrainStructure) -> tuple[float, ...]:
    """Each mesh's frequency over the first mesh's in the rigid rotation: ``z_a |theta_a'|``
    of its first gear, ``theta' = phi_0 / r``; also checks that each mesh's two gears pass
    teeth at one rate (their teeth and base radii agree)."""
    train = st.train
    ids = [b.id for b in train.bodies]
    body = {b.id: b for b in train.bodies}
    speed = {i: abs(st.rigid[ids.index(i)]) / body[i].radius for i in ids}
    rates = []
    for m in train.meshes:
        a, b = (body[x] for x in m.bodies)
        ra, rb = a.teeth * speed[a.id], b.teeth * speed[b.id]
        if abs(ra - rb) > 1e-3 * max(ra, rb):
            raise InputError(
                train.source,
                f"train.mesh {m.id}",
                f"gears {a.id!r} and {b.id!r} pass teeth at different rates: their teeth "
                f"({a.teeth}, {b.teeth}) and base radii ({a.radius * 1e3:g}, "
                f"{b.radius * 1e3:g} mm) disagree; a mesh's gears share a base pitch",
            )
        rates.append(ra)
    return tuple(r / rates[0] for r in rates)


def _loaded(st: TrainStructure) -> np.ndarray:
    """F per unit load factor (N on each u): the torques over the radii and the shafts'
    assembly twists (module docstring); refused where the torques' power is not zero."""
    train = st.train
    ids = [b.id for b in train.bodies]
    tau = np.array([train.torques.get(b.id, 0.0) / b.radius for b in train.bodies])
    power = float(st.rigid @ tau)
    scale = float(np.abs(st.rigid) @ np.abs(tau))
    if scale > 0 and abs(power) > 1e-9 * scale:
        speeds = [st.rigid[ids.index(i)] / train.bodies[ids.index(i)].radius for i in ids]
        ratio = ", ".join(f"{i} {s / speeds[0]:+.6g}" for i, s in zip(ids, speeds, strict=True))
        raise InputError(
            train.source,
            "train.torque",
            "the torques do not balance at the train's speeds (relative speeds: "
            f"{ratio}), so it would speed up; losses are not modelled: give torques "
            "whose power adds up to zero",
        )
    k = np.asarray(st.stiffness)
    twist = np.array([0.0] * len(train.meshes) + [s.twist for s in train.shafts])
    return tau + st.incidence.T @ (k * twist)


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
        if m.variation and abs(h - round(h)) > 1e-6:
            raise InputError(
                train.source,
                f"train.mesh {m.id}",
                f"its mesh frequency is {h:.6g} times the first mesh's, not a whole multiple; "
                "list first the mesh of the lowest frequency, or give this one no variation",
            )
        terms = []
        for l_, (a, b) in enumerate(m.variation, start=1):
            phi = 2 * math.pi * l_ * m.phase
            c, s = math.cos(phi), math.sin(phi)
            terms.append((l_ * round(h), a * c - b * s, a * s + b * c))
        waves[j] = tuple(terms)
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
            ("load_factor", "f", 1.0, "nonnegative", "the load factor, 1 the file's load"),
            ("damping_ratio", "zeta", 1.0, "unit", "the damping ratio"),
        ),
        data={
            "shafts": shafts,
            "bodies": tuple(st.members),
            "structure": st.as_structure(eq["omega_n"]),
        },
        **eq,
    )
