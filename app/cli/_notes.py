"""Notes a command prints once, after its output: ``gearsym: note: ...`` on stderr.

A note is neither a warning (nothing went wrong) nor a failure.  A command gathers its
notes while it loads its models and says them when it has run to its end
(``gearsym.cli._run``): a refused or failed command keeps its one line, and ``--quiet``
(no progress bar) keeps the notes.
"""

from __future__ import annotations

import math
import sys

__all__ = ["forget", "note_backlash", "note_frame", "note_run", "note_torques", "say"]

_PENDING: dict[str, str] = {}  # model name -> note of the command under way


def forget() -> None:
    """A new command (``gearsym.cli.main``): no notes yet."""
    _PENDING.clear()


def note_backlash(system):
    """Note ``system.backlash_note`` (a polynomial backlash: where its force is zero)
    once per model and command; return ``system``."""
    note = system.backlash_note
    if note:
        _PENDING.setdefault(system.name, note)
    return system


def note_torques(system, swept: dict | None = None):
    """Note ``system.torque_note`` (external torques out of balance) once per model and
    command, at each value of ``swept`` (``{name: values}``, for a run over a torque: at
    its ends); return ``system``."""
    ends = [{k: float(v[i]) for k, v in (swept or {}).items()} for i in (0, -1)]
    torques = any(k.startswith("torque_Nm_") for k in swept or {})
    notes = [(e, system.with_values(**e).torque_note) for e in ends] if torques else []
    at, note = next(((e, n) for e, n in notes if n), (None, system.torque_note))
    if at and note:  # say at which end of the run (the other may be balanced)
        where = ", ".join(f"{k} = {v:g}" for k, v in at.items())
        note = f"at {where}, {note}"
    if note:
        _PENDING.setdefault(f"{system.name} torques", note)
    return system


def note_frame(system, swept: dict | None = None, *, run: bool = False):
    """For a model whose carrier turns (its module's ``FRAME``): note once that the
    frame's terms stay at the file's speed at the run's mesh frequencies (``system``'s,
    or those at the ends of ``swept``) where that speed does not give them; ``run``: the
    command's run over ``swept``, whose note replaces one said of its starting point.
    Return ``system``."""
    frame = getattr(system.module, "FRAME", None)
    if not frame:
        return system
    key = f"{system.name} frame"
    if run:
        _PENDING.pop(key, None)
    ends = [{k: float(v[i]) for k, v in swept.items()} for i in (0, -1)] if swept else [{}]
    scale = system.module.OMEGA_N / (2 * math.pi)
    try:
        hz = sorted({system.with_values(**e).omega * scale for e in ends})
    except (KeyError, ValueError):  # a value the command itself refuses, in its words
        return system
    rpm = abs(frame["carrier_speed_rpm"])
    at = f"{hz[0]:.6g} Hz" if len(hz) == 1 else f"{hz[0]:.6g} to {hz[-1]:.6g} Hz"
    own = frame["mesh_frequency_of_speed_hz"]
    if own is None:  # which mesh frequency the speed gives is not known (the ring not held)
        parameters, w = system.module.PARAMETERS, system.contract.forcing_frequency
        point = system.module.DEFAULTS[parameters.index(w)] * scale
        if all(abs(h - point) <= 1e-3 * point for h in hz):
            return system
        note = (
            f"{system.name}: the carrier turns at {rpm:g} rpm, the file's speed, at every mesh "
            f"frequency: at {at} the rotating frame's terms are those of the file's operating "
            f"point ({point:.6g} Hz), not of a speed that follows the mesh frequency"
        )
    elif all(abs(h - own) <= 1e-3 * own for h in hz):
        return system
    else:
        but = f", except at {own:.6g} Hz itself," if hz[0] < own < hz[-1] else ""
        note = (
            f"{system.name}: the carrier turns at {rpm:g} rpm, the file's speed, at every mesh "
            f"frequency (with the ring held, that speed turns the meshes at {own:.6g} Hz), so "
            f"at {at}{but} the mesh excitation and the rotating frame's terms belong to two "
            "different speeds; another speed is another file"
        )
    _PENDING.setdefault(key, note)
    return system


def note_run(system, swept: dict):
    """The notes of a run over ``swept`` (``{name: values}``, the ends count): the torques'
    balance and a turning carrier's frame (:func:`note_torques`, :func:`note_frame`)."""
    return note_frame(note_torques(system, swept), swept, run=True)


def say() -> None:
    """Print the command's notes, each once, one line each; nothing when stderr is
    closed."""
    from gearsym.derive.escape import one_line

    notes = dict.fromkeys(_PENDING.values())  # two models with one note: said once
    _PENDING.clear()
    try:
        for note in notes:
            print(one_line(f"gearsym: note: {note}"), file=sys.stderr, flush=True)
    except (OSError, ValueError):
        pass
