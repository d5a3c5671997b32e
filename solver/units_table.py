"""A result with its table in the engineer's units beside the model's (``units.py``
converts; this adds the columns and the ``in_units`` block to a result's files)."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from .units import MESH_HZ, SPEED, UNITS, Units, at, coordinate_of, point_in_units

__all__ = ["InUnits", "in_units"]


@dataclass(frozen=True)
class InUnits:
    """A result (sweep, map, branches: anything with ``to_dict`` and ``to_table``) with its
    table in physical units beside the model's: ``to_table`` appends columns, never
    replacing one (``<col>_um`` for each deflection column, ``lyapunov_per_s``, and the
    row's ``speed_rpm`` and ``mesh_frequency_hz``), and ``to_dict`` adds the block
    ``in_units`` (the operating point, each added column's meaning and its values).  The
    scales of a row are those with its ``parameters`` (columns) set."""

    result: object
    system: object
    parameters: tuple = ()
    kind: str = "physical"

    def _units(self, values: tuple) -> Units:
        return at(self.system, self.kind, dict(zip(self.parameters, values, strict=True)))

    def to_table(self) -> tuple[list, list]:
        return self._table[:2]

    @functools.cached_property
    def _table(self) -> tuple[list, list, int]:  # once (a long run's samples: many rows)
        """The columns, the rows and how many of the columns are the result's own."""
        columns, rows = self.result.to_table()
        base = Units.of(self.system, self.kind)
        if not base.physical:
            return list(columns), [list(r) for r in rows], len(columns)
        where = [list(columns).index(p) for p in self.parameters if p in columns]
        added = [(c, coordinate_of(base, c)) for c in columns if coordinate_of(base, c)]
        tau = "tau" in columns  # a trajectory's samples: their time in seconds
        memo: dict = {}
        extra_names = [f"{c}_um" for c, _ in added]
        lyapunov = "lyapunov" in columns
        extra_names += ["lyapunov_per_s"] * lyapunov
        extra_names += ["t_s"] * tau
        if tau and not where and not lyapunov and hasattr(rows, "shape"):  # one array
            import numpy as np

            cols = [rows[:, columns.index(c)] * base.deflection(q, 1.0) for c, q in added]
            cols.append(rows[:, columns.index("tau")] / base.scales["omega_n_rad_per_s"])
            speeds_n, speeds = _velocities(self.system, base, columns, rows, added)
            names, forces = _forces(self.system, base, columns, rows)
            return (
                [*columns, *extra_names, *speeds_n, *names],
                np.column_stack([rows, *cols, *speeds, *forces]),
                len(columns),
            )
        # the rows' speed and mesh frequency (from omega if the model states no speed); not
        # for a trajectory's samples, all at the one operating point the block states
        speeds = [k for k in (SPEED, MESH_HZ) if k not in columns and k in base.scales] * (not tau)
        hz = MESH_HZ not in columns and MESH_HZ not in base.scales and not tau
        out = []
        for row in rows:
            key = tuple(float(row[k]) for k in where)
            u = memo.get(key) or memo.setdefault(key, self._units(key) if where else base)
            extra = [_times(_num(row[columns.index(c)]), u.deflection(q, 1.0)) for c, q in added]
            if lyapunov:
                omega_n = u.scales["omega_n_rad_per_s"]
                extra.append(_times(_num(row[columns.index("lyapunov")]), omega_n))
            if tau:
                extra.append(u.time(float(row[columns.index("tau")])))
            extra += [u.scales[k] for k in speeds] + [u.frequency(u.omega)] * hz
            out.append([*row, *extra])
        return [*columns, *extra_names, *speeds, *[MESH_HZ] * hz], out, len(columns)

    def block(self) -> dict:
        """The ``in_units`` block (``{}`` in model units)."""
        return self._block

    @functools.cached_property
    def _block(self) -> dict:  # once: every file of a command writes it
        base = Units.of(self.system, self.kind)
        if not base.physical:
            return {}
        columns, rows, first = self._table
        meaning = {
            "lyapunov_per_s": "largest Lyapunov exponent per second (lyapunov x omega_n)",
            "t_s": "time in seconds (tau / omega_n)",
            **{
                f"{self.system.states[self.system.velocity_index(c)]}_m_per_s": f"rate of {c} "
                "in m/s at the sample (omega_n b d/dtau)"
                for c in self.system.coordinates
            },
            **{
                f"{c}_force_N": f"mesh force of {c} in N at the sample, static load included "
                "(the model's mesh force x k_m b; the static force and the dynamic factor "
                "are under coordinates)"
                for c in self.system.coordinates
            },
            SPEED: f"speed of gear '{base.scales.get('speed_gear', '?')}' in rpm at the row",
            MESH_HZ: "mesh frequency in Hz at the row (omega omega_n / 2 pi)",
        }
        about = {
            c: meaning.get(c, f"{c[:-3]} in µm (half backlashes x b x 1e6, b at the row)")
            for c in columns[first:]
        }
        swept = [q for q in self.parameters if q in (base.forcing, SPEED, MESH_HZ)]
        # one analysed point: its ranges, peaks and forces in units (point_in_units)
        point = hasattr(self.result, "classification") and hasattr(self.result, "trajectory")
        summary = {"coordinates": point_in_units(self.result, base)["coordinates"]} if point else {}
        return summary | {
            "units": base.kind,
            # the rows' own frequency where it is what varies (their columns hold it)
            "operating_point": f"{swept[0]} varies by row (its column)"
            if swept
            else base.operating_point(),
            "columns": about,
            "table": {
                c: rows[:, k] if hasattr(rows, "shape") else [r[k] for r in rows]
                for k, c in enumerate(columns)
                if k >= first
            },
        }

    def to_dict(self) -> dict:
        block = self.block()
        return self.result.to_dict() | ({"in_units": block} if block else {})

    def save(self, path, **extra):
        """Write to ``path``: ``.json``, ``.csv`` or ``.mat`` (``solver/export.py``)."""
        from .export import save

        return save(self, path, **extra)


def _velocities(system, units: Units, columns: list, rows, added) -> tuple[list, list]:
    """A trajectory's mesh-coordinate rates in m/s (``<velocity state>_m_per_s``: the
    state times b omega_n, d/dt = omega_n d/dtau), for the coordinates in µm."""
    names, cols = [], []
    omega_n = units.scales["omega_n_rad_per_s"]
    for c, q in added:
        v = system.states[system.velocity_index(c)]
        b = units.scales["half_backlash_m"].get(q)
        if v in columns and b:
            names.append(f"{v}_m_per_s")
            cols.append(rows[:, columns.index(v)] * b * omega_n)
    return names, cols


def _forces(system, units: Units, columns: list, rows) -> tuple[list, list]:
    """A trajectory's dynamic mesh force at every sample in N, one column per mesh
    coordinate the model states a stiffness scale for (``<coordinate>_force_N``); none
    for a model without ``mesh_force``.  A sample that is not finite has no force (NaN:
    the run left its valid range there)."""
    import numpy as np

    mesh_force = getattr(system.module, "mesh_force", None)
    if (
        mesh_force is None
        or not len(rows)
        or not any(units.force_unit(c) == "N" for c in system.coordinates)
    ):
        return [], []
    t = rows[:, columns.index("tau")]
    x = rows[:, [columns.index(s) for s in system.states]].T
    ok = np.all(np.isfinite(x), axis=0) & np.isfinite(t)
    m = len(np.atleast_1d(system.module.static_mesh_force(system.p)))  # the meshes (first)
    f = np.full((m, t.size), np.nan)
    if ok.any():
        f[:, ok] = np.asarray(mesh_force(t[ok], x[:, ok], system.p), float)[:m]
    # the meshes' coordinates come first, as point_in_units reads them
    coords = [(k, c) for k, c in enumerate(system.coordinates[:m]) if units.force_unit(c) == "N"]
    return [f"{c}_force_N" for _, c in coords], [units.force(c, 1.0) * f[k] for k, c in coords]


def _num(v) -> float | None:
    """A finite number, else None (text, a missing value, NaN)."""
    if v is None or isinstance(v, str):
        return None
    v = float(v)
    return v if math.isfinite(v) else None


def _times(v: float | None, factor: float) -> float | None:
    return None if v is None else v * factor


def in_units(result, system, kind: str = "physical") -> InUnits:
    """``result`` with its table in ``kind`` units (:class:`InUnits`); the
    parameters that set each row's scales are the result's own (a sweep's parameter, a
    map's x and y)."""

    if kind not in UNITS:
        raise ValueError(f"units '{kind}': not one of {', '.join(UNITS)}")
    if hasattr(result, "x") and hasattr(result, "y"):
        names = (result.x, result.y)
    else:
        name = getattr(result, "parameter", None) or result.to_dict().get("parameter")
        names = (name,) if name else ()
    return InUnits(result, system, tuple(names), kind)
