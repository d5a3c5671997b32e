"""Commands on the derivation side: ``derive``, ``backlash``, ``stiffness``."""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

from ._common import Fail, figure_file, parse_set

__all__ = ["register"]


def register(sub) -> None:
    d = sub.add_parser(
        "derive",
        help="derive models; write the generated code and its audit page",
        description="Derive the non-dimensional model of scenes or topologies and write "
        "the generated module and its audit page. Without targets: every shipped scene and "
        "topology into the project's generated/ and docs/ (with docs/derivation.md). A "
        "user's scene, or any target with --set, goes to the user cache "
        "($GEARSYM_CACHE/models, default ~/.cache/gearsym/models) unless --out.",
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
    b.add_argument("--order", type=int, default=7, help="odd order, 1 to 31")
    b.add_argument(
        "--range",
        type=float,
        default=3.0,
        metavar="A",
        help="fit on [-A, A], 1 < A <= 100",
    )
    b.add_argument(
        "--step",
        type=float,
        default=None,
        help="spacing of the uniform samples, at most 10^6 of them (default 0.01)",
    )
    b.add_argument("--continuous", action="store_true", help="continuous L2 fit instead of samples")
    b.add_argument("--json", action="store_true", help="print JSON")
    b.set_defaults(func=_cmd_backlash)

    st = sub.add_parser(
        "stiffness",
        help="mesh stiffness from gear geometry (PEM and ISO 6336)",
        description="Time-varying mesh stiffness of each mesh of a topology "
        "(or a scene's topology) by the sliced potential-energy method, its "
        "Fourier fit, the ISO 6336-1 method B cross-check, the layout phase "
        "and the transmission error.",
    )
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
        help="transverse slices across the face width, 1 to 100000",
    )
    st.add_argument(
        "--harmonics",
        type=int,
        default=3,
        metavar="H",
        help="harmonics in the Fourier fit, 0 to 64",
    )
    st.add_argument("--json", action="store_true", help="print everything as JSON")
    st.add_argument(
        "--plot",
        metavar="FILE",
        help="draw k(t), its harmonic fit and one tooth pair (FILE_<mesh> for several meshes)",
    )
    st.set_defaults(func=_cmd_stiffness)


def _cmd_derive(args) -> int:
    from gearsym.derive.build import (
        build_files,
        check,
        describe,
        project_root,
        shipped_targets,
        write_files,
        write_stiffness_figure,
    )
    from gearsym.derive.emit.python import write_atomic
    from gearsym.derive.input.scene import resolve_target

    if args.check:
        if args.targets or args.set or args.out or args.dry_run:
            raise Fail(
                "derive --check takes no targets, --set, --out or --dry-run: it checks the "
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
        from gearsym.derive.build import shipped_planetary, shipped_trains

        trains = len(shipped_trains())
        print(
            "generated/ and docs/ match a fresh regeneration of "
            f"{len(shipped_targets())} shipped targets, {len(shipped_planetary())} "
            f"planetary sets and {trains} gear train{'s' if trains != 1 else ''} with closed "
            "loops"
        )
        return 0

    shipped = not args.targets
    paths = shipped_targets() if shipped else [resolve_target(t) for t in args.targets]
    overrides = parse_set(args.set)
    built = build_files(paths, index=shipped, overrides=overrides)
    if args.out:
        files, where = built.files, Path(args.out)
    elif _as_shipped(paths, overrides):
        files, where = built.files, project_root()
    else:
        files, where = _cache_files(built), None
    if args.dry_run:
        written = []
    elif where is None:
        from gearsym.resolve import store_cached

        written = [Path(p) for p in files]
        for path, text in files.items():  # a module goes into the cache with its digest
            (store_cached if path.endswith(".py") else write_atomic)(Path(path), text)
    else:
        written = write_files(files, where)
        if shipped:
            written.append(write_stiffness_figure(where))
    if args.json:
        from gearsym.solver._json import dumps

        print(dumps({m.name: describe(m) for m in built.models}, indent=2))
        return 0
    for model in built.models:
        _summary(model)
    for rel in built.files:
        if rel.startswith("docs/derivation/") and Path(rel).stem not in {
            m.name for m in built.models
        }:
            print(
                f"{Path(rel).stem}  (a planetary set or gear train with closed loops: its "
                "audit page; its nonlinear model, where its file has a dynamics table, "
                "derived on first use)"
            )
    if where is None:
        for path in written:
            print(f"wrote {path}")
    elif written:
        names = ", ".join(
            str(Path(w).relative_to(where)) if Path(w).is_relative_to(where) else str(w)
            for w in written[:6]
        )
        more = f" and {len(written) - 6} more" if len(written) > 6 else ""
        print(f"wrote {names}{more} under {where}")
    return 0


def _as_shipped(paths, overrides) -> bool:
    """The shipped scenes and topologies as they are: their files belong in the project
    (that is what ``derive --check`` compares).  Anything else (a user's scene, or a
    shipped one with --set) never writes into the installed package."""
    from gearsym.derive.build import shipped_planetary, shipped_targets, shipped_trains

    shipped = {
        Path(p).resolve() for p in [*shipped_targets(), *shipped_planetary(), *shipped_trains()]
    }
    return not overrides and all(Path(p).resolve() in shipped for p in paths)


def _cache_files(built) -> dict[str, str]:
    """The generated modules (and audit pages beside them) at the derivation cache's
    names, where the scene resolver finds them (absolute paths)."""
    from gearsym.resolve import cached_module, model_cache

    files = {}
    for model in built.models:
        module = cached_module(model.name, model.inputs_hash)
        for rel, text in built.files.items():
            if Path(rel).stem == model.name:
                target = module if rel.endswith(".py") else module.with_suffix(".md")
                files[str(target)] = text
    models = {m.name for m in built.models}
    for rel, text in built.files.items():  # a planetary set's page: no module beside it
        if rel.startswith("docs/derivation/") and Path(rel).stem not in models:
            # named by its content too (not the command line it states, which names the
            # file as it was typed): two files of one name keep a page each
            said = ("Derived by ", "Generated by ")
            body = "\n".join(x for x in text.splitlines() if not x.startswith(said))
            digest = hashlib.sha256(body.encode("utf-8")).hexdigest()[:12]
            files[str(model_cache() / f"{Path(rel).stem}_{digest}.md")] = text
    return files


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
    from gearsym.derive.mesh.backlash import fit_dead_zone

    if args.continuous and args.step is not None:
        raise Fail(
            f"--step {args.step:g} sets the samples of a discrete fit and --continuous "
            "asks for none; drop one"
        )
    if args.step is None:
        args.step = 0.01
    try:
        fit = fit_dead_zone(args.order, args.range, None if args.continuous else args.step)
    except ValueError as err:
        option = {"order": "--order", "range": "--range"}.get(str(err).split(" ")[0], "--step")
        raise Fail(f"backlash {option}: {err}") from None
    error = fit.max_error()
    if args.json:
        from gearsym.solver._json import dumps

        print(
            dumps(
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


def _cmd_stiffness(args) -> int:
    import warnings

    from gearsym.derive.emit.stiffness_report import mesh_report, plot_mesh
    from gearsym.derive.input.reader import load_toml, nearest
    from gearsym.derive.input.scene import load_scene, resolve_target
    from gearsym.derive.input.topology import load_topology

    if args.slices < 1 or args.slices > 100000:
        raise Fail(f"--slices {args.slices}: give a number of slices from 1 to 100000")
    if not 0 <= args.harmonics <= 64:
        raise Fail(f"--harmonics {args.harmonics}: give 0 to 64 harmonics")
    if args.plot:
        figure_file(args.plot, "--plot")
    path = resolve_target(args.target)
    data = load_toml(path)
    topology = load_scene(path).topology if "scene" in data else load_topology(path)
    meshes = topology.meshes
    if args.mesh:
        ids = [m.id for m in meshes]
        if args.mesh not in ids:
            raise Fail(
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
        from gearsym.solver._json import dumps, with_status

        why = (
            "a stiffness overflowed or is undefined: check the material and gear data "
            "(a Young's modulus far outside physical ranges?)"
        )
        data = {"topology": topology.name, "meshes": reports}
        print(dumps(with_status(data, why), indent=2))
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
