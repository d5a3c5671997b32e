"""Verdicts a user can trust (issue 12, point 5): minimal period, neutral Floquet
multipliers, an honest Lyapunov uncertainty, the Poincare cloud's extent, the adaptive
sample for the correlation dimension (now: test_verdict_evidence.py)."""

import numpy as np
import pytest
from gearsym.solver.analysis import classify_points, largest_lyapunov
from gearsym.solver.integrate import simulate
from gearsym.solver.periodic import FlowMap, shoot
from gearsym.solver.periodic.shooting import search
from gearsym.solver.system import System

from .conftest import HERE

DUFFING = HERE / "duffing_model.py"


# -- Floquet: neutral within the monodromy's error -------------------------------------


def _linear(k, omega=1.3, B=0.5):
    """x'' + k x' + x = B cos(omega tau): the Duffing fixture with a = 1, c = 0."""
    return System.load(DUFFING, a=1.0, c=0.0, k=k, omega=omega, B=B)


def _closed_form_multipliers(k, T):
    """exp(T s) for the roots s of s^2 + k s + 1 = 0 (the homogeneous linear oscillator)."""
    return np.exp(T * np.roots([1.0, k, 1.0]))


def test_undamped_linear_oscillator_is_neutral_not_unstable():
    # Reference: mu = exp(+-i T) exactly (closed form), |mu| = 1; det M = 1 (Liouville).
    system = _linear(0.0)
    orbit = shoot(system, [0.5 / (1 - 1.3**2), 0.0])
    fl = orbit.floquet
    exact = _closed_form_multipliers(0.0, system.period)
    np.testing.assert_allclose(np.sort_complex(fl.multipliers), np.sort_complex(exact), atol=1e-8)
    assert fl.stability == "neutral" and not fl.stable
    # The stated tolerance covers the actual deviation from the circle, and stays fine.
    assert np.max(np.abs(np.abs(fl.multipliers) - 1.0)) <= fl.tolerance < 1e-6
    assert fl.describe()["stability"] == "neutral"


def test_undamped_duffing_orbit_is_neutral_by_liouville():
    # x'' + x + x^3 = 0.3 cos(2 tau): the flow preserves volume, so det M = 1 (Liouville)
    # and a pair of multipliers off the real axis lies on the unit circle.
    system = System.load(DUFFING, a=1.0, c=1.0, k=0.0, omega=2.0, B=0.3)
    fl = shoot(system, [-0.1, 0.0]).floquet
    assert abs(np.prod(fl.multipliers) - 1.0) < 1e-8
    assert abs(fl.multipliers[0].imag) > 1e-3
    assert fl.stability == "neutral"


@pytest.mark.parametrize("k, expected", [(0.05, "stable"), (-1e-4, "unstable")])
def test_small_damping_either_way_is_resolved(k, expected):
    # Reference: |mu| = exp(-k T / 2) (closed form); with k = -1e-4 it is 1 + 2.4e-4,
    # far outside the tolerance, so the tolerance must not swallow a real instability.
    system = _linear(k)
    fl = shoot(system, [0.5 / (1 - 1.3**2), 0.0]).floquet
    exact = np.exp(-k * system.period / 2)
    np.testing.assert_allclose(np.abs(fl.multipliers), exact, rtol=1e-8)
    assert fl.stability == expected and fl.stable == (expected == "stable")


# -- minimal period --------------------------------------------------------------------


def test_search_tells_the_period_one_orbit_from_a_true_period_two():
    # Twin-well Duffing past its period doubling (B = 0.27 > 0.25, Guckenheimer and
    # Holmes 1983, section 2.2; located in test_periodic.py): the period-1 orbit is a
    # fixed point of the two-period map too, and the attractor is period 2.
    system = System.load(DUFFING, k=0.3, a=-1.0, c=1.0, omega=1.2, B=0.27)
    attractor = simulate(system, np.array([1.0, 0.0]), method="cvodes", transient=600).x_final
    one = shoot(system, attractor, 1)
    assert one.minimal_period == 1
    found = search(system, 2, [one.x0, attractor])
    assert [a["outcome"] for a in found.attempts] == ["period-1", "period-2"]
    assert found.found and found.orbit.minimal_period == 2
    half = FlowMap(system)(found.orbit.x0, system.period)
    assert np.max(np.abs(half - found.orbit.x0)) > 1e-2
    # From the period-1 orbit alone: no period-2 orbit, and the one found is reported at
    # its own period; its multipliers squared are those of the two-period map (M2 = M1^2).
    alone = search(system, 2, [one.x0])
    assert not alone.found and alone.lower.n == 1 and alone.to_dict()["found"] is False
    twice = shoot(system, one.x0, 2)
    assert twice.minimal_period == 1
    np.testing.assert_allclose(
        np.sort_complex(alone.lower.floquet.multipliers**2),
        np.sort_complex(twice.floquet.multipliers),
        rtol=1e-6,
    )


# -- Lyapunov: the stated uncertainty covers the error ---------------------------------


def _covered(system, x0, reference, t0=0.0):
    worst = 0.0
    for periods in (100, 200, 400):
        for seed in range(5):
            est = largest_lyapunov(system, x0, t0=t0, periods=periods, seed=seed)
            error = abs(est.exponent - reference)
            assert error <= est.uncertainty, (periods, seed, error, est.uncertainty)
            worst = max(worst, est.uncertainty)
    return worst


def test_lyapunov_uncertainty_covers_the_error_on_the_reference_orbit():
    # Reference 1 (independent method): on a stable periodic orbit the largest exponent
    # is log|mu_1| / T of its Floquet multipliers.  Reference 2: a long run (8000 periods).
    system = System.load("reference_light", **{"lambda": 0.8})
    orbit = shoot(system, [1.0, -1.0, 0.0, 0.0])
    floquet_ref = np.log(np.max(np.abs(orbit.floquet.multipliers))) / system.period
    long = largest_lyapunov(system, orbit.x0, periods=8000, seed=11)
    assert abs(long.exponent - floquet_ref) <= long.uncertainty < 1e-4
    worst = _covered(system, orbit.x0, floquet_ref)
    assert worst < 0.5 * abs(floquet_ref)  # honest, yet still a usable statement
    d = long.describe()
    assert d["uncertainty"] == long.uncertainty and set(d["uncertainty_parts"]) == {
        "bias",
        "oscillation",
        "statistical",
    }


def test_lyapunov_uncertainty_covers_the_error_on_a_damped_oscillator():
    # Reference (closed form): x'' + 2 zeta x' + x = B cos(omega tau), underdamped, has
    # largest exponent -zeta omega_n = -k / 2 for every solution.
    k = 0.1
    for omega in (0.77, 1.3):
        _covered(_linear(k, omega=omega), np.array([0.3, 0.0]), -k / 2)


# -- Poincare cloud extent and the adaptive sample -------------------------------------


def test_a_small_cloud_is_reported_with_its_extent():
    # Henon's attractor shrunk by 1e-4: the extent in the evidence is the cloud's ptp.
    x, y, pts = 0.1, 0.1, []
    for _ in range(600):
        x, y = 1 - 1.4 * x * x + y, 0.3 * x
        pts.append((x, y))
    cloud = 1e-4 * np.array(pts[100:]).T
    ev = classify_points(cloud, tol=1e-6).evidence
    assert ev["poincare_extent"]["displacement"] == pytest.approx(np.ptp(cloud[0]))
    assert ev["poincare_extent"]["velocity"] == pytest.approx(np.ptp(cloud[1]))
