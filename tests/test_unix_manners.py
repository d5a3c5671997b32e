"""Unix manners and strict JSON (issue 23, items 6 and 8), on the real command.

* A closed pipe (``gearsym ... | head -1``) ends the command as it ends ``cat``: killed by
  SIGPIPE, nothing on stderr.  ``subprocess`` reports that as ``-SIGPIPE`` (-13); the
  shell as 128 + 13 = 141.  A plain ``exit(141)`` would look the same to the shell but not
  to a parent that asks how the child ended (``os.WIFSIGNALED``), so the tests ask for the
  signal itself.
* Ctrl-C reaches every process of the group (the parent and its pool workers): one line on
  stderr, exit status 130, no traceback from any process, and the store keeps what was
  finished, so that the same command resumes without computing it again.
* ``--json`` is strict JSON (RFC 8259: no NaN, no Infinity), also on inputs whose numbers
  overflow: either the input is refused in one line or the numbers are null and a
  ``status`` says why.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from gearsym.solver.sweep.store import stored_count

pytestmark = pytest.mark.skipif(
    not hasattr(signal, "SIGPIPE") or sys.platform == "win32", reason="POSIX signals"
)

ROOT = Path(__file__).resolve().parents[1]
SIGPIPE = -getattr(signal, "SIGPIPE", 13)  # subprocess's returncode of a death by SIGPIPE


def _gearsym(*argv: str) -> list[str]:
    return [sys.executable, "-m", "gearsym", *argv]


def _strict(text: str):
    def refuse(name):
        raise AssertionError(f"not JSON: {name}")

    return json.loads(text, parse_constant=refuse)


# --- a closed pipe --------------------------------------------------------------------


def test_a_reader_that_leaves_after_one_line_ends_the_command_quietly(tmp_path):
    # The output (about 25 KB) outgrows the pipe, shrunk to one page where Linux allows:
    # the command is still writing when the reader leaves, whatever the timing.
    fcntl = pytest.importorskip("fcntl")
    read, write = os.pipe()
    if hasattr(fcntl, "F_SETPIPE_SZ"):
        fcntl.fcntl(write, fcntl.F_SETPIPE_SZ, 4096)
    argv = ("simulate", "reference-light", "--periods", "200", "--lyapunov-periods", "0")
    proc = subprocess.Popen(
        _gearsym(*argv, "--json"), stdout=write, stderr=subprocess.PIPE, cwd=tmp_path
    )
    os.close(write)
    with os.fdopen(read, "rb") as reader:
        first = reader.readline()
    err = proc.stderr.read().decode()
    proc.stderr.close()
    assert proc.wait(timeout=120) == SIGPIPE, err
    assert first == b"{\n"
    assert err == ""


def test_a_reader_gone_before_any_output_ends_it_the_same_way(tmp_path):
    # The whole output is one buffered write at the end: the closed pipe shows in the
    # final flush, which must not become "Exception ignored ... BrokenPipeError".
    read, write = os.pipe()
    os.close(read)
    proc = subprocess.run(
        _gearsym("backlash", "--order", "5"), stdout=write, stderr=subprocess.PIPE, cwd=tmp_path
    )
    os.close(write)
    assert (proc.returncode, proc.stderr.decode()) == (SIGPIPE, "")


def test_called_from_python_a_closed_pipe_returns_141_and_leaves_the_caller_alive(
    monkeypatch,
):
    from gearsym.cli import main

    read, write = os.pipe()
    os.close(read)
    closed = os.fdopen(write, "w")
    monkeypatch.setattr(sys, "stdout", closed)
    try:
        assert main(["backlash", "--order", "5"]) == 128 + signal.SIGPIPE
    finally:
        monkeypatch.undo()
        with contextlib.suppress(BrokenPipeError):  # what main() printed is still buffered
            closed.close()


# --- Ctrl-C ---------------------------------------------------------------------------


def _interrupt_when_stored(argv, store: Path, cwd: Path):
    """Start ``gearsym argv`` in its own process group, send SIGINT to the group as soon
    as ``store`` holds a finished file; return (exit status, stderr, stored files)."""
    proc = subprocess.Popen(
        _gearsym(*argv),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        cwd=cwd,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 180
        while not list(store.glob("*.json")):
            assert proc.poll() is None, proc.communicate()[1].decode()
            assert time.monotonic() < deadline, "no finished point in three minutes"
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGINT)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    stored = {f.name: (f.stat().st_ino, f.stat().st_mtime_ns) for f in store.glob("*.json")}
    return proc.returncode, err.decode(), stored


def _assert_one_quiet_line(code: int, err: str) -> None:
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    lines = err.splitlines()
    assert code == 130, err
    assert lines == ["gearsym: interrupted"], err


def _assert_kept(store: Path, stored: dict) -> None:
    """The files finished before the interrupt were not written again by the rerun."""
    again = {f.name: (f.stat().st_ino, f.stat().st_mtime_ns) for f in store.glob("*.json")}
    assert {name: again.get(name) for name in stored} == stored


def test_ctrl_c_on_a_map_with_worker_processes_keeps_its_columns_and_resumes(tmp_path):
    out = tmp_path / "map"
    argv = [
        "map",
        "reference-light",
        "--x",
        "lambda=0:1:4",
        "--y",
        "omega=0.45:0.55:2",
        "--initial-states",
        "2",
        "--transient",
        "300",
        "--periods",
        "20000",
        "--lyapunov-periods",
        "0",
        "--executor",
        "processes",
        "--workers",
        "2",
        f"--out={out}",
        "--quiet",
    ]
    store = out / "store" / "points"  # one store layout for sweeps and maps
    code, err, stored = _interrupt_when_stored(argv, store, tmp_path)
    _assert_one_quiet_line(code, err)
    assert 1 <= len(stored) < 8  # two chains of 4 columns each, a file per column
    runs = stored_count(out / "store")  # a column holds one run per y value
    assert runs == 2 * len(stored)
    again = subprocess.run(_gearsym(*argv), capture_output=True, text=True, cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert again.stdout.splitlines()[0] == (
        f"resumed: {runs} finished runs came from {out / 'store'}"
    )
    _assert_kept(store, stored)
    assert len(list(store.glob("*.json"))) == 8


def test_ctrl_c_on_a_sweep_keeps_its_points_and_resumes(tmp_path):
    out = tmp_path / "sweep"
    argv = [
        "sweep",
        "reference-light",
        "--param",
        "lambda",
        "--range",
        "0:1:4",
        "--periods",
        "20000",
        "--lyapunov-periods",
        "0",
        "--no-figure",
        "--quiet",
        f"--out={out}",
    ]
    store = out / "store" / "points"
    code, err, stored = _interrupt_when_stored(argv, store, tmp_path)
    _assert_one_quiet_line(code, err)
    assert 1 <= len(stored) < 4
    again = subprocess.run(_gearsym(*argv), capture_output=True, text=True, cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert f"resumed: {len(stored)} of 4 points came from {out / 'store'}" in again.stdout
    _assert_kept(store, stored)


# --- strict JSON ----------------------------------------------------------------------


def _edited(tmp_path: Path, topology: str, old: str, new: str) -> Path:
    text = (ROOT / "scenes" / "topologies" / topology).read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / f"absurd-{topology}"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


ABSURD = [
    # a pinion of 1e-320 kg m^2 (a subnormal number): the eigenproblem overflows
    ("modes", "siso.toml", "bore_radius_mm = 30", "bore_radius_mm = 30\ninertia_kg_m2 = 1e-320"),
    # a Young's modulus of 1e200 Pa: the stiffness and its fit overflow
    ("stiffness", "diso.toml", "youngs_modulus_Pa = 2.06e11", "youngs_modulus_Pa = 1e200"),
]


@pytest.mark.parametrize(("command", "topology", "old", "new"), ABSURD)
def test_json_of_absurd_inputs_is_strict_with_a_status_or_a_refusal(
    tmp_path, command, topology, old, new
):
    path = _edited(tmp_path, topology, old, new)
    run = subprocess.run(
        _gearsym(command, str(path), "--json"), capture_output=True, text=True, cwd=tmp_path
    )
    if run.returncode == 2:  # refused as bad input: one line naming it, nothing on stdout
        assert run.stdout == "" and len(run.stderr.splitlines()) == 1, run.stderr
        assert "gearsym: error:" in run.stderr
        return
    assert run.returncode == 0, run.stderr
    data = _strict(run.stdout)
    assert "non-finite number(s) written as null" in data["status"]
    assert "outside physical ranges" in data["status"]


def test_with_status_names_the_non_finite_numbers_and_dumps_writes_null():
    import numpy as np
    from gearsym.solver._json import dumps, non_finite, with_status

    obj = {"a": [1.0, float("nan")], "b": {"c": np.array([[1.0, np.inf]])}, "n": 3}
    assert non_finite(obj) == ["a[1]", "b.c[0][1]"]
    text = dumps(with_status(obj, "why"))
    data = _strict(text)
    assert data["a"] == [1.0, None] and data["b"]["c"] == [[1.0, None]]
    assert data["status"] == "2 non-finite number(s) written as null (a[1], b.c[0][1]): why"
    assert with_status({"x": 1.0}, "why") == {"x": 1.0}
