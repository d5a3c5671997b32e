"""The nonlinear model of a planetary set whose carrier turns (issue 26, Build 3): the
rotating frame's gyroscopic and centripetal terms in the model that simulate, sweep, map
and shoot take, with backlash in every mesh.

References, none of them the reduced model's own code:

* the hand assembly at speed of ``test_planetary_speed`` (M, G and K - W^2 K_Omega of Lin
  and Parker's equations written out by hand, the planets' load on u_c from the exact
  energy of one planet in the frame): linearised on its loaded equilibrium, every mesh in
  contact, the undamped model has those frequencies, the rigid-body rotation removed;
* the full equations in body coordinates, integrated by SciPy here: ``M q'' + W G q' +
  (K - W^2 K_Omega) q = F - sum_j r_j^T k_j b_j g(r_j q / b_j)`` over every coordinate, the
  rigid-body rotation kept (its momentum zero at the start), the carrier taking the sun's
  reaction so that the rotation is unforced.  With a kick that opens the teeth, the
  meshes' deflections of the reduced, generated model follow it, and its energy in the
  frame (G does no work) stays put.  A reduction that dropped the rotation's momentum
  (the set's Coriolis coupling to the planets' radial motion) would miss both.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
import scipy.integrate
import scipy.linalg
from gearsym.derive.equations.planetary import derive_planetary
from gearsym.solver.integrate import simulate

from .test_planetary import example
from .test_planetary_dynamics import DYN, _model
from .test_planetary_speed import by_hand_at_speed, first_order

RPM = 3000.0


@pytest.fixture(scope="module")
def turning(tmp_path_factory):
    ps = replace(example(3), dynamics=DYN, variation=None, carrier_speed_rpm=RPM)
    return ps, *_model(ps, tmp_path_factory.mktemp("turning"), "turning")


def test_linearised_it_has_the_hand_assemblys_frequencies_at_speed(turning):
    ps, _, system = turning
    x = system.module.static_state(system.p)
    assert all(abs(u) > 1 for u in system.module.mesh_deflections(x).values())
    lam = np.linalg.eigvals(system.module.jacobian(0.0, x, system.p))
    assert np.max(np.abs(lam.real)) < 1e-12 * np.max(np.abs(lam))  # undamped
    ours = np.sort(lam.imag[lam.imag > 0]) * system.module.OMEGA_N / (2 * np.pi)
    M, C, K, _ = by_hand_at_speed(ps, RPM)
    hand = first_order(M, C, K)
    hand = hand[np.argsort(np.abs(hand))][2:]  # the rigid-body rotation's double zero
    hand = np.sort(hand.imag[hand.imag > 0]) / (2 * np.pi)
    assert ours.size == hand.size
    assert np.max(np.abs(ours - hand) / hand) < 1e-9
    # the frame's terms matter at this speed: the fixed-carrier frequencies differ
    still = np.sort(first_order(*by_hand_at_speed(ps, 0.0)[:3]).imag)
    still = still[still > 1.0] / (2 * np.pi)
    assert np.max(np.abs(still - hand) / hand) > 1e-2


def test_it_follows_the_full_equations_through_tooth_separation(turning):
    ps, dyn, system = turning
    st = derive_planetary(ps)
    W = st.carrier_speed_rad_s
    M = np.diag(st.mass)
    R, k = st.incidence, np.asarray(st.stiffness)
    zero = np.zeros((len(st.mass), len(st.mass)))
    Kw = zero if st.centripetal is None else st.centripetal
    Gw = zero if st.gyroscopic is None else st.gyroscopic
    mesh = [j for j, kind in enumerate(st.kinds) if kind == "mesh"]
    other = [j for j in range(len(k)) if j not in mesh]
    b = np.array([50e-6 if st.springs[j].startswith("s") else 40e-6 for j in mesh])
    Kother = R[other].T @ (k[other, None] * R[other]) - W**2 * Kw
    G = W * Gw
    # the rigid-body rotation: the null vector of the whole stiffness at this speed
    w2, V = scipy.linalg.eigh(R.T @ (k[:, None] * R) - W**2 * Kw, M)
    phi = V[:, 0]
    assert abs(w2[0]) < 1e-9 * w2[-1] and w2[1] > 1e-6 * w2[-1]
    F = np.zeros(len(st.mass))
    us, uc = st.physical.index("u_s"), st.physical.index("u_c")
    F[us] = DYN.sun_force
    F[uc] = -F[us] * phi[us] / phi[uc]  # the carrier's reaction: the rotation unforced

    def dead_zone(u):
        return np.where(u > 1, u - 1, np.where(u < -1, u + 1, 0.0))

    def rhs(_, x):
        n = len(st.mass)
        q, v = x[:n], x[n:]
        u = R[mesh] @ q / b
        force = F - Kother @ q - G @ v - R[mesh].T @ (k[mesh] * b * dead_zone(u))
        return np.concatenate([v, force / np.diag(M)])

    def energy(x):
        n = len(st.mass)
        q, v = x[:n], x[n:]
        u = R[mesh] @ q / b
        teeth = 0.5 * np.sum(k[mesh] * b**2 * dead_zone(u) ** 2)
        return 0.5 * v @ M @ v + 0.5 * q @ Kother @ q + teeth - F @ q

    # start: the reduced model's loaded equilibrium, kicked so that the ring teeth open
    module = system.module
    m = len(module.COORDINATES)
    x0 = module.static_state(system.p)
    x0[m:] = 0.1 * np.linspace(1.0, -1.0, m)
    T, b_ref, wn = dyn.transform, dyn.length_m, dyn.omega_n
    q0 = b_ref * T @ x0[:m]
    v0 = b_ref * wn * T @ x0[m:]
    # the rotation's momentum zero, as the reduced model takes it
    v0 -= phi * (phi @ M @ v0 + phi @ (G @ q0)) / (phi @ M @ phi)
    omega = system.p[0]
    periods, per = 3, 64
    tau = np.arange(periods * per) * (2 * np.pi / omega) / per
    full = scipy.integrate.solve_ivp(
        rhs,
        (0.0, tau[-1] / wn),
        np.concatenate([q0, v0]),
        method="DOP853",
        t_eval=tau / wn,
        rtol=1e-11,
        atol=1e-11 * np.abs(np.concatenate([q0, v0])).max(),
    )
    assert full.success
    E = np.array([energy(x) for x in full.y.T])
    # G does no work; each crossing of a gap's edge (a kink in the force) costs DOP853 its
    # order there, so the drift is above the tolerance: 2e-8 of the energy here
    assert np.max(np.abs(E - E[0])) < 1e-7 * np.max(np.abs(E))
    delta_full = (R[mesh] @ full.y[: len(st.mass)]) / b[:, None]
    tr = simulate(
        system, x0, transient=0, periods=periods, samples_per_period=per, rtol=1e-11, atol=1e-12
    )
    assert tr.status == "ok"
    ours = module.mesh_deflections(tr.x)
    names = [st.springs[j] for j in mesh]
    reduced = np.array([ours[n] for n in names])
    assert reduced.shape == delta_full.shape
    # the teeth open: some mesh leaves contact during the run
    assert np.min(np.abs(delta_full)) < 1.0
    # two integrations through the same kinks: 9e-7 of the largest deflection here; the
    # reduction without the rotation's momentum (its Coriolis stiffening) misses by 8e-2,
    # and by 6e-6 even with every tooth in contact (both tried)
    err = np.max(np.abs(reduced - delta_full))
    assert math.isfinite(err) and err < 1e-5 * np.max(np.abs(delta_full)), err


def test_a_speed_that_makes_the_stiffness_indefinite_is_refused_and_the_audit_says_the_frame():
    """At 50,000 rpm (below the bearings' limit) the four-planet set's stiffness ``K -
    W^2 K_Omega`` has negative directions, as ``gearsym modes`` finds: the nonlinear model
    and the transmission-error response refuse it too, in one line each.  At 3000 rpm the
    audit page states the frame's terms of the nonlinear model."""
    from gearsym.derive.emit.audit_planetary import planetary_page
    from gearsym.derive.equations.planetary_dynamics import derive_dynamics
    from gearsym.derive.input.reader import InputError
    from gearsym.planetary import te_response
    from gearsym.solver.analysis.modes import UnstableAtSpeed

    fast = derive_planetary(replace(example(4), dynamics=DYN, carrier_speed_rpm=50000.0))
    with pytest.raises(InputError, match="indefinite") as err:
        derive_dynamics(fast)
    assert "\n" not in str(err.value)
    with pytest.raises(UnstableAtSpeed, match="indefinite"):
        te_response(replace(fast, phases=((0.0, 0.0),) * 4), 100.0, 200.0)
    st = derive_planetary(replace(example(3), dynamics=DYN, carrier_speed_rpm=RPM))
    page = planetary_page(st, "gearsym derive x", "x.toml")
    assert f"The carrier turns at {RPM:g} rpm" in page and "momentum zero" in page


def test_the_audit_says_which_mesh_frequency_the_speed_gives():
    """The shipped turning set with backlash: its ring alone held, 89 teeth at 3000 rpm
    turn the meshes at 89 x 3000 / 60 = 4450 Hz, its operating point; the same set with an
    operating point of 1000 Hz is told that its excitation and frame belong to two
    speeds."""
    from gearsym.derive.emit.audit_planetary import planetary_page
    from gearsym.derive.input.planetary import load_planetary
    from gearsym.derive.input.scene import resolve_target

    ps = load_planetary(resolve_target("lin-parker-1999-3-turning-backlash"))
    assert ps.carrier_speed_rpm == RPM and ps.ring_teeth == 89
    page = planetary_page(derive_planetary(ps), "gearsym derive x", "x.toml")
    assert "Z_r n_c / 60 = 4450 Hz, the file's operating point." in page
    other = replace(ps, dynamics=replace(ps.dynamics, mesh_frequency_hz=1000.0))
    page = planetary_page(derive_planetary(other), "gearsym derive x", "x.toml")
    assert "the file's operating point is 1000 Hz" in page and "two different speeds" in page


def test_a_run_at_another_mesh_frequency_is_told_the_frame_stays_at_the_files_speed():
    """The shipped turning set states FRAME (3000 rpm; 89 x 3000 / 60 = 4450 Hz with the
    ring held) in its generated module.  simulate at its own operating point says nothing;
    with --set mesh_frequency_hz=2000, and a sweep from 4000 to 4500 Hz, one note line
    says that the frame's terms stay at 3000 rpm and at which mesh frequencies they and the
    excitation belong to two speeds.  The same set without a speed has no FRAME and no
    note."""
    import subprocess
    import sys

    import gearsym

    system = gearsym.load("lin-parker-1999-3-turning-backlash")
    assert system.module.FRAME == {
        "carrier_speed_rpm": RPM,
        "mesh_frequency_of_speed_hz": pytest.approx(89 * RPM / 60, rel=1e-12),
    }
    assert getattr(gearsym.load("lin-parker-1999-3-backlash").module, "FRAME", None) is None

    def notes(*args) -> list[str]:
        done = subprocess.run(
            [sys.executable, "-m", "gearsym", *args], capture_output=True, text=True, timeout=600
        )
        assert done.returncode == 0, done.stderr
        return [line for line in done.stderr.splitlines() if "gearsym: note:" in line]

    short = ("--transient", "2", "--periods", "2")
    assert notes("simulate", "lin-parker-1999-3-turning-backlash", *short) == []
    (note,) = notes(
        "simulate", "lin-parker-1999-3-turning-backlash", "--set", "mesh_frequency_hz=2000", *short
    )
    assert "3000 rpm" in note and "4450 Hz" in note and "at 2000 Hz" in note
    assert "two different speeds" in note
    assert (
        notes("simulate", "lin-parker-1999-3-backlash", "--set", "mesh_frequency_hz=2000", *short)
        == []
    )


def test_a_runs_note_names_the_runs_mesh_frequencies():
    """The turning set at an operating point of 1000 Hz (not its speed's 4450): its
    starting point is noted at 1000 Hz, and a sweep over 4000 to 4500 Hz replaces that
    with its own range, 4450 Hz itself excepted; a sweep over 4450 Hz alone says nothing."""
    import gearsym
    from gearsym.cli._notes import _PENDING, forget, note_frame, note_run

    system = gearsym.load("lin-parker-1999-3-turning-backlash", mesh_frequency_hz=1000.0)
    forget()
    try:
        note_frame(system)  # as gearsym.cli._system.system_of notes a loaded set
        (loaded,) = _PENDING.values()
        assert "at 1000 Hz" in loaded and "4450 Hz" in loaded
        note_run(system, {"mesh_frequency_hz": [4000.0, 4500.0]})
        (swept,) = _PENDING.values()
        assert "at 4000 to 4500 Hz, except at 4450 Hz itself," in swept
        assert "1000" not in swept
        note_run(system, {"mesh_frequency_hz": [4450.0, 4450.0]})
        assert not _PENDING
    finally:
        forget()
