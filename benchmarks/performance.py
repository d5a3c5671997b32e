"""Speed and accuracy of every integration back end: writes performance.md and its figure.

Run: ``gearsym bench [--quick] [--json] [--out DIR | --docs]``, or the same options to
``python -m gearsym.benchmarks.performance`` (from a checkout also
``python benchmarks/performance.py``). The report ``performance.md`` and the figure
``performance-pareto.png`` go to ``--out DIR`` (default ``bench-out``, created if missing)
or, with ``--docs``, to the checkout's ``docs/`` (the tracked report). The folder is
checked for writing before the benchmark starts.

Sections (every timing a median of repeated runs on this machine, ratios measured in the
same run):

1. Headline: the light-load reference sweep over the load ratio (400 points, 300 transient
   + 100 sampled periods, rtol 1e-8) with the compiled batched DOP853, against the plain
   baseline a user would write (``solve_ivp(RK45)`` with a hand-written Python right-hand
   side; timed on a subset of the points and scaled to 400) and against the hand-written
   vectorised lockstep DOP853 in C of ``benchmarks/lockstep_reference.c``.
2. Throughput: right-hand-side evaluations per second of one-point-at-a-time integration.
3. Pareto: error of the Poincare points against a tight reference, time per point and
   evaluations, for every back end and tolerances 1e-3 ... 1e-12 (fixed-step methods: steps
   per period).
4. Feature cost: time and modelling error of each model feature.
5. Scaling with the sweep size and with the number of meshes; compile times.
6. Appended sections (:data:`SECTIONS`): the user-facing ``gearsym sweep`` of 400
   independent points as a user runs it (a new process each time, start-up included)
   against the baseline of section 1 measured in the same run; the 50 x 50 regime map
   (``benchmarks/atlas.py``); a table of the speed floors of issue 12 side by side.

This module runs the sections and writes the report; sections 1 to 5 are measured by
``backends.py``, section 6 by ``sections.py``, on the reference model, baseline and
hand-written C of ``baseline.py`` (their names are re-exported here).  The peers of the
compiled engine (JAX + diffrax) are measured by ``peers.py``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

# absolute, so that ``python benchmarks/performance.py`` runs too
from gearsym.benchmarks._output import OutputError, checkout_docs, output_folder, run_script
from gearsym.benchmarks.backends import (  # noqa: F401 (re-exported: the sections' names)
    ADAPTIVE,
    FEATURES,
    FIXED,
    features,
    headline,
    pareto,
    pareto_front,
    scaling,
    throughput,
)
from gearsym.benchmarks.baseline import (  # noqa: F401 (re-exported for floors.py, peers.py)
    _fmt,
    _median_time,
    _named,
    _reference,
    _reference_library,
    baseline_point,
    plain_rhs,
    reference_run,
)
from gearsym.benchmarks.sections import (  # noqa: F401 (re-exported)
    SECTIONS,
    SWEEP_POINTS,
    Section,
    cli_sweep,
    cli_sweep_lines,
    floors_lines,
)

REPORT = "performance.md"
FIGURE = "performance-pareto.png"
DEFAULT_OUT = "bench-out"


def write_doc(
    res: dict, path: Path, figure: Path | None = None, command: str | None = None
) -> None:
    """Write the report of ``run``'s result to ``path`` and, unless None, the Pareto
    figure to ``figure`` (the report links it by name, so keep both in one folder).
    ``command`` is the command the report says wrote it."""
    if command is None:
        command = f"gearsym bench{' --quick' if res['quick'] else ''}"
    h, th = res["headline"], res["throughput"]
    cpu = os.cpu_count()
    lines = [
        "# Performance: speed against accuracy",
        "",
        f"Written by `{command}` on "
        f"{res['date']} ({cpu} cores; the machine is shared, so every time is the median of "
        "repeated runs and every ratio is measured within the same run). "
        "Code: `benchmarks/performance.py`, `benchmarks/lockstep_reference.c`.",
        "",
        "## Headline: the light-load load-ratio sweep",
        "",
        f"{h['points']} values of λ on [0, 1], {h['transient_periods']} transient + "
        f"{h['sampled_periods']} sampled periods each, rtol 1e-8, atol 1e-10, the reference "
        "model (`reference_light`).",
        "",
        "| run | time for the sweep (s) | evaluations per point | max Poincaré error |",
        "|---|---|---|---|",
        f"| baseline: `solve_ivp(RK45)`, hand-written Python right-hand side "
        f"({h['baseline_points_timed']} points timed, × {h['points']}) | "
        f"{_fmt(h['baseline_s_400'])} | {h['baseline_nfev_per_point']:.0f} | "
        f"{_fmt(h['baseline_max_poincare_error'])} |",
        f"| the same with SciPy's DOP853 (the compiled method's algorithm) | "
        f"{_fmt(h['baseline_dop853_s_400'])} | {h['baseline_dop853_nfev_per_point']:.0f} | "
        f"{_fmt(h['baseline_dop853_max_poincare_error'])} |",
        f"| compiled batched DOP853 (`gearsym.solver.integrate.native`), 1 core | "
        f"{_fmt(h['compiled_1_core_s'])} | {h['compiled_nfev_per_point']:.0f} | "
        f"{_fmt(h['compiled_max_poincare_error'])} |",
        f"| compiled batched DOP853, 2 processes | {_fmt(h['compiled_2_cores_s'])} | | |",
        f"| hand-written vectorised lockstep DOP853 in C, 1 core | {_fmt(h['reference_c_s'])} | "
        f"{h['reference_c_nfev_per_point']:.0f} | {_fmt(h['reference_c_max_poincare_error'])} |",
        "",
        f"**Speed-up over the baseline: {h['speedup_1_core']:.0f}× on one core, "
        f"{h['speedup_2_cores']:.0f}× on two**; over the same plain right-hand side under "
        f"SciPy's DOP853 (same algorithm as the compiled run, so the ratio is what compiling "
        f"and batching alone bring): {h['speedup_1_core_vs_dop853_baseline']:.0f}× on one core. "
        f"The compiled backend takes {h['over_reference_1_core']:.2f}× the time of the "
        f"hand-written C. Poincaré errors against {h['accuracy_reference']} (which agrees with "
        "SciPy's DOP853 at rtol 1e-13 to about 2e-10 over this window). Two-core times vary "
        "most with the machine's other load.",
        "",
        "## Throughput of one-point-at-a-time integration",
        "",
        f"- right-hand side alone (C loop): {th['rhs_only_evals_per_s'] / 1e6:.1f} million "
        "evaluations per second;",
        f"- DOP853 one point at a time (what continuation sweeps use): "
        f"{th['one_point_dop853_evals_per_s'] / 1e6:.1f} million evaluations per second, "
        f"{th['one_point_dop853_ms_per_point']:.2f} ms per 400-period point.",
        "",
        "## Speed against accuracy, every back end",
        "",
        f"Error: largest difference of the Poincaré points from SciPy's Radau at rtol 1e-12 "
        "(an implicit method, independent of the explicit ones measured), "
        f"over λ points spread on [0.1, 0.9] and a {res['pareto'][0]['window_periods']}-period "
        "window; time per point (median). Adaptive methods at atol = rtol/100; fixed-step ones "
        "by steps per period. A method stops at the first setting slower than 5 s per point.",
        "",
    ]
    if figure is not None:
        lines += [f"![Pareto]({figure.name})", ""]
    lines += [
        "| method | setting | max error | s per point | evaluations |",
        "|---|---|---|---|---|",
    ]
    front = {(r["method"], r["setting"]) for r in pareto_front(res["pareto"])}
    for r in res["pareto"]:
        mark = " **(Pareto)**" if (r["method"], r["setting"]) in front else ""
        lines.append(
            f"| {r['method']} | {r['setting']}{mark} | {_fmt(r['error'])} | "
            f"{_fmt(r['s_per_point'])} | {r['nfev']} |"
        )
    lines += [
        "",
        "## What each model feature costs",
        "",
        "Compiled batched DOP853 over λ ∈ [0, 1]; the change is the largest (and median) "
        "difference of the Poincaré points of u and v from the reference model at the same λ "
        "(the modelling effect of the feature, not an integration error).",
        "",
        "| model | rhs operations | ms per point | evaluations per point | max change | "
        "median change |",
        "|---|---|---|---|---|---|",
    ]
    for r in res["features"]:
        lines.append(
            f"| {r['feature']} | {r['operations_rhs']} | {r['ms_per_point']:.2f} | "
            f"{r['nfev_per_point']:.0f} | {_fmt(r['max_change_poincare_u_v'])} | "
            f"{_fmt(r['median_change_poincare_u_v'])} |"
        )
    sc = res["scaling"]
    lines += [
        "",
        "## Scaling",
        "",
        "| sweep points | s | ms per point |",
        "|---|---|---|",
        *(f"| {r['points']} | {r['s']:.3f} | {r['ms_per_point']:.2f} |" for r in sc["sweep_size"]),
        "",
        "| model | meshes | rhs operations | compile (s, once per model) | ms per point | "
        "evaluations per point |",
        "|---|---|---|---|---|---|",
        *(
            f"| {r['model']} | {r['meshes']} | {r['operations_rhs']} | {r['compile_s']:.2f} | "
            f"{r['ms_per_point']:.2f} | {r['nfev_per_point']:.0f} |"
            for r in sc["meshes"]
        ),
        "",
    ]
    lines += floors_lines(res)
    for section in SECTIONS:
        if section.name in res:
            lines += section.write(res)
    path.write_text("\n".join(lines), encoding="utf-8")
    if figure is not None:
        _plot(res["pareto"], figure)


def _plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    for method in dict.fromkeys(r["method"] for r in rows):
        pts = [
            (r["s_per_point"], r["error"])
            for r in rows
            if r["method"] == method and math.isfinite(r["error"]) and r["error"] > 0
        ]
        if pts:
            x, y = zip(*pts, strict=True)
            ax.loglog(x, y, "o-", ms=3, lw=1, label=method)
    ax.set_xlabel("seconds per sweep point")
    ax.set_ylabel("max error of the Poincaré points")
    ax.legend(fontsize=8, ncol=2)
    ax.grid(True, which="major", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110, metadata={"Software": None})
    plt.close(fig)


def run(quick: bool) -> dict:
    res = {"quick": quick, "date": time.strftime("%Y-%m-%d")}
    steps = [
        ("headline", headline),
        ("throughput", throughput),
        ("pareto", pareto),
        ("features", features),
        ("scaling", scaling),
    ]
    steps += [(s.name, lambda quick, s=s: s.measure(quick, res)) for s in SECTIONS]
    for name, fn in steps:
        started = time.perf_counter()
        print(f"bench: {name} ...", file=sys.stderr, flush=True)
        res[name] = fn(quick)
        print(f"bench: {name} done in {time.perf_counter() - started:.0f} s", file=sys.stderr)
    return res


def output_files(out: Path | str | None = None, *, docs: bool = False) -> tuple[Path, Path]:
    """The report and figure paths: in ``out`` (default ``bench-out``) or, with ``docs``,
    in the checkout's ``docs/``; the folder is created if missing and checked for writing.

    Raises :class:`OutputError` (one line) when both are given, outside a checkout with
    ``docs``, or when the folder cannot be written.
    """
    if docs and out is not None:
        raise OutputError(
            "--docs and --out both given: --docs writes the checkout's docs/, --out DIR "
            "another folder; give one"
        )
    folder = checkout_docs() if docs else Path(DEFAULT_OUT if out is None else out)
    folder = output_folder(folder, (REPORT, FIGURE))
    return folder / REPORT, folder / FIGURE


def main(argv: list[str] | None = None) -> int:
    """``gearsym bench``: check the output folder, run, write the report and figure.

    Raises :class:`OutputError` before any benchmark runs when the output is unusable.
    """
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer points and repeats")
    parser.add_argument("--json", action="store_true", help="also print every figure as JSON")
    parser.add_argument("--out", type=Path, metavar="DIR", help=f"default {DEFAULT_OUT}")
    parser.add_argument("--docs", action="store_true", help="write the checkout's docs/")
    args = parser.parse_args(argv)
    report, figure = output_files(args.out, docs=args.docs)
    res = run(args.quick)
    command = "gearsym bench" + " --quick" * args.quick + " --docs" * args.docs
    write_doc(res, report, figure, command)
    if args.json:
        from gearsym.solver._json import dumps

        print(dumps(res, indent=2))
    else:
        print(f"wrote {report} and {figure}")
    return 0


if __name__ == "__main__":
    run_script(main)
