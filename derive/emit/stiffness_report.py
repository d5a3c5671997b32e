"""Mesh stiffness reports: the numbers behind `gearsym stiffness` and ``docs/stiffness.md``.

For each mesh of a topology: the pair's geometry, the sliced potential-energy stiffness
(``derive/mesh/pem.py``) with its Fourier fit and convergence in the number of slices, the
ISO 6336-1 method B figures (``derive/mesh/iso6336.py``) and their ratio to the mean, the
contact-line model's harmonic ratios for comparison, the layout phase and the transmission
error.
"""

from __future__ import annotations

import hashlib
import math
import warnings

import numpy as np

from ..escape import markdown
from ..input.topology import Mesh, Topology
from ..mesh.iso6336 import iso_stiffness
from ..mesh.pem import PemResult, foundation_parameters, pair_compliance, pem_stiffness
from ..mesh.stiffness import contact_line_stiffness

__all__ = ["CONVERGENCE_SLICES", "mesh_report", "plot_mesh", "stiffness_page"]

CONVERGENCE_SLICES = (10, 50, 200, 1000)


def _pem(topology: Topology, mesh: Mesh, slices: int, harmonics: int) -> PemResult:
    g1, g2 = topology.gear(mesh.driver), topology.gear(mesh.driven)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # reported once, in the report's warnings
        return pem_stiffness(
            mesh.pair,
            [(g.material.youngs_modulus, g.material.poisson_ratio) for g in (g1, g2)],
            [g1.bore_radius, g2.bore_radius],
            slices=slices,
            harmonics=harmonics,
            names=(g1.id, g2.id),
        )


def mesh_report(
    topology: Topology,
    mesh: Mesh,
    *,
    slices: int = 200,
    harmonics: int = 3,
    convergence: tuple[int, ...] = CONVERGENCE_SLICES,
) -> tuple[dict, PemResult]:
    """JSON-ready figures of one mesh, and the :class:`PemResult` behind them."""
    pair = mesh.pair
    g1, g2 = topology.gear(mesh.driver), topology.gear(mesh.driven)
    res = _pem(topology, mesh, slices, harmonics)
    iso = iso_stiffness(pair, youngs=(g1.material.youngs_modulus, g2.material.youngs_modulus))
    line = contact_line_stiffness(
        1.0, pair.transverse_contact_ratio, pair.axial_contact_ratio, harmonics
    )
    (sap1, eap1), (sap2, eap2) = pair.active_radii
    gears = {}
    for gear, sap, eap in ((g1, sap1, eap1), (g2, sap2, eap2)):
        geo = gear.geometry
        hf, theta = foundation_parameters(geo, gear.bore_radius)
        gears[gear.id] = {
            "teeth": gear.teeth,
            "transverse_module_mm": geo.transverse_module * 1e3,
            "transverse_pressure_angle_deg": math.degrees(geo.transverse_pressure_angle),
            "base_helix_angle_deg": math.degrees(geo.base_helix_angle),
            "pitch_radius_mm": geo.pitch_radius * 1e3,
            "base_radius_mm": geo.base_radius * 1e3,
            "root_radius_mm": geo.root_radius * 1e3,
            "form_radius_mm": geo.form_radius * 1e3,
            "tip_radius_mm": geo.tip_radius * 1e3,
            "start_of_active_profile_mm": sap * 1e3,
            "end_of_active_profile_mm": eap * 1e3,
            "bore_radius_mm": gear.bore_radius * 1e3,
            "foundation_hf": hf,
            "foundation_theta_f_rad": theta,
        }
    pitch = pair.driver.base_radius * math.tan(pair.working_pressure_angle)
    at_pitch = pair_compliance(
        pair,
        [(g.material.youngs_modulus, g.material.poisson_ratio) for g in (g1, g2)],
        [g1.bore_radius, g2.bore_radius],
        np.array([pitch]),
    )
    comp = {k: float(v[0]) for k, v in at_pitch.items()}
    total = comp.pop("total")
    rows = []
    for n in convergence:
        r = _pem(topology, mesh, n, harmonics)
        rows.append(
            {
                "slices": n,
                "mean_N_per_m": r.mean,
                "ratios": list(r.ratios()),
                "residual": r.residual,
            }
        )
    report = {
        "mesh": mesh.id,
        "driver": mesh.driver,
        "driven": mesh.driven,
        "gears": gears,
        "face_width_mm": pair.face_width * 1e3,
        "working_pressure_angle_deg": math.degrees(pair.working_pressure_angle),
        "centre_distance_mm": pair.centre_distance * 1e3,
        "path_of_contact_mm": pair.path_of_contact * 1e3,
        "transverse_base_pitch_mm": pair.transverse_base_pitch * 1e3,
        "contact_ratio": {
            "transverse": pair.transverse_contact_ratio,
            "axial": pair.axial_contact_ratio,
            "total": pair.total_contact_ratio,
        },
        "pem": {
            "slices": slices,
            "samples": len(res.k),
            "mean_N_per_m": res.mean,
            "mean_transverse_N_per_m": res.transverse_mean,
            "min_N_per_m": float(res.k.min()),
            "max_N_per_m": float(res.k.max()),
            "harmonics": [
                {
                    "order": h,
                    "cos_N_per_m": c,
                    "sin_N_per_m": s,
                    "ratio": math.hypot(c, s) / res.mean,
                }
                for h, (c, s) in enumerate(zip(res.cos, res.sin, strict=True), start=1)
            ],
            "fit_residual_rms": res.residual,
            "fit_residual_max": float(np.max(np.abs(res.k - res.fit(res.tau))) / res.mean),
            "compliance_shares_at_pitch_point": {k: v / total for k, v in comp.items()},
            "single_pair_max_N_per_m": float(np.max(res.single_pair)),
        },
        "convergence": rows,
        "contact_line_ratios": [
            math.hypot(c, s) for c, s in zip(*line.normalised(harmonics), strict=True)
        ],
        "iso6336": {
            "virtual_teeth": list(iso.virtual_teeth),
            "q_prime": iso.q_prime,
            "c_th": iso.c_th,
            "C_M": iso.c_m,
            "C_R": iso.c_r,
            "C_B": iso.c_b,
            "c_prime": iso.c_prime,
            "c_gamma_alpha": iso.c_gamma_alpha,
            "c_gamma_beta": iso.c_gamma_beta,
            "k_from_c_gamma_alpha_N_per_m": iso.mesh_stiffness,
            "unit": "N/(mm um)",
        },
        "pem_over_iso": res.mean / iso.mesh_stiffness,
        "phase": {"rad": mesh.phase, "source": mesh.phase_source},
        "transmission_error": {
            "amplitude_um": [a * 1e6 for a in mesh.transmission_error.amplitudes],
            "phase_deg": [math.degrees(p) for p in mesh.transmission_error.phases],
        },
        "stiffness_in_model": mesh.stiffness.source,
        "warnings": list(res.warnings),
    }
    return report, res


def plot_mesh(res: PemResult, path, title: str = "") -> None:
    """k(t) over two mesh periods with its harmonic fit, and one tooth pair's stiffness."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    tau = np.concatenate([res.tau, res.tau + 1.0])
    k = np.concatenate([res.k, res.k])
    ht, hk = res.history()
    fig, ax = plt.subplots(figsize=(7.5, 4.0))
    ax.plot(tau, k / 1e9, lw=1.2, label=f"sliced PEM, N = {res.slices}")
    fine = np.linspace(0.0, 2.0, 1001)
    ax.plot(
        fine,
        res.fit(fine) / 1e9,
        "--",
        lw=1.2,
        label=f"{len(res.cos)}-harmonic fit (RMS misfit {100 * res.residual:.2f} %)",
    )
    ax.plot(ht, hk / 1e9, ":", lw=1.4, label="one tooth pair, entry to exit")
    ax.axhline(res.mean / 1e9, color="0.6", lw=0.8)
    ax.set_xlabel("time / mesh period")
    ax.set_ylabel("mesh stiffness k (10$^9$ N/m)")
    ax.set_xlim(0.0, 2.0 if ht[-1] < 2.0 else float(math.ceil(ht[-1])))
    ax.set_ylim(0.0, 1.25 * float(k.max()) / 1e9)
    ax.legend(loc="upper right", fontsize=8)
    if title:
        ax.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110, metadata={"Software": None})
    plt.close(fig)


def _f(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}"


def stiffness_page(topology: Topology, command: str, figure: str | None) -> str:
    """``docs/stiffness.md`` for ``topology`` (the reference DI-SO stage)."""
    reports = [mesh_report(topology, m) for m in topology.meshes]
    first, res = reports[0]
    data_hash = hashlib.sha256(
        np.round(np.concatenate([res.k, res.history()[1]]) / res.mean, 9).tobytes()
    ).hexdigest()[:16]
    g1, g2 = first["gears"].values()
    rows = first["convergence"]
    means = [r["mean_N_per_m"] for r in rows]
    mean_spread = (max(means) - min(means)) / means[-1]
    at = next((r for r in rows if r["slices"] == first["pem"]["slices"]), rows[-1])
    ratio_change = max(
        abs(a - b) / b for a, b in zip(at["ratios"], rows[-1]["ratios"], strict=True)
    )
    out = [
        "# Mesh stiffness from gear geometry",
        "",
        f"Generated by `{markdown(command, code=True)}`; do not edit (`gearsym derive --check` "
        "compares it with a "
        "fresh regeneration).",
        "",
        "The non-dimensional stiffness coefficients κij(τ) of the equations of motion come from "
        "the teeth, module and angles alone: a time-varying mesh stiffness k(t) by the "
        "potential-energy method (PEM) on a sliced helical pair, fitted by a Fourier series, "
        "with ISO 6336-1 method B as an independent check of its mean. Code: "
        "`derive/mesh/geometry.py`, `derive/mesh/pem.py`, `derive/mesh/iso6336.py`; command: "
        "`gearsym stiffness diso [--slices N] [--harmonics H] [--json] [--plot FILE]`.",
        "",
        "## Formulas",
        "",
        "**Geometry** (ISO 21771:2007). m_t = m_n / cos β, tan α_t = tan α_n / cos β, "
        "sin β_b = sin β cos α_n, r = z m_t / 2, r_b = r cos α_t, r_a = r + (1 + x) m_n, "
        "r_f = r − (h_fP* − x) m_n. The involute starts at the form circle, where the basic "
        "rack's straight flank ends: r_Ff² = r_b² + (r sin α_t − h_F / sin α_t)² with "
        "h_F = (h_fP* − ρ_fP*(1 − sin α_n) − x) m_n; a negative root means undercut. The path "
        "of contact runs from A, where the driven tip cuts the line of action, to E, the "
        "driver's tip: g_α = √(r_a1² − r_b1²) + √(r_a2² − r_b2²) − a_w sin α_wt; "
        "ε_α = g_α / p_bt, ε_β = b sin β / (π m_n). The start of active profile of each gear "
        "must lie on its involute (above its form circle), else the mating tip meets the fillet "
        "and the topology is refused.",
        "",
        "**One tooth** (a cantilever in the transverse plane). With the roll angle t of the "
        "contact point (its radius r_b √(1 + t²)), the force acts along the line of action at "
        "α_m = t − α_2 from the perpendicular to the tooth centreline, α_2 = (π/2 + 2x tan α_n)/z "
        "+ inv α_t being half the tooth angle at the base circle. Along the centreline y, with "
        "half thickness h(y), section area A = 2hL and moment of inertia I = (2h)³L/12, the "
        "energies of bending, shear and axial compression give (Yang and Lin 1987; Tian 2004)",
        "",
        "    1/k_b = ∫ [(y_c − y) cos α_m − h_c sin α_m]² / (E I) dy",
        "    1/k_s = ∫ 1.2 cos² α_m / (G A) dy,      1/k_a = ∫ sin² α_m / (E A) dy",
        "",
        "integrated in the involute roll angle τ from the root circle (or the base circle) to "
        "the contact point, where h = r_b[sin(α_2 − τ) + τ cos(α_2 − τ)], "
        "y = r_b[cos(α_2 − τ) − τ sin(α_2 − τ)], dy = r_b τ cos(α_2 − τ) dτ (48-point "
        "Gauss–Legendre). Both cases of the root: a root circle above the base circle clamps the "
        "involute at the root circle; one below it adds a straight-sided section of the base "
        "circle's thickness from the root to the base circle (Chen and Shao 2011), integrated in "
        "closed form.",
        "",
        '**Fillet foundation** (Sainsot, Velex and Duverger 2004, "Contribution of gear body '
        'to tooth deflections — a new bidimensional analytical formula"): '
        "1/k_f = cos² α_m / (E L) [L*(u_f/S_f)² + M*(u_f/S_f) + P*(1 + Q* tan² α_m)], "
        "X* = A/θ_f² + B h_f² + C h_f/θ_f + D/θ_f + E h_f + F with the paper's coefficient table "
        "(`derive/data/sainsot2004.toml`, checked by the tests), h_f = r_f / r_int, θ_f the half "
        "tooth angle at the root circle, S_f = 2 r_f θ_f, u_f the distance along the centreline "
        "from the root circle to where the line of action crosses it. Outside the fitted range "
        "1.4 ≤ h_f ≤ 7, 0.01 ≤ θ_f ≤ 0.12 rad the toolkit warns.",
        "",
        "**Contact** (Yang and Lin 1987): the linearised Hertzian compliance of a line contact, "
        "1/k_h = 2/(π L E*), 1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂ — for one material "
        "k_h = π E L / (4(1 − ν²)), independent of load and position.",
        "",
        "**One tooth pair**: 1/k = 1/k_h + Σ over both teeth (1/k_b + 1/k_s + 1/k_a + 1/k_f). "
        "All terms scale as 1/L.",
        "",
        "**Helical pair by slicing**: the face width is cut into N transverse slices of width "
        "b/N; slice z meets its tooth pair z tan β_b further back on the path of contact, so at "
        "time τ (mesh periods, from the entry of a pair at A on the front face) pair j touches "
        "slice z at s = s_A + (τ − j) p_bt − z tan β_b. All slices of all pairs in contact act in "
        "parallel. The sliced stiffness k_t along the transverse line of action becomes the "
        "stiffness along the normal line of action the equations use by k = k_t / cos² β_b.",
        "",
        "**Fourier fit**: k(t) = k_m + Σ_j [k_j1 cos(jω_e t) + k_j2 sin(jω_e t)] by least squares "
        "on 2048 uniform samples per mesh period (the discrete Fourier coefficients); the "
        "derivation takes k_j1/k_m, k_j2/k_m. The RMS misfit is reported: k(t) has corners "
        "(for spur gears, jumps) where a tooth pair enters or leaves, which a few harmonics "
        "cannot follow.",
        "",
        "**ISO 6336-1:2019 method B**: z_n = z / (cos² β_b cos β); "
        "q′ = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2 + C8 x1² + C9 x2²; "
        "c′_th = 1/q′; c′ = c′_th C_M C_R C_B cos β (C_M = 0.8; C_R = 1 for solid discs; "
        "C_B = mean over both gears of [1 + 0.5(1.2 − h_fP/m_n)][1 − 0.02(20° − α_Pn)]); "
        "c_γα = c′(0.75 ε_α + 0.25), c_γβ = 0.85 c_γα; the figure to compare is k = c_γα b.",
        "",
        "**Layout phase and transmission error**: a second pinion whose centre lies ψ further "
        "round the common gear sees each tooth z ψ/360° teeth later; the stiffness and "
        "transmission-error excitation of its mesh lag by 2πδ, δ the fractional part of "
        "z ψ/360°. The composite transmission error of each mesh is a sum of harmonics of the "
        "mesh frequency with amplitude and phase, given in the topology.",
        "",
        "## Assumptions",
        "",
        "- Unmodified involute teeth (no tip relief or crowning), perfect alignment, no "
        "  manufacturing errors in the stiffness (they enter as transmission error).",
        "- Each slice is an independent spur tooth of the transverse profile (no coupling "
        "  between slices), loaded along the transverse line of action; the axial force "
        "  component is ignored.",
        "- The tooth is clamped at the root circle; the root fillet's own shape enters only "
        "  through the fillet-foundation term, which uses the root radius and angle.",
        "- The Hertzian term of a slice uses the slice width b/N; its contact line is "
        "  b/(N cos β_b) long, which would stiffen the contact by 1/cos β_b (1.4 % here) and "
        "  k_m by under 0.1 %.",
        "- Linear, load-independent Hertzian compliance; the mean stiffness is therefore the "
        "  same at every load (ISO's c′ is likewise for line loads of 100 N/mm or more).",
        "- Bore radius: each topology gives it (`bore_radius_mm`); the default is a third of "
        "  the root radius, h_f = 3, near the middle of the foundation formula's range.",
        f"- Here: bores {g1['bore_radius_mm']:.0f} mm (pinion) and "
        f"{g2['bore_radius_mm']:.0f} mm (gear), h_f = {g1['foundation_hf']:.2f} and "
        f"{g2['foundation_hf']:.2f}, θ_f = {g1['foundation_theta_f_rad']:.4f} and "
        f"{g2['foundation_theta_f_rad']:.4f} rad. The root circles lie above the base circles "
        f"({g1['root_radius_mm']:.3f} > {g1['base_radius_mm']:.3f} mm, "
        f"{g2['root_radius_mm']:.3f} > {g2['base_radius_mm']:.3f} mm).",
        "",
        f"## The reference DI-SO stage (`{topology.name}`)",
        "",
    ]
    out += [
        "| mesh | ε_α | ε_β | ε_γ | k_m PEM (N/m) | k = c_γα b ISO (N/m) | PEM / ISO | "
        "\\|k_1\\|/k_m | \\|k_2\\|/k_m | \\|k_3\\|/k_m | RMS misfit | phase lag (rad) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for rep, _ in reports:
        cr, h = rep["contact_ratio"], rep["pem"]["harmonics"]
        out.append(
            f"| {rep['mesh']} | {cr['transverse']:.3f} | {cr['axial']:.3f} | {cr['total']:.3f} | "
            f"{rep['pem']['mean_N_per_m']:.4e} | "
            f"{rep['iso6336']['k_from_c_gamma_alpha_N_per_m']:.4e} | {rep['pem_over_iso']:.3f} | "
            + " | ".join(f"{x['ratio']:.4f}" for x in h)
            + f" | {rep['pem']['fit_residual_rms']:.4f} | {rep['phase']['rad']:.4f} |"
        )
    iso = first["iso6336"]
    k_transverse = first["pem"]["mean_transverse_N_per_m"]
    out += [
        "",
        f"ISO 6336-1 method B for mesh {first['mesh']}: z_n = {iso['virtual_teeth'][0]:.3f} / "
        f"{iso['virtual_teeth'][1]:.3f}, q′ = {iso['q_prime']:.6f} mm µm/N, "
        f"c′_th = {iso['c_th']:.3f}, C_M = {iso['C_M']}, C_R = {iso['C_R']}, "
        f"C_B = {iso['C_B']:.4f}, c′ = {iso['c_prime']:.3f}, c_γα = {iso['c_gamma_alpha']:.3f}, "
        f"c_γβ = {iso['c_gamma_beta']:.3f} N/(mm µm). The table compares the PEM mean along "
        "the normal line of action (the stiffness the equations of motion use; ISO's c′ is "
        "likewise a stiffness normal to the flank per unit face width) with c_γα b; the PEM "
        f"mean along the transverse line of action, {k_transverse:.4e} N/m, is "
        f"{k_transverse / iso['k_from_c_gamma_alpha_N_per_m']:.3f} of it. k(t) ranges over "
        f"[{first['pem']['min_N_per_m']:.4e}, {first['pem']['max_N_per_m']:.4e}] N/m.",
        "",
        "Harmonics of k(t) (N/m) against the contact-line-length model (Maatar and Velex "
        "1996), which takes the stiffness per unit contact length as constant:",
        "",
        "| j | k_j1 | k_j2 | \\|k_j\\|/k_m PEM | \\|k_j\\|/k_m contact line |",
        "|---|---|---|---|---|",
    ]
    for h, cl in zip(first["pem"]["harmonics"], first["contact_line_ratios"], strict=True):
        out.append(
            f"| {h['order']} | {h['cos_N_per_m']:.5e} | {h['sin_N_per_m']:.5e} | "
            f"{h['ratio']:.5f} | {cl:.5f} |"
        )
    out += [
        "",
        "The PEM ratios lie below the contact-line ones: a tooth pair is stiffest mid-path and "
        "softer near the tips, so pairs take up and shed load more gradually than their contact "
        "length does.",
        "",
        "Shares of one tooth pair's compliance at the pitch point:",
        "",
        "| term | share |",
        "|---|---|",
    ]
    for k, v in first["pem"]["compliance_shares_at_pitch_point"].items():
        out.append(f"| {k.replace('_', ' ')} | {v:.3f} |")
    out += [
        "",
        "### Convergence in the number of slices",
        "",
        "The mean does not depend on N in the limit of continuous time (each slice's time "
        "average is the same integral over the path of contact); on 2048 samples per period it "
        f"moves by {mean_spread:.1e} relative over the table. The harmonics converge as the "
        "slices resolve the helix.",
        "",
        "| N | k_m (N/m) | \\|k_1\\|/k_m | \\|k_2\\|/k_m | \\|k_3\\|/k_m | RMS misfit |",
        "|---|---|---|---|---|---|",
    ]
    for row in first["convergence"]:
        out.append(
            f"| {row['slices']} | {row['mean_N_per_m']:.6e} | "
            + " | ".join(f"{r:.5f}" for r in row["ratios"])
            + f" | {row['residual']:.5f} |"
        )
    out += [
        "",
        f"The shipped topologies use N = {first['pem']['slices']}: its harmonic ratios differ "
        f"from N = {rows[-1]['slices']} by at most {ratio_change:.1e} relative.",
        "",
    ]
    if figure:
        out += [
            f"![k(t) of mesh {first['mesh']}]({figure})",
            "",
            f"Mesh {first['mesh']}: k(t) from the sliced PEM, its 3-harmonic fit, and one tooth "
            f"pair from entry to exit (figure data sha256 {data_hash}).",
            "",
        ]
    if any(rep["warnings"] for rep, _ in reports):
        out += ["## Warnings", ""] + [f"- {w}" for rep, _ in reports for w in rep["warnings"]]
        out.append("")
    return "\n".join(out)
