"""File-system failures that cannot be checked before computing (issue 14): an unwritable
cache falls back with one warning, and a disk that fills up during a sweep ends in one
line naming the file, with the finished points kept for the next run."""

from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

GEARSYM = [sys.executable, "-m", "gearsym.cli"]


def test_an_unwritable_cache_falls_back_to_a_temporary_folder_with_one_warning(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("x", encoding="utf-8")
    env = os.environ | {"GEARSYM_CACHE": str(blocker / "cache")}
    run = subprocess.run(
        [
            *GEARSYM,
            "simulate",
            "reference-light",
            "--periods",
            "5",
            "--transient",
            "5",
            "--lyapunov-periods",
            "0",
        ],
        capture_output=True,
        text=True,
        env=env,
        cwd=tmp_path,
    )
    assert run.returncode == 0, run.stderr
    # the note on the polynomial backlash (issue 25) aside
    lines = [ln for ln in run.stderr.splitlines() if ln.strip() and "gearsym: note:" not in ln]
    assert len(lines) == 1 and lines[0].startswith("gearsym: warning: the cache"), lines
    assert str(blocker / "cache") in lines[0] and "GEARSYM_CACHE" in lines[0]


def _small_files():
    # Files may grow to 200 kB only: the write that passes it fails with EFBIG, as a full
    # disk fails with ENOSPC (SIGXFSZ ignored, so the write returns the error).
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (200_000, 200_000))


def test_a_full_disk_during_a_sweep_is_one_line_and_keeps_the_finished_points(tmp_path):
    out = tmp_path / "sweep"
    args = [
        *GEARSYM,
        "sweep",
        "reference-light",
        "--param",
        "lambda",
        "--range",
        "0:1:40",
        "--transient",
        "20",
        "--periods",
        "1200",
        "--lyapunov-periods",
        "0",
        "--out",
        str(out),
        "--quiet",
        "--no-figure",
    ]
    full = subprocess.run(args, capture_output=True, text=True, preexec_fn=_small_files)
    lines = [ln for ln in full.stderr.splitlines() if ln.strip()]
    assert full.returncode == 2, full.stderr
    assert len(lines) == 1 and "Traceback" not in full.stderr, full.stderr
    assert "sweep.json" in lines[0] and "finished work is kept" in lines[0], lines[0]
    stored = list((out / "store" / "points").glob("*.json"))
    assert stored  # the points computed before the failure are on disk
    again = subprocess.run(args, capture_output=True, text=True)
    assert again.returncode == 0, again.stderr
    assert "resumed: 40 of 40 points" in again.stdout
    assert Path(out / "sweep.json").stat().st_size > 200_000
