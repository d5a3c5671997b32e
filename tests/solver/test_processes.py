"""Worker processes end with their parent (issue 14, point 6).

A process pool's workers used to outlive a killed ``gearsym sweep`` or ``gearsym
reproduce``: re-parented to PID 1 they finished their tasks, wrote into the store and
then slept for ever.  Each command runs here in a session of its own, so that its
process group holds the parent and its workers and nothing else of the test run.
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(
    not Path("/proc/self/stat").exists(), reason="reads the process table from /proc"
)

# Forty independent CVODES points (about a tenth of a second each) on a pool of worker
# processes: long enough to be killed with points stored and points to come.
SWEEP = [
    sys.executable,
    "-m",
    "gearsym.cli",
    "sweep",
    "reference-light",
    "--param",
    "lambda",
    "--range",
    "0:1:40",
    "--independent",
    "--executor",
    "processes",
    "--method",
    "cvodes",
    "--transient",
    "60",
    "--periods",
    "8",
    "--lyapunov-periods",
    "40",
    "--quiet",
    "--no-figure",
]
# --fresh: every unit computed by the workers, none loaded from a result store
REPRODUCE = [sys.executable, "-m", "gearsym.cli", "reproduce", "--quick", "--fresh", "--quiet"]
REPRODUCE += ["--out"]


def _stat(pid: str) -> list[str]:
    """The fields of /proc/PID/stat after the command name: state, ppid, pgrp, ..."""
    return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()


def _group(pgid: int) -> dict[int, str]:
    """The living processes of process group ``pgid``: pid -> command name (zombies,
    dead and waiting to be reaped, are not counted)."""
    found = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            state, _, group = _stat(entry.name)[:3]
            name = (entry / "comm").read_text().strip()
        except (OSError, IndexError):
            continue  # ended while read
        if int(group) == pgid and state not in ("Z", "X"):
            found[int(entry.name)] = name
    return found


def _workers(parent: int) -> list[int]:
    """The pool workers of ``parent``: its children running its own command line."""
    try:
        own = Path(f"/proc/{parent}/cmdline").read_bytes()
    except OSError:
        return []
    found = []
    for pid in _group(parent):
        try:
            if int(_stat(str(pid))[1]) == parent and (
                Path(f"/proc/{pid}/cmdline").read_bytes() == own
            ):
                found.append(pid)
        except (OSError, IndexError):
            continue
    return found


def _wait(condition, seconds: float, what: str) -> None:
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            pytest.fail(f"gave up waiting for {what}")
        time.sleep(0.05)


def _gone_within(pgid: int, seconds: float) -> dict[int, str]:
    """What is left of group ``pgid`` after at most ``seconds`` (empty when all ended)."""
    deadline = time.monotonic() + seconds
    while (left := _group(pgid)) and time.monotonic() < deadline:
        time.sleep(0.02)
    return left


def _stop(proc: subprocess.Popen) -> None:
    """Clean up after a failed test: nothing of the command may outlive it."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait()


@pytest.mark.parametrize(
    "signum, to_group",
    [
        (signal.SIGKILL, False),  # kill -9 of the command
        (signal.SIGTERM, False),  # kill of the command (a batch system's time limit)
        (signal.SIGINT, True),  # Ctrl-C in a terminal: the whole foreground group
    ],
    ids=["SIGKILL", "SIGTERM", "Ctrl-C"],
)
def test_the_workers_of_a_killed_sweep_end_with_it(tmp_path, signum, to_group):
    out = tmp_path / "sweep"
    proc = subprocess.Popen(
        [*SWEEP, "--out", str(out)],
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        points = out / "store" / "points"
        _wait(lambda: len(list(points.glob("[0-9]*.json"))) >= 2, 120, "two stored points")
        _wait(lambda: len(_workers(proc.pid)) >= min(2, os.cpu_count()), 30, "the workers")
        (os.killpg if to_group else os.kill)(proc.pid, signum)
        code = proc.wait(timeout=60)
        left = _gone_within(proc.pid, 5.0)
        assert not left, f"still running 5 s after {signum.name}: {left}"
        stored = len(list(points.glob("[0-9]*.json")))
        assert stored < 40, stored  # killed mid-run: the workers did not go on alone
        if signum == signal.SIGINT:
            # the command itself ends its workers and says so, in one line
            assert code == 130
            assert proc.stderr.read().strip() == "gearsym: interrupted"
        else:
            assert code == -signum
    finally:
        _stop(proc)


@pytest.mark.slow
def test_the_workers_of_a_terminated_reproduce_end_with_it(tmp_path):
    proc = subprocess.Popen(
        [*REPRODUCE, str(tmp_path / "reproduce")],
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        _wait(lambda: len(_workers(proc.pid)) >= 2, 120, "the sweeps' workers")

        # Kill while the workers integrate, not while a C compiler they started runs (a
        # compiler is no worker: it would finish its file on its own and then end).
        def only_python():
            return all(name.startswith("python") for name in _group(proc.pid).values())

        _wait(only_python, 120, "the compiles to end")
        os.kill(proc.pid, signal.SIGTERM)
        assert proc.wait(timeout=60) == -signal.SIGTERM
        left = _gone_within(proc.pid, 5.0)
        assert not left, f"still running 5 s after SIGTERM: {left}"
    finally:
        _stop(proc)
