"""What a frequency response's parameter sets, for its methods and its messages:
``others_moved`` (what else than the forcing frequency a parameter changes: the stepped
integration follows the frequency alone), ``names_moved`` (that list for a message) and
``no_second_curve`` (the note of a response whose second harmonic-balance curve could not
start)."""

from __future__ import annotations

import numpy as np

__all__ = ["names_moved", "no_second_curve", "others_moved"]


def no_second_curve(system, parameter, start, stop, n, err) -> str:
    """The note of a response whose second harmonic-balance curve could not start at
    ``stop``: why (the simulation there ended badly, or settled on no period-n orbit
    harmonic balance could reach), and which method covers the rest of the range."""
    why = str(err)
    if why.startswith("no start"):
        why = why.split(";")[0].replace("no start for harmonic balance: ", "")
    else:
        why = (
            f"harmonic balance found no period-{n} orbit near the motion a simulation "
            f"settles on there ({why.split('; try')[0]})"
        )
    other = (
        "the stepped integration (method 'integration') follows the settled motion over the range"
        if not others_moved(system, parameter, (start, (start + stop) / 2, stop))
        else "shooting (method 'shooting') continues the first curve's branch"
    )
    return (
        f"no second curve from the other end ({parameter} = {stop:g}), where the first "
        f"left the range: {why}; {other}"
    )


def names_moved(moved: list[str], most: int = 4) -> str:
    """``others_moved``'s list for a message: the first ``most`` names and a count."""
    more = len(moved) - most
    return ", ".join(moved[:most]) + (f" and {more} more" if more > 0 else "")


def others_moved(system, parameter: str, values) -> list[str]:
    """The model parameters other than the forcing frequency that ``parameter`` changes
    over ``values`` (none for the forcing frequency itself, or a speed in rpm that only
    sets it): what the stepped-frequency integration, which runs its lanes in the
    excitation phase, cannot follow.  A parameter that changes nothing at all, not even
    the frequency, says so (the sweep would repeat one point)."""
    ff = system.contract.forcing_frequency
    if parameter == ff:
        return []
    P = np.array([system.parameters_with(**{parameter: float(v)}) for v in values])
    names = system.module.PARAMETERS
    moved = [n for k, n in enumerate(names) if n != ff and np.ptp(P[:, k]) != 0.0]
    if not moved and np.ptp(P[:, names.index(ff)]) == 0.0:
        return ["nothing (not the forcing frequency either)"]
    return moved
