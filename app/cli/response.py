"""``gearsym frequency-response``: the periodic response over the forcing frequency (or any
parameter) by harmonic-balance and shooting continuation, stable and unstable branches."""

from __future__ import annotations

import math
import sys

from ._common import (
    Fail,
    RunFailed,
    at_most,
    out_folder,
    parse_set,
    refuse_conflicts,
    refuse_restated,
    require,
)
from ._limits import MAX_PERIOD
from ._notes import note_run
from ._output import format_option, units_option, write_result
from ._system import system_of, unknown_names

__all__ = ["register"]

# Bounded work (every size that sets the cost; each stated in its option's help).  The
# harmonic-balance continuation stops after 20,000 points (NUM or a smaller --step set its
# steps); a shooting point costs a Newton solve with the monodromy (0.1 to 1 s), an
# integration point a settled run: 2,000 of them is some minutes on the smallest model.
MAX_POINTS = 20_000
MAX_POINTS_TIMED = 2_000
MAX_SETTLE = 10_000
MAX_INTEGRATED = 1e7  # periods a sweep of --method integration (up and down run together)
# solver/sweep/frequency.py's MAX_HARMONICS and MAX_UNKNOWNS (imported only when a command
# runs: the parser is built without the solver; tests/test_cli_limits.py checks they agree)
MAX_HARMONICS, MAX_UNKNOWNS = 256, 4096


def register(sub) -> None:
    fr = sub.add_parser(
        "frequency-response",
        help="frequency response: harmonic balance and shooting, stable and unstable branches",
        description="Follow the periodic solution over a parameter (the forcing frequency "
        "omega by default) by pseudo-arclength continuation: harmonic balance (alternating "
        "frequency-time, Hill's stability) and/or shooting (monodromy). Prints one line per "
        "method with its folds; writes frequency_response.json, .csv, .mat and a figure "
        "of the amplitude of every mesh coordinate (stable solid, unstable dashed, folds "
        "marked).",
    )
    fr.add_argument("scene", metavar="SCENE", help="a scene path or built-in name")
    fr.add_argument(
        "--param",
        required=True,
        metavar="NAME=START:STOP:NUM",
        help="the parameter (a scene or model parameter; START and STOP inside its valid "
        "range) and its range; NUM is the number of points every method returns, at NUM "
        "equally spaced values from START to STOP, for example omega=0.3:1:400. hb and "
        "shooting continue the branch (see --step) and solve it again at those values on "
        "each monotonic piece: a branch without folds has NUM points, a branch that folds k "
        "times has k + 1 pieces, each with the values in its span, plus its k turning points; "
        "integration gives NUM frequencies up and NUM down (less any that failed). NUM at "
        f"most {MAX_POINTS:,} ({MAX_POINTS_TIMED:,} with shooting or integration). A branch "
        "that reaches the edge of the parameter's valid range stops there and says so",
    )
    fr.add_argument(
        "--step",
        type=float,
        default=None,
        help="hb and shooting: the continuation's first arclength step (default: the range "
        "over NUM - 1; hb: also the most the parameter moves per step; shooting: the step "
        "adapts up to twice this); it sets how finely folds are followed, not the number "
        "of points",
    )
    fr.add_argument(
        "--set", action="append", metavar="KEY=VALUE", help="set a scene or model parameter"
    )
    fr.add_argument(
        "--harmonics",
        type=int,
        default=15,
        metavar="H",
        help=f"harmonics of omega/n (at most {MAX_HARMONICS}, and at most "
        f"{MAX_UNKNOWNS} unknowns: states x (2H + 1))",
    )
    fr.add_argument(
        "--tail",
        type=float,
        metavar="SHARE",
        help="raise H (doubling, from --harmonics, up to the --harmonics limit) until the "
        "top quarter of the harmonics carries at most SHARE of the response at the start, "
        "for example 1e-6",
    )
    fr.add_argument(
        "--period",
        type=int,
        default=1,
        metavar="N",
        help=f"period N T (at most {MAX_PERIOD})",
    )
    fr.add_argument(
        "--method",
        choices=("hb", "shooting", "integration", "all"),
        default="hb",
        help="hb (harmonic balance), shooting, integration (up and down stepped "
        "sweeps in the compiled engine, over the forcing frequency or a speed in rpm), or all",
    )
    fr.add_argument(
        "--settle",
        type=int,
        default=50,
        metavar="N",
        help=f"integration: periods settled at each frequency before sampling (at most "
        f"{MAX_SETTLE:,}; NUM x (N + --sampled) at most {MAX_INTEGRATED:.0e} periods)",
    )
    fr.add_argument(
        "--sampled",
        type=int,
        default=16,
        metavar="N",
        help=f"integration: periods sampled at each frequency (at most {MAX_SETTLE:,})",
    )
    units_option(
        fr,
        "the figure in mesh frequency (Hz) and dynamic transmission-error amplitude (µm), "
        "and the result files with added columns (<coordinate>_amplitude_um and the other "
        "deflections in µm, speed_rpm where the model has a gear's speed, "
        "mesh_frequency_hz) and an in_units block",
    )
    fr.add_argument("--physical", action="store_true", help="the same as --units physical")
    fr.add_argument("--out", metavar="DIR", help="output folder (default response_<model>)")
    format_option(fr, "frequency_response")
    fr.add_argument("--json", action="store_true", help="print one JSON record per solution point")
    fr.add_argument("--no-figure", action="store_true", help="write the data only")
    fr.set_defaults(func=_cmd_response)


def _param(text: str):
    name, sep, spec = text.partition("=")
    parts = spec.split(":")
    try:
        if not sep or not name.strip() or len(parts) != 3:
            raise ValueError
        start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise Fail(
            f"--param {text}: expected NAME=START:STOP:NUM, for example omega=0.3:1:400"
        ) from None
    if not (math.isfinite(start) and math.isfinite(stop)) or start == stop:
        raise Fail(f"--param {text}: START and STOP must be finite and differ")
    if num < 2:
        raise Fail(f"--param {text}: NUM must be >= 2")
    return name.strip(), start, stop, num


def _bounded(args, system, num: int, methods, cap: int, span: float) -> None:
    """Refuse a size that would make the run take hours (the limits above)."""
    if args.harmonics > cap:
        raise Fail(
            f"--harmonics {args.harmonics}: at most {cap} for {system.name} "
            f"({system.n} states x (2H + 1) <= {MAX_UNKNOWNS} unknowns, H <= "
            f"{MAX_HARMONICS}); use fewer harmonics, or --tail to raise them only "
            "as far as the response needs"
        )
    at_most(("--period", args.period, MAX_PERIOD))
    timed = [m for m in methods if m != "hb"]
    if args.step is not None:
        if not 0 < args.step <= span:
            raise Fail(f"--step {args.step:g}: give a step in (0, {span:g}], the range")
        most = MAX_POINTS_TIMED if timed else MAX_POINTS
        if span / args.step > most:
            raise Fail(
                f"--step {args.step:g}: the continuation would take more than {most:,} "
                f"steps over the range; give a step of at least {span / most:.3g}"
            )
    if num > MAX_POINTS or (timed and num > MAX_POINTS_TIMED):
        most = MAX_POINTS_TIMED if timed and num > MAX_POINTS_TIMED else MAX_POINTS
        why = f" with --method {args.method}" if most == MAX_POINTS_TIMED else ""
        raise Fail(
            f"--param {args.param}: NUM {num} is more than the {most:,} points a "
            f"response takes{why}; give a smaller NUM"
        )
    if "integration" in methods:
        at_most(
            ("--settle", args.settle, MAX_SETTLE),
            ("--sampled", args.sampled, MAX_SETTLE),
            unit=" periods",
        )
        total = num * (args.settle + args.sampled)
        if total > MAX_INTEGRATED:
            raise Fail(
                f"--method {args.method}: {num} frequencies x ({args.settle} + "
                f"{args.sampled}) periods is {total:.2g} periods a sweep, more than "
                f"{MAX_INTEGRATED:.0e}; lower NUM, --settle or --sampled"
            )


def _cmd_response(args) -> int:
    from gearsym.resolve import needs_derivation
    from gearsym.solver._json import dumps
    from gearsym.solver.periodic import HarmonicBalanceError, ShootingError
    from gearsym.solver.sweep.frequency import frequency_response, harmonics_cap
    from gearsym.solver.sweep.frequency_ranges import names_moved, others_moved

    name, start, stop, num = _param(args.param)
    if args.harmonics < 1:
        raise Fail(f"--harmonics must be >= 1, got {args.harmonics}")
    if args.period < 1:
        raise Fail(f"--period must be >= 1, got {args.period}")
    if args.tail is not None and not (0 < args.tail < 1):
        raise Fail(f"--tail must be a share in (0, 1), got {args.tail}")
    refuse_conflicts(args, [name], f"--param {args.param}")
    system = system_of(args.scene, parse_set(args.set))
    refuse_restated(args, system.module, [name], f"--param {args.param}")
    if needs_derivation(name, system.module):
        raise Fail(
            f"--param {name}: an open value (each value derives its own model), not a "
            "parameter to continue; map it with `gearsym map`, or set one value with "
            "--set"
        )
    for value in (start, stop):
        try:
            system.parameters_with(**{name: value})
        except KeyError as err:
            said = unknown_names(system.module, [name], "--param")
            raise Fail(said or f"--param {name}: {err.args[0]}") from None
        except ValueError as err:
            raise Fail(f"--param {args.param}: {name} = {value:g}: {err}") from None
    note_run(system, {name: [start, stop]})
    # the harmonic balance's Jacobian and Hill's matrix: (n (2H + 1))^2 numbers, a few times
    size = system.n * (2 * max(args.harmonics, 8 * args.period) + 1)
    require(32.0 * size**2, f"--harmonics {args.harmonics}", "use fewer harmonics")
    if args.settle < 1 or args.sampled < 1:
        raise Fail(f"--settle and --sampled must be >= 1, got {args.settle}, {args.sampled}")
    methods = ("hb", "shooting", "integration") if args.method == "all" else (args.method,)
    _bounded(args, system, num, methods, harmonics_cap(system), abs(stop - start))
    ends = (start, (start + stop) / 2, stop)
    moved = "integration" in methods and others_moved(system, name, ends)
    if moved:
        raise Fail(
            f"--method integration sweeps the forcing frequency "
            f"'{system.contract.forcing_frequency}' only (or a speed, which sets nothing "
            f"else), not '{name}', which sets {names_moved(moved)}; use hb or shooting"
        )
    out = out_folder(args.out or f"response_{system.name}")
    try:
        resp = frequency_response(
            system,
            name,
            start,
            stop,
            points=num,
            methods=methods,
            harmonics=args.harmonics,
            n=args.period,
            settle=args.settle,
            sampled=args.sampled,
            tail=args.tail,
            step=args.step,
        )
    except (HarmonicBalanceError, ShootingError) as err:
        raise RunFailed(f"frequency-response: {err}") from None
    physical = args.physical or args.units == "physical"
    if physical:  # the model's columns and keys kept; µm, rpm and Hz columns added
        from gearsym.solver.units_table import in_units

        written = write_result(out, "frequency_response", in_units(resp, system), args)
    else:
        written = write_result(out, "frequency_response", resp, args)
    figure = None
    if not args.no_figure:
        from gearsym.solver.plots_response import frequency_response_figure
        from gearsym.solver.plots_style import save_figure

        figure = save_figure(
            frequency_response_figure(
                resp,
                physical=physical,
                title=f"{system.name}: period-{args.period} response over {name}",
            ),
            out / "frequency_response.png",
        )
    if args.json:
        for rec in resp.records():
            print(dumps(rec))
        return 0
    if system.piecewise and "hb" in methods:
        print(
            "note: a piecewise force law (dead zone): Hill's stability is approximate here "
            "(multipliers within about 1e-3 on orbits that cross the kinks; "
            "docs/analysis.md); --method all adds shooting"
            + (", which locates the kinks" if system.contract.switching_surfaces else "")
        )
    methods = [c.method for c in resp.curves]
    for k, c in enumerate(resp.curves):
        stable = int(c.stable.sum())
        # one method's second curve (harmonic balance from the other end) named by its index
        which = f" (curve {k}, column 'curve')" if methods.count(c.method) > 1 else ""
        if c.method == "integration":
            print(
                f"integration, {c.details['direction']} sweep: {len(c.values)} points in "
                f"{c.wall_time:.2f} s (both sweeps together)"
            )
            continue
        extra = ""
        if c.method == "hb":
            extra = (
                f"; H = {c.details['harmonics']}, top harmonics carry at most "
                f"{c.details['largest_tail_share']:.1e} of the response"
            )
        print(
            f"{c.method}{which}: {len(c.values)} points ({stable} stable) in "
            f"{c.wall_time:.2f} s{extra}"
        )
        for e in c.events:
            ev = e.evidence
            check = (
                f"  (Hill against the monodromy: {ev['hill_vs_monodromy']:.1e}; largest "
                f"|monodromy multiplier| {ev['max_monodromy_multiplier']:.9f})"
                if "hill_vs_monodromy" in ev
                else ""
            )
            print(f"  {e.name:<16} {name} = {e.value:.8g}{check}")
        for note in c.details.get("notes", []):
            print(f"  note: {note}")
        if c.details.get("status") in ("boundary", "max-points"):
            print(f"  {c.details['message']}")
    names = ", ".join(p.name for p in [*written, *([figure] if figure else [])])
    print(f"wrote {names} in {out}")
    sys.stdout.flush()
    return 0
