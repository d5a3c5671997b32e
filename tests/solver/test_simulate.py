"""The integration front door against closed forms and against each other."""

import numpy as np
import pytest
from gearsym.solver.integrate import METHODS, simulate
from gearsym.solver.integrate.methods import get_method
from gearsym.solver.system import System


def closed_form_steady_state(system, tau):
    """u(tau) of u'' + 2 Xi u' + K u = f + ebar''(tau) by complex amplitudes (the forced
    damped linear oscillator): u = K^-1 f + Re[(K - w^2 I + i w 2 Xi)^-1 F e^{i w tau}]."""
    names = list(system.module.PARAMETERS)
    val = dict(zip(names, system.p, strict=True))
    c = system.coordinates
    m = len(c)
    K = np.array([[val.get(f"kappa_{a}_{b}", 0.0) for b in c] for a in c])
    Xi = np.array([[val.get(f"xi_{a}_{b}", 0.0) for b in c] for a in c])
    f = np.array([val[f"f_{a}"] for a in c])
    w = val["omega"]
    F = np.array(
        [
            -(w**2) * val[f"E_{a}_1"] * np.exp(1j * (val[f"psi_{a}_1"] - val.get(f"phi_{a}", 0.0)))
            for a in c
        ]
    )
    X = np.linalg.solve(K - w**2 * np.eye(m) + 2j * w * Xi, F)
    static = np.linalg.solve(K, f)
    u = static[:, None] + np.real(X[:, None] * np.exp(1j * w * tau[None, :]))
    du = np.real(1j * w * X[:, None] * np.exp(1j * w * tau[None, :]))
    return np.vstack([u, du])


@pytest.mark.parametrize("method", ["scipy-dop853", "cvodes"])
def test_linear_limit_matches_the_closed_form_steady_state(linear_system, method):
    tr = simulate(
        linear_system,
        method=method,
        rtol=1e-11,
        atol=1e-13,
        transient=200,
        periods=4,
        samples_per_period=16,
    )
    exact = closed_form_steady_state(linear_system, tr.t)
    # Amplitude and phase to 1e-6: every sample of the steady state within 1e-6.
    assert np.max(np.abs(tr.x - exact)) < 1e-6


@pytest.mark.slow
def test_all_methods_reach_the_steady_state(linear_system):
    # the adaptive methods run the transient at rtol 1e-6 (transient_rtol: Radau's 150
    # periods at 1e-9 took 25 s), the sampled window at 1e-9 as the fixed-step ones do
    for method in METHODS:
        tr = simulate(
            linear_system,
            method=method,
            rtol=1e-9,
            atol=1e-11,
            transient=150,
            periods=2,
            samples_per_period=8,
            steps_per_period=2048,
            transient_rtol=1e-6 if get_method(method).adaptive else None,
        )
        exact = closed_form_steady_state(linear_system, tr.t)
        assert np.max(np.abs(tr.x - exact)) < 1e-5, method
        assert tr.describe()["method"] == method


@pytest.mark.parametrize(
    "method,theory,steps",
    [
        ("rk", 4, [32, 64, 128, 256]),  # classical Runge-Kutta: order 4
        ("collocation", 7, [32, 64, 128]),  # Radau IIA with 4 points: order 2*4 - 1 = 7
    ],
)
def test_fixed_step_methods_converge_at_their_theoretical_order(
    linear_system, method, theory, steps
):
    # Global error after three periods against a tight CVODES run of the same problem;
    # the slope of log error against log step count is the observed order.
    x0 = np.array([1.1, -0.99, 0.0, 0.0])
    errors = []
    for n in steps:
        tr = simulate(
            linear_system,
            x0,
            method=method,
            transient=0,
            periods=3,
            samples_per_period=1,
            steps_per_period=n,
        )
        errors.append(np.max(np.abs(tr.x_final - closed_form_steady_state_from(linear_system, tr))))
    order = -np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert abs(order - theory) < 0.35, (order, errors)


def closed_form_steady_state_from(system, tr):
    """A tight reference of the same initial-value problem (the transient included)."""
    ref = simulate(
        system,
        tr.x[:, 0],
        method="cvodes",
        rtol=1e-13,
        atol=1e-15,
        transient=0,
        periods=tr.periods,
        samples_per_period=1,
        t0=tr.t[0],
    )
    return ref.x_final


def test_scipy_and_casadi_agree_on_a_periodic_poincare_point():
    system = System.load("reference_light", **{"lambda": 0.8})
    a = simulate(system, method="scipy-dop853", rtol=1e-10, atol=1e-12, transient=150, periods=4)
    b = simulate(system, method="cvodes", rtol=1e-10, atol=1e-12, transient=150, periods=4)
    assert np.max(np.abs(a.poincare[:, -1] - b.poincare[:, -1])) < 1e-6


def test_dead_zone_runs_stop_at_each_contact_boundary(tmp_path):
    from gearsym.derive.build import build_files, project_root, write_files

    text = (project_root() / "scenes" / "reference-light.toml").read_text()
    text = text.replace('backlash = "polynomial"', 'backlash = "dead-zone"')
    for key in ("backlash_order", "backlash_range", "backlash_step"):
        text = "\n".join(line for line in text.splitlines() if not line.startswith(key))
    text = text.replace(
        'topology = "topologies/diso.toml"',
        f'topology = "{(project_root() / "scenes/topologies/diso.toml").as_posix()}"',
    )
    text = text.replace('name = "reference-light"', 'name = "dead-zone-light"')
    scene = tmp_path / "dz.toml"
    scene.write_text(text)
    write_files(build_files([scene]).files, tmp_path)
    # A light load keeps both meshes crossing the contact boundaries every period.
    system = System.load(tmp_path / "generated" / "dead_zone_light.py", f1=0.02, **{"lambda": 0.1})
    # Over a few periods (the motion may be sensitive to its initial state, so compare
    # before errors could grow): RK45 restarted at each crossing against a tight CVODES.
    a = simulate(system, method="RK45", rtol=1e-10, atol=1e-12, transient=4, periods=4)
    b = simulate(system, method="cvodes", rtol=1e-12, atol=1e-14, transient=4, periods=4)
    assert a.boundary_crossings >= 8  # u and v meet the contact boundaries every period
    assert np.max(np.abs(a.x - b.x)) < 1e-6


def test_divergence_is_reported_not_hidden(duffing):
    runaway = duffing.with_values(k=-0.5)  # negative damping: the energy grows
    tr = simulate(runaway, method="RK45", transient=0, periods=50, bound=50.0)
    assert tr.status == "divergent" and "passed |x| = 50" in tr.message


def test_unknown_method_lists_the_valid_ones(duffing):
    with pytest.raises(ValueError, match="methods: RK45, scipy-dop853"):
        simulate(duffing, method="rk45")


def test_a_start_on_two_contact_boundaries_finishes(tmp_path):
    from gearsym.derive.build import build_files, project_root, write_files

    text = (project_root() / "scenes" / "reference-light.toml").read_text()
    text = text.replace('backlash = "polynomial"', 'backlash = "dead-zone"')
    text = "\n".join(line for line in text.splitlines() if not line.startswith("backlash_"))
    text = text.replace(
        'topology = "topologies/diso.toml"',
        f'topology = "{(project_root() / "scenes/topologies/diso.toml").as_posix()}"',
    )
    text = text.replace('name = "reference-light"', 'name = "dead-zone-two"')
    scene = tmp_path / "dz.toml"
    scene.write_text(text)
    write_files(build_files([scene]).files, tmp_path)
    system = System.load(tmp_path / "generated" / "dead_zone_two.py")
    tr = simulate(system, [1.0, -1.0, 0.0, 0.0], method="RK45", transient=2, periods=2)
    assert tr.status == "ok" and np.all(np.isfinite(tr.x))


def test_spectrum_reads_the_closed_form_amplitude(linear_system):
    from gearsym.solver.analysis import spectrum

    tr = simulate(
        linear_system,
        method="cvodes",
        rtol=1e-11,
        atol=1e-13,
        transient=200,
        periods=8,
        samples_per_period=32,
    )
    exact = closed_form_steady_state(linear_system, tr.t)
    # Amplitude of u at omega, from the closed form's samples over whole periods.
    a_exact = (exact[0].max() - exact[0].min()) / 2
    sp = spectrum(tr, "u")
    k = int(np.argmin(np.abs(sp.frequency - linear_system.omega)))
    assert sp.amplitude[k] == pytest.approx(a_exact, rel=1e-4)


def test_a_signal_constant_to_rounding_has_no_spectral_peaks():
    """A coordinate at rest (a loop carrying only its locked-in load) is constant up to
    rounding: its spectrum holds noise of about 1e-16 of it, which the relative floor
    alone reported as peaks; an oscillation of 1e-6 of the same mean keeps its peak at
    its own frequency (the signal is built here, so the reference is the input)."""
    from gearsym.solver.analysis.spectra import Spectrum, _hann

    n, omega = 1024, 0.5
    t = np.arange(n) * (2 * np.pi / omega) / 32  # 32 samples a period, 32 periods
    rng = np.random.default_rng(0)

    def of(y):
        w, w_sum = _hann(n)
        amp = np.abs(np.fft.rfft((y - y.mean()) * w)) * 2.0 / w_sum
        return Spectrum(amp, omega, "hann", n, n * t[1], float(np.max(np.abs(y))))

    rest = 2.7569 + 4e-16 * rng.standard_normal(n)
    assert of(rest).peaks() == []
    moving = 2.7569 + 1e-6 * np.cos(omega * t)
    (peak,) = of(moving).peaks()
    assert peak["per_omega"] == pytest.approx(1.0)
    assert peak["amplitude"] == pytest.approx(1e-6, rel=1e-6)
    # without the signal's size (level 0) the old relative floor is all there is
    assert of(rest).__class__(of(rest).amplitude, omega, "hann", n, n * t[1]).peaks() != []
