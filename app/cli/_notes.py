"""Notes a command prints once, after its output: ``gearsym: note: ...`` on stderr.

A note is neither a warning (nothing went wrong) nor a failure.  A command gathers its
notes while it loads its models and says them when it has run to its end
(``gearsym.cli._run``): a refused or failed command keeps its one line, and ``--quiet``
(no progress bar) keeps the notes.
"""

from __future__ import annotations

import sys

__all__ = ["forget", "note_backlash", "say"]

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
