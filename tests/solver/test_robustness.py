"""The extremes matrix and the validity guard (docs/robustness.md lists the outcomes)."""

import numpy as np
import pytest
from gearsym.solver.integrate import METHODS, simulate
from gearsym.solver.system import System
from gearsym.studies.robustness import CASES, harmonics_models, run_case


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    return harmonics_models(tmp_path_factory.mktemp("harmonics"))


@pytest.mark.slow
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("case", CASES, ids=[c.label for c in CASES])
def test_every_backend_gives_a_result_or_a_clear_failure(case, method, models):
    outcome = run_case(case, method, models)
    assert outcome["status"] in ("ok", "divergent", "invalid", "failed")
    if outcome["status"] == "ok":
        assert outcome["finite"], outcome
    else:
        assert outcome["message"], outcome


@pytest.mark.parametrize("method", ["RK45", "cvodes"])
def test_leaving_the_polynomial_range_is_reported_with_time_coordinate_value(method):
    system = System.load("reference_light", f1=2.0)  # static u above 3, the fit's range
    warned = simulate(system, method=method, transient=4, periods=2)
    assert warned.status == "ok"
    t, c, v = warned.left_valid_range
    assert c == "u" and abs(v) > 3.0 and t >= 0
    stopped = simulate(system, method=method, transient=4, periods=2, on_invalid="error")
    assert stopped.status == "invalid"
    assert "outside the backlash model's valid range |u| <= 3" in stopped.message
    assert np.all(np.isnan(stopped.x[:, stopped.t > t]))  # nothing meaningless is kept


def test_a_run_that_stays_in_range_is_not_flagged():
    tr = simulate(
        System.load("reference_light"), method="cvodes", transient=20, periods=2, on_invalid="error"
    )
    assert tr.status == "ok" and tr.left_valid_range is None
