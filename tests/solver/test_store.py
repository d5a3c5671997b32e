"""Sweeps that lose nothing: per-point store, resume after SIGKILL, refusal, determinism."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from gearsym.solver.sweep import SweepStoreError, sweep
from gearsym.solver.system import System

SETTINGS = dict(method="cvodes", transient=40, periods=8, lyapunov_periods=20)


def _strip(point):
    """A point without its wall-clock time, the one field that may differ between runs."""
    point = json.loads(json.dumps(point.to_dict() if hasattr(point, "to_dict") else point))
    point.get("integration", {}).pop("wall_time_s", None)
    return point


def test_serial_and_parallel_sweeps_are_bit_identical():
    system = System.load("reference_light")
    lam = np.linspace(0.0, 1.0, 4)
    a = sweep(system, "lambda", lam, continuation=False, executor="serial", **SETTINGS)
    b = sweep(
        system, "lambda", lam, continuation=False, executor="processes", workers=2, **SETTINGS
    )
    assert [_strip(p) for p in a.points] == [_strip(p) for p in b.points]


def test_a_dask_local_cluster_sweep_equals_the_serial_one():
    # dask.distributed: two worker processes on a LocalCluster, independent points and one
    # continuation chain; the points are bit-identical to a serial run (the lyapunov
    # exponent included: same integrator, same operations).
    pytest.importorskip("dask.distributed")
    system = System.load("reference_light")
    lam = np.linspace(0.0, 1.0, 4)
    settings = dict(SETTINGS, method="dop853")
    for continuation in (False, True):
        a = sweep(system, "lambda", lam, continuation=continuation, executor="serial", **settings)
        b = sweep(
            system, "lambda", lam, continuation=continuation, executor="dask", workers=2, **settings
        )
        assert [_strip(p) for p in a.points] == [_strip(p) for p in b.points]


def test_a_store_of_another_model_is_refused(tmp_path):
    lam = [0.0, 0.5]
    sweep(System.load("reference_light"), "lambda", lam, store=tmp_path, **SETTINGS)
    with pytest.raises(SweepStoreError, match="another model version"):
        sweep(System.load("reference_heavy"), "lambda", lam, store=tmp_path, **SETTINGS)
    with pytest.raises(SweepStoreError, match="values differ"):
        sweep(System.load("reference_light"), "lambda", [0.0, 0.6], store=tmp_path, **SETTINGS)


def test_resuming_a_half_done_store_gives_the_uninterrupted_result(tmp_path):
    system = System.load("reference_heavy")
    lam = np.linspace(0.0, 1.0, 5)
    full = sweep(system, "lambda", lam, store=tmp_path / "full", **SETTINGS)
    part = tmp_path / "part"
    sweep(system, "lambda", lam, store=part, **SETTINGS)
    for f in sorted((part / "points").glob("*.json"))[2:]:
        f.unlink()  # as if the run had stopped after two points
    resumed = sweep(system, "lambda", lam, store=part, **SETTINGS)
    assert [_strip(p) for p in resumed.points] == [_strip(p) for p in full.points]


@pytest.mark.slow
def test_a_sweep_killed_with_sigkill_resumes_and_matches(tmp_path):
    args = [
        sys.executable,
        "-m",
        "gearsym.cli",
        "sweep",
        "reference-light",
        "--param",
        "lambda",
        "--range",
        "0:1:8",
        "--executor",
        "serial",
        # CVODES, not the compiled default: the points must take long enough (a tenth of a
        # second each) for the kill below to land in the middle of the sweep.
        "--method",
        "cvodes",
        "--transient",
        "60",
        "--periods",
        "8",
        "--lyapunov-periods",
        "40",
        "--quiet",
    ]
    killed = tmp_path / "killed"
    proc = subprocess.Popen(
        args + ["--out", str(killed)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    points = killed / "store" / "points"
    deadline = time.time() + 120
    while time.time() < deadline and len(list(points.glob("[0-9]*.json"))) < 3:
        time.sleep(0.05)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    stored = len(list(points.glob("[0-9]*.json")))
    assert 3 <= stored < 8, stored  # killed mid-run, with some points stored
    assert not (killed / "sweep.json").exists()
    subprocess.run(args + ["--out", str(killed)], check=True, capture_output=True)
    clean = tmp_path / "clean"
    subprocess.run(args + ["--out", str(clean)], check=True, capture_output=True)
    a = json.loads((killed / "sweep.json").read_text())["points"]
    b = json.loads((clean / "sweep.json").read_text())["points"]
    assert [_strip(p) for p in a] == [_strip(p) for p in b]


def test_a_stored_point_of_another_format_is_refused_not_deleted(tmp_path):
    system = System.load("reference_light")
    sweep(system, "lambda", [0.0, 0.5], store=tmp_path, **SETTINGS)
    stray = tmp_path / "points" / "00001.json"
    stray.write_text(json.dumps({"value": 0.5}))  # valid JSON, not a point
    with pytest.raises(SweepStoreError, match="00001.json is not a sweep point"):
        sweep(system, "lambda", [0.0, 0.5], store=tmp_path, **SETTINGS)
    assert stray.exists()
