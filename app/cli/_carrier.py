"""``gearsym modes SET --speeds LO:HI[:NUM]`` of a planetary set: its natural frequencies
against the carrier's speed (``gearsym.planetary.carrier_sweep``), for the terminal, a
figure and the result files."""

from __future__ import annotations

from ._common import Fail, figure_file, out_folder
from ._output import write_result

__all__ = ["carrier_speeds", "run_carrier_sweep"]

DEFAULT_NUM = 41  # speeds of the sweep when --speeds gives none


def carrier_speeds(text: str) -> tuple[float, float, int]:
    """``(lo, hi, num)`` of ``--speeds LO:HI[:NUM]`` for a planetary set (carrier rpm)."""
    parts = text.split(":")
    try:
        if len(parts) not in (2, 3):
            raise ValueError
        lo, hi = float(parts[0]), float(parts[1])
        num = int(parts[2]) if len(parts) == 3 else DEFAULT_NUM
    except ValueError:
        raise Fail(
            f"--speeds {text}: expected LO:HI or LO:HI:NUM (carrier rpm, NUM speeds), for "
            "example 0:6000:61"
        ) from None
    if not (0 <= lo < hi < float("inf")) or not 2 <= num <= 2001:
        raise Fail(f"--speeds {text}: give 0 <= LO < HI, finite, in rpm, and 2 <= NUM <= 2001")
    return lo, hi, num


def run_carrier_sweep(path, st, args) -> int:
    """The sweep of the derived set ``st`` (``path`` its file) as ``args`` ask."""
    import gearsym

    lo, hi, num = carrier_speeds(args.speeds)
    if args.parametric or args.floquet or getattr(args, "te", False):
        if getattr(args, "te", False):
            raise Fail(
                "--speeds with --te: the transmission-error analysis is at the file's carrier "
                "speed, not over a range of them; run them one at a time"
            )
        raise Fail(
            "--speeds with --parametric: that analysis is at the file's carrier speed, not "
            "over a range of them; run them one at a time"
        )
    if args.plot:
        figure_file(args.plot, "--plot")
    try:
        sweep = gearsym.planetary.carrier_sweep(st, lo, hi, num)
    except ValueError as err:
        raise Fail(f"--speeds {args.speeds}: {err}") from None
    if args.plot:
        from gearsym.solver.plots_modes import carrier_figure
        from gearsym.solver.plots_style import save_figure

        save_figure(carrier_figure(sweep), args.plot)
    if args.out:
        from gearsym.solver.export import Document

        columns = ["speed_rpm", "mode", "frequency_hz", "label"]
        rows = [
            [n, m["index"], f, label]
            for i, n in enumerate(sweep["speeds_rpm"])
            for m in modes_at(sweep, i)
            for f, label in [(m["frequency_hz"][i], m["label"][i])]
        ]
        data = sweep | {"source": str(path)}
        write_result(out_folder(args.out), "carrier_sweep", Document(data, columns, rows), args)
    if args.json:
        from gearsym.solver._json import dumps

        print(dumps(sweep, indent=1))
        return 0
    _print(sweep)
    if args.plot:
        print(f"  Campbell diagram: {args.plot}")
    return 0


def modes_at(sweep: dict, i: int) -> list:
    """The modes with a frequency at speed index ``i`` (none where the set diverges)."""
    return [m for m in sweep["modes"] if m["frequency_hz"][i] is not None]


def _print(sweep: dict) -> None:
    speeds = sweep["speeds_rpm"]
    frame = (
        "frequencies seen from the carrier (gyroscopic and centripetal terms)"
        if sweep["frame"].startswith("the carrier")
        else "a torsional model: no term depends on the speed"
    )
    print(
        f"{sweep['model']}: {len(sweep['modes'])} elastic modes against the carrier speed, "
        f"{speeds[0]:g} to {speeds[-1]:g} rpm ({len(speeds)} speeds); {frame}"
    )
    print(f"  {'#':>2}  {'type at LO':<13}  {'Hz at LO':>9}  {'Hz at HI':>9}  (-: no modes there)")

    def hz(v) -> str:
        return f"{'-':>9}" if v is None else f"{v:9.1f}"

    for m in sweep["modes"]:
        f, label = m["frequency_hz"], m["label"][0] or "-"
        print(f"  {m['index']:2d}  {label:<13}  {hz(f[0])}  {hz(f[-1])}")
    for u in sweep["unstable"][:1]:
        print(
            f"  no modes at {len(sweep['unstable'])} speeds from {u['speed_rpm']:g} rpm: {u['why']}"
        )
    if sweep["mesh"] is None:
        print(f"  no mesh-frequency lines: {sweep['mesh_why_not']}")
        return
    mesh = sweep["mesh"]
    print(
        f"  mesh frequency {mesh['ring_teeth']} x carrier rpm / 60 (the ring held); "
        f"its first 3 harmonics meet a mode {len(sweep['crossings'])} times"
    )
    first = [c for c in sweep["crossings"] if c["harmonic"] == 1]
    if len(first) > 10:
        print(f"    the first 10 of the 1x mesh's {len(first)}; all in --json, --out and --plot")
    for c in first[:10]:
        print(
            f"    1x mesh meets mode {c['mode']} ({c['label']}) at {c['speed_rpm']:.1f} rpm, "
            f"{c['frequency_hz']:.1f} Hz"
        )
