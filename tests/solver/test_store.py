"""Sweeps that lose nothing: the run store, resume after SIGKILL, refusal, determinism."""

import json
import os
import signal
import subprocess
import sys
import time
import warnings

import numpy as np
import pytest
from gearsym.solver.sweep import SweepStoreError, sweep
from gearsym.solver.sweep.store import RunStore
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


def _damage_a_point(store, kind):
    """Damage one stored file as a crash, a full disk or a stray edit may; its name."""
    points = store / "points"
    if kind == "truncated-chunk":
        f = points / "00002-2.json"
        f.write_text(f.read_text()[: f.stat().st_size // 2])
        return f
    f = points / "00001-1.json"
    f.write_text({"empty-object": "{}", "not-json": "not json", "no-keys": '{"value": 0.5}'}[kind])
    return f


def _sweep_warnings(*args, **kw):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = sweep(*args, **kw)
    return result, [str(w.message) for w in caught if "damaged" in str(w.message)]


@pytest.mark.parametrize("kind", ["empty-object", "not-json", "no-keys", "truncated-chunk"])
def test_a_damaged_point_file_is_set_aside_and_its_points_recomputed(tmp_path, kind):
    # A point file that holds no valid point is moved to store/damaged (never deleted),
    # named in one warning, and the resumed sweep recomputes its points: the result is
    # the uninterrupted one, bit for bit.  A continuation chain recomputes from there on.
    system = System.load("reference_light")
    if kind == "truncated-chunk":  # compiled: lockstep chunks of two points in one file
        lam, kw = np.linspace(0.0, 1.0, 8), dict(transient=20, periods=6, lyapunov_periods=0)
        kw |= dict(method="dop853", continuation=False)
    else:
        lam, kw = np.linspace(0.0, 1.0, 3), dict(SETTINGS, continuation=kind != "not-json")
    store = tmp_path / "store"
    full = sweep(system, "lambda", lam, store=store, **kw)
    f = _damage_a_point(store, kind)
    text = f.read_text()
    resumed, said = _sweep_warnings(system, "lambda", lam, store=store, **kw)
    assert len(said) == 1 and said[0].startswith(f"{f} is damaged"), said
    assert said[0].endswith("its points will be recomputed"), said
    assert (store / "damaged" / f.name).read_text() == text  # kept as it was
    assert [_strip(p) for p in resumed.points] == [_strip(p) for p in full.points]
    again, said = _sweep_warnings(system, "lambda", lam, store=store, **kw)
    assert said == [] and [_strip(p) for p in again.points] == [_strip(p) for p in full.points]


@pytest.mark.parametrize(
    "text, why",
    [
        ('{"format": 1, "model": "refer', "damaged"),
        ("[1, 2]", "damaged"),
        ("{}", "damaged or incomplete"),
    ],
    ids=["truncated", "not-a-dict", "no-keys"],
)
def test_a_damaged_manifest_is_refused_in_one_line(tmp_path, text, why):
    manifest = tmp_path / "store" / "manifest.json"
    manifest.parent.mkdir()
    manifest.write_text(text)
    system = System.load("reference_light")
    with pytest.raises(SweepStoreError, match=f"manifest.json is {why}"):
        sweep(system, "lambda", [0.0, 0.5], store=tmp_path / "store", **SETTINGS)
    assert manifest.read_text() == text  # nothing overwritten


# a sweep on the command line into the folder that follows
SHORT_SWEEP = [sys.executable, "-m", "gearsym.cli", "sweep", "reference-light"]
SHORT_SWEEP += ["--param", "lambda", "--range", "0:1:3", "--quiet", "--no-figure", "--out"]


def test_the_cli_refuses_a_truncated_manifest_in_one_line(tmp_path):
    manifest = tmp_path / "store" / "manifest.json"
    manifest.parent.mkdir()
    manifest.write_text('{"format": 1, "model": "refer')
    done = subprocess.run([*SHORT_SWEEP, str(tmp_path)], capture_output=True, text=True)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr, done.stderr
    assert lines[0].startswith(f"gearsym: error: sweep: {manifest} is damaged"), lines[0]
    assert "choose another --out" in lines[0]


_HOLD = (
    "import json, sys; from pathlib import Path; "
    "from gearsym.solver.sweep.store import RunStore; "
    "RunStore.open(Path(sys.argv[1]), **json.loads(sys.argv[2])); "
    "print('locked', flush=True); sys.stdin.read()"
)


def test_a_store_has_one_writer_at_a_time(tmp_path):
    # Another process writing into the folder (a sweep still running, or its workers)
    # makes a second writer stop at once, in one line naming the holder's pid; the lock
    # goes with its holder, even when that is killed with SIGKILL.
    store = tmp_path / "store"
    manifest = dict(kind="sweep", model_hash="0" * 12, values={"lambda": [0.0]})
    holder = subprocess.Popen(
        [sys.executable, "-c", _HOLD, str(store), json.dumps(manifest)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout.readline().strip() == "locked"
        assert (store / "lock").read_text().strip() == str(holder.pid)
        with pytest.raises(SweepStoreError, match=f"in use by another sweep .process {holder.pid}"):
            RunStore.open(store, **manifest)
        done = subprocess.run([*SHORT_SWEEP, str(tmp_path)], capture_output=True, text=True)
        lines = done.stderr.strip().splitlines()
        assert done.returncode == 2 and len(lines) == 1, done.stderr
        assert lines[0] == (
            f"gearsym: error: sweep: {store} is in use by another sweep (process "
            f"{holder.pid}); wait for it to finish or choose another --out"
        )
    finally:
        holder.kill()
        holder.wait()
    again = RunStore.open(store, **manifest)  # the kernel freed the lock with its holder
    assert again.read() == {} and again.count() == 0
    assert (store / "lock").read_text().strip() == str(os.getpid())
    again.close()


def test_one_store_format_for_sweeps_and_maps_refuses_others_in_one_line(tmp_path):
    # A sweep's store and a map's store are one format: a store of the other kind, or
    # one of the first format (points/ for sweeps, columns/ for maps), is refused in one
    # line naming the folder and the fix.
    system = System.load("reference_light")
    sweep(system, "lambda", [0.0], store=tmp_path / "sweep", **SETTINGS)
    with pytest.raises(SweepStoreError, match="holds a sweep, not a map; choose another"):
        RunStore.open(tmp_path / "sweep", kind="map", model_hash="0", values={})
    old = tmp_path / "old"
    old.mkdir()
    (old / "manifest.json").write_text('{"kind": "regime map", "model_hashes": []}')
    with pytest.raises(SweepStoreError, match=r"older gearsym \(store format 1.*another --out"):
        sweep(system, "lambda", [0.0], store=old, **SETTINGS)


def test_a_record_survives_its_dict_bit_for_bit():
    from gearsym.solver.analysis import analyse_point
    from gearsym.solver.analysis.record import RunRecord

    system = System.load("reference_light")
    record = analyse_point(system, **SETTINGS).record(
        {"lambda": 0.8}, start="given", x0=[1, 0, 0, 0]
    )
    back = RunRecord.from_dict(json.loads(json.dumps(record.to_dict())))
    assert back.to_dict() == record.to_dict() and back.value == 0.8 and back.start == "given"
    assert all(np.array_equal(back.poincare[s], record.poincare[s]) for s in system.states)
    assert back.lyapunov_exponent == record.lyapunov_exponent is not None
