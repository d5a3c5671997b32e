"""The reproduce report's sensitivity section (issue 12, point 6)."""

import math

import numpy as np
import pytest
from gearsym.solver.periodic.records import Bifurcation
from gearsym.studies.report_sensitivity import sensitivity_section
from gearsym.studies.sensitivity import OPEN_SPREAD, Sensitivity, _critical, _matches, _named


def _rec(lam, value, v, status="ok"):
    return {"lambda": lam, "k": value, "status": status, "motion": {"u": "period-1", "v": v}}


def test_critical_lambda_is_where_every_attractor_of_v_stays_periodic():
    lam = np.array([0.0, 0.5, 1.0])
    records = [
        _rec(0.0, 1, "chaotic"),
        _rec(0.5, 1, "period-1"),
        _rec(0.5, 1, "quasi-periodic"),  # a coexisting non-periodic attractor
        _rec(1.0, 1, "period-1"),
        _rec(0.0, 2, "period-1"),
        _rec(0.5, 2, "period-1"),
        _rec(1.0, 2, "period-3"),
        _rec(1.0, 2, "undetermined", status="left the valid range"),  # not an attractor
        _rec(1.0, 3, "chaotic"),
    ]
    assert _critical(records, lam, 1, "k") == 1.0
    assert _critical(records, lam, 2, "k") == 0.0
    assert math.isnan(_critical(records, lam, 3, "k"))


def test_period_3_means_the_minimal_period_three():
    assert _matches("period-3", "period-3")
    assert not _matches("period-30", "period-3")
    assert _matches("quasi-periodic", "quasi")


def test_stated_values_are_among_those_tried():
    for values, stated, _ in OPEN_SPREAD.values():
        assert stated in values


def test_section_states_every_finding_and_marks_the_stated_value():
    row = Sensitivity(
        case="heavy",
        key="te_amplitude_um",
        values=(5.0, 50.0),
        stated=5.0,
        unit="µm",
        motions={5.0: ["period-1"], 50.0: ["period-1", "period-2"]},
        critical={5.0: 0.0, 50.0: float("nan")},
        reproduced={"u period-3 at high λ": [], "v chaotic at low λ": [50.0]},
        failed=2,
        figures=[],
    )
    scales = {"u": {"k_m_N_per_m": 1e9, "b_um": 50.0, "force_N": 5e4}}
    text = sensitivity_section([row], scales, {"heavy": 0.5}, {})
    assert "| heavy (f1 = 0.5) | q braking | `te_amplitude_um` (µm) | 5*, 50 |" in text
    assert "5: 0; 50: none" in text
    assert "*u period-3 at high λ*: **no value tried reproduces it.**" in text
    assert "*v chaotic at low λ*: reproduced with `te_amplitude_um` = 50 (q braking)." in text
    assert "2 runs failed" in text
    assert "| u | 1e+09 | 50 | 5e+04 | 1000 | 2.5e+04 |" in text
    assert "multiples of ω̄/3" in text


def test_text_values_are_named_in_records_and_table():
    values = ("mesh", "modal")
    records = [{"lambda": 0.0, "damping_normalisation": 1.0, "status": "ok"}]
    assert _named(records, "damping_normalisation", values)[0]["damping_normalisation"] == "modal"
    assert _named(records, "k", (1.0, 2.0)) is records  # numeric axes are left alone
    row = Sensitivity(
        case="light",
        key="damping_normalisation",
        values=values,
        stated="mesh",
        unit="text",
        motions={"mesh": ["period-1"], "modal": ["chaotic"]},
        critical={"mesh": 0.0, "modal": 0.4},
        reproduced={"v chaotic at low λ": ["modal"]},
        failed=0,
        figures=[],
        reading="both-driving",
    )
    text = sensitivity_section([row], {}, {"light": 0.1}, {})
    assert "| light (f1 = 0.1) | both driving | `damping_normalisation` | mesh*, modal |" in text
    assert "mesh: 0; modal: 0.4" in text
    assert "reproduced with `damping_normalisation` = modal (both driving)." in text


def test_response_section_counts_the_solutions_at_the_operating_frequency():
    from types import SimpleNamespace

    from gearsym.studies.response import _at, response_section

    # a curve that folds back over omega = 0.5: three crossings, the middle one unstable
    values = np.array([0.4, 0.6, 0.45, 0.7])
    amp = np.array([0.1, 0.2, 0.3, 0.4])
    curve = SimpleNamespace(
        values=values,
        stable=np.array([True, False, False, True]),
        stats={"u": {"amplitude": amp, "mean": amp * 0}},
        events=(
            Bifurcation("fold", 0.6, np.zeros(2), parameter="omega", index=2),
            Bifurcation("fold", 0.45, np.zeros(2), parameter="omega", index=4),
        ),
    )
    sols = _at(curve, 0.5, ("u",))
    assert len(sols) == 3
    assert [s["stable"] for s in sols] == [False, False, False]  # each spans a change
    assert sols[0]["amplitude"]["u"] == pytest.approx(0.15)
    row = SimpleNamespace(
        case="light",
        f1=0.1,
        lam=0.8,
        at_omega=sols,
        attractor=None,
        resp=SimpleNamespace(system=SimpleNamespace(coordinates=("u",)), curves=[curve]),
    )
    text = response_section([row])
    assert "| light (f1 = 0.1) | 0.8 | 0.6000, 0.4500 | 3: " in text
    assert "not simulated" in text
