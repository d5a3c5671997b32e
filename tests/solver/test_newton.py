"""The one Newton solver: a trial step whose evaluation fails is a shorter step's cue."""

import numpy as np
import pytest
from gearsym.solver.periodic.newton import NewtonError, newton


def _arctan(limit: float):
    """F(z) = arctan(z - 3), whose root is 3 (the closed form): from z = 5 the full
    Newton step overshoots to z = -0.53, where this stand-in for a flow fails (a run that
    stops) as an integration does, with RuntimeError."""

    def fun(z):
        if z[0] < limit:
            raise RuntimeError(f"the flow stopped: too many steps at z = {z[0]:.3g}")
        return np.arctan(z - 3.0), np.array([[1.0 / (1.0 + (z[0] - 3.0) ** 2)]]), None

    return fun


def test_a_failed_trial_is_no_decrease_and_the_step_is_halved():
    res = newton(_arctan(0.0), [5.0], tol=1e-13, max_iter=30)
    assert res.z[0] == pytest.approx(3.0, abs=1e-12)


def test_without_damping_a_failed_step_is_a_newton_error_that_says_why():
    with pytest.raises(NewtonError, match="evaluation failed: the flow stopped"):
        newton(_arctan(0.0), [5.0], tol=1e-13, max_iter=30, damped=False)


def test_a_line_search_that_only_meets_failures_says_the_last_one():
    with pytest.raises(NewtonError, match="shortest step's evaluation failed"):
        newton(_arctan(4.99999), [5.0], tol=1e-13, max_iter=30)
