"""The body-model benchmark's page (benchmarks/body_models.py) on made-up runs: floors
judged as stated, every row written."""

from __future__ import annotations

from gearsym.benchmarks.body_models import page


def test_the_page_judges_the_floors_and_lists_every_row():
    rows = [
        {
            "model": "m",
            "coordinates": 2,
            "states": 4,
            "ms_per_point": 10.0,
            "ms_per_point_coordinate": 5.0,
            "nfev_per_point": 1e5,
        }
    ]
    text = page(
        {"a": 7.7, "b": 61.0},
        {
            "full": 36.0,
            "csv": 20.0,
            "loose": 19.5,
            "mb": {"json": 42.4, "mat": 8.2},
            "agree": {
                "points": 400,
                "verdicts_differ": 0,
                "sweep.csv": (6.3e-7, "min_eta_2", "3482.5"),
                "sweep_poincare.csv": (0.0, None, None),
                "orbits": 400,
                "multiplier": 1.6e-13,
            },
        },
        {"run": 0.57, "check": 0.59},
        rows,
        "today",
        "here",
    )
    assert "`a` | 7.7 | 60 | met |" in text
    assert "`b` | 61.0 | 60 | not met |" in text
    assert "JSON + CSV + MAT | 36.0 | 20 | not met |" in text
    assert "| m | 2 | 4 | 10.0 | 5.00 | 100000 |" in text
    assert "42 MB of JSON, 8 MB of MAT" in text
    assert "`--transient-rtol 1e-6` | 19.5 | 20 | met |" in text
    assert "verdicts differ at 0 of 400 points" in text
    assert "sweep.csv 6.3e-07 (min_eta_2 at 3482.5 Hz), of any Poincaré point 0.0e+00," in text
    assert "at 400 points, whose orbits' largest Floquet multipliers agree to 1.6e-13" in text
    assert "run 0.57 s, the shooting check of its end state 0.59 s (its monodromy" in text
