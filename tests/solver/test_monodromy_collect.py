"""The monodromy a run collects (``collect=(..., "monodromy")``): the variational
equations' tangents, one per state, against central differences of the flow (an
independent route written here) and the compiled engine against its NumPy fallback."""

import numpy as np
import pytest
from gearsym.solver.integrate import native
from gearsym.solver.integrate.run import integrate
from gearsym.solver.integrate.spec import RunSpec
from gearsym.solver.system import System

pytestmark = pytest.mark.skipif(native.compiler() is None, reason="no C compiler")


def _spec(periods: int, **kw) -> RunSpec:
    return RunSpec(
        method="dop853",
        rtol=1e-12,
        atol=1e-14,
        time="phase",
        transient=0,
        periods=periods,
        valid_range="ignore",
        bound=1e6,
        collect=("samples", "exponent", "monodromy"),
        lyapunov_periods=periods,
        **kw,
    )


def _central(system, x, spec, h=1e-5):
    """d phi / dx by central differences of the plain flow (steps h max(1, |x_i|)): the
    error about h^2 + rtol / h, near 1e-7 relative."""
    plain = spec.with_(collect=("samples",), lyapunov_periods=0)
    n = system.n
    M = np.empty((n, n))
    for k in range(n):
        step = h * max(1.0, abs(x[k]))
        e = np.zeros(n)
        e[k] = step
        up = integrate(system, x + e, plain).x[0, -1]
        down = integrate(system, x - e, plain).x[0, -1]
        M[:, k] = (up - down) / (2 * step)
    return M


@pytest.mark.parametrize("name,periods", [("reference_light", 1), ("reference_light", 3)])
def test_the_collected_monodromy_is_the_flow_derivative(name, periods):
    system = System.load(name).with_values(**{"lambda": 0.4})
    x = np.array([0.9, 0.7, 0.1, -0.2])
    spec = _spec(periods)
    res = integrate(system, x, spec)
    M = res.monodromy[0]
    np.testing.assert_allclose(M, _central(system, x, spec), rtol=0, atol=2e-6 * np.abs(M).max())
    # the samples are those of the run without the monodromy
    plain = integrate(system, x, spec.with_(collect=("samples", "exponent")))
    np.testing.assert_allclose(res.x, plain.x, rtol=0, atol=1e-10)
    assert res.status == ("ok",)


def test_several_points_and_the_fallback_agree():
    system = System.load("reference_light")
    P = np.array([system.with_values(**{"lambda": v}).p for v in (0.1, 0.5, 0.9)])
    from gearsym.solver.integrate.run import Batch

    batch = Batch.of(system.module, P)
    X0 = np.array([[0.9, 0.7, 0.1, -0.2], [1.1, 0.2, 0.0, 0.3], [0.5, -0.4, 0.2, 0.1]])
    spec = _spec(2)
    fast = integrate(batch, X0, spec, backend="native")
    slow = integrate(batch, X0, spec, backend="numpy")
    assert fast.monodromy.shape == (3, 4, 4) and fast.x.shape[0] == 3
    for a, b in zip(fast.monodromy, slow.monodromy, strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-7 * np.abs(b).max())
    # each point's monodromy is its own: the same as run alone
    alone = integrate(System.load("reference_light").with_values(**{"lambda": 0.5}), X0[1], spec)
    np.testing.assert_allclose(fast.monodromy[1], alone.monodromy[0], rtol=1e-8, atol=1e-10)


def test_a_piecewise_model_runs_point_by_point():
    # The dead zone's runs take their own steps (group 1), the copies of a point too: the
    # samples are those of the run alone, up to the steps (the tangent, another start
    # here, is in the step control; a kink passed at another step moves them by 1e-7).
    # Its flow is only once differentiable at the kinks, and near a grazing contact
    # neither the tangent nor differences settle: from this state the first entry is
    # 0.43608 or 0.43627 by tolerance, and the compiled engine and its fallback, which
    # renormalise at other stops, differ by 2e-5; why the orbit check takes differences
    # for such a model (orbit_check.py).
    system = System.load("reference_dead_zone")
    x = np.array([0.9, 0.7, 0.1, -0.2])
    spec = _spec(2)
    res = integrate(system, x, spec)
    alone = integrate(system, x, spec.with_(collect=("samples", "exponent")))
    np.testing.assert_allclose(res.x, alone.x, rtol=0, atol=1e-6)
    assert res.monodromy.shape == (1, 4, 4) and np.all(np.isfinite(res.monodromy))


def test_the_monodromy_needs_the_tangent_from_the_start():
    with pytest.raises(ValueError, match="lyapunov_periods = transient \\+ periods"):
        _spec(2).with_(lyapunov_periods=1)
    with pytest.raises(ValueError, match="needs 'exponent' collected"):
        _spec(2).with_(collect=("samples", "monodromy"), lyapunov_periods=0)


def test_the_orbit_check_names_its_route_when_it_fails_too():
    from gearsym.solver.analysis.orbit_check import check_orbit

    x = np.array([0.9, 0.7, 0.1, -0.2])
    failed = check_orbit(System.load("reference_dead_zone"), x, 1, max_iter=0)
    assert not failed.converged and "central-difference" in failed.describe()["method"]
    assert "grazing" in failed.describe()["multiplier_error_note"]
    smooth = check_orbit(System.load("reference_light"), x, 1, max_iter=0)
    assert not smooth.converged and "variational" in smooth.describe()["method"]
    assert "multiplier_error_note" not in smooth.describe()


@pytest.mark.parametrize(
    "name,values",
    [
        ("reference-light", {"lambda": 0.4}),
        ("lin-parker-1999-3-backlash", {"mesh_frequency_hz": 2000.0}),
        ("back-to-back-rig", {}),
    ],
)
def test_the_matrix_of_tangents_gives_the_monodromy_of_the_tangents_one_by_one(
    name, values, monkeypatch
):
    """The monodromy library (F and the Jacobian's nonzero entries once a stage, J W over
    them: derive/emit/c_jacobian.py, native/monodromy.c) against the route it replaces,
    one copy of the state per tangent through the variational library (J w generated
    apart, from C_SOURCE_VARIATIONAL): the same matrix to rounding, also for the dead
    zones of the planetary set and the rig."""
    from gearsym.resolve import load
    from gearsym.solver.integrate.native import build

    system = load(name).with_values(**values)
    assert build.monodromy_library(system.module)
    start = RunSpec(method="dop853", rtol=1e-8, atol=1e-10, transient=200, periods=1)
    x = integrate(system, np.full(system.n, 0.01), start).x[0, -1]
    matrix = integrate(system, x, _spec(1))
    monkeypatch.setattr(build, "monodromy_library", lambda module: False)
    copies = integrate(system, x, _spec(1))
    scale = np.abs(copies.monodromy).max()
    np.testing.assert_allclose(matrix.monodromy, copies.monodromy, rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(matrix.x, copies.x, rtol=0, atol=1e-12)
    # one run of n + n^2 states, where the copies made n runs of 2n
    assert matrix.nfev[0] < copies.nfev[0] / 4
