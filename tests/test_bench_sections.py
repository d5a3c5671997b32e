"""``benchmarks/performance.py``: the appended sections (the user-facing sweep, the regime
map) land in the report with the floors side by side, without running the benchmark.

Reference: the fake result of ``test_bench_cli`` (made-up numbers in the shape of
``performance.run``'s), with a fake section result for the CLI sweep."""

from __future__ import annotations

from gearsym.benchmarks import performance

from .test_bench_cli import _fake_result

CLI = {
    "points": 400,
    "command": "gearsym sweep reference-light --param=lambda --range=0:1:400",
    "runs_s": [1.0, 1.2, 1.1],
    "median_s": 1.1,
    "ms_per_point": 2.75,
    "start_up_s": 0.3,
    "no_figure_runs_s": [0.9, 1.0, 0.8],
    "no_figure_median_s": 0.9,
    "baseline_s": 1100.0,
    "speedup": 1000.0,
    "motions": {"u": ["period-1", "period-3"]},
}


def test_the_cli_sweep_section_and_the_floors_table(tmp_path):
    res = {**_fake_result(True), "cli_sweep": CLI}
    report = tmp_path / performance.REPORT
    performance.write_doc(res, report)
    text = report.read_text(encoding="utf-8")
    assert "## Speed floors (issues 12 and 13), measured side by side in this run" in text
    assert "**1000×** (1.10 s against 1.1e+03 s)" in text
    assert "## The user-facing sweep, start-up included" in text
    assert "u: period-1, period-3" in text
    assert "## Regime maps" not in text  # not measured in this run: not written


def test_a_section_appended_to_the_list_is_measured_and_written(monkeypatch, tmp_path):
    seen = {}

    def measure(quick, res):
        seen["baseline"] = res["headline"]["baseline_s_per_point"]
        return {"value": 42}

    extra = performance.Section("extra", measure, lambda res: [f"extra: {res['extra']['value']}"])
    monkeypatch.setattr(performance, "SECTIONS", [extra])
    for name in ("headline", "throughput", "pareto", "features", "scaling"):
        monkeypatch.setattr(performance, name, lambda quick, name=name: _fake_result(quick)[name])
    res = performance.run(quick=True)
    assert res["extra"] == {"value": 42} and seen["baseline"] == 1.0
    performance.write_doc(res, tmp_path / performance.REPORT)
    assert "extra: 42" in (tmp_path / performance.REPORT).read_text(encoding="utf-8")


def test_the_response_section_and_its_floor_row():
    from gearsym.benchmarks.response import response_section

    method = {
        "median_s": 1.5,
        "curve_points": 634,
        "folds": [0.45838, 0.37922],
        "error": 6.8e-10,
        "checked": 8,
    }
    r = {
        "points": 400,
        "range": [0.3, 0.9],
        "hb": method,
        "shooting": dict(method),
        "integration": {**method, "settle": 50, "sampled": 16},
    }
    text = "\n".join(response_section(r))
    assert (
        "(floor of issue 13: 2 s), median | 1.50 | 634 | 0.45838, 0.37922 | 6.8e-10 (8) |" in text
    )
    rows = "\n".join(performance.floors_lines({"response": r}))
    assert "| ≤ 2 s | **1.50 s** |" in rows
