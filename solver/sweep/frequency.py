"""Frequency response: the periodic solutions over the forcing frequency (or any other
parameter) by harmonic-balance continuation and by shooting continuation, as curves of
mean, amplitude (half peak-to-peak) and RMS per coordinate with their stability.

Both methods follow the solution curve by pseudo-arclength, so both find the unstable
branches between the folds (the jumps of a backlash nonlinearity); harmonic balance
judges stability by Hill's method, shooting by the monodromy.  Each curve keeps the
method, its events (folds and stability changes, located) and its wall time.
"""

from __future__ import annotations

import time

import numpy as np

from ..system import System
from ._resample import on_grid
from .frequency_ranges import names_moved, no_second_curve, others_moved
from .frequency_result import Curve, FrequencyResponse

__all__ = [
    "MAX_HARMONICS",
    "MAX_UNKNOWNS",
    "METHODS",
    "Curve",
    "FrequencyResponse",
    "dynamic_factor",
    "frequency_response",
    "harmonics_cap",
]

METHODS = ("hb", "shooting", "integration")
# Harmonic balance solves a dense system of n_states (2H + 1) unknowns a few times per
# point: 4096 unknowns take about a second a solve (and 0.5 GiB), a response of a few
# hundred points some minutes; more would be hours.
MAX_UNKNOWNS = 4096
MAX_HARMONICS = 256


def harmonics_cap(system: System) -> int:
    """The most harmonics the model may take: at most :data:`MAX_HARMONICS` and
    :data:`MAX_UNKNOWNS` unknowns (n_states (2H + 1))."""
    return max(1, min(MAX_HARMONICS, (MAX_UNKNOWNS // system.n - 1) // 2))


def dynamic_factor(system: System, tau, x, p) -> dict:
    """Per mesh coordinate: the peak of the dynamic mesh force over the static one,
    max |F(tau)| / |F_static| over the samples ``x`` (states x samples) at ``tau``
    (nan where the model does not emit its mesh forces or a mesh carries no static load)."""
    mod = system.module
    coords = system.coordinates
    if not system.contract.provides("mesh_force", "static_mesh_force"):
        return {c: float("nan") for c in coords}
    F = np.asarray(mod.mesh_force(np.asarray(tau, float), np.asarray(x, float), p))
    F = F.reshape(len(coords), -1)
    static = np.asarray(mod.static_mesh_force(p), float)
    out = {}
    for i, c in enumerate(coords):
        ok = abs(static[i]) > 1e-12 and np.all(np.isfinite(F[i]))
        out[c] = float(np.max(np.abs(F[i])) / abs(static[i])) if ok else float("nan")
    return out


def _hb_factors(system, parameter, br, n, samples: int = 512) -> dict:
    """The dynamic factor at every point of a harmonic-balance branch, in one vectorised
    call of the generated mesh forces (``samples`` phases a period)."""
    coords = system.coordinates
    npts = len(br.points)
    mod = system.module
    if not npts or not system.contract.provides("mesh_force", "static_mesh_force"):
        return {c: np.full(npts, np.nan) for c in coords}
    prob = br.harmonic_balance
    phases = 2 * np.pi * np.arange(samples) / samples
    C = np.array([pt.coefficients for pt in br.points])  # (P, nx, M)
    X = prob.time_series(C.reshape(-1, prob.M), phases).reshape(npts, system.n, samples)
    P = np.array([system.parameters_with(**{parameter: pt.value}) for pt in br.points])
    iw = mod.PARAMETERS.index(system.contract.forcing_frequency)
    tau = n * phases[None, :] / P[:, iw, None]  # (P, samples)
    F = np.asarray(
        mod.mesh_force(
            tau.ravel(), X.transpose(1, 0, 2).reshape(system.n, -1), np.repeat(P.T, samples, axis=1)
        )
    )
    F = F.reshape(len(coords), npts, samples)
    static = np.array([mod.static_mesh_force(p) for p in P])  # (P, m)
    out = {}
    for i, c in enumerate(coords):
        s = np.abs(static[:, i])
        peak = np.max(np.abs(F[i]), axis=1)
        out[c] = np.where(s > 1e-12, peak / np.where(s > 1e-12, s, 1.0), np.nan)
    return out


def _hb_curve(system, parameter, start, stop, harmonics, n, ds, grid) -> Curve:
    from ..periodic.hb_continuation import HarmonicBalanceProblem, continue_hb

    span = abs(stop - start)
    br = continue_hb(
        system,
        parameter,
        start,
        stop,
        harmonics=harmonics,
        n=n,
        ds=ds,
        ds_max=span / 10,
        dlam_max=ds,
        confirm=False,
    )
    screening = None
    if system.piecewise:
        # Hill's flags on a piecewise model: kept only where the located monodromy
        # confirms them (hb_confirm.py); the counts go into the curve's details
        from ..periodic.hb_confirm import screen

        screening = screen(system, br)
        br = screening.branch
    br = on_grid(
        HarmonicBalanceProblem(system, parameter, br.harmonic_balance, check=False), br, grid
    )
    stats = {}
    prob = br.harmonic_balance
    for c in system.coordinates:
        i = system.index(c)
        C = np.array([pt.coefficients[i] for pt in br.points]).reshape(-1, prob.M)
        lo, hi = prob.extrema(C)  # at the polynomial's refined extrema, not on a grid
        stats[c] = {
            "mean": br.mean(c),
            "amplitude": (hi - lo) / 2,
            "rms": br.rms(c),
            "max": hi,
            "min": lo,
        }
    for c, d in _hb_factors(system, parameter, br, n).items():
        stats[c]["dynamic_factor"] = d
    tail = float(np.max(br.tail_shares())) if len(br.points) else 0.0
    return Curve(
        "hb",
        parameter,
        br.values,
        br.stable,
        stats,
        br.bifurcations,
        br.wall_time + (0.0 if screening is None else screening.wall_time),
        {
            "harmonics": harmonics,
            "samples": br.harmonic_balance.N,
            "largest_tail_share": tail,
            "notes": list(br.notes),
            "status": br.status,
            "message": br.message,
            "screening": None if screening is None else screening.describe(),
        },
        br.states,
    )


def _shooting_curve(system, parameter, start, stop, n, ds, guess, grid) -> Curve:
    from ..integrate import simulate
    from ..periodic import continue_orbit
    from ..periodic.continuation import ShootingProblem

    started = time.perf_counter()
    br = continue_orbit(
        system, parameter, start, stop, guess, n=n, ds=ds, ds_max=2 * ds, max_points=20_000
    )
    br = on_grid(ShootingProblem(system, parameter, n), br, grid)
    keys = ("mean", "amplitude", "rms", "max", "min", "dynamic_factor")
    stats = {c: {q: [] for q in keys} for c in system.coordinates}
    for v, x0 in zip(br.values, br.states, strict=True):
        s = system.with_values(**{parameter: v})
        tr = simulate(s, np.asarray(x0), transient=0, periods=n, samples_per_period=256)
        for c, d in dynamic_factor(s, tr.t, tr.x, s.p).items():
            stats[c]["dynamic_factor"].append(d)
        for c in system.coordinates:
            y = tr.coordinate(c)[:-1]
            stats[c]["mean"].append(float(np.mean(y)))
            stats[c]["amplitude"].append(float((y.max() - y.min()) / 2))
            stats[c]["rms"].append(float(np.sqrt(np.mean(y**2))))
            stats[c]["max"].append(float(y.max()))
            stats[c]["min"].append(float(y.min()))
    stats = {c: {q: np.array(v) for q, v in d.items()} for c, d in stats.items()}
    return Curve(
        "shooting",
        parameter,
        np.asarray(br.values, float),
        np.asarray(br.stable, bool),
        stats,
        br.bifurcations,
        time.perf_counter() - started,
        {"status": br.status, "message": br.message},
        tuple(np.asarray(x, float) for x in br.states),
    )


def _integration_curves(system, parameter, start, stop, points, settle, sampled, spp):
    """Up and down stepped-frequency sweeps by time integration, the two in one lockstep
    group in the excitation phase (``native.phase``): at each step every lane runs
    ``settle`` periods from the previous frequency's end state, then ``sampled`` periods
    sampled ``spp`` times each (the first step settles ``max(settle, 300)`` periods from
    the loaded rest state).  Every point is where the simulation settles (an attractor):
    ``stable`` is true; the Poincare spread tells a periodic point from the rest."""
    from ..integrate import default_initial_state
    from ..integrate.native.phase import run_phase

    up = np.linspace(start, stop, points)
    moved = others_moved(system, parameter, up)
    if moved:
        raise ValueError(
            f"integration sweeps run over the forcing frequency "
            f"'{system.contract.forcing_frequency}' only (or a quantity that sets nothing "
            f"else, such as a speed), not '{parameter}', which sets {names_moved(moved)}"
        )
    started = time.perf_counter()
    lanes = (up, up[::-1])
    x = np.array([default_initial_state(system)] * 2)
    coords = system.coordinates
    iw = system.module.PARAMETERS.index(system.contract.forcing_frequency)
    keys = ("mean", "amplitude", "rms", "max", "min", "poincare_spread", "dynamic_factor")
    stats = [{c: {q: np.empty(points) for q in keys} for c in coords} for _ in lanes]
    status = [[] for _ in lanes]
    poincare = [[] for _ in lanes]
    for k in range(points):
        P = np.array([system.parameters_with(**{parameter: float(w[k])}) for w in lanes])
        run = run_phase(
            system.module,
            P,
            x,
            transient=max(settle, 300) if k == 0 else settle,
            periods=sampled,
            samples_per_period=spp,
        )
        for j in range(2):
            status[j].append(run.status[j])
            xs = run.x[j, :-1]  # the closing sample starts the next period
            poincare[j].append(run.x[j, ::spp].tolist())
            factor = dynamic_factor(system, run.t[:-1] / P[j, iw], xs.T, P[j])
            for c in coords:
                stats[j][c]["dynamic_factor"][k] = factor[c]
                y = xs[:, system.index(c)]
                pts = run.x[j, ::spp, system.index(c)]
                st = stats[j][c]
                st["mean"][k], st["max"][k], st["min"][k] = y.mean(), y.max(), y.min()
                st["amplitude"][k] = (y.max() - y.min()) / 2
                st["rms"][k] = np.sqrt(np.mean(y**2))
                st["poincare_spread"][k] = np.ptp(pts) if np.all(np.isfinite(pts)) else np.nan
        ok = np.array([s == "ok" for s in run.status])
        x = np.where(ok[:, None], run.x[:, -1], np.array([default_initial_state(system)] * 2))
    wall = time.perf_counter() - started
    out = []
    for j, (name, w) in enumerate(zip(("up", "down"), lanes, strict=True)):
        good = np.array([s == "ok" for s in status[j]])
        out.append(
            Curve(
                "integration",
                parameter,
                w[good],
                np.ones(int(good.sum()), bool),
                {c: {q: v[good] for q, v in d.items()} for c, d in stats[j].items()},
                (),
                wall,
                {
                    "direction": name,
                    "settle_periods": settle,
                    "sampled_periods": sampled,
                    "samples_per_period": spp,
                    "failed": int((~good).sum()),
                    "poincare": [q for q, g in zip(poincare[j], good, strict=True) if g],
                },
            )
        )
    return out


def frequency_response(
    system: System,
    parameter: str = "omega",
    start: float = 0.3,
    stop: float = 1.0,
    *,
    points: int = 200,
    methods=("hb",),
    harmonics: int = 15,
    n: int = 1,
    settle: int = 50,
    sampled: int = 16,
    samples_per_period: int = 64,
    tail: float | None = None,
    step: float | None = None,
) -> FrequencyResponse:
    """The periodic response over ``parameter`` from ``start`` to ``stop`` by each of
    ``methods`` (``hb``, ``shooting``, ``integration``); ``points`` is the number of
    solution points each curve returns: the values ``linspace(start, stop, points)``.
    Harmonic balance and shooting continue the branch by pseudo-arclength (first step
    ``step``, default the range over ``points - 1``; harmonic balance: the parameter moves
    by at most that per step; shooting: the step adapts up to twice that), then solve it
    again at the grid's values on each monotonic piece, keeping the turning points
    (``_resample.py``): a branch without folds has ``points`` points; one that folds k
    times has k + 1 monotonic pieces, each with the grid's values in its span, and its k
    turning points; a branch that stops early (the parameter's valid range) covers the
    grid up to there.  When the harmonic-balance branch turns back and leaves the range
    at ``start``, a second one is continued from ``stop`` (two curves of method ``hb``).
    ``integration``: up and down stepped sweeps of ``points`` frequencies each,
    ``settle`` + ``sampled`` periods each (only over the forcing frequency; see
    :func:`_integration_curves`).  ``tail``: harmonic balance raises H at
    the start (up to :func:`harmonics_cap`) until the top harmonics carry at most this
    share (``harmonic_balance``);
    the largest share along the branch is reported in the curve's details."""
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise ValueError(f"unknown method(s) {unknown}; methods: {', '.join(METHODS)}")
    if points < 2:
        raise ValueError(f"points must be >= 2, got {points}")
    if step is not None and not 0 < step <= abs(stop - start):
        raise ValueError(f"step must be in (0, |stop - start|], got {step}")
    ds = step or abs(stop - start) / (points - 1)
    grid = np.linspace(start, stop, points)
    from ..periodic.harmonic_balance import HarmonicBalanceError

    curves = []
    guess = None
    for m in methods:
        if m == "hb":
            if tail is not None:
                from ..periodic.harmonic_balance import harmonic_balance

                harmonics = harmonic_balance(
                    system.with_values(**{parameter: start}),
                    harmonics=harmonics,
                    n=n,
                    tail=tail,
                    max_harmonics=harmonics_cap(system),
                    stability=False,
                ).harmonics
            curve = _hb_curve(system, parameter, start, stop, harmonics, n, ds, grid)
            curves.append(curve)
            if curve.details["status"] not in ("complete", "boundary"):
                # the branch turned back out of the range: the rest of the range from the
                # other end (the solution a simulation settles on there)
                try:
                    rest = _hb_curve(system, parameter, stop, start, harmonics, n, ds, grid)
                except HarmonicBalanceError as err:
                    # the first curve stands; the note says why the rest of the range
                    # has none (the motion a simulation settles on there has no
                    # period-n orbit near it, say: a chaotic one)
                    curve.details["notes"].append(
                        no_second_curve(system, parameter, start, stop, n, err)
                    )
                    continue
                rest.details["notes"].insert(
                    0,
                    f"a second curve, from the other end ({parameter} = {stop:g}): the "
                    "first turned back at a fold and left the range where it started",
                )
                curves.append(rest)
        elif m == "integration":
            curves += _integration_curves(
                system, parameter, start, stop, points, settle, sampled, samples_per_period
            )
        else:
            from ..periodic.harmonic_balance import harmonic_balance

            if guess is None:
                first = harmonic_balance(
                    system.with_values(**{parameter: start}),
                    harmonics=harmonics,
                    n=n,
                    stability=False,
                )
                guess = first.state(0.0)
            curves.append(_shooting_curve(system, parameter, start, stop, n, ds, guess, grid))
    return FrequencyResponse(system, parameter, float(start), float(stop), tuple(curves))
