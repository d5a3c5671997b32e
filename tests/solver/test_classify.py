"""Motion classification against systems whose motion is known."""

import numpy as np
from gearsym.solver.analysis import analyse_point, classify_points, correlation_dimension
from gearsym.solver.system import System


def test_period_one_response_gives_one_poincare_cluster():
    system = System.load("reference_light", **{"lambda": 0.8})
    result = analyse_point(system, method="cvodes", transient=200, periods=64, lyapunov_periods=100)
    for c in ("u", "v"):
        assert result.classification[c].motion == "period-1"
        points = result.trajectory.poincare[[system.index(c), system.index("d" + c)]]
        assert np.ptp(points, axis=1).max() < 1e-5  # one cluster
    assert result.record().lyapunov["exponent"] < 0  # from the orbit's multipliers


def test_two_frequency_signal_is_quasi_periodic():
    # x(t) = cos t + 0.5 cos(sqrt(2) t), sampled at t = 2 pi k: the points lie on a closed
    # curve (a torus section), never repeating.
    k = np.arange(400)
    t = 2 * np.pi * k
    w = np.sqrt(2.0)
    points = np.vstack([np.cos(t) + 0.5 * np.cos(w * t), -np.sin(t) - 0.5 * w * np.sin(w * t)])
    verdict = classify_points(points, tol=1e-6)
    assert verdict.motion == "quasi-periodic", verdict.evidence
    assert 0.8 < correlation_dimension(points) < 1.2


def test_period_three_sequence_is_found():
    base = np.array([[0.1, 0.5, -0.3], [1.0, 0.2, 0.7]])
    points = np.tile(base, 20)
    assert classify_points(points, tol=1e-9).motion == "period-3"


def test_ueda_duffing_is_chaotic_with_a_positive_exponent(duffing):
    # Ueda (1979): x'' + 0.05 x' + x^3 = 7.5 cos t is chaotic.
    result = analyse_point(
        duffing,
        np.array([3.0, 4.0]),
        method="cvodes",
        transient=100,
        periods=200,
        lyapunov_periods=300,
    )
    assert result.lyapunov.exponent > 0.05
    assert result.classification["x"].motion == "chaotic", result.classification["x"].evidence


def test_a_period_above_32_is_not_called_quasi_periodic():
    rng = np.random.default_rng(0)
    points = np.tile(rng.standard_normal((2, 40)), 3)[:, :100]  # period 40
    verdict = classify_points(points, tol=1e-6)
    assert verdict.motion == "undetermined" and "finite set of 40 points" in verdict.evidence["why"]


def test_henon_points_are_not_a_torus():
    # Henon's map x' = 1 - 1.4 x^2 + y, y' = 0.3 x: a strange attractor of correlation
    # dimension about 1.21 (Grassberger and Procaccia 1983).
    x, y, points = 0.1, 0.1, []
    for k in range(500):
        x, y = 1 - 1.4 * x * x + y, 0.3 * x
        if k >= 100:
            points.append((x, y))
    verdict = classify_points(np.array(points).T, tol=1e-6)
    assert verdict.motion == "chaotic", verdict.evidence


def test_correlation_dimension_is_bounded_on_long_runs():
    # Closed forms: a circle has dimension 1, a filled square 2.  50,000 points would need
    # 40 GB for all pair distances; the estimate takes at most DIMENSION_SAMPLE_MAX of
    # them, evenly spread, so memory stays bounded (numpy allocations are traced).
    import tracemalloc

    import numpy as np
    from gearsym.solver.analysis.classify import correlation_dimension, distinct_points

    rng = np.random.default_rng(0)
    t = rng.uniform(0, 2 * np.pi, 50_000)
    tracemalloc.start()
    circle = correlation_dimension(np.vstack([np.cos(t), np.sin(t)]))
    square = correlation_dimension(rng.uniform(size=(2, 50_000)))
    clusters = distinct_points(rng.uniform(size=(2, 50_000)), 1e-6)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert abs(circle - 1.0) < 0.05 and abs(square - 2.0) < 0.2
    assert clusters == 1001  # a cloud: more clusters than half the window of 2,000
    assert peak < 200e6
