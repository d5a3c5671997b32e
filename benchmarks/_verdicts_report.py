"""The verdict benchmark's page (``docs/verdicts.md``): the maps, the confusion table,
the cost, and every wrong, undetermined or unresolved cell with both verdicts' evidence.

Written for ``verdicts.py``; reads only its summary and cells (plain data).
"""

from __future__ import annotations

from gearsym.benchmarks._verdicts_reference import K_CHAOS, QP_BAND, REPEAT

__all__ = ["default_label", "markdown"]


def default_label(verdict: dict) -> str:
    """A default verdict's label (``undetermined`` when it has no motion)."""
    return verdict.get("motion") or "undetermined"


def _order(label: str) -> tuple:
    if label.startswith("period-"):
        return (0, int(label.split("-")[1]))
    rank = ("quasi-periodic", "chaotic", "divergent", "undetermined", "unresolved")
    return (1, rank.index(label) if label in rank else len(rank))


def _evidence(ref: dict) -> str:
    """The reference's evidence in one line."""
    parts = []
    per = ref.get("periodic")
    if per and per.get("ok"):
        mu = per["shooting"]["largest_multiplier"]
        conv = ", converging" if per["converging"] else ""
        parts.append(f"repeats after {per['n']} (gap {per['repeat_gap']:.1e}{conv}), |μ| {mu:.4f}")
        parts.append(f"settled by period {ref.get('settled_by_period')}")
    if "exponent" in ref:
        e = ref["exponent"]
        parts.append(f"λ {e['lambda']:.2e} ± {e['uncertainty']:.1e}")
    if "zero_one" in ref:
        parts.append(f"K {ref['zero_one']['K']:.2f}")
    if "curve" in ref:
        parts.append(f"curve {ref['curve']['agreeing']:.2f}")
    if "why" in ref:
        parts.append(ref["why"])
    return "; ".join(parts)


def _default_evidence(d: dict) -> str:
    """The default verdict's evidence in one line (its reason when undetermined)."""
    if d.get("why"):
        return d["why"]
    parts = []
    if d.get("largest_multiplier") is not None:
        conv = ", converging" if d.get("converging") else ""
        parts.append(f"|μ| {d['largest_multiplier']:.4f}{conv}")
    if d.get("exponent_interval") is not None:
        lo, hi = d["exponent_interval"]
        parts.append(f"λ in [{lo:.2e}, {hi:.2e}]")
    if d.get("zero_one_K") is not None:
        parts.append(f"K {d['zero_one_K']:.2f}")
    if d.get("rotation_number") is not None:
        parts.append(f"ρ {d['rotation_number']:.4f}")
    return "; ".join(parts)


def markdown(summary: dict, cells: list[dict], command: str, wall: float) -> str:
    """The page: ``summary`` from ``verdicts.summarise`` with its ``maps`` (name -> lambda
    values, f1 values, why, candidates, cells, seconds) and ``cost``; ``cells`` the
    judged cells; ``wall`` seconds."""
    s = summary
    refs = sorted(s["confusion"], key=_order)
    cols = sorted(
        {k for row in s["confusion"].values() for k in row} | {"undetermined"}, key=_order
    )
    lines = [
        "# Verdict benchmark: map verdicts against 10,000-period reference runs",
        "",
        f"Written by `{command}` in {wall / 60:.1f} min (issue 27, Floors), on the engine "
        f"(`solver/`) of commit {s['engine']}. "
        "Maps: λ by f1 (0.1 light, 0.5 heavy load), forward and backward starts, "
        "`regime_map`'s default settings (300 + 100 periods, exponent over 200, verdict "
        "budget 3,000 periods), one per row of the table below (the last five chosen by a "
        "coarse scan over the sensitivity study's open values, see `MAPS` in "
        f"`benchmarks/verdicts.py`). Cells: {s['cells']} attractors of the "
        f"maps, {s['border_cells']} on borders (labels differ from a neighbour's, or "
        "coexisting attractors with different labels), the rest spread over the interiors. "
        "Reference: a 10,000-period run from the cell's start state (DOP853, rtol 1e-10), "
        "its last 5,000 periods classified by the benchmark's own code "
        f"(`benchmarks/_verdicts_reference.py`: repetition within {REPEAT:g} of the extent "
        "and `shoot` with |μ| < 1 at the minimal period; chaos: λ − U > 0 over the tail "
        f"and its own 0–1 test K ≥ {K_CHAOS}; a torus: |λ| + U ≤ {QP_BAND:g} and a closed "
        "curve the map rotates).",
        "",
        f"**Wrong labels: {s['wrong']}** (floor: 0). **Undetermined: {s['undetermined']} of "
        f"{s['cells']} = {100 * s['undetermined_share']:.1f} %** (floor: at most 10 %). "
        f"Reference unresolved (not counted): {s['unresolved_references']}.",
        "",
        "| map | λ | f1 | why | candidates | cells | map run (s) |",
        "|---|---|---|---|---:|---:|---:|",
    ]
    for name, m in s["maps"].items():
        lam = m["lambda"]
        lines.append(
            f"| {name} | {lam[0]:g} to {lam[-1]:g} in {len(lam)} | "
            f"{', '.join(f'{v:g}' for v in m['f1'])} | {m['why']} | {m['candidates']} | "
            f"{m['cells']} | {m['seconds']:.0f} |"
        )
    lines += [
        "",
        "## Confusion table (rows: reference, columns: default verdict)",
        "",
        "| reference \\ default | " + " | ".join(cols) + " |",
        "|---|" + "---:|" * len(cols),
    ]
    for r in refs:
        row = s["confusion"][r]
        lines.append(f"| {r} | " + " | ".join(str(row.get(k, "")) for k in cols) + " |")
    lines += ["", "Median periods run by the default verdict, per label: "]
    lines[-1] += ", ".join(f"{k} {v:.0f}" for k, v in s["median_periods_run"].items()) + "."
    cost = s["cost"]
    lines += [
        "",
        f"Cost: maps {cost['maps_seconds']:.0f} s, reference runs {cost['reference_seconds']:.0f} "
        f"s of worker time (median {cost['reference_median_seconds']:.1f} s, longest "
        f"{cost['reference_max_seconds']:.0f} s a cell), {cost['workers']} workers, "
        f"{wall / 60:.1f} min wall.",
    ]
    cand = s["candidates"]
    counts = ", ".join(
        f"{k} {v}" for k, v in sorted(cand["labels"].items(), key=lambda kv: _order(kv[0]))
    )
    lines += [
        "",
        f"Default labels of all {cand['count']} candidate attractors of the maps (the cells "
        f"above are {s['cells']} of them): {counts}.",
    ]
    listed = [c for c in cells if c["wrong"] or default_label(c["default"]) == "undetermined"]
    listed += [c for c in cells if c["reference"]["label"] == "unresolved" and c not in listed]
    lines += [
        "",
        "## Wrong, undetermined and unresolved cells",
        "",
        "| map | λ | f1 | start | default (periods) | default's evidence | reference | "
        "reference's evidence |",
        "|---|---:|---:|---|---|---|---|---|",
    ]
    for c in listed:
        d = c["default"]
        mark = "**wrong** " if c["wrong"] else ""
        # a literal bar inside a table cell is escaped
        why, ref_why = (
            e.replace("|", "\\|") for e in (_default_evidence(d), _evidence(c["reference"]))
        )
        lines.append(
            f"| {c['map']} | {c['lambda']:g} | {c['f1']:g} | {c['start']} | {mark}"
            f"{default_label(d)} ({d.get('periods_run')}) | {why} | {c['reference']['label']} | "
            f"{ref_why} |"
        )
    if not listed:
        lines.append("| (none) | | | | | | | |")
    undetermined = cand["undetermined"]
    if undetermined:
        lines += [
            "",
            f"## Undetermined candidates ({len(undetermined)}; no reference run unless a cell)",
            "",
            "| map | λ | f1 | start | why |",
            "|---|---:|---:|---|---|",
        ]
        for c in undetermined[:40]:
            why = (c["why"] or "").replace("|", "\\|")
            lines.append(f"| {c['map']} | {c['lambda']:g} | {c['f1']:g} | {c['start']} | {why} |")
        if len(undetermined) > 40:
            lines.append(f"| ({len(undetermined) - 40} more in `verdicts.json`) | | | | |")
    lines += ["", "Every cell, its start state and both verdicts' evidence: `verdicts.json`."]
    return "\n".join(lines) + "\n"
