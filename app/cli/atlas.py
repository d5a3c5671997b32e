"""``gearsym map``: regime maps over two parameters with several initial states."""

from __future__ import annotations

import math
import sys

from ._common import (
    LIMITS,
    MAX_TOTAL_PERIODS,
    Fail,
    at_most,
    budget_option,
    out_folder,
    parse_range,
    parse_set,
    refuse_conflicts,
    require,
)
from ._notes import note_run
from ._output import format_option, units_option, write_result
from ._system import system_of, unknown_names

__all__ = ["register"]

MAX_INITIAL_STATES = 64
MAX_WORKERS = 1024


def register(sub) -> None:
    mp = sub.add_parser(
        "map",
        help="regime map over two parameters: motion, exponent, coexisting attractors",
        description="For every point of an x by y grid, integrate K initial states (the "
        "previous x value's end state forward and backward, plus seeded random states) in "
        "the compiled map engine, classify each run (motion per coordinate, largest "
        "Lyapunov exponent, Max/Min, meshing regime) and group the runs into attractors. "
        "Writes map.json, map.csv, map.mat (--format) and five figures; resumes from "
        "DIR/store.",
    )
    mp.add_argument("scene", metavar="SCENE", help="a scene path or built-in name")
    for axis in ("x", "y"):
        mp.add_argument(
            f"--{axis}",
            required=True,
            metavar="NAME=START:STOP:NUM",
            help=f"the {axis} axis: a scene or model parameter (or an open value) and NUM "
            "values from START to STOP (the grid's runs x (--transient + --periods) at most "
            f"{MAX_TOTAL_PERIODS:.0e} periods)",
        )
    mp.add_argument(
        "--initial-states",
        type=int,
        default=4,
        metavar="K",
        help="initial states per grid point: forward, backward, then K - 2 random (at most "
        f"{MAX_INITIAL_STATES})",
    )
    mp.add_argument("--seed", type=int, default=0, help="seed of the random initial states")
    budget_option(mp)
    mp.add_argument(
        "--box",
        action="append",
        metavar="STATE=LO:HI",
        help="where random initial states are drawn, per state (repeatable; default: "
        "coordinates one half backlash beyond each contact edge, velocities in [-1, 1])",
    )
    mp.add_argument(
        "--set", action="append", metavar="KEY=VALUE", help="set a scene or model parameter"
    )
    mp.add_argument(
        "--method",
        choices=("dop853", "dopri5"),
        default="dop853",
        help="compiled integrator of the lockstep runs",
    )
    mp.add_argument("--rtol", type=float, default=1e-8, help="relative tolerance")
    mp.add_argument("--atol", type=float, default=1e-10, help="absolute tolerance")
    mp.add_argument(
        "--transient",
        type=int,
        default=300,
        help=f"periods discarded (at most {LIMITS['transient']:,})",
    )
    mp.add_argument(
        "--periods",
        type=int,
        default=100,
        help=f"periods sampled (at most {LIMITS['periods']:,})",
    )
    mp.add_argument(
        "--lyapunov-periods",
        type=int,
        default=200,
        help="the exponent is summed over the last N periods of the run (0: none; at "
        f"most the run's periods and {LIMITS['lyapunov_periods']:,})",
    )
    mp.add_argument(
        "--executor",
        choices=("serial", "processes", "dask"),
        default="processes",
        help="serial, local processes or dask.distributed (needs gearsym[dask])",
    )
    mp.add_argument(
        "--workers",
        type=int,
        default=None,
        help=f"processes (default: all cores; at most {MAX_WORKERS})",
    )
    mp.add_argument("--scheduler", metavar="ADDRESS", help="dask scheduler address")
    mp.add_argument("--out", metavar="DIR", help="output folder (default map_<model>_<x>_<y>)")
    format_option(mp, "map")
    mp.add_argument(
        "--json",
        action="store_true",
        help="print one JSON record per (grid point, attractor) on stdout",
    )
    mp.add_argument("--quiet", action="store_true", help="no progress bar")
    units_option(
        mp,
        "the extremes in µm and the exponent per second (figures and printed), omega with the"
        " speed in rpm (or the speed with the mesh frequency in Hz) on the figures' axes, and"
        " the result files with added columns (max_<coordinate>_um, min_<coordinate>_um, "
        "lyapunov_per_s, speed_rpm, mesh_frequency_hz) and an in_units block",
    )
    mp.set_defaults(func=_cmd_map)


def _axis(text: str, flag: str):
    name, sep, spec = text.partition("=")
    if not sep or not name.strip():
        raise Fail(f"{flag} {text}: expected NAME=START:STOP:NUM, for example lambda=0:1:51")
    hint = f"(write {flag}={name}=-0.5:1:11 when START is negative)"
    return name.strip(), parse_range(spec, given=f"{flag} {text}", negative=hint)


def _box(items) -> dict:
    out = {}
    for item in items or []:
        state, sep, spec = item.partition("=")
        lo, sep2, hi = spec.partition(":")
        try:
            if not (sep and sep2):
                raise ValueError
            bounds = (float(lo), float(hi))
        except ValueError:
            raise Fail(f"--box {item}: expected STATE=LO:HI, for example --box=v=-2:2") from None
        if not (all(map(math.isfinite, bounds)) and bounds[0] <= bounds[1]):
            raise Fail(f"--box {item}: LO and HI must be finite with LO <= HI")
        out[state.strip()] = bounds
    return out


def _resolver(scene: str, system, sets: dict, names: tuple[str, str]):
    """System of one grid point: ordinary parameters by ``with_values``; open values
    (those the derivation needs, when the derive layer knows them) through the resolver's
    derivation cache, one model per distinct set of open values."""
    from gearsym.resolve import needs_derivation

    open_axes = [n for n in names if needs_derivation(n, system.module)]
    if not open_axes:
        return None
    from gearsym.resolve import load

    memo: dict = {}

    def resolve(values: dict):
        key = tuple((n, values[n]) for n in open_axes)
        if key not in memo:
            memo[key] = load(scene, **sets, **dict(key))
        rest = {k: v for k, v in values.items() if k not in open_axes}
        return memo[key].with_values(**rest)

    return resolve


def _bounded(args, runs: int) -> None:
    """Refuse a size that would make the map take hours (the limits above)."""
    sizes = [
        ("--initial-states", args.initial_states, MAX_INITIAL_STATES),
        ("--workers", args.workers or 1, MAX_WORKERS),
    ]
    sizes += [("--" + k.replace("_", "-"), getattr(args, k), most) for k, most in LIMITS.items()]
    at_most(*sizes)
    total = runs * (args.transient + args.periods)
    if total > MAX_TOTAL_PERIODS:
        raise Fail(
            f"{runs:,} runs of {args.transient} + {args.periods} periods is {total:.2g} "
            f"periods, more than {MAX_TOTAL_PERIODS:.0e} (hours of work); map fewer "
            "points, initial states or periods"
        )


def _cmd_map(args) -> int:
    from gearsym.solver.plots_maps import write_map_figures
    from gearsym.solver.sweep.atlas import regime_map

    xn, xv = _axis(args.x, "--x")
    yn, yv = _axis(args.y, "--y")
    if xn == yn:
        raise Fail(f"--x and --y name the same parameter '{xn}'; map two different ones")
    if args.initial_states < 1:
        raise Fail(f"--initial-states must be >= 1, got {args.initial_states}")
    for name in ("transient", "lyapunov_periods", "budget"):
        if getattr(args, name) < 0:
            raise Fail(f"--{name.replace('_', '-')} must be >= 0")
    if args.periods < 1:
        raise Fail("--periods must be >= 1")
    if args.lyapunov_periods > args.transient + args.periods:
        raise Fail(
            f"--lyapunov-periods {args.lyapunov_periods} is more than the run "
            f"({args.transient} + {args.periods} periods); lower it or lengthen --transient"
        )
    if not (args.rtol > 0 and args.atol > 0):
        raise Fail("--rtol and --atol must be positive numbers")
    if args.workers is not None and args.workers < 1:
        raise Fail(f"--workers must be >= 1, got {args.workers}")
    refuse_conflicts(args, [xn, yn], f"--x {xn} / --y {yn}")
    # per run: its Poincare points (4 states), its extremes and its exponent's history
    runs = xv.size * yv.size * args.initial_states
    require(
        runs * 8.0 * (4 * (args.periods + 1) + 8 + args.lyapunov_periods) * 2,
        f"{xv.size} x {yv.size} x {args.initial_states} runs of {args.periods} periods",
        "map fewer points, initial states or periods",
    )
    _bounded(args, runs)
    sets = parse_set(args.set)
    box = _box(args.box)
    system = system_of(args.scene, sets)
    unknown = sorted(set(box) - set(system.states))
    if unknown:
        raise Fail(f"--box {unknown[0]}: not a state; states: {', '.join(system.states)}")
    resolve = _resolver(args.scene, system, sets, (xn, yn))
    first = resolve or (lambda v: system.with_values(**v))
    for flag, name, values in (("--x", xn, xv), ("--y", yn, yv)):
        try:
            first({xn: xv[0], yn: yv[0]} | {name: values[0]})
            first({xn: xv[-1], yn: yv[-1]} | {name: values[-1]})
        except KeyError as err:
            said = unknown_names(system.module, [xn], "--x") or unknown_names(
                system.module, [yn], "--y"
            )
            raise Fail(said or f"{flag} {name}: {err.args[0]}") from None
        except ValueError as err:
            raise Fail(f"{flag} {name}: {err}") from None
    if resolve is None:  # (an open value's models are derived per value)
        note_run(system, {xn: [xv[0], xv[-1]], yn: [yv[0], yv[-1]]})
    out = out_folder(args.out or f"map_{system.name}_{xn}_{yn}")
    try:
        result = regime_map(
            system,
            (xn, xv),
            (yn, yv),
            initial_states=args.initial_states,
            seed=args.seed,
            box=box,
            transient=args.transient,
            periods=args.periods,
            lyapunov_periods=args.lyapunov_periods,
            budget=args.budget,
            method=args.method,
            rtol=args.rtol,
            atol=args.atol,
            executor=args.executor,
            workers=args.workers,
            scheduler=args.scheduler,
            store=out / "store",
            progress=not (args.quiet or args.json),
            resolve=resolve,
        )
    except ValueError as err:
        raise Fail(f"map: {err}") from None
    from gearsym.solver.provenance import provenance
    from gearsym.solver.units_table import in_units

    physical = args.units == "physical"
    table = in_units(result, system, args.units) if physical else result
    written = write_result(out, "map", table, args, **provenance(system))
    figures = write_map_figures(result, out, system=system, units=args.units)
    if args.json:
        from gearsym.solver._json import dumps

        for record in result.records():
            sys.stdout.write(dumps(record) + "\n")
        return 0
    if result.resumed:
        print(f"resumed: {result.resumed} finished runs came from {out / 'store'}")
    _summary(result)
    if physical:
        _physical(result, system, table)
    print(f"wrote {', '.join(p.name for p in written)} and {len(figures)} figures in {out}")
    return 0


def _summary(m) -> None:
    from collections import Counter

    n = len(m.x_values) * len(m.y_values)
    print(
        f"{m.model}: {len(m.x_values)} x {len(m.y_values)} grid ({m.x} x {m.y}), "
        f"{m.settings['initial_states']} initial states each, {m.wall_time:.1f} s"
        + (f" ({m.settings['engine']})" if m.settings.get("engine") else "")
    )
    for c in m.coordinates:
        counts = Counter(m.grid("motion", c).ravel())
        parts = ", ".join(f"{k} {v / n:.0%}" for k, v in counts.most_common())
        print(f"  motion of {c} (dominant attractor): {parts}")
    many = int((m.grid("attractors") > 1).sum())
    print(f"  grid points with more than one outcome: {many} of {n}")
    runs = [a.run for row in m.cells for cell in row for a in cell.attractors]
    verdicts = [r.verdict for r in runs if r.verdict]
    longer = sum(
        (v.get("periods_run") or 0) > m.settings["transient"] + m.settings["periods"]
        for v in verdicts
    )
    looked = sum("reexamined" in v for v in verdicts)
    print(
        f"  verdicts (attractors shown): {longer} of {len(verdicts)} run on past the first "
        f"{m.settings['transient'] + m.settings['periods']} periods, {looked} re-examined at a "
        "border with the long budget"
    )


def _physical(m, system, table) -> None:
    """The map's span and the extremes of its mesh deflections in physical units."""
    from gearsym.solver.units import MESH_HZ, SPEED, parameter_span

    speeds = {SPEED, MESH_HZ, system.contract.forcing_frequency}
    for name, values in ((m.x, m.x_values), (m.y, m.y_values)):
        # the speed the map runs at, said by its speed axis (another axis holds it fixed)
        span = parameter_span(system, "physical", name, values) if name in speeds else ""
        if span:
            print(f"  {span}")
    if not {m.x, m.y} & speeds:
        from gearsym.solver.units import Units

        print(f"  at {Units.of(system).operating_point()}")
    columns, rows = table.to_table()
    for c in m.coordinates:
        found = []
        for field in (f"min_{c}_um", f"max_{c}_um"):
            if field in columns:
                k = columns.index(field)
                found += [r[k] for r in rows if r[k] is not None]
        if found:
            print(f"  {c} over the grid (all attractors): [{min(found):.4g}, {max(found):.4g}] µm")
