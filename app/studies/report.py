"""The report of ``gearsym reproduce``: each finding of the reference study beside the
toolkit's, with the evidence and a verdict (agrees, partly, differs, not tested)."""

from __future__ import annotations

import numpy as np

from .cases import CASES
from .claims import NOT_A_CLAIM, NOT_TESTED, STUDY, Found, carried, findings, runs, runs_text

__all__ = ["findings_table", "graded", "report", "runs", "runs_text", "stable_coverage", "tally"]


def _verdict(ok) -> str:
    return {True: "agrees", False: "**differs**", None: "partly", NOT_TESTED: "not tested"}[ok]


def stable_coverage(branches, sweeps, tol: float = 5e-3) -> tuple[int, int, list]:
    """How many periodic brute-force points lie on a stable continued branch.

    A brute-force point (the Poincare state at tau = 0 mod T of a period-n point, with its
    parameter value) counts as covered when its distance in (lambda, state) to a segment
    between two stable neighbouring points of a period-n branch is below ``tol`` (a
    chord: near a fold the branch curves within a step).
    """
    covered = total = 0
    missed = []
    for sw in sweeps:
        for value, point in zip(sw.values, sw.points, strict=True):
            motion = point.motion("u")
            if not motion.startswith("period-") or not len(point.poincare["u"]):
                continue
            total += 1
            q = np.concatenate([[value], point.poincare_state(list(point.poincare))])
            best = np.inf
            for br in branches:
                if f"period-{br.n}" != motion:
                    continue
                P = np.column_stack([br.values, np.asarray(br.states)])
                for i in range(len(P) - 1):
                    if br.stable[i] and br.stable[i + 1]:
                        best = min(best, _segment_distance(q, P[i], P[i + 1]))
            if best < tol:
                covered += 1
            else:
                missed.append(float(value))
    return covered, total, missed


def _segment_distance(q, a, b) -> float:
    d = b - a
    w = 0.0 if not np.any(d) else float(np.clip(np.dot(q - a, d) / np.dot(d, d), 0.0, 1.0))
    return float(np.linalg.norm(q - (a + w * d)))


FIGURES_MARK = "<!-- the figures written, listed by reproduce.py -->"
# replaced by reproduce.py with how many units of work came from the result store
STORED_MARK = "<!-- units of work loaded from the result store -->"


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _files(files) -> str:
    return ", ".join(f"`{f}`" for f in files) or "none"


def _found(f: Found) -> str:
    more = carried(f) if f.grade is True or f.grade is None else ""
    return f.text + (f"; {more}" if more else "")


def findings_table(study: dict, poly: dict, dead: dict) -> list[str]:
    """The findings table: the study's words, what the polynomial and the dead zone show,
    a verdict per model, why, and the files that show it."""
    rows = [
        "| study | found with the polynomial | found with the dead zone | verdict | why | "
        "evidence |",
        "|---|---|---|---|---|---|",
    ]
    for key, words in study.items():
        p, d = poly[key], dead[key]
        if p.grade == NOT_A_CLAIM:
            words, verdict = f"— ({words})", "not a claim of the study"
        else:
            verdict = f"polynomial: {_verdict(p.grade)}; dead zone: {_verdict(d.grade)}"
        why = f"polynomial: {p.why}; dead zone: {d.why}"
        evidence = f"polynomial: {_files(p.evidence)}; dead zone: {_files(d.evidence)}"
        cells = (words, _found(p), _found(d), verdict, why, evidence)
        rows.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return rows


def graded(bundles: dict, lam, res) -> dict:
    """``{"polynomial": findings, "dead zone": findings}``: each finding of the study
    graded on each model's runs (``claims.findings``)."""
    map_lam = np.round(np.linspace(0.0, 1.0, res.map_points), 10)
    return {name: findings(bundles[name], lam, map_lam, CASES) for name in bundles}


def tally(found: dict) -> dict:
    """Per model, how many of the study's findings agree, partly agree, differ or were
    not tested (as the findings table grades them; observations the study did not make
    are not counted); only the verdicts that occur."""
    out = {}
    for model, per in found.items():
        grades = [f.grade for f in per.values() if f.grade != NOT_A_CLAIM]
        counts = {_verdict(g).strip("*"): 0 for g in grades}
        for g in grades:
            counts[_verdict(g).strip("*")] += 1
        order = ("agrees", "partly", "differs", "not tested")
        out[model] = {v: counts[v] for v in order if v in counts}
    return out


def report(
    res, lam, bundles: dict, elapsed, quick, systems, branches, method: str, found=None
) -> str:
    """The report's Markdown up to its figure list (``bundles``: "polynomial" and "dead
    zone", each a :class:`Bundle`; ``systems``: case -> System of the polynomial;
    ``found``: :func:`graded`'s result, computed here if not given)."""
    poly, dead = bundles["polynomial"], bundles["dead zone"]
    found = found or graded(bundles, lam, res)
    rows = findings_table(STUDY, found["polynomial"], found["dead zone"])
    cont_lines = []
    for case, _, f1 in CASES:
        found = sorted(
            {(br.named(b), round(b.value, 6)) for br in branches[case] for b in br.bifurcations},
            key=lambda kv: kv[1],
        )
        covered, total, missed = stable_coverage(branches[case], poly.by_case[case])
        cont_lines.append(
            f"- f1 = {f1}: "
            + (", ".join(f"{k} at λ = {v:.6f}" for k, v in found) or "no bifurcation on [0, 1]")
            + f"; {covered} of {total} periodic brute-force points lie on a stable continued "
            "branch" + (f" (not: λ = {', '.join(f'{m:g}' for m in missed[:6])})" if missed else "")
        )
    light = systems["light"]
    lines = [
        "# Reference study: reproduction report",
        "",
        f"Made by `gearsym reproduce{' --quick' if quick else ''}` in {elapsed:.0f} s "
        f"({'quick' if quick else 'full'} resolution: {res.points} values of λ in [0, 1], "
        f"{res.transient} transient + {res.periods} sampled forcing periods per point, then "
        "each verdict continued from where the run ended until it is settled (3,000 periods "
        f"at most; 8,000 for border runs and for every run a claim rests on); integrator "
        f"{method}, rtol 1e-8). Model hashes: light `{light.model_hash[:12]}`, heavy "
        f"`{systems['heavy'].model_hash[:12]}`, dead zone "
        f"`{dead.files['model_hash'][:12]}`. Result store (each sweep, run, map and its "
        f"figures kept in the model cache under the hash of the code and its inputs): "
        f"{STORED_MARK} (`gearsym reproduce --fresh` computes every one again).",
        "",
        "Nothing is tuned toward the study. The values it leaves open (flywheel, half "
        "backlash, transmission error, pinion layout, stiffness harmonics, sign of f2) are "
        "those of the shipped scenes, listed in the model check below. Initial state: "
        "each mesh pressed into contact by its load, at rest; sweeps continue each point "
        "from the previous one's final state, forward and backward in λ.",
        "",
        "## Findings of the study beside the toolkit's",
        "",
        "Each finding is tested on the study's 7th-order polynomial g(x) and on the exact "
        "dead zone it approximates (scene `reference-dead-zone`, f1 set per load), with the "
        "same runs. A motion label is the attractor's verdict on its evidence "
        "(`docs/analysis.md`, Verdicts); a claim that agrees names the runs it rests on and "
        "how many forcing periods they were run.",
        "",
        *rows,
        "",
        "A verdict of **differs** is reported as found. With the open values chosen here the",
        "model can settle on other attractors than the study's; the forward/backward rows show",
        "where more than one attractor coexists.",
        "",
        "## Continuation of the periodic orbits",
        "",
        "Pseudo-arclength continuation of each periodic branch the forward sweep of the "
        "polynomial model visits, both ways in λ, with fold, period-doubling and "
        "Neimark-Sacker points located by bisection on test functions (see "
        "`docs/analysis.md`):",
        "",
        *cont_lines,
        "",
        "## Figures",
        "",
        FIGURES_MARK,
        "",
        "Data (parameter values, scales and model hash with every point) are in `data/`.",
        "",
    ]
    return "\n".join(lines)
