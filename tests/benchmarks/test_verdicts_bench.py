"""The verdict benchmark's own reference classifier (benchmarks/_verdicts_reference.py)
on named references, and its choice of cells; fast (one two-state model is integrated)."""

from pathlib import Path

import numpy as np
from gearsym.benchmarks._verdicts_reference import (
    QP_BAND,
    TAIL,
    closed_curve,
    reference_label,
    repeat_period,
    zero_one_K,
)
from gearsym.benchmarks._verdicts_report import markdown
from gearsym.benchmarks.verdicts import MAPS, pick, summarise
from gearsym.solver.system import System
from gearsym.studies.sensitivity import OPEN_SPREAD

DUFFING = Path(__file__).parents[1] / "solver" / "duffing_model.py"


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


def test_reference_reads_a_known_torus_as_quasi_periodic():
    # x'' + x = 0.5 cos(sqrt(2) tau) from a state off the forced solution: the free
    # oscillation (frequency 1) beside the forced one (sqrt 2) is a two-frequency torus;
    # the section at T = 2 pi / sqrt 2 is an ellipse rotated by frac(1 / sqrt 2) per
    # period, folded into (0, 1/2]: 1 - 1/sqrt(2) (closed form); the exponent is exactly 0
    # (undamped and linear).  The whole reference path runs: no repetition, the exponent
    # in the band, the closed-curve test with its rotation number.
    system = System.load(DUFFING, a=1.0, c=0.0, k=0.0, omega=np.sqrt(2.0), B=0.5)
    ref = reference_label(system, np.array([0.3, 0.0]))
    assert ref["label"] == "quasi-periodic"
    assert "periodic" not in ref  # no period-n candidate on a rotation number this irrational
    assert abs(ref["exponent"]["lambda"]) + ref["exponent"]["uncertainty"] <= QP_BAND
    curve = ref["curve"]
    assert curve["is_curve"] and curve["agreeing"] >= 0.98
    # the rank shift s is an integer out of TAIL points: exact to within 1/TAIL
    assert abs(curve["rotation_number"] - (1 - 1 / np.sqrt(2.0))) <= 1.0 / TAIL


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


def test_maps_are_over_the_sensitivity_study_open_values():
    # every open value a map sets is one the sensitivity study tries (a reading aside)
    for row in MAPS:
        assert 0.0 <= row.lam[0] < row.lam[1] <= 1.0 and len(row.f1) >= 3
        for key, value in row.open_values.items():
            if key != "load_reading":
                assert value in OPEN_SPREAD[key][0], (row.name, key, value)


def test_a_wrong_label_is_listed_with_both_verdicts_evidence():
    cell = {
        "map": "m",
        "lambda": 0.1,
        "f1": 0.3,
        "start": "forward",
        "border": True,
        "default": {"motion": "period-2", "periods_run": 400, "largest_multiplier": 0.91},
        "reference": {"label": "chaotic", "exponent": {"lambda": 0.02, "uncertainty": 0.001}},
    }
    s = summarise([cell])
    s["maps"] = {"m": {"lambda": [0.0, 0.25], "f1": [0.1, 0.3], "why": "w"}}
    s["maps"]["m"] |= {"candidates": 3, "cells": 1, "seconds": 1.0}
    s["cost"] = dict.fromkeys(
        ("maps_seconds", "reference_seconds", "reference_median_seconds"), 1.0
    ) | {"reference_max_seconds": 1.0, "workers": 2}
    s["engine"] = "abc1234"
    s["candidates"] = {"count": 3, "labels": {"period-2": 3}, "undetermined": []}
    row = [line for line in markdown(s, [cell], "cmd", 60.0).splitlines() if "**wrong**" in line]
    assert len(row) == 1
    # the bars of |μ| escaped, so the table keeps its columns
    assert "period-2 (400)" in row[0] and "\\|μ\\| 0.9100" in row[0] and "λ 2.00e-02" in row[0]
    assert row[0].replace("\\|", "").count("|") == 9
