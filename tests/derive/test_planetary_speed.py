"""A planetary set with its carrier turning (issue 26, Build 3): the gyroscopic and
centripetal terms of the rotating frame, against named references.

* Closed form: a mass on an isotropic spring seen from axes turning at Omega has the
  frequencies sqrt(k / m) -/+ Omega (m (w + Omega)^2 = k for z = x + i y ~ exp(i w t)).
* An independent assembly written here: M and K of Lin and Parker's lateral-torsional
  model by hand (``test_planetary.by_hand``), their gyroscopic matrix G and centripetal
  K_Omega of their equations of motion by hand, and the planets' bearings' load on u_c from
  a numerical Hessian of one planet's exact energy in the rotating frame (centripetal
  potential and its bearing as a vector spring between its centre and the pin, the pin on
  a circle of radius r_c, in static equilibrium): the eigenvalues of the first-order form,
  no gearsym code.
* First principles: turning the whole set is neutral at any carrier speed (its rigid-body
  mode stays at 0 Hz); G is skew, so the gyroscopic forces do no work (the undamped
  model's energy in the frame is conserved) and the stiffness is symmetric.
* Cooley and Parker (2012, "Vibration properties of high-speed planetary gears with
  gyroscopic effects", J. Vib. Acoust. 134) show the rotational, translational and planet
  mode types surviving the gyroscopic terms for equally spaced planets, the degenerate
  translational pairs splitting: checked on the types here, not on their numbers.
"""

from __future__ import annotations

import math
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest
from gearsym.derive.equations.planetary import derive_planetary
from gearsym.derive.input.planetary import load_planetary
from gearsym.solver.analysis.modes import planetary_modes

from .test_planetary import by_hand, example

RPM = 2 * math.pi / 60


def test_mass_on_an_isotropic_spring_in_turning_axes():
    m, k, rpm = 2.0, 8.0e6, 6000.0
    W = rpm * RPM
    structure = {
        "physical": ("zeta_1", "eta_1"),
        "mass": (m, m),
        "coordinates": ("x", "y"),
        "kinds": ("bearing", "bearing"),
        "incidence": ((1.0, 0.0), (0.0, 1.0)),
        "stiffness": (k, k),
        "members": ("planet1", "planet1"),
        "motions": ("translation", "translation"),
        "carrier_speed_rad_s": W,
        "gyroscopic": ((0.0, -2 * m), (2 * m, 0.0)),
        "centripetal": ((m, 0.0), (0.0, m)),
    }
    f = [mode.frequency_hz for mode in planetary_modes(structure, "one mass").modes]
    wn = math.sqrt(k / m)
    assert f == pytest.approx([(wn - W) / (2 * math.pi), (wn + W) / (2 * math.pi)], rel=1e-12)


def by_hand_at_speed(ps, rpm: float, r_c: float = 0.1):
    """(M, G, K - W^2 K_Omega) by hand; the planets' load on u_c from the exact Hessian
    (SymPy) of one planet's exact energy in the frame, coordinates zeta, eta, u_c, in
    static equilibrium (the pin at radius ``r_c``, which the result must not depend on)."""
    import sympy as sp

    W = rpm * RPM
    M, K = by_hand(ps)
    n = len(ps.angles_deg)
    masses = np.diag(M)
    G = np.zeros_like(K)
    Kw = np.zeros_like(K)
    for body in range(3 + n):
        x, y = 3 * body, 3 * body + 1
        G[x, y], G[y, x] = -2 * masses[x], 2 * masses[y]
        Kw[x, x], Kw[y, y] = masses[x], masses[y]
    mp, kp = ps.members["planet"].mass, ps.members["planet"].bearing
    zeta, eta, u_c = sp.symbols("zeta eta u_c", real=True)
    d = mp * W**2 * r_c / (kp - mp * W**2)  # static stretch: kp d = mp W^2 (r_c + d)
    p = sp.Matrix([r_c + d + zeta, eta])
    pin = r_c * sp.Matrix([sp.cos(u_c / r_c), sp.sin(u_c / r_c)])
    energy = kp * (p - pin).dot(p - pin) / 2 - mp * W**2 * p.dot(p) / 2
    q = (zeta, eta, u_c)
    H = np.array([[float(sp.diff(energy, a, b).subs({v: 0 for v in q})) for b in q] for a in q])
    gradient = [float(sp.diff(energy, a).subs({v: 0 for v in q})) for a in q]
    assert np.allclose(gradient, 0.0, atol=1e-9 * kp * r_c)  # an equilibrium
    # the Hessian's u_c entry less the bearing's linear k_p: the load's share, per planet
    Keff = K - W**2 * Kw
    Keff[2, 2] += n * (H[2, 2] - kp)
    return M, G * W, Keff, H


def first_order(M, C, K) -> np.ndarray:
    n = M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    return np.linalg.eigvals(A)


@pytest.mark.parametrize(
    ("n", "rpm", "r_c"), [(3, 3000.0, 0.1), (4, 12000.0, 0.05), (5, 20000.0, 0.2)]
)
def test_frequencies_at_speed_equal_the_hand_assembly(n, rpm, r_c):
    ps = replace(example(n), carrier_speed_rpm=rpm)
    ours = [m.frequency_hz for m in planetary_modes(derive_planetary(ps).as_structure(), "x").modes]
    M, C, K, H = by_hand_at_speed(ps, rpm, r_c)
    lam = first_order(M, C, K)
    by_size = lam[np.argsort(np.abs(lam))]
    # the rigid-body rotation: a double eigenvalue at 0 (scattered by rounding only)
    assert np.all(np.abs(by_size[:2]) < 1e-6 * np.abs(lam).max())
    rest = by_size[2:]
    assert np.all(np.abs(rest.real) < 1e-9 * np.abs(lam).max())  # on the imaginary axis
    hand = np.sort(rest.imag[rest.imag > 0]) / (2 * math.pi)
    assert ours[0] == 0.0
    assert np.array(ours[1:]) == pytest.approx(hand, rel=1e-9)
    # the exact planet Hessian has the model's other entries: bearing k_p on zeta and on
    # eta - u_c, and the centripetal -m_p W^2 on zeta and eta
    kp, mp, W = ps.members["planet"].bearing, ps.members["planet"].mass, rpm * RPM
    expected = {(0, 0): kp - mp * W**2, (0, 1): 0.0, (0, 2): 0.0, (1, 1): kp - mp * W**2}
    expected[(1, 2)] = -kp
    for (i, j), value in expected.items():
        assert H[i, j] == pytest.approx(value, rel=1e-12, abs=1e-9 * kp)


@pytest.mark.parametrize("rpm", [1000.0, 10000.0, 30000.0])
def test_turning_the_whole_set_stays_neutral(rpm):
    st = derive_planetary(replace(example(4), carrier_speed_rpm=rpm))
    modal = planetary_modes(st.as_structure(), "x")
    assert [m.label for m in modal.modes].count("rigid-body") == 1
    assert modal.modes[0].frequency_hz == 0.0
    assert modal.modes[1].frequency_hz > 100.0


def test_gyroscopic_forces_do_no_work_and_the_stiffness_is_symmetric():
    st = derive_planetary(replace(example(3), carrier_speed_rpm=5000.0))
    G, Kw = st.gyroscopic, st.centripetal
    assert np.array_equal(G, -G.T)
    assert np.array_equal(Kw, Kw.T)
    v = np.random.default_rng(0).normal(size=G.shape[0])
    assert abs(v @ G @ v) <= 1e-12 * np.abs(G).max() * (v @ v)


def test_mode_types_survive_the_gyroscopic_terms():
    """Cooley and Parker (2012): rotational modes keep the central members from
    translating, planet modes keep them still; the translational pairs split."""
    for n in (3, 5):
        fixed = planetary_modes(derive_planetary(example(n)).as_structure(), "x").modes
        turning = planetary_modes(
            derive_planetary(replace(example(n), carrier_speed_rpm=3000.0)).as_structure(), "x"
        ).modes
        labels = [m.label for m in turning]
        assert labels.count("coupled") == 0
        assert labels.count("rotational") == [m.label for m in fixed].count("rotational")
        trans = [m for m in turning if m.label == "translational"]
        assert len(trans) == 12 and all(m.multiplicity == 1 for m in trans)
        planet = [m for m in turning if m.label == "planet"]
        assert all(m.multiplicity == n - 3 for m in planet)
        assert len(planet) == 3 * (n - 3)
        # the lowest pair split about its fixed-carrier frequency by about the speed
        f0 = min(m.frequency_hz for m in fixed if m.label == "translational")
        lo, hi = trans[0].frequency_hz, trans[1].frequency_hz
        assert lo < f0 < hi and 0.5 * 50.0 < (hi - lo) / 2 < 1.5 * 50.0


def test_slow_carrier_approaches_the_fixed_carrier():
    fixed = planetary_modes(derive_planetary(example(3)).as_structure(), "x").modes
    slow = planetary_modes(
        derive_planetary(replace(example(3), carrier_speed_rpm=1e-3)).as_structure(), "x"
    ).modes
    for a, b in zip(fixed, slow, strict=True):
        assert abs(a.frequency_hz - b.frequency_hz) < 1e-4  # the split: 1.7e-5 Hz


def run(*args):
    return subprocess.run(
        [sys.executable, "-m", "gearsym", *args], capture_output=True, text=True, timeout=300
    )


def variant(tmp_path, name: str, base: str, old: str, new: str):
    """A copy of the shipped set ``base`` with ``old`` replaced by ``new``: its path."""
    from gearsym.derive.input.scene import resolve_target

    path = tmp_path / f"{name}.toml"
    text = resolve_target(base).read_text(encoding="utf-8")
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


def refused(done, words: str) -> None:
    """Exit 2 with one line on stderr that holds ``words``, no traceback."""
    assert done.returncode == 2 and words in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr


DOFS = 'degrees_of_freedom = "lateral-torsional"'


def test_cli_and_refusals(tmp_path):
    turning = variant(
        tmp_path, "turning", "lin-parker-1999-3", DOFS, DOFS + "\ncarrier_speed_rpm = 3000"
    )
    done = run("modes", str(turning))
    assert done.returncode == 0, done.stderr
    assert "carrier at 3000 rpm" in done.stdout and "696.5" in done.stdout
    torsional = 'degrees_of_freedom = "torsional"\ncarrier_speed_rpm = 3000'
    refused(
        run("modes", str(variant(tmp_path, "torsional", "lin-parker-1999-3", DOFS, torsional))),
        "carrier_speed_rpm",
    )
    fast = variant(
        tmp_path, "fast", "lin-parker-1999-3", DOFS, DOFS + "\ncarrier_speed_rpm = 200000"
    )
    refused(run("modes", str(fast)), "keep it below")


def test_speeds_the_set_cannot_run_at_are_refused():
    """At 50,000 and 80,000 rpm Lin and Parker's three-planet set's stiffness is
    indefinite (held at best by its gyroscopic terms): refused, saying so."""
    from gearsym.solver.analysis.modes import UnstableAtSpeed

    for rpm in (50000.0, 80000.0):
        st = derive_planetary(replace(example(3), carrier_speed_rpm=rpm))
        with pytest.raises(UnstableAtSpeed, match="indefinite"):
            planetary_modes(st.as_structure(), "x")


def test_unbalanced_planets_and_shared_loads_are_refused(tmp_path):
    from gearsym.derive.input.reader import InputError
    from gearsym.derive.input.scene import resolve_target

    unbalanced = "planet_angles_deg = [0, 100, 230]\ncarrier_speed_rpm = 5000"
    path = variant(tmp_path, "unbalanced", "lin-parker-1999-3", "planets = 3", unbalanced)
    refused(run("modes", str(path)), "do not balance")
    # opposite pairs balance: accepted, and the rotation stays neutral
    pairs = replace(example(4, angles=(0.0, 100.0, 180.0, 280.0)), carrier_speed_rpm=20000.0)
    modal = planetary_modes(derive_planetary(pairs).as_structure(), "x").modes
    assert modal[0].label == "rigid-body" and modal[1].frequency_hz > 100.0
    # every member held, unequal pressure angles: the meshes share the load, refused
    cp = load_planetary(resolve_target("cooley-parker-2012-4"))
    held = replace(cp, alpha_r_deg=cp.alpha_r_deg + 4.0, carrier_speed_rpm=3000.0)
    with pytest.raises(InputError, match="meshes would carry"):
        derive_planetary(held)
    derive_planetary(replace(cp, carrier_speed_rpm=3000.0))  # equal angles: accepted


def test_the_rigid_body_shape_keeps_its_signs():
    turning = replace(example(3), carrier_speed_rpm=3000.0)
    fixed = planetary_modes(derive_planetary(example(3)).as_structure(), "x").modes[0]
    rigid = planetary_modes(derive_planetary(turning).as_structure(), "x").modes[0]
    assert rigid.label == "rigid-body"
    for name, a in fixed.shape.items():
        assert np.sign(rigid.shape[name]) == np.sign(a) or abs(a) < 1e-9


def test_the_shipped_turning_set_and_its_audit_page():
    from gearsym.derive.emit.audit_planetary import planetary_page
    from gearsym.derive.input.scene import resolve_target

    ps = load_planetary(resolve_target("lin-parker-1999-3-turning"))
    assert ps.carrier_speed_rpm == 3000.0
    st = derive_planetary(ps)
    page = planetary_page(st, "gearsym derive", ps.source)
    assert "Rotating frame: the carrier turns at Ω_c = 314.159 rad/s" in page
    n, kp, mp, W = 3, ps.members["planet"].bearing, ps.members["planet"].mass, 3000 * RPM
    assert f"= −{n * kp * mp / (kp - mp * W**2):.6g} kg on `u_c`" in page
    fixed = load_planetary(resolve_target("lin-parker-1999-3"))
    assert "Rotating frame" not in planetary_page(derive_planetary(fixed), "x", fixed.source)
