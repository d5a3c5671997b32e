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
traceback instead.  Unix manners: when the reader of the output goes away
(``gearsym ... | head -1``) the command ends quietly, killed by SIGPIPE as ``cat`` is (the
shell reports 141); Ctrl-C prints one line and exits 130, keeping what was stored.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys

# The commands parallelise over processes and their matrices are small: one BLAS thread
# per process (set before NumPy loads; a value the user set is kept).  Idle BLAS threads
# spinning at start-up cost a sweep a third of a second of CPU on two cores.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from . import _notes, atlas, derive, modes, orbits, point, response, study  # noqa: E402
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
    from gearsym.derive.escape import one_line

    return f"gearsym: warning: {one_line(message)}\n"


def _say(line: str) -> None:
    """One line on stderr (a newline in a user's path or name shown escaped); nothing
    when stderr itself is a closed pipe."""
    from gearsym.derive.escape import one_line

    try:
        print(one_line(line), file=sys.stderr, flush=True)
    except (OSError, ValueError):
        pass


def _reader_gone() -> bool:
    """Whether stdout or stderr is a pipe (or socket) whose reader has closed it: poll
    reports POLLERR on the write end then.  A broken pipe elsewhere (a connection to a
    dask scheduler, say) is not the user closing the output."""
    import select

    for stream in (sys.stdout, sys.stderr):
        try:
            poll = select.poll()
            poll.register(stream.fileno(), select.POLLOUT)
            if any(ev & (select.POLLERR | select.POLLHUP) for _, ev in poll.poll(0)):
                return True
        except (AttributeError, OSError, ValueError):  # no descriptor (captured output)
            continue
    return False


def _closed_pipe(as_program: bool) -> int:
    """End as ``cat`` does when its reader goes away: killed by SIGPIPE, no message.

    The exception has already unwound the command (its pool is shut down, its stores
    closed).  Run as the program, the process kills itself with SIGPIPE (exit status
    141 in the shell, -13 from ``subprocess``) after pointing stdout at /dev/null, so
    that nothing still buffered is flushed at exit into the closed pipe.  Called from
    Python (``main([...])``) it returns 128 + SIGPIPE instead of ending the caller.
    """
    code = 128 + getattr(signal, "SIGPIPE", 13)
    if not as_program:
        return code
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.dup2(devnull, sys.stderr.fileno())
    except (AttributeError, OSError, ValueError):
        pass
    if hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)
        os.kill(os.getpid(), signal.SIGPIPE)
    return code


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)  # the command, in result files
    _notes.forget()  # a process may run several commands (tests): each has its notes
    if getattr(args, "method", "absent") is None:
        from gearsym.solver.integrate import fastest_method

        args.method = fastest_method(args.rtol)
    try:
        return _run(args)
    except BrokenPipeError:
        if not _reader_gone():
            raise
        return _closed_pipe(as_program=argv is None)


def _run(args) -> int:
    """Run the command; every failure a user can cause becomes one line and a status."""
    if args.debug:
        code = args.func(args)
        sys.stdout.flush()
        _notes.say()
        return code
    import warnings

    from gearsym.derive import InputError

    shown, warnings.formatwarning = warnings.formatwarning, _one_line_warning
    try:
        if getattr(args, "out", None) and args.command != "bench":  # bench checks its own
            out_folder(args.out)
        if getattr(args, "format", None) is not None:
            from ._output import result_formats

            result_formats(args)
        code = args.func(args)
        sys.stdout.flush()  # a closed pipe shows here, not in the interpreter's exit
        _notes.say()  # a command that ran to its end (not refused, not failed)
        return code
    except (InputError, Fail) as err:
        _say(f"gearsym: error: {err}")
        return 2
    except RunFailed as err:
        _say(f"gearsym: run failed: {err}")
        return 3
    except BrokenPipeError as err:
        if _reader_gone():
            raise  # main() ends quietly
        _say(f"gearsym: error: a connection closed while writing ({err.strerror or err})")
        return 2
    except OSError as err:
        # A file-system failure the checks before computing could not foresee (the disk
        # filling up, say): the file and the reason; what was stored so far stays.
        where = err.filename or "a file"
        _say(
            f"gearsym: error: cannot write or read {where} ({err.strerror or err}); "
            "free space or choose another folder, and run again (finished work is kept)"
        )
        return 2
    except ValueError as err:
        from gearsym.solver.sweep.store import SweepStoreError

        if not isinstance(err, SweepStoreError):
            raise
        # An output folder whose store holds another sweep or map (reproduce's, say).
        _say(f"gearsym: error: {err}")
        return 2
    except MemoryError:
        _say("gearsym: error: out of memory; ask for fewer periods, points or harmonics")
        return 2
    except KeyboardInterrupt:
        # Every store (sweep, map) has its finished points already: the same command
        # resumes from them.  On a terminal the progress line may be half drawn.
        tty = getattr(sys.stderr, "isatty", lambda: False)()
        if tty:
            _say("")  # end the half-drawn progress line
        _say("gearsym: interrupted")
        return 130
    finally:
        warnings.formatwarning = shown


if __name__ == "__main__":
    sys.exit(main())
