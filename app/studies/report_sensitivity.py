"""The report's sensitivity section: the open values against the study's findings."""

from __future__ import annotations

import math

__all__ = ["sensitivity_section", "third_order_lines"]

FACE_WIDTH_MM = 50.0  # the study's face width (every mesh of the reference scenes)


def _line(peaks, f: float, tol: float = 0.01) -> float:
    """The amplitude of the spectral line at ``f`` (0 when there is none)."""
    return max((p["amplitude"] for p in peaks if abs(p["frequency"] - f) < tol), default=0.0)


def third_order_lines(peaks, omega: float) -> dict:
    """A period-3 orbit's lines at multiples of omega/3 against those at multiples of omega.

    ``peaks``: spectral peaks (``frequency`` in the units of ``omega``, ``amplitude``).
    Returns the largest amplitude at k omega / 3 (k not a multiple of 3, k <= 18), the
    amplitudes at omega and 2 omega, and how many times the first is below each
    (None when the orbit has no third-order line)."""
    third = max(_line(peaks, k * omega / 3) for k in range(1, 19) if k % 3)
    base = {m: _line(peaks, m * omega) for m in (1, 2)}
    below = {m: (a / third if third > 0 else None) for m, a in base.items()}
    return {"third": third, "base": base, "below": below}


def _period3_note(points, omega: float = 0.5) -> str:
    """What the study's spectrum at f1 = 0.5 can and cannot tell about its 'period-3',
    measured on every period-3 orbit the toolkit found at the operating points."""
    text = (
        "The study calls the motion at f1 = 0.5 period-3 and shows spectra with peaks at "
        "0.5, 1.0 and 1.5 only, all multiples of the forcing frequency ω̄ = 0.5. A period-3 "
        "orbit repeats every three forcing periods, so it has lines at multiples of "
        "ω̄/3 ≈ 0.167 as well (0.167, 0.333, 0.667, …), but nothing makes them large: "
        "weak third-order lines are invisible on a linear amplitude axis beside the lines "
        "at 0.5 and 1.0. "
    )
    found = []
    for (case, value), result in sorted(points.items()):
        v = getattr(result, "verdict", None)
        if v is None or v.period != 3:
            continue
        peaks = result.spectra["u"].peaks() if result.spectra else []
        lines = third_order_lines(peaks, omega)
        if lines["below"][1] is None:
            found.append(f"{case} load, λ = {value:g}: period-3 with no line off the multiples")
            continue
        found.append(
            f"{case} load, λ = {value:g}: the largest third-order line of u is "
            f"{lines['third']:.2e}, {lines['below'][1]:.0f} times below the line at 0.5 and "
            f"{lines['below'][2]:.0f} times below the line at 1.0"
        )
    if not found:
        return text + (
            "No period-3 orbit was found at the operating points, so the toolkit cannot "
            "say how strong such lines would be here. The study's spectrum alone tells that "
            "the motion is dominated by the forcing and its harmonics; it cannot tell "
            "period-1 from period-3."
        )
    return text + (
        "On the toolkit's period-3 orbits (confirmed by the shooting check): "
        + "; ".join(found)
        + ". A spectrum like the study's is therefore what such an orbit gives: it does not "
        "contradict the period-3 label, and it cannot confirm it either; only the Poincaré "
        "points (repeating every third period) or a logarithmic spectrum can."
    )


def _failed(r) -> str:
    return f"; {r.failed} runs failed (left the valid range)" if r.failed else ""


def _num(v) -> str:
    return v if isinstance(v, str) else f"{v:g}"


def _motion_order(motion: str):
    """period-1, period-2, ..., period-12, then the rest in alphabetical order."""
    if motion.startswith("period-") and motion[7:].isdigit():
        return (0, int(motion[7:]), "")
    return (1, 0, motion)


def _unit(r) -> str:
    return {"text": "", "model": " (model, stated)"}.get(r.unit, f" ({r.unit})")


READING_NAMES = {"q-braking": "q braking", "both-driving": "both driving"}


def _critical(c: dict) -> str:
    parts = []
    for v, lam in c.items():
        parts.append(f"{_num(v)}: " + ("none" if math.isnan(lam) else f"{lam:g}"))
    return "; ".join(parts)


def sensitivity_section(rows, scales: dict, loads: dict, points: dict) -> str:
    """Markdown: the table, the findings no value reproduces, the study's own
    contradiction, and the physical scales."""
    w = ["## Sensitivity to the values the study leaves open\n"]
    w.append(
        "For each open value, a regime map over λ (0 to 1) by the value, from three initial "
        "states per point, so coexisting attractors show; every attractor found counts, not "
        "only the "
        "dominant one. The three starts are the forward and backward chains in λ (each "
        "from the previous λ's end state, the first from the loaded rest state) and one "
        "random state in the regime map's default box (seed 0). The built-in scenes keep "
        "their stated values (marked *); the values "
        "tried are a fixed spread round them, set before any run. Every row is mapped in both "
        "readings of the loads the study allows (`load_reading`): pinion q braking (the "
        "built-in scenes') and both pinions driving with the q-g coordinate measured the "
        "other way. Text values (the damping normalisation) are mapped over their index and "
        "labelled by name. The backlash row is not an open value (the study states its "
        "7th-order fit) but sets the fit beside the exact dead zone it approximates "
        "(scene `reference-dead-zone`), which has no valid range to leave.\n"
    )
    w.append(
        "Critical λ: the smallest λ past which every attractor of v is periodic "
        "(0: periodic everywhere; none: not periodic at λ = 1). A finding counts as "
        "reproduced by a value when at least one attractor at that value shows it inside the "
        "study's λ range: u quasi-periodic for λ ≤ 0.57 (light) or ≤ 0.13 (heavy); v chaotic "
        "for λ ≤ 0.3 (the study's 'low λ'); u period-3 (exactly, the minimal period) for "
        "λ ≥ 0.13 (heavy only: not a claim of the study at light load).\n"
    )
    names = list(dict.fromkeys(n for r in rows for n in r.reproduced))
    w.append(
        "| load | reading | open value | values tried | motion types found | "
        "critical λ of v | " + " | ".join(f"reproduces: {n}" for n in names) + " |"
    )
    w.append("|---|---|---|---|---|---|" + "---|" * len(names))
    for r in rows:
        tried = ", ".join(_num(v) + ("*" if v == r.stated else "") for v in r.values)
        types = sorted({m for ms in r.motions.values() for m in ms}, key=_motion_order)
        cells = []
        for n in names:
            if n not in r.reproduced:
                cells.append("not a claim at this load")
            elif r.reproduced[n]:
                cells.append("yes, at " + ", ".join(_num(v) for v in r.reproduced[n]))
            else:
                cells.append("no")
        w.append(
            f"| {r.case} (f1 = {loads[r.case]}) | {READING_NAMES.get(r.reading, r.reading)} | "
            f"`{r.key}`{_unit(r)} | {tried} | "
            f"{', '.join(types) or '—'}{_failed(r)} | {_critical(r.critical)} | "
            + " | ".join(cells)
            + " |"
        )
    w.append("")
    for case in dict.fromkeys(r.case for r in rows):
        here = [r for r in rows if r.case == case]
        for n in here[0].reproduced:
            found = [
                f"`{r.key}` = {', '.join(_num(v) for v in r.reproduced[n])} "
                f"({READING_NAMES.get(r.reading, r.reading)})"
                for r in here
                if r.reproduced[n]
            ]
            held = [r.carriers[n] for r in here if r.reproduced[n] and n in r.carriers]
            runs = sum(k for k, _ in held)
            how = f", carried by {runs} attractor runs" if held else ""
            if held and any(t != "no run" for _, t in held):
                how += " (" + "; ".join(dict.fromkeys(t for _, t in held if t != "no run")) + ")"
            if found:
                w.append(f"- {case} load, *{n}*: reproduced with {'; '.join(found)}{how}.")
            else:
                w.append(f"- {case} load, *{n}*: **no value tried reproduces it.**")
    w.append("")
    w.append(_period3_note(points) + "\n")
    w.append("### Physical scales\n")
    w.append(
        "The non-dimensional mesh force f times the force scale k_m·b (mean mesh stiffness "
        "times half backlash, as in the derivation) is newtons along the line of action; u "
        "and v times b are the dynamic transmission error. Face width "
        f"{FACE_WIDTH_MM:g} mm.\n"
    )
    forces = " | ".join(f"static force, f1 = {f} (N)" for f in loads.values())
    w.append(f"| mesh | k_m (N/m) | b (µm) | force scale (N) | per face width (N/mm) | {forces} |")
    w.append("|---|---|---|---|---|" + "---|" * len(loads))
    for c, s in scales.items():
        w.append(
            f"| {c} | {s['k_m_N_per_m']:.4g} | {s['b_um']:g} | {s['force_N']:.4g} | "
            f"{s['force_N'] / FACE_WIDTH_MM:.4g} | "
            + " | ".join(f"{f * s['force_N']:.4g}" for f in loads.values())
            + " |"
        )
    w.append("")
    w.append(
        "Figures: `sensitivity/<load>-<reading>-<open value>-*.png`, the regime maps (motion "
        "of u and "
        "v, largest Lyapunov exponent, attractor count, meshing) over λ by each value.\n"
    )
    return "\n".join(w)
