"""Where a run may start and how much of it a command keeps: the force law's valid range
at the start, the default start the loads give, the samples a run keeps and the memory
they need (issue 14)."""

from __future__ import annotations

import numpy as np

from .._memory import require
from ..system import System

__all__ = ["SAMPLE_BUDGET", "check_samples", "check_start", "default_initial_state", "samples_for"]


def check_samples(periods: int, samples_per_period: int, n: int) -> None:
    """Refuse a run whose samples would not fit in memory, before allocating them: the
    samples, the run's own output and the analysis' copies, about four times the
    samples of ``n`` states and the times."""
    require(
        32.0 * (periods * samples_per_period + 1) * (n + 1),
        f"{periods} sampled periods at {samples_per_period} samples each",
        "sample fewer periods",
    )


def check_start(system: System, x0=None) -> None:
    """Refuse a start outside the force law's valid range (``x0``, or the default start
    the loads give): a run from there would be reported as diverging, not as a state the
    model does not describe."""
    given = x0 is not None
    x0 = default_initial_state(system) if x0 is None else np.asarray(x0, dtype=float)
    for i, bound in system.contract.valid_bounds():
        if abs(x0[i]) <= bound:
            continue
        state = system.states[i]
        where = f"|{state}| <= {bound:g}"
        if given:
            raise ValueError(
                f"the initial state {state} = {x0[i]:.6g} is outside the backlash model's "
                f"valid range {where}; start inside it"
            )
        load = system.contract.loads.get(state)
        f = system.parameter(load) if load else float("nan")
        raise ValueError(
            f"the static load {load} = {f:.6g} presses {state} to {x0[i]:.6g}, outside the "
            f"backlash model's valid range {where}; lower the load, or use a scene with "
            "backlash = 'dead-zone' (valid everywhere)"
        )


SAMPLE_BUDGET = 1 << 20  # samples per state a command keeps of one run (8 MiB each)


def samples_for(periods: int, wanted: int = 64) -> int:
    """Samples per period for a run of ``periods`` sampled periods: ``wanted`` while the
    run keeps at most :data:`SAMPLE_BUDGET` samples, else the largest power of two that
    fits, down to 8 (a spectrum still reaching 4 omega): 20,000 periods take 32, 100,000
    take 8."""
    spp = wanted
    while spp > 8 and periods * spp > SAMPLE_BUDGET:
        spp //= 2
    return spp


def default_initial_state(system: System) -> np.ndarray:
    """Each coordinate pressed into contact by its static load (past the contact edge on
    the load's side by the load, ``u = 1 + f`` for a forward load), at rest: close to the
    loaded equilibrium for a force law near the dead zone.  A module that states its own
    loaded equilibrium (``static_state(p)``: a planetary set's, whose meshes are not
    coordinates) starts there."""
    static = getattr(system.module, "static_state", None)
    if static is not None:  # a model that states its loaded equilibrium (a planetary set's)
        x0 = static(system.p)
        if x0 is not None:
            return np.asarray(x0, dtype=float)
    c = system.contract
    x0 = np.zeros(system.n)
    for coord, load in c.loads.items():
        f = system.parameter(load)
        if f == 0:
            continue
        lower, upper = c.contact.get(coord, (0.0, 0.0))
        x0[c.index(coord)] = (upper if f > 0 else lower) + f
    return x0
