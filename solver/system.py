"""A generated model, ready to integrate: names, parameter vector, period, CasADi graphs.

:class:`System` is the solver's only view of a model.  It reads the generated module's
contract (:class:`~gearsym.solver.contract.Contract`) and its functions (``parameters()``,
``rhs``, ``jacobian``, ``casadi_functions``), never anything about gears.  It is
immutable; ``with_values`` returns a new system with other parameter values, sharing the
compiled CasADi graphs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from types import ModuleType

import numpy as np

from .contract import Contract, load_generated

__all__ = ["System", "restates"]


def restates(module, a: str, b: str) -> bool:
    """Whether the named values ``a`` and ``b`` of ``module`` state one quantity: one
    name, an alias and the name it stands for (``half_backlash_um``, ``_pg``), a body
    model's physical name and its parameter (``mesh_frequency_hz``, ``omega``), or a
    physical quantity and a parameter it replaces (``speed_rpm``, ``omega``; a torque
    and ``lambda``).  Two quantities that replace the same parameters are not one: the
    torques of two gears both replace the non-dimensional loads, and each keeps its own."""
    physical = getattr(module, "PHYSICAL", {})
    aliases = getattr(module, "PHYSICAL_ALIASES", {})
    replaces = getattr(module, "PHYSICAL_REPLACES", {})

    def names(k: str) -> set:
        out = {k, *aliases.get(k, ())}
        to = physical.get(k)
        return out | {to} if isinstance(to, str) else out

    na, nb = names(a), names(b)
    return bool(na & nb) or any(
        n in replaces.get(m, ()) or m in replaces.get(n, ()) for n in na for m in nb
    )


@dataclass(frozen=True, eq=False)
class System:
    """A generated model with one set of parameter values.

    Attributes
    ----------
    module : module
        The generated module.
    p : ndarray, shape (P,)
        Parameter vector in the module's order.
    values : dict
        The named values (scene or model parameters) that produced ``p``.
    contract : Contract
        What the model states about itself (read once per model, shared by ``with_values``).
    """

    module: ModuleType
    p: np.ndarray
    values: dict = field(default_factory=dict)
    contract: Contract = None  # type: ignore[assignment]

    def __post_init__(self):
        if self.contract is None:
            object.__setattr__(self, "contract", Contract.of(self.module))
        names = self.contract.parameters
        bad = [n for n, v in zip(names, self.p, strict=True) if not np.isfinite(v)]
        if bad:
            raise ValueError(f"parameter(s) {', '.join(bad)} are not finite numbers")
        omega = self.contract.forcing_frequency
        if not self.p[names.index(omega)] > 0:
            raise ValueError(f"{omega} (the excitation frequency) must be > 0")

    def __reduce__(self):
        # A module cannot be pickled: a System goes to (and comes back from) a worker
        # process as its generated module's file and its values, the file loaded there
        # (and verified) by ``load_generated``.
        return (_rebuild, (self.module.__file__, self.p, self.values))

    @classmethod
    def load(cls, name_or_module, **values) -> System:
        """The model of a generated module (a module, its name or its file) with ``values``
        (scene or model parameters by name; the rest keep the scene's values)."""
        module = (
            name_or_module
            if isinstance(name_or_module, ModuleType)
            else load_generated(name_or_module)
        )
        return cls(module, module.parameters(**values), dict(values))

    def _kept(self, values: dict) -> dict:
        """This system's named values less those that ``values`` state again under another
        name (``omega`` after ``speed_rpm``, ``mesh_frequency_hz`` after ``omega``): the
        later value wins, as it does under one name (:func:`restates`)."""
        return {
            k: v
            for k, v in self.values.items()
            if not any(restates(self.module, k, n) for n in values)
        }

    def with_values(self, **values) -> System:
        """The same model with some named values changed (the rest kept; a value stated
        again under another name is replaced)."""
        merged = self._kept(values) | values
        new = System(self.module, self.module.parameters(**merged), merged, self.contract)
        # Share the CasADi graphs: they depend on the model, not on the values.
        if "casadi" in self.__dict__:
            new.__dict__["casadi"] = self.__dict__["casadi"]
        return new

    def parameters_with(self, **values) -> np.ndarray:
        """The parameter vector with some named values changed (no new System)."""
        return self.module.parameters(**(self._kept(values) | values))

    # -- names -------------------------------------------------------------------------
    @property
    def name(self) -> str:
        return self.module.NAME

    @property
    def states(self) -> tuple[str, ...]:
        return self.contract.states

    @property
    def coordinates(self) -> tuple[str, ...]:
        return self.contract.coordinates

    @property
    def n(self) -> int:
        return len(self.contract.states)

    def index(self, state: str) -> int:
        return self.contract.index(state)

    def velocity_index(self, coordinate: str) -> int:
        """Index of the time derivative of mesh coordinate ``coordinate``."""
        return self.contract.velocity(coordinate)

    def parameter(self, name: str) -> float:
        return float(self.p[self.contract.parameters.index(name)])

    # -- forcing -----------------------------------------------------------------------
    @property
    def omega(self) -> float:
        """Excitation frequency (non-dimensional) of the reference mesh."""
        return self.parameter(self.contract.forcing_frequency)

    @property
    def period(self) -> float:
        """Forcing period T = 2 pi / omega (non-dimensional time)."""
        return 2.0 * math.pi / self.omega

    @property
    def piecewise(self) -> bool:
        return self.contract.piecewise

    @property
    def backlash(self) -> str:
        return self.module.FEATURES["backlash"]

    @property
    def backlash_note(self) -> str | None:
        """One sentence on a polynomial backlash: where its force is zero (the contract's
        ``force_sign``) and that it carries load inside the gap; None for other models.

        The study's 7th-order fit is zero at ``x = 0, +-0.770`` half backlashes, not at the
        gap's edges ``+-1`` (``derive/mesh/force_sign.py``).  The CLI prints it once per
        model; the API only offers it (a sweep builds thousands of systems).
        """
        if self.backlash != "polynomial" or not self.contract.force_sign:
            return None
        zeros = {_zeros_text(s.zeros) for s in self.contract.force_sign.values()}
        where = (
            zeros.pop()
            if len(zeros) == 1
            else "; ".join(
                f"{c}: {_zeros_text(s.zeros)}" for c, s in self.contract.force_sign.items()
            )
        )
        return (
            "backlash model 'polynomial' (a polynomial fit of the dead zone, as the study's): "
            f"its force is zero at x = {where} half backlashes, not at the backlash edge ±1, "
            "and it carries load inside the backlash; "
            '`backlash = "dead-zone"` for the exact dead zone'
        )

    @property
    def torque_note(self) -> str | None:
        """One sentence when the external torques in effect are not in balance over the
        train's rigid rotation ``r`` (the null space of the mesh incidence: ``T . r != 0``):
        the mesh coordinates remove that rotation, so the meshes carry the loads of a train
        accelerating as a whole, not of steady running.  It names the torque on one gear
        that balances the others (the last not set by name: the output, where the inputs
        are given).  None when balanced (to 1e-7 of the largest term), or for models without
        torques."""
        import numpy as np

        m = self.module
        physical = getattr(m, "PHYSICAL", {})
        structure = getattr(m, "STRUCTURE", {})
        gears = [b.removeprefix("theta_") for b in structure.get("physical", ())]
        names = [f"torque_Nm_{g}" for g in gears]
        if not names or not all(n in physical for n in names) or not hasattr(m, "_physical"):
            return None
        given = m._physical(self.values)[0] or [v[0] for v in physical.values()]
        q = dict(zip(physical, given, strict=True))
        torque = np.array([float(q[n]) for n in names])
        incidence = np.atleast_2d(np.asarray(structure.get("incidence", ()), float))
        if incidence.shape != (len(gears) - 1, len(gears)):
            return None  # not a tree of gears (one rigid rotation, one mesh fewer than gears)
        null = np.linalg.svd(incidence)[2]
        r = null[-1] / null[-1][np.argmax(np.abs(null[-1]))]
        net = float(torque @ r)
        # balanced to 1e-7 of the largest term: a torque set to the balancing value this
        # note prints (9 digits) is balanced
        if abs(net) <= 1e-7 * float(np.max(np.abs(torque * r))):
            return None
        unset = [i for i, n in enumerate(names) if n not in self.values]
        k = unset[-1] if unset else len(names) - 1
        steady = torque[k] - net / r[k]
        ratio = ", ".join(f"{v:.4g}" for v in r)
        return (
            f"the torques are not in balance: sum of T r over the rigid rotation r = ({ratio}) "
            f"of {', '.join(gears)} is {net:.6g} N m, so the meshes carry the loads of a "
            f"train accelerating as a whole; torque_Nm_{gears[k]} = {steady:.9g} balances "
            "the others (steady running)"
        )

    @property
    def model_hash(self) -> str:
        return self.module.INPUTS_SHA256

    # -- evaluation ----------------------------------------------------------------------
    def rhs(self, tau: float, x: np.ndarray) -> np.ndarray:
        return self.module.rhs(tau, x, self.p)

    def jacobian(self, tau: float, x: np.ndarray) -> np.ndarray:
        return self.module.jacobian(tau, x, self.p)

    @cached_property
    def casadi(self):
        """(rhs, jacobian) as CasADi Functions of (tau, x, p); built once per model."""
        return self.module.casadi_functions()

    def scales(self) -> dict:
        """How to go back to SI with this system's values: omega_n, the half backlash and
        mean stiffness of each mesh coordinate, and (for a model with physical quantities,
        the generated ``scales()``) the mesh frequency and the speed in effect."""
        out = {
            "omega_n_rad_per_s": float(self.module.OMEGA_N),
            "half_backlash_m": dict(self.module.HALF_BACKLASH),
            "time": "tau = omega_n t; coordinates in half backlashes",
        }
        scales = getattr(self.module, "scales", None)
        if scales is None:
            return out
        s = scales(**self.values)
        out["omega_n_rad_per_s"] = s["omega_n_rad_per_s"]
        out["half_backlash_m"] = {c: s[f"half_backlash_m_{c}"] for c in out["half_backlash_m"]}
        out["mean_stiffness_N_per_m"] = {
            c: s[f"mean_stiffness_N_per_m_{c}"] for c in out["half_backlash_m"]
        }
        for key in ("mesh_frequency_hz", "speed_rpm", "speed_gear"):
            out[key] = s[key]
        return out

    def __repr__(self) -> str:
        # the forcing frequency and at most four of the values given
        given = [(k, v) for k, v in self.values.items() if k != self.contract.forcing_frequency]
        shown = [f"ω̄ = {self.omega:.4g}"] + [f"{k} = {float(v):.4g}" for k, v in given[:4]]
        more = f" (+{len(given) - 4} more)" if len(given) > 4 else ""
        return f"System({self.name}: {', '.join(shown)}{more})"

    def summary(self) -> str:
        """A few lines: the model, its states, the values, the backlash and the scales."""
        scales = self.scales()
        b = ", ".join(f"{c} {v * 1e6:.4g} µm" for c, v in scales["half_backlash_m"].items())
        given = ", ".join(f"{k} = {float(v):.6g}" for k, v in self.values.items())
        return "\n".join(
            [
                f"{self.name} (hash {self.model_hash[:12]}): states {', '.join(self.states)}; "
                f"{'piecewise' if self.piecewise else 'smooth'}, {self.backlash or 'no'} backlash",
                f"ω̄ = {self.omega:.6g} (T = {self.period:.6g} τ); values: {given or 'none'}",
                f"scales: ω_n = {scales['omega_n_rad_per_s']:.6g} rad/s; half backlash {b}",
            ]
        )

    def describe(self) -> dict:
        return {
            "model": self.name,
            "model_hash": self.model_hash,
            "values": {k: float(v) for k, v in self.values.items()},
            "parameters": dict(zip(self.contract.parameters, map(float, self.p), strict=True)),
            "omega_n_rad_per_s": self.module.OMEGA_N,
            "half_backlash_m": dict(self.module.HALF_BACKLASH),
            "features": dict(self.module.FEATURES),
        }

    to_dict = describe


def _rebuild(source: str, p, values: dict) -> System:
    """A pickled :class:`System` again (``System.__reduce__``)."""
    return System(load_generated(source), np.asarray(p, float), dict(values))


def _zeros_text(zeros) -> str:
    """``0, ±0.770``: the zeros to three decimals by size, a pair ``-z, z`` as ``±z``."""
    out = []
    for z in sorted(set(zeros), key=lambda z: (abs(z), z)):
        if z == 0:
            out.append("0")
        elif z > 0 and -z in zeros:
            out.append(f"±{z:.3f}")
        elif not (z < 0 and -z in zeros):
            out.append(f"{z:.3f}")
    return ", ".join(out)
