"""``gearsym modes``: natural frequencies and mode shapes of the linear, time-averaged
model, with the resonance (Campbell) diagram against the mesh frequency."""

from __future__ import annotations

import math
import sys

from ._common import Fail, figure_file, out_folder
from ._output import format_option, write_result

__all__ = ["register"]


def register(sub) -> None:
    p = sub.add_parser(
        "modes",
        help="natural frequencies, mode shapes and the resonance diagram of a model",
        description="Natural frequencies (Hz and over the mesh frequency) and mode shapes of "
        "the linear, time-averaged model (mean mesh stiffness, backlash closed, no damping), "
        "each labelled by where its kinetic energy sits, and the speeds where a mesh-frequency "
        "harmonic meets one.",
    )
    p.add_argument("target", help="built-in scene or topology name, or a .toml path")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument(
        "--speeds",
        metavar="LO:HI",
        help="speed range of the first mesh's driver, rpm (default: 0 to twice the scene's); "
        "of a planetary set, LO:HI[:NUM] the carrier's speeds (NUM of them, default 41): "
        "its natural frequencies against them, the Campbell diagram with --plot",
    )
    p.add_argument(
        "--plot",
        metavar="FILE",
        help="write the resonance diagram (PNG, PDF, SVG); of a planetary set with "
        "--parametric, its parametric-instability diagram, with --te its meshes' forces "
        "under their transmission errors, with --speeds its Campbell diagram",
    )
    p.add_argument("--out", metavar="DIR", help="also write modes.json, .csv, .mat (--format)")
    p.add_argument(
        "--parametric",
        action="store_true",
        help="a planetary set: the primary parametric instabilities its meshes' stiffness "
        "variation ([planetary.variation]) drives, first order, each band of the mesh "
        "frequency or marked suppressed by the phasing (default: off)",
    )
    p.add_argument(
        "--te",
        action="store_true",
        help="a planetary set: which modes each harmonic of the meshes' transmission error "
        "excites and which the planets' phasing suppresses (the file's errors, else 1 µm "
        "in harmonics 1 to N on the sun and on the ring meshes apart; needs the tooth "
        "counts)",
    )
    p.add_argument(
        "--floquet",
        action="store_true",
        help="with --parametric: each band's edges also by the Floquet multipliers (a second "
        "or two a band; default: off)",
    )
    format_option(p, "modes")
    p.set_defaults(func=_cmd_modes)


def _speeds(text: str | None, scene_rpm: float | None) -> tuple[float, float]:
    if text is None:
        return 0.0, 2.0 * scene_rpm
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except ValueError:
        raise Fail(f"--speeds {text}: expected LO:HI in rpm, for example 0:3000") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo < hi):
        raise Fail(f"--speeds {text}: give 0 <= LO < HI, finite, in rpm")
    return lo, hi


def _cmd_modes(args) -> int:
    from gearsym.derive.input.planetary import is_planetary
    from gearsym.derive.input.scene import resolve_target
    from gearsym.derive.input.train import is_train
    from gearsym.resolve import module_for
    from gearsym.solver.analysis.modes import modes

    path = resolve_target(args.target)
    if is_planetary(path):
        return _planetary(path, args)
    if args.te:
        raise Fail(
            "--te: the transmission-error table is for planetary sets (a [planetary] file); "
            "run without it"
        )
    if args.parametric or args.floquet:
        raise Fail(
            "--parametric: the parametric-instability table is for planetary sets (a "
            "[planetary] file); run without it"
        )
    if args.plot:
        figure_file(args.plot, "--plot")
    if is_train(path):  # a train with closed loops: its model in body coordinates
        from gearsym.derive.input.train import load_train

        train = load_train(path)
        if train.dynamics is None:  # no operating point: the linear model's modes alone
            from gearsym.derive.emit.planetary_module import inputs_hash
            from gearsym.planetary import train_modes
            from gearsym.solver.provenance import header

            head = header(train.name, inputs_hash(path), {}, {}, source=str(path))
            return _report(train_modes(train), None, lambda: head, args, strain=True)
        from gearsym.resolve import planetary_system

        module = planetary_system(path).module
    else:
        module = module_for(args.target)
    result = modes(module)

    def header():
        from gearsym.solver.provenance import provenance
        from gearsym.solver.system import System

        return provenance(System.load(module))

    scene_rpm = 60.0 * result.mesh_frequency_hz / result.reference_teeth
    return _report(result, scene_rpm, header, args, strain=is_train(path))


def _report(result, scene_rpm, header, args, *, strain: bool) -> int:
    """Print, write and draw ``result`` (``Modes``); ``scene_rpm`` the reference driver's
    speed at the scene's mesh frequency, None where the file states none (then the
    resonance speeds need ``--speeds``); ``header()`` the result files' header block;
    ``strain``: list where each mode strains (a train's bodies only turn) rather than where
    its kinetic energy sits."""
    if scene_rpm is None and args.plot and not args.speeds:
        raise Fail(
            f"--plot: {result.model} states no mesh frequency ([train.dynamics] "
            "mesh_frequency_hz), so the resonance diagram needs its speed range: add --speeds "
            "LO:HI (rpm of the first mesh's driver)"
        )
    speeds = None if scene_rpm is None and not args.speeds else _speeds(args.speeds, scene_rpm)
    if args.out:
        from gearsym.solver.export import Document

        data = header() | result.to_dict(speeds)
        write_result(out_folder(args.out), "modes", Document(data, *result.to_table()), args)
    if args.plot:
        from gearsym.solver.plots_modes import campbell_figure
        from gearsym.solver.plots_style import save_figure

        save_figure(campbell_figure(result, speeds, scene_rpm=scene_rpm), args.plot)
    if args.json:
        from gearsym.solver._json import dumps, with_status

        why = (
            "the eigenproblem overflowed: its inertias, masses or stiffnesses span more "
            "than double precision (one far outside physical ranges?)"
        )
        print(dumps(with_status(result.to_json(speeds), why), indent=1))
        return 0
    if scene_rpm is None:
        print(
            f"{result.model}: {len(result.modes)} modes of the linear, time-averaged model; "
            "its file states no mesh frequency ([train.dynamics]), so no ratio to it"
        )
    else:
        print(
            f"{result.model}: {len(result.modes)} modes of the linear, time-averaged model; "
            f"mesh frequency {result.mesh_frequency_hz:.1f} Hz at the scene's speed "
            f"({scene_rpm:.0f} rpm of gear {result.reference_driver}, the first mesh's driver)"
        )
    what = "strain energy" if strain else "kinetic energy"
    print(f"  {'#':>2}  {'Hz':>10}  {'/ mesh':>7}  {'label':<13}  {what}")
    for m in result.modes:
        energy = m.strain_shares if strain else m.kinetic_shares
        top = sorted(energy.items(), key=lambda kv: -kv[1]) if strain else energy.items()
        shares = ", ".join(f"{k} {v:.2f}" for k, v in top if v >= 0.005)
        ratio = result.over_mesh(m)
        ratio = "—" if ratio is None else f"{ratio:.3f}"
        print(f"  {m.index:2d}  {m.frequency_hz:10.1f}  {ratio:>7}  {m.label:<13}  {shares}")
    res = [r for r in result.resonances(speeds) if r["harmonic"] == 1] if speeds else []
    if res:
        print(
            f"  the mesh frequency meets a mode between {speeds[0]:g} and {speeds[1]:g} rpm "
            "at: "
            + ", ".join(f"{r['speed_rpm']:.0f} rpm (mode {r['mode']})" for r in res)
            + " (2x and 3x mesh in --json and --plot)"
        )
    if args.plot:
        print(f"  resonance diagram: {args.plot}")
    return 0


def _planetary(path, args) -> int:
    """``gearsym modes`` of a planetary set: the modes typed and counted as Lin and Parker
    (1999) prove them (``planetary_modes``); no speed is known, so no resonance diagram."""
    from gearsym.derive.equations.planetary import derive_planetary
    from gearsym.derive.input.planetary import load_planetary
    from gearsym.solver.analysis.modes import UnstableAtSpeed, planetary_modes

    if args.speeds:
        from ._carrier import carrier_speeds, run_carrier_sweep

        carrier_speeds(args.speeds)  # its one-line error before the derivation
        try:
            st = derive_planetary(load_planetary(path))
        except UnstableAtSpeed as err:
            raise Fail(f"{path}: {err}") from None
        return run_carrier_sweep(path, st, args)
    if args.plot and args.parametric == args.te:
        raise Fail(
            "--plot: a planetary set's diagrams are of --parametric (its parametric "
            "instabilities), --te (its meshes' forces under their transmission errors) or "
            "--speeds LO:HI (its modes against the carrier's speed); give one of them"
        )
    if args.plot:
        figure_file(args.plot, "--plot")
    ps = load_planetary(path)
    if (args.parametric or args.floquet) and ps.variation is None:
        raise Fail(
            f"--parametric: {path} has no [planetary.variation] table (the meshes' contact "
            "ratios and stiffness amplitude, and sun_teeth, ring_teeth for their phases); "
            "add it (docs/user-guide.md, Planetary sets)"
        )
    if args.floquet and not args.parametric:
        raise Fail("--floquet: only with --parametric; add --parametric")
    if args.te and ps.sun_teeth is None:
        raise Fail(
            f"--te: {path} has no sun_teeth and ring_teeth in [planetary], which the meshes' "
            "phases need; add them"
        )
    st = derive_planetary(ps)
    try:
        result = planetary_modes(st.as_structure(), ps.name)
    except UnstableAtSpeed as err:  # a carrier speed the set cannot run at
        raise Fail(f"{path}: {err}; lower carrier_speed_rpm") from None
    data = {
        "model": ps.name,
        "source": str(path),
        "degrees_of_freedom": ps.dofs,
        "carrier_speed_rpm": ps.carrier_speed_rpm,
        "planets": ps.planets,
        "planet_angles_deg": list(ps.angles_deg),
        "equally_spaced": ps.equally_spaced,
        "rigid_body_modes": st.rigid_body_modes,
        "mesh_phases": None
        if st.phases is None
        else [{"planet": n, "sun": g_s, "ring": g_r} for n, (g_s, g_r) in enumerate(st.phases, 1)],
        "modes": [
            {
                "index": m.index,
                "frequency_hz": m.frequency_hz,
                "label": m.label,
                "multiplicity": m.multiplicity,
                "kinetic_shares": m.kinetic_shares,
                "strain_shares": m.strain_shares,
                "shape": m.shape,
            }
            for m in result.modes
        ],
    }
    if args.parametric:
        from gearsym.planetary import parametric_instabilities

        if args.floquet:
            print("confirming each band by the Floquet multipliers", file=sys.stderr)
        data["parametric"] = parametric_instabilities(st, floquet=args.floquet)
    if args.te:
        from gearsym.planetary import te_excitation

        from ._parametric import te_response_around

        data["transmission_error"] = te_excitation(st)
        if args.plot:
            data["transmission_error"]["response"] = te_response_around(
                st, data["transmission_error"]
            )
    if args.plot:
        from gearsym.solver.plots_modes import parametric_figure, te_figure
        from gearsym.solver.plots_style import save_figure

        te = data.get("transmission_error")
        figure = te_figure(te["response"], te) if args.te else parametric_figure(data["parametric"])
        save_figure(figure, args.plot)
    if args.out:
        from gearsym.solver.export import Document

        columns = ["index", "frequency_hz", "label", "multiplicity"]
        rows = [[m.index, m.frequency_hz, m.label, m.multiplicity] for m in result.modes]
        write_result(out_folder(args.out), "modes", Document(data, columns, rows), args)
    if args.json:
        from gearsym.solver._json import dumps

        print(dumps(data, indent=1))
        return 0
    spacing = "equally spaced" if ps.equally_spaced else "unequally spaced"
    print(
        f"{ps.name}: {len(result.modes)} modes of the {ps.dofs} planetary model, "
        f"{ps.planets} {spacing} planets, "
        + (
            f"carrier at {ps.carrier_speed_rpm:g} rpm (gyroscopic and centripetal terms; "
            "frequencies seen from the carrier)"
            if ps.carrier_speed_rpm
            else "carrier speed 0 (no gyroscopic terms)"
        )
        + f"; {st.rigid_body_modes} rigid-body"
    )
    print(f"  {'#':>2}  {'Hz':>10}  {'type':<13}  {'x':>2}  kinetic energy")
    seen = set()
    for m in result.modes:
        key = (m.label, round(m.frequency_hz, 6))
        if key in seen:
            continue  # a repeated frequency once, with its multiplicity
        seen.add(key)
        shares = ", ".join(f"{k} {v:.2f}" for k, v in m.kinetic_shares.items() if v >= 0.005)
        print(
            f"  {m.index:2d}  {m.frequency_hz:10.1f}  {m.label:<13}  {m.multiplicity:2d}  {shares}"
        )
    counts = {}
    for m in result.modes:
        counts[m.label] = counts.get(m.label, 0) + 1
    print("  " + ", ".join(f"{n} {label}" for label, n in counts.items()))
    if args.parametric:
        from ._parametric import print_parametric

        print_parametric(data["parametric"])
    if args.te:
        from ._parametric import print_te

        print_te(data["transmission_error"])
    if args.plot:
        what = "transmission-error response" if args.te else "parametric-instability diagram"
        print(f"  {what}: {args.plot}")
    return 0
