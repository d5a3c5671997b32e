"""``gearsym reproduce``: the reference study's analyses and an honest comparison.

For the light-load (f1 = 0.1) and heavy-load (f1 = 0.5) scenes: forward and backward
continuation sweeps over the load ratio lambda (bifurcation diagrams), the operating points
lambda = 0.1 and 0.8 (time series, phase portraits with Poincare points, spectra), and the
(f1, lambda) map of Max(u), Min(v) and the motion of v (the study's Table 2).  The report
puts each finding of the study beside what the toolkit found, with the evidence, and says
plainly where they differ.  Nothing here is tuned toward the study's findings: the values
the study leaves open are those of the shipped scenes, stated in their files.
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from gearsym.solver._json import dumps
from gearsym.solver.executor import map_tasks
from gearsym.solver.export import save_all
from gearsym.solver.integrate import fastest_method
from gearsym.solver.sweep import SweepJob, sweep_many
from gearsym.solver.sweep.progress import Stages, fmt_seconds
from gearsym.solver.system import System

from .bearings import bearing_jobs, bearings_section
from .cases import CASES, DEAD_ZONE, RESOLUTIONS, TOLERANCES
from .claims import Bundle
from .figures import figure_list
from .long_runs import lengthen_claims
from .memo import ResultStore
from .points import analyse_all, pick
from .report import FIGURES_MARK, STORED_MARK, graded, report, tally
from .sensitivity import STAGES as SENSITIVITY_STAGES
from .sensitivity import preparations as prepare_sensitivity
from .writer import Writer

__all__ = ["STAGES", "Reproduced", "reproduce", "verdict_words"]

# the stages of a run, in order, as the progress lines and the timings name them
STAGES = (
    "lambda sweeps and maps (points)",
    "runs the claims rest on, continued (runs)",
    "operating points, branches, responses (tasks)",
    "figures (figures)",
    *SENSITIVITY_STAGES,
    "report (sections)",
)


def verdict_words(counts: dict) -> str:
    """``{"agrees": 4, "partly": 2}`` -> ``'4 agree, 2 partly agree'``."""
    plural = {"agrees": "agree", "partly": "partly agree", "differs": "differ"}
    return ", ".join(f"{n} {plural.get(v, v)}" for v, n in counts.items())


@dataclass(frozen=True)
class Reproduced:
    """What a run of :func:`reproduce` wrote and how it went: the report's path, the
    count of each verdict per model (``{"polynomial": {"agrees": 3, ...}, ...}``), the
    wall time, ``(stage, seconds)`` per stage and how many units of work were loaded from
    the result store (:mod:`gearsym.studies.memo`)."""

    report: Path
    verdicts: dict
    seconds: float
    stages: tuple
    stored: str = ""  # how many units of work came from the result store

    def summary(self) -> str:
        """A few lines for the end of a run: the verdicts, the time, where things are."""
        lines = []
        for model, counts in self.verdicts.items():
            lines.append(f"findings of the study, {model}: {verdict_words(counts)}")
        folder = self.report.parent
        lines += [
            f"time: {fmt_seconds(self.seconds)}" + (f" ({self.stored})" if self.stored else ""),
            f"report: {self.report}",
            f"figures: {folder}/*.png, {folder / 'sensitivity'}/; data: {folder / 'data'}/",
        ]
        return "\n".join(lines)


def reproduce(
    out: Path,
    *,
    quick: bool = False,
    executor: str = "processes",
    workers: int | None = None,
    progress: bool = True,
    fresh: bool = False,
) -> Reproduced:
    """Run everything, write figures, data and ``report.md`` under ``out``; return the
    report's path, the verdicts' tally and how long each stage took.  Progress goes to
    stderr, one line per stage (:class:`~gearsym.solver.sweep.progress.Stages`).  Each
    unit of work is kept in the result store of the model cache and loaded from there
    by a run with the same code and inputs (:mod:`gearsym.studies.memo`); ``fresh``:
    compute every unit again (and keep the new results)."""
    res = RESOLUTIONS["quick" if quick else "full"]
    stages = Stages(len(STAGES), "reproduce", enabled=progress)
    writer = Writer()
    try:
        return _reproduce(out, quick, executor, workers, fresh, res, stages, writer)
    finally:
        writer.finish()


def _reproduce(out, quick, executor, workers, fresh, res, stages, writer) -> Reproduced:
    out = Path(out)
    (out / "data").mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    memo = ResultStore.in_cache(out, fresh=fresh)
    method = fastest_method(TOLERANCES["rtol"])
    settings = dict(
        TOLERANCES,
        method=method,
        transient=res.transient,
        periods=res.periods,
        lyapunov_periods=res.lyapunov_periods,
    )
    lam = np.round(np.linspace(0.0, 1.0, res.points), 10)
    systems = {case: System.load(module) for case, module, _ in CASES}
    # the exact dead zone the study's polynomial approximates, at each case's load
    dead = {case: System.load(DEAD_ZONE).with_values(f1=f1) for case, _, f1 in CASES}
    map_lam = np.round(np.linspace(0.0, 1.0, res.map_points), 10)

    def case_jobs(models):
        return [
            SweepJob(models[case], "lambda", lam, backward=backward, settings=settings)
            for case, _, _ in CASES
            for backward in (False, True)
        ]

    def map_jobs(model):
        return [
            SweepJob(model.with_values(f1=f1), "lambda", map_lam, settings=settings)
            for f1 in res.map_f1
        ]

    groups = {
        "cases": case_jobs(systems),
        "maps": map_jobs(systems["light"]),
        "bearings": bearing_jobs(lam, settings),  # the same sweeps on bearings (issue 15)
        "dead cases": case_jobs(dead),
        "dead maps": map_jobs(dead["light"]),
    }
    # Each sweep keeps its finished points under out/store, in a folder named by what
    # defines it (model, values, settings): a run stopped by Ctrl-C resumes from them,
    # and a run with other settings or another model starts a folder of its own.
    jobs = [
        replace(job, store=out / "store" / f"sweep_{_job_key(job)}")
        for group in groups.values()
        for job in group
    ]
    bar = stages.stage(
        STAGES[0], sum(len(j.values) for j in jobs), after="now the border runs, re-examined"
    )
    done = iter(_sweeps(jobs, memo, executor, workers, bar))
    got = {name: [next(done) for _ in group] for name, group in groups.items()}
    got = lengthen_claims(
        got,
        groups,
        settings,
        executor=executor,
        workers=workers,
        progress=lambda total: stages.stage(STAGES[1], total),
        memo=memo,
    )
    by_case = {case: got["cases"][2 * k : 2 * k + 2] for k, (case, _, _) in enumerate(CASES)}
    dead_case = {case: got["dead cases"][2 * k : 2 * k + 2] for k, (case, _, _) in enumerate(CASES)}
    bearing_sweeps, maps = got["bearings"], got["maps"]
    files = {"polynomial": {"sweep": {}, "point": {}, "bifurcation": {}}}
    files["dead zone"] = {"sweep": {}, "point": {}, "bifurcation": {}}
    for sw in got["cases"] + maps + bearing_sweeps:
        tag = f"{sw.model}_{sw.direction}_f1_{sw.base_values.get('f1', 'scene')}"
        writer.submit(save_all, sw, out / "data" / f"sweep_{tag}.json")
    for case, _, _ in CASES:
        files["polynomial"]["sweep"][case] = tuple(
            f"data/sweep_{sw.model}_{sw.direction}_f1_scene.json" for sw in by_case[case]
        )
        files["dead zone"]["sweep"][case] = tuple(
            f"data/sweep_{sw.model}_{sw.direction}_{case}.json" for sw in dead_case[case]
        )
        for sw, name in zip(dead_case[case], files["dead zone"]["sweep"][case], strict=True):
            writer.submit(save_all, sw, out / name)
    files["polynomial"]["map"] = "map_f1_lambda.png"
    files["dead zone"]["map"] = f"data/sweep_{DEAD_ZONE}_map_f1_*.json"
    for sw, f1 in zip(got["dead maps"], res.map_f1, strict=True):
        writer.submit(save_all, sw, out / "data" / f"sweep_{DEAD_ZONE}_map_f1_{f1}.json")
    files["dead zone"]["model_hash"] = dead["light"].model_hash
    from .figures import (
        backlash_figure,
        branch_png,
        call,
        floquet_figure,
        map_png,
        stiffness_figure,
        sweep_state_figure,
    )

    # figures of what the batch does not change, drawn by its workers (in this process
    # they kept both workers idle)
    start = "start: each mesh pressed into contact by its load, at rest; then each point from"
    plain = f"{systems['light'].name}, scene values (no overrides)"
    drawn = [
        (
            sweep_state_figure,
            (
                by_case[case],
                out / f"meshing_lyapunov_{case}.png",
                f"{case} load, f1 = {f1}: meshing state and largest Lyapunov exponent",
                f"{systems[case].name}, scene values (no overrides); {start} the previous "
                f"one's end state; {res.transient} + {res.periods} periods, {method} "
                f"rtol {TOLERANCES['rtol']:g}",
            ),
        )
        for case, _, f1 in CASES
    ]
    drawn += [
        (backlash_figure, (systems["light"], out / "backlash.png", plain)),
        (stiffness_figure, (systems["light"], out / "stiffness.png", plain)),
    ]
    sweeps = {"polynomial": by_case, "dead zone": dead_case}
    models = {"polynomial": systems, "dead zone": dead}
    # the light scene's Model (SymPy, about a second) for the model check and the
    # physical scales of the report, derived beside the batch rather than after it
    from .model_check import _model

    derived = writer.submit(_model, systems["light"].module.SCENE)
    done = analyse_all(
        sweeps,
        models,
        settings,
        out,
        files,
        quick=quick,
        executor=executor,
        workers=workers,
        progress=lambda total: stages.stage(STAGES[2], total),
        figures=drawn,
        # the sensitivity maps' models, derived and compiled while the branches and
        # responses run (its own stage then finds them in the cache)
        first=prepare_sensitivity(quick),
        memo=memo,
    )
    # the writer's files done before the figures: both are Python-heavy, and a thread
    # switching with the figures' text layout at every interval slowed them by half
    # (a repeated run, whose batch above is loaded in a second, met the writer here)
    writer.wait()
    from .mechanisms import mechanisms_section

    points, dead_points = pick(done, "polynomial", "sweep"), pick(done, "dead zone", "sweep")
    starts = {
        "polynomial": (dict(points), pick(done, "polynomial", "rest")),
        "dead zone": (dead_points, pick(done, "dead zone", "rest")),
    }
    points.update(pick(done, "polynomial", "chaotic"))
    # The figures of the batch's results are drawn by the workers, side by side (drawn
    # here, one after another, they left both workers idle for about 5 s of a first run)
    jobs = [
        (
            map_png,
            (
                np.array(res.map_f1),
                map_lam,
                [sw.maxima("u") for sw in maps],
                [sw.minima("v") for sw in maps],
                [sw.motion("v") for sw in maps],
                out / "map_f1_lambda.png",
            ),
        )
    ]
    branches = {case: done[("branches", case)] for case, _, _ in CASES}
    for case, _, f1 in CASES:
        title = f"{case} load, f1 = {f1}: periodic branches over the sweeps"
        jobs.append((branch_png, (branches[case], by_case[case], title, systems[case], out / case)))
        jobs.append(
            (
                floquet_figure,
                (
                    branches[case],
                    out / f"floquet_{case}.png",
                    f"{case} load, f1 = {f1}",
                    f"{systems[case].name}, scene values (no overrides); branches continued "
                    "both ways from the periodic points of the forward sweep",
                ),
            )
        )
        (out / "data" / f"continuation_{case}.json").write_text(
            dumps([b.describe() for b in branches[case]]), encoding="utf-8"
        )
    from .response import response_section, run_response

    responses = {k[1:]: r for k, r in done.items() if k[0] == "response"}
    response_rows = run_response(
        out,
        systems,
        CASES,
        points,
        quick=quick,
        done=responses,
        save=lambda result, path: writer.submit(save_all, result, path),
        figures=jobs,
    )
    bar = stages.stage(STAGES[3], len(jobs))
    map_tasks(call, jobs, executor=executor, workers=workers, on_result=lambda _: bar.step())
    from .report_sensitivity import sensitivity_section
    from .sensitivity import SCENES, physical_scales, run_sensitivity

    rows = run_sensitivity(
        out,
        res,
        settings,
        quick=quick,
        executor=executor,
        workers=workers,
        stages=stages,
        memo=memo,
    )
    bar = stages.stage(STAGES[6], 5)
    derived.result()  # the light scene's Model, derived by the writer's thread
    scales = physical_scales(SCENES["light"][0])
    section = sensitivity_section(rows, scales, {c: f1 for c, (_, f1) in SCENES.items()}, points)
    bar.step()
    elapsed = time.perf_counter() - started
    bundles = {
        "polynomial": Bundle("polynomial", by_case, points, maps, res.map_f1, files["polynomial"]),
        "dead zone": Bundle(
            "dead zone", dead_case, dead_points, got["dead maps"], res.map_f1, files["dead zone"]
        ),
    }
    found = graded(bundles, lam, res)
    text = report(res, lam, bundles, elapsed, quick, systems, branches, method, found=found)
    text = text.replace(STORED_MARK, memo.summary(), 1)
    head, sep, tail = text.partition("## Figures")
    bar.step()
    forward = [by_case[case][0] for case, _, _ in CASES]
    bearings = bearings_section(forward, bearing_sweeps, out)
    bar.step()
    from .model_check import model_check_section

    checked = model_check_section(systems, {case: f1 for case, _, f1 in CASES})
    bar.step()
    mechanisms = mechanisms_section(starts)
    bar.step()
    text = (
        head
        + checked
        + "\n"
        + mechanisms
        + "\n"
        + response_section(response_rows)
        + "\n"
        + section
        + "\n"
        + bearings
        + "\n"
        + sep
        + tail
    )
    text = text.replace(FIGURES_MARK, figure_list(out))
    writer.finish()  # every data file written before the report that names them
    path = out / "report.md"
    path.write_text(text, encoding="utf-8")
    stages.end()
    took = time.perf_counter() - started
    return Reproduced(path, tally(found), took, tuple(stages.times), memo.summary())


def _sweeps(jobs: list, memo, executor, workers, bar) -> list:
    """The sweep jobs' results: those the result store keeps loaded (their points counted
    on ``bar`` at once), the rest run by one :func:`sweep_many` and kept."""
    keys = [memo.key(sweep_many, replace(job, store=None)) for job in jobs]
    out, todo = memo.kept(keys, lambda k, _: bar.step("(result store)", n=len(jobs[k].values)))
    run = [jobs[k] for k in todo]
    ran = sweep_many(run, executor=executor, workers=workers, progress=bar) if run else []
    for k, result in zip(todo, ran, strict=True):
        memo.keep(keys[k], (result, None))
        memo.computed += 1
        out[k] = result
    return out


def _job_key(job: SweepJob) -> str:
    """16 hex digits of the sha256 of everything that defines a sweep job."""
    defining = {
        "model": job.system.model_hash,
        "base": job.system.values,
        "parameter": job.parameter,
        "values": [float(v) for v in job.values],
        "backward": job.backward,
        "settings": job.settings,
    }
    return hashlib.sha256(dumps(defining, sort_keys=True).encode()).hexdigest()[:16]
