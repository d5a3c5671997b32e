"""The reproduce timing benchmark's page (benchmarks/reproduce_time.py) on made-up runs:
medians per run and per stage, and the floors of issue 25 (point 7: full reproduce at most
90 s first, 30 s repeated)."""

from gearsym.benchmarks.reproduce_time import table


def _run(seconds, stages):
    return {
        "seconds": seconds,
        "stages": [("sweeps (points)", stages[0]), ("report (sections)", stages[1])],
        "verdicts": {"polynomial": {"agrees": 4, "differs": 1}},
    }


def test_medians_and_floors():
    full = {
        "first": [_run(100.0, (60.0, 5.0)), _run(80.0, (50.0, 4.0)), _run(85.0, (55.0, 3.0))],
        "repeated": [_run(31.0, (20.0, 1.0)), _run(29.0, (18.0, 1.0)), _run(40.0, (25.0, 2.0))],
    }
    page = table({"full": full}, "2026-11-25", "2 cores")
    # medians by hand: first 85 (of 80, 85, 100), repeated 31 (of 29, 31, 40)
    assert "| `gearsym reproduce` | 3 | 85.0 | 31.0 | 90 s / 30 s: met / not met |" in page
    # stage medians: sweeps first 55 (50, 55, 60), repeated 20 (18, 20, 25)
    assert "| sweeps (points) | 55.0 | 20.0 |" in page
    assert "| report (sections) | 4.0 | 1.0 |" in page
    assert "polynomial: 4 agree, 1 differ" in page


def test_quick_has_no_floor():
    runs = {"first": [_run(50.0, (30.0, 2.0))], "repeated": [_run(20.0, (10.0, 1.0))]}
    page = table({"quick": runs}, "2026-11-25", "2 cores")
    assert "| `gearsym reproduce --quick` | 1 | 50.0 | 20.0 | — |" in page
