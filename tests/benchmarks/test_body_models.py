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
        {"full": 36.0, "csv": 20.0, "mb": {"json": 42.4, "mat": 8.2}},
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
    assert "run 0.57 s, the shooting check of its end state 0.59 s (its monodromy" in text
