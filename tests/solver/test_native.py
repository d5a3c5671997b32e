"""The compiled batched integrators against the NumPy code and SciPy's integrators."""

import warnings

import numpy as np
import pytest
from gearsym.solver.integrate import default_initial_state, native, simulate
from gearsym.solver.system import System

pytestmark = pytest.mark.skipif(native.compiler() is None, reason="no C compiler")

SHIPPED = ["reference_light", "reference_dead_zone", "reference_linear", "siso", "tiso"]


@pytest.mark.parametrize("name", SHIPPED)
def test_c_right_hand_side_equals_the_numpy_one(name):
    # The C code (trig harmonics by recurrence, phases hoisted) and the NumPy code are
    # printed from the same SymPy expressions: they agree to rounding.
    system = System.load(name)
    lib, _ = native.library(system.module)
    rng = np.random.default_rng(1)
    n = system.n
    for _ in range(20):
        x = rng.uniform(-2.5, 2.5, n)
        tau = rng.uniform(0, 200)
        dx = np.empty(n)
        lib.gs_eval(tau, x, np.ascontiguousarray(system.p), dx)
        np.testing.assert_allclose(dx, system.rhs(tau, x), rtol=1e-12, atol=1e-12)
    # the batched (structure-of-arrays) form, several points sharing omega
    X = rng.uniform(-2.5, 2.5, (n, 7))
    P = np.repeat(system.p[:, None], 7, axis=1)
    P[1] = np.linspace(0.0, 0.5, 7)  # a load differs between points
    DX = np.empty_like(X)
    lib.gs_eval_batch(3.7, 7, np.ascontiguousarray(X), np.ascontiguousarray(P), DX)
    np.testing.assert_allclose(DX, system.module.rhs(3.7, X, P), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize(
    "native_method,scipy_method", [("dop853", "scipy-dop853"), ("dopri5", "RK45")]
)
def test_same_poincare_points_as_scipy(native_method, scipy_method):
    # Same algorithm and step control as SciPy's solve_ivp: the Poincare points of the
    # stable period-1 orbit at lambda = 0.8 agree well within the tolerance.
    system = System.load("reference_light", **{"lambda": 0.8})
    x0 = default_initial_state(system)
    kw = dict(rtol=1e-8, atol=1e-10, transient=50, periods=10, samples_per_period=4)
    a = simulate(system, x0, method=native_method, **kw)
    b = simulate(system, x0, method=scipy_method, **kw)
    assert a.status == b.status == "ok"
    np.testing.assert_allclose(a.x, b.x, atol=1e-7)
    assert a.nfev > 0 and a.nsteps > 0


def test_rk4_converges_at_fourth_order():
    # Observed order of the fixed-step RK4 against a tight DOP853 run: halving the step
    # divides the error by about 2^4 (theory 4).
    system = System.load("reference_light", **{"lambda": 0.5})
    x0 = default_initial_state(system)
    kw = dict(transient=0, periods=4, samples_per_period=1)
    ref = simulate(system, x0, method="dop853", rtol=1e-13, atol=1e-14, **kw).x
    errors = [
        np.max(np.abs(simulate(system, x0, method="rk4", steps_per_period=s, **kw).x - ref))
        for s in (64, 128, 256)
    ]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 4.0) < 0.35), orders


def test_lockstep_batch_agrees_with_point_by_point():
    # Lockstep groups share the step (the smallest any point needs): same points to within
    # the tolerance at stable period-1 orbits.
    module = System.load("reference_light").module
    lam = np.linspace(0.6, 1.0, 9)
    P = np.array([module.parameters(**{"lambda": v}) for v in lam])
    x0 = default_initial_state(System.load("reference_light"))
    X0 = np.repeat(x0[None, :], len(lam), axis=0)
    kw = dict(method="dop853", transient=60, periods=5, samples_per_period=1)
    one = native.run_batch(module, P, X0, lockstep=False, **kw)
    many = native.run_batch(module, P, X0, lockstep=True, group=4, **kw)
    assert one.status == many.status == ("ok",) * len(lam)
    np.testing.assert_allclose(many.x, one.x, atol=1e-7)


def test_lockstep_dense_output_equals_scipy_dop853_dense_output():
    # Reference: SciPy's DOP853 with dense_output=True (an independent implementation of
    # the same method, step control and interpolant).  Two identical points make the
    # lockstep group take exactly one point's steps, unshortened up to the window's end,
    # so the interpolated samples agree to rounding; the step-shortening path (dense=False)
    # lands on each sample and agrees only to the tolerance.
    from scipy.integrate import solve_ivp

    system = System.load("reference_light", **{"lambda": 0.3})
    x0 = default_initial_state(system)
    P = np.array([system.p, system.p])
    X0 = np.array([x0, x0])
    kw = dict(method="dop853", rtol=1e-8, atol=1e-10, transient=5, periods=3)
    dense = native.run_batch(system.module, P, X0, samples_per_period=16, **kw)
    ref = solve_ivp(
        system.rhs,
        (0.0, dense.t[-1]),
        x0,
        method="DOP853",
        rtol=1e-8,
        atol=1e-10,
        dense_output=True,
    )
    assert dense.status == ("ok", "ok")
    assert dense.nsteps[0] == ref.t.size - 1  # the same steps
    np.testing.assert_allclose(dense.x[0], ref.sol(dense.t).T, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(dense.x[0], dense.x[1])
    assert dense.t.size == 3 * 16 + 1
    clipped = native.run_batch(system.module, P, X0, samples_per_period=16, dense=False, **kw)
    assert clipped.nsteps[0] > dense.nsteps[0]
    np.testing.assert_allclose(dense.x, clipped.x, rtol=0, atol=1e-7)


def test_phase_runs_of_three_frequencies_in_one_group_equal_scipy_in_tau():
    # Reference: SciPy's DOP853 in tau at a tight tolerance, one frequency at a time.  In
    # the phase s = omega tau the three frequencies share one lockstep group; the state is
    # the physical one, so the samples compare directly.
    from gearsym.solver.integrate.native.phase import run_phase

    system = System.load("reference_light", **{"lambda": 0.8})
    omegas = (0.45, 0.5, 0.55)
    P = np.array([system.parameters_with(omega=w) for w in omegas])
    X0 = np.repeat(default_initial_state(system)[None, :], 3, axis=0)
    run = run_phase(system.module, P, X0, transient=60, periods=4, samples_per_period=16)
    assert run.status == ("ok",) * 3
    assert np.allclose(run.t, 2 * np.pi * (60 + np.arange(4 * 16 + 1) / 16))
    for j, w in enumerate(omegas):
        ref = simulate(
            system.with_values(omega=w),
            X0[j],
            method="scipy-dop853",
            rtol=1e-11,
            atol=1e-13,
            transient=60,
            periods=4,
            samples_per_period=16,
        )
        np.testing.assert_allclose(ref.t * w, run.t[: ref.t.size], rtol=1e-12)
        np.testing.assert_allclose(run.x[j, : ref.t.size], ref.x.T, rtol=0, atol=1e-7)


def test_a_diverging_point_does_not_spoil_its_group():
    module = System.load("reference_light").module
    good = module.parameters(**{"lambda": 0.8})
    bad = module.parameters(**{"lambda": 0.8, "xi_u_u": -0.5, "xi_v_v": -0.5})
    P = np.array([good, bad, good])
    x0 = default_initial_state(System.load("reference_light"))
    X0 = np.repeat(x0[None, :], 3, axis=0)
    res = native.run_batch(module, P, X0, method="dop853", transient=40, periods=2, group=3)
    assert res.status == ("ok", "divergent", "ok")
    assert np.isfinite(res.t_fail[1]) and np.all(np.isnan(res.x[1, -1]))
    alone = native.run_batch(module, P[:1], X0[:1], method="dop853", transient=40, periods=2)
    np.testing.assert_allclose(res.x[0], alone.x[0], atol=1e-7)


def test_library_is_cached_on_disk(tmp_path, monkeypatch):
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path))
    module = System.load("siso").module
    native.reset()
    _, first = native.library(module)
    native.reset()
    _, second = native.library(module)
    assert first["compiled"] and not second["compiled"]
    assert first["path"] == second["path"] and first["path"].startswith(str(tmp_path))


def test_without_a_compiler_numpy_takes_over_with_a_warning(monkeypatch):
    monkeypatch.setenv("GEARSYM_CC", "none")
    native.reset()
    try:
        module = System.load("reference_light").module
        P = np.array([module.parameters(**{"lambda": v}) for v in (0.7, 0.9)])
        x0 = default_initial_state(System.load("reference_light"))
        X0 = np.repeat(x0[None, :], 2, axis=0)
        with pytest.warns(UserWarning, match="GEARSYM_CC='none' turns the C compiler off.*NumPy"):
            res = native.run_batch(module, P, X0, method="dop853", transient=30, periods=3)
        assert res.backend == "numpy"
        monkeypatch.delenv("GEARSYM_CC")
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            compiled = native.run_batch(module, P, X0, method="dop853", transient=30, periods=3)
        assert compiled.backend == "native"
        np.testing.assert_allclose(res.x, compiled.x, atol=1e-6)
    finally:
        native.reset()


def test_native_lyapunov_exponent_matches_cvodes():
    # Two independent integrators of the same variational equations (compiled DOP853 and
    # CasADi's CVODES) give the same Benettin estimate.
    from gearsym.solver.analysis import largest_lyapunov

    system = System.load("reference_light", **{"lambda": 0.1})
    tr = simulate(system, method="dop853", transient=200, periods=2, samples_per_period=1)
    a = largest_lyapunov(system, tr.x_final, t0=tr.t_final, periods=60, backend="native")
    b = largest_lyapunov(system, tr.x_final, t0=tr.t_final, periods=60, backend="cvodes")
    assert a.exponent < 0
    assert a.exponent == pytest.approx(b.exponent, rel=1e-5)
    assert a.describe()["method"].endswith("compiled DOP853")


def test_bad_starts_end_at_once_with_a_status():
    # A start beyond the bound (or one whose right-hand side is not finite) ends the point
    # at once instead of stepping forever; NaN parameters are refused with a message.
    module = System.load("reference_light").module
    p = module.parameters()
    start = np.array([[1.0, 0.0, 0.0, 0.0], [1e50, -1e50, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
    for lockstep in (False, True):
        res = native.run_batch(
            module,
            np.repeat(p[None, :], 3, axis=0),
            start,
            transient=2,
            periods=1,
            lockstep=lockstep,
            group=3,
        )
        assert res.status == ("ok", "divergent", "ok")
    bad = p.copy()
    bad[3] = np.nan
    with pytest.raises(ValueError, match="P holds a NaN"):
        native.run_batch(module, bad[None, :], start[:1])


def test_fallback_with_workers_and_a_diverging_point(monkeypatch):
    # Without a compiler, several workers and a diverging point still give every point its
    # own status, as the compiled path does.
    monkeypatch.setenv("GEARSYM_CC", "none")
    module = System.load("reference_light").module
    P = np.array(
        [
            module.parameters(**{"lambda": 0.8}),
            module.parameters(**{"lambda": 0.8, "xi_u_u": -0.5, "xi_v_v": -0.5}),
        ]
    )
    x0 = default_initial_state(System.load("reference_light"))
    X0 = np.repeat(x0[None, :], 2, axis=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = native.run_batch(module, P, X0, method="dop853", transient=40, periods=2, workers=2)
    assert res.backend == "numpy"
    assert res.status == ("ok", "divergent")


# ---- the one C entry, gs_integrate, and its job (native/abi.py, native/engine.py) ----


def _job_parts(module, N=2, **changes):
    """The arguments of abi.fill for a small sampled run of ``module``."""
    from gearsym.solver.contract import Contract
    from gearsym.solver.integrate.native import abi

    n, n_p = len(Contract.of(module).states), len(Contract.of(module).parameters)
    P = np.ascontiguousarray(np.repeat(module.parameters()[None, :], N, axis=0))
    arrays = {
        "P": P,
        "X0": np.zeros((N, n)),
        "x": np.empty((N, 3, n)),
        "nfev": np.zeros(N, dtype=np.int64),
        "nsteps": np.zeros(N, dtype=np.int64),
        "status": np.zeros(N, dtype=np.int32),
        "t_fail": np.zeros(N),
    }
    ints = dict(
        abi=abi.ABI_VERSION,
        n_points=N,
        n_states=n,
        n_params=n_p,
        group=2,
        transient=1,
        periods=2,
        samples_per_period=1,
        steps_per_period=16,
        lyapunov_periods=0,
        max_steps=10**6,
        method=1,
        time_mode=0,
        omega_index=0,
        valid_range=2,
        flags=0,
    )
    ints.update(changes)
    doubles = dict(t0=0.0, period=2 * np.pi, rtol=1e-8, atol=1e-10, bound=1e3)
    return ints, doubles, arrays, {k: v.size for k, v in arrays.items()}


def test_job_layout_is_checked_against_the_c_struct():
    # The library exports gs_job's fields (name and kind, in order) and offsets; abi.bind
    # accepted them at load, and a library that lays the struct out otherwise is refused
    # with one line naming the first difference.
    from gearsym.solver.integrate.native import abi

    lib, _ = native.library(System.load("reference_light").module)
    names = lib.gs_job_fields().decode().split()
    assert names == [f"{n}:{abi._KIND[t]}" for n, t in abi.Job._fields_]

    class Swapped:
        def __init__(self):
            self.gs_job_fields = lambda: lib.gs_job_fields().replace(b"rtol", b"RTOL")
            self.gs_job_layout = lib.gs_job_layout

    with pytest.raises(abi.LayoutMismatch, match=r"field \d+: C 'RTOL:d', Python 'rtol:d'"):
        abi.bind(Swapped(), "fake.so")


def test_oversized_and_mismatched_sizes_are_refused_before_the_call():
    from gearsym.solver.integrate.native import abi

    module = System.load("reference_light").module
    ints, doubles, arrays, lengths = _job_parts(module, n_points=2**64)
    with pytest.raises(ValueError, match="n_points = 18446744073709551616 is outside the 64-bit"):
        abi.fill(ints, doubles, arrays, lengths)
    ints, doubles, arrays, lengths = _job_parts(module)
    arrays["x"] = np.empty((2, 2, 4))  # one sample short
    with pytest.raises(ValueError, match=r"^x holds 16 numbers where the run needs 24$"):
        abi.fill(ints, doubles, arrays, lengths)


def test_the_c_refuses_what_python_would_have_caught_and_writes_nothing():
    # The C checks every size again (products in int64 with an overflow check): a job
    # whose lengths lie, whose sample count overflows or whose group would need a huge
    # allocation is refused with a code, the outputs untouched.
    from gearsym.solver.integrate.native import abi

    module = System.load("reference_light").module
    lib, _ = native.library(module)
    cases = [
        ({}, {"x_len": 23}, "length"),
        ({"periods": 2**62, "samples_per_period": 4}, {}, "length"),
        ({"group": 10**9}, {}, "option"),
        ({"abi": abi.ABI_VERSION + 1}, {}, "version"),
    ]
    for changes, lie, words in cases:
        ints, doubles, arrays, lengths = _job_parts(module, **changes)
        lengths = {k: v for k, v in lengths.items()}
        job, keep = abi.fill(ints, doubles, arrays, lengths)
        for name, value in lie.items():
            setattr(job, name, value)
        arrays["status"][:] = 7
        with pytest.raises(RuntimeError, match=words):
            abi.call(lib, job)
        assert np.all(arrays["status"] == 7)
    ints, doubles, arrays, lengths = _job_parts(module)  # the honest job runs
    job, keep = abi.fill(ints, doubles, arrays, lengths)
    abi.call(lib, job)
    assert np.all(arrays["status"] == 0) and np.all(np.isfinite(arrays["x"]))


def test_rk4_through_the_tableau_equals_the_classic_formula():
    # Reference: classic RK4 written out (y + h/6 (k1 + 2 k2 + 2 k3 + k4)) on the NumPy
    # right-hand side, on the engine's grid t0 + j h.  The compiled step is the generic
    # one with tableau.RK4's coefficients; the two differ only by rounding (C vs NumPy
    # right-hand side, weights 1/6, 1/3 vs h/6, 2).
    from gearsym.solver.integrate.native.engine import run_compiled
    from gearsym.solver.integrate.spec import RunSpec

    system = System.load("reference_light", **{"lambda": 0.5})
    x0 = default_initial_state(system)
    spec = RunSpec(
        method="rk4",
        transient=0,
        periods=1,
        samples_per_period=4,
        steps_per_period=64,
        valid_range="ignore",
        lockstep=False,
    )
    res = run_compiled(system.module, system.p[None], x0[None], spec)
    h, y, ref = system.period / 64, x0.copy(), [x0.copy()]
    for j in range(64):
        t = j * h
        k1 = system.rhs(t, y)
        k2 = system.rhs(t + 0.5 * h, y + 0.5 * h * k1)
        k3 = system.rhs(t + 0.5 * h, y + 0.5 * h * k2)
        k4 = system.rhs(t + h, y + h * k3)
        y = y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        if (j + 1) % 16 == 0:
            ref.append(y.copy())
    assert res.status == ("ok",) and res.nsteps[0] == 64 and res.nfev[0] == 4 * 64 + 1
    np.testing.assert_allclose(res.x[0], np.array(ref), rtol=0, atol=1e-12)


def test_a_start_outside_the_valid_range_is_an_exit_at_t0():
    from gearsym.solver.contract import Contract
    from gearsym.solver.integrate.native.engine import run_compiled
    from gearsym.solver.integrate.spec import RunSpec

    system = System.load("diso")
    (i, bound), *_ = Contract.of(system.module).valid_bounds()
    x0 = default_initial_state(system)
    x0[i] = 1.5 * bound
    for mode, status in (("record", "ok"), ("stop", "left the valid range")):
        spec = RunSpec(transient=1, periods=1, t0=2.0, valid_range=mode, bound=1e6)
        res = run_compiled(system.module, system.p[None], x0[None], spec)
        assert res.status == (status,)
        np.testing.assert_array_equal(res.exits[0], [2.0, i, 1.5 * bound])
