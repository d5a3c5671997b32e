"""Lateral-torsional(-axial, -tilting) equations: gears on bearings, shafts, helical meshes in 3-D.

Each gear ``k`` has its rotation ``theta_k`` (positive in its operating direction) and, as
the scene asks (``degrees_of_freedom``), its translations ``x_k, y_k`` across its axis and
``z_k`` along it, held by its bearing, and with tilting its rotations ``tx_k, ty_k`` about
the transverse axes x and y (diametral inertia ``J_k``, the bearing's tilting stiffness).
Global frame: ``z`` along the (parallel) axes; the first mesh's driver turns
counter-clockwise seen from ``+z``, an external mesh reverses the sense
(``Topology.senses``, ``epsilon_k = +-1``).

**Mesh.**  The driver's centre lies at the angle ``phi`` round the driven gear's
(``driver_position_deg``).  The transverse line of action, the direction of the force on
the driven gear when the driver's working flank is loaded, is at the angle

    ``psi = phi + epsilon_driven (pi/2 + alpha_wt)``

(tangential in the driven gear's turning sense, tilted by the working pressure angle
towards its centre: the separating force).  The normal line of action adds the base helix
angle: ``n = cos(beta_b) (cos psi, sin psi, 0) + sigma sin(beta_b) (0, 0, 1)`` with
``sigma = sign(beta_driver) epsilon_driver`` (a right-hand driver turning counter-clockwise
pushes its mate towards ``+z``).  The deflection along ``n`` (compression positive,
``s = +-1`` for a coordinate measured forward or reversed) is

    ``delta = s [cos(beta_b) (r_b,d theta_d - r_b,n theta_n + (x_d - x_n) cos psi
    + (y_d - y_n) sin psi) + sigma sin(beta_b) (z_d - z_n)] + s e(t)``,

and the mesh force ``F = k(t) b g(delta / b) + c delta'`` acts along ``n``.  The drive
flank's line of action serves the back flank too (as in the lumped models of Kahraman
1994): after a reversal the tangential and axial components are exact, the radial one
keeps the drive flank's sign.  The contact is lumped at the pitch point in the face's
centre plane: a tilt moves it along z by ``tx py - ty px``, so the axial component of the
mesh force tilts the gears (its moments about the transverse axes, as in Kahraman 1994);
without tilting those moments go straight to the bearings.

**Coordinates.**  ``eta = R q + (s e, 0, 0)`` with ``q`` the physical coordinates
(rotations, then translations) and ``R``'s rows the mesh deflections, the shafts' twists
``theta_a - theta_b`` and the translations themselves.  The forces are those of springs and
dampers along ``eta``: ``K = diag(k_mesh(t), k_shaft, k_bearing)``, ``C`` likewise; so
Newton's law ``M q'' = T - R^T (K g(eta) + C eta')`` becomes, with ``W = R M^-1 R^T``,

    ``eta'' + W (K g(eta) + C eta') = R M^-1 T + S e''``,

the torsional model's form with ``W`` now coupling rotations and translations.  The
rigid-body rotation (``R``'s null space) drops out as before.  ``M`` is diagonal, so no
matrix is inverted symbolically.

**Scales.**  Each coordinate is divided by a length: a mesh by its half backlash ``b_i``, a
translation by the reference mesh's ``b_1``, a shaft's twist by ``b_1 / r_b,a`` (the twist
that turns gear ``a``'s base circle by ``b_1``).  Time is ``tau = omega_n t`` with the
*torsional* ``omega_n = sqrt(k_m,1 W^t_11)``, ``W^t`` the rotations' part of ``W``: the
same time scale, so the same ``omega`` at the same speed, as the torsional model of the
topology.  A mesh's damper follows from the damping ratio on its torsional equivalent mass,
``c_i = 2 zeta sqrt(k_m,i / W^t_ii)`` (the torsional model's ``"mesh"`` normalisation):
the mesh, not its supports, sets it.  Bearings and shafts bring their own dampers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import sympy as sp

from ..input.reader import InputError
from ..input.topology import Topology

__all__ = ["DEGREES_OF_FREEDOM", "Structure", "derive_structure", "physical_data"]

# Scene [features] degrees_of_freedom -> the translations each gear gets.
DEGREES_OF_FREEDOM = {
    "torsional": (),
    "lateral-torsional": ("x", "y"),
    "lateral-torsional-axial": ("x", "y", "z"),
    "lateral-torsional-axial-tilting": ("x", "y", "z", "tx", "ty"),
}
_TILTS = ("tx", "ty")  # rotations about the transverse axes x and y


@dataclass(frozen=True)
class Coordinate:
    """One coordinate of ``eta``: its name, kind (``mesh``, ``shaft``, ``x``, ``y``,
    ``z``), what it belongs to (mesh, shaft or gear id) and its scale, stiffness and
    damping symbols."""

    name: str
    kind: str
    owner: str
    scale: sp.Expr
    stiffness: sp.Expr
    damping: sp.Expr


@dataclass(frozen=True)
class Structure:
    """The dimensional and non-dimensional derivation (module docstring), SymPy objects
    with their numeric values."""

    topology: Topology
    dofs: str
    coordinates: tuple[Coordinate, ...]
    physical: tuple[sp.Symbol, ...]  # q: rotations, then translations
    mass: tuple[sp.Symbol, ...]  # M's diagonal, in the order of q
    torque: tuple[sp.Symbol, ...]  # generalised forces of q (torques; 0 on translations)
    incidence: sp.ImmutableMatrix  # R
    compliance: sp.ImmutableMatrix  # W = R M^-1 R^T
    torsional_compliance: sp.ImmutableMatrix  # W^t: the rotations' part, mesh rows
    zeta: sp.Symbol
    omega_n_expr: sp.Expr
    damping_expr: tuple[sp.Expr, ...]  # C's diagonal (mesh dampers from zeta)
    kappa: sp.ImmutableMatrix
    xi: sp.ImmutableMatrix
    load: tuple[sp.Expr, ...]
    values: dict
    angles: dict  # mesh id -> {'psi', 'sigma', 'beta_b'} values and symbols

    @property
    def damping(self) -> str:
        return "mesh"

    @property
    def gears(self) -> tuple[str, ...]:
        return tuple(g.id for g in self.topology.gears)

    def torque_symbol(self, gear: str) -> sp.Symbol:
        """The symbol of the external torque on ``gear`` (the reading of the loads)."""
        return self.torque[self.gears.index(gear)]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(c.name for c in self.coordinates)

    def value(self, expr) -> float:
        return float(sp.sympify(expr).subs(self.values).evalf(17))

    def numeric(self, matrix) -> list[list[float]]:
        return [[self.value(e) for e in row] for row in matrix.tolist()]


def _names(topo: Topology, axes: tuple[str, ...], source: str) -> list[tuple[str, str, str]]:
    """(name, kind, owner) of every coordinate: meshes, shafts, then translations."""
    out = [(m.coordinate, "mesh", m.id) for m in topo.meshes]
    out += [(s.id, "shaft", s.id) for s in topo.shafts]
    out += [(f"{a}{g.id}", a, g.id) for g in topo.gears for a in axes]
    from ..input.meshes import BACKLASH_NAME, RESERVED_NAMES

    seen: set[str] = set()
    for name, kind, owner in out:
        if kind == "shaft" and (name in RESERVED_NAMES or BACKLASH_NAME.fullmatch(name)):
            raise InputError(
                topo.source,
                "shaft",
                f"shaft id '{name}' is reserved (it names the twist coordinate); avoid "
                f"{', '.join(sorted(RESERVED_NAMES))} and g1, g3, ...",
            )
        if name in seen or f"d{name}" in seen:
            raise InputError(
                source,
                "mesh" if kind == "mesh" else kind,
                f"coordinate '{name}' ({kind} of '{owner}') clashes with another coordinate "
                "or its derivative; rename the mesh coordinate, shaft or gear",
            )
        seen |= {name, f"d{name}"}
    return out


def derive_structure(
    topo: Topology,
    dofs: str,
    damping_ratio: float,
    source: str,
    simplify_coefficients: bool = True,
) -> Structure:
    """Derive the lateral-torsional(-axial) equations of ``topo`` (module docstring);
    without ``simplify_coefficients`` the non-dimensional coefficients are left out (the
    physical data of :func:`physical_data` need none)."""
    axes = DEGREES_OF_FREEDOM[dofs]
    if axes:
        bare = [g.id for g in topo.gears if g.id not in topo.bearings]
        if bare:
            raise InputError(
                source,
                "features.degrees_of_freedom",
                f"'{dofs}' moves every gear across its axis, but gear(s) {', '.join(bare)} of "
                f"{topo.source} have no [[bearing]]; give each gear a bearing",
            )
    if "tx" in axes:
        loose = [g for g, b in topo.bearings.items() if b.tilt is None]
        if loose:
            raise InputError(
                source,
                "features.degrees_of_freedom",
                f"'{dofs}' tilts every gear, but the [[bearing]] of gear(s) {', '.join(loose)} "
                f"of {topo.source} has no tilt_Nm_per_rad; give each bearing its tilting "
                "stiffness",
            )
    gears = [g.id for g in topo.gears]
    col = {g: k for k, g in enumerate(gears)}
    names = _names(topo, axes, source)
    sense = topo.senses()
    values: dict[sp.Symbol, float] = {}

    def sym(name: str, value: float, **assumptions) -> sp.Symbol:
        s = sp.Symbol(name, **assumptions)
        values[s] = float(value)
        return s

    theta = [sp.Symbol(rf"\theta_{{{g}}}", real=True) for g in gears]
    trans = [sp.Symbol(f"{a}_{{{g}}}", real=True) for g in gears for a in axes]
    q = tuple(theta + trans)
    tcol = {
        (g, a): len(gears) + k * len(axes) + j
        for k, g in enumerate(gears)
        for j, a in enumerate(axes)
    }
    inertia = [sym(f"I_{{{g.id}}}", g.inertia, positive=True) for g in topo.gears]
    mass = [sym(f"m_{{{g.id}}}", g.mass, positive=True) for g in topo.gears]
    radius = [sym(f"r_{{b,{g.id}}}", g.base_radius, positive=True) for g in topo.gears]
    torque = [sym(f"T_{{{g}}}", topo.torques.get(g, 0.0), real=True) for g in gears]
    tilt_inertia = [sym(f"J_{{{g.id}}}", g.diametral_inertia, positive=True) for g in topo.gears]
    masses = tuple(
        inertia + [(tilt_inertia if a in _TILTS else mass)[col[g]] for g in gears for a in axes]
    )
    forces = tuple(torque + [sp.Integer(0)] * len(trans))

    b1 = sym(f"b_{{{topo.meshes[0].id}}}", topo.meshes[0].half_backlash, positive=True)
    rows, coords, angles = [], [], {}
    zeta = sp.Symbol(r"\zeta", nonnegative=True)
    values[zeta] = float(damping_ratio)
    for name, kind, owner in names:
        row = sp.zeros(1, len(q))
        if kind == "mesh":
            me = next(m for m in topo.meshes if m.id == owner)
            d, n = col[me.driver], col[me.driven]
            beta = sym(rf"\beta_{{b,{owner}}}", me.pair.driver.base_helix_angle, nonnegative=True)
            psi_value = me.driver_position + sense[me.driven] * (
                math.pi / 2 + me.pair.working_pressure_angle
            )
            psi = sym(rf"\psi_{{{owner}}}", psi_value, real=True)
            sigma = int(math.copysign(1, me.pair.driver.helix_angle)) * sense[me.driver]
            s = me.orientation
            cb, sb = sp.cos(beta), sp.sin(beta)
            row[d] += s * cb * radius[d]
            row[n] -= s * cb * radius[n]
            for a, proj in (("x", sp.cos(psi)), ("y", sp.sin(psi)), ("z", None)):
                if a not in axes:
                    continue
                part = s * cb * proj if proj is not None else s * sigma * sb
                row[tcol[me.driver, a]] += part
                row[tcol[me.driven, a]] -= part
            if "tx" in axes:
                # A tilt (a about x, b about y) moves the contact point (px, py) at the face
                # centre along z by a py - b px; the contact is taken at the pitch point,
                # r_w = r_b / cos(alpha_wt) from each centre along the centre line.
                phi = sym(rf"\phi_{{{owner}}}", me.driver_position, real=True)
                awt = sym(rf"\alpha_{{wt,{owner}}}", me.pair.working_pressure_angle, positive=True)
                for gear, sign, side in ((me.driver, 1, -1), (me.driven, -1, 1)):
                    rw = radius[col[gear]] / sp.cos(awt)
                    px, py = side * rw * sp.cos(phi), side * rw * sp.sin(phi)
                    row[tcol[gear, "tx"]] += sign * s * sigma * sb * py
                    row[tcol[gear, "ty"]] -= sign * s * sigma * sb * px
            b = (
                b1
                if me is topo.meshes[0]
                else sym(f"b_{{{owner}}}", me.half_backlash, positive=True)
            )
            k = sym(f"k_{{m,{owner}}}", me.stiffness.mean, positive=True)
            coords.append(Coordinate(name, kind, owner, b, k, sp.Integer(0)))  # damping below
            angles[owner] = {"psi": psi, "sigma": sigma, "beta_b": beta}
        elif kind == "shaft":
            sh = next(s for s in topo.shafts if s.id == owner)
            a_, b_ = col[sh.gears[0]], col[sh.gears[1]]
            row[a_], row[b_] = 1, -1
            k = sym(f"k_{{{owner}}}", sh.stiffness, positive=True)
            c = sym(f"c_{{{owner}}}", sh.damping, nonnegative=True)
            coords.append(Coordinate(name, kind, owner, b1 / radius[a_], k, c))
        elif kind in _TILTS:
            row[tcol[owner, kind]] = 1
            bearing = topo.bearings[owner]
            k = sym(f"k_{{t,{owner}}}", bearing.tilt, positive=True)
            c = sym(f"c_{{t,{owner}}}", bearing.tilt_damping, nonnegative=True)
            coords.append(Coordinate(name, kind, owner, b1 / radius[col[owner]], k, c))
        else:
            row[tcol[owner, kind]] = 1
            bearing = topo.bearings[owner]
            if kind == "z":
                stiff, damp, tag = bearing.axial, bearing.axial_damping, "a"
            else:
                stiff, damp, own = bearing.transverse(kind)
                tag = "y" if own else "r"
            k = sym(f"k_{{{tag},{owner}}}", stiff, positive=True)
            c = sym(f"c_{{{tag},{owner}}}", damp, nonnegative=True)
            coords.append(Coordinate(name, kind, owner, b1, k, c))
        rows.append(row)
    R = sp.ImmutableMatrix(sp.Matrix.vstack(*rows))
    Minv = sp.diag(*[1 / mm for mm in masses])
    W = sp.ImmutableMatrix(R * Minv * R.T)
    n_rot = len(gears)
    m = len(topo.meshes)
    Rt = R[:m, :n_rot]
    Wt = sp.ImmutableMatrix(Rt * sp.diag(*[1 / i for i in inertia]) * Rt.T)
    load_dim = R * Minv * sp.Matrix(forces)

    omega_n = sp.sqrt(coords[0].stiffness * Wt[0, 0])
    damping = []
    for i, c in enumerate(coords):
        if c.kind == "mesh":
            damping.append(2 * zeta * sp.sqrt(c.stiffness / Wt[i, i]))
        else:
            damping.append(c.damping)
    N = len(coords)
    # Without simplification (physical_data), the coefficients are not needed.
    kappa = xi = None
    load: tuple = ()
    if simplify_coefficients:
        # W is symmetric and mostly zero: simplify each distinct entry once (cos^2 + sin^2 of
        # the line of action and the helix), then only factor the coefficients built on it;
        # simplifying every coefficient afresh took 10 s a model.
        Ws: dict[tuple[int, int], sp.Expr] = {}
        for i in range(N):
            for j in range(i, N):
                Ws[i, j] = Ws[j, i] = sp.simplify(W[i, j]) if W[i, j] != 0 else sp.Integer(0)
        W = sp.ImmutableMatrix(N, N, lambda i, j: Ws[i, j])

        def simplify(expr):
            # Every factor is positive, so absolute values that sqrt() leaves behind can go.
            expr = sp.factor(expr)
            return expr.replace(lambda e: isinstance(e, sp.Abs), lambda e: e.args[0])

        L = [c.scale for c in coords]
        K = [c.stiffness for c in coords]
        kappa = sp.ImmutableMatrix(
            N, N, lambda i, j: simplify(W[i, j] * K[j] * L[j] / (L[i] * omega_n**2))
        )
        xi = sp.ImmutableMatrix(
            N, N, lambda i, j: simplify(W[i, j] * damping[j] * L[j] / (2 * L[i] * omega_n))
        )
        load = tuple(simplify(load_dim[i] / (L[i] * omega_n**2)) for i in range(N))
    return Structure(
        topology=topo,
        dofs=dofs,
        coordinates=tuple(coords),
        physical=q,
        mass=masses,
        torque=forces,
        incidence=R,
        compliance=W,
        torsional_compliance=Wt,
        zeta=zeta,
        omega_n_expr=omega_n,
        damping_expr=tuple(damping),
        kappa=kappa,
        xi=xi,
        load=load,
        values=values,
        angles=angles,
    )


def physical_data(model) -> dict:
    """The linear, time-averaged model in physical coordinates, as plain numbers, for the
    modal analysis (``solver/analysis/modes.py``): ``q`` (rotations ``theta_<gear>``,
    then translations ``<axis>_<gear>``), the diagonal mass matrix (kg, kg m^2), the rows
    ``d eta / d q`` of each coordinate of the model (mesh deflections, shaft twists,
    translations), each one's spring at the mean stiffness (N/m, N m/rad), its kind, its
    scale (``u = eta / scale``), the time unit and the reference driver and its teeth."""
    topo = model.scene.topology
    st = model.structure
    if st is None:
        st = derive_structure(topo, "torsional", model.scene.damping_ratio, "", False)
    R = st.incidence.subs(st.values).evalf(17)
    axes = DEGREES_OF_FREEDOM[st.dofs]
    phys = [f"theta_{g.id}" for g in topo.gears] + [f"{a}_{g.id}" for g in topo.gears for a in axes]

    def r15(v) -> float:
        return float(f"{float(v):.15g}")

    return {
        "physical": tuple(phys),
        "mass": tuple(r15(st.value(mm)) for mm in st.mass),
        "coordinates": st.names,
        "kinds": tuple(c.kind for c in st.coordinates),
        "owners": tuple(c.owner for c in st.coordinates),
        "incidence": tuple(tuple(r15(v) for v in R.row(i)) for i in range(R.rows)),
        "stiffness": tuple(r15(st.value(c.stiffness)) for c in st.coordinates),
        "scale": tuple(r15(st.value(c.scale)) for c in st.coordinates),
        "omega_n": r15(model.scales["omega_n_rad_per_s"]),
        "reference_driver": topo.reference.driver,
        "reference_teeth": topo.gear(topo.reference.driver).teeth,
    }
