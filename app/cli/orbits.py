"""Commands on periodic orbits: ``shoot`` and ``continue``."""

from __future__ import annotations

import math

import numpy as np

from ._common import (
    Fail,
    RunFailed,
    at_most,
    orbit_guess,
    out_folder,
    parse_set,
    refuse_conflicts,
    refuse_restated,
    require,
)
from ._limits import MAX_PERIOD, MAX_SEGMENTS, MAX_SETTLED, MAX_TRIES, MIN_STEP, bounded_shoot
from ._notes import note_run
from ._output import branches_document, format_option, units_option, write_result
from ._start import resolve_start, start_options
from ._system import system_of, unknown_names

__all__ = ["register"]


# Bounded work (each in its option's help): a period-n orbit costs about n times a period-1
# one (0.3 s a period on the reference scenes, minutes for period 64 on the largest model)
def register(sub) -> None:
    sh = sub.add_parser(
        "shoot",
        help="find a periodic orbit by shooting; Floquet multipliers",
        description="Find the period-n orbit (period n T) by Newton shooting "
        "from a simulated guess (or --x0 / --from-sweep), with its Floquet multipliers, "
        "stability judged within the monodromy's estimated error, and Liouville check. "
        "The orbit's minimal period is checked: when a guess leads to an orbit of lower "
        "period, --tries more guesses settled from seeded random states are tried; when "
        "none has minimal period n, the lower-period orbit is reported as what it is "
        "and the exit status is 3 (a run that did not find what was asked).",
    )
    sh.add_argument("scene", metavar="SCENE", help="a scene path or built-in name")
    sh.add_argument(
        "--period", type=int, default=1, help=f"n: the orbit's period is n T (1 to {MAX_PERIOD})"
    )
    sh.add_argument(
        "--tries",
        type=int,
        default=6,
        help=f"more guesses when the first leads to a lower period (at most "
        f"{MAX_TRIES}; each settles max(--settle, 300) n T)",
    )
    sh.add_argument("--seed", type=int, default=0, help="seed of those guesses' random starts")
    start_options(sh)
    sh.add_argument(
        "--segments", type=int, default=1, help=f"multiple shooting segments (1 to {MAX_SEGMENTS})"
    )
    sh.add_argument(
        "--monodromy",
        choices=("ad", "variational", "fd"),
        default=None,
        help="monodromy route (default: ad; variational with located crossings for a dead zone)",
    )
    sh.add_argument(
        "--compare-monodromy",
        action="store_true",
        help="also compute the monodromy the other two ways; compare",
    )
    sh.add_argument(
        "--settle",
        type=int,
        default=None,
        help="periods n T simulated for the guess (default 300; 0 with --x0 or "
        "--from-sweep: their state is the guess as given); the guesses settle at most "
        f"{MAX_SETTLED:,} periods T in all (N x n x (tries + 1))",
    )
    sh.add_argument("--json", action="store_true", help="print the orbit as JSON")
    sh.add_argument(
        "--out", metavar="DIR", help="also write orbit.json, .csv, .mat (--format), multipliers.png"
    )
    format_option(sh, "orbit")
    sh.set_defaults(func=_cmd_shoot)

    co = sub.add_parser(
        "continue",
        help="continue a periodic orbit in a parameter",
        description="Pseudo-arclength continuation of the period-n orbit, "
        "with fold, period-doubling and Neimark-Sacker points located; at most 400 points. "
        "A branch that reaches the edge of the parameter's valid range stops there and "
        "says so (the points up to there are kept).",
    )
    co.add_argument("scene", metavar="SCENE", help="a scene path or built-in name")
    co.add_argument(
        "--param", required=True, help="a scene or model parameter to continue (not an open value)"
    )
    co.add_argument(
        "--from", dest="from_", type=float, required=True, help="start (inside its valid range)"
    )
    co.add_argument("--to", type=float, required=True, help="end (inside its valid range)")
    co.add_argument(
        "--period", type=int, default=1, help=f"n: the orbit's period is n T (1 to {MAX_PERIOD})"
    )
    co.add_argument(
        "--step",
        type=float,
        default=None,
        help=f"first arclength step, {MIN_STEP:g} to |TO - FROM|, then up to four times it "
        "(default 0.02 x max(1, |TO - FROM|) up to |TO - FROM|: rpm step by their range)",
    )
    co.add_argument(
        "--switch", action="store_true", help="switch to the period-2n branch at a period doubling"
    )
    co.add_argument(
        "--settle",
        type=int,
        default=300,
        help=f"periods n T simulated for the first guess (N x n at most {MAX_SETTLED:,})",
    )
    co.add_argument(
        "--out",
        metavar="DIR",
        help="output folder for branches.json, .csv, .mat and the figures (default "
        "continue_<model>_<param>)",
    )
    format_option(co, "branches")
    co.set_defaults(func=_cmd_continue)
    for parser in (sh, co):
        parser.add_argument(
            "--set", action="append", metavar="KEY=VALUE", help="set a parameter (repeatable)"
        )
        units_option(
            parser,
            "deflections in µm, the period in s, the speed in rpm and the mesh frequency in Hz, "
            "printed, in the figure and the files (docs/user-guide.md)",
        )


def _guesses(system, n: int, first, tries: int, seed: int, settle: int):
    """The first guess, then states settled for ``settle`` n T from seeded random starts
    in a box around it (made lazily: only when the first leads to a lower period)."""
    from gearsym.solver.integrate import SimulationError, simulate

    yield first
    rng = np.random.default_rng(seed)
    half = max(1.0, float(np.max(np.abs(first))))
    for _ in range(tries):
        x = first + rng.uniform(-half, half, size=first.size)
        try:
            run = simulate(system, x, transient=max(settle, 1) * n, periods=1, samples_per_period=1)
        except (SimulationError, ValueError):
            continue
        if run.status == "ok":
            yield run.x_final


def _cmd_shoot(args) -> int:
    from gearsym.solver._json import dumps
    from gearsym.solver.integrate import SimulationError, simulate
    from gearsym.solver.periodic import ShootingError
    from gearsym.solver.periodic.shooting import search
    from gearsym.solver.units import orbit_in_units, orbit_line

    if args.period < 1 or args.segments < 1:
        raise Fail("--period and --segments must be whole numbers >= 1")
    if args.tries < 0:
        raise Fail(f"--tries must be >= 0, got {args.tries}")
    if args.seed is not None and args.seed < 0:
        raise Fail(f"--seed must be a whole number >= 0, got {args.seed}")
    start = resolve_start(args)
    system = start.system
    # Newton's matrix on all segments, dense: (n S)^2 numbers, and its factors
    require(
        24.0 * (system.n * args.segments) ** 2,
        f"--segments {args.segments}",
        "use fewer segments (one per period is the default; a few suffice)",
    )
    bounded_shoot(args)
    if start.x0 is None:
        settle = 300 if args.settle is None else args.settle
        guess = orbit_guess(system, args.period, settle)
    else:
        settle = 0 if args.settle is None else args.settle
        if settle < 0:
            raise Fail(f"--settle must be >= 0, got {settle}")
        guess = start.x0
        if settle:
            try:
                run = simulate(
                    system, guess, transient=settle * args.period, periods=1, samples_per_period=1
                )
            except (SimulationError, ValueError) as err:
                raise Fail(f"shoot: settling from {start.source} failed: {err}") from None
            if run.status != "ok":
                raise Fail(f"shoot: settling from {start.source} ended {run.status}")
            guess = run.x_final
    tries = args.tries if args.period > 1 else 0
    guesses = _guesses(system, args.period, guess, tries, args.seed, max(settle, 300))
    try:
        found = search(
            system, args.period, guesses, segments=args.segments, monodromy=args.monodromy
        )
    except ShootingError as err:
        raise RunFailed(f"shoot: {err}; residuals {[f'{r:.2g}' for r in err.history]}") from None
    orbit = found.orbit or found.lower
    data = orbit.describe()
    data["requested"] = args.period
    data["found_requested_period"] = found.found
    data["attempts"] = found.attempts
    data["initial_state"] = start.describe()
    if args.units == "physical":
        data["in_units"] = orbit_in_units(orbit, args.units)
    if args.out:
        from gearsym.solver import plots
        from gearsym.solver.export import Document
        from gearsym.solver.provenance import provenance

        out = out_folder(args.out)
        doc = Document(provenance(system) | data, *orbit.to_table())
        write_result(out, "orbit", doc, args)
        title = f"{system.name}: period-{orbit.n} orbit"
        fig = plots.multipliers_figure(orbit.floquet.multipliers, title=title)
        plots.save_figure(fig, out / "multipliers.png")
    if args.compare_monodromy:
        from gearsym.solver.periodic import FlowMap, monodromy_agreement

        data["monodromy_agreement"] = monodromy_agreement(FlowMap(system), orbit.x0, orbit.period)
    status = 0 if found.found else 3
    if args.json:
        print(dumps(data, indent=1))
        return status
    if not found.found:
        print(
            f"no orbit of minimal period {args.period} found from {len(found.attempts)} "
            f"guess(es); they led to the period-{orbit.n} orbit below (exit status 3)"
        )
    print(
        f"{system.name}: period-{orbit.n} orbit, residual {orbit.residual:.2e} after "
        f"{orbit.iterations} Newton iteration(s) ({args.monodromy or 'default'} monodromy, "
        f"{args.segments} segment(s))"
    )
    if start.x0 is not None:
        print(f"  guess from {start.source}" + (f", settled {settle} periods" if settle else ""))
    print("  x0: " + ", ".join(f"{k} = {v:.10g}" for k, v in data["x0"].items()))
    if "in_units" in data:
        print(orbit_line(data["in_units"]))
    fl = orbit.floquet
    print(
        "  multipliers: "
        + ", ".join(f"{m.real:+.6f}{m.imag:+.6f}i (|{abs(m):.6f}|)" for m in fl.multipliers)
    )
    what, where = {
        "fold": ("real and positive", "a fold"),
        "period-doubling": ("real and negative", "a period doubling"),
        "neimark-sacker": ("one of a complex pair", "a Neimark-Sacker bifurcation"),
    }[fl.kind]
    if fl.stability == "neutral":
        verdict = (
            f"neutral: the largest multiplier is on the unit circle (|mu| - 1 = "
            f"{abs(fl.critical) - 1:+.1e}, within ±{fl.tolerance:.1e}, the monodromy's "
            f"estimated error); it is {what}, as at {where}"
        )
    else:
        side = "were it to reach" if fl.stability == "stable" else "it is outside"
        verdict = f"{fl.stability} (|mu| - 1 = {abs(fl.critical) - 1:+.1e}, tolerance "
        verdict += f"±{fl.tolerance:.1e}); the largest multiplier is {what} ({side} the "
        verdict += f"unit circle: {where})"
    print(f"  {verdict}; Liouville error |log det M - ∫ tr J| = {fl.liouville_error:.2e}")
    for k, v in data.get("monodromy_agreement", {}).items():
        print(f"  monodromy {k}: {v:.2e} (max difference / max entry)")
    return status


def _cmd_continue(args) -> int:
    from gearsym.solver import plots
    from gearsym.solver.periodic import (
        ShootingError,
        StroboscopicMap,
        continue_orbit,
        switch_period_doubling,
    )
    from gearsym.solver.units import parameter_span
    from gearsym.solver.units_table import in_units

    for name in ("from_", "to"):
        if not math.isfinite(getattr(args, name)):
            raise Fail(f"--{name.rstrip('_')} must be a finite number")
    if args.from_ == args.to:
        raise Fail(f"--to {args.to:g} equals --from: nothing to continue; give another end")
    span = abs(args.to - args.from_)  # the default step by it: 0.02 of omega, 120 of 6,000 rpm
    args.step = min(0.02 * max(1.0, span), span) if args.step is None else args.step
    if not (args.step > 0 and math.isfinite(args.step)):
        raise Fail(f"--step must be a positive number, got {args.step}")
    if args.period < 1:
        raise Fail(f"--period must be >= 1, got {args.period}")
    if args.settle < 0:
        raise Fail(f"--settle must be >= 0, got {args.settle}")
    if not MIN_STEP <= args.step <= span:
        raise Fail(
            f"--step {args.step:g}: give {MIN_STEP:g} to {span:g} (|--to - --from|; "
            "a larger first step leaves the range at once)"
        )
    at_most(("--period", args.period, MAX_PERIOD))
    if args.settle * args.period > MAX_SETTLED:
        raise Fail(
            f"--settle {args.settle} with --period {args.period} settles "
            f"{args.settle * args.period:,} periods T, more than {MAX_SETTLED:,}; "
            "lower --settle"
        )
    from gearsym.resolve import needs_derivation

    refuse_conflicts(args, [args.param], f"--param {args.param}")
    system = system_of(args.scene, parse_set(args.set))
    refuse_restated(args, system.module, [args.param], f"--param {args.param}")
    if needs_derivation(args.param, system.module):
        raise Fail(
            f"--param {args.param}: an open value (each value derives its own model), "
            "not a parameter to continue; map it with `gearsym map`, or set one value "
            "with --set"
        )
    from gearsym.solver.integrate.simulate import check_start

    for option, value in (("--from", args.from_), ("--to", args.to)):
        try:
            point = system.with_values(**{args.param: value})
            if option == "--from":
                start = point
                check_start(point)
        except (KeyError, ValueError) as err:
            said = unknown_names(system.module, [args.param], "--param")
            raise Fail(said or f"{option} {value:g}: {args.param} = {value:g}: {err}") from None
    note_run(system, {args.param: [args.from_, args.to]})
    out = out_folder(args.out or f"continue_{system.name}_{args.param}")
    guess = orbit_guess(start, args.period, args.settle)
    try:
        branches = [
            continue_orbit(
                system,
                args.param,
                args.from_,
                args.to,
                guess,
                n=args.period,
                ds=args.step,
                ds_max=4 * args.step,
            )
        ]
    except ShootingError as err:
        raise RunFailed(f"continue: the first orbit was not found: {err}") from None
    except ValueError as err:
        raise Fail(f"continue: {err}") from None
    if args.switch:
        for bif in list(branches[0].bifurcations):
            if bif.kind == "period-doubling":
                try:
                    branches.append(
                        switch_period_doubling(
                            system,
                            args.param,
                            bif,
                            args.period,
                            args.to,
                            ds=args.step,
                            ds_max=4 * args.step,
                        )
                    )
                except ShootingError as err:
                    print(f"  branch switching at {bif.value:.6g} failed: {err}")
    doc = in_units(branches_document(system, branches), system, args.units)
    written = write_result(out, "branches", doc, args)
    title = f"{system.name}: continuation in {args.param}"
    fig = plots.branch_figure(
        branches, system.coordinates, title=title, system=system, units=args.units
    )
    plots.save_figure(fig, out / "branches.png")
    for k, br in enumerate(branches):
        smap = StroboscopicMap(system, br.n)
        for b in br.bifurcations:
            lam = b.value
            _, M, _ = smap.jacobian(b.x0, system.parameters_with(**{args.param: lam}))
            fig = plots.multipliers_figure(
                np.linalg.eigvals(M), title=f"{br.named(b)} at {args.param} = {lam:.6g}"
            )
            kind = br.named(b).replace(" ", "-")
            plots.save_figure(fig, out / f"multipliers_{k}_{kind}_{lam:.6g}.png")
    for br in branches:
        stable = sum(br.stable)
        print(f"period-{br.n} branch: {len(br.values)} points, {stable} stable; {br.message}")
        if span := parameter_span(system, args.units, args.param, br.values):
            print(f"  {span}")
        for b in br.bifurcations:
            at = parameter_span(system, args.units, args.param, [b.value]).partition(": ")[2]
            print(
                f"  {br.named(b):<16} {args.param} = {b.value:.8g}  multiplier "
                f"{b.multiplier.real:+.6f}{b.multiplier.imag:+.6f}i" + (f" ({at})" if at else "")
            )
            if "location" in b.evidence:
                print(f"    {b.evidence['location']}")
    print(f"wrote {', '.join(p.name for p in written)} and branches.png in {out}")
    return 0
