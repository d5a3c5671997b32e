"""The verdict benchmark's own reference classifier (benchmarks/_verdicts_reference.py)
on named references, and its choice of cells; fast (no model is integrated)."""

import numpy as np
from gearsym.benchmarks._verdicts_reference import closed_curve, repeat_period, zero_one_K
from gearsym.benchmarks.verdicts import pick, summarise


def _logistic(r: float, n: int = 5000) -> np.ndarray:
    x, out = 0.3, np.empty(n)
    for _ in range(1000):
        x = r * x * (1 - x)
    for k in range(n):
        x = r * x * (1 - x)
        out[k] = x
    return out


def test_zero_one_reads_the_logistic_map():
    # Gottwald and Melbourne (2009): K near 1 for r = 4 (chaotic), near 0 for r = 3.55
    # (period 8) and for a quasi-periodic signal (golden-mean rotation)
    assert zero_one_K(_logistic(4.0)) > 0.95
    assert abs(zero_one_K(_logistic(3.55))) < 0.05
    theta = 2 * np.pi * (np.sqrt(5) - 1) / 2 * np.arange(5000)
    assert abs(zero_one_K(np.cos(theta) + 0.3 * np.cos(2 * theta + 1))) < 0.05


def test_closed_curve_finds_a_rotation_and_rejects_chaos():
    rho = (np.sqrt(5) - 1) / 2
    th = 2 * np.pi * rho * np.arange(5000)
    torus = np.c_[np.cos(th) + 0.2 * np.cos(2 * th), np.sin(th), 0.5 * np.cos(th + 0.3)]
    found = closed_curve(torus)
    assert found["is_curve"]
    assert abs(found["rotation_number"] - min(rho, 1 - rho)) < 1e-3
    x, y, henon = 0.1, 0.1, []
    for k in range(6000):
        x, y = 1 - 1.4 * x * x + y, 0.3 * x
        if k >= 1000:
            henon.append((x, y))
    assert not closed_curve(np.array(henon))["is_curve"]


def test_repeat_period_is_the_smallest():
    pts = np.tile(np.array([[0.0, 1.0], [1.0, 0.0], [0.5, 0.5]]), (600, 1))
    assert repeat_period(pts, 1e-9)[0] == 3
    assert repeat_period(np.random.default_rng(0).random((2000, 2)), 1e-9)[0] is None


def test_cells_borders_first_and_wrong_labels_counted():
    cells = [
        {"map": m, "lambda": k / 10, "f1": 0.1, "border": k % 4 == 0, "default": {}}
        for m in ("a", "b")
        for k in range(10)
    ]
    chosen = pick(cells, 10)
    assert len(chosen) == 10
    assert sum(c["border"] for c in chosen) == 6  # all six border cells fit in 60 %
    labelled = [
        {"border": False, "default": {"motion": d, "periods_run": 400}, "reference": {"label": r}}
        for d, r in (
            ("period-1", "period-1"),
            ("period-2", "period-1"),
            ("undetermined", "chaotic"),
            ("chaotic", "unresolved"),
        )
    ]
    s = summarise(labelled)
    assert (s["wrong"], s["undetermined"], s["unresolved_references"]) == (1, 1, 1)
    assert s["confusion"]["period-1"] == {"period-1": 1, "period-2": 1}
