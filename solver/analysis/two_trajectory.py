"""The largest Lyapunov exponent from two nearby trajectories: a second test of chaos that
uses neither the Jacobian nor the tangent vector.

Two states ``x`` and ``y = x + d0 e`` (``|e| = 1``, a fixed random direction) are
integrated side by side for ``m`` forcing periods; their separation ``d = |y - x|`` grows
as ``d0 exp(lambda m T)`` while it stays small, so each chunk gives the rate
``r_i = log(d_i / d0) / (m T)``; ``y`` is then put back at distance ``d0`` along the
separation (Benettin, Galgani and Strelcyn 1976, "Kolmogorov entropy and numerical
experiments", Phys. Rev. A 14; Wolf, Swift, Swinney and Vastano 1985, "Determining
Lyapunov exponents from a time series", Physica D 16).  On a piecewise model (the dead
zone) the two trajectories cross the kinks at their own times, so nothing is linearised
across them.

``m`` keeps the separation in the linear range: ``exp(lambda_hi m T) <= 1e3`` with
``d0 = 1e-8`` (``lambda_hi`` the caller's upper bound of the exponent), at most 50
periods.  The first chunk (the alignment of ``e``) is discarded; the exponent is the mean
rate of the rest and its interval the batch-means one of ``lyapunov.uncertainty``
(eight blocks, Student's t), so the two estimates are read alike.
"""

from __future__ import annotations

import numpy as np

from ..integrate.run import Batch, integrate
from ..integrate.spec import RunSpec
from ..system import System

__all__ = ["two_trajectory"]

_D0 = 1e-8
_T975 = (12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365)


def two_trajectory(
    system: System,
    x0,
    periods: int,
    *,
    t0: float = 0.0,
    upper: float = 0.1,
    rtol: float = 1e-11,
    atol: float = 1e-13,
    seed: int = 0,
) -> dict:
    """The exponent per unit tau over ``periods`` forcing periods from ``x0`` at ``t0``,
    with ``interval`` (about 95 %), ``chunk`` (periods between renormalisations) and
    ``chunks``; ``upper`` bounds the exponent from above (sets the chunk length)."""
    T = system.period
    chunk = int(np.clip(np.floor(np.log(1e3) / max(upper * T, 1e-12)), 1, 50))
    n_chunks = max(periods // chunk, 2)
    rng = np.random.default_rng(seed)
    e = rng.standard_normal(system.n)
    x = np.asarray(x0, dtype=float)
    y = x + _D0 * e / np.linalg.norm(e)
    batch = Batch.of(system.module, np.repeat(system.p[None, :], 2, axis=0))
    spec = RunSpec(
        method="dop853",
        rtol=rtol,
        atol=atol,
        transient=0,
        periods=chunk,
        valid_range="ignore",
        bound=1e6,
        # the plain library: with the tangent in the step control the pair stopped ("step
        # too small") at this tolerance on the dead zone's kinks; it is needed only for
        # weak chaos, so its compilation is rare
    )
    rates, t = [], t0
    for _ in range(n_chunks):
        res = integrate(batch, np.vstack([x, y]), spec.with_(t0=t))
        if any(s != "ok" for s in res.status):
            raise FloatingPointError(f"the pair of runs stopped: {res.status}")
        x, y = res.x[0, -1], res.x[1, -1]
        d = float(np.linalg.norm(y - x))
        if not (d > 0 and np.isfinite(d)):
            raise FloatingPointError("the two trajectories coincided or left the numbers")
        rates.append(np.log(d / _D0) / (chunk * T))
        y = x + _D0 * (y - x) / d
        t += chunk * T
    r = np.array(rates[1:])
    B = min(8, r.size)
    means = np.array([b.mean() for b in np.array_split(r, B)])
    half = _T975[B - 2] * float(means.std(ddof=1)) / np.sqrt(B) if B >= 2 else float("inf")
    lam = float(r.mean())
    return {
        "exponent": lam,
        "interval": [float(lam - half), float(lam + half)],
        "chunk": chunk,
        "chunks": int(r.size),
        "method": "two nearby trajectories, renormalised every chunk (no Jacobian)",
    }
