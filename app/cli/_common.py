"""What every command of the CLI shares: the one-line failure, argument parsers, the
analysis options, the scene resolver's error wrapping and JSON output."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

__all__ = [
    "Fail",
    "analysis_options",
    "analysis_settings",
    "orbit_guess",
    "parse_range",
    "parse_set",
    "system_of",
    "write_json",
]


class Fail(Exception):
    """A user-facing failure: one line, exit code 2."""


def parse_set(items: list[str]) -> dict[str, float | str]:
    """``--set key=value`` items: numbers, except the open values that take text
    (``load_reading``, ``damping_normalisation``: ``gearsym.derive.open_values.CHOICES``)."""
    from gearsym.derive.open_values import CHOICES

    out = {}
    for item in items or []:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise Fail(f"--set {item}: expected key=value, for example --set lambda=0.5")
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


def parse_range(text: str):

    parts = text.split(":")
    try:
        if len(parts) != 3:
            raise ValueError
        start, stop, num = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise Fail(
            f"--range {text}: expected START:STOP:NUM, for example 0:1:51 "
            "(write --range=-0.5:1:11 when START is negative)"
        ) from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise Fail(f"--range {text}: START and STOP must be finite numbers")
    if num < 1 or (num == 1 and start != stop):
        raise Fail(f"--range {text}: NUM must be >= 2, or 1 with START equal to STOP")
    return np.linspace(start, stop, num)


def system_of(scene_arg: str, sets: dict[str, float]):
    """The System of a scene (built-in name or path) with ``--set`` values (resolver:
    ``gearsym.resolve``); a bad scene file raises its own InputError."""
    from gearsym.resolve import module_for, split_open_values
    from gearsym.solver.system import System

    opened, rest = split_open_values(sets)
    module = module_for(scene_arg, opened)
    try:
        return System.load(module, **rest)
    except KeyError as err:
        from gearsym.derive._input import nearest
        from gearsym.derive.open_values import OPEN_VALUE_BASES

        unknown = [k for k in rest if k not in module.PARAMETERS]
        hint = nearest(unknown[0], OPEN_VALUE_BASES) if unknown else ""
        more = f"{hint}; open values (derived anew): {', '.join(sorted(OPEN_VALUE_BASES))}"
        raise Fail(f"--set: {err.args[0]}{more}") from None
    except ValueError as err:
        raise Fail(f"--set: {err}") from None


def analysis_settings(args) -> dict:
    for name in ("rtol", "atol"):
        value = getattr(args, name)
        if not (value > 0 and math.isfinite(value)):
            raise Fail(f"--{name} must be a positive number, got {value}")
    for name in ("transient", "periods"):
        if getattr(args, name) < (0 if name == "transient" else 1):
            raise Fail(f"--{name} must be a whole number >= {0 if name == 'transient' else 1}")
    return dict(
        method=args.method,
        rtol=args.rtol,
        atol=args.atol,
        transient=args.transient,
        periods=args.periods,
        lyapunov_periods=args.lyapunov_periods,
        on_invalid=args.on_invalid,
    )


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
        choices=METHODS,
        default=None,
        help="integrator (default: the fastest that meets --rtol: dop853, or cvodes without a "
        "C compiler; RK45 is the study's)",
    )
    sub.add_argument("--rtol", type=float, default=1e-8)
    sub.add_argument("--atol", type=float, default=1e-10)
    sub.add_argument("--transient", type=int, default=300, help="periods discarded")
    sub.add_argument("--periods", type=int, default=100, help="periods sampled")
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
        default=200,
        help="periods for the largest Lyapunov exponent (0: skip)",
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
    except (SimulationError, ValueError) as err:
        raise Fail(f"the simulation that gives the initial guess failed: {err}") from None
    if run.status != "ok":
        raise Fail(f"the simulation that gives the initial guess ended {run.status}: {run.message}")
    return run.poincare[:, 0]
