"""The result of a regime map: per grid point its attractors; records, grids and files."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..analysis.classify import Classification
from ..analysis.record import Extremes, RunRecord
from .attractors import Attractor

__all__ = ["Cell", "RegimeMap"]


@dataclass(frozen=True)
class Cell:
    """One grid point: its two values and its attractors (largest share first)."""

    x: float
    y: float
    attractors: tuple[Attractor, ...]

    @property
    def dominant(self) -> Attractor:
        return self.attractors[0]


@dataclass(frozen=True)
class RegimeMap:
    """Attractors over an x by y grid (``cells[ix][iy]``), with the settings that made it.

    ``grid(field, state)`` gives a (ny, nx) array of the dominant attractor's value
    (the one most initial states reached; ties go to the forward start):
    ``motion``, ``period``, ``meshing`` (per coordinate), ``max``, ``min``,
    ``poincare_spread`` (per state / coordinate), ``lyapunov``, ``attractors`` (count).
    """

    model: str
    model_hashes: tuple[str, ...]
    x: str
    x_values: np.ndarray
    y: str
    y_values: np.ndarray
    states: tuple[str, ...]
    coordinates: tuple[str, ...]
    values: dict
    settings: dict
    cells: tuple[tuple[Cell, ...], ...]
    wall_time: float
    digest: str = ""
    resumed: int = 0  # runs that came from the store

    @property
    def meshes(self) -> tuple[str, ...]:
        """The coordinates with contact edges (a meshing regime)."""
        meshing = self.cells[0][0].dominant.run.meshing_regime
        return tuple(c for c in self.coordinates if c in meshing)

    def _grid_text(self) -> str:
        def axis(name, v):
            return f"{name} {v[0]:.4g} to {v[-1]:.4g} ({len(v)})" if len(v) else name

        return f"{axis(self.x, self.x_values)} x {axis(self.y, self.y_values)}"

    def _motions(self, most: int | None = None) -> str:
        """``period-1 in 12 cells, chaotic in 3``: the dominant attractor's motion."""
        from collections import Counter

        counts = Counter(
            c.dominant.run.motion(self.coordinates[0])
            if c.dominant.run.ok
            else c.dominant.run.status
            for column in self.cells
            for c in column
        )
        shown = counts.most_common(most)
        more = len(counts) - len(shown)
        text = ", ".join(f"{m} in {k}" for m, k in shown) + (f", {more} more" if more else "")
        return text + " cells"

    def __repr__(self) -> str:
        return (
            f"RegimeMap({self.model}: {self._grid_text()}, "
            f"{self.settings.get('initial_states')} initial states; {self._motions(3)})"
        )

    def summary(self) -> str:
        """A few lines: the grid, the runs, the dominant motions, coexisting attractors."""
        s = self.settings
        count = self.grid("attractors")
        most = int(np.nanmax(count)) if np.any(np.isfinite(count)) else 0
        fixed = ", ".join(
            f"{k} = {v:.4g}" for k, v in self.values.items() if k not in (self.x, self.y)
        )
        return "\n".join(
            [
                f"regime map of {self.model}: {self._grid_text()}"
                + (f"; {fixed}" if fixed else ""),
                f"runs: {s.get('initial_states')} initial states per point, "
                f"{s.get('transient')} + {s.get('periods')} periods, {s.get('method')} "
                f"rtol {s.get('rtol')}; {self.wall_time:.1f} s",
                f"dominant motion: {self._motions()}",
                f"coexisting attractors: up to {most} at a point, "
                f"{int(np.sum(count > 1))} points with more than one",
            ]
        )

    def records(self) -> list[dict]:
        """One record per (grid point, attractor), the two values under their names."""
        out = []
        for column in self.cells:
            for cell in column:
                for k, a in enumerate(cell.attractors):
                    out.append(
                        {
                            self.x: cell.x,
                            self.y: cell.y,
                            "attractor": k,
                            "attractors": len(cell.attractors),
                            **a.to_dict(self.states),
                        }
                    )
        return out

    def grid(self, field: str, key: str | None = None) -> np.ndarray:
        def value(cell: Cell):
            if field == "attractors":  # attractors proper: failures are not counted
                return sum(a.run.status == "ok" for a in cell.attractors)
            d = cell.dominant.to_dict(self.states)[field]
            return d if key is None else d.get(key)

        nx, ny = len(self.x_values), len(self.y_values)
        rows = [[value(self.cells[ix][iy]) for ix in range(nx)] for iy in range(ny)]
        if field in ("motion", "meshing", "status"):
            return np.array(rows, dtype=object)
        return np.array([[np.nan if v is None else v for v in r] for r in rows], dtype=float)

    def to_dict(self) -> dict:
        return {
            "kind": "regime map",
            "model": self.model,
            "model_hashes": list(self.model_hashes),
            "x": {"name": self.x, "values": self.x_values.tolist()},
            "y": {"name": self.y, "values": self.y_values.tolist()},
            "states": list(self.states),
            "coordinates": list(self.coordinates),
            "values": self.values,
            "settings": self.settings,
            "wall_time_s": self.wall_time,
            "records": self.records(),
        }

    def to_table(self) -> tuple[list, list]:
        columns = [self.x, self.y, "attractor", "attractors", "share", "status", "lyapunov"]
        columns += ["periods_run"]
        columns += [f"motion_{c}" for c in self.coordinates]
        columns += [f"meshing_{c}" for c in self.coordinates]
        columns += [f"max_{s}" for s in self.states] + [f"min_{s}" for s in self.states]
        rows = []
        for r in self.records():
            rows.append(
                [r[self.x], r[self.y], r["attractor"], r["attractors"], r["share"]]
                + [r["status"], r["lyapunov"], r.get("periods_run")]
                + [r["motion"][c] for c in self.coordinates]
                + [r["meshing"].get(c) for c in self.coordinates]
                + [r["max"][s] for s in self.states]
                + [r["min"][s] for s in self.states]
            )
        return columns, rows

    def save(self, path, **extra) -> Path:
        from ..export import save

        return save(self, path, **extra)

    @classmethod
    def load(cls, path) -> RegimeMap:
        """A map saved with ``save(... .json)`` (the attractors' tails are not kept: one
        Poincare point per attractor, its ``state``)."""
        d = json.loads(Path(path).read_text(encoding="utf-8"))
        if d.get("kind") != "regime map":
            raise ValueError(f"{path} is not a saved regime map")
        x, y = d["x"]["name"], d["y"]["name"]
        xv, yv = np.array(d["x"]["values"]), np.array(d["y"]["values"])
        states = tuple(d["states"])
        cells: dict = {}
        for r in d["records"]:
            why = r.get("why", {})
            lyapunov = None
            if r["lyapunov"] is not None:
                lyapunov = {"exponent": r["lyapunov"], "uncertainty": r["lyapunov_uncertainty"]}
            run = RunRecord(
                values={x: float(r[x]), y: float(r[y])},
                status=r["status"],
                classification={
                    c: Classification(m, r["period"][c], {"why": why[c]} if c in why else {})
                    for c, m in r["motion"].items()
                },
                extremes={s: Extremes(r["max"][s], r["min"][s]) for s in states},
                start=r["starts"][0],
                meshing_regime=r["meshing"],
                lyapunov=lyapunov,
                poincare={s: np.array([v], float) for s, v in zip(states, r["state"], strict=True)},
                spread=r["poincare_spread"],
                verdict=r.get("verdict"),
            )
            key = (float(r[x]), float(r[y]))
            votes = r.get("verdicts", {})
            cells.setdefault(key, []).append(Attractor(r["share"], tuple(r["starts"]), run, votes))
        grid = tuple(
            tuple(Cell(float(a), float(b), tuple(cells[(float(a), float(b))])) for b in yv)
            for a in xv
        )
        return cls(
            d["model"],
            tuple(d["model_hashes"]),
            x,
            xv,
            y,
            yv,
            states,
            tuple(d["coordinates"]),
            d["values"],
            d["settings"],
            grid,
            d["wall_time_s"],
        )
