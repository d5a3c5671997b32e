"""The nonlinear model of a planetary set (backlash in every mesh), against references of
its own:

* linearised on its loaded equilibrium (every mesh in contact, no stiffness variation) it
  has the natural frequencies of Lin and Parker's M and K assembled by hand from their
  sub-matrices (``test_planetary.by_hand``, written for the test; the rigid-body mode is the
  one the nonlinear model removes);
* its equilibrium has the closed form of an equally spaced set: each planet takes a third
  of the sun's force in both its meshes (the planet's moment balance);
* undamped and without variation it conserves the energy of its linear model over 1,000
  periods (a conservation law; the energy is built from the derivation's own reduced mass
  and stiffness, so this checks the emitted, compiled equations against them, and the
  frequencies above check the matrices);
* with its stiffness variation, the ring meshes' teeth separate where the second harmonic
  meets the 6986 Hz translational pair of the hand assembly (6986 / 2 Hz).
"""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest
from gearsym.derive.emit.planetary_module import planetary_module
from gearsym.derive.equations.planetary import derive_planetary
from gearsym.derive.equations.planetary_dynamics import derive_dynamics
from gearsym.derive.input.planetary import Dynamics
from gearsym.derive.input.reader import InputError
from gearsym.derive.input.scene import resolve_target
from gearsym.solver.integrate import simulate
from gearsym.solver.system import System

from .test_planetary import by_hand, example, frequencies

DYN = Dynamics(5000.0, 50e-6, 40e-6, 1000.0, 0.0)  # undamped; ring backlash unequal


def _model(ps, tmp_path, name):
    dyn = derive_dynamics(derive_planetary(ps))
    path = tmp_path / f"{name}.py"
    path.write_text(planetary_module(dyn, "test"), encoding="utf-8")
    return dyn, System.load(path)


@pytest.fixture(scope="module")
def three(tmp_path_factory):
    ps = replace(example(3), dynamics=DYN, variation=None)
    return ps, *_model(ps, tmp_path_factory.mktemp("three"), "three")


@pytest.mark.parametrize("n, dofs", [(3, "lateral-torsional"), (4, "torsional")])
def test_linearised_on_its_equilibrium_it_has_the_hand_assemblys_frequencies(n, dofs, tmp_path):
    ps = replace(example(n, dofs), dynamics=DYN, variation=None)
    _, system = _model(ps, tmp_path, f"set{n}")
    x = system.module.static_state(system.p)
    assert all(abs(u) > 1 for u in system.module.mesh_deflections(x).values())
    J = system.module.jacobian(0.0, x, system.p)
    lam = np.linalg.eigvals(J)
    ours = np.sort(np.abs(lam.imag))[::2] * system.module.OMEGA_N / (2 * np.pi)
    if dofs == "lateral-torsional":
        M, K = by_hand(ps)
    else:  # the torsional model's own matrices (test_planetary checks them by hand)
        st = derive_planetary(ps)
        M, K = np.diag(st.mass), st.incidence.T @ (np.asarray(st.stiffness)[:, None] * st.incidence)
    hand = np.sort(frequencies(M, K))[1:]  # the rigid-body rotation removed
    assert np.allclose(np.real(lam), 0.0, atol=1e-12)  # undamped
    assert np.max(np.abs(ours - hand) / hand) < 1e-9


def test_the_equilibrium_shares_the_sun_force_equally(three):
    ps, dyn, system = three
    x = system.module.static_state(system.p)
    assert np.max(np.abs(system.module.rhs(0.0, x, system.p))) < 1e-12
    u = system.module.mesh_deflections(x)
    # each mesh carries F_s / 3 along its line of action: u = 1 + F / (3 k b_mesh)
    for mesh, b in (("sp", 50e-6), ("rp", 40e-6)):
        for k in (1, 2, 3):
            assert u[f"{mesh}{k}"] == pytest.approx(1 + 5000.0 / (3 * 5e8 * b), rel=1e-10)


def test_undamped_it_conserves_its_energy_over_1000_periods(three):
    ps, dyn, system = three
    st = dyn.structure
    M = np.diag(st.mass)
    r = st.incidence[st.springs.index("sp1")]
    m_ref = 1.0 / np.sum(r**2 / np.asarray(st.mass))
    A = dyn.transform.T @ M @ dyn.transform / m_ref
    K = dyn.stiffness
    load = system.p[1] * dyn.load_direction  # f_s T^T F: the load in the reduced coordinates
    gaps = sum(v["weight"] * np.asarray(v["row"]) for v in system.module.MESHES.values())
    m = len(system.module.COORDINATES)

    def energy(X):
        y, v = X[:m], X[m:]
        return (
            0.5 * np.einsum("i...,ij,j...->...", v, A, v)
            + 0.5 * np.einsum("i...,ij,j...->...", y, K, y)
            - np.tensordot(load + gaps, y, axes=1)
        )

    x0 = system.module.static_state(system.p)
    E0 = energy(x0)
    x0 = x0.copy()
    x0[m:] = 0.01 * np.linspace(1.0, -1.0, m)  # small: every mesh stays in contact
    tr = simulate(
        system, x0, transient=0, periods=1000, samples_per_period=4, rtol=1e-11, atol=1e-13
    )
    assert tr.status == "ok"
    # every mesh in contact throughout: the model is the linear one, whose energy this is
    assert all(np.min(u) > 1 for u in system.module.mesh_deflections(tr.x).values())
    E = energy(tr.x) - E0  # the vibration's energy above the equilibrium
    # DOP853 at rtol 1e-11 over 4,000 samples: a drift of 1e-7 would be 10,000 times the
    # tolerance; a sign error in a coupling term would change E at first order
    assert np.max(np.abs(E - E[0])) < 1e-7 * E[0]


def test_the_ring_teeth_separate_at_the_second_harmonic_of_a_translational_pair():
    import gearsym

    resp = gearsym.planetary.mesh_response(
        "lin-parker-1999-3-backlash", 3300.0, 3700.0, 9, transient=150, periods=30
    )
    pair = by_hand(example(3))
    f_k = min(frequencies(*pair), key=lambda f: abs(f - 6986.3))  # the hand assembly's
    peak = resp["frequencies_hz"][int(np.argmax(resp["up"]["ring-planet"]["u_max"]))]
    assert abs(peak - f_k / 2) <= 50.0  # the grid's step
    assert resp["band_hz_by_kind"]["ring-planet"] and not resp["band_hz_by_kind"]["sun-planet"]
    lo, hi = resp["band_hz_by_kind"]["ring-planet"][0]
    assert lo - 50.0 <= f_k / 2 <= hi + 50.0
    json.dumps(resp)  # JSON-ready


def run(*args):
    return subprocess.run(
        [sys.executable, "-m", "gearsym", *args], capture_output=True, text=True, timeout=300
    )


def test_simulate_reports_each_mesh_and_refuses_what_it_cannot_model(tmp_path):
    done = run(
        "simulate", "lin-parker-1999-3-backlash", "--set", "mesh_frequency_hz=3500", "--json"
    )
    assert done.returncode == 0, done.stderr
    meshes = json.loads(done.stdout)["meshes"]
    assert sorted(meshes) == ["rp1", "rp2", "rp3", "sp1", "sp2", "sp3"]
    assert all(meshes[f"rp{k}"]["apart"] > 0 for k in (1, 2, 3))
    assert all(meshes[f"sp{k}"]["apart"] == 0 for k in (1, 2, 3))
    done = run("simulate", "lin-parker-1999-3-backlash", "--set", "sun_torque_Nm=3")
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
    assert "sun_force_N" in done.stderr
    # a value out of range is refused in the unit and under the name it was given
    for given, rule in (("mesh_frequency_hz=-5", "> 0"), ("damping_ratio=5", "in [0, 1]")):
        done = run("simulate", "lin-parker-1999-3-backlash", "--set", given)
        assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
        assert given.split("=")[0] in done.stderr and rule in done.stderr, done.stderr
    # two members free to turn: two rigid-body modes, refused in one line
    text = resolve_target("lin-parker-1999-3-backlash").read_text(encoding="utf-8")
    free = tmp_path / "free.toml"
    free.write_text(text.replace("torsional_N_per_m = 1e9", "torsional_N_per_m = 0"))
    done = run("simulate", str(free))
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
    assert "rigid-body modes" in done.stderr


def test_a_set_without_the_table_is_refused_before_any_derivation():
    with pytest.raises(InputError, match=r"\[planetary.dynamics\]"):
        derive_dynamics(derive_planetary(example(3)))


def test_a_maps_random_starts_lie_round_the_loaded_equilibrium(three):
    from gearsym.solver.sweep.atlas import default_box

    _, _, system = three
    box = default_box(system)
    x = system.module.static_state(system.p)
    for k, c in enumerate(system.coordinates):
        assert box[c] == pytest.approx((x[k] - 1.0, x[k] + 1.0))
    assert box["du_s"] == (-1.0, 1.0)


@pytest.mark.parametrize("sun_teeth, ring_teeth, in_phase", [(30, 90, True), (31, 89, False)])
def test_a_transmission_error_in_phase_on_every_planet_moves_no_central_member_across(
    sun_teeth, ring_teeth, in_phase, tmp_path
):
    """Parker and Lin (2004, "Mesh phasing relationships in planetary and epicyclic
    gears"): an excitation of the sun meshes in phase on equally spaced planets (Z_s / N
    whole) drives only the rotational modes, so no central member translates; phased
    sequentially (Z_s / N not whole) it drives translational modes too. The error is
    delayed by each mesh's phase, as its stiffness would be."""
    from gearsym.derive.input.meshes import TransmissionError

    te = TransmissionError((2e-6, 0.5e-6), (0.0, 0.7))
    dyn = Dynamics(5000.0, 50e-6, 50e-6, 1500.0, 0.03, error_sun=te)
    ps = replace(
        example(3), dynamics=dyn, variation=None, sun_teeth=sun_teeth, ring_teeth=ring_teeth
    )
    _, system = _model(ps, tmp_path, f"te{sun_teeth}")
    x0 = system.module.static_state(system.p)
    tr = simulate(system, x0, transient=200, periods=2, samples_per_period=32, rtol=1e-11)
    assert tr.status == "ok"
    u = system.module.mesh_deflections(tr.x)
    assert all(np.min(v) > 1 for v in u.values())  # in contact: the linear model
    assert np.ptp(u["sp1"]) > 0.01  # the error moves the sun meshes
    coords = list(system.module.COORDINATES)
    across = [coords.index(f"{a}_{m}") for m in "crs" for a in "xy"]
    travel = max(float(np.ptp(tr.x[i])) for i in across)
    if in_phase:
        assert travel < 1e-9
    else:
        assert travel > 1e-4


def test_a_transmission_error_without_the_teeth_is_refused_in_one_line():
    from gearsym.derive.input.meshes import TransmissionError

    te = TransmissionError((2e-6,), (0.0,))
    dyn = Dynamics(5000.0, 50e-6, 50e-6, 1500.0, 0.03, error_ring=te)
    ps = replace(example(3), dynamics=dyn, variation=None, sun_teeth=None, ring_teeth=None)
    with pytest.raises(InputError, match="needs sun_teeth and ring_teeth"):
        derive_dynamics(derive_planetary(ps))
