"""The ``gearsym`` command line: one module per command group.

* ``derive.py`` -- derive, backlash, stiffness;
* ``modes.py`` -- modes;
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

from . import atlas, derive, modes, orbits, point, response, study  # noqa: E402
from ._common import Fail, OneLineParser, RunFailed, out_folder  # noqa: E402

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="gearsym", description="Gear-train nonlinear dynamics: derive, generate code, analyse."
    )
    parser.add_argument(
        "--debug", action="store_true", help="show full tracebacks instead of one-line errors"
    )
    sub = parser.add_subparsers(
        dest="command", required=True, metavar="COMMAND", parser_class=OneLineParser
    )
    for group in (derive, modes, point, orbits, atlas, response, study):
        group.register(sub)
    return parser


def _one_line_warning(message, category, filename, lineno, line=None) -> str:
    """Warnings on the command line: one line each, without the source line that
    raised them (``--debug`` keeps Python's own format)."""
    return f"gearsym: warning: {message}\n"


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if getattr(args, "method", "absent") is None:
        from gearsym.solver.integrate import fastest_method

        args.method = fastest_method(args.rtol)
    if args.debug:
        return args.func(args)
    import warnings

    from gearsym.derive import InputError

    shown, warnings.formatwarning = warnings.formatwarning, _one_line_warning
    try:
        if getattr(args, "out", None) and args.command != "bench":  # bench checks its own
            out_folder(args.out)
        return args.func(args)
    except (InputError, Fail) as err:
        print(f"gearsym: error: {err}", file=sys.stderr)
        return 2
    except RunFailed as err:
        print(f"gearsym: run failed: {err}", file=sys.stderr)
        return 3
    except OSError as err:
        # A file-system failure the checks before computing could not foresee (the disk
        # filling up, say): the file and the reason; what was stored so far stays.
        where = err.filename or "a file"
        print(f"gearsym: error: cannot write or read {where} ({err.strerror or err}); "
              "free space or choose another folder, and run again (finished work is kept)",
              file=sys.stderr)  # fmt: skip
        return 2
    except ValueError as err:
        from gearsym.solver.sweep.store import SweepStoreError

        if not isinstance(err, SweepStoreError):
            raise
        # An output folder whose store holds another sweep or map (reproduce's, say).
        print(f"gearsym: error: {err}", file=sys.stderr)
        return 2
    except MemoryError:
        print("gearsym: error: out of memory; ask for fewer periods, points or harmonics",
              file=sys.stderr)  # fmt: skip
        return 2
    except KeyboardInterrupt:
        print("gearsym: interrupted", file=sys.stderr)
        return 130
    finally:
        warnings.formatwarning = shown


if __name__ == "__main__":
    sys.exit(main())
