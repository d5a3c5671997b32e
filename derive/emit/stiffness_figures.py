"""The figures of one mesh's stiffness: the numbers behind `gearsym stiffness` and its plot.

For one mesh of a topology: the pair's geometry, the sliced potential-energy stiffness
(``derive/mesh/pem.py``) with its Fourier fit and convergence in the number of slices, the
ISO 6336-1 method B figures (``derive/mesh/iso6336.py``) and their ratio to the mean, the
contact-line model's harmonic ratios for comparison, the layout phase and the transmission
error.  ``stiffness_report.py`` writes them into ``docs/stiffness.md``.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ..input.reader import InputError
from ..input.topology import Mesh, Topology
from ..mesh.iso6336 import iso_stiffness
from ..mesh.pem import PemResult, foundation_parameters, pair_compliance, pem_stiffness
from ..mesh.stiffness import contact_line_stiffness

__all__ = ["CONVERGENCE_SLICES", "mesh_pem", "mesh_report", "plot_mesh"]

CONVERGENCE_SLICES = (10, 50, 200, 1000)


def mesh_pem(topology: Topology, mesh: Mesh, slices: int, harmonics: int) -> PemResult:
    """The sliced potential-energy stiffness of ``mesh`` (its warnings silenced: a report
    lists them once)."""
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
    """JSON-ready figures of one mesh, and the :class:`PemResult` behind them; an
    :class:`InputError` for an internal mesh (the sliced potential-energy method models
    external teeth only)."""
    pair = mesh.pair
    if pair.internal:
        raise InputError(
            topology.source,
            f"mesh '{mesh.id}'",
            "is internal (a pinion and ring): the potential-energy stiffness report covers "
            "external teeth only; its ISO 6336-1 stiffness is on its derivation audit page "
            "(gearsym derive)",
        )
    g1, g2 = topology.gear(mesh.driver), topology.gear(mesh.driven)
    res = mesh_pem(topology, mesh, slices, harmonics)
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
        r = mesh_pem(topology, mesh, n, harmonics)
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
