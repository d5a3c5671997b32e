"""The report of ``gearsym reproduce``: its tables, notes and mechanisms, on small inputs
with known answers."""

from __future__ import annotations

import math
import re

import pytest
from gearsym.studies.claims import NOT_A_CLAIM, NOT_TESTED, Found, runs_text
from gearsym.studies.long_runs import periods_run
from gearsym.studies.model_check import _dead, _force_rows, _g
from gearsym.studies.report import findings_table
from gearsym.studies.report_sensitivity import _period3_note, third_order_lines


class _Run:
    def __init__(self, n):
        self.verdict = {"periods_run": n}


def test_runs_text_joins_equal_neighbours():
    text = runs_text([0.0, 0.1, 0.2, 0.3], ["chaotic", "chaotic", "period-1", "period-1"])
    assert text == "chaotic on [0, 0.1]; period-1 on [0.2, 0.3]"


def test_periods_run_states_the_range_of_the_verdicts():
    assert periods_run([_Run(400), _Run(8000)]) == "run 400 to 8,000 periods"
    assert periods_run([_Run(132)]) == "run 132 periods"
    assert periods_run([]) == "no run"


def test_findings_table_has_both_models_a_reason_and_no_verdict_on_a_non_claim():
    study = {"a": "claim A", "b": "an observation"}
    agree = Found("x", True, "because", ("f.png",), [_Run(8000), _Run(8000)])
    poly = {"a": agree, "b": Found("y", NOT_A_CLAIM, "history", ("g.png",))}
    dead = {"a": Found("z", NOT_TESTED, "nothing to test", ("h.json",)), "b": poly["b"]}
    rows = findings_table(study, poly, dead)
    assert rows[0].startswith("| study | found with the polynomial | found with the dead zone")
    a, b = rows[2], rows[3]
    assert "polynomial: agrees; dead zone: not tested" in a
    assert "carried by 2 runs (run 8,000 periods)" in a
    assert "polynomial: because; dead zone: nothing to test" in a
    assert "`f.png`" in a and "`h.json`" in a
    assert "| not a claim of the study |" in b and "agrees" not in b
    assert not re.search(r"\bnan\b", "\n".join(rows))


def test_the_study_polynomial_vanishes_at_0_and_0770_and_the_dead_zone_on_the_gap():
    # the study's printed fit: g = 0.0017 x^7 - 0.0366 x^5 + 0.2833 x^3 - 0.1555 x
    coef = (-0.1555, 0.2833, -0.0366, 0.0017)
    assert _g(coef, 0.0) == 0.0
    assert abs(_g(coef, 0.770)) < 2e-3  # the printed coefficients are rounded
    assert _g(coef, 0.5) < 0 < _g(coef, 1.0)  # pulls back inside the gap, pushes beyond 0.77
    assert [_dead(x) for x in (-2.0, -1.0, 0.3, 1.0, 1.5)] == [-1.0, 0.0, 0.0, 0.0, 0.5]
    text = "\n".join(_force_rows(coef, (-0.7701, 0.0, 0.7701)))
    assert "-0.7701, +0.0000, +0.7701" in text and not re.search(r"\bnan\b", text)


def test_third_order_lines_against_the_lines_at_omega():
    omega = 0.5
    peaks = [
        {"frequency": omega / 3, "amplitude": 2e-3},
        {"frequency": 2 * omega / 3, "amplitude": 5e-3},
        {"frequency": omega, "amplitude": 0.1},
        {"frequency": 2 * omega, "amplitude": 0.05},
    ]
    lines = third_order_lines(peaks, omega)
    assert lines["third"] == 5e-3
    assert math.isclose(lines["below"][1], 20.0) and math.isclose(lines["below"][2], 10.0)
    assert third_order_lines(peaks[2:], omega)["below"][1] is None


def test_period3_note_no_longer_says_the_study_contradicts_itself():
    text = _period3_note({})
    assert "contradicts" not in text
    assert "cannot tell period-1 from period-3" in text


@pytest.mark.parametrize("lam, spurious", [(0.1, True), (0.8, False)])
def test_spurious_well_of_v_at_light_load(lam, spurious):
    """The polynomial's second stable root of g(v) = F on the unloaded side exists while
    |F| < F* = 0.0449 (force_sign.spurious_load_limit): at f1 = 0.1, for lambda < 0.449."""
    from gearsym.solver.system import System
    from gearsym.studies.mechanisms import _barrier

    system = System.load("reference_light").with_values(**{"lambda": lam})
    b = _barrier(system, "v")
    assert (b is not None) == spurious
    if spurious:
        barrier, well = b
        coef = [system.parameter(k) for k in ("g1", "g3", "g5", "g7")]
        F = system.module.static_mesh_force(system.p)[1]
        assert well > 0 > F  # the unloaded side
        assert abs(_g(coef, barrier) - F) < 1e-9  # a root of g(x) = F ...
        h = 1e-6  # ... where g falls: unstable, the top of the barrier
        assert _g(coef, barrier + h) < _g(coef, barrier - h)
    assert _barrier(System.load("reference_dead_zone"), "v") is None


def test_sensitivity_table_has_no_na_and_states_the_carrying_runs():
    from gearsym.studies.report_sensitivity import sensitivity_section
    from gearsym.studies.sensitivity import Sensitivity

    def row(case, reproduced, carriers):
        return Sensitivity(
            case,
            "te_amplitude_um",
            (5.0,),
            5.0,
            "µm",
            {5.0: ["chaotic"]},
            {5.0: float("nan")},
            reproduced,
            0,
            [],
            carriers=carriers,
        )

    heavy = row(
        "heavy",
        {"u period-3 at high λ": [], "v chaotic": [5.0]},
        {"v chaotic": (3, "run 8,000 periods")},
    )
    light = row("light", {"v chaotic": [5.0]}, {"v chaotic": (2, "run 8,000 periods")})
    text = sensitivity_section([heavy, light], {}, {"heavy": 0.5, "light": 0.1}, {})
    assert "not a claim at this load" in text
    assert "carried by 3 attractor runs (run 8,000 periods)" in text
    assert "n/a" not in text and not re.search(r"\bnan\b", text)
