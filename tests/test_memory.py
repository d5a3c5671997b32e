"""Bounded memory (issue 14): long runs stay within a fixed budget, whatever --periods.

The peak resident size of the command's own process is read from the kernel
(the resource usage of that child alone), with the figure and the JSON written.
The floors are the issue's: 300 MB at 20,000 sampled periods, 500 MB at 100,000 (before
the fix: 1.47 GB at 20,000, a crash at 100,000).
"""

from __future__ import annotations

import subprocess
import sys

import pytest

# A small interpreter starts the command and reports its peak: the command is forked
# from this small process, not from the test run (a forked child counts its parent's
# pages as resident until it execs).
_WRAP = """
import resource, subprocess, sys
code = subprocess.call([sys.executable, "-m", "gearsym.cli", *sys.argv[1:]],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
print(code, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
"""


def peak_mb(args: list[str], cwd) -> tuple[int, float]:
    """(exit code, peak resident MB) of ``gearsym args`` in its own process."""
    out = subprocess.run(
        [sys.executable, "-c", _WRAP, *args], cwd=cwd, capture_output=True, text=True, check=True
    ).stdout.split()
    return int(out[0]), int(out[1]) / 1024.0  # kB on Linux


@pytest.mark.slow
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
        [
            "simulate",
            scene,
            "--set",
            "lambda=0.05",
            "--periods",
            str(periods),
            "--lyapunov-periods",
            "0",
            "--out",
            str(tmp_path / "out"),
        ],
        tmp_path,
    )
    assert code == 0
    assert (tmp_path / "out" / "point.png").exists()
    assert mb < limit_mb, f"{mb:.0f} MB"
