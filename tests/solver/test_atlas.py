"""Regime maps (solver/sweep/atlas.py): boundaries, coexisting attractors, the store.

References: the period-doubling point of the twin-well Duffing oscillator located
independently by Newton shooting and its Floquet multiplier (CasADi monodromy, not the map
engine); the hysteresis band of the hardening Duffing oscillator from the first-order
harmonic balance (Nayfeh and Mook 1979, "Nonlinear Oscillations", section 4.1.2); the
per-point Benettin exponent of analysis/lyapunov.py.
"""

import json

import numpy as np
import pytest
from gearsym.solver.analysis import largest_lyapunov
from gearsym.solver.analysis.lyapunov import uncertainty
from gearsym.solver.integrate.native import run_batch
from gearsym.solver.integrate.run import Batch, integrate
from gearsym.solver.integrate.spec import RunSpec
from gearsym.solver.periodic import shoot
from gearsym.solver.sweep.atlas import regime_map
from gearsym.solver.sweep.attractors import meshing_regime
from gearsym.solver.sweep.maps_result import RegimeMap
from gearsym.solver.sweep.store import stored_count
from gearsym.solver.system import System
from scipy.optimize import brentq

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")


@pytest.fixture(scope="module")
def reference_light_system():
    return System.load("reference_light")


def test_meshing_regimes_follow_kahraman_and_singh():
    # contact beyond the edges -1 and 1 (half backlash 1)
    assert meshing_regime(1.1, 1.4, -1, 1) == "no impact"  # always in forward contact
    assert meshing_regime(-1.6, -1.3, -1, 1) == "no impact"  # always in backward contact
    assert meshing_regime(0.7, 1.3, -1, 1) == "single-sided impact"
    assert meshing_regime(-1.3, -0.2, -1, 1) == "single-sided impact"
    assert meshing_regime(-1.5, 1.5, -1, 1) == "double-sided impact"
    assert meshing_regime(-0.5, 0.5, -1, 1) == "no contact"


def test_map_engine_agrees_with_sampled_runs(reference_light_system):
    """Poincare points of the map engine equal run_batch's within the tolerance (the stops
    every period change the step sequence, not the solution), extremes bound them."""
    s = reference_light_system
    lam = np.linspace(0.0, 1.0, 6)
    P = np.array([s.parameters_with(**{"lambda": v}) for v in lam])
    X0 = np.tile([1.0, 0.0, 0.0, 0.0], (6, 1))
    ref = run_batch(s.module, P, X0, transient=150, periods=20)
    spec = RunSpec(transient=150, periods=20, collect=("samples", "extremes"), valid_range="stop")
    got = integrate(Batch.of(s.module, P), X0, spec)
    assert got.status == ("ok",) * 6
    assert np.max(np.abs(got.x - ref.x)) < 1e-6
    assert np.all(got.xmax >= ref.x.max(axis=1) - 1e-6)
    assert np.all(got.xmin <= ref.x.min(axis=1) + 1e-6)


def test_map_exponent_agrees_with_per_point_benettin(reference_light_system):
    s = reference_light_system.with_values(**{"lambda": 0.3})
    spec = RunSpec(collect=("samples", "exponent"), lyapunov_periods=200, valid_range="stop")
    res = integrate(s, np.array([1.0, 0, 0, 0]), spec)
    running = res.exponent[0]
    ref = largest_lyapunov(s, res.x[0, -1], t0=0.0, periods=400)
    bound = uncertainty(running, s.period)["uncertainty"] + ref.uncertainty
    assert abs(running[-1] - ref.exponent) <= bound


def _twin_well(duffing, k):
    return duffing.with_values(a=-1.0, c=1.0, k=k, omega=1.2, B=0.2)


def _period_doubling(system, x0) -> float:
    """B where the period-1 orbit's multiplier passes -1 (shooting, brentq)."""
    guess = {"x": np.asarray(x0, float)}

    def f(B):
        orbit = shoot(system.with_values(B=B), guess["x"], 1)
        guess["x"] = orbit.x0
        mu = orbit.floquet.multipliers
        real = mu[np.abs(mu.imag) < 1e-9].real
        return float(real.min()) + 1.0 if real.size else 1.0

    grid = np.arange(0.20, 0.30, 0.005)  # follow the orbit up from B = 0.2
    values = [f(B) for B in grid]
    k = next(i for i in range(len(grid) - 1) if values[i] > 0 >= values[i + 1])
    guess["x"] = shoot(system.with_values(B=grid[k]), guess["x"], 1).x0
    return brentq(f, grid[k], grid[k + 1], xtol=1e-6)


def test_map_locates_the_period_doubling_of_the_twin_well_duffing(duffing):
    # k >= 0.3 keeps the next doubling (to period 4) above B = 0.285
    ks = np.array([0.30, 0.305, 0.31])
    B = np.round(np.arange(0.23, 0.2851, 0.005), 6)
    m = regime_map(
        _twin_well(duffing, 0.3),
        ("B", B),
        ("k", ks),
        initial_states=1,
        transient=300,
        periods=64,
        lyapunov_periods=0,
        executor="serial",
    )
    step = B[1] - B[0]
    motion = m.grid("motion", "x")
    for iy, k in enumerate(ks):
        b_pd = _period_doubling(_twin_well(duffing, k), [0.568, 0.413])
        assert B[0] + step < b_pd < B[-1] - step  # the boundary crosses the map
        for ix, b in enumerate(B):
            if abs(b - b_pd) <= step:
                continue  # slow convergence next to the bifurcation: any verdict
            expected = "period-1" if b < b_pd else "period-2"
            assert motion[iy, ix] == expected, (k, b, b_pd, motion[iy, ix])


def _harmonic_balance(w, k, c, B):
    """Amplitudes of the first-order harmonic balance of x'' + k x' + x + c x^3 =
    B cos(w t): the positive roots A of [(1 - w^2 + 3/4 c A^2)^2 + (k w)^2] A^2 = B^2;
    with three roots the middle one is unstable."""
    z = np.roots([9 / 16 * c * c, 1.5 * c * (1 - w * w), (1 - w * w) ** 2 + (k * w) ** 2, -B * B])
    z = np.sort(z[np.abs(z.imag) < 1e-9].real)
    A = np.sqrt(z[z > 0])
    return A if A.size == 1 else A[[0, -1]]


def test_map_finds_both_attractors_inside_the_hardening_duffing_hysteresis_band(duffing):
    k, c = 0.1, 0.1
    w = np.round(np.arange(1.0, 1.41, 0.05), 6)
    Bs = np.array([0.25, 0.3])
    m = regime_map(
        duffing.with_values(a=1.0, c=c, k=k, B=0.3, omega=1.2),
        ("omega", w),
        ("B", Bs),
        initial_states=4,
        box={"x": (-3.0, 3.0), "dx": (-3.0, 3.0)},
        lyapunov_periods=0,
        executor="serial",
    )
    checked = 0
    for ix, wv in enumerate(w):
        for iy, Bv in enumerate(Bs):
            A = _harmonic_balance(wv, k, c, Bv)
            # keep away from the folds, where the first-order balance is least accurate
            if any(_harmonic_balance(wv + d, k, c, Bv).size != A.size for d in (-0.03, 0.03)):
                continue
            cell = m.cells[ix][iy]
            found = sorted(a.run.xmax[0] for a in cell.attractors if a.run.status == "ok")
            assert len(found) == A.size, (wv, Bv, found, A)
            assert np.allclose(found, A, rtol=0.03), (wv, Bv, found, A)
            checked += 1 + (A.size == 2)
    assert checked >= 15  # both sides of the band and inside it were checked


def test_map_store_resumes_and_refuses_another_map(duffing, tmp_path):
    s = duffing.with_values(a=1.0, c=0.1, k=0.1, B=0.3, omega=1.2)
    kw = dict(initial_states=3, transient=100, periods=32, lyapunov_periods=50)
    kw |= dict(executor="serial", store=tmp_path)
    axes = (("omega", [1.1, 1.2, 1.3]), ("B", [0.25, 0.3]))
    first = regime_map(s, *axes, **kw)
    assert first.resumed == 0
    assert stored_count(tmp_path) == 3 * 3 * 2  # 3 x values, 2 y values, 3 starts each
    # forward and backward chains, random starts: 3 columns each, one file a column
    files = sorted((tmp_path / "points").glob("*.json"))
    assert len(files) == 3 * 3
    for f in files[1:3] + files[-1:]:
        f.unlink()  # as if interrupted there: forward x = 1.2, 1.3 and the last random
    again = regime_map(s, *axes, **kw)
    assert again.resumed == 3 * 3 * 2 - 3 * 2
    assert json.dumps(again.records()) == json.dumps(first.records())
    with pytest.raises(ValueError, match="holds another map"):
        regime_map(s, ("omega", [1.1, 1.2]), axes[1], **kw)


def test_map_records_round_trip(duffing, tmp_path):
    s = duffing.with_values(a=1.0, c=0.1, k=0.1, B=0.3, omega=1.2)
    m = regime_map(
        s,
        ("omega", [1.1, 1.2]),
        ("B", [0.3]),
        initial_states=2,
        lyapunov_periods=50,
        transient=100,
        periods=32,
        executor="serial",
    )
    for r in m.records():
        assert {"omega", "B", "share", "motion", "lyapunov", "meshing", "max", "min"} <= set(r)
    back = RegimeMap.load(m.save(tmp_path / "map.json"))
    assert back.records() == json.loads(json.dumps(m.to_dict()))["records"]
    assert (tmp_path / m.save(tmp_path / "map.csv").name).exists()


def test_map_figures_label_a_text_axis_and_write_only_the_kinds_asked(duffing, tmp_path):
    from gearsym.solver.plots_maps import map_figures, write_map_figures

    s = duffing.with_values(a=1.0, c=0.1, k=0.1, B=0.3, omega=1.2)
    m = regime_map(
        s,
        ("omega", [1.1, 1.2]),
        ("B", [0.0, 1.0]),
        initial_states=1,
        lyapunov_periods=0,
        transient=50,
        periods=32,
        executor="serial",
    )
    paths = write_map_figures(
        m, tmp_path, "t", ticks={"B": ["low", "high"]}, title="a title", kinds=("motion",)
    )
    assert [p.name for p in paths] == ["t-motion.png"]
    assert sorted(f.name for f in tmp_path.iterdir()) == ["t-motion.png"]
    with pytest.raises(ValueError, match="kinds: spectrum unknown"):
        map_figures(m, kinds=("spectrum",))
    import matplotlib.pyplot as plt
    from gearsym.solver.plots_maps import _label

    fig, ax = plt.subplots()
    _label(ax, m, {"B": ["low", "high"]})
    assert [t.get_text() for t in ax.get_yticklabels()] == ["low", "high"]
    plt.close(fig)
