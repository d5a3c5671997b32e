"""Maps without a compiler (issue 23, item 4): the SciPy fallback of the map engine
(``integrate/native/fallback.py``) against the compiled engine, and a compiler that is
missing or fails as one warning line on the command line.

Tolerances, from the integration tolerance ``rtol`` (``atol`` = 1e-10 is far below the
states, of order 1):

* Poincare points: both engines integrate the same equations with the local error held
  to ``rtol |x|`` per step; on these contracting period-1 orbits (exponent about -0.03
  per tau, so the multipliers shrink errors by 0.68 per period) local errors do not pile
  up, each engine's global error stays within a few ``rtol |x|`` and the two differ by
  at most ``10 rtol max|x|`` (measured: 0.2 rtol max|x| at rtol 1e-8).
* Exponents: each period adds ``log |w|`` with the relative error of the tangent vector,
  a few ``rtol``; the mean over the summed periods, per unit tau, then differs by at most
  ``10 rtol / T`` (measured: 0.35 rtol / T).
* Extremes are taken at accepted steps, which the engines place differently: a sinusoid
  of range R sampled at steps up to twice the mean step ``T / m`` (m accepted steps per
  period) misses its extreme by at most ``R (1 - cos(2 pi / m)) / 2`` (measured: a tenth
  of that).
"""

import json
import os
import re
import subprocess
import sys
import warnings

import numpy as np
import pytest
from gearsym.solver.integrate import native
from gearsym.solver.integrate.run import Batch, integrate
from gearsym.solver.integrate.spec import RunSpec
from gearsym.solver.system import System

RTOL = 1e-8
GEARSYM = [sys.executable, "-m", "gearsym.cli"]
SMALL = ["--transient", "10", "--periods", "4", "--lyapunov-periods", "8", "--quiet"]


@pytest.fixture
def no_compiler(monkeypatch):
    """GEARSYM_CC=none, with this session's loaded libraries, failed builds and warnings
    forgotten before and after (``native.reset``)."""
    native.reset()
    monkeypatch.setenv("GEARSYM_CC", "none")
    yield
    native.reset()


def _map(module, P, X0, backend="auto", *, lyapunov_periods, **options):
    """A map run: Poincare points, extremes and the exponent, stopped at the valid range."""
    spec = RunSpec(
        collect=("samples", "extremes", "exponent"),
        lyapunov_periods=lyapunov_periods,
        valid_range="stop",
        **options,
    )
    return integrate(Batch.of(module, P), X0, spec, backend=backend)


def _compiled(fn):
    native.reset()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no fallback on this side
        return fn()


def test_fallback_fills_every_field_as_the_compiled_engine(no_compiler, monkeypatch):
    s = System.load("reference_light")
    P = np.array(
        [s.parameters_with(**{"lambda": a, "f1": b}) for a in (0, 0.5, 1) for b in (0.1, 0.2)]
    )
    X0 = np.tile([1.0, 0.0, 0.0, 0.0], (len(P), 1))
    kw = dict(transient=20, periods=10, lyapunov_periods=20, rtol=RTOL, atol=1e-10)
    with pytest.warns(
        UserWarning, match="GEARSYM_CC='none' turns the C compiler off.*NumPy instead"
    ):
        got = _map(s.module, P, X0, **kw)
    with pytest.raises(native.NativeUnavailable):
        _map(s.module, P, X0, backend="native", **kw)
    monkeypatch.delenv("GEARSYM_CC")
    ref = _compiled(lambda: _map(s.module, P, X0, backend="native", **kw))
    assert (got.backend, ref.backend) == ("numpy", "native")
    assert (got.label, ref.label) == ("NumPy fallback DOP853", "compiled DOP853")
    assert got.status == ref.status == ("ok",) * len(P)
    assert got.x.shape == ref.x.shape == (len(P), 11, 4)
    np.testing.assert_array_equal(got.t, ref.t)
    scale = np.max(np.abs(ref.x))
    assert np.max(np.abs(got.x - ref.x)) <= 10 * RTOL * scale
    assert got.exponent.shape == ref.exponent.shape == (len(P), 20)
    assert np.max(np.abs(got.exponent - ref.exponent)) <= 10 * RTOL / s.period
    for r in (got, ref):
        assert np.all(r.xmin <= r.x.min(axis=1)) and np.all(r.xmax >= r.x.max(axis=1))
    m = min(got.nsteps.min(), ref.nsteps.min()) / (kw["transient"] + kw["periods"])
    miss = (ref.xmax - ref.xmin) * (1 - np.cos(2 * np.pi / m)) / 2
    assert np.all(np.abs(got.xmax - ref.xmax) <= miss)
    assert np.all(np.abs(got.xmin - ref.xmin) <= miss)
    assert np.all(got.nfev > 0) and np.all(got.nsteps > 0) and np.all(np.isnan(got.t_fail))


@pytest.mark.parametrize(("bound", "status"), [(1e3, "left the valid range"), (2.0, "divergent")])
def test_fallback_stops_a_failing_point_as_the_compiled_engine(
    no_compiler, monkeypatch, bound, status
):
    # a negative damping grows: it leaves the valid range |u|, |v| <= 3 first, or passes
    # the escape bound when that is lower; the same status and time, NaN after, no exponent
    s = System.load("reference_light")
    P = np.array(
        [s.parameters_with(**{"lambda": 0.8}), s.parameters_with(xi_u_u=-0.5, xi_v_v=-0.5)]
    )
    X0 = np.tile([1.0, 0.0, 0.0, 0.0], (2, 1))
    kw = dict(transient=20, periods=5, lyapunov_periods=10, rtol=RTOL, atol=1e-10, bound=bound)
    got = _map(s.module, P, X0, backend="numpy", **kw)
    monkeypatch.delenv("GEARSYM_CC")
    ref = _compiled(lambda: _map(s.module, P, X0, backend="native", **kw))
    assert got.status == ref.status == ("ok", status)
    assert np.all(np.isnan(got.x[1])) and np.all(np.isnan(got.exponent[1]))
    assert np.all(np.isfinite(got.exponent[0]))
    # each stops at the end of the accepted step that crossed: within a step of each other
    # (both take 15 to 20 steps per period T here, see nsteps)
    assert abs(got.t_fail[1] - ref.t_fail[1]) < s.period / 10


def _verdict(attractor: dict) -> tuple:
    """What a map says of an attractor: which starts reach it, its status, motion, period
    and meshing regime per coordinate."""
    keys = ("starts", "status", "motion", "period", "meshing")
    return tuple(json.dumps(attractor[k], sort_keys=True) for k in keys)


def _said(stderr: str) -> list[str]:
    notes = "gearsym: note:"  # the note on the polynomial backlash (issue 25) aside
    return [ln for ln in stderr.splitlines() if not ln.startswith(notes)]


def _cli_map(tmp_path, cc: str):
    """A map of two cells and one start each, from the NumPy fallback: what it says."""
    env = os.environ | {"GEARSYM_CC": cc, "GEARSYM_CACHE": str(tmp_path / "cache")}
    grid = ["--x=lambda=0:1:2", "--y=f1=0.1:0.1:1", "--initial-states=1"]
    argv = ["map", "reference-light", *grid, *SMALL, f"--out={tmp_path / 'map'}"]
    done = subprocess.run([*GEARSYM, *argv], capture_output=True, text=True, env=env)
    return done.returncode, _said(done.stderr)


@pytest.mark.slow  # some 40 s: the fallback steps every point in Python
def test_gearsym_map_without_a_compiler_gives_the_compiled_verdicts(tmp_path):
    """Issue 24's acceptance test: ``gearsym map`` with GEARSYM_CC=none runs (slower) and
    says what the compiled engine says of every attractor of a small map (periods enough
    for the motions to be determined)."""
    env = os.environ | {"GEARSYM_CACHE": str(tmp_path / "cache")}
    grid = ["--x=lambda=0:1:3", "--y=f1=0.1:0.2:2", "--initial-states=2", "--quiet"]
    runs = ["--transient", "60", "--periods", "20", "--lyapunov-periods", "40"]
    maps = {}
    for cc in ("none", "cc"):
        out = tmp_path / cc
        argv = [*GEARSYM, "map", "reference-light", *grid, *runs, f"--out={out}"]
        done = subprocess.run(argv, capture_output=True, text=True, env=env | {"GEARSYM_CC": cc})
        assert done.returncode == 0, done.stderr
        maps[cc] = json.loads((out / "map.json").read_text(encoding="utf-8"))["records"]
        if cc == "none":  # without a compiler: one warning line, nothing else
            assert _said(done.stderr) == [
                "gearsym: warning: GEARSYM_CC='none' turns the C compiler off; integrating "
                "with NumPy instead (slower)"
            ]
    got, ref = maps["none"], maps["cc"]
    period = System.load("reference_light").period
    assert len(got) == len(ref) >= 6
    assert any(r["motion"]["u"] != "undetermined" for r in ref)  # verdicts, not shrugs
    for a, b in zip(got, ref, strict=True):
        where = ("lambda", "f1", "attractor", "attractors", "share")
        assert [a[k] for k in where] == [b[k] for k in where]
        assert _verdict(a) == _verdict(b)
        end_a, end_b = np.array(a["state"]), np.array(b["state"])
        assert np.max(np.abs(end_a - end_b)) <= 10 * RTOL * np.max(np.abs(end_b))
        assert abs(a["lyapunov"] - b["lyapunov"]) <= 10 * RTOL / period


@pytest.mark.slow
def test_a_compiler_that_fails_is_one_bug_report_line_and_still_a_map(tmp_path):
    code, lines = _cli_map(tmp_path, "false")
    assert code == 0, lines
    assert len(lines) == 1, lines
    line = lines[0]
    assert line.startswith("gearsym: warning: compiling the C code of reference_light with ")
    assert "failed (exit status 1); this is a bug, please report it" in line
    assert line.endswith("; integrating with NumPy instead (slower)")
    log = line.split("the compiler's full output is in ")[1].split(")")[0]
    assert log.startswith(str(tmp_path / "cache")) and os.path.isfile(log)
    assert (tmp_path / "map" / "map.json").exists()


@pytest.mark.parametrize(
    "cc,says",
    [
        ("none", "GEARSYM_CC='none' turns the C compiler off"),
        ("gcc; touch PWNED", "GEARSYM_CC='gcc; touch PWNED' is not a program on PATH"),
    ],
)
def test_the_fallback_says_why_there_is_no_compiler(cc, says, monkeypatch, tmp_path):
    """A GEARSYM_CC that names no program is said as such (it is never run through a
    shell: the text after ';' does nothing)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("GEARSYM_CC", cc)
    native.reset()
    try:
        with pytest.raises(native.NativeUnavailable, match=re.escape(says)):
            native.library(System.load("reference_light").module)
    finally:
        native.reset()
    assert not (tmp_path / "PWNED").exists()
