"""Where the study's findings live in the values it leaves open (issue 12, point 6).

For each open value the derive layer offers (``gearsym.derive.input.open_values``), a regime map
over lambda by that value, at both loads and in both readings of the loads, from three
initial states so that coexisting attractors show.  Each value is a new derivation
(cached); the built-in scenes keep their stated values, which are always among the values
tried.  Nothing is tuned: the values tried are a fixed spread round the stated one, chosen
before any run.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .long_runs import lengthen_carriers

__all__ = [
    "OPEN_SPREAD",
    "FINDINGS",
    "Sensitivity",
    "physical_scales",
    "preparations",
    "run_sensitivity",
]

# key -> (values tried, stated value of the built-in scenes, unit); text values (a damping
# normalisation, a backlash model) are mapped over their index and labelled by name
OPEN_SPREAD = {
    # a uniform 2.5 um grid up to four times the stated 5 um, and 50 um (one half backlash)
    "te_amplitude_um": ((0.0, 2.5, 5.0, 7.5, 10.0, 12.5, 15.0, 20.0, 50.0), 5.0, "µm"),
    # the q-g mesh's error against the p-g mesh's, a quarter turn apart
    "te_phase_deg_qg": ((0.0, 90.0, 180.0, 270.0), 0.0, "°"),
    "flywheel_inertia_kg_m2": ((1.0, 10.0, 100.0), 10.0, "kg m²"),
    "layout_angle_deg": ((0.0, 60.0, 120.0, 180.0), 120.0, "°"),
    "stiffness_harmonic_scale": ((0.0, 1.0, 2.0), 1.0, "×"),
    "damping_normalisation": (("mesh", "modal"), "mesh", "text"),
    # not open (the study states its 7th-order fit), but the fit's error is a modelling
    # choice a reader will ask about: the exact dead zone it approximates beside it
    "backlash": (("polynomial", "dead-zone"), "polynomial", "model"),
}
QUICK_SPREAD = {"te_amplitude_um": ((5.0, 50.0), 5.0, "µm")}
# the two readings of the loads (topologies/diso.toml [[reading]]); every row is mapped in
# both, the built-in scenes' reading first
READINGS = ("q-braking", "both-driving")
# the scene that models each backlash choice (same values otherwise; f1 set per load)
BACKLASH_SCENES = {"polynomial": None, "dead-zone": "reference-dead-zone"}

# Findings per load, each a test on the set of attractors (motion of u / v) at each lambda.
# (case, name, coordinate, motion test, lambda range where the study reports it)
FINDINGS = {
    "light": (
        ("u quasi-periodic at low λ", "u", "quasi", (0.0, 0.57)),
        ("v chaotic at low λ", "v", "chaotic", (0.0, 0.3)),
    ),
    "heavy": (
        ("u quasi-periodic at low λ", "u", "quasi", (0.0, 0.13)),
        ("v chaotic at low λ", "v", "chaotic", (0.0, 0.3)),
        ("u period-3 at high λ", "u", "period-3", (0.13, 1.0)),
    ),
}
# Both loads on the light scene's model, f1 set: the reference-heavy scene differs from
# reference-light only in its stated f1 (a parameter), so one derivation of each variant
# and one compiled library serve both loads (the heavy scene's own variants were the
# same equations derived and compiled a second time)
SCENES = {"light": ("reference-light", 0.1), "heavy": ("reference-light", 0.5)}
# the stages of run_sensitivity, as its progress lines name them
STAGES = (
    "sensitivity: models derived and compiled (models)",
    "sensitivity: regime maps, long runs and figures (maps)",
)


@dataclass
class Sensitivity:
    case: str
    key: str
    values: tuple
    stated: float
    unit: str
    motions: dict  # value -> sorted motion types (u and v) over every lambda and attractor
    critical: dict  # value -> critical lambda of v (nan: none, 0: periodic everywhere)
    reproduced: dict  # finding -> list of values that reproduce it
    failed: int  # attractor records whose runs failed (e.g. left the valid range)
    figures: list
    reading: str = "q-braking"
    carriers: dict = field(default_factory=dict)  # finding -> (runs, "run a to b periods")


def _matches(motion: str, test: str) -> bool:
    return motion.startswith(test) if test != "period-3" else motion == "period-3"


def is_text(values) -> bool:
    return any(isinstance(v, str) for v in values)


def _load_value(scene: str, f1: float, reading: str, key: str, value):
    """The System of ``scene`` in ``reading`` with the open value ``key`` = ``value``
    (one derivation, cached, where ``key`` is not a parameter of the model; ``key``
    None: the scene's own model in ``reading``)."""
    from gearsym.resolve import load

    if key is None:
        return load(scene, load_reading=reading, f1=f1)
    if key == "backlash":
        return load(BACKLASH_SCENES[value] or scene, load_reading=reading, f1=f1)
    return load(scene, load_reading=reading, f1=f1, **{key: value})


def _prepare(args: tuple) -> None:
    """Worker: derive one model of the sensitivity maps and compile the libraries its
    runs take (with the variational system the exponent needs) into the caches, so that
    the maps find them there: one per kind of map column the model has rows in (its
    y values at one lambda: :func:`_column_shares`) and the one-point library of the
    re-examined runs.  A missing compiler is left to the map, which decides and warns
    once.  ``args``: ``(scene, f1, reading, key, value, quick)``."""
    from gearsym.solver.integrate.native.build import NativeUnavailable, library, single_point

    *which, quick = args
    system = _load_value(*which)
    module = system.module
    try:
        for shared in _column_shares(system, which, quick):
            library(module, variational=True, shared=shared)
        library(module, variational=True, shared=single_point(module))
    except NativeUnavailable:
        pass


def _column_shares(system, which: tuple, quick: bool) -> list:
    """The ``shared`` of the library of each kind of map column the model of ``which`` =
    ``(scene, f1, reading, key, value)`` has more than one row in
    (``engine.batch_shared``): the scene's own model holds a whole column of every map
    whose value is a parameter of it; a model derived for one value holds one row (the
    one-point library)."""
    from gearsym.solver.integrate.native.engine import batch_shared
    from gearsym.solver.integrate.spec import RunSpec

    from .cases import RESOLUTIONS

    scene, f1, reading, key, _ = which
    if key is not None:
        return []
    res = RESOLUTIONS["quick" if quick else "full"]
    spec = RunSpec(transient=res.transient, periods=res.periods)
    out = []
    for k, (values, _, _) in (QUICK_SPREAD if quick else OPEN_SPREAD).items():
        if is_text(values) or _derives(system.module, k, values[0]):
            continue
        P = [_load_value(scene, f1, reading, k, v).with_values(**{"lambda": 0.5}).p for v in values]
        out.append(batch_shared(system.module, np.array(P), spec))
    return list(dict.fromkeys(out))


def preparations(quick: bool) -> list:
    """``(function, args)`` pairs that derive and compile every model of the maps, one per
    scene and load reading (module-level, for a worker): ``gearsym reproduce`` hands them
    to its batch of operating points, where they keep a worker busy while the frequency
    responses run (derived here, one after another in the main process, they left both
    workers idle for about 40 s of a first run)."""
    scenes = dict((scene, f1) for scene, f1 in reversed(SCENES.values()))  # one per scene
    return [
        (_prepare_reading, (scene, f1, reading, quick))
        for scene, f1 in scenes.items()
        for reading in READINGS
    ]


def _prepare_reading(scene: str, f1: float, reading: str, quick: bool) -> None:
    """Worker: the scene's model in ``reading`` and every model its maps derive, each
    derived and compiled into the caches (:func:`_prepare`)."""
    spread = QUICK_SPREAD if quick else OPEN_SPREAD
    _prepare((scene, f1, reading, None, None, quick))
    base = _load_value(scene, f1, reading, None, None).module
    for key, (values, _, _) in spread.items():
        for value in values:
            if _derives(base, key, value):
                _prepare((scene, f1, reading, key, value, quick))


def _resolver(scene: str, f1: float, reading: str, key: str, values: tuple):
    """The System of one map point: one derivation per value of ``key`` (cached), in
    ``reading``; a text value arrives as its index in ``values``."""
    memo: dict = {}
    text = is_text(values)

    def resolve(point: dict):
        v = point[key]
        if v not in memo:
            value = values[int(round(v))] if text else v
            memo[v] = _load_value(scene, f1, reading, key, value)
        return memo[v].with_values(**{k: x for k, x in point.items() if k != key})

    return resolve


def _critical(records, lam_values, value, key) -> float:
    """Smallest lambda past which every attractor of v is periodic (nan: never); runs
    that failed (left the polynomial's valid range) are not attractors and not counted."""
    ok = []
    for lam in lam_values:
        here = [
            r for r in records if r["lambda"] == lam and r[key] == value and r["status"] == "ok"
        ]
        ok.append(bool(here) and all(r["motion"]["v"].startswith("period-") for r in here))
    for k in range(len(ok)):
        if all(ok[k:]):
            return float(lam_values[k])
    return float("nan")


def _named(records, key, values):
    """Records with a text axis's index replaced by the text it stands for."""
    if not is_text(values):
        return records
    return [{**r, key: values[int(round(r[key]))]} for r in records]


def _derives(module, key: str, value) -> bool:
    """Whether ``load`` derives a model of its own for ``key`` = ``value`` (an open value
    of the derivation) rather than setting it as a parameter of ``module`` (the generated
    model of the map's scene and reading)."""
    if key == "backlash":
        return True
    from gearsym.resolve import split_open_values

    return bool(split_open_values({key: value}, module)[0])


def run_sensitivity(
    out: Path, res, settings: dict, *, quick, executor, workers, stages=None, memo=None
):
    """Regime maps over lambda by each open value at both loads, in both load readings;
    figures and data under ``out``; a list of :class:`Sensitivity` rows.  ``stages``: a
    :class:`~gearsym.solver.sweep.progress.Stages` the two stages (models, maps) report to;
    ``memo``: a :class:`~gearsym.studies.memo.ResultStore` the maps are loaded from where
    it keeps them (then their models are not prepared) and kept in."""
    from gearsym.resolve import load
    from gearsym.solver.sweep import map_tasks
    from gearsym.solver.sweep.progress import Stages

    stages = stages or Stages(2, "sensitivity", enabled=False)
    spread = QUICK_SPREAD if quick else OPEN_SPREAD
    lam = np.round(np.linspace(0.0, 1.0, 6 if quick else 11), 10)
    (out / "sensitivity").mkdir(parents=True, exist_ok=True)
    tasks = [
        (out, res, settings, lam, case, scene, f1, reading, key, spread[key])
        for case, (scene, f1) in SCENES.items()
        for reading in READINGS
        for key in spread
    ]
    # Every model of every map derived and compiled first, side by side (one at a time in
    # this process they kept the workers idle for about half of the stage); a value that
    # is a parameter of the generated model needs no model of its own.  A repeated run
    # that loads every map from the result store needs none of them.
    every: dict = {}
    if memo is None or not all(memo.has(memo.key(_map_task, t)) for t in tasks):
        base = {
            (s, r): load(s, load_reading=r).module for s, _ in SCENES.values() for r in READINGS
        }
        for scene, f1 in SCENES.values():
            for reading in READINGS:
                for key, (values, _, _) in spread.items():
                    for value in values:
                        own = not _derives(base[scene, reading], key, value)
                        k, v = (None, None) if own else (key, value)  # own: the scene's model
                        # one per model: the two loads differ only in f1, a parameter
                        every.setdefault((scene, reading, k, v), (scene, f1, reading, k, v, quick))
    bar = stages.stage(STAGES[0], len(every))
    map_tasks(_prepare, list(every.values()), executor=executor, workers=workers, on_result=bar)
    # Then each map, its long runs and its figures as one task of a worker (serial inside):
    # the workers share the maps, not the columns of one map, so no core waits for the
    # end of a map's chains, and no process pool is started per map.  The costliest
    # first (:func:`_cost`), so that no long map is left to run alone at the end.
    order = sorted(range(len(tasks)), key=lambda k: -_cost(tasks[k][-1][0]))
    bar = stages.stage(STAGES[1], len(tasks))
    run = map_tasks if memo is None else memo.map
    done = run(
        _map_task, [tasks[k] for k in order], executor=executor, workers=workers, on_result=bar
    )
    rows = [None] * len(tasks)
    for k, row in zip(order, done, strict=True):
        rows[k] = row
    return rows


# A row of the exact dead zone costs about four rows of the polynomial in these maps: a
# piecewise force law runs each point alone, not in lock-step groups (integrate.run).
# Measured on a first reproduce: the light scene's backlash map (one row each) 5.8 s, its
# transmission-error map (nine polynomial rows) 10.9 s.
DEAD_ZONE_ROW_COST = 4


def _cost(values) -> float:
    """A map's expected cost in polynomial rows (the order the maps are handed out)."""
    return sum(DEAD_ZONE_ROW_COST if v == "dead-zone" else 1 for v in values)


def _map_task(args: tuple) -> Sensitivity:
    """Worker: one regime map over lambda by one open value (serial), its claim-carrying
    runs continued, its data and figures written; its :class:`Sensitivity` row."""
    from gearsym.solver.export import save_all
    from gearsym.solver.sweep.atlas import regime_map

    out, res, settings, lam, case, scene, f1, reading, key, (values, stated, unit) = args
    text = is_text(values)
    axis = np.arange(len(values), dtype=float) if text else np.array(values, float)
    name = f"{case}_{reading}_{key}"
    resolve = _resolver(scene, f1, reading, key, values)
    m = regime_map(
        _load_value(scene, f1, reading, None, None),
        ("lambda", lam),
        (key, axis),
        initial_states=3,
        seed=0,
        transient=res.transient,
        periods=res.periods,
        lyapunov_periods=min(res.lyapunov_periods, res.transient + res.periods),
        method=settings["method"],
        rtol=settings["rtol"],
        atol=settings["atol"],
        executor="serial",
        store=out / "store" / f"sensitivity_{name}",
        resolve=resolve,
    )
    m, carriers = lengthen_carriers(m, FINDINGS[case], resolve, settings, "serial", None, _matches)
    save_all(m, out / "data" / f"sensitivity_{name}.json")  # and .csv, .mat
    figures = _draw(
        (
            m,
            out / "sensitivity",
            f"{case}-{reading}-{key}",
            {key: list(values)} if text else None,
            f"{scene} (f1 = {f1}), load reading {reading}, {key} as on the y axis, all else "
            "as stated",
            ("motion", "lyapunov", "attractors", "meshing"),
        )
    )
    records = _named(m.records(), key, values)
    motions, critical = {}, {}
    for v in values:
        here = [r for r in records if r[key] == v and r["status"] == "ok"]
        motions[v] = sorted({r["motion"][c] for r in here for c in ("u", "v")})
        critical[v] = _critical(records, lam, v, key)
    reproduced = {}
    for finding, coord, test, (lo, hi) in FINDINGS[case]:
        inside = [r for r in records if lo <= r["lambda"] <= hi]
        shows = [r[key] for r in inside if _matches(r["motion"][coord], test)]
        reproduced[finding] = [v for v in values if v in shows]
    failed = sum(r["status"] != "ok" for r in records)
    return Sensitivity(
        case,
        key,
        values,
        stated,
        unit,
        motions,
        critical,
        reproduced,
        failed,
        figures,
        reading,
        carriers,
    )


def _draw(args: tuple) -> list:
    """Worker: the figures of one sensitivity map (``write_map_figures``' arguments);
    paths."""
    from gearsym.solver.plots_maps import write_map_figures

    return write_map_figures(*args)


def physical_scales(scene: str) -> dict:
    """Force and length scales of a scene's model (application layer: it derives).
    The non-dimensional mesh force times ``force_N`` is newtons; u times ``b_um`` is the
    dynamic transmission error in µm."""
    from .model_check import _model

    s = _model(scene).scales
    out = {}
    for c, b in s["half_backlash_m"].items():
        km = s["mean_stiffness_N_per_m"][c]
        out[c] = {"k_m_N_per_m": km, "b_um": b * 1e6, "force_N": km * b}
    return out
