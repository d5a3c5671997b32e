"""The front door of batched runs (``solver/integrate/run.py``) and its one fallback.

References: the compiled engine (``native/``) for the fallback (``native/fallback.py``) in
every time mode and method, within the tolerances argued in ``test_map_fallback.py``
(a few ``rtol |x|`` each, so ``10 rtol max|x|`` apart); the classic RK4 on the same fixed
grid for the fixed-step method (the same arithmetic: agreement to rounding); the stated
work counts of the stepping itself (RK4: four calls a step).
"""

import pickle
import warnings

import numpy as np
import pytest
from gearsym.solver.contract import load_generated
from gearsym.solver.integrate import native
from gearsym.solver.integrate.run import Batch, integrate
from gearsym.solver.integrate.spec import RunSpec
from gearsym.solver.sweep.atlas import regime_map
from gearsym.solver.system import System

RTOL = 1e-8


@pytest.fixture(scope="module")
def points():
    s = System.load("reference_light")
    P = np.array([s.parameters_with(**{"lambda": a}) for a in (0.3, 0.8)])
    return s, P, np.tile([1.0, 0.0, 0.0, 0.0], (2, 1))


def _both(batch, X0, spec):
    native.reset()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no fallback on the compiled side
        ref = integrate(batch, X0, spec, backend="native")
    return integrate(batch, X0, spec, backend="numpy"), ref


@pytest.mark.parametrize(
    "options",
    [
        dict(samples_per_period=8),
        dict(samples_per_period=8, time="phase"),
        dict(samples_per_period=4, method="dopri5", valid_range="record"),
    ],
)
def test_fallback_samples_agree_with_the_compiled_engine(points, options):
    s, P, X0 = points
    spec = RunSpec(transient=30, periods=3, rtol=RTOL, **options)
    got, ref = _both(Batch.of(s.module, P), X0, spec)
    assert (got.label, ref.label) == (
        f"NumPy fallback {spec.method.upper()}",
        f"compiled {spec.method.upper()}",
    )
    assert got.status == ref.status == ("ok", "ok")
    np.testing.assert_array_equal(got.t, ref.t)
    assert got.x.shape == ref.x.shape == (2, spec.n_samples, 4)
    assert np.max(np.abs(got.x - ref.x)) <= 10 * RTOL * np.max(np.abs(ref.x))
    # the fallback's own counts: at least one call a step, and of the same order as the
    # compiled engine's (the step controls are the same)
    assert np.all(got.nfev > got.nsteps) and np.all(got.nsteps > 0)
    assert np.all(np.abs(np.log(got.nsteps / ref.nsteps)) < np.log(2))
    assert (got.exits is None) == (ref.exits is None) == (spec.valid_range == "ignore")


def test_fallback_rk4_is_the_compiled_rk4_to_rounding(points):
    s, P, X0 = points
    spec = RunSpec(method="rk4", transient=5, periods=2, samples_per_period=4, steps_per_period=64)
    got, ref = _both(Batch.of(s.module, P), X0, spec)
    assert got.status == ref.status == ("ok", "ok")
    np.testing.assert_allclose(got.x, ref.x, rtol=0, atol=1e-12)
    steps = (spec.transient + spec.periods) * spec.steps_per_period
    assert list(got.nsteps) == [steps, steps]
    assert list(got.nfev) == [4 * steps + 1] * 2  # four calls a step, one at the start


def test_the_valid_range_is_recorded_or_stops_the_point_as_compiled(points):
    # negative damping grows until |u| passes the valid range 3: recorded (the run goes on
    # to the escape bound) or stopped there, at the same time within a step
    s, P, X0 = points
    P = np.array([P[0], s.parameters_with(xi_u_u=-0.5, xi_v_v=-0.5)])
    for mode, status in (("record", "divergent"), ("stop", "left the valid range")):
        spec = RunSpec(transient=20, periods=2, rtol=RTOL, valid_range=mode, bound=10.0)
        got, ref = _both(Batch.of(s.module, P), X0, spec)
        assert got.status == ref.status == ("ok", status)
        assert np.isnan(got.exits[0, 0]) and np.isnan(ref.exits[0, 0])
        assert got.exits[1, 1] == ref.exits[1, 1]
        assert abs(got.exits[1, 0] - ref.exits[1, 0]) < s.period / 10
        assert abs(abs(got.exits[1, 2]) - 3.0) < 1e-6
        assert np.all(np.isnan(got.x[1, -1]))


def test_inputs_are_checked_once_with_one_clear_line(points):
    s, P, X0 = points
    spec = RunSpec(transient=1, periods=1)
    batch = Batch.of(s.module, P)
    with pytest.raises(ValueError, match=r"x0 must have shape \(4,\) or \(2, 4\), got \(3,\)"):
        integrate(batch, [1.0, 0, 0], spec)
    with pytest.raises(ValueError, match="x0 holds a NaN"):
        integrate(batch, [np.nan, 0, 0, 0], spec)
    bad = P.copy()
    bad[1, 0] = np.inf
    with pytest.raises(ValueError, match="P holds a NaN or infinite value"):
        integrate(Batch.of(s.module, bad), X0, spec)
    two = np.array([s.parameters_with(omega=w) for w in (0.5, 0.6)])
    with pytest.raises(ValueError, match="must be the same for every point in time 'tau'"):
        integrate(Batch.of(s.module, two), X0, spec)
    with pytest.raises(ValueError, match="backend 'gpu' is unknown; backends: auto, native"):
        integrate(batch, X0, spec, backend="gpu")
    with pytest.raises(ValueError, match="workers must be a whole number >= 1"):
        integrate(batch, X0, spec, workers=0)
    with pytest.raises(TypeError, match="spec must be a RunSpec"):
        integrate(batch, X0, {"rtol": 1e-8})


def test_a_batch_pickles_without_its_module_and_refuses_a_changed_file(points, tmp_path):
    s, P, _ = points
    path = tmp_path / "model.py"
    path.write_bytes(open(s.module.__file__, "rb").read())
    batch = Batch.of(load_generated(path), P)
    again = pickle.loads(pickle.dumps(batch[1:]))
    assert again._module is None and again.digest == batch.digest
    np.testing.assert_array_equal(again.P, P[1:])
    assert again.module.NAME == s.module.NAME
    path.write_bytes(path.read_bytes() + b"\n# edited\n")
    with pytest.raises(ValueError, match="changed while a run was under way"):
        _ = pickle.loads(pickle.dumps(batch)).module


def test_workers_split_the_fallback_points_and_keep_their_order(points):
    s, P, X0 = points
    spec = RunSpec(transient=10, periods=2, collect=("samples", "extremes"), valid_range="stop")
    batch = Batch.of(s.module, P)
    one = integrate(batch, X0, spec, backend="numpy")
    two = integrate(batch, X0, spec, backend="numpy", workers=2)
    np.testing.assert_array_equal(one.x, two.x)
    np.testing.assert_array_equal(one.xmax, two.xmax)
    assert one.status == two.status and list(one.nfev) == list(two.nfev)


def test_a_map_checks_its_options_before_any_work():
    s = System.load("reference_light")
    axes = (("lambda", [0.0, 1.0]), ("f1", [0.1]))
    for kw, says in (
        (dict(rtol=-1.0), "rtol must be a positive number, got -1"),
        (dict(atol=0.0), "atol must be a positive number, got 0"),
        (dict(lyapunov_periods=500), r"lyapunov_periods must be a whole number in \[0, 400\]"),
        (dict(periods=0), r"periods must be a whole number in \[1, "),
    ):
        with pytest.raises(ValueError, match=says):
            regime_map(s, *axes, executor="serial", **kw)
