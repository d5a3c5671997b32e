"""What ``gearsym reproduce`` says at its end (issue 25, point 7): the verdicts of the
study's findings counted per model as the findings table grades them, the time, and
where the report and figures are."""

from pathlib import Path

from gearsym.studies.claims import NOT_A_CLAIM, NOT_TESTED, Found
from gearsym.studies.report import tally
from gearsym.studies.reproduce import Reproduced


def _found(*grades):
    return {f"claim {k}": Found("shown", g, "why") for k, g in enumerate(grades)}


def test_tally_counts_the_table_verdicts_and_skips_non_claims():
    found = {
        "polynomial": _found(True, True, None, False, NOT_A_CLAIM, NOT_TESTED),
        "dead zone": _found(True, False, False, NOT_A_CLAIM),
    }
    # by hand from the grades above (True agrees, None partly, False differs)
    assert tally(found) == {
        "polynomial": {"agrees": 2, "partly": 1, "differs": 1, "not tested": 1},
        "dead zone": {"agrees": 1, "differs": 2},
    }


def test_summary_names_the_verdicts_the_time_and_the_files():
    done = Reproduced(
        Path("out/report.md"),
        {"polynomial": {"agrees": 2, "differs": 1}},
        125.0,
        (("sweeps (points)", 100.0),),
    )
    lines = done.summary().splitlines()
    assert lines[0] == "findings of the study, polynomial: 2 agree, 1 differ"
    assert lines[1] == "time: 2 min 05 s"
    assert lines[2] == "report: out/report.md"
    assert lines[3].startswith("figures: out/*.png")
