"""The reference study's findings tested on one model's runs (the study's polynomial or
the exact dead zone): what the model shows, a grade, why, the runs that carry it and the
files that show it.

A grade is ``True`` (agrees), ``None`` (partly), ``False`` (differs), :data:`NOT_A_CLAIM`
(an observation the study did not make: no verdict) or :data:`NOT_TESTED` (the runs hold
nothing the claim can be tested on, with the reason).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from gearsym.solver.analysis import spectrum
from gearsym.solver.analysis.meshing import meshing_states

from .long_runs import periods_run

__all__ = ["NOT_A_CLAIM", "NOT_TESTED", "Bundle", "Found", "findings", "runs_text"]

NOT_TESTED = "not tested"
NOT_A_CLAIM = "not a claim"
QUASI = "quasi-periodic"


@dataclass
class Bundle:
    """One model's runs: ``by_case[case]`` the (forward, backward) lambda sweeps,
    ``points[(case, lambda)]`` the operating points (``PointResult``), ``maps`` the
    lambda sweeps at each f1 of ``f1s``; ``files`` the names of what was written
    (``sweep``: case -> file, ``map``: file, ``point``: (case, lambda) -> (figure, data),
    ``bifurcation``: case -> figure)."""

    name: str
    by_case: dict
    points: dict
    maps: list
    f1s: tuple
    files: dict = field(default_factory=dict)


@dataclass
class Found:
    """One finding on one model: what it shows, the grade, why, and evidence."""

    text: str
    grade: object
    why: str
    evidence: tuple = ()
    carriers: list = field(default_factory=list)  # the RunRecords the grade rests on


def runs(values, labels) -> list[tuple[str, float, float]]:
    """Consecutive runs of equal labels: (label, first value, last value)."""
    out = []
    for v, lab in zip(values, labels, strict=True):
        if out and out[-1][0] == lab:
            out[-1] = (lab, out[-1][1], float(v))
        else:
            out.append((lab, float(v), float(v)))
    return out


def runs_text(values, labels) -> str:
    return "; ".join(f"{lab} on [{a:g}, {b:g}]" for lab, a, b in runs(values, labels))


def _at(values) -> str:
    return ", ".join(f"{v:g}" for v in values) or "none"


def carried(found: Found) -> str:
    """'carried by 3 runs (run 400 to 8,000 periods)'."""
    n = len(found.carriers)
    if not n:
        return ""
    return f"carried by {n} run{'s' if n > 1 else ''} ({periods_run(found.carriers)})"


def _grade(full: bool, part: bool):
    return True if full else (None if part else False)


def _sweep_rows(b: Bundle, case: str, f1: float, lam) -> dict:
    fwd, bwd = b.by_case[case]
    files = (b.files["bifurcation"][case], *b.files["sweep"][case])
    mu, mv = fwd.motion("u"), fwd.motion("v")
    target = "period-1" if case == "light" else "period-3"
    edge = 0.57 if case == "light" else 0.13
    low = [k for k, v in enumerate(lam) if v < edge]
    high = [k for k, v in enumerate(lam) if v >= edge]
    quasi = [k for k in low if mu[k] == QUASI]
    off = [k for k in high if mu[k] != target]
    ok_high = not off
    why = (
        f"every λ ≥ {edge} is {target}"
        if ok_high
        else f"λ ≥ {edge} not {target} at λ = {_at(lam[k] for k in off)}"
    ) + (
        f"; quasi-periodic at λ = {_at(lam[k] for k in quasi)}"
        if quasi
        else f"; no quasi-periodic attractor below λ = {edge}"
    )
    out = {}
    out[f"{case}-u"] = Found(
        f"u (forward): {runs_text(lam, mu)}",
        _grade(ok_high and bool(quasi), ok_high),
        why,
        files,
        [fwd.points[k] for k in quasi + (high if ok_high else [])],
    )
    chaos_low = [k for k, v in enumerate(lam) if v <= 0.3 and mv[k] == "chaotic"]
    end_ok = mv[-1] == target
    why = (
        f"chaotic at λ = {_at(lam[k] for k in chaos_low)}"
        if chaos_low
        else "no chaotic attractor at λ ≤ 0.3"
    ) + (f"; {target} at λ = 1" if end_ok else f"; {mv[-1]} at λ = 1, not {target}")
    out[f"{case}-v"] = Found(
        f"v (forward): {runs_text(lam, mv)}",
        _grade(bool(chaos_low) and end_ok, end_ok or bool(chaos_low)),
        why,
        files,
        [fwd.points[k] for k in chaos_low] + ([fwd.points[-1]] if end_ok else []),
    )
    hysteresis = [float(v) for v, a, c in zip(lam, mv, bwd.motion("v"), strict=True) if a != c]
    apart = [
        float(v)
        for v, a, c in zip(lam, fwd.minima("v"), bwd.minima("v"), strict=True)
        if abs(a - c) > 0.05
    ]
    text = (
        f"motion differs at {len(hysteresis)} values of λ ({_at(hysteresis)})"
        if hysteresis
        else "same motion at every λ"
    ) + (
        f"; Min(v) differs by more than 0.05 at {len(apart)} of {len(lam)} values "
        f"(λ ∈ [{min(apart):g}, {max(apart):g}])"
        if apart
        else "; Min(v) within 0.05 at every λ"
    )
    out[f"{case}-hysteresis"] = Found(
        text,
        NOT_A_CLAIM,
        "coexisting attractors: which one the system settles on depends on its history"
        if hysteresis or apart
        else "one attractor along both sweeps",
        files,
    )
    return out


def _range(tr, c) -> tuple[float, float]:
    u = tr.coordinate(c)
    return float(u.min()), float(u.max())


def _near(rng, lo, hi, tol=0.1) -> bool:
    return abs(rng[0] - lo) < tol and abs(rng[1] - hi) < tol


def _peaks(tr, c):
    return sorted(spectrum(tr, c).peaks(), key=lambda p: -p["amplitude"])


def _has(peaks, wanted, tol=0.02) -> bool:
    return all(any(abs(p - w) < tol for p in peaks) for w in wanted)


def _fmt(values) -> str:
    return ", ".join(f"{v:.3g}" for v in sorted(values)) or "none found"


def _lyap(r) -> str:
    rec = r.record().lyapunov
    return "none (the run has no exponent)" if rec is None else f"{rec['exponent']:.4f}"


def _point_rows(b: Bundle) -> dict:
    out = {}

    def point(case, value):
        r = b.points[(case, value)]
        return r, r.trajectory, r.verdict.motion, b.files["point"][(case, value)]

    r, tr, mo, files = point("light", 0.1)
    u_rng, v_rng = _range(tr, "u"), _range(tr, "v")
    sh = meshing_states(tr).get("u", {})
    separates = (sh.get("separated") or 0) > 0
    in_range = _near(u_rng, 0.7, 1.3)
    out["light-0.1-u"] = Found(
        f"u ∈ [{u_rng[0]:.3f}, {u_rng[1]:.3f}], {mo}; the model's force on u is forward "
        f"{sh.get('forward', 0):.2f}, zero {sh.get('separated', 0):.2f} of the time"
        + (
            f", inside the gap yet loaded {sh['loaded_in_gap']:.2f}"
            if sh.get("loaded_in_gap")
            else ""
        ),
        _grade(in_range and separates, in_range or separates),
        ("range within 0.1 of the study's" if in_range else "range not within 0.1 of [0.7, 1.3]")
        + (
            "; the force vanishes part of the time (separation)"
            if separates
            else "; the force never vanishes: no separation"
            + (" (the polynomial is zero only at 0 and ±0.770)" if b.name == "polynomial" else "")
        ),
        files,
        [r.record()],
    )
    impacts = v_rng[0] < -1 and v_rng[1] > 1
    chaotic = mo == "chaotic"
    out["light-0.1-v"] = Found(
        f"v ∈ [{v_rng[0]:.3f}, {v_rng[1]:.3f}], {mo}, largest Lyapunov exponent {_lyap(r)}",
        _grade(chaotic and impacts, chaotic or impacts),
        ("chaotic on the verdict's evidence" if chaotic else f"the verdict is {mo}, not chaotic")
        + ("; v passes both edges ±1" if impacts else "; v does not pass both edges ±1"),
        files,
        [r.record()],
    )
    r, tr, mo, files = point("light", 0.8)
    peaks = [p["frequency"] for p in _peaks(tr, "u")[:2]]
    periodic, lines = mo == "period-1", _has(peaks, (0.5, 1.0))
    out["light-0.8"] = Found(
        f"{mo} (u and v); largest peaks of u at {_fmt(peaks)}",
        _grade(periodic and lines, periodic or lines),
        ("period-1" if periodic else f"{mo}, not period-1")
        + ("; the two largest lines at 0.5 and 1.0" if lines else "; other largest lines"),
        files,
        [r.record()],
    )
    r, tr, mo, files = point("heavy", 0.1)
    u_rng = _range(tr, "u")
    peaks = [p["frequency"] for p in _peaks(tr, "u")[:3]]
    in_range, lines = _near(u_rng, 1.4, 1.6), _has(peaks, (0.5, 1.0, 1.5))
    out["heavy-0.1"] = Found(
        f"u ∈ [{u_rng[0]:.3f}, {u_rng[1]:.3f}], {mo}; largest peaks at {_fmt(peaks)}",
        _grade(in_range and lines, u_rng[0] > 1),
        ("range within 0.1 of [1.4, 1.6]" if in_range else "range not within 0.1 of [1.4, 1.6]")
        + ("; lines at 0.5, 1.0 and 1.5" if lines else "; not the three lines 0.5, 1.0, 1.5")
        + ("; u stays beyond the edge +1 (forward contact)" if u_rng[0] > 1 else ""),
        files,
        [r.record()],
    )
    r, tr, mo, files = point("heavy", 0.8)
    v_rng = _range(tr, "v")
    in_range, p3 = _near(v_rng, -1.6, -1.3), mo == "period-3"
    out["heavy-0.8"] = Found(
        f"v ∈ [{v_rng[0]:.3f}, {v_rng[1]:.3f}]; {mo} (u and v)",
        _grade(in_range and p3, in_range or p3),
        ("range within 0.1 of [−1.6, −1.3]" if in_range else "range not within 0.1")
        + ("; period-3 confirmed by shooting" if p3 else f"; {mo}, not period-3"),
        files,
        [r.record()],
    )
    return out


def _map_rows(b: Bundle, map_lam) -> dict:
    f1s, maps, files = b.f1s, b.maps, (b.files["map"],)
    max_u = np.array([sw.maxima("u") for sw in maps])
    min_v = np.array([sw.minima("v") for sw in maps])
    out = {}
    spread = float(np.max(np.ptp(max_u, axis=1)))
    out["max-u-lambda"] = Found(
        f"largest change of Max(u) over λ at fixed f1: {spread:.3f}",
        spread < 0.2,
        "below 0.2 half backlashes" if spread < 0.2 else "0.2 half backlashes or more",
        files,
    )
    mean_u = max_u.mean(axis=1)
    rising = bool(np.all(np.diff(mean_u) > 0))
    out["max-u-f1"] = Found(
        "mean Max(u) over λ for f1 = "
        + ", ".join(f"{f:g}: {m:.3f}" for f, m in zip(f1s, mean_u, strict=True)),
        rising,
        "rises with every step of f1" if rising else "does not rise with every step of f1",
        files,
    )
    crit = []
    for sw in maps:
        mv = sw.motion("v")
        k = len(mv)
        while k > 0 and mv[k - 1].startswith("period-"):
            k -= 1
        crit.append(float(map_lam[k]) if k < len(mv) else None)
    shown = ", ".join(
        f"{f:g}: " + ("none found" if c is None else f"{c:g}")
        for f, c in zip(f1s, crit, strict=True)
    )
    if all(c == 0.0 for c in crit) or any(c is None for c in crit):
        grade = NOT_TESTED
        why = (
            "v is periodic at every λ: there is no critical λ to compare"
            if all(c == 0.0 for c in crit)
            else "v is not periodic at λ = 1 for some f1: no critical λ there"
        )
    else:
        grade = bool(np.all(np.diff(crit) < 0))
        why = "falls with every step of f1" if grade else "does not fall with every step of f1"
    out["critical"] = Found(f"critical λ for f1 = {shown}", grade, why, files)
    chaotic = [[p.min("v") for p in sw.points if p.motion("v") == "chaotic"] for sw in maps]
    cmin = [min(c) if c else None for c in chaotic]
    found = [abs(m) for m in cmin if m is not None]
    if len(found) < 2:
        grade = NOT_TESTED
        why = "chaotic points at fewer than two values of f1: no trend to test"
    else:
        grade = bool(np.all(np.diff(found) > 0))
        why = "grows with f1" if grade else "does not grow with every step of f1"
    out["min-v-chaotic"] = Found(
        "Min(v) over chaotic points for f1 = "
        + ", ".join(
            f"{f:g}: " + ("none found" if m is None else f"{m:.3f}")
            for f, m in zip(f1s, cmin, strict=True)
        ),
        grade,
        why,
        files,
        [p for sw in maps for p in sw.points if p.motion("v") == "chaotic"],
    )
    mean_v = np.abs(min_v.mean(axis=1))
    grows = bool(np.all(np.diff(mean_v) > 0))
    out["min-v"] = Found(
        "mean Min(v) over λ for f1 = "
        + ", ".join(f"{f:g}: {m:.3f}" for f, m in zip(f1s, min_v.mean(axis=1), strict=True)),
        grows,
        "all points, not only chaotic: " + ("grows with f1" if grows else "does not grow"),
        files,
    )
    return out


# The study's findings in the report's order: key -> the study's words ({f1}: the load).
STUDY = {
    "light-u": "f1 = 0.1: p-g quasi-periodic for λ ∈ [0, 0.57], period-1 for λ ∈ [0.57, 1]",
    "light-v": "f1 = 0.1: q-g chaotic at low λ, period-1 at high λ",
    "light-hysteresis": "f1 = 0.1: forward against backward sweep",
    "heavy-u": "f1 = 0.5: p-g quasi-periodic for λ ∈ [0, 0.13], period-3 for λ ∈ [0.13, 1]",
    "heavy-v": "f1 = 0.5: q-g chaotic at low λ, period-3 at high λ",
    "heavy-hysteresis": "f1 = 0.5: forward against backward sweep",
    "light-0.1-u": "f1 = 0.1, λ = 0.1: u ∈ [0.7, 1.3] (meshing and separation)",
    "light-0.1-v": "f1 = 0.1, λ = 0.1: v chaotic in [−1.5, 1.5] (forward and backward impacts)",
    "light-0.8": "f1 = 0.1, λ = 0.8: both period-1, spectral peaks at 0.5 and 1.0",
    "heavy-0.1": "f1 = 0.5, λ = 0.1: u ∈ [1.4, 1.6] in forward meshing, peaks 0.5, 1.0, 1.5",
    "heavy-0.8": "f1 = 0.5, λ = 0.8: v ∈ [−1.6, −1.3] (backward meshing), both period-3",
    "max-u-lambda": "Raising λ changes Max(u) little",
    "max-u-f1": "Raising f1 raises Max(u)",
    "critical": "Raising f1 lowers the critical λ past which q-g is periodic",
    "min-v-chaotic": "Raising f1 enlarges |Min(v)| in the chaotic range",
    "min-v": "Raising f1 enlarges |Min(v)|",
}


def findings(b: Bundle, lam, map_lam, cases) -> dict:
    """key (of :data:`STUDY`) -> :class:`Found` on the model of ``b``."""
    out = {}
    for case, _, f1 in cases:
        out.update(_sweep_rows(b, case, f1, lam))
    out.update(_point_rows(b))
    out.update(_map_rows(b, map_lam))
    return {k: out[k] for k in STUDY}
