"""Which compiled library a batch runs with, and at which optimisation level
(``engine.batch_shared``, ``compiler.level``): the choices ``native/compiler.py`` and
``engine.HOIST_FROM`` state, each with the measurement behind it there."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from gearsym.resolve import module_for
from gearsym.solver.integrate.native.build import level, single_point
from gearsym.solver.integrate.native.engine import HOIST_FROM, batch_shared, shared_parameters
from gearsym.solver.integrate.spec import RunSpec


def _sweep(module, points: int) -> np.ndarray:
    return np.array([module.parameters(**{"lambda": v}) for v in np.linspace(0, 1, points)])


def test_a_short_batch_runs_with_the_models_one_library():
    module = module_for("reference-light")
    P = _sweep(module, 40)
    assert batch_shared(module, P, RunSpec(transient=300, periods=100)) == ()


def test_a_long_batch_of_a_smooth_model_gets_its_own_library():
    module = module_for("reference-light")
    P = _sweep(module, 40)
    periods = HOIST_FROM // 40  # 40 points x periods = HOIST_FROM
    shared = batch_shared(module, P, RunSpec(transient=0, periods=periods))
    assert shared == shared_parameters(P)
    assert 0 < len(shared) < len(module.CONTRACT["parameters"])  # lambda's own vary
    assert batch_shared(module, P, RunSpec(transient=0, periods=periods, hoist=False)) == ()


def test_one_point_runs_with_the_one_point_library():
    module = module_for("reference-light")
    shared = batch_shared(module, _sweep(module, 1), RunSpec())
    assert shared == single_point(module)


def test_a_piecewise_model_never_gets_a_batch_library():
    module = module_for("reference-dead-zone")
    P = _sweep(module, 40)
    assert batch_shared(module, P, RunSpec(transient=0, periods=HOIST_FROM)) == ()


def test_optimisation_levels():
    small, dead = module_for("reference-light"), module_for("reference-dead-zone")
    large = module_for("diso-bearings-light")
    assert level(small, False, ()) == ("-O3",)  # a batch library of a smooth model
    assert level(small, True, ()) == ("-O3",)
    assert level(small, True, single_point(small)) == ()  # its one-point library: -O2
    assert level(large, True, single_point(large)) == ("-O3",)  # from 12 states
    assert level(dead, True, ()) == ()  # piecewise
    assert level(small, "monodromy") == ()
    assert level(large, "monodromy") == ("-O3",)


@pytest.mark.parametrize(
    ("rows", "identical"), [(1, True), (3, True), (40, False)], ids=["one", "copies", "batch"]
)
def test_the_library_checked_is_the_library_run(monkeypatch, rows, identical):
    # decide_backend checks (and may compile) a library before the run; a run that then
    # took another compiled one library for nothing and another in the middle of the run
    from gearsym.solver.integrate import default_initial_state
    from gearsym.solver.integrate.run import Batch, integrate
    from gearsym.solver.system import System

    build = sys.modules["gearsym.solver.integrate.native.build"]
    engine = sys.modules["gearsym.solver.integrate.native.engine"]

    module = module_for("reference-light")
    P = np.repeat(_sweep(module, 1), rows, axis=0) if identical else _sweep(module, rows)
    x0 = np.asarray(default_initial_state(System.load(module)), float)
    asked = []

    def recording(real):
        def library(module, variational=False, shared=()):
            asked.append((variational, tuple(shared)))
            return real(module, variational, shared)

        return library

    monkeypatch.setattr(build, "library", recording(build.library))
    monkeypatch.setattr(engine, "library", recording(engine.library))
    spec = RunSpec(transient=2, periods=2, collect=("samples", "exponent"), lyapunov_periods=4)
    integrate(Batch.of(module, P), np.repeat(x0[None, :], rows, axis=0), spec)
    assert len(asked) >= 2 and len(set(asked)) == 1, asked
    want = single_point(module) if identical else ()
    assert asked[0] == (True, want)
