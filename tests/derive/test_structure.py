"""Models beyond torsion (derive/equations/structure.py, issue 15): the very-stiff limit against the
torsional model, energy conservation of the linear undamped model, and the generated
coefficients against the physical matrices the modal analysis uses."""

from pathlib import Path

import numpy as np
import pytest
from gearsym.derive.input.scene import builtin_root
from gearsym.resolve import module_for
from gearsym.solver import System
from gearsym.solver.integrate import simulate

TOPOLOGIES = builtin_root() / "topologies"


@pytest.fixture(autouse=True)
def _own_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))


def _topology(folder: Path, name: str, radial: float, axial: float, damping: float) -> Path:
    """diso-bearings.toml with every bearing replaced (an extension of the shipped file)."""
    lines = [
        "[topology]",
        f'extends = "{TOPOLOGIES / "diso-bearings.toml"}"',
        f'name = "{name}"',
    ]
    for gear in "pqg":
        lines += [
            "[[bearing]]",
            f'gear = "{gear}"',
            f"radial_N_per_m = {radial:g}",
            f"axial_N_per_m = {axial:g}",
            f"radial_damping_N_s_per_m = {damping:g}",
            f"axial_damping_N_s_per_m = {damping:g}",
        ]
    path = folder / f"{name}.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def _scene(folder: Path, name: str, topology: Path, text: str) -> Path:
    """A scene file: ``text`` (its [features], [parameters], ... tables) on ``topology``."""
    path = folder / f"{name}.toml"
    path.write_text(f'[scene]\nname = "{name}"\ntopology = "{topology}"\n{text}')
    return path


def _light_scene(folder: Path, name: str, topology: Path, dofs: str) -> Path:
    """reference-light.toml's scene on another topology with other degrees of freedom."""
    text = (builtin_root() / "reference-light.toml").read_text()
    body = text[text.index("[features]") :]
    body = body.replace("[features]\n", f'[features]\ndegrees_of_freedom = "{dofs}"\n', 1)
    return _scene(folder, name, topology, body)


@pytest.mark.slow
def test_very_stiff_bearings_give_the_torsional_poincare_points(tmp_path):
    """The lateral-torsional-axial DI-SO with bearings k times stiffer approaches the
    torsional model (the reference, reference-light at lambda = 0.1, a period-1 orbit).
    The translations a bearing allows move the mesh by about F/k_b against the mesh's
    own F/k_m, so the difference of the Poincare points must shrink like k_m/k_b:
    stated tolerance k_m/k_b half backlashes (k_m = 8.8e8 N/m; measured 0.85, 0.76 and
    0.75 of it at k_b = 1e11, 1e12, 1e13 N/m), and at least 8 times smaller for each
    tenfold stiffness (measured 11.3 and 10.1)."""
    options = dict(method="dop853", rtol=1e-11, atol=1e-12, transient=300, periods=8)
    ref = simulate(System.load(module_for("reference-light")), **options)
    ref_points = ref.poincare[:2]
    assert np.ptp(ref_points, axis=1).max() < 1e-6  # period 1: one point
    k_mesh = 8.8e8
    errors = []
    for k in (1e11, 1e12, 1e13):
        topo = _topology(tmp_path, f"stiff{int(np.log10(k))}", k, k, 0.0)
        scene = _light_scene(
            tmp_path, f"stiff-light-{int(np.log10(k))}", topo, "lateral-torsional-axial"
        )
        tr = simulate(System.load(module_for(scene)), **options)
        assert tr.status == "ok"
        error = np.abs(tr.poincare[:2] - ref_points).max()
        assert error < k_mesh / k, (k, error)
        errors.append(error)
    assert errors[1] < errors[0] / 8 and errors[2] < errors[1] / 8, errors


def _linear_undamped(tmp_path, dofs: str = "lateral-torsional-axial") -> System:
    topo = _topology(tmp_path, "undamped", 1e9, 5e8, 0.0)
    text = topo.read_text().replace(
        "axial_damping_N_s_per_m = 0", "axial_damping_N_s_per_m = 0\ntilt_damping_Nm_s_per_rad = 0"
    )
    topo.write_text(text)
    scene = _scene(
        tmp_path,
        "undamped-linear",
        topo,
        f'[features]\ndegrees_of_freedom = "{dofs}"\nstiffness_harmonics = 0\n'
        'backlash = "linear"\ntransmission_error = false\nmesh_phase = false\n'
        "[parameters]\nomega = 0.5\ndamping_ratio = 0.0\n[loads]\nu = 0\nv = 0\n",
    )
    return System.load(module_for(scene))


def _energy(module, x: np.ndarray) -> np.ndarray:
    """Kinetic plus strain energy in physical units, from the physical matrices alone
    (STRUCTURE: R, M, k, the scales): eta = L u, deta/dt = omega_n L u', and the kinetic
    energy 1/2 eta_dot^T W^-1 eta_dot with W = R M^-1 R^T (the rigid rotation at rest)."""
    s = module.STRUCTURE
    R = np.array(s["incidence"])
    W = R @ np.diag(1 / np.array(s["mass"])) @ R.T
    L = np.array(s["scale"])
    k = np.array(s["stiffness"])
    n = len(L)
    eta = L[:, None] * x[:n]
    rate = s["omega_n"] * L[:, None] * x[n:]
    kinetic = 0.5 * np.einsum("it,ij,jt->t", rate, np.linalg.inv(W), rate)
    return kinetic + 0.5 * np.einsum("i,it->t", k, eta**2)


@pytest.mark.parametrize("dofs", ["lateral-torsional-axial", "lateral-torsional-axial-tilting"])
def test_undamped_linear_model_conserves_energy_over_1000_periods(tmp_path, dofs):
    """The undamped, unforced, constant-stiffness, linear model: the energy of the
    physical matrices stays constant over 1,000 forcing periods to the integration
    tolerance (reference: exact conservation of a conservative system): at rtol 1e-10 the
    largest relative drift stays below 100 rtol (measured 3.5 rtol; with tilting 29 rtol),
    and it follows the tolerance: at rtol 1e-6 it is at least 1e3 times larger (measured
    14 rtol and 109 rtol; the tilting modes near 2.7 kHz take more steps), so the drift is
    the integrator's, not the model's."""
    system = _linear_undamped(tmp_path, dofs)
    rng = np.random.default_rng(7)
    x0 = rng.uniform(-0.5, 0.5, system.n)
    drift = {}
    for rtol in (1e-6, 1e-10):
        tr = simulate(
            system,
            x0,
            method="dop853",
            rtol=rtol,
            atol=rtol * 1e-2,
            transient=0,
            periods=1000,
            samples_per_period=4,
        )
        e = _energy(system.module, tr.x)
        drift[rtol] = np.abs(e / e[0] - 1).max()
    assert drift[1e-10] < 100 * 1e-10, drift
    assert drift[1e-6] > 1e3 * drift[1e-10], drift


def test_generated_coefficients_equal_the_physical_matrices():
    """kappa of the generated helical-pair model (SymPy, simplified closed forms) equals
    L^-1 W K L / omega_n^2 from the emitted physical matrices (an independent route),
    to 1e-12."""
    module = module_for("helical-pair-bearings")
    system = System.load(module)
    s = module.STRUCTURE
    R, L = np.array(s["incidence"]), np.array(s["scale"])
    W = R @ np.diag(1 / np.array(s["mass"])) @ R.T
    expected = (W * np.array(s["stiffness"])[None, :] * L[None, :]) / (
        L[:, None] * s["omega_n"] ** 2
    )
    names = s["coordinates"]
    for i, a in enumerate(names):
        for j, b in enumerate(names):
            name = f"kappa_{a}_{b}"
            got = system.parameter(name) if name in module.PARAMETERS else 0.0
            assert got == pytest.approx(expected[i, j], rel=1e-12, abs=1e-14), name


def test_hill_stability_of_the_model_on_bearings_matches_shooting():
    """The DI-SO on bearings has two identical pinions on identical bearings: double
    Floquet exponents, which Hill's method once took for shifted copies of one another
    (it then kept a spurious exponent and failed Liouville's check by 0.24). Reference:
    the monodromy of the shot orbit (an independent method), at omega = 0.5."""
    from gearsym.solver.periodic import harmonic_balance, shoot

    system = System.load(module_for("diso-bearings-light"))
    hb = harmonic_balance(system, harmonics=15)
    assert hb.floquet.stability == "stable" and hb.floquet.monodromy_error < 1e-6
    orbit = shoot(system, hb.state(0.0))
    hill_mu = np.sort(np.abs(hb.floquet.multipliers))
    shot_mu = np.sort(np.abs(orbit.floquet.multipliers))
    assert hill_mu == pytest.approx(shot_mu, abs=1e-6)


def test_an_anisotropic_bearing_across_the_line_of_action_rings_alone(tmp_path):
    """The helical pair with its transverse line of action along x (driver_position
    = 90 deg + alpha_wt puts psi at 0) and stiffer bearings along y: each gear's y motion
    is then free of the mesh, so two modes are the closed forms sqrt(k_y/m)/(2 pi) of a
    mass on a spring, and the x motions stay coupled to the mesh."""
    import math

    from gearsym.derive.input.topology import load_topology
    from gearsym.solver.analysis.modes import modes

    base = load_topology(TOPOLOGIES / "helical-pair-bearings.toml")
    alpha = math.degrees(base.meshes[0].pair.working_pressure_angle)
    ky = {"p": 3e9, "g": 4e9}
    lines = [
        "[topology]",
        f'extends = "{TOPOLOGIES / "helical-pair-bearings.toml"}"',
        'name = "aniso"',
        "[[mesh]]",
        'id = "pg"',
        f"driver_position_deg = {90 + alpha!r}",
    ]
    for gear, k in ky.items():
        lines += ["[[bearing]]", f'gear = "{gear}"', f"radial_y_N_per_m = {k:g}"]
    path = tmp_path / "aniso.toml"
    path.write_text("\n".join(lines) + "\n")
    result = modes(module_for(path))
    freqs = [m.frequency_hz for m in result.modes]
    for gear, k in ky.items():
        closed = math.sqrt(k / base.gear(gear).mass) / (2 * math.pi)
        near = min(freqs, key=lambda f, c=closed: abs(f - c))
        assert near == pytest.approx(closed, rel=1e-10), (gear, closed, freqs)
        mode = next(m for m in result.modes if m.frequency_hz == near)
        assert mode.shape[f"y_{gear}"] == pytest.approx(1.0)
        assert mode.kinetic_shares["translational"] == pytest.approx(1.0, abs=1e-12)


def test_a_spur_pair_tilts_free_of_the_mesh(tmp_path):
    """Tilting the helical pair's gears: with a zero helix angle the mesh force has no
    axial component, so no moment tilts the gears, and each gear's two tilting modes are
    the closed form sqrt(k_t/J)/(2 pi) of a rotor on its tilting spring (J the diametral
    inertia); with the helix they couple to the mesh (the axial force's moments) and the
    tilting modes move."""
    import math

    from gearsym.derive.input.topology import load_topology
    from gearsym.solver.analysis.modes import modes

    base = TOPOLOGIES / "helical-pair-bearings.toml"
    spur = tmp_path / "spur.toml"
    spur.write_text(
        f'[topology]\nextends = "{base}"\nname = "spur"\n'
        '[[gear]]\nid = "p"\nhelix_angle_deg = 0\n'
        '[[gear]]\nid = "g"\nhelix_angle_deg = 0\n'
    )
    for topo_path, helical in ((spur, False), (base, True)):
        topo = load_topology(topo_path)
        scene = _scene(
            tmp_path,
            f"tilt-{topo.name}",
            topo_path,
            '[features]\ndegrees_of_freedom = "lateral-torsional-axial-tilting"\n'
            "[parameters]\nomega = 0.5\ndamping_ratio = 0.03\n",
        )
        result = modes(module_for(scene))
        freqs = np.array([m.frequency_hz for m in result.modes])
        for gear in ("p", "g"):
            g = topo.gear(gear)
            closed = math.sqrt(topo.bearings[gear].tilt / g.diametral_inertia) / (2 * math.pi)
            hits = np.sum(np.isclose(freqs, closed, rtol=1e-10))
            if helical:
                assert hits < 2, (gear, closed, freqs)
            else:
                assert hits == 2, (gear, closed, freqs)
                tilting = [m for m in result.modes if np.isclose(m.frequency_hz, closed)]
                assert all(m.label == "tilting" for m in tilting)
