"""The engines that exist once: tableaux, the method registry, the contract, Newton, the
stroboscopic map and the continuation's single flow map."""

import math

import numpy as np
import pytest
from gearsym.solver.contract import Contract
from gearsym.solver.integrate.methods import METHODS, Method, get_method
from gearsym.solver.integrate.tableau import DOP853, DOPRI5, RK4, ButcherTableau, rk_step
from gearsym.solver.periodic import (
    NewtonError,
    StroboscopicMap,
    continue_orbit,
    newton,
    shoot,
)
from gearsym.solver.system import System


@pytest.mark.parametrize("tab", [RK4, DOPRI5, DOP853], ids=lambda t: t.name)
def test_shipped_tableaux_satisfy_the_consistency_conditions(tab):
    # Row sums of A equal c, weights sum to 1 (checked on construction); the first-order
    # conditions hold to rounding: sum b = 1, sum b c = 1/2 (Butcher 2008, "Numerical
    # Methods for ODEs", 2nd ed., table 231(I)).
    assert abs(tab.b.sum() - 1) < 1e-14
    assert abs(tab.b @ tab.c - 0.5) < 1e-14


def test_a_tableau_that_breaks_a_condition_is_refused():
    with pytest.raises(ValueError, match="rows of A must sum to c"):
        ButcherTableau("bad", 2, A=[[0, 0], [0.4, 0]], b=[0.5, 0.5], c=[0, 0.5])
    with pytest.raises(ValueError, match="weights b must sum to 1"):
        ButcherTableau("bad", 2, A=[[0, 0], [0.5, 0]], b=[0.5, 0.4], c=[0, 0.5])
    with pytest.raises(ValueError, match="explicit"):
        ButcherTableau("bad", 2, A=[[0, 0.1], [0.5, 0]], b=[0.5, 0.5], c=[0.1, 0.5])


@pytest.mark.parametrize("tab", [RK4, DOPRI5, DOP853], ids=lambda t: t.name)
def test_generic_step_converges_at_the_tableau_order(tab):
    # y' = y cos t, y(0) = 1: exact y = exp(sin t). Halving the step divides the error of
    # the propagated solution by 2^order (observed order within 0.3 of the theory).
    def f(t, y):
        return y * np.cos(t)

    def error(steps):
        h, y = 2.0 / steps, np.array([1.0])
        for k in range(steps):
            y = rk_step(tab, f, k * h, y, h)
        return abs(y[0] - math.exp(math.sin(2.0)))

    coarse = 8 if tab.order < 8 else 4
    slope = math.log2(error(coarse) / error(2 * coarse))
    assert abs(slope - tab.order) < 0.3, slope


def test_the_registry_is_validated_and_names_the_valid_methods():
    assert METHODS[0] == "RK45" and len(set(METHODS)) == len(METHODS)
    assert get_method("collocation").step_unit == 4 and not get_method("cvodes").step_unit
    assert get_method("RK45").locates_surfaces and not get_method("dop853").locates_surfaces
    with pytest.raises(ValueError, match="unknown method 'rk45'; methods: RK45, scipy-dop853"):
        get_method("rk45")
    with pytest.raises(ValueError, match="step unit goes with fixed-step methods only"):
        Method("x", "scipy", adaptive=True, order=4, step_unit=1)


def test_an_inconsistent_contract_is_refused_with_what_is_wrong(duffing):
    class Fake:
        NAME = "fake"
        CONTRACT = dict(duffing.module.CONTRACT, velocities={"x": 7}, loads={"x": "f_x"})

    with pytest.raises(ValueError, match="velocity index outside the state.*load that is not"):
        Contract.of(Fake)
    Fake.CONTRACT = dict(duffing.module.CONTRACT, contact={"x": (1.0, -1.0)}, valid_range={"y": 3})
    with pytest.raises(ValueError, match="valid names something.*lower > upper"):
        Contract.of(Fake)
    Fake.CONTRACT = dict(duffing.module.CONTRACT, format=0)
    with pytest.raises(ValueError, match="regenerate it with `gearsym derive`"):
        Contract.of(Fake)


def test_newton_solves_a_known_system_and_reports_failure_as_a_value_with_history():
    # x^2 + y^2 = 4, x = y: the root (sqrt 2, sqrt 2) (closed form).
    def fun(z):
        x, y = z
        return np.array([x * x + y * y - 4, x - y]), np.array([[2 * x, 2 * y], [1, -1]]), None

    found = newton(fun, [3.0, 1.0], tol=1e-13, max_iter=20)
    np.testing.assert_allclose(found.z, [math.sqrt(2)] * 2, rtol=1e-13)
    assert found.history[0] > found.history[-1] and found.steps == len(found.history) - 1
    with pytest.raises(NewtonError, match="singular") as err:
        newton(lambda z: (z * 0 + 1, np.zeros((2, 2)), None), [1.0, 1.0], tol=1e-9, max_iter=5)
    assert err.value.history == [1.0]


def test_the_stroboscopic_map_has_the_orbit_as_fixed_point_and_monodromy_as_jacobian():
    system = System.load("reference_light", **{"lambda": 0.8})
    orbit = shoot(system, [1.0, -1.0, 0.0, 0.0])
    smap = StroboscopicMap(system)
    assert np.max(np.abs(smap(orbit.x0) - orbit.x0)) < 1e-9
    _, M, _ = smap.jacobian(orbit.x0)
    np.testing.assert_allclose(M, orbit.monodromy, atol=1e-9)
    np.testing.assert_allclose(smap.iterate(orbit.x0, 3)[-1], orbit.x0, atol=1e-8)
    # another omega through p alone: the period follows p (T = 2 pi / omega)
    p = system.parameters_with(omega=0.25)
    assert smap.period(p) == pytest.approx(2 * math.pi / 0.25)


def test_continuation_builds_one_flow_map_for_the_whole_branch(monkeypatch):
    from gearsym.solver.periodic import flow as flow_module

    built = []
    original = flow_module.FlowMap.__post_init__

    def counting(self):
        built.append(self)
        original(self)

    monkeypatch.setattr(flow_module.FlowMap, "__post_init__", counting)
    system = System.load("reference_light")
    x0 = shoot(system.with_values(**{"lambda": 0.8}), [1.0, -1.0, 0.0, 0.0]).x0
    built.clear()
    branch = continue_orbit(system, "lambda", 0.8, 1.0, x0, ds=0.05, ds_max=0.2)
    assert len(branch.values) > 3 and len(built) == 1


def test_a_period_one_orbit_shot_as_period_three_says_its_smallest_period():
    # Reference: the period-1 orbit at lambda = 0.8 (shot with n = 1) is a fixed point of
    # the three-period map too; shooting with n = 3 finds it and must not call it period-3.
    system = System.load("reference_light", **{"lambda": 0.8})
    one = shoot(system, [1.0, -1.0, 0.0, 0.0])
    three = shoot(system, one.x0, 3)
    np.testing.assert_allclose(three.x0, one.x0, atol=1e-8)
    assert three.smallest_period() == 1 and one.smallest_period() == 1
