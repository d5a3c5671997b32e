"""Independent sweep points integrated together (compiled lockstep chunks) against the same
points one at a time.

Reference: the per-point path -- ``analyse_point``, each point integrated on its own by the
compiled DOP853 (``simulate``), which the batched path must reproduce within the
integrator's tolerance (rtol 1e-8 on states of order 1: 1e-6 allowed), verdicts included.
"""

import json
import subprocess
import sys

import numpy as np
import pytest
from gearsym.cli import main
from gearsym.solver._json import dumps
from gearsym.solver.analysis import analyse_point
from gearsym.solver.integrate import native
from gearsym.solver.integrate.simulate import simulate, simulate_many
from gearsym.solver.sweep import SweepResult, sweep
from gearsym.solver.sweep.chains import plan
from gearsym.solver.sweep.store import stored_count
from gearsym.solver.system import System

pytestmark = pytest.mark.skipif(native.compiler() is None, reason="no C compiler")

# Eight values put two points in each of the four lockstep chunks; 0.0476 is a period-3
# point and 0.1303 a period-12 point of the reference model at the default settings.
VALUES = [0.0, 0.047619047619047616, 0.1, 0.13032581453634084, 0.35, 0.5, 0.8, 1.0]


def _plain(point) -> dict:
    """A point as stored, without its wall-clock time (the one field that may differ)."""
    d = json.loads(dumps(point.to_dict()))
    d["integration"].pop("wall_time_s", None)
    return d


@pytest.fixture(scope="module")
def light():
    return System.load("reference_light")


@pytest.fixture(scope="module")
def batched(light):
    return sweep(light, "lambda", VALUES, continuation=False, lyapunov_periods=0)


def test_the_points_run_in_lockstep_chunks(light):
    chains = plan(light, "lambda", VALUES, continuation=False, backward=False, x0=None, settings={})
    assert all(c.batch for c in chains) and [len(c.values) for c in chains] == [2, 2, 2, 2]
    assert sorted(i for c in chains for i in c.indices) == list(range(len(VALUES)))
    # not compiled: one point per chain, as before
    chains = plan(
        light,
        "lambda",
        VALUES,
        continuation=False,
        backward=False,
        x0=None,
        settings={"method": "cvodes"},
    )
    assert not any(c.batch for c in chains) and len(chains) == len(VALUES)


def test_simulate_many_matches_simulate(light):
    systems = [light.with_values(**{"lambda": v}) for v in (0.0, 0.35, 0.8)]
    many = simulate_many(systems, transient=100, periods=20, samples_per_period=16)
    for s, tr in zip(systems, many, strict=True):
        one = simulate(s, transient=100, periods=20, samples_per_period=16)
        assert tr.status == one.status == "ok"
        assert np.max(np.abs(tr.x - one.x)) < 1e-6  # rtol 1e-8 on O(1) states
        assert tr.t_final == one.t_final and tr.x.shape == one.x.shape


def test_batched_sweep_equals_point_by_point(light, batched):
    # Verdicts equal; Poincare points, Max/Min and meshing shares within the tolerance.
    for v, point in zip(VALUES, batched.points, strict=True):
        ref = analyse_point(light.with_values(**{"lambda": v}), lyapunov_periods=0)
        tr = ref.trajectory
        assert point.ok and tr.status == "ok"
        for c in light.coordinates:
            assert point.motion(c) == ref.classification[c].motion
        for k, s in enumerate(light.states):
            assert point.max(s) == pytest.approx(tr.x[k].max(), abs=1e-6)
            assert point.min(s) == pytest.approx(tr.x[k].min(), abs=1e-6)
            assert np.allclose(point.poincare[s], tr.poincare[k], rtol=0, atol=1e-6)
        # no tangent vector run: a periodic verdict's exponent is its orbit's, log|mu|/nT
        assert "multipliers" in point.lyapunov["method"] and point.lyapunov["exponent"] < 0
    assert [p.motion("u") for p in batched.points][1:4] == ["period-3", "period-1", "period-12"]


def test_serial_and_parallel_batched_sweeps_are_bit_identical(light, batched):
    # The chunks depend on the number of points only, not on the executor.
    other = sweep(
        light, "lambda", VALUES, continuation=False, lyapunov_periods=0, executor="processes"
    )
    assert [_plain(p) for p in batched.points] == [_plain(p) for p in other.points]


def test_sweep_json_from_the_stored_texts_is_the_plain_encoding(light, tmp_path):
    # The file assembled from the store's per-point texts equals dumps(to_dict()), also
    # for a backward sweep and after a resume (texts read back from the store); the
    # resumed sweep recomputes the chunk that was lost and equals the uninterrupted one.
    settings = dict(transient=20, periods=6, lyapunov_periods=0)
    for backward in (False, True):
        store = tmp_path / f"store{backward}"
        result = sweep(light, "lambda", VALUES, continuation=False, store=store, **settings)
        assert result.texts is not None
        assert result.to_json() == dumps(result.to_dict())
        # a lockstep chunk is one file: first index and number of points in its name
        files = sorted(f.name for f in (store / "points").iterdir())
        assert files == [f"{i:05d}-2.json" for i in (0, 2, 4, 6)]
        assert stored_count(store) == len(VALUES)
        (store / "points" / "00002-2.json").unlink()  # as if killed before it
        assert stored_count(store) == len(VALUES) - 2
        again = sweep(light, "lambda", VALUES, continuation=False, store=store, **settings)
        assert again.resumed == len(VALUES) - 2
        assert [_plain(p) for p in again.points] == [_plain(p) for p in result.points]
        assert again.to_json() == dumps(again.to_dict())
        path = again.save(tmp_path / "sweep.json")
        assert SweepResult.load(path).motion("u") == result.motion("u")
    assert sweep(light, "lambda", VALUES[:3], **settings).texts is None  # nothing stored


def test_cli_sweep_of_independent_points(tmp_path, capsys):
    out = tmp_path / "sw"
    args = ["sweep", "reference-light", "--param", "lambda", "--range", "0:1:8"]
    args += ["--independent", "--lyapunov-periods", "0", "--quiet", "--out", str(out)]
    assert main(args) == 0
    data = json.loads((out / "sweep.json").read_text())
    assert data["direction"] == "independent" and len(data["points"]) == 8
    assert all(p["status"] == "ok" for p in data["points"])
    assert all("multipliers" in p["lyapunov"]["method"] for p in data["points"])
    assert (out / "bifurcation.png").stat().st_size > 0
    out = capsys.readouterr().out
    assert "attractor: period-1 on [0, 1]" in out and "verdicts: 0 of 8 points" in out


def test_cli_sweep_errors_are_one_line(tmp_path, capsys):
    base = ["sweep", "reference-light", "--param", "lambda", "--independent", "--quiet"]
    base += ["--lyapunov-periods", "0", "--transient", "20", "--periods", "6"]
    assert main([*base, "--range", "0:1:8", "--out", str(tmp_path / "a")]) == 0
    capsys.readouterr()
    # the same folder, another sweep: refused in one line, nothing overwritten
    assert main([*base, "--range", "0:1:9", "--out", str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("gearsym: error: sweep: ")
    assert "holds another sweep" in err[0]


def test_simulate_many_checks_its_input(light):
    with pytest.raises(ValueError, match="2 systems but 1 initial states"):
        simulate_many([light, light], [np.zeros(4)])
    with pytest.raises(TypeError, match="unknown option"):
        simulate_many([light], periodz=3)


def test_a_sweep_without_a_figure_loads_neither_matplotlib_sympy_nor_casadi(tmp_path):
    # A fresh process, as a user runs it: the data-only sweep needs none of the three.
    code = (
        "import sys; from gearsym.cli import main; "
        f"rc = main(['sweep', 'reference-light', '--param', 'lambda', '--range', '0:1:8', "
        f"'--independent', '--lyapunov-periods', '0', '--transient', '20', '--periods', '6', "
        f"'--quiet', '--no-figure', '--out', r'{tmp_path / 'sw'}']); "
        "print(rc, sorted(m for m in ('matplotlib', 'sympy', 'casadi') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.stdout.strip().splitlines()[-1] == "0 []", done.stderr
    assert (tmp_path / "sw" / "sweep.json").exists()
    assert not (tmp_path / "sw" / "bifurcation.png").exists()
