"""CasADi's own reports kept off the terminal.

When a CVODES integration fails (an infinite right-hand side, too many steps), CasADi
writes a warning and a dump of the failing function's inputs to Python's ``sys.stderr``
before it raises; the exception already says what failed, and the caller reports it
once, in its own words (a Newton that fails, a continuation step that is shortened).
Options (``show_eval_warnings``, ``disable_internal_warnings``) quiet the integrator
itself but not the dump of its forward-sensitivity derivative, so the calls that
integrate run inside :func:`quiet`.
"""

from __future__ import annotations

import contextlib
import io
import sys

__all__ = ["quiet", "reworded"]


@contextlib.contextmanager
def quiet():
    """Collect what is written to ``sys.stderr`` inside the block and drop it (CasADi
    writes there through Python; nothing of gearsym's own prints inside these calls)."""
    if isinstance(sys.stderr, io.StringIO) and getattr(sys.stderr, "_gearsym_quiet", False):
        yield  # already quiet: nested calls
        return
    sink = io.StringIO()
    sink._gearsym_quiet = True
    with contextlib.redirect_stderr(sink):
        yield


def reworded(err: Exception) -> str:
    """CasADi's error about a failed integration as one short line."""
    import re

    text = str(err)
    code = re.search(r'CVode returned "(\w+)"', text)
    known = {
        "CV_FIRST_RHSFUNC_ERR": "the right-hand side is not finite at the start (a state "
        "or a parameter too large)",
        "CV_RHSFUNC_FAIL": "the right-hand side became not finite (the orbit diverges)",
        "CV_TOO_MUCH_WORK": "the integrator took too many steps (the orbit diverges or the "
        "period is very long)",
    }
    if code:
        return f"the integration failed: {known.get(code[1], code[1])}"
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    return f"the integration failed: {lines[-1] if lines else type(err).__name__}"
