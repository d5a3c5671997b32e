"""The reference study's frequency response (issue 13, point 5): the period-1 response of
both load cases over the forcing frequency around the study's omega = 0.5, by harmonic
balance continuation with Hill's stability, at the study's two operating load ratios, and
where the study's operating point sits on it: how many periodic solutions coexist at
omega = 0.5, which are stable, and which of them the simulated attractor is."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["OMEGA", "RANGE", "ResponseCase", "resolution", "response_section", "run_response"]

OMEGA = 0.5  # the study's forcing frequency
RANGE = (0.3, 0.9)  # around it: the primary resonances of both meshes lie inside
LAMBDAS = (0.1, 0.8)  # the study's operating load ratios


@dataclass
class ResponseCase:
    case: str
    f1: float
    lam: float
    resp: object  # FrequencyResponse
    at_omega: list  # the solutions at omega = 0.5: dicts with amplitudes and stability
    attractor: dict | None  # the simulated attractor's amplitudes and its match


def _at(curve, value: float, coords) -> list[dict]:
    """The solutions where the curve crosses ``value`` (linear between two points)."""
    out = []
    v = curve.values
    for k in range(len(v) - 1):
        a, b = v[k] - value, v[k + 1] - value
        if a == 0 or a * b < 0:
            w = 0.0 if a == 0 else a / (a - b)
            amp = {
                c: float(
                    (1 - w) * curve.stats[c]["amplitude"][k]
                    + w * curve.stats[c]["amplitude"][k + 1]
                )
                for c in coords
            }
            mean = {
                c: float((1 - w) * curve.stats[c]["mean"][k] + w * curve.stats[c]["mean"][k + 1])
                for c in coords
            }
            stable = bool(curve.stable[k]) and bool(curve.stable[k + 1])
            factor = {}
            for c in coords:
                d = curve.stats[c].get("dynamic_factor")
                factor[c] = float("nan") if d is None else float((1 - w) * d[k] + w * d[k + 1])
            out.append({"amplitude": amp, "mean": mean, "stable": stable, "factor": factor})
    if v[-1] == value:
        k = len(v) - 1
        out.append(
            {
                "amplitude": {c: float(curve.stats[c]["amplitude"][k]) for c in coords},
                "mean": {c: float(curve.stats[c]["mean"][k]) for c in coords},
                "stable": bool(curve.stable[k]),
            }
        )
    return out


def _attractor(result, solutions, coords) -> dict | None:
    """The simulated operating point's amplitudes and the nearest solution at omega."""
    if result is None:
        return None
    tr = result.trajectory
    amp = {}
    for c in coords:
        y = tr.coordinate(c)
        y = y[np.isfinite(y)]
        amp[c] = float((y.max() - y.min()) / 2) if y.size else float("nan")
    motion = {c: result.classification[c].motion for c in coords}
    best, gap = None, float("inf")
    for k, s in enumerate(solutions):
        d = max(abs(s["amplitude"][c] - amp[c]) for c in coords)
        if d < gap:
            best, gap = k, d
    return {"amplitude": amp, "motion": motion, "nearest": best, "gap": gap}


def resolution(quick: bool) -> tuple[int, int]:
    """(points, harmonics) of the frequency responses: each grid over ``RANGE`` holds the
    study's omega = 0.5 as a point (0.3 + 26 x 0.6/78, 0.3 + 133 x 0.6/399), where the
    solutions are read, not interpolated between two grid points."""
    return (79, 10) if quick else (400, 15)


def run_response(
    out: Path,
    systems: dict,
    cases,
    points: dict,
    *,
    quick: bool,
    done: dict | None = None,
    save=None,
    figures: list | None = None,
) -> list:
    """The frequency responses (figures and data under ``out``), one per (case, lambda);
    ``done``: ``(case, lambda) -> FrequencyResponse`` already computed (the rest are
    computed here); ``save(response, path)`` writes a response's files (default
    ``export.save_all`` here and now); ``figures``: a list the ``(function, args)`` of each
    figure is appended to, for the caller to draw (default: drawn here)."""
    from gearsym.solver.export import save_all
    from gearsym.solver.sweep.frequency import frequency_response

    from .figures import response_figure

    num, harmonics = resolution(quick)
    done = done or {}
    rows = []
    for case, _, f1 in cases:
        system = systems[case]
        coords = system.coordinates
        per_lambda = {}
        for lam in LAMBDAS:
            s = system.with_values(**{"lambda": lam})
            resp = done.get((case, lam))
            if resp is None:
                resp = frequency_response(s, "omega", *RANGE, points=num, harmonics=harmonics)
            # JSON, CSV and MATLAB, as every command writes (solver/export.py)
            (save or save_all)(resp, out / "data" / f"response_{case}_lambda_{lam}.json")
            sols = _at(resp.curves[0], OMEGA, coords)
            att = _attractor(points.get((case, lam)), sols, coords)
            rows.append(ResponseCase(case, f1, lam, resp, sols, att))
            per_lambda[lam] = resp
        figure = (
            per_lambda,
            out / f"response_{case}.png",
            f"{case} load, f1 = {f1}: period-1 response over ω̄ (harmonic balance, H = {harmonics})",
            f"{system.name}, scene values but ω̄ (no other overrides); pseudo-arclength "
            f"continuation from ω̄ = {RANGE[0]} (start settled by simulation from the loaded "
            "rest state); stability by Hill's method; the study's ω̄ = 0.5 marked",
            OMEGA,
        )
        if figures is None:
            response_figure(*figure)
        else:
            figures.append((response_figure, figure))
    return rows


def _fmt_solution(s, coords) -> str:
    amps = ", ".join(f"{c} {s['amplitude'][c]:.3g}" for c in coords)
    factor = s.get("factor", {})
    df = ", ".join(f"{c} {factor[c]:.3g}" for c in coords if np.isfinite(factor.get(c, np.nan)))
    return f"{'stable' if s['stable'] else 'unstable'} ({amps}" + (
        f"; dynamic factor {df})" if df else ")"
    )


def response_section(rows) -> str:
    """Markdown: where the study's operating points sit on the frequency response."""
    w = ["## Frequency response around the study's operating point\n"]
    w.append(
        "The period-1 response of each load case over the forcing frequency ω̄ from "
        f"{RANGE[0]} to {RANGE[1]}, by harmonic-balance continuation (alternating "
        "frequency–time with the generated Jacobian; stability by Hill's method; "
        "`docs/analysis.md`), at the study's two load ratios. Amplitudes are half "
        "peak-to-peak, in half backlashes; the dynamic factor of a mesh is its peak dynamic "
        "force (elastic and viscous) over its static force. A fold is where a slow "
        "frequency sweep would jump; between two folds the branch is unstable and two "
        "stable solutions coexist. "
        "Folds are listed in the order met along the branch from ω̄ = 0.3. The simulated "
        "operating point (the analysis of the section above) is matched to a solution when "
        "both are period-1 and their amplitudes agree within 1e-3 (the simulation's "
        "extremes are sampled 64 times a period).\n"
    )
    w.append(
        "| load | λ | folds (ω̄) | periodic solutions at ω̄ = 0.5 | the simulated "
        "operating point (study's ω̄ = 0.5) |"
    )
    w.append("|---|---|---|---|---|")
    for r in rows:
        coords = r.resp.system.coordinates
        curve = r.resp.curves[0]
        folds = ", ".join(
            f"{e.value:.4f}" + ("" if e.name == "fold" else f" ({e.name})")
            for e in curve.events
            if e.jump
        )
        other = [e for e in curve.events if not e.jump]
        if other:
            folds += "; " + ", ".join(f"{e.name} at {e.value:.4f}" for e in other)
        sols = "; ".join(_fmt_solution(s, coords) for s in r.at_omega) or "none found"
        att = r.attractor
        if att is None:
            seen = "not simulated"
        else:
            motion = ", ".join(f"{c} {att['motion'][c]}" for c in coords)
            amps = ", ".join(f"{c} {att['amplitude'][c]:.3g}" for c in coords)
            if (
                att["nearest"] is not None
                and att["gap"] < 1e-3
                and all(m == "period-1" for m in att["motion"].values())
            ):
                match = f"the {'stable' if r.at_omega[att['nearest']]['stable'] else 'unstable'} "
                match += f"solution no. {att['nearest'] + 1} (amplitudes within {att['gap']:.1e})"
            else:
                match = "on none of the period-1 solutions (nearest amplitude gap "
                match += f"{att['gap']:.3g})" if np.isfinite(att["gap"]) else "—)"
            seen = f"{motion}; amplitudes {amps}; {match}"
        w.append(
            f"| {r.case} (f1 = {r.f1}) | {r.lam} | {folds or 'none'} | "
            f"{len(r.at_omega)}: {sols} | {seen} |"
        )
    w.append("")
    w.append(
        "Figures: `response_<load>.png` (both load ratios, stable solid, unstable dashed, "
        "folds marked, ω̄ = 0.5 marked); data: `data/response_<load>_lambda_<λ>.json` "
        "(one record per solution point). `gearsym frequency-response SCENE --param "
        "omega=0.3:0.9:400` draws the same for any scene.\n"
    )
    return "\n".join(w)
