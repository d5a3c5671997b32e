"""Bounded memory (issue 14): long runs stay within a fixed budget, whatever --periods.

The peak resident size of the command's own process is read from the kernel
(``wait4``'s resource usage of that child alone), with the figure and the JSON written.
The floors are the issue's: 300 MB at 20,000 sampled periods, 500 MB at 100,000 (before
the fix: 1.47 GB at 20,000, a crash at 100,000).
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest


def peak_mb(args: list[str], cwd) -> tuple[int, float]:
    """(exit code, peak resident MB) of ``gearsym args`` in its own process."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "gearsym.cli", *args],
        cwd=cwd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return proc.returncode, usage.ru_maxrss / 1024.0  # kB on Linux


@pytest.mark.skipif(sys.platform != "linux", reason="ru_maxrss is in kB on Linux only")
@pytest.mark.parametrize(
    "scene,periods,limit_mb",
    [
        ("reference-light", 20_000, 300),
        ("reference-dead-zone", 20_000, 300),  # the piecewise model, point by point
        ("reference-light", 100_000, 500),
    ],
)
def test_long_runs_stay_under_the_memory_floor(tmp_path, scene, periods, limit_mb):
    code, mb = peak_mb(
        ["simulate", scene, "--set", "lambda=0.05", "--periods", str(periods),
         "--lyapunov-periods", "0", "--out", str(tmp_path / "out")],
        tmp_path,
    )  # fmt: skip
    assert code == 0
    assert (tmp_path / "out" / "point.png").exists()
    assert mb < limit_mb, f"{mb:.0f} MB"
