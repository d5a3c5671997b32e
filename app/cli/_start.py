"""Initial-state control shared by ``simulate`` and ``shoot``.

* ``--x0 1.2,0,0.3,0`` -- every state, comma-separated, in the model's state order (the
  order ``gearsym derive`` prints and the generated module's docstring lists), or
  ``--x0 u=1.2,v=0,du=0.3,dv=0`` -- every state by name, in any order;
* ``--from-sweep FILE.json --at VALUE`` -- the end state of a saved sweep's point at
  VALUE of its parameter (the state at tau = (transient + periods) T, phase 0 of the
  forcing, where a continued sweep starts its next point); the scene's parameter is set
  to VALUE too, unless ``--set`` names it.

Every user error (wrong count, unknown name, a value that is not in the sweep, a file
that is not a readable sweep, a sweep of another model) is one line, exit code 2.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from ._common import Fail, parse_set
from ._system import system_of

__all__ = ["Start", "resolve_start", "start_options"]


def start_options(parser) -> None:
    group = parser.add_mutually_exclusive_group()
    group.add_argument(
        "--x0",
        metavar="STATE",
        help="initial state: all states comma-separated in the model's order "
        "(1.2,0,0.3,0) or by name (u=1.2,v=0,du=0.3,dv=0)",
    )
    group.add_argument(
        "--from-sweep",
        metavar="FILE",
        help="start from the end state of a saved sweep's point (sweep.json); needs --at",
    )
    parser.add_argument(
        "--at",
        type=float,
        metavar="VALUE",
        help="with --from-sweep: the sweep's parameter value whose state to start from",
    )


@dataclass(frozen=True)
class Start:
    """The system to run and where to start it (``x0`` None: the default start)."""

    system: object
    x0: np.ndarray | None
    source: str

    def describe(self) -> dict:
        return {
            "source": self.source,
            "x0": None
            if self.x0 is None
            else dict(zip(self.system.states, map(float, self.x0), strict=True)),
        }


def parse_x0(text: str, states) -> np.ndarray:
    """The state vector of ``--x0`` (positional or name=value, see the module docstring)."""
    items = [t.strip() for t in text.split(",")]
    order = ", ".join(states)
    named = ["=" in t for t in items]
    if any(named) and not all(named):
        raise Fail(f"--x0 {text}: give every state by position or every state by name")
    if all(named):
        pairs = dict(t.partition("=")[::2] for t in items)
        pairs = {k.strip(): v for k, v in pairs.items()}
        unknown = sorted(set(pairs) - set(states))
        missing = [s for s in states if s not in pairs]
        if unknown or missing or len(pairs) != len(items):
            why = f"unknown {', '.join(unknown)}" if unknown else f"missing {', '.join(missing)}"
            if len(pairs) != len(items) and not (unknown or missing):
                why = "a state is named twice"
            raise Fail(f"--x0 {text}: {why}; the states are {order}")
        items = [pairs[s] for s in states]
    elif len(items) != len(states):
        raise Fail(f"--x0 {text}: {len(items)} value(s), the model has {len(states)} ({order})")
    try:
        x0 = np.array([float(v) for v in items])
    except ValueError:
        raise Fail(f"--x0 {text}: every value must be a number ({order})") from None
    if not np.all(np.isfinite(x0)):
        raise Fail(f"--x0 {text}: values must be finite")
    return x0


def _sweep_point(path: str, at: float):
    from gearsym.solver.sweep import SweepResult

    try:
        sweep = SweepResult.load(path)
    except FileNotFoundError:
        raise Fail(f"--from-sweep {path}: no such file") from None
    except (OSError, ValueError, KeyError, TypeError) as err:
        why = type(err).__name__ if isinstance(err, KeyError) else err
        raise Fail(f"--from-sweep {path}: not a readable sweep file ({why})") from None
    values = np.asarray(sweep.values, dtype=float)
    hit = np.flatnonzero(np.isclose(values, at, rtol=1e-9, atol=1e-12))
    if hit.size == 0:
        near = values[np.argsort(np.abs(values - at))[:2]]
        raise Fail(
            f"--at {at:g}: not a value of the sweep's {sweep.parameter} "
            f"({values.size} values from {values.min():g} to {values.max():g}; nearest "
            + ", ".join(f"{v:.10g}" for v in sorted(near))
            + ")"
        )
    point = next(p for p in sweep.points if math.isclose(p.value, values[hit[0]]))
    if not point.ok or point.x_final is None:
        raise Fail(
            f"--at {at:g}: the sweep's point at {sweep.parameter} = {point.value:g} ended "
            f"'{point.status}'{': ' + point.error if point.error else ''}; no state to start from"
        )
    return sweep, point


def resolve_start(args) -> Start:
    """The system (scene, ``--set``, and the sweep's value) and the initial state."""
    sets = parse_set(args.set)
    if args.at is not None and not args.from_sweep:
        raise Fail("--at needs --from-sweep FILE")
    if not args.from_sweep:
        system = system_of(args.scene, sets)
        if args.x0 is None:
            return Start(system, None, "default initial state")
        return Start(system, parse_x0(args.x0, system.states), "--x0")
    if args.at is None:
        raise Fail("--from-sweep needs --at VALUE (the sweep's parameter value)")
    if not math.isfinite(args.at):
        raise Fail("--at must be a finite number")
    sweep, point = _sweep_point(args.from_sweep, args.at)
    system = system_of(args.scene, {sweep.parameter: point.value} | sets)
    if sweep.model != system.name:
        raise Fail(
            f"--from-sweep {args.from_sweep}: a sweep of model '{sweep.model}', "
            f"the scene is '{system.name}'"
        )
    x0 = np.asarray(point.x_final, dtype=float)
    if x0.shape != (system.n,):
        raise Fail(
            f"--from-sweep {args.from_sweep}: the stored state has {x0.size} values, "
            f"the model has {system.n}"
        )
    if sweep.model_hash != system.model_hash:
        print(
            f"note: {args.from_sweep} was made with another derivation of {system.name} "
            f"(hash {sweep.model_hash[:12]}, now {system.model_hash[:12]}); its state is "
            "used as given",
            file=sys.stderr,
        )
    source = f"sweep {args.from_sweep} at {sweep.parameter} = {point.value:g}"
    if sweep.parameter in sets:
        source += f" (with --set {sweep.parameter}={sets[sweep.parameter]:g})"
    return Start(system, x0, source)
