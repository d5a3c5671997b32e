"""A looser tolerance for the transient (``simulate(..., transient_rtol=...)``).

The transient only carries the state to the attractor.  With ``transient_rtol`` the back
end runs twice on one checked request: the transient at ``transient_rtol`` (``atol``
scaled with it), sampled only at the start and the end of its last period, and then the
window from where it ended, at ``rtol``, on the request's own sample grid.  The two make
one :class:`~.result.Run`: the work of both, the first exit from the valid range, and a
transient that fails (or leaves the valid range with ``on_invalid="error"``) fails the run,
its window NaN.  ``simulate`` checks the user's start only, never the transient's end.
What the trade buys and costs: ``benchmarks/body_models.py`` (``docs/body-models.md``).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .result import Request, Run

__all__ = ["check_transient_rtol", "said", "two_runs", "two_runs_many"]

_EPS = 100 * np.finfo(float).eps  # what SciPy-style step control honours (simulate._check)


def check_transient_rtol(value, record) -> None:
    """``ValueError`` naming ``transient_rtol`` when it cannot be used with ``record``
    (the method's registry record)."""
    numeric = isinstance(value, int | float | np.floating) and not isinstance(value, bool)
    loose = float(value) if numeric else math.nan
    if not record.adaptive:
        raise ValueError(
            f"transient_rtol is for the adaptive methods; '{record.name}' takes "
            "steps_per_period fixed steps a period"
        )
    low = 0.0 if record.family == "casadi" else _EPS
    if not low < loose <= 0.1:  # NaN too
        raise ValueError(
            f"transient_rtol must be a number in ({low:.2g}, 0.1], got {value!r} "
            "(a transient needs no more than 1e-6, say)"
        )


def said(req: Request) -> dict:
    """The transient's own tolerances, as a trajectory's options record them (none when
    the request has no looser transient)."""
    if req.transient_rtol is None or req.transient == 0:
        return {}
    loose = float(req.transient_rtol)
    return {"transient_rtol": loose, "transient_atol": req.atol * loose / req.rtol}


def _transient(system, req: Request) -> Request:
    """The transient's own request: its last period sampled at both ends."""
    start = float(req.grid[0])  # t0 + transient T, where the window starts
    T = system.period
    own = said(req)
    return replace(
        req,
        rtol=own["transient_rtol"],
        atol=own["transient_atol"],
        transient=req.transient - 1,
        periods=1,
        samples_per_period=1,
        grid=np.array([start - T, start]),
        transient_rtol=None,
    )


def _window(req: Request, first: Run) -> Request:
    return replace(
        req, x0=first.x[:, -1].copy(), t0=float(req.grid[0]), transient=0, transient_rtol=None
    )


def _stops(req: Request, first: Run) -> bool:
    """The transient ended the run: it failed, or left the valid range where the request
    stops there."""
    return first.status != "ok" or (
        first.left_valid_range is not None and req.on_invalid == "error"
    )


def _joined(req: Request, first: Run, second: Run | None) -> Run:
    if second is None:
        x = np.full((first.x.shape[0], req.grid.size), np.nan)
        return replace(first, x=x)
    crossings = [c for c in (first.crossings, second.crossings) if c is not None]
    return Run(
        second.x,
        second.status,
        second.message,
        first.nfev + second.nfev,
        first.nsteps + second.nsteps,
        sum(crossings) if crossings else None,
        first.left_valid_range or second.left_valid_range,
    )


def two_runs(backend, system, req: Request) -> Run:
    """``backend(system, req)`` with the transient at ``req.transient_rtol``."""
    first = backend(system, _transient(system, req))
    second = None if _stops(req, first) else backend(system, _window(req, first))
    return _joined(req, first, second)


def two_runs_many(run_many, systems, reqs, workers: int) -> list[Run]:
    """``run_many(systems, reqs, workers=...)`` alike: the transients in one batch, then the
    windows of those that did not stop the run in another (a batch shares its start time:
    its points share their period)."""
    transients = [_transient(s, q) for s, q in zip(systems, reqs, strict=True)]
    firsts = run_many(systems, transients, workers=workers)
    go = [i for i, (q, f) in enumerate(zip(reqs, firsts, strict=True)) if not _stops(q, f)]
    windows = [_window(reqs[i], firsts[i]) for i in go]
    done = run_many([systems[i] for i in go], windows, workers=workers) if go else []
    seconds = dict(zip(go, done, strict=True))
    pairs = enumerate(zip(reqs, firsts, strict=True))
    return [_joined(q, f, seconds.get(i)) for i, (q, f) in pairs]
