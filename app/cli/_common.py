"""What every command of the CLI shares: the one-line failure, argument parsers, the
analysis options, the scene resolver's error wrapping and JSON output."""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path

import numpy as np

__all__ = [
    "LIMITS",
    "MAX_TOTAL_PERIODS",
    "Fail",
    "DefaultsFormatter",
    "OneLineParser",
    "RunFailed",
    "figure_file",
    "out_folder",
    "analysis_options",
    "analysis_settings",
    "orbit_guess",
    "parse_range",
    "parse_set",
    "refuse_conflicts",
    "refuse_restated",
    "require",
    "write_json",
]


class Fail(Exception):
    """A user-facing failure: one line, exit code 2."""


class RunFailed(Exception):
    """A run that ended invalid, divergent or failed numerically: one line, exit code 3."""


class DefaultsFormatter(argparse.HelpFormatter):
    """Help that ends each option's text with "(default: X)" when the option takes a
    value and has a default (not None); a text with ``%(default)s`` of its own is kept."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text, default = action.help or "", action.default
        takes_value = action.option_strings and action.nargs != 0
        if takes_value and default not in (None, argparse.SUPPRESS) and "%(" not in text:
            text += " (default: %(default)s)"
        return text


class OneLineParser(argparse.ArgumentParser):
    """argparse's parser whose refusals are one line (no usage block), exit code 2; its
    help shows every option's default (:class:`DefaultsFormatter`)."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", DefaultsFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str):
        import difflib
        import re

        option = re.search(r"argument (--[\w-]+)", message)
        if "expected one argument" in message and option:
            message += f" (write {option[1]}=VALUE when the value starts with '-')"
        if message.startswith("unrecognized arguments: "):
            known = sorted(self._options())
            for word in message.split(": ", 1)[1].split():
                near = difflib.get_close_matches(word.split("=")[0], known, n=1)
                if near and near[0] != word.split("=")[0]:  # an option of another command
                    message += f" (did you mean {near[0]}?)"
                    break
        self.exit(2, f"{self.prog}: error: {message}; see `{self.prog} --help`\n")

    def _options(self) -> set[str]:
        """Every option string of this parser and its commands' parsers."""
        out = set()
        for action in self._actions:
            out.update(s for s in action.option_strings if s.startswith("--"))
            choices = getattr(action, "choices", None)
            for sub in choices.values() if isinstance(choices, dict) else ():
                if isinstance(sub, argparse.ArgumentParser):
                    out |= OneLineParser._options(sub)
        return out


def out_folder(path, option: str = "--out") -> Path:
    """The output folder ``path``, created and shown writable before anything is
    computed; otherwise a :class:`Fail` naming it and the fix."""
    out = Path(path)
    fix = f"choose another folder with {option}"
    if out.exists() and not out.is_dir():
        kind = "a file" if out.is_file() else "not a folder"
        raise Fail(f"{option} {out}: is {kind}; {fix}")
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / f".gearsym-write-test-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as err:
        raise Fail(f"{option} {out}: cannot write there ({err.strerror}); {fix}") from None
    return out


def figure_file(path, option: str) -> Path:
    """A figure's file name: a format matplotlib writes and a writable folder."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    out = Path(path)
    formats = FigureCanvasAgg.get_supported_filetypes()
    suffix = out.suffix.lstrip(".").lower()
    if out.is_dir() or not suffix:
        raise Fail(f"{option} {out}: give a file name with a format, for example k.png")
    if suffix not in formats:
        raise Fail(
            f"{option} {out}: '.{suffix}' is not a figure format; use one of "
            + ", ".join(sorted(formats))
        )
    out_folder(out.parent if str(out.parent) else ".", option)
    return out


def parse_set(items: list[str]) -> dict[str, float | str]:
    """``--set key=value`` items: numbers, except the open values that take text
    (``load_reading``, ``damping_normalisation``: ``gearsym.derive.input.open_values.CHOICES``)."""
    from gearsym.derive.input.open_values import CHOICES

    out = {}
    for item in items or []:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise Fail(f"--set {item}: expected key=value, for example --set lambda=0.5")
        if key.strip() in out:
            raise Fail(f"--set {item}: {key.strip()} is set twice; give it once")
        if key.strip() in CHOICES:
            if not value.strip():
                raise Fail(f"--set {item}: give a value ({CHOICES[key.strip()]})")
            out[key.strip()] = value.strip()
            continue
        try:
            number = float(value)
        except ValueError:
            raise Fail(f"--set {item}: '{value}' is not a number") from None
        if not math.isfinite(number):
            raise Fail(f"--set {item}: value must be finite")
        out[key.strip()] = number
    return out


def parse_range(text: str, given: str | None = None, negative: str | None = None):
    """``START:STOP:NUM`` as ``numpy.linspace(START, STOP, NUM)``.

    A refusal starts with ``given`` (what the user typed, default ``--range TEXT``); a
    map's axis passes ``negative``, the way to write a negative START, which then ends
    every refusal (``--range`` says it only where the form itself is wrong)."""
    given = f"--range {text}" if given is None else given
    tail = f" {negative}" if negative else ""
    parts = text.split(":")
    try:
        if len(parts) != 3:
            raise ValueError
        start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        how = negative or "(write --range=-0.5:1:11 when START is negative)"
        raise Fail(f"{given}: expected START:STOP:NUM, for example 0:1:51 {how}") from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise Fail(f"{given}: START and STOP must be finite numbers{tail}")
    if num < 1 or (num == 1 and start != stop):
        raise Fail(f"{given}: NUM must be >= 2, or 1 with START equal to STOP{tail}")
    if num > 1 and start == stop:
        raise Fail(
            f"{given}: START equals STOP, so all {num} values are the same; "
            f"give different ends, or {start:g}:{stop:g}:1{tail}"
        )
    return np.linspace(start, stop, num)


def at_most(*sizes: tuple[str, float, float], unit: str = "") -> None:
    """Refuse the first ``(option, value, most)`` whose value is above its limit, in one
    line that names the option and the limit (bounded work: each limit is in --help)."""
    for option, value, most in sizes:
        if value > most:
            raise Fail(f"{option} {value}: at most {most:,}{unit}")


def require(nbytes: float, what: str, fix: str) -> None:
    """:func:`gearsym.solver._memory.require` as a one-line failure."""
    from gearsym.solver._memory import MemoryRefused
    from gearsym.solver._memory import require as _require

    try:
        _require(nbytes, what, fix)
    except MemoryRefused as err:
        raise Fail(str(err)) from None


def refuse_conflicts(args, varied: list[str], option: str) -> None:
    """Options that contradict each other, refused instead of one silently winning:
    ``--set`` of a parameter the command varies, and ``--scheduler`` without dask."""
    for item in getattr(args, "set", None) or []:
        key = item.partition("=")[0].strip()
        if key in varied:
            raise Fail(f"--set {item} contradicts {option}, which varies {key}; drop one")
    if getattr(args, "scheduler", None) and getattr(args, "executor", "dask") != "dask":
        raise Fail(
            f"--scheduler {args.scheduler} needs --executor dask (not "
            f"'{args.executor}'); drop --scheduler or add --executor dask"
        )


def refuse_restated(args, module, varied: list[str], option: str) -> None:
    """``--set`` of a quantity that a varied parameter states under another name: omega
    beside a sweep over ``speed_rpm`` (the sweep's value won, and the record kept the --set
    beside it), an alias of a mesh's own name, a non-dimensional load beside a torque."""
    from gearsym.solver.system import restates

    for item in getattr(args, "set", None) or []:
        key = item.partition("=")[0].strip()
        for v in varied:
            if key != v and restates(module, key, v):
                said = f"--set {item} and {option} state one quantity ({key} and {v})"
                raise Fail(f"{said}; drop the --set")


# Bounded work: the most periods a run may ask for (stated in each option's help).  The
# compiled integrator takes 10 us to 1 ms a period depending on the model, the exponent's
# variational run about 1 ms: a million periods is seconds to a quarter of an hour.
LIMITS = {
    "transient": 1_000_000,
    "periods": 1_000_000,
    "lyapunov_periods": 100_000,
    "budget": 1_000_000,
}
# periods integrated in all by a sweep or a map (points x runs x periods): 1e9 is about
# three hours of one core on the smallest model, minutes on a cluster
MAX_TOTAL_PERIODS = 1e9


def analysis_settings(args) -> dict:
    for name in ("rtol", "atol"):
        value = getattr(args, name)
        if not (value > 0 and math.isfinite(value)):
            raise Fail(f"--{name} must be a positive number, got {value}")
    for name, low in (("transient", 0), ("periods", 1), ("lyapunov_periods", 0), ("budget", 0)):
        if getattr(args, name) < low:
            option = "--" + name.replace("_", "-")
            raise Fail(f"{option} must be a whole number >= {low}, got {getattr(args, name)}")
    if args.rtol > 0.1:
        why = "a relative tolerance above 0.1 controls nothing; give 1e-3 or less"
        raise Fail(f"--rtol {args.rtol:g}: {why}")
    from gearsym.solver.integrate.methods import get_method

    adaptive = args.method is None or get_method(args.method).adaptive
    if (loose := args.transient_rtol) is not None and not (1e-13 <= loose <= 0.1 and adaptive):
        why = "a relative tolerance from 1e-13 to 0.1 (1e-6, say) with an adaptive --method"
        raise Fail(f"--transient-rtol {loose:g}: give {why}, or leave it out")  # NaN too
    from gearsym.solver.integrate.simulate import check_samples, samples_for

    spp = samples_for(args.periods)
    try:
        check_samples(args.periods, spp, 8)
    except ValueError as err:
        raise Fail(f"--periods {args.periods}: {err}") from None
    for name, most in LIMITS.items():
        if getattr(args, name) > most:
            option = "--" + name.replace("_", "-")
            raise Fail(
                f"{option} {getattr(args, name)}: at most {most:,} periods (a longer "
                "run takes hours)"
            )
    if spp < 64 and not getattr(args, "quiet", False):
        print(
            f"gearsym: note: {args.periods} periods are sampled {spp} times each (not 64) "
            f"to bound memory; spectra reach {spp // 2} times the excitation frequency",
            file=sys.stderr,
        )
    return dict(
        method=args.method,
        rtol=args.rtol,
        atol=args.atol,
        transient=args.transient,
        periods=args.periods,
        samples_per_period=spp,
        lyapunov_periods=args.lyapunov_periods,
        on_invalid=args.on_invalid,
        budget=args.budget,
        **({} if loose is None else {"transient_rtol": loose}),
    )


def method_name(text: str) -> str:
    """``--method``'s value; an old integrator name is refused naming the new one."""
    from gearsym.solver.integrate.methods import RENAMED

    if text in RENAMED:
        raise argparse.ArgumentTypeError(RENAMED[text])
    return text


def analysis_options(sub) -> None:
    from gearsym.solver.integrate import METHODS

    sub.add_argument(
        "--set",
        action="append",
        metavar="KEY=VALUE",
        help="set a scene or model parameter (repeatable)",
    )
    sub.add_argument(
        "--method",
        type=method_name,
        choices=METHODS,
        default=None,
        help="integrator (default: the fastest that meets --rtol: dop853, or cvodes without a "
        "C compiler; RK45 is the study's)",
    )
    sub.add_argument("--rtol", type=float, default=1e-8, help="relative tolerance (<= 0.1)")
    sub.add_argument("--atol", type=float, default=1e-10, help="absolute tolerance")
    sub.add_argument(
        "--transient",
        type=int,
        default=300,
        help=f"periods discarded (at most {LIMITS['transient']:,})",
    )
    sub.add_argument(
        "--transient-rtol",
        type=float,
        metavar="RTOL",
        help="a looser rtol for the discarded periods alone, atol scaled with it: faster",
    )
    sub.add_argument(
        "--periods",
        type=int,
        default=100,
        help=f"periods sampled (at most {LIMITS['periods']:,}, and what memory holds)",
    )
    sub.add_argument(
        "--on-invalid",
        choices=("warn", "error"),
        default="warn",
        help="when a coordinate leaves the backlash model's valid range: warn "
        "and go on, or stop the run there (status 'invalid')",
    )
    sub.add_argument(
        "--lyapunov-periods",
        type=int,
        default=400,
        help="a run not periodic is continued from its end in windows of this many periods "
        "(each next one twice as long), each with the largest Lyapunov exponent (0: no "
        f"exponent, so only periodic verdicts settle; at most {LIMITS['lyapunov_periods']:,})",
    )
    budget_option(sub)


def budget_option(sub) -> None:
    from gearsym.solver.analysis import BUDGET

    sub.add_argument(
        "--budget",
        type=int,
        default=BUDGET,
        help=f"periods a verdict may take in all, from the run's start (0: no "
        "continued windows; borders of sweeps and maps get 8,000; at most "
        f"{LIMITS['budget']:,})",
    )


def write_json(folder: str, name: str, data) -> Path:
    """Write ``data`` as ``folder/name`` (no NaN: see solver._json); return the folder."""
    from gearsym.solver._json import dumps

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    (out / name).write_text(dumps(data, indent=1), encoding="utf-8")
    return out


def orbit_guess(system, n: int, settle: int):
    """A starting state on the attractor at tau = 0 (mod nT), from a simulation."""
    from gearsym.solver.integrate import SimulationError, simulate

    if n < 1 or settle < 0:
        raise Fail(f"--period must be >= 1 and --settle >= 0 (got {n} and {settle})")
    try:
        run = simulate(
            system, method="cvodes", transient=settle * n, periods=n, samples_per_period=1
        )
    except SimulationError as err:
        raise RunFailed(f"the simulation that gives the initial guess failed: {err}") from None
    except ValueError as err:
        raise Fail(f"the simulation that gives the initial guess: {err}") from None
    if run.status != "ok":
        raise RunFailed(
            f"the simulation that gives the initial guess ended {run.status}: {run.message}"
        )
    return run.poincare[:, 0]
