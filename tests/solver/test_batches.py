"""Work handed to worker processes comes back as it would have been computed in the main
process: a model (``System``) pickles as its generated file and values, and the border
runs of several sweeps, re-examined as one batch of the workers, match the same sweeps
run in one process (the reference: the serial executor, which runs every re-examination
here, one after the other)."""

import pickle

import numpy as np
import pytest
from gearsym.solver.integrate import simulate
from gearsym.solver.system import System


def test_a_system_pickles_as_its_generated_file_and_its_values():
    s = System.load("reference-light").with_values(**{"lambda": 0.3})
    back = pickle.loads(pickle.dumps(s))
    assert back.module.__file__ == s.module.__file__
    assert back.values == s.values and np.array_equal(back.p, s.p)
    runs = [simulate(m, None, transient=3, periods=2, method="dop853") for m in (s, back)]
    assert np.array_equal(runs[0].x_final, runs[1].x_final)


@pytest.mark.slow
def test_border_runs_reexamined_by_workers_match_the_serial_run():
    from gearsym.solver.sweep import SweepJob, sweep_many

    dead = System.load("reference-dead-zone").with_values(f1=0.1)
    lam = np.round(np.linspace(0.0, 1.0, 11), 10)
    settings = dict(
        method="dop853", rtol=1e-8, atol=1e-10, transient=100, periods=32, lyapunov_periods=60
    )
    jobs = [SweepJob(dead, "lambda", lam, backward=b, settings=settings) for b in (False, True)]
    got = {ex: sweep_many(jobs, executor=ex, workers=2) for ex in ("serial", "processes")}
    looked = [p for sw in got["processes"] for p in sw.points if p.verdict.get("reexamined")]
    assert len(looked) >= 2  # a batch, not one look run in this process
    for a, b in zip(got["serial"], got["processes"], strict=True):
        for p, q in zip(a.points, b.points, strict=True):
            assert p.verdict == q.verdict
            assert np.array_equal(p.x_final, q.x_final)


def test_border_runs_re_examined_together_agree_with_one_at_a_time():
    """The looks of a sweep run their windows as lockstep batches (borders.run_looks,
    settle.settle_many); the reference is the same looks one at a time (borders.run_look,
    settle.settle): the same verdict and periods run for each, and the chaotic ones'
    exponents within their two error bars (the batch shares its steps, so a chaotic
    orbit's points differ, not its statistics).  The light scene at f1 = 0.1 with a 12.5 µm
    transmission error is chaotic over most of lambda (reproduce's sensitivity maps)."""
    import sys

    import gearsym
    from gearsym.solver.sweep import SweepJob, borders, sweep_many

    plain = sys.modules["gearsym.solver.sweep.sweep"]
    system = gearsym.load("reference-light", f1=0.1, te_amplitude_um=12.5)
    # 41 points, not 21: which points a chaotic sweep marks for a look depends on the
    # rounding of the compiled code (-march=native), and 21 gave 2 looks on one machine
    lam = np.round(np.linspace(0.0, 1.0, 41), 10)
    settings = dict(
        method="dop853", rtol=1e-8, atol=1e-10, transient=300, periods=100, lyapunov_periods=400
    )
    with pytest.MonkeyPatch.context() as mp:  # the sweep's runs before their looks
        mp.setattr(plain, "_looked", lambda runs, points, *a, **k: [list(p) for p in points])
        (sw,) = sweep_many([SweepJob(system, "lambda", lam, settings=settings)])
    looks = [lk for _, lk in borders.sweep_looks(system, "lambda", list(sw.points), settings)]
    assert len(looks) >= 3
    one = [borders.run_look(lk) for lk in looks]
    together = borders.run_all(looks, executor="serial")
    for a, b in zip(one, together, strict=True):
        assert a.verdict["motion"] == b.verdict["motion"]
        assert a.verdict["periods_run"] == b.verdict["periods_run"]
        if a.verdict["motion"] == "chaotic":
            la, lb = a.lyapunov, b.lyapunov
            bars = la["uncertainty"] + lb["uncertainty"]
            assert abs(la["exponent"] - lb["exponent"]) <= bars
