"""The reference label of one map run: a 10,000-period run classified by its own code.

Written for ``verdicts.py`` and independent of the verdict engine (``verdict.py``,
``settle.py``, ``orbit_check.py``, ``zero_one.py``, ``torus.py``): only the integrator
(``integrate()``), the Benettin exponent (``largest_lyapunov``) and the user-facing
shooting (``periodic.shooting.shoot``, CasADi flow, its own Newton) are shared.

From the run's start state ``x0`` at ``tau = 0`` the model is integrated for ``RUN``
forcing periods T (compiled DOP853 at rtol 1e-10, a hundred times tighter than the map's),
keeping the Poincare points ``P_k = x(k T)``; the first ``RUN - TAIL`` periods are
discarded (a transient, chaotic or not, shorter than that is over), and the tail is
labelled, in this order:

* **period-n** -- the last ``WINDOW`` points repeat after n periods,
  ``max |P_{k+n} - P_k| <= REPEAT * max(1, extent)`` (max-norm, n <= ``LONGEST``,
  smallest such n), and ``shoot`` from the last point converges to an orbit of minimal
  period n, every Floquet multiplier inside the unit circle, within ``10 REPEAT`` of the
  run; or (n <= 64) the gaps over the last window stay below 1e-2 of the extent and halve
  from its first 100 periods to its last, and the orbit ``shoot`` finds lies within
  ``10 gap / (1 - |mu|)`` of the run (still converging: ``converging`` true).  An orbit
  of a divisor m of n is judged at m, as converging (a multiplier near -1 makes a run
  still converging repeat after 2m sooner than after m);
* **chaotic** -- the exponent over the tail (``largest_lyapunov``, 5,000 periods from
  ``P_{RUN - TAIL}``) has ``lambda - U > 0`` and the 0-1 test below gives ``K >= 0.8``;
* **quasi-periodic** -- ``|lambda| + U <= QP_BAND`` (per unit tau) and the section is a
  closed invariant curve on which the map acts as a rotation (:func:`closed_curve`);
* else **unresolved**, with the reason (excluded from the wrong-label count).
"""

from __future__ import annotations

import numpy as np

__all__ = ["RUN", "TAIL", "closed_curve", "reference_label", "repeat_period", "zero_one_K"]

RUN, TAIL, WINDOW = 10_000, 5_000, 1_000
LONGEST = 400  # longest period multiple looked for by repetition
REPEAT = 1e-5  # repetition tolerance, relative to max(1, the tail's extent)
K_CHAOS = 0.8  # the 0-1 test's chaotic reading
QP_BAND = 1e-3  # |lambda| + U below this (per unit tau) reads as a zero exponent


def zero_one_K(phi, *, n_c: int = 100, seed: int = 0) -> float:
    """The 0-1 test for chaos, correlation method (Gottwald and Melbourne 2009, "On the
    implementation of the 0-1 test for chaos", SIAM J. Appl. Dyn. Syst. 8, 129-145).

    For ``n_c`` frequencies ``c`` drawn in ``(pi/5, 4 pi/5)``: ``z_c(j) = sum_{i<=j}
    phi_i e^{i c i}``, the mean square displacement ``M_c(n) = <|z_c(j+n) - z_c(j)|^2>_j``
    for ``n = 1 .. N/10``, less its oscillating part ``<phi>^2 (1 - cos n c)/(1 - cos c)``,
    correlated with n; ``K`` is the median correlation: near 1 for chaos, near 0 for
    regular motion.  ``phi``: (N,) one observable sampled once per forcing period.
    """
    phi = np.asarray(phi, float)
    N = phi.size
    ncut = N // 10
    c = np.random.default_rng(seed).uniform(np.pi / 5, 4 * np.pi / 5, n_c)
    j = np.arange(1, N + 1)
    z = np.cumsum(phi[None, :] * np.exp(1j * np.outer(c, j)), axis=1)  # (n_c, N)
    a2 = np.abs(z) ** 2
    head = np.concatenate([np.zeros((n_c, 1)), np.cumsum(a2, axis=1)], axis=1)
    # sum_j conj(z_j) z_{j+n} for every n, by one zero-padded FFT per c
    f = np.fft.fft(z, 2 * N, axis=1)
    cross = np.fft.ifft(np.conj(f) * f, axis=1)[:, : ncut + 1]
    n = np.arange(1, ncut + 1)
    terms = N - n
    # sum_{j < N-n} |z_{j+n}|^2 + |z_j|^2 - 2 Re conj(z_j) z_{j+n}
    later = head[:, N][:, None] - head[:, n]
    first = head[:, N - n]
    M = (later + first - 2.0 * cross[:, 1:].real) / terms
    D = M - phi.mean() ** 2 * (1 - np.cos(np.outer(c, n))) / (1 - np.cos(c))[:, None]
    nc = n - n.mean()
    Dc = D - D.mean(axis=1, keepdims=True)
    denom = np.sqrt((nc**2).sum() * (Dc**2).sum(axis=1))
    K = np.where(denom > 0, (Dc @ nc) / np.where(denom > 0, denom, 1.0), 0.0)
    return float(np.median(K))


def repeat_period(points: np.ndarray, tol: float) -> tuple[int | None, float]:
    """The smallest n <= LONGEST with the last WINDOW points ``(K, n_states)`` repeating
    after n periods within ``tol`` (max-norm), and that largest gap (inf: none)."""
    last = points[-(WINDOW + LONGEST) :]
    for n in range(1, LONGEST + 1):
        gap = float(np.max(np.abs(last[-WINDOW:] - last[-WINDOW - n : -n])))
        if gap <= tol:
            return n, gap
    return None, float("inf")


def closed_curve(points: np.ndarray) -> dict:
    """Is the section ``(K, n_states)`` a closed invariant curve with the map a rotation?

    Each projection (the plane of the two largest principal axes, and every pair of
    states) orders the points by their angle round the centroid; on a closed curve that
    the projection sees star-shaped, the map is conjugate to a rotation, so the rank of
    ``P_{k+1}`` minus that of ``P_k`` is one constant ``s`` (mod K) to within 2, and
    ``s / K`` is the rotation number.  A chaotic cloud gives scattered shifts.  Curve:
    at least 98 % of the shifts agree and no angular gap exceeds 0.2 rad.
    """
    Z = np.asarray(points, float)
    sd = Z.std(axis=0)
    Z = (Z[:, sd > 0] - Z[:, sd > 0].mean(axis=0)) / sd[sd > 0]
    K = Z.shape[0]
    planes = []
    if Z.shape[1] >= 2:
        _, _, Vt = np.linalg.svd(Z, full_matrices=False)
        planes.append(("principal axes", Z @ Vt[:2].T))
        d = Z.shape[1]
        planes += [(f"states {i}, {k}", Z[:, [i, k]]) for i in range(d) for k in range(i + 1, d)]
    best = {"is_curve": False, "agreeing": 0.0, "projection": None, "rotation_number": None}
    for name, xy in planes:
        xy = xy - xy.mean(axis=0)
        theta = np.arctan2(xy[:, 1], xy[:, 0])
        order = np.argsort(theta)
        rank = np.empty(K, int)
        rank[order] = np.arange(K)
        shift = np.mod(np.diff(rank), K)
        s = int(np.median(shift))
        dev = np.abs(shift - s)
        agree = float(np.mean(np.minimum(dev, K - dev) <= 2))
        gaps = np.diff(np.concatenate([np.sort(theta), [np.sort(theta)[0] + 2 * np.pi]]))
        if agree > best["agreeing"]:
            best = {
                "is_curve": bool(agree >= 0.98 and gaps.max() <= 0.2),
                "agreeing": agree,
                "projection": name,
                "largest_angular_gap": float(gaps.max()),
                "rotation_number": min(s, K - s) / K,
            }
    return best


def _shoot(system, x, n, scale) -> dict:
    """``shoot`` for period n from ``x`` at a multiple of T (residual below 1e-9 of
    ``scale``): converged, minimal period, multipliers, the orbit's state ``x``."""
    from gearsym.solver.periodic import ShootingError, shoot

    try:
        orbit = shoot(system, x, n, tol=1e-9 * scale)
    except (ShootingError, FloatingPointError, RuntimeError, np.linalg.LinAlgError) as err:
        return {"converged": False, "why": str(err).splitlines()[0][:200]}
    mu = orbit.floquet.multipliers
    return {
        "converged": True,
        "minimal_period": orbit.minimal_period,
        "largest_multiplier": float(np.max(np.abs(mu))),
        "multipliers": [[float(m.real), float(m.imag)] for m in mu],
        "x": orbit.x0,
        "residual": orbit.residual,
    }


def _periodic(system, tail: np.ndarray, scale: float) -> dict | None:
    """The period-n evidence of the tail (repeating or converging), or None."""
    n, gap = repeat_period(tail, REPEAT * scale)
    converging = False
    if n is None:  # still converging? the gaps of the last window are small and shrink
        for m in range(1, 65):
            g = np.max(np.abs(tail[m:] - tail[:-m]), axis=1)[-WINDOW:]
            if g.max() < 1e-2 * scale and g[-100:].max() < 0.5 * g[:100].max():
                n, gap, converging = m, float(g[-1]), True
                break
    if n is None:
        return None
    shot = _shoot(system, tail[-1], n, scale)
    m = shot.get("minimal_period")
    if shot["converged"] and m is not None and m < n:
        # an orbit of a divisor m the run is still converging to (a multiplier near -1
        # makes the run repeat after 2m sooner than after m): judged at m, as converging
        gap = float(np.max(np.abs(tail[-1] - tail[-1 - m])))
        n, shot, converging = m, _shoot(system, tail[-1], m, scale), True
    ev = {"n": n, "repeat_gap": gap, "converging": converging, "shooting": shot}
    if not shot["converged"]:
        return ev | {"ok": False, "why": f"repeats after {n} periods; shooting: {shot['why']}"}
    x = shot.pop("x")
    dist = float(np.max(np.abs(x - tail[-1])))
    r = shot["largest_multiplier"]
    allowed = 10 * REPEAT * scale if not converging else 10 * gap / max(1 - r, 1e-12)
    ev["distance_from_run"] = dist
    if shot["minimal_period"] != n:
        why = f"shooting found minimal period {shot['minimal_period']}, not {n}"
    elif r >= 1:
        why = f"the orbit is not attracting (|mu| = {r:.6f})"
    elif dist > allowed:
        why = f"the orbit lies {dist:.2e} from the run (allowed {allowed:.2e})"
    else:
        return ev | {"ok": True}
    return ev | {"ok": False, "why": why}


def _settled_at(P: np.ndarray, n: int, tol: float) -> int:
    """The first period after which ``|P_{k+n} - P_k| <= tol`` for good."""
    g = np.max(np.abs(P[n:] - P[:-n]), axis=1)
    bad = np.nonzero(g > tol)[0]
    return 0 if bad.size == 0 else int(bad[-1] + 1)


def reference_label(system, x0, *, rtol: float = 1e-10, atol: float = 1e-12) -> dict:
    """The reference label of the run from ``x0`` (n,) at tau 0: ``label`` (``period-n``,
    ``chaotic``, ``quasi-periodic``, ``divergent`` or ``unresolved``), ``why`` when
    unresolved, and the evidence (see the module text)."""
    from gearsym.solver.analysis.lyapunov import largest_lyapunov
    from gearsym.solver.integrate.run import integrate
    from gearsym.solver.integrate.spec import RunSpec

    spec = RunSpec(rtol=rtol, atol=atol, transient=0, periods=RUN, valid_range="record")
    res = integrate(system, np.asarray(x0, float), spec)
    status = res.status[0]
    ev: dict = {"status": status}
    if res.exits is not None and np.isfinite(res.exits[0, 0]):
        ev["left_valid_range_at_period"] = float(res.exits[0, 0] / system.period)
    if status != "ok":
        label = "divergent" if status == "divergent" else "unresolved"
        return {"label": label, "why": f"the long run stopped: {status}", **ev}
    P = res.x[0]
    tail = P[RUN - TAIL :]
    scale = max(1.0, float(np.ptp(tail, axis=0).max()))
    ev["extent"] = scale
    per = _periodic(system, tail, scale)
    if per is not None:
        ev["periodic"] = per
        if per["ok"]:
            n = per["n"]
            ev["settled_by_period"] = _settled_at(P, n, 10 * max(per["repeat_gap"], REPEAT * scale))
            return {"label": f"period-{n}", **ev}
    try:  # the exponent at the engine's default tolerances (its error bar is measured there)
        lyap = largest_lyapunov(
            system, P[RUN - TAIL], t0=(RUN - TAIL) * system.period, periods=TAIL
        )
    except FloatingPointError as err:
        return {"label": "unresolved", "why": f"the exponent's run stopped: {err}", **ev}
    lam, U = lyap.exponent, lyap.uncertainty
    ev["exponent"] = {"lambda": lam, "uncertainty": U, "periods": TAIL}
    widest = int(np.argmax(np.ptp(tail[:, : len(system.coordinates)], axis=0)))
    K = zero_one_K(tail[:, widest])
    ev["zero_one"] = {"K": K, "state": system.states[widest]}
    if lam - U > 0 and K >= K_CHAOS:
        return {"label": "chaotic", **ev}
    if abs(lam) + U <= QP_BAND:
        curve = closed_curve(tail)
        ev["curve"] = curve
        if curve["is_curve"]:
            return {"label": "quasi-periodic", **ev}
        why = f"exponent near zero but the section is not a closed curve ({curve['agreeing']:.2f})"
    elif lam - U > 0:
        why = f"exponent {lam:.2e} +- {U:.1e} positive but the 0-1 test reads K = {K:.2f}"
    else:
        why = f"exponent {lam:.2e} +- {U:.1e}, K = {K:.2f}: neither chaos nor a torus"
    if per is not None and not per["ok"]:
        why = per["why"] + "; " + why
    return {"label": "unresolved", "why": why, **ev}
