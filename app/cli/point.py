"""Commands on operating points: ``simulate`` and ``sweep``."""

from __future__ import annotations

import sys
import time

from ._common import (
    MAX_TOTAL_PERIODS,
    Fail,
    RunFailed,
    analysis_options,
    analysis_settings,
    out_folder,
    parse_range,
    parse_set,
    refuse_conflicts,
    refuse_restated,
    require,
)
from ._notes import note_run
from ._output import format_option, units_option, write_poincare, write_result
from ._start import resolve_start, start_options
from ._system import system_of, unknown_names
from ._verdict import verdict_lines

__all__ = ["register"]

MAX_SWEEP_POINTS = 100_000  # a sweep's values (with the periods' total: _common.py)


def register(sub) -> None:
    si = sub.add_parser(
        "simulate",
        help="simulate one operating point and classify it",
        description="Simulate a scene, discard the transient, and report the "
        "Poincaré points, motion type with its evidence, ranges, spectral "
        "peaks and meshing-state shares of every mesh.",
    )
    si.add_argument("scene", metavar="SCENE", help="a scene path or built-in name")
    analysis_options(si)
    start_options(si)
    si.add_argument("--json", action="store_true", help="print everything as JSON")
    units_option(
        si,
        "deflections (dynamic transmission error) in µm, mesh forces in N with the dynamic "
        "factor, frequencies in Hz and orders of the mesh frequency, the speed in rpm; "
        "point.png in µm, ms, m/s and Hz; the point files with added columns "
        "(<coordinate>_um, t_s, d<coordinate>_m_per_s, <coordinate>_force_N) and an in_units "
        "block",
    )
    si.add_argument(
        "--out", metavar="DIR", help="also write point.json, .csv, .mat (--format) and point.png"
    )
    format_option(si, "point")
    si.set_defaults(func=_cmd_simulate)

    sw = sub.add_parser(
        "sweep",
        help="bifurcation diagram over one parameter",
        description="Sweep one scene or model parameter with continuation "
        "of the final state (forward, or --backward), or --independent points "
        "run in parallel.",
    )
    sw.add_argument("scene", metavar="SCENE", help="a scene path or built-in name")
    sw.add_argument("--param", required=True, help="parameter to sweep, e.g. lambda")
    sw.add_argument(
        "--range",
        required=True,
        metavar="START:STOP:NUM",
        help="NUM values from START to STOP; write --range=-1:1:21 when START is negative; "
        f"NUM at most {MAX_SWEEP_POINTS:,}, and NUM x the larger of --transient + "
        f"--periods and --budget at most {MAX_TOTAL_PERIODS:.0e} periods",
    )
    sw.add_argument("--backward", action="store_true", help="continue from STOP to START")
    sw.add_argument(
        "--independent",
        action="store_true",
        help="no continuation: every point from the same initial state (with a compiled "
        "method the points are integrated together, in chunks, on every core)",
    )
    sw.add_argument(
        "--executor",
        choices=("serial", "processes", "dask"),
        default="processes",
        help="serial, local processes (all cores) or dask.distributed "
        "(needs gearsym[dask]; a LocalCluster unless --scheduler)",
    )
    sw.add_argument(
        "--scheduler", metavar="ADDRESS", help="dask scheduler address, e.g. tcp://head:8786"
    )
    sw.add_argument("--out", metavar="DIR", help="output folder (default sweep_<model>_<param>)")
    format_option(sw, "sweep")
    sw.add_argument("--quiet", action="store_true", help="no progress bar")
    units_option(
        sw,
        "the figure's deflections in µm with omega's speed (rpm) or the speed's mesh "
        "frequency (Hz) on a top axis, the printed ranges in µm, rpm and Hz, and the result "
        "files with added columns (<coordinate>_um, speed_rpm, mesh_frequency_hz, "
        "lyapunov_per_s) and an in_units block",
    )
    sw.add_argument(
        "--no-figure",
        action="store_true",
        help="write the data only (sweep.json, .csv, .mat), not bifurcation.png",
    )
    analysis_options(sw)
    sw.set_defaults(func=_cmd_sweep)


def _cmd_simulate(args) -> int:
    from gearsym.solver._json import dumps
    from gearsym.solver.analysis import analyse_point, meshing_states
    from gearsym.solver.integrate import SimulationError

    start = resolve_start(args)
    system = start.system
    started = time.perf_counter()
    try:
        result = analyse_point(system, start.x0, **analysis_settings(args))
    except SimulationError as err:
        raise RunFailed(f"simulate: {err}") from None
    except ValueError as err:
        where = "simulate" if start.x0 is None else f"simulate from {start.source}"
        raise Fail(f"{where}: {err}") from None
    data = result.describe()
    data["initial_state"] = start.describe()
    from gearsym.solver.units import Units, point_in_units

    units = Units.of(system, args.units)
    in_units = point_in_units(result, units)
    data["in_units"] = in_units
    if hasattr(system.module, "MESHES"):  # a planetary set: its meshes are not coordinates
        from gearsym.planetary import contact

        data["meshes"] = contact(result.trajectory)
        if hasattr(system.module, "SHAFTS"):  # a gear train's: their locked-in torque
            from gearsym.planetary import shaft_torques

            data["shafts"] = shaft_torques(result.trajectory)
    if args.out:
        from gearsym.solver import plots
        from gearsym.solver.units_table import in_units as with_units

        out = out_folder(args.out)
        write_result(
            out,
            "point",
            with_units(result, system) if units.physical else result,
            args,
            initial_state=data["initial_state"],
            meshes=data.get("meshes"),  # a planetary set's or a train's, as --json has them
            shafts=data.get("shafts"),
        )
        figure = plots.point_figure(result, title=system.name, units=args.units)
        plots.save_figure(figure, out / "point.png")
    tr = result.trajectory
    # exit status 3: the run ended invalid, divergent or failed (docs/user-guide.md)
    code = 0 if tr.status == "ok" else 3
    if args.json:
        print(dumps(data, indent=1))
        if code:  # stdout is for the reading program; the failure is said on stderr too
            print(f"gearsym: run failed: status {tr.status}: {tr.message}", file=sys.stderr)
        return code
    asked = tr.transient + tr.periods
    run = getattr(result.verdict, "periods_run", None) or asked
    # the run the verdict needed, which may have gone on past --transient + --periods (the
    # samples of figure, spectra and files are its last window); a failed run says what
    # it was asked for (the status line below says where it stopped)
    ran = f"{run:,} periods run" if tr.status == "ok" else f"{asked:,} periods asked"
    kept = "" if run == asked or tr.status != "ok" else f", the last {tr.periods} kept"
    print(
        f"{system.name}: {tr.method}, {tr.tolerance}, {ran}{kept}, "
        f"{time.perf_counter() - started:.2f} s, status {tr.status}"
    )
    if start.x0 is not None:
        print(f"  started from {start.source}: " + ", ".join(f"{v:.6g}" for v in start.x0))
    if tr.status != "ok":
        print(f"  {tr.message}")
    for line in verdict_lines(result.verdict):
        print(line)

    def num(v, fmt=".4f"):
        return "n/a" if v is None else format(v, fmt)

    shares = meshing_states(tr)
    if units.physical:
        print(f"  operating point: {in_units['operating_point']}")
    module = result.trajectory.system.module
    bodies = (
        dict(zip(module.STRUCTURE["physical"], module.BODIES, strict=True))
        if hasattr(module, "BODIES")
        else {}
    )
    for c, k in result.classification.items():
        row = in_units["coordinates"][c]
        low, high = row["range"] or (None, None)
        peaks = ", ".join(f"{p['frequency']:.4g}" for p in row["peaks"])
        body = bodies.get(c)  # a gear train's coordinate is a body's rotation
        label = f"{c} ({body})" if body else c
        # no peak where the run went: the coordinate is constant to rounding
        none = "no peaks (constant to rounding)" if tr.status == "ok" else "peaks n/a"
        line = f"  {label}: range [{num(low)}, {num(high)}]  " + (
            f"peaks at {peaks}" if peaks else none
        )
        if units.physical:
            orders = ", ".join(f"{p['order']:.3g}" for p in row["peaks"])
            what = "displacement" if hasattr(system.module, "MESHES") else "dynamic TE"
            b = units.deflection(c, 1.0)  # (the relative displacement: contact beyond ±b)
            edge = f" (contact beyond ±{b:g} µm)" if c in system.contract.contact else ""
            line = f"  {label}: {what} [{num(low, '.2f')}, {num(high, '.2f')}] µm{edge}  " + (
                f"peaks at {peaks} Hz (orders {orders})" if peaks else none
            )
            if row.get("force_range"):
                fl, fh = row["force_range"]
                df = row["dynamic_factor"]
                line += f"\n      mesh force [{fl:.4g}, {fh:.4g}] N, dynamic factor " + (
                    f"{df:.3f}" if df is not None else "n/a (no static load)"
                )
        if c in shares:
            f, s, b = (num(shares[c][key], ".2f") for key in ("forward", "separated", "backward"))
            line += f"  force forward/zero/backward {f}/{s}/{b}"
            if shares[c].get("loaded_in_gap") is not None:
                line += f" (inside the gap, loaded: {num(shares[c]['loaded_in_gap'], '.2f')})"
        print(line)
        sp = k.evidence.get("spread")
        if sp and k.period is None:
            print(
                f"      Poincaré cloud: extent {num(sp['displacement'], '.2e')} in {c}, "
                f"{num(sp['velocity'], '.2e')} in its velocity, {num(sp['share'], '.2f')} of "
                "the widest coordinate's"
                + (
                    "; slaved to the widest through the coupling"
                    if (sp["share"] or 1) < 0.05
                    else ""
                )
            )
    for mesh, row in data.get("meshes", {}).items():
        side = "u > 1" if row.get("loaded_side", 1) > 0 else "u < -1"
        b = row.get("half_backlash_um")
        um = f" ({row['min'] * b:.2f} to {row['max'] * b:.2f} µm)" if units.physical and b else ""
        print(
            f"  mesh {mesh}: deflection [{row['min']:.4f}, {row['max']:.4f}] half backlashes{um}; "
            f"teeth apart {row['apart']:.2f}, on the loaded flank ({side}) "
            f"{row['loaded_flank']:.2f}, the back flank {row['back_flank']:.2f} of "
            f"{row['samples']} samples"
        )
    for shaft, row in data.get("shafts", {}).items():
        a, b = row["bodies"]
        print(
            f"  shaft {shaft} ({a} to {b}): torque mean {row['mean_Nm']:.6g} N m, range "
            f"[{row['min_Nm']:.6g}, {row['max_Nm']:.6g}]"
        )
    if tr.left_valid_range is not None:
        t, c, v = tr.left_valid_range
        print(
            f"  warning: {c} = {v:.3g} at tau = {t:.6g} is outside the backlash model's "
            f"valid range |{c}| <= {system.contract.valid_range[c]:g}"
        )
    return code


def _cmd_sweep(args) -> int:
    from gearsym.solver.integrate import SimulationError
    from gearsym.solver.sweep import Progress, sweep
    from gearsym.studies.report import runs_text

    figure = not args.no_figure

    class _Bar(Progress):
        """The progress line.  Its first step loads the figure code (matplotlib, a third of
        a second) while the workers are still integrating, not after them."""

        def step(self, note: str = "") -> None:
            if self.done == 0 and figure:
                import gearsym.solver.plots  # noqa: F401
            super().step(note)

    values = parse_range(args.range)
    refuse_conflicts(args, [args.param], f"--param {args.param}")
    if args.backward and args.independent:
        raise Fail("--backward orders a continuation, and --independent has none; drop one")
    settings = analysis_settings(args)
    # each point keeps its Poincare points and a summary (about 4 KiB)
    require(
        len(values) * (8.0 * 4 * args.periods + 4096) * 2,
        f"--range {args.range}: {len(values)} points of {args.periods} periods",
        "sweep fewer points or periods",
    )
    total = len(values) * max(args.transient + args.periods, args.budget)
    if len(values) > MAX_SWEEP_POINTS or total > MAX_TOTAL_PERIODS:
        raise Fail(
            f"--range {args.range}: {len(values):,} points of {args.transient} + "
            f"{args.periods} + {args.lyapunov_periods} periods; at most "
            f"{MAX_SWEEP_POINTS:,} points and {MAX_TOTAL_PERIODS:.0e} periods in all "
            "(hours of work); sweep fewer points or periods"
        )
    from gearsym.resolve import needs_derivation

    system = system_of(args.scene, parse_set(args.set))
    refuse_restated(args, system.module, [args.param], f"--param {args.param}")
    if needs_derivation(args.param, system.module):
        raise Fail(
            f"--param {args.param}: an open value (each value derives its own model); sweep "
            f"it with `gearsym map {args.scene} --x {args.param}=START:STOP:NUM --y "
            "lambda=...`, or set one value with --set"
        )
    from gearsym.solver.sweep.chains import checked_values

    try:
        checked_values(system, args.param, values)  # before the folder is made
    except ValueError as err:
        said = unknown_names(system.module, [args.param], "--param")
        raise Fail(said or f"--param {args.param} --range {args.range}: {err}") from None
    note_run(system, {args.param: values})
    out = out_folder(args.out or f"sweep_{system.name}_{args.param}")
    bar = _Bar(len(values), f"{args.param}", enabled=not args.quiet)
    try:
        result = sweep(
            system,
            args.param,
            values,
            continuation=not args.independent,
            backward=args.backward,
            executor=args.executor,
            progress=bar,
            scheduler=args.scheduler,
            store=out / "store",
            **settings,
        )
    except (SimulationError, ValueError) as err:
        raise Fail(f"sweep: {err}") from None
    failed = [p.value for p in result.points if not p.ok]
    if result.resumed:
        print(f"resumed: {result.resumed} of {len(values)} points came from {out / 'store'}")
    from gearsym.solver.units import parameter_span, poincare_range
    from gearsym.solver.units_table import in_units

    physical = args.units == "physical"
    paths = write_result(
        out, "sweep", in_units(result, system, args.units) if physical else result, args
    )
    paths += write_poincare(out, result, args)
    if figure:
        from gearsym.solver import plots

        fig = plots.save_figure(
            plots.bifurcation_diagram(
                [result],
                list(system.coordinates),
                title=f"{system.name}: {args.param} sweep",
                system=system,
                units=args.units,
            ),
            out / "bifurcation.png",
        )
        paths.append(fig)
    print(f"wrote {', '.join(p.name for p in paths)} in {out}")
    if physical:
        span = parameter_span(system, args.units, args.param, result.values)
        print(f"  {span or system.name + ': no speed to give in rpm'}")
        for c in system.coordinates:
            shown = poincare_range(
                system, args.units, args.param, result.values, result.poincare(c), c
            )
            what = (  # a planetary set's or a train's coordinates are its bodies'
                "displacement" if hasattr(system.module, "MESHES") else "dynamic transmission error"
            )
            print(f"  {c} (Poincaré values, {what}): {shown or 'none'}")
    motions = [result.motion(c) for c in system.coordinates]
    if all(m == motions[0] for m in motions):  # one verdict per attractor: said once
        print(f"  attractor: {runs_text(values, motions[0])}")
    else:
        for c, m in zip(system.coordinates, motions, strict=True):
            print(f"  {c}: {runs_text(values, m)}")
    verdicts = [p.verdict for p in result.points if p.verdict]
    first = args.transient + args.periods
    longer = sum((v.get("periods_run") or 0) > first for v in verdicts)
    looked = sum("reexamined" in v for v in verdicts)
    chaos = sum("transient_chaos" in v.get("evidence", v) for v in verdicts)
    print(
        f"  verdicts: {longer} of {len(verdicts)} points run on past the first {first} "
        f"periods, {looked} re-examined at a border with the long budget"
        + (f", {chaos} after a chaotic transient" if chaos else "")
    )
    if failed:
        print(
            f"  {len(failed)} point(s) did not finish normally (status in sweep.json): "
            + ", ".join(f"{v:g}" for v in failed[:10])
            + " (exit status 3)"
        )
    return 3 if failed else 0
