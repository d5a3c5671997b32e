"""The extremes matrix: every back end at the edges of the parameter space.

Each case changes one thing of the light-load reference scene (load ratio, load, damping,
excitation frequency, number of stiffness harmonics, tolerance) and is run with every
integration back end.  The outcome must be a result with finite numbers or a clear
failure (status and message), never a NaN in a result that claims to be fine.
``python benchmarks/robustness.py`` writes the table to ``docs/robustness.md``; the test
suite runs the same cases.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from gearsym.solver.analysis import analyse_point
from gearsym.solver.integrate import METHODS, SimulationError
from gearsym.solver.system import System

__all__ = ["CASES", "Case", "harmonics_models", "run_case"]


@dataclass(frozen=True)
class Case:
    label: str
    values: dict = field(default_factory=dict)  # scene parameters
    settings: dict = field(default_factory=dict)  # simulate settings
    model: str = "reference_light"  # or "harmonics-0" / "harmonics-10"


CASES = (
    Case("load ratio λ = 0", {"lambda": 0.0}),
    Case("load ratio λ = 1", {"lambda": 1.0}),
    Case("load f1 = 0.001", {"f1": 0.001}),
    Case("load f1 = 2 (past the polynomial's range)", {"f1": 2.0}),
    Case("damping ratio 0", {"damping_ratio": 0.0}),
    Case("damping ratio 1e-4", {"damping_ratio": 1e-4}),
    Case("damping ratio 0.5", {"damping_ratio": 0.5}),
    Case("excitation ω̄ = 0.05", {"omega": 0.05}),
    Case("excitation ω̄ = 3", {"omega": 3.0}),
    Case("0 stiffness harmonics", model="harmonics-0"),
    Case("10 stiffness harmonics", model="harmonics-10"),
    Case("tolerance 1e-3", settings={"rtol": 1e-3, "atol": 1e-5}),
    Case("tolerance 1e-13", settings={"rtol": 1e-13, "atol": 1e-15}),
    # Not in the list: a case that must fail, to show how failures end.
    # (The damping ratio itself must be in [0, 1]; the model's own damping coefficients
    # are raw parameters and may be negative.)
    Case("mesh damping coefficients -0.5 (energy grows)", {"xi_u_u": -0.5, "xi_v_v": -0.5}),
)

# The study is about how each integration ends, not about the motion: no exponent, and no
# extension of the 2-period window to the 400 Poincare points a non-periodic verdict
# would otherwise ask for (that made Radau on the undamped case run for minutes): budget 0.
BASE = dict(
    transient=6,
    periods=2,
    samples_per_period=16,
    lyapunov_periods=0,
    steps_per_period=256,
    budget=0,
)


def harmonics_models(folder: Path) -> dict[str, Path]:
    """Generate the reference light-load model with 0 and with 10 stiffness harmonics
    (variants of the scene, derived into ``folder/generated``)."""
    from gearsym.derive import derive_model, load_target, variant
    from gearsym.derive.emit.python import emit_module, write_atomic
    from gearsym.derive.input.scene import builtin_root

    scene = load_target(builtin_root() / "reference-light.toml")
    out = {}
    for h in (0, 10):
        model = derive_model(variant(scene, f"harmonics-{h}", stiffness_harmonics=h))
        path = Path(folder) / "generated" / f"{model.name}.py"
        write_atomic(path, emit_module(model, "gearsym.studies.robustness.harmonics_models"))
        out[f"harmonics-{h}"] = path
    return out


def run_case(case: Case, method: str, models: dict[str, Path] | None = None) -> dict:
    """Run one case with one back end; return its outcome as plain data."""
    module = (models or {}).get(case.model, case.model)
    started = time.perf_counter()
    outcome = {"case": case.label, "method": method}
    try:
        system = System.load(module, **case.values)
        result = analyse_point(system, method=method, **(BASE | case.settings))
    except (SimulationError, ValueError) as err:
        outcome.update(status="failed", message=str(err).splitlines()[0][:160])
    else:
        tr = result.trajectory
        u = tr.coordinate(system.coordinates[0])
        finite = bool(np.all(np.isfinite(tr.x)))
        outcome.update(
            status=tr.status,
            message=tr.message,
            finite=finite,
            u_range=(float(u.min()), float(u.max())) if finite else None,
            nfev=tr.nfev,
            left_valid_range=tr.left_valid_range,
        )
    outcome["seconds"] = time.perf_counter() - started
    return outcome


def describe(outcome: dict) -> str:
    """One table cell."""
    if outcome["status"] == "ok":
        lo, hi = outcome["u_range"]
        note = f"u ∈ [{lo:.3f}, {hi:.3f}]"
        if outcome.get("left_valid_range"):
            t, c, v = outcome["left_valid_range"]
            note += f"; left the valid range ({c} = {v:.3g} at τ = {t:.3g})"
        return note
    return f"{outcome['status']}: {outcome['message']}"


def matrix(models=None) -> list[dict]:
    return [run_case(case, method, models) for case in CASES for method in METHODS]
