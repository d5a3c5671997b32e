"""The ``gearsym`` command line: one module per command group.

* ``derive.py`` -- derive, backlash, stiffness;
* ``point.py`` -- simulate, sweep;
* ``orbits.py`` -- shoot, continue;
* ``atlas.py`` -- map;
* ``response.py`` -- frequency-response;
* ``study.py`` -- reproduce, bench;
* ``_common.py`` -- the one-line failure and the shared options.

User errors (bad files, bad values) print one line and exit 2; ``--debug`` shows the
traceback instead.
"""

from __future__ import annotations

import argparse
import os
import sys

# The commands parallelise over processes and their matrices are small: one BLAS thread
# per process (set before NumPy loads; a value the user set is kept).  Idle BLAS threads
# spinning at start-up cost a sweep a third of a second of CPU on two cores.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from . import atlas, derive, orbits, point, response, study  # noqa: E402
from ._common import Fail  # noqa: E402

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="gearsym", description="Gear-train nonlinear dynamics: derive, generate code, analyse."
    )
    parser.add_argument(
        "--debug", action="store_true", help="show full tracebacks instead of one-line errors"
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for group in (derive, point, orbits, atlas, response, study):
        group.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if getattr(args, "method", "absent") is None:
        from gearsym.solver.integrate import fastest_method

        args.method = fastest_method(args.rtol)
    if args.debug:
        return args.func(args)
    from gearsym.derive import InputError

    try:
        return args.func(args)
    except (InputError, Fail) as err:
        print(f"gearsym: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("gearsym: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
