"""The ``gearsym`` command line.

This is the one module of ``solver/`` that also drives ``derive/``: it is the front door
of the whole pipeline.  User errors (bad files, bad values) print one line and exit 2;
``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

__all__ = ["main"]


class _Fail(Exception):
    """A user-facing failure: one line, exit code 2."""


def _parse_set(items: list[str]) -> dict[str, float]:
    out = {}
    for item in items or []:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise _Fail(f"--set {item}: expected key=value, for example --set lambda=0.5")
        try:
            number = float(value)
        except ValueError:
            raise _Fail(f"--set {item}: '{value}' is not a number") from None
        if not math.isfinite(number):
            raise _Fail(f"--set {item}: value must be finite")
        out[key.strip()] = number
    return out


def _cmd_derive(args) -> int:
    from gearsym.derive.build import (
        build_files,
        check,
        describe_json,
        project_root,
        shipped_targets,
        write_files,
        write_stiffness_figure,
    )
    from gearsym.derive.scene import resolve_target

    if args.check:
        if args.targets or args.set or args.out:
            raise _Fail(
                "derive --check takes no targets, --set or --out: it checks the "
                "shipped scenes and topologies"
            )
        stale = check()
        for line in stale:
            print(f"stale: {line}", file=sys.stderr)
        if stale:
            print(
                f"{len(stale)} file(s) differ from a fresh regeneration; run "
                "`gearsym derive` and commit the result",
                file=sys.stderr,
            )
            return 1
        print(
            "generated/ and docs/ match a fresh regeneration of "
            f"{len(shipped_targets())} shipped targets"
        )
        return 0

    shipped = not args.targets
    paths = shipped_targets() if shipped else [resolve_target(t) for t in args.targets]
    built = build_files(paths, index=shipped, overrides=_parse_set(args.set))
    root = Path(args.out) if args.out else project_root()
    written = [] if args.dry_run else write_files(built.files, root)
    if shipped and not args.dry_run:
        written.append(write_stiffness_figure(root))
    if args.json:
        print(describe_json(built.models))
        return 0
    for model in built.models:
        _summary(model)
    if written:
        print(f"wrote {len(written)} files under {root}")
    return 0


def _summary(model) -> None:
    from gearsym.derive.build import describe, display_path

    d = describe(model)
    print(f"{model.name}  ({display_path(model.scene.source)})")
    print(f"  states: {', '.join(d['states'])}   parameters: {len(d['parameters'])}")
    print(f"  omega_n = {d['scales']['omega_n_rad_per_s']:.6g} rad/s, omega = {d['omega']:.6g}")
    print("  f: " + ", ".join(f"{c} = {v:.6g}" for c, v in d["f"].items()))
    print("  kappa (means): " + ", ".join(f"{k} = {v['mean']:.6g}" for k, v in d["kappa"].items()))
    print("  xi: " + ", ".join(f"{k} = {v:.6g}" for k, v in d["xi"].items()))
    ops = d["operations"]
    print(f"  operations: rhs {ops['rhs']}, rhs + jacobian {ops['rhs_and_jacobian']}")


def _cmd_backlash(args) -> int:
    from gearsym.derive.backlash import fit_dead_zone

    try:
        fit = fit_dead_zone(args.order, args.range, None if args.continuous else args.step)
    except ValueError as err:
        raise _Fail(f"backlash: {err}") from None
    error = fit.max_error()
    if args.json:
        print(
            json.dumps(
                {
                    "order": fit.order,
                    "range": fit.fit_range,
                    "method": "continuous" if fit.samples is None else "samples",
                    "samples": fit.samples,
                    "coefficients": {
                        str(k): c for k, c in zip(fit.powers, fit.coefficients, strict=True)
                    },
                    "valid_range": [-fit.fit_range, fit.fit_range],
                    "max_error_vs_dead_zone": error,
                    "slope_at_zero": fit.coefficients[0],
                },
                indent=2,
            )
        )
        return 0
    how = (
        "continuous L2"
        if fit.samples is None
        else f"{fit.samples} uniform samples, step {args.step:g}"
    )
    print(
        f"odd polynomial of order {fit.order}, least squares on [-{fit.fit_range:g}, "
        f"{fit.fit_range:g}] ({how})"
    )
    for k, c in zip(fit.powers, fit.coefficients, strict=True):
        print(f"  x^{k:<2d} {c: .10f}")
    print(f"valid for |x| <= {fit.fit_range:g}; max |g - dead zone| = {error:.4g}")
    if fit.coefficients[0] < 0:
        print("note: negative slope at x = 0, so the origin of an unloaded mesh is unstable")
    return 0


def _system(scene_arg: str, sets: dict[str, float]):
    """The System of a scene: its generated module when current, else derived now into a
    cache folder (so a user's own scene needs no manual `gearsym derive`)."""
    import importlib
    import os

    from gearsym.derive import derive_model, load_target, resolve_target
    from gearsym.derive.emit import emit_module, write_atomic
    from gearsym.derive.model import inputs_hash
    from gearsym.solver.system import System

    path = resolve_target(scene_arg)
    scene = load_target(path)
    name = scene.name.replace("-", "_")
    digest = inputs_hash(scene)
    module = None
    try:
        module = importlib.import_module(f"gearsym.generated.{name}")
    except ModuleNotFoundError:
        pass
    if module is None or getattr(module, "INPUTS_SHA256", "") != digest:
        cache = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "gearsym"
        target = cache / f"{name}_{digest[:12]}.py"
        if not target.exists():
            model = derive_model(scene)
            write_atomic(target, emit_module(model, f"gearsym derive {path}"))
        module = target
    try:
        return System.load(module, **sets)
    except KeyError as err:
        raise _Fail(f"--set: {err.args[0]}") from None
    except ValueError as err:
        raise _Fail(f"--set: {err}") from None


def _analysis_settings(args) -> dict:
    for name in ("rtol", "atol"):
        value = getattr(args, name)
        if not (value > 0 and math.isfinite(value)):
            raise _Fail(f"--{name} must be a positive number, got {value}")
    for name in ("transient", "periods"):
        if getattr(args, name) < (0 if name == "transient" else 1):
            raise _Fail(f"--{name} must be a whole number >= {0 if name == 'transient' else 1}")
    return dict(method=args.method, rtol=args.rtol, atol=args.atol, transient=args.transient,
                periods=args.periods, lyapunov_periods=args.lyapunov_periods,
                on_invalid=args.on_invalid)  # fmt: skip


def _cmd_stiffness(args) -> int:
    import json
    import warnings

    from gearsym.derive._input import load_toml, nearest
    from gearsym.derive.scene import load_scene, resolve_target
    from gearsym.derive.stiffness_report import mesh_report, plot_mesh
    from gearsym.derive.topology import load_topology

    if args.slices < 1 or args.slices > 100000:
        raise _Fail(f"--slices {args.slices}: give a number of slices from 1 to 100000")
    if not 0 <= args.harmonics <= 64:
        raise _Fail(f"--harmonics {args.harmonics}: give 0 to 64 harmonics")
    path = resolve_target(args.target)
    data = load_toml(path)
    topology = load_scene(path).topology if "scene" in data else load_topology(path)
    meshes = topology.meshes
    if args.mesh:
        ids = [m.id for m in meshes]
        if args.mesh not in ids:
            raise _Fail(
                f"--mesh {args.mesh}: no such mesh in {topology.name}"
                + nearest(args.mesh, ids)
                + f"; meshes: {', '.join(ids)}"
            )
        meshes = [m for m in meshes if m.id == args.mesh]
    reports = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for mesh in meshes:
            rep, res = mesh_report(topology, mesh, slices=args.slices, harmonics=args.harmonics)
            reports.append(rep)
            if args.plot:
                plot = Path(args.plot)
                if len(meshes) > 1:
                    plot = plot.with_name(f"{plot.stem}_{mesh.id}{plot.suffix or '.png'}")
                plot_mesh(res, plot, f"{topology.name}: mesh {mesh.id}")
                rep["plot"] = str(plot)
    if args.json:
        print(json.dumps({"topology": topology.name, "meshes": reports}, indent=2))
        return 0
    for rep in reports:
        cr, pem, iso = rep["contact_ratio"], rep["pem"], rep["iso6336"]
        print(
            f"mesh {rep['mesh']} ({rep['driver']} drives {rep['driven']}), "
            f"b = {rep['face_width_mm']:g} mm"
        )
        print(
            f"  contact ratios: transverse {cr['transverse']:.4f}, axial {cr['axial']:.4f}, "
            f"total {cr['total']:.4f}"
        )
        print(
            f"  PEM ({pem['slices']} slices): km = {pem['mean_N_per_m']:.5e} N/m "
            f"(normal line of action; transverse {pem['mean_transverse_N_per_m']:.5e}), "
            f"k in [{pem['min_N_per_m']:.4e}, {pem['max_N_per_m']:.4e}]"
        )
        for h in pem["harmonics"]:
            print(
                f"    k_{h['order']}: cos {h['cos_N_per_m']:+.5e}, sin {h['sin_N_per_m']:+.5e} "
                f"N/m, |k_{h['order']}|/km = {h['ratio']:.5f}"
            )
        print(
            f"    fit residual: RMS {pem['fit_residual_rms']:.2e}, max "
            f"{pem['fit_residual_max']:.2e} of km"
        )
        print(
            f"  ISO 6336-1 method B: c'th = {iso['c_th']:.3f}, c' = {iso['c_prime']:.3f}, "
            f"c_gamma_alpha = {iso['c_gamma_alpha']:.3f}, c_gamma_beta = "
            f"{iso['c_gamma_beta']:.3f} N/(mm um); k = c_gamma_alpha b = "
            f"{iso['k_from_c_gamma_alpha_N_per_m']:.5e} N/m"
        )
        print(f"  PEM / ISO = {rep['pem_over_iso']:.4f}")
        print(
            f"  phase lag {rep['phase']['rad']:.6f} rad ({rep['phase']['source']}); "
            f"transmission error {rep['transmission_error']['amplitude_um']} um"
        )
        conv = ", ".join(
            f"N={r['slices']}: |k_1|/km={r['ratios'][0]:.5f}" if r["ratios"] else f"N={r['slices']}"
            for r in rep["convergence"]
        )
        print(f"  convergence: {conv}")
        for w in rep["warnings"]:
            print(f"  warning: {w}")
        if "plot" in rep:
            print(f"  wrote {rep['plot']}")
    return 0


def _cmd_bench(args) -> int:
    import importlib.util

    from gearsym.derive.build import project_root

    path = project_root() / "benchmarks" / "performance.py"
    if not path.exists():
        raise _Fail(
            "bench needs the checkout's benchmarks/ folder; install gearsym from a clone "
            "with `pip install -e .`"
        )
    spec = importlib.util.spec_from_file_location("gearsym_benchmarks_performance", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    argv = (["--quick"] if args.quick else []) + (["--json"] if args.json else [])
    if args.out:
        argv += ["--out", args.out]
    return bench.main(argv)


def _cmd_simulate(args) -> int:
    from gearsym.solver._json import dumps
    from gearsym.solver.point import analyse_point
    from gearsym.solver.simulate import SimulationError

    system = _system(args.scene, _parse_set(args.set))
    try:
        result = analyse_point(system, **_analysis_settings(args))
    except (SimulationError, ValueError) as err:
        raise _Fail(f"simulate: {err}") from None
    data = result.describe()
    if args.out:
        from gearsym.solver import plots

        out = _write_json(args.out, "point.json", data)
        plots.point_figure(result.trajectory, out / "point.png", title=system.name)
    if args.json:
        print(dumps(data, indent=1))
        return 0
    tr = result.trajectory
    print(f"{system.name}: {tr.method}, rtol {tr.rtol:g}, {tr.transient} + {tr.periods} periods, "
          f"{tr.wall_time:.2f} s, status {tr.status}")  # fmt: skip
    if result.lyapunov is not None:
        print(f"  largest Lyapunov exponent {result.lyapunov.exponent:.5f} per unit tau")
    if tr.status != "ok":
        print(f"  {tr.message}")

    def num(v, fmt=".4f"):
        return "n/a" if v is None else format(v, fmt)

    for c, k in result.classification.items():
        e = data["extremes"][c]
        peaks = ", ".join(f"{p['frequency']:.3g}" for p in data["spectra"][c]["peaks"][:4])
        shares = data["meshing_states"][c]
        print(f"  {c}: {k.motion:<15} range [{num(e['min'])}, {num(e['max'])}]  peaks at "
              f"{peaks or 'n/a'}  forward/separated/backward {num(shares['forward'], '.2f')}/"
              f"{num(shares['separated'], '.2f')}/{num(shares['backward'], '.2f')}")  # fmt: skip
    if tr.left_valid_range is not None:
        t, c, v = tr.left_valid_range
        print(f"  warning: {c} = {v:.3g} at tau = {t:.6g} is outside the backlash model's "
              f"valid range |{c}| <= {system.valid_range:g}")  # fmt: skip
    return 0


def _parse_range(text: str):
    import numpy as np

    parts = text.split(":")
    try:
        if len(parts) != 3:
            raise ValueError
        start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise _Fail(f"--range {text}: expected START:STOP:NUM, for example 0:1:51 "
                    "(write --range=-0.5:1:11 when START is negative)") from None  # fmt: skip
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise _Fail(f"--range {text}: START and STOP must be finite numbers")
    if num < 1 or (num == 1 and start != stop):
        raise _Fail(f"--range {text}: NUM must be >= 2, or 1 with START equal to STOP")
    return np.linspace(start, stop, num)


def _cmd_sweep(args) -> int:
    from gearsym.solver import plots
    from gearsym.solver.reproduce import runs_text
    from gearsym.solver.simulate import SimulationError
    from gearsym.solver.sweep import Progress, sweep

    values = _parse_range(args.range)
    system = _system(args.scene, _parse_set(args.set))
    out = Path(args.out or f"sweep_{system.name}_{args.param}")
    bar = Progress(len(values), f"{args.param}", enabled=not args.quiet)
    stored = len(list((out / "store" / "points").glob("[0-9]*.json")))
    try:
        result = sweep(system, args.param, values, continuation=not args.independent,
                       backward=args.backward, executor=args.executor, progress=bar,
                       scheduler=args.scheduler,
                       store=out / "store", **_analysis_settings(args))  # fmt: skip
    except (SimulationError, ValueError) as err:
        raise _Fail(f"sweep: {err}") from None
    failed = [p["value"] for p in result.points if p["status"] != "ok"]
    if stored:
        print(f"resumed: {stored} of {len(values)} points came from {out / 'store'}")
    path = result.save(out / "sweep.json")
    fig = plots.bifurcation_diagram([result], list(system.coordinates), out / "bifurcation.png",
                                    title=f"{system.name}: {args.param} sweep")  # fmt: skip
    print(f"wrote {path} and {fig}")
    for c in system.coordinates:
        print(f"  {c}: {runs_text(values, result.motion(c))}")
    if failed:
        print(f"  {len(failed)} point(s) did not finish normally (status in sweep.json): "
              + ", ".join(f"{v:g}" for v in failed[:10]))  # fmt: skip
    return 0


def _cmd_reproduce(args) -> int:
    import time

    from gearsym.solver.reproduce import reproduce

    started = time.perf_counter()
    report = reproduce(Path(args.out), quick=args.quick,
                       executor="serial" if args.serial else "processes",
                       progress=not args.quiet)  # fmt: skip
    print(f"wrote {report} ({time.perf_counter() - started:.0f} s)")
    print(report.read_text(encoding="utf-8").split("## Figures")[0])
    return 0


def _write_json(folder: str, name: str, data) -> Path:
    """Write ``data`` as ``folder/name`` (no NaN: see solver._json); return the folder."""
    from gearsym.solver._json import dumps

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    (out / name).write_text(dumps(data, indent=1), encoding="utf-8")
    return out


def _orbit_guess(system, n: int, settle: int):
    """A starting state on the attractor at tau = 0 (mod nT), from a simulation."""
    from gearsym.solver.simulate import SimulationError, simulate

    if n < 1 or settle < 0:
        raise _Fail(f"--period must be >= 1 and --settle >= 0 (got {n} and {settle})")
    try:
        run = simulate(system, method="cvodes", transient=settle * n, periods=n,
                       samples_per_period=1)  # fmt: skip
    except (SimulationError, ValueError) as err:
        raise _Fail(f"the simulation that gives the initial guess failed: {err}") from None
    if run.status != "ok":
        raise _Fail(f"the simulation that gives the initial guess ended {run.status}: "
                    f"{run.message}")  # fmt: skip
    return run.poincare[:, 0]


def _cmd_shoot(args) -> int:
    from gearsym.solver._json import dumps
    from gearsym.solver.shooting import ShootingError, shoot

    if args.period < 1 or args.segments < 1:
        raise _Fail("--period and --segments must be whole numbers >= 1")
    system = _system(args.scene, _parse_set(args.set))
    guess = _orbit_guess(system, args.period, args.settle)
    try:
        orbit = shoot(system, guess, args.period, segments=args.segments,
                      monodromy=args.monodromy)  # fmt: skip
    except ShootingError as err:
        raise _Fail(f"shoot: {err}; residuals {[f'{r:.2g}' for r in err.history]}") from None
    data = orbit.describe()
    if args.out:
        from gearsym.solver import plots

        out = _write_json(args.out, "orbit.json", data)
        plots.multipliers_figure(orbit.floquet.multipliers, out / "multipliers.png",
                                 title=f"{system.name}: period-{orbit.n} orbit")  # fmt: skip
    if args.compare_monodromy:
        from gearsym.solver.flow import FlowMap

        flow = FlowMap(system)
        mats = {m: flow.with_jacobian(orbit.x0, orbit.period, method=m)[1]
                for m in ("ad", "variational", "fd")}  # fmt: skip
        scale = np.max(np.abs(mats["ad"]))
        data["monodromy_agreement"] = {
            f"{a}_vs_{b}": float(np.max(np.abs(mats[a] - mats[b])) / scale)
            for a, b in (("ad", "variational"), ("ad", "fd"), ("variational", "fd"))
        }
    if args.json:
        print(dumps(data, indent=1))
        return 0
    fl = orbit.floquet
    print(f"{system.name}: period-{orbit.n} orbit, residual {orbit.residual:.2e} after "
          f"{orbit.iterations} Newton iteration(s) ({args.monodromy or 'default'} monodromy, "
          f"{args.segments} segment(s))")  # fmt: skip
    print("  x0: " + ", ".join(f"{k} = {v:.10g}" for k, v in data["x0"].items()))
    print("  multipliers: " + ", ".join(f"{m.real:+.6f}{m.imag:+.6f}i (|{abs(m):.6f}|)"
                                        for m in fl.multipliers))  # fmt: skip
    losing = {"fold": "+1 (fold)", "period-doubling": "-1 (period doubling)",
              "neimark-sacker": "a complex pair (Neimark-Sacker)"}[fl.kind]  # fmt: skip
    print(f"  {'stable' if fl.stable else 'unstable'}; the largest multiplier is on the side of "
          f"{losing}; Liouville error |log det M - ∫ tr J| = {fl.liouville_error:.2e}")  # fmt: skip
    for k, v in data.get("monodromy_agreement", {}).items():
        print(f"  monodromy {k}: {v:.2e} (max difference / max entry)")
    return 0


def _cmd_continue(args) -> int:
    from gearsym.solver import plots
    from gearsym.solver._json import dumps
    from gearsym.solver.continuation import continue_orbit, switch_period_doubling
    from gearsym.solver.shooting import ShootingError

    for name in ("from_", "to"):
        if not math.isfinite(getattr(args, name)):
            raise _Fail(f"--{name.rstrip('_')} must be a finite number")
    if not (args.step > 0 and math.isfinite(args.step)):
        raise _Fail(f"--step must be a positive number, got {args.step}")
    if args.period < 1:
        raise _Fail(f"--period must be >= 1, got {args.period}")
    system = _system(args.scene, _parse_set(args.set))
    try:
        start = system.with_values(**{args.param: args.from_})
    except KeyError as err:
        raise _Fail(f"--param: {err.args[0]}") from None
    except ValueError as err:
        raise _Fail(f"--from: {err}") from None
    guess = _orbit_guess(start, args.period, args.settle)
    try:
        branches = [continue_orbit(system, args.param, args.from_, args.to, guess,
                                   n=args.period, ds=args.step, ds_max=4 * args.step)]  # fmt: skip
    except ShootingError as err:
        raise _Fail(f"continue: the first orbit was not found: {err}") from None
    except ValueError as err:
        raise _Fail(f"continue: {err}") from None
    if args.switch:
        for bif in list(branches[0].bifurcations):
            if bif.kind == "period-doubling":
                try:
                    branches.append(switch_period_doubling(system, args.param, bif, args.period,
                                                           args.to, ds=args.step,
                                                           ds_max=4 * args.step))  # fmt: skip
                except ShootingError as err:
                    print(f"  branch switching at {bif.value:.6g} failed: {err}")
    out = Path(args.out or f"continue_{system.name}_{args.param}")
    out.mkdir(parents=True, exist_ok=True)
    (out / "branches.json").write_text(dumps([b.describe() for b in branches], indent=1),
                                       encoding="utf-8")  # fmt: skip
    state = system.coordinates[0]
    plots.branch_figure(branches, out / "branches.png", 0, state,
                        title=f"{system.name}: continuation in {args.param}")  # fmt: skip
    for k, br in enumerate(branches):
        for b in br.bifurcations:
            lam = b.value
            sys_b = system.with_values(**{args.param: lam})
            from gearsym.solver.flow import FlowMap

            _, M, _ = FlowMap(sys_b).with_jacobian(b.x0, br.n * sys_b.period)
            plots.multipliers_figure(np.linalg.eigvals(M),
                                     out / f"multipliers_{k}_{b.kind}_{lam:.6g}.png",
                                     title=f"{b.kind} at {args.param} = {lam:.6g}")  # fmt: skip
    for br in branches:
        stable = sum(br.stable)
        print(f"period-{br.n} branch: {len(br.values)} points, {stable} stable; {br.message}")
        for b in br.bifurcations:
            print(f"  {b.kind:<16} {args.param} = {b.value:.8g}  multiplier "
                  f"{b.multiplier.real:+.6f}{b.multiplier.imag:+.6f}i")  # fmt: skip
    print(f"wrote {out / 'branches.json'} and {out / 'branches.png'}")
    return 0


def _analysis_options(sub) -> None:
    from gearsym.solver.simulate import METHODS

    sub.add_argument("--set", action="append", metavar="KEY=VALUE",
                     help="set a scene or model parameter (repeatable)")  # fmt: skip
    sub.add_argument("--method", choices=METHODS, default=None, help="integrator")
    sub.add_argument("--rtol", type=float, default=1e-8)
    sub.add_argument("--atol", type=float, default=1e-10)
    sub.add_argument("--transient", type=int, default=300, help="periods discarded")
    sub.add_argument("--periods", type=int, default=100, help="periods sampled")
    sub.add_argument("--on-invalid", choices=("warn", "error"), default="warn",
                     help="when a coordinate leaves the backlash model's valid range: warn "
                     "and go on, or stop the run there (status 'invalid')")  # fmt: skip
    sub.add_argument("--lyapunov-periods", type=int, default=200,
                     help="periods for the largest Lyapunov exponent (0: skip)")  # fmt: skip


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="gearsym", description="Gear-train nonlinear dynamics: derive, generate code, analyse."
    )
    parser.add_argument(
        "--debug", action="store_true", help="show full tracebacks instead of one-line errors"
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    d = sub.add_parser(
        "derive",
        help="derive models; write generated/ and docs/",
        description="Derive the non-dimensional model of scenes or "
        "topologies, write generated/<name>.py and docs/derivation/<name>.md. "
        "Without targets: every shipped scene and topology, and "
        "docs/derivation.md.",
    )
    d.add_argument(
        "targets",
        nargs="*",
        metavar="SCENE_OR_TOPOLOGY",
        help="a .toml path or the name of a built-in scene or topology",
    )
    d.add_argument(
        "--json",
        action="store_true",
        help="print every number of the non-dimensional equations as JSON",
    )
    d.add_argument(
        "--check",
        action="store_true",
        help="exit 1, naming the files, if generated/ or docs/ are stale",
    )
    d.add_argument("--out", metavar="DIR", help="write under DIR instead of the project")
    d.add_argument(
        "--set",
        action="append",
        metavar="KEY=VALUE",
        help="override a scene parameter (repeatable)",
    )
    d.add_argument("--dry-run", action="store_true", help="derive but write nothing")
    d.set_defaults(func=_cmd_derive)

    b = sub.add_parser(
        "backlash",
        help="odd-polynomial least-squares fit of the dead zone",
        description="Fit an odd polynomial to the unit dead zone by least "
        "squares; with the defaults it reproduces the reference study's "
        "7th-order coefficients.",
    )
    b.add_argument("--order", type=int, default=7, help="odd order (default 7)")
    b.add_argument(
        "--range", type=float, default=3.0, metavar="A", help="fit on [-A, A] (default 3)"
    )
    b.add_argument(
        "--step", type=float, default=0.01, help="spacing of the uniform samples (default 0.01)"
    )
    b.add_argument("--continuous", action="store_true", help="continuous L2 fit instead of samples")
    b.add_argument("--json", action="store_true", help="print JSON")
    b.set_defaults(func=_cmd_backlash)

    st = sub.add_parser("stiffness", help="mesh stiffness from gear geometry (PEM and ISO 6336)",
                        description="Time-varying mesh stiffness of each mesh of a topology "
                        "(or a scene's topology) by the sliced potential-energy method, its "
                        "Fourier fit, the ISO 6336-1 method B cross-check, the layout phase "
                        "and the transmission error.")  # fmt: skip
    st.add_argument(
        "target",
        metavar="PAIR_OR_SCENE",
        help="a topology or scene: .toml path or built-in name (e.g. diso)",
    )
    st.add_argument("--mesh", metavar="ID", help="only this mesh")
    st.add_argument(
        "--slices",
        type=int,
        default=200,
        metavar="N",
        help="transverse slices across the face width (default 200)",
    )
    st.add_argument(
        "--harmonics",
        type=int,
        default=3,
        metavar="H",
        help="harmonics in the Fourier fit (default 3)",
    )
    st.add_argument("--json", action="store_true", help="print everything as JSON")
    st.add_argument(
        "--plot",
        metavar="FILE",
        help="draw k(t), its harmonic fit and one tooth pair (FILE_<mesh> for several meshes)",
    )
    st.set_defaults(func=_cmd_stiffness)

    be = sub.add_parser("bench", help="measure speed against accuracy; write docs/performance.md",
                        description="Benchmarks of every integration back end (benchmarks/"
                        "performance.py): the headline sweep against the plain SciPy baseline "
                        "and a hand-written C reference, throughput, the speed/accuracy Pareto "
                        "table, feature costs and scaling.")  # fmt: skip
    be.add_argument("--quick", action="store_true", help="fewer points and repeats (~1 min)")
    be.add_argument("--json", action="store_true", help="also print every figure as JSON")
    be.add_argument("--out", metavar="FILE", help="write FILE instead of docs/performance.md")
    be.set_defaults(func=_cmd_bench)

    si = sub.add_parser("simulate", help="simulate one operating point and classify it",
                        description="Simulate a scene, discard the transient, and report the "
                        "Poincaré points, motion type with its evidence, ranges, spectral "
                        "peaks and meshing-state shares of every mesh.")  # fmt: skip
    si.add_argument("scene", metavar="SCENE", help="a scene path or built-in name")
    _analysis_options(si)
    si.add_argument("--json", action="store_true", help="print everything as JSON")
    si.add_argument("--out", metavar="DIR", help="also write point.json and point.png")
    si.set_defaults(func=_cmd_simulate, method_default="RK45")

    sw = sub.add_parser("sweep", help="bifurcation diagram over one parameter",
                        description="Sweep one scene or model parameter with continuation "
                        "of the final state (forward, or --backward), or --independent points "
                        "run in parallel.")  # fmt: skip
    sw.add_argument("scene", metavar="SCENE")
    sw.add_argument("--param", required=True, help="parameter to sweep, e.g. lambda")
    sw.add_argument("--range", required=True, metavar="START:STOP:NUM",
                    help="NUM values from START to STOP; write --range=-1:1:21 when START "
                    "is negative")  # fmt: skip
    sw.add_argument("--backward", action="store_true", help="continue from STOP to START")
    sw.add_argument(
        "--independent",
        action="store_true",
        help="no continuation: every point from the same initial state",
    )
    sw.add_argument("--executor", choices=("serial", "processes", "dask"), default="processes",
                    help="serial, local processes (default, all cores) or dask.distributed "
                    "(needs gearsym[dask]; a LocalCluster unless --scheduler)")  # fmt: skip
    sw.add_argument("--scheduler", metavar="ADDRESS",
                    help="dask scheduler address, e.g. tcp://head:8786")  # fmt: skip
    sw.add_argument("--out", metavar="DIR")
    sw.add_argument("--quiet", action="store_true", help="no progress bar")
    _analysis_options(sw)
    sw.set_defaults(func=_cmd_sweep, method_default="fastest")

    sh = sub.add_parser("shoot", help="find a periodic orbit by shooting; Floquet multipliers",
                        description="Find the period-n orbit (period n T) by Newton shooting "
                        "from a simulated guess, with its Floquet multipliers, stability and "
                        "Liouville check.")  # fmt: skip
    sh.add_argument("scene", metavar="SCENE")
    sh.add_argument("--set", action="append", metavar="KEY=VALUE")
    sh.add_argument("--period", type=int, default=1, help="n: the orbit's period is n T")
    sh.add_argument("--segments", type=int, default=1, help="multiple shooting segments")
    sh.add_argument("--monodromy", choices=("ad", "variational", "fd"), default=None,
                    help="monodromy route (default: ad; variational with located "
                    "crossings for a dead zone)")  # fmt: skip
    sh.add_argument(
        "--compare-monodromy",
        action="store_true",
        help="also compute the monodromy the other two ways and compare",
    )
    sh.add_argument("--settle", type=int, default=300, help="periods simulated for the guess")
    sh.add_argument("--json", action="store_true")
    sh.add_argument("--out", metavar="DIR", help="also write orbit.json and multipliers.png")
    sh.set_defaults(func=_cmd_shoot)

    co = sub.add_parser("continue", help="continue a periodic orbit in a parameter",
                        description="Pseudo-arclength continuation of the period-n orbit, "
                        "with fold, period-doubling and Neimark-Sacker points located."
                        )  # fmt: skip
    co.add_argument("scene", metavar="SCENE")
    co.add_argument("--param", required=True)
    co.add_argument("--from", dest="from_", type=float, required=True)
    co.add_argument("--to", type=float, required=True)
    co.add_argument("--period", type=int, default=1)
    co.add_argument("--step", type=float, default=0.02, help="initial arclength step")
    co.add_argument(
        "--switch",
        action="store_true",
        help="switch onto the period-2n branch at each period doubling",
    )
    co.add_argument("--settle", type=int, default=300)
    co.add_argument("--set", action="append", metavar="KEY=VALUE")
    co.add_argument("--out", metavar="DIR")
    co.set_defaults(func=_cmd_continue)

    rp = sub.add_parser("reproduce", help="the reference study's analyses and report",
                        description="Run the reference study's light- and heavy-load "
                        "analyses; write figures, data and report.md.")  # fmt: skip
    rp.add_argument("--out", default="reproduce-out", metavar="DIR")
    rp.add_argument("--quick", action="store_true", help="coarse resolution (under a minute)")
    rp.add_argument("--serial", action="store_true", help="one process only")
    rp.add_argument("--quiet", action="store_true", help="no progress bar")
    rp.set_defaults(func=_cmd_reproduce)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if getattr(args, "method", "absent") is None:
        args.method = args.method_default
        if args.method == "fastest":
            from gearsym.solver.simulate import fastest_method

            args.method = fastest_method(args.rtol)
    if args.debug:
        return args.func(args)
    from gearsym.derive import InputError

    try:
        return args.func(args)
    except (InputError, _Fail) as err:
        print(f"gearsym: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("gearsym: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
