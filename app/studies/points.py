"""The operating points and periodic branches of ``gearsym reproduce``, as one batch.

After the sweeps, these runs are independent of each other:

* the operating points lambda = 0.1 and 0.8 of each case in both models, each from the end
  state of the forward sweep's run before it, with the long budget (claims rest on them);
* the same points started from the loaded rest state (the module's default), to say which
  coexisting solution a start from rest reaches;
* the first point of each case's polynomial sweeps judged chaotic, from where its run ended;
* the continuation of every periodic branch each case's forward sweep visits.

* the period-1 frequency responses (harmonic balance) of both cases at both operating
  points, and the bifurcation diagrams.

They go to the workers as one batch, each figure drawn by the worker that made its data
(one stage at a time in the main process, this part of ``reproduce`` kept a core idle).
"""

from __future__ import annotations

import numpy as np
from gearsym.solver._json import dumps
from gearsym.solver.analysis import analyse_point
from gearsym.solver.periodic import ShootingError, continue_orbit
from gearsym.solver.sweep import map_tasks
from gearsym.solver.system import System

from .cases import CASES
from .long_runs import LONG_BUDGET

__all__ = ["OPERATING", "analyse_all", "pick"]

OPERATING = (0.1, 0.8)  # the study's operating points (lambda)
MODELS = ("polynomial", "dead zone")
TAGS = {"polynomial": ("", "the polynomial"), "dead zone": ("deadzone_", "the exact dead zone")}


def analyse_all(sweeps: dict, models: dict, settings: dict, out, files: dict, **batch):
    """Every run of the batch, each point's figure and data written by its worker.

    Parameters
    ----------
    sweeps : dict
        ``{model: {case: (forward, backward)}}`` for the models of :data:`MODELS`.
    models : dict
        ``{model: {case: System}}``.
    out : Path
        Where figures go (data under ``out/data``); their names go into ``files[model]``.
    batch : dict
        ``quick``, ``executor``, ``workers``; optional ``progress``: ``progress(total)`` ->
        a :class:`~gearsym.solver.sweep.progress.Progress` of the tasks; optional
        ``figures``: ``(function, args)`` pairs (module-level functions that draw and save
        a figure from data the batch does not change), drawn by the workers beside the runs;
        optional ``first``: ``(function, args)`` pairs called by the workers before every
        run (work that is long on a clean cache, such as deriving and compiling models,
        which at the end of the batch kept one worker busy while the other waited);
        optional ``memo``: a :class:`~gearsym.studies.memo.ResultStore` the tasks are loaded
        from where it keeps them, and kept in.

    Returns
    -------
    dict
        ``(model, "sweep" | "rest" | "chaotic", case, lambda) -> PointResult``,
        ``("branches", case) -> list of Branch`` (the polynomial model's) and
        ``("response", case, lambda) -> FrequencyResponse`` (harmonic balance over omega,
        ``response.RANGE``).
    """
    from .response import LAMBDAS, RANGE, resolution

    keys, tasks = [], []
    for k, call in enumerate(batch.get("first", ())):  # long on a clean cache: first
        keys.append(("figure", "first", k))
        tasks.append(("call", call))
    step = 0.05 if batch["quick"] else 0.02
    long = dict(settings, budget=LONG_BUDGET)
    for case, module, _ in CASES:  # the longest tasks first
        forward = sweeps["polynomial"][case][0]
        keys.append(("branches", case))
        tasks.append(("continue", (module, forward.points, list(forward.values), step)))
    num, harmonics = resolution(batch["quick"])
    for case, _, _ in CASES:
        for lam in LAMBDAS:
            at = models["polynomial"][case].with_values(**{"lambda": lam})
            keys.append(("response", case, lam))
            tasks.append(("response", (at, RANGE, num, harmonics)))
    for model in MODELS:
        tag, named = TAGS[model]
        for case, _, f1 in CASES:
            system = models[model][case]
            name = f"bifurcation_{tag}{case}.png"
            files[model]["bifurcation"][case] = name
            title = f"{case} load, f1 = {f1}, {named}: Poincaré points against lambda"
            keys.append(("figure", model, case))
            tasks.append(
                ("bifurcation", (sweeps[model][case], out / name, title, models[model][case]))
            )
            forward = sweeps[model][case][0]
            for value in OPERATING:
                k = int(np.argmin(np.abs(forward.values - value)))
                x0 = forward.points[k - 1].x_final if k > 0 else None
                at = system.with_values(**{"lambda": value})
                stem = f"point_{tag}{case}_lambda_{value}"
                files[model]["point"][(case, value)] = (f"{stem}.png", f"data/{stem}.json")
                title = f"{case} load (f1 = {f1}), {named}, lambda = {value}"
                draw = (out / f"{stem}.png", title, out / "data" / f"{stem}.json")
                keys += [(model, "sweep", case, value), (model, "rest", case, value)]
                tasks += [("point", (at, x0, long, draw)), ("point", (at, None, long, None))]
    for case, pair in sweeps["polynomial"].items():
        hit = next((p for sw in pair for p in sw.points if p.motion("u") == "chaotic"), None)
        if hit is not None:
            value = hit.values["lambda"]
            at = models["polynomial"][case].with_values(**{"lambda": value})
            path = out / f"point_chaotic_{case}_lambda_{value:.4g}.png"
            title = f"{case} load, lambda = {value:.4g}: a point the sweep judged chaotic"
            keys.append(("polynomial", "chaotic", case, value))
            tasks.append(("point", (at, hit.x_final, settings, (path, title, None))))
    for k, call in enumerate(batch.get("figures", ())):  # short: after the runs
        keys.append(("figure", "call", k))
        tasks.append(("call", call))
    progress = batch.get("progress")
    bar = progress(len(tasks)) if progress is not None else None
    memo = batch.get("memo")  # a ResultStore: the tasks it keeps are loaded from it
    run = map_tasks if memo is None else memo.map
    done = run(_run, tasks, executor=batch["executor"], workers=batch["workers"], on_result=bar)
    return {k: r for k, r in zip(keys, done, strict=True) if k[0] != "figure"}


def _run(task: tuple):
    """Worker: one task of :func:`analyse_all`."""
    from gearsym.solver import plots

    kind, args = task
    if kind == "call":
        function, call_args = args
        function(*call_args)
        return None
    if kind == "continue":
        return _continue_case(*args)
    if kind == "response":
        from gearsym.solver.sweep.frequency import frequency_response

        system, (lo, hi), num, harmonics = args
        return frequency_response(system, "omega", lo, hi, points=num, harmonics=harmonics)
    if kind == "bifurcation":
        sweeps, path, title, system = args
        fig = plots.bifurcation_diagram(sweeps, ["u", "v"], title=title, system=system)
        plots.save_figure(fig, path)
        return None
    system, x0, options, draw = args
    result = analyse_point(system, x0, **options)
    if draw is not None:
        path, title, data = draw
        plots.save_figure(plots.point_figure(result, title=title), path)
        if data is not None:
            data.write_text(dumps(result.describe()), encoding="utf-8")
    return result


def _continue_case(module: str, sweep_points, values, step: float) -> list:
    """Every periodic branch the forward sweep visits, continued both ways over [0, 1]."""
    system = System.load(module)
    branches, seen = [], set()
    for value, point in zip(values, sweep_points, strict=True):
        motion = point.motion("u")
        if not motion.startswith("period-") or motion in seen:
            continue
        seen.add(motion)
        n = point.period("u")
        x0 = point.poincare_state(system.states)
        for target in (1.0, 0.0):  # both ways from where the sweep found it
            if target == float(value):
                continue  # no branch of zero length
            try:
                br = continue_orbit(
                    system, "lambda", float(value), target, x0, n=n, ds=step, ds_max=4 * step
                )
            except ShootingError:
                continue
            if len(br.values) > 1:
                branches.append(br)
    return branches


def pick(done: dict, model: str, kind: str) -> dict:
    """``(case, lambda) -> PointResult`` of one model and kind of run."""
    return {(k[2], k[3]): r for k, r in done.items() if k[0] == model and k[1] == kind}
