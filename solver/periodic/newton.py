"""One Newton solver for every periodic-orbit problem (shooting and the continuation
corrector): ``F(z) = 0`` with the Jacobian from the caller, optionally damped by
backtracking on the residual's max-norm."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

__all__ = ["NewtonError", "NewtonResult", "newton"]

# what an evaluation at a trial point may raise when the point is out of reach: a failed
# integration (RuntimeError), a singular system, a refused value, an overflow
_TRIAL_FAILURES = (RuntimeError, ValueError, ArithmeticError, np.linalg.LinAlgError)


class NewtonError(RuntimeError):
    """Newton's method did not converge; ``history`` holds the residual norms reached."""

    def __init__(self, message: str, history: list):
        super().__init__(message)
        self.history = history


@dataclass(frozen=True)
class NewtonResult:
    """The solution, its residual norm, the steps taken, the residual history, and what
    the last evaluation returned besides residual and Jacobian (``extra``)."""

    z: np.ndarray
    residual: float
    steps: int
    history: list = field(default_factory=list)
    extra: object = None


def newton(
    fun: Callable,
    z0,
    *,
    tol: float,
    max_iter: int,
    damped: bool = True,
    min_steps: int = 0,
    singular: str = "singular Jacobian",
) -> NewtonResult:
    """Solve ``F(z) = 0`` from ``z0``.

    Parameters
    ----------
    fun : callable
        ``fun(z) -> (F, dF/dz, extra)``.
    tol : float
        Converged when ``max |F| <= tol`` (and at least ``min_steps`` steps were taken).
    max_iter : int
        Steps allowed.
    damped : bool
        Halve the step until the residual's max-norm decreases (down to 1/10^4); a
        trial whose evaluation fails (a flow that stops) counts as no decrease.
    singular : str
        What a singular Jacobian means, for the error message.

    Raises
    ------
    NewtonError
        No convergence, a non-finite residual, a singular Jacobian, (damped) no
        decrease along the Newton direction, or (undamped) a failed evaluation at a step.
    """
    z = np.asarray(z0, dtype=float).copy()
    F, J, extra = fun(z)
    norm = float(np.max(np.abs(F)))
    history = [norm]
    steps = 0
    while not (norm <= tol and steps >= min_steps):
        if steps >= max_iter or not np.isfinite(norm):
            raise NewtonError(
                f"Newton did not converge in {steps} iterations (residual {norm:.3g})", history
            )
        try:
            step = np.linalg.solve(J, -F)
        except np.linalg.LinAlgError:
            raise NewtonError(singular, history) from None
        lam, failed = 1.0, None
        while True:
            trial = z + lam * step
            try:
                Ft, Jt, et = fun(trial)
            except NewtonError:
                raise
            except _TRIAL_FAILURES as err:
                if type(err).__name__ == "NativeUnavailable":
                    raise  # no compiler, or a library that did not build: not the trial's
                # a trial the flow cannot reach (an integration that stops, a state the
                # model refuses) is no decrease: a shorter step is tried, as for a larger
                # residual, instead of ending the whole solve there
                first = str(err).splitlines()[0] if str(err) else type(err).__name__
                if not damped:
                    raise NewtonError(
                        f"the Newton step's evaluation failed: {first}", history
                    ) from err
                failed, nt = first, float("inf")
            else:
                failed, nt = None, float(np.max(np.abs(Ft)))
            if not damped or nt < norm:
                break
            lam /= 2
            if lam < 1e-4:
                why = f" (the shortest step's evaluation failed: {failed})" if failed else ""
                raise NewtonError(
                    f"Newton's line search found no decrease of the residual "
                    f"({norm:.3g}) after {steps} iterations{why}",
                    history,
                )
        z, F, J, extra, norm = trial, Ft, Jt, et, nt
        steps += 1
        history.append(norm)
    return NewtonResult(z, norm, steps, history, extra)
