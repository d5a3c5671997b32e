"""Commands that run studies: ``reproduce`` and ``bench``."""

from __future__ import annotations

from pathlib import Path

from ._common import Fail

__all__ = ["register"]


def register(sub) -> None:
    rp = sub.add_parser(
        "reproduce",
        help="the reference study's analyses and report",
        description="Run the reference study's light- and heavy-load "
        "analyses; write figures, data and report.md.",
    )
    rp.add_argument(
        "--out",
        default="reproduce-out",
        metavar="DIR",
        help="folder for the report and its figures",
    )
    rp.add_argument("--quick", action="store_true", help="coarse resolution (under a minute)")
    rp.add_argument("--serial", action="store_true", help="one process only")
    rp.add_argument(
        "--fresh",
        action="store_true",
        help="compute every unit of work again instead of loading those a run with the same "
        "code and inputs kept in the result store of the model cache (default: load them)",
    )
    rp.add_argument(
        "--quiet", action="store_true", help="no progress lines on stderr (otherwise one per stage)"
    )
    rp.set_defaults(func=_cmd_reproduce)

    be = sub.add_parser(
        "bench",
        help="measure speed against accuracy; write performance.md and its figure",
        description="Benchmarks of every integration back end (gearsym.benchmarks."
        "performance): the headline sweep against the plain SciPy baseline and a hand-written "
        "C reference, throughput, the speed/accuracy Pareto table, feature costs and scaling. "
        "Writes performance.md and performance-pareto.png to --out DIR, or with --docs to the "
        "checkout's docs/. The folder is checked for writing before the run (several minutes).",
    )
    be.add_argument("--quick", action="store_true", help="fewer points and repeats (~1 min)")
    be.add_argument("--json", action="store_true", help="also print every figure as JSON")
    be.add_argument(
        "--out",
        metavar="DIR",
        help="folder for performance.md and performance-pareto.png "
        "(default bench-out; created if missing)",
    )
    be.add_argument(
        "--docs",
        action="store_true",
        help="write docs/performance.md and docs/performance-pareto.png of the checkout "
        "instead (the tracked report; not with --out)",
    )
    be.set_defaults(func=_cmd_bench)


def _cmd_reproduce(args) -> int:
    from gearsym.studies.reproduce import reproduce

    done = reproduce(
        Path(args.out),
        quick=args.quick,
        executor="serial" if args.serial else "processes",
        progress=not args.quiet,
        fresh=args.fresh,
    )
    print(done.summary())  # the report itself is in its file only
    return 0


def _cmd_bench(args) -> int:
    from gearsym.benchmarks import performance

    argv = ["--quick"] * args.quick + ["--json"] * args.json + ["--docs"] * args.docs
    if args.out is not None:
        argv.append(f"--out={args.out}")
    try:
        return performance.main(argv)
    except performance.OutputError as err:
        raise Fail(f"bench: {err}") from None
