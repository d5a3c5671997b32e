"""How the CLI prints a verdict and its evidence (``simulate``, the operating points)."""

from __future__ import annotations

__all__ = ["verdict_lines"]


def verdict_lines(v) -> list[str]:
    """The attractor's verdict and the evidence it rests on, as the CLI prints it."""
    if v is None:
        return []
    ev = v.evidence
    lines = [f"  attractor: {v.motion} (verdict after {v.periods_run} periods)"]
    if "orbit" in ev:
        o = ev["orbit"]
        lines.append(
            f"      shooting check: period-{o['minimal_period']} orbit, residual "
            f"{o['residual']:.1e}, largest multiplier {o['largest_multiplier']:.4f}"
            + ("; the run was still converging to it" if ev.get("converging") else "")
            + (f"; neutral, {ev['neutral']}" if "neutral" in ev else "")
        )
    if "transient_chaos" in ev:
        lines.append("      " + ev["transient_chaos"]["text"])
    for w in (ev.get("windows") or [])[-2:]:
        parts = [f"periods {w['window'][0]}-{w['window'][1]}: {w['label']}"]
        if "exponent" in w:
            e = w["exponent"]
            lo, hi = e["interval"]
            parts.append(f"exponent {e['exponent']:.5f} per tau in [{lo:.5f}, {hi:.5f}]")
        if "zero_one" in w:
            parts.append(f"0-1 test K = {w['zero_one']['K']:.2f}")
        if "interval" in w.get("two_trajectory", {}):
            lo, hi = w["two_trajectory"]["interval"]
            parts.append(f"two-trajectory exponent in [{lo:.5f}, {hi:.5f}]")
        if "rotation_number" in w:
            parts.append(f"rotation number {w['rotation_number']:.5f}")
        lines.append("      " + ", ".join(parts))
    if "why" in ev:
        lines.append(f"      why undetermined: {ev['why']}")
    return lines
