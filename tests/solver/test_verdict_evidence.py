"""Verdicts on evidence (issue 27): each label from its own test, on systems whose answer
is known from a closed form or the literature, never from gearsym's own earlier output."""

import numpy as np
import pytest
from gearsym.solver.analysis import analyse_point, classify_points
from gearsym.solver.analysis.orbit_check import check_orbit
from gearsym.solver.analysis.two_trajectory import two_trajectory
from gearsym.solver.periodic import shoot
from gearsym.solver.system import System

from .conftest import HERE

DUFFING = HERE / "duffing_model.py"


def _twin_well(B):
    """x'' + 0.3 x' - x + x^3 = B cos(1.2 tau): Guckenheimer and Holmes (1983, section
    2.2), whose period doubling cascade to chaos lies between B = 0.26 and 0.31."""
    return System.load(DUFFING, k=0.3, a=-1.0, c=1.0, omega=1.2, B=B)


def test_ueda_oscillator_is_chaotic_on_two_windows_and_the_0_1_test():
    # Ueda (1979): x'' + 0.05 x' + x^3 = 7.5 cos(tau) is chaotic; its largest exponent is
    # about 0.1 per unit time (Ueda's attractor; e.g. Parlitz and Lauterborn 1985).
    r = analyse_point(System.load(DUFFING), np.array([2.5, 0.0]))
    v = r.verdict
    assert v.motion == "chaotic" and v.period is None
    windows = v.evidence["windows"]
    assert [w["label"] for w in windows[-2:]] == ["chaotic", "chaotic"]
    for w in windows[-2:]:
        lo, hi = w["exponent"]["interval"]
        assert 0.0 < lo and 0.05 < w["exponent"]["exponent"] < 0.15 and hi < 0.2
        assert w["zero_one"]["K"] > 0.9  # Gottwald and Melbourne: K near 1 for chaos
    assert v.periods_run == windows[-1]["window"][1]  # the periods it took, recorded
    # one verdict for the attractor, carried by every coordinate with its spread
    assert r.classification["x"].motion == "chaotic"
    assert r.classification["x"].evidence["spread"]["share"] == 1.0


def test_a_budget_too_short_for_chaos_says_undetermined_with_its_reason():
    r = analyse_point(System.load(DUFFING), np.array([2.5, 0.0]), budget=800)
    assert r.verdict.motion == "undetermined"
    assert "800 periods" in r.verdict.evidence["why"]


def test_two_frequency_motion_is_a_torus_with_the_closed_form_rotation_number():
    # x'' + x = 0.5 cos(sqrt(2) tau) from a state off the forced solution: the free
    # oscillation (frequency 1) beside the forced one (sqrt 2) -- a two-frequency torus
    # whose rotation number per forcing period is frac(1 / sqrt 2), folded into (0, 1/2]:
    # 1 - 1/sqrt(2) (closed form); the exponent is exactly 0 (undamped and linear).
    system = System.load(DUFFING, a=1.0, c=0.0, k=0.0, omega=np.sqrt(2.0), B=0.5)
    v = analyse_point(system, np.array([0.3, 0.0])).verdict
    assert v.motion == "quasi-periodic"
    for w in v.evidence["windows"][-2:]:
        assert w["label"] == "torus"
        assert w["rotation_number"] == pytest.approx(1 - 1 / np.sqrt(2.0), abs=1e-6)
        assert (
            abs(w["exponent"]["exponent"]) + w["exponent"]["uncertainty"] <= w["exponent"]["delta"]
        )
        assert w["zero_one"]["K"] < 0.2  # regular (Gottwald and Melbourne)


def test_a_slowly_converging_period_two_is_not_quasi_periodic_nor_period_four():
    # Just past the period doubling (B = 0.266): the period-2 orbit attracts with a
    # multiplier near +1, so 100 sampled periods have not yet closed; the per-coordinate
    # reading of the window alone (the old verdict) does not say period-2.
    system = _twin_well(0.266)
    r = analyse_point(system, np.array([1.0, 0.0]), transient=50)
    old = classify_points(r.trajectory.poincare[[0, 1]], tol=1e-5)
    assert old.motion != "period-2"
    v = r.verdict
    assert v.motion == "period-2" and v.evidence["converging"]
    orbit = v.evidence["orbit"]
    assert orbit["minimal_period"] == 2 and 0.9 < orbit["largest_multiplier"] < 1.0
    # the multipliers against the independent shooting route (CasADi, AD monodromy)
    ref = shoot(system, np.array(r.settled.orbit.x), 2, t0=r.trajectory.t_final)
    mu = np.array([complex(*m) for m in orbit["multipliers"]])
    np.testing.assert_allclose(
        np.sort(np.abs(mu)), np.sort(np.abs(ref.floquet.multipliers)), atol=1e-5
    )


def test_orbit_check_agrees_with_the_independent_shooting_route():
    # Reference: shooting.shoot (CasADi flow, monodromy by automatic differentiation).
    system = System.load("reference_light", **{"lambda": 0.8})
    x0 = np.array([1.0, -1.0, 0.0, 0.0])
    ref = shoot(system, x0)
    check = check_orbit(system, ref.x0 + 1e-4, 1)
    assert check.attracting and check.minimal_period == 1
    assert np.max(np.abs(check.x - ref.x0)) < 1e-8
    np.testing.assert_allclose(
        np.sort_complex(check.multipliers), np.sort_complex(ref.floquet.multipliers), atol=1e-6
    )
    # a period-2 request converges to the same orbit and says its minimal period is 1
    assert check_orbit(system, ref.x0, 2).minimal_period == 1


@pytest.mark.slow
def test_a_chaotic_transient_is_reported_and_ends_on_the_periodic_orbit():
    # Twin-well Duffing inside the period-5 window that opens between B = 0.3415 and
    # 0.3418 (found by scanning; the window's saddle-node leaves long chaotic transients
    # just inside it): every start ends on the period-5 orbit, and a start whose first
    # window was chaotic is reported as a chaotic transient, with its length bounded.
    system = _twin_well(0.3417)
    rng = np.random.default_rng(1)
    verdicts = [
        analyse_point(system, rng.uniform(-1.5, 1.5, 2), transient=0, periods=100).verdict
        for _ in range(8)
    ]
    assert {v.motion for v in verdicts} == {"period-5"}
    transient = [v.evidence["transient_chaos"] for v in verdicts if "transient_chaos" in v.evidence]
    assert transient
    for t in transient:
        assert t["chaotic_until_at_least"] < t["periodic_by"]
        assert "chaotic transient" in t["text"]


def test_two_trajectory_exponent_against_the_closed_form_and_benettin():
    # Reference 1 (closed form): x'' + k x' + x = B cos(omega tau) has the exponent -k/2
    # for every solution.  Reference 2: Benettin's variational estimate on Ueda's
    # oscillator; the two intervals must overlap (no Jacobian in this one).
    linear = System.load(DUFFING, a=1.0, c=0.0, k=0.1, omega=1.3, B=0.5)
    pair = two_trajectory(linear, np.array([0.3, 0.0]), 400, upper=0.01)
    lo, hi = pair["interval"]
    assert lo <= -0.05 <= hi and hi - lo < 1e-3
    ueda = analyse_point(System.load(DUFFING), np.array([2.5, 0.0])).verdict
    last = ueda.evidence["windows"][-1]
    start = np.array(analyse_point(System.load(DUFFING), np.array([2.5, 0.0])).settled.x_final)
    pair = two_trajectory(System.load(DUFFING), start, 800, upper=last["exponent"]["interval"][1])
    a, b = pair["interval"]
    c, d = last["exponent"]["interval"]
    assert a > 0 and max(a, c) <= min(b, d)


def test_shooting_check_on_a_dead_zone_orbit_against_the_located_monodromy():
    # Reference: shooting.shoot on the dead zone, whose monodromy integrates the
    # variational equations with the kinks located (an independent route to the
    # central differences of the check).  At lambda = 0 the attractor is a period-6
    # orbit with a multiplier near 0.97 (slow convergence: the stated error matters).
    from gearsym.resolve import load

    system = load("reference-dead-zone").with_values(**{"lambda": 0.0})
    r = analyse_point(system)
    assert r.verdict.period is not None
    o = r.settled.orbit
    ref = shoot(system, o.x, r.verdict.period)
    np.testing.assert_allclose(
        np.sort(np.abs(o.multipliers)), np.sort(np.abs(ref.floquet.multipliers)), atol=1e-6
    )
