"""The report's model check: the model's numbers a gear engineer checks before trusting any
motion -- contact ratios, the backlash force g(x) beside the exact dead zone with its zeros,
the coupling kappa_ij and damping xi_ij, the static deflections with the polynomial's
spurious equilibrium and the loads at which it exists -- and every open value used.

Equations (non-dimensional, ``docs/derivation/reference_light.md``):
``x_i'' + 2 xi_ij x_j' + kappa_ij(tau) g(x_j) = f_i + e_i''``; at rest with the mean
stiffness ``kappa F = f`` gives each mesh's static force ``F_i`` and its deflection
``g(x_i) = F_i``.  The dead zone ``d(x) = x - sign(x)`` for ``|x| > 1``, 0 inside, has the
one deflection ``x = F + sign(F)``; the polynomial has every real root of ``g(x) = F``,
among them a spurious stable one on the unloaded side while ``0 < |F| < F*``
(``gearsym.derive.mesh.force_sign``).
"""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = ["model_check_section"]

POWERS = (1, 3, 5, 7)
SAMPLES = (0.0, 0.5, 0.770, 1.0, 1.5, 2.0, 3.0)  # x where g and the dead zone are shown


def _g(coef, x: float) -> float:
    return float(sum(a * x**k for a, k in zip(coef, POWERS, strict=True)))


def _dead(x: float) -> float:
    return 0.0 if abs(x) <= 1 else x - math.copysign(1.0, x)


@functools.lru_cache(maxsize=2)
def _model(scene: str):
    """The derived Model of a scene (SymPy, seconds): derived once per process for the
    model check and the sensitivity section's physical scales."""
    from gearsym.derive import derive_model, load_target, resolve_target

    return derive_model(load_target(resolve_target(scene)))


def _contact_rows(model) -> list[str]:
    rows = [
        "| mesh | coordinate | transverse ε_α | overlap ε_β | total ε_γ | half backlash b (µm) "
        "| mean stiffness k_m (N/m) | phase lag |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for me in model.scene.topology.meshes:
        pr = me.pair
        rows.append(
            f"| {me.id} | {me.coordinate} | {pr.transverse_contact_ratio:.4f} | "
            f"{pr.axial_contact_ratio:.4f} | {pr.total_contact_ratio:.4f} | "
            f"{me.half_backlash * 1e6:g} | {me.stiffness.mean:.4g} | "
            f"{me.phase:.4g} rad ({me.phase_source}) |"
        )
    return rows


def _force_rows(coef, zeros) -> list[str]:
    rows = [
        "| x (half backlashes) | " + " | ".join(f"{x:.3g}" for x in SAMPLES) + " |",
        "|---|" + "---|" * len(SAMPLES),
        "| g(x), the study's polynomial | "
        + " | ".join(f"{_g(coef, x):+.4f}" for x in SAMPLES)
        + " |",
        "| d(x), the exact dead zone | " + " | ".join(f"{_dead(x):+.4f}" for x in SAMPLES) + " |",
    ]
    rows.append("")
    rows.append(
        "g is odd (g(−x) = −g(x)). Its zeros within the valid range: "
        + ", ".join(f"{z:+.4f}" for z in zeros)
        + "; g < 0 on (0, "
        + f"{max(zeros):.4f}): inside the gap the polynomial pulls the mesh back instead of "
        "letting it separate. The dead zone is zero on the whole gap |x| ≤ 1."
    )
    return rows


def _coupling_rows(system) -> list[str]:
    names = [n for n in system.contract.parameters if n.startswith(("kappa_", "xi_"))]
    rows = ["| coefficient | value | meaning |", "|---|---|---|"]
    for n in names:
        kind, i, j = n.split("_")
        what = "mean stiffness" if kind == "kappa" else "damping"
        rows.append(
            f"| {kind}_{i}{j} | {system.parameter(n):.6g} | {what} of "
            + (f"g({j})" if kind == "kappa" else f"{j}'")
            + f" in the {i} equation |"
        )
    return rows


def _static_rows(systems: dict, loads: dict, coef, limit: float) -> list[str]:
    from gearsym.derive.mesh.force_sign import static_equilibria

    rows = [
        "| load | λ | mesh | static force F | dead zone x | polynomial: stable x | "
        "spurious stable x (unloaded side) |",
        "|---|---|---|---|---|---|---|",
    ]
    for case, f1 in loads.items():
        for lam in (0.1, 0.8):
            s = systems[case].with_values(**{"lambda": lam})
            F = np.asarray(s.module.static_mesh_force(s.p), float)
            for c, Fi in zip(s.coordinates, F, strict=True):
                eq = static_equilibria(coef, POWERS, float(Fi), s.module.VALID_RANGE)
                stable = [e.x for e in eq if e.stable and not e.spurious]
                spurious = [e.x for e in eq if e.spurious]
                rows.append(
                    f"| {case} (f1 = {f1}) | {lam:g} | {c} | {Fi:+.4f} | "
                    f"{Fi + math.copysign(1.0, Fi):+.4f} | "
                    + (", ".join(f"{x:+.4f}" for x in stable) or "none")
                    + " | "
                    + (", ".join(f"{x:+.4f}" for x in spurious) or "none")
                    + " |"
                )
    rows.append("")
    rows.append(
        f"The polynomial holds a spurious stable equilibrium while 0 < |F| < F* = {limit:.4f} "
        f"(a saddle-node at F*): for v, whose static force is about −λ·f1, at λ < "
        + " and ".join(f"{limit / f1:.3g} when f1 = {f1:g}" for f1 in loads.values())
        + "; for u (F about f1) at f1 < "
        + f"{limit:.4f}. A start near it can stay in the wrong well; the dead zone has none."
    )
    return rows


def _open_rows(model, system) -> list[str]:
    scene = model.scene
    rows = ["| value | used | where it comes from |", "|---|---|---|"]
    for me in model.scene.topology.meshes:
        c = me.coordinate
        amp = system.parameter(f"E_{c}_1") * me.half_backlash * 1e6
        rows.append(
            f"| transmission error, mesh {me.id} | {amp:g} µm first harmonic | "
            "the scene's topology (not stated by the study) |"
        )
        rows.append(f"| mesh phase, mesh {me.id} | {me.phase:.4g} rad | {me.phase_source} |")
    for g in scene.topology.gears:
        if g.attached_inertia:
            rows.append(
                f"| attached (flywheel) inertia, gear {g.id} | {g.attached_inertia:g} kg m² | "
                "the scene's topology |"
            )
    feats = scene.features
    rows.append(
        f"| stiffness harmonics | {feats.stiffness_harmonics} (scale 1×) | the study's "
        "3-harmonic series, from the potential-energy stiffness |"
    )
    rows.append(f"| load reading | {scene.load_reading} | the scene's `[open]` table |")
    rows.append(
        f"| damping normalisation | {scene.damping_normalisation} | the scene's `[open]` table |"
    )
    for k, v in scene.parameters.items():
        rows.append(f"| {k} | {v:g} | stated by the study (scene `[parameters]`) |")
    return rows


def model_check_section(systems: dict, loads: dict, scene: str = "reference-light") -> str:
    """Markdown: the model check (see the module text).

    Parameters
    ----------
    systems : dict
        case -> System of the study's polynomial model (``light``, ``heavy``).
    loads : dict
        case -> f1.
    scene : str
        The scene whose derivation gives the geometry and the open values.
    """
    from gearsym.derive.mesh.force_sign import polynomial_sign, spurious_load_limit

    model = _model(scene)
    light = systems["light"]
    coef = [light.parameter(k) for k in ("g1", "g3", "g5", "g7")]
    valid = light.module.VALID_RANGE
    zeros = polynomial_sign(coef, POWERS, valid).zeros
    limit = spurious_load_limit(coef, POWERS, valid)
    w = ["## Model check\n"]
    w.append(
        "What the model is, before what it does (from the derivation, "
        f"`docs/derivation/{scene.replace('-', '_')}.md`).\n"
    )
    w.append("### Contact ratios and meshes (ISO 21771)\n")
    w += [*_contact_rows(model), ""]
    w.append("### The backlash force beside the exact dead zone (`backlash.png`)\n")
    w += [*_force_rows(coef, zeros), ""]
    w.append("### Coupling and damping of the two meshes\n")
    w += [*_coupling_rows(light), ""]
    w.append("### Static deflections and the polynomial's spurious equilibrium\n")
    w += [*_static_rows(systems, loads, coef, limit), ""]
    w.append("### Every open value used\n")
    w.append(
        "The values the study leaves open, as the shipped scenes set them (the sensitivity "
        "section maps each over a spread), and the parameters it states.\n"
    )
    w += [*_open_rows(model, light), ""]
    return "\n".join(w)
