"""``gearsym bench``: where it writes and how it fails, without running the benchmark.

The benchmark itself takes minutes; here its ``run`` is replaced by one that raises (the
output checks must fail before any work) or by one returning a small fake result (the
report and figure must land in ``--out``, and the tracked ``docs/`` stay untouched).
"""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

import pytest
from gearsym.benchmarks import performance
from gearsym.cli import main
from gearsym.derive.build import project_root

DOCS = project_root() / "docs"


def _no_run(quick):
    raise AssertionError("the benchmark ran although the output was unusable")


def _fake_result(quick):
    """The shape of ``performance.run``'s result with made-up numbers."""
    row = {"method": "dop853", "nfev": 100, "window_periods": 30}
    return {
        "quick": quick,
        "date": "2000-01-01",
        "headline": defaultdict(lambda: 1.0),
        "throughput": defaultdict(lambda: 1.0),
        "pareto": [
            {**row, "setting": "rtol 1e-03", "error": 1e-3, "s_per_point": 0.01},
            {**row, "setting": "rtol 1e-06", "error": 1e-6, "s_per_point": 0.02},
        ],
        "features": [
            {
                "feature": "reference",
                "operations_rhs": 10,
                "ms_per_point": 1.0,
                "nfev_per_point": 100.0,
                "max_change_poincare_u_v": 0.0,
                "median_change_poincare_u_v": 0.0,
            }
        ],
        "scaling": {
            "sweep_size": [{"points": 1, "s": 0.1, "ms_per_point": 100.0}],
            "meshes": [
                {
                    "model": "siso",
                    "meshes": 1,
                    "operations_rhs": 10,
                    "compile_s": 1.0,
                    "ms_per_point": 1.0,
                    "nfev_per_point": 100.0,
                }
            ],
        },
    }


def _docs_state() -> dict[str, tuple[int, int]]:
    return {
        name: ((DOCS / name).stat().st_mtime_ns, (DOCS / name).stat().st_size)
        for name in (performance.REPORT, performance.FIGURE)
        if (DOCS / name).exists()
    }


def _one_line_error(capsys) -> str:
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith("gearsym: error: bench: ")
    assert "Traceback" not in captured.err
    return lines[0]


def test_benchmarks_is_an_installed_package():
    module = importlib.import_module("gearsym.benchmarks.performance")
    assert module.__name__ == "gearsym.benchmarks.performance"
    assert callable(module.main) and callable(module.run)
    # the C reference is package data beside the module, not looked up in a checkout
    assert (Path(module.__file__).parent / "lockstep_reference.c").is_file()
    for name in ("robustness", "deadzone_multipliers"):
        importlib.import_module(f"gearsym.benchmarks.{name}")


def test_docs_and_out_together_fail_in_one_line(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(performance, "run", _no_run)
    assert main(["bench", "--docs", "--out", str(tmp_path / "x")]) == 2
    line = _one_line_error(capsys)
    assert "--docs" in line and "--out" in line
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("kind", ["unwritable", "a file"])
def test_unusable_out_fails_before_the_benchmark(monkeypatch, capsys, tmp_path, kind):
    monkeypatch.setattr(performance, "run", _no_run)
    if kind == "unwritable":
        out = "/proc/gearsym-bench"  # nobody, not even root, can create a folder here
    else:
        out = str(tmp_path / "file")
        Path(out).write_text("not a folder", encoding="utf-8")
    assert main(["bench", "--quick", "--out", out]) == 2
    assert out in _one_line_error(capsys)


def test_docs_outside_a_checkout_fails_in_one_line(monkeypatch, capsys, tmp_path):
    import gearsym.derive.build

    monkeypatch.setattr(performance, "run", _no_run)
    monkeypatch.setattr(gearsym.derive.build, "project_root", lambda: tmp_path)
    assert main(["bench", "--docs"]) == 2
    assert "no docs/ folder" in _one_line_error(capsys)


def test_results_land_in_out_and_docs_stay_untouched(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(performance, "run", _fake_result)
    before = _docs_state()
    out = tmp_path / "new" / "bench"  # created, parents too
    assert main(["bench", "--quick", "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == sorted([performance.REPORT, performance.FIGURE])
    report = (out / performance.REPORT).read_text(encoding="utf-8")
    assert "Written by `gearsym bench --quick`" in report
    assert f"![Pareto]({performance.FIGURE})" in report
    assert (out / performance.FIGURE).read_bytes().startswith(b"\x89PNG")
    assert str(out / performance.REPORT) in capsys.readouterr().out
    assert _docs_state() == before


def test_default_out_is_bench_out_in_the_working_folder(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(performance, "run", _fake_result)
    monkeypatch.chdir(tmp_path)
    before = _docs_state()
    assert main(["bench", "--json"]) == 0
    assert (tmp_path / "bench-out" / performance.REPORT).is_file()
    assert (tmp_path / "bench-out" / performance.FIGURE).is_file()
    assert json.loads(capsys.readouterr().out)["date"] == "2000-01-01"
    assert _docs_state() == before


def test_docs_flag_writes_the_checkout_docs(monkeypatch, tmp_path):
    docs = tmp_path / "docs"
    docs.mkdir()
    monkeypatch.setattr(performance, "run", _fake_result)
    monkeypatch.setattr(performance, "checkout_docs", lambda: docs)
    assert main(["bench", "--docs"]) == 0
    report = (docs / performance.REPORT).read_text(encoding="utf-8")
    assert "Written by `gearsym bench --docs`" in report
    assert (docs / performance.FIGURE).is_file()


def test_help_names_the_output_options(capsys):
    with pytest.raises(SystemExit):
        main(["bench", "--help"])
    text = capsys.readouterr().out
    assert "--out DIR" in text and "--docs" in text and "bench-out" in text


def test_script_fails_in_one_line(tmp_path):
    done = subprocess.run(
        [sys.executable, "-m", "gearsym.benchmarks.performance", "--docs", "--out", "x"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=120,
    )
    assert done.returncode == 2
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert "--docs and --out" in done.stderr
    assert not (tmp_path / "x").exists()
