"""Meshing state from the sign of the model's own backlash force.

References: closed-form shares of a sinusoid ``u = A sin t`` (time with ``u > a`` over a
period is ``arccos(a / A) / pi``); a static solution (``g(u) = F``: the dead zone's
``u = 1 + F``), integrated; the polynomial's spurious equilibrium against a direct solve
of the generated right-hand side (``scipy.optimize.fsolve``) and its Jacobian's
eigenvalues; Kahraman and Singh's regimes.
"""

import numpy as np
import pytest
from gearsym.derive.mesh.backlash import fit_dead_zone
from gearsym.solver.analysis import meshing_states as exported
from gearsym.solver.analysis.meshing import (
    GAP_LOADED_REGIMES,
    contract_regimes,
    meshing_regime,
    meshing_states,
)
from gearsym.solver.analysis.spectra import meshing_states as from_spectra
from gearsym.solver.contract import Contract, ForceSign, load_generated
from gearsym.solver.integrate import Trajectory, simulate
from gearsym.solver.system import System
from scipy.optimize import fsolve

K = 200_000  # samples over one period of the sinusoid: shares within 1 / K
QUIET = {f"{k}_{q}_{h}": 0.0 for k in ("kc", "ks") for q in "uv" for h in (1, 2, 3)}
QUIET |= {"E_u_1": 0.0, "E_v_1": 0.0}  # no stiffness variation, no transmission error


def _sinusoid(system, amplitude):
    """A Trajectory whose every coordinate is ``A sin(t + 0.1234)`` over one period."""
    t = np.arange(K) * (2 * np.pi / K)
    x = np.zeros((system.n, K))
    for c in system.coordinates:
        x[system.index(c)] = amplitude * np.sin(t + 0.1234)
    return Trajectory(
        system=system,
        method="closed form",
        rtol=0.0,
        atol=0.0,
        transient=0,
        periods=1,
        samples_per_period=K,
        t=t,
        x=x,
        x_final=x[:, -1],
        t_final=float(t[-1]),
        status="ok",
        message="",
        nfev=0,
        nsteps=0,
        wall_time=0.0,
    )


def test_meshing_states_moved_with_a_re_export():
    assert exported is from_spectra is meshing_states


def test_dead_zone_shares_of_a_sinusoid_are_the_closed_form():
    tr = _sinusoid(System.load("reference_dead_zone"), 2.0)
    share = np.arccos(1 / 2.0) / np.pi  # 1/3 beyond each edge
    for c in ("u", "v"):
        s = meshing_states(tr)[c]
        assert set(s) == {"forward", "separated", "backward"}  # unchanged for a dead zone
        assert s["forward"] == pytest.approx(share, abs=2 / K)
        assert s["backward"] == pytest.approx(share, abs=2 / K)
        assert s["separated"] == pytest.approx(1 - 2 * share, abs=2 / K)


def test_polynomial_never_separates_and_its_gap_share_is_named_apart():
    # g > 0 on (0.7701, inf) and (-0.7701, 0): half the period of an odd sinusoid;
    # inside the gap |u| < 1 (loaded throughout) 2 arcsin(1/A) / pi of it.
    tr = _sinusoid(System.load("reference_light"), 2.0)
    for c in ("u", "v"):
        s = meshing_states(tr)[c]
        assert s["separated"] == 0.0
        assert s["forward"] == pytest.approx(0.5, abs=2 / K)
        assert s["backward"] == pytest.approx(0.5, abs=2 / K)
        assert s["loaded_in_gap"] == pytest.approx(2 * np.arcsin(0.5) / np.pi, abs=2 / K)


def test_a_static_dead_zone_solution_is_in_contact_all_the_time():
    # Closed form: at rest g(u) = F (F = kappa^-1 f, static_mesh_force), u = 1 + F for a
    # forward load, u = -1 + F for a backward one; started there, the run stays there.
    system = System.load("reference_dead_zone", **QUIET)
    f = system.module.static_mesh_force(system.p)
    x0 = np.zeros(system.n)
    x0[system.index("u")] = 1 + f[0]
    x0[system.index("v")] = -1 + f[1]
    assert f[0] > 0 > f[1]
    tr = simulate(system, x0, method="RK45", transient=1, periods=4, samples_per_period=32)
    np.testing.assert_allclose(tr.coordinate("u"), 1 + f[0], atol=1e-9)
    s = meshing_states(tr)
    assert s["u"] == {"forward": 1.0, "separated": 0.0, "backward": 0.0}
    assert s["v"] == {"forward": 0.0, "separated": 0.0, "backward": 1.0}


def test_spurious_equilibrium_is_an_equilibrium_of_the_generated_model():
    # Light load: v's static force F_v ~ -0.012 lies within (-F*, 0): a stable equilibrium
    # at v ~ +0.72, on the unloaded side inside the gap, where g(v) < 0 still (backward).
    system = System.load("reference_light", **QUIET)
    f = system.module.static_mesh_force(system.p)
    fit = fit_dead_zone()
    assert 0 < -f[1] < fit.spurious_load_limit() < f[0]
    (spur,) = [e for e in fit.equilibria(f[1]) if e.spurious]
    (main_u,) = [e for e in fit.equilibria(f[0]) if e.stable]  # u: one equilibrium only
    x0 = np.zeros(system.n)
    x0[system.index("u")], x0[system.index("v")] = main_u.x, spur.x
    solved = fsolve(lambda x: system.rhs(0.0, x), x0 + 1e-3, xtol=1e-13)
    np.testing.assert_allclose(solved, x0, atol=1e-10)
    assert np.all(np.linalg.eigvals(system.jacobian(0.0, x0)).real < 0)  # stable
    tr = simulate(system, x0, method="RK45", transient=1, periods=4, samples_per_period=32)
    s = meshing_states(tr)["v"]
    assert s == {"forward": 0.0, "separated": 0.0, "backward": 1.0, "loaded_in_gap": 1.0}


def test_regimes_keep_kahraman_and_singh_for_the_dead_zone():
    # The same answers as before the move (tests/solver/test_atlas.py), edges -1 and 1.
    assert meshing_regime(1.1, 1.4, -1, 1) == "no impact"
    assert meshing_regime(0.7, 1.3, -1, 1) == "single-sided impact"
    assert meshing_regime(-1.5, 1.5, -1, 1) == "double-sided impact"
    assert meshing_regime(-0.5, 0.5, -1, 1) == "no contact"
    assert meshing_regime(np.nan, 0.5, -1, 1) == "undetermined"


def test_regimes_of_a_force_loaded_in_the_gap_say_what_the_force_does():
    z = 0.7701168086601865
    no, one, two, inside = GAP_LOADED_REGIMES
    assert meshing_regime(0.8, 1.4, -z, z, zero_between=False) == no == "no impact"
    assert meshing_regime(0.7, 1.3, -z, z, zero_between=False) == one
    assert meshing_regime(-1.5, 1.5, -z, z, zero_between=False) == two
    assert meshing_regime(-0.75, -0.7, -z, z, zero_between=False) == inside
    c = System.load("reference_light").contract
    xmin, xmax = np.array([0.78, -0.9, 0, 0]), np.array([1.2, 0.9, 0, 0])
    assert contract_regimes(c, xmin, xmax) == {"u": "no impact", "v": two}


def test_contract_reads_format_1_as_a_dead_zone_and_format_2_as_stated():
    module = load_generated("reference_light")
    new = Contract.of(module)
    assert new.force_sign["v"].zero_between is False
    assert new.force_sign["v"].edges == pytest.approx((-0.7701168, 0.7701168))

    class Old:  # the same module as format 1 wrote it: no force_sign
        NAME = "old"
        CONTRACT = {k: v for k, v in module.CONTRACT.items() if k != "force_sign"}
        CONTRACT["format"] = 1

    for f in module.CONTRACT["functions"]:
        setattr(Old, f, staticmethod(getattr(module, f)))
    old = Contract.of(Old)
    assert old.force_sign["u"] == ForceSign((-1.0, 1.0), (-1, 0, 1))
    Old.CONTRACT = dict(module.CONTRACT, format=2)
    del Old.CONTRACT["force_sign"]
    with pytest.raises(ValueError, match="lacks force_sign"):
        Contract.of(Old)
    Old.CONTRACT = dict(module.CONTRACT, format=3)
    with pytest.raises(ValueError, match="reads formats 1, 2"):
        Contract.of(Old)
    bad = dict(module.CONTRACT["force_sign"]["u"], zero_between=True)
    Old.CONTRACT = dict(module.CONTRACT, force_sign={"u": bad})
    with pytest.raises(ValueError, match="force_sign of u states"):
        Contract.of(Old)


def test_sign_of_a_table_at_and_between_its_zeros():
    s = ForceSign((-0.77, 0.0, 0.77), (-1, 1, -1, 1))
    u = np.array([-2.0, -0.77, -0.5, 0.0, 0.5, 0.77, 2.0])
    np.testing.assert_array_equal(s.sign(u), [-1, 0, 1, 0, -1, 0, 1])
    assert s.sign(0.5) == -1
