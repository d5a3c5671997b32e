"""Parametric instability of a planetary set whose carrier turns (issue 26, Build 3).

The first-order bands of ``primary_instabilities`` and ``combination_instabilities`` at
speed (complex modes, ``x^H (M - i W G / (2 w)) x = 1``; ``solver/analysis/parametric.py``)
against an independent method written here: the Floquet multipliers of

    ``M q'' + W G q' + (K - W^2 K_W + sum_j k_j eps cos(Omega t - 2 pi gamma_j) r_j r_j^T) q = 0``

assembled in the body coordinates from the structure's arrays and integrated by SciPy's
DOP853 over one mesh period (no modal basis, no gearsym integrator).  The rigid-body
rotation is a Jordan block at 1 of that monodromy; its two multipliers, the two nearest
1, are set aside.  Lin and Parker's three-planet set with Z_s = 31, Z_r = 89 at 3000 rpm.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
import scipy.integrate
import scipy.optimize
from gearsym.derive.equations.planetary import derive_planetary, planetary_meshes
from gearsym.derive.input.planetary import load_planetary
from gearsym.derive.input.scene import resolve_target
from gearsym.solver.analysis.parametric import (
    Meshes,
    combination_instabilities,
    monodromy,
    multipliers,
    primary_instabilities,
)

from .test_planetary_speed import refused, run, variant

RPM = 3000.0


def _set(eps: float, rpm: float = RPM, harmonics: int = 1, planets: int = 3):
    """Lin and Parker's set (three or five equally spaced planets) at ``rpm``, every mesh
    varying by ``eps`` in each of ``harmonics`` harmonics, delayed by its phase."""
    ps = load_planetary(resolve_target("lin-parker-1999-3"))
    ps = replace(ps, sun_teeth=31, ring_teeth=89, carrier_speed_rpm=rpm)
    if planets != 3:
        angles = tuple(360.0 * n / planets for n in range(planets))
        ps = replace(ps, angles_deg=angles, equally_spaced=True)
    st = derive_planetary(ps)
    rows = [i for i, kind in enumerate(st.kinds) if kind == "mesh"]
    phases = [st.phases[int(st.springs[i][2:]) - 1][st.springs[i][0] != "s"] for i in rows]
    wave = ((eps, 0.0),) * harmonics
    meshes = Meshes(tuple(rows), tuple(phases), tuple(wave for _ in rows))
    return st.as_structure(), meshes


def _own_multipliers(S: dict, meshes: Meshes, Omega: float) -> np.ndarray:
    """The test's Floquet multipliers (module text), the rigid-body pair set aside."""
    mass = np.asarray(S["mass"], float)
    R, k = np.asarray(S["incidence"], float), np.asarray(S["stiffness"], float)
    W = float(S["carrier_speed_rad_s"])
    K = R.T @ np.diag(k) @ R - W**2 * np.asarray(S["centripetal"], float)
    C = W * np.asarray(S["gyroscopic"], float)
    n = mass.size
    Minv = np.diag(1.0 / mass)

    def rhs(t, y):
        Y = y.reshape(2 * n, 2 * n)
        Kt = K.copy()
        for row, gamma, wave in zip(meshes.rows, meshes.phases, meshes.waveform, strict=True):
            v = sum(
                a * math.cos(h * (Omega * t - 2 * math.pi * gamma))
                + b * math.sin(h * (Omega * t - 2 * math.pi * gamma))
                for h, (a, b) in enumerate(wave, start=1)
            )
            Kt += k[row] * v * np.outer(R[row], R[row])
        return np.vstack([Y[n:], -Minv @ (Kt @ Y[:n] + C @ Y[n:])]).ravel()

    sol = scipy.integrate.solve_ivp(
        rhs,
        (0.0, 2 * math.pi / Omega),
        np.eye(2 * n).ravel(),
        method="DOP853",
        rtol=1e-11,
        atol=1e-13,
    )
    mu = np.linalg.eigvals(sol.y[:, -1].reshape(2 * n, 2 * n))
    return mu[np.argsort(np.abs(mu - 1.0))[2:]]


def _growth(S, meshes, Omega) -> float:
    return float(np.abs(_own_multipliers(S, meshes, Omega)).max() - 1.0)


def _edge(S, meshes, inside: float, outside: float, tol: float) -> float:
    """The band's edge between an unstable ``inside`` and a stable ``outside``."""
    while abs(outside - inside) > tol:
        mid = 0.5 * (inside + outside)
        if _growth(S, meshes, mid) > 1e-7:
            inside = mid
        else:
            outside = mid
    return 0.5 * (inside + outside)


def test_the_map_on_the_flexible_modes_has_the_independent_multipliers():
    """gearsym's monodromy at speed (restricted to the flexible modes) has the multipliers
    of the test's own in the body coordinates, to 1e-8, in a band and outside it."""
    S, meshes = _set(0.05)
    pair = next(i for i in primary_instabilities(S, meshes, 1) if not i.suppressed)
    for Omega in (pair.centre, 1.3 * pair.centre):
        ours, own = multipliers(S, meshes, Omega), _own_multipliers(S, meshes, Omega)
        assert ours.shape == own.shape
        distance = np.abs(ours[:, None] - own[None, :])
        i, j = scipy.optimize.linear_sum_assignment(distance)  # each to its own match
        assert distance[i, j].max() < 1e-8
    assert monodromy(S, meshes, pair.centre).shape == (own.size, own.size)


def test_first_order_bands_at_speed_against_the_independent_floquet_band():
    """The turning splits the lowest translational pair (696.5 and 789.3 Hz at 3000 rpm);
    l = 1 with Z_s mod 3 = 1 keeps the primary band of one whirl and cuts the other's.
    The kept band's edges by the test's own multipliers differ from the first-order ones
    by O(eps^2): the error over the half-width halves from eps = 0.02 to 0.01 (0.022 to
    0.011 measured) and is below 0.05 at 0.01; with the modes normalised on M alone, x^H
    M x = 1, it stays near 0.08 (0.085, 0.074: the frame's term in the normalisation is
    some 7 % of the width) and this test fails.  The cut band is stable at its centre."""
    errors = []
    for eps in (0.02, 0.01):
        S, meshes = _set(eps)
        found = primary_instabilities(S, meshes, 1)
        low = [i for i in found if i.modes[0] in (0, 1)]
        assert [len(i.modes) for i in low] == [1, 1]  # split: one mode each
        assert [i.omega / (2 * math.pi) for i in low] == pytest.approx([696.46, 789.26], abs=0.01)
        cut, kept = (low[0], low[1]) if low[0].suppressed else (low[1], low[0])
        assert cut.suppressed and not kept.suppressed
        assert _growth(S, meshes, cut.centre) < 1e-7
        half = 0.5 * (kept.upper - kept.lower)
        assert _growth(S, meshes, kept.centre) > 1e-4
        tol = 1e-4 * half
        lo = _edge(S, meshes, kept.centre, kept.centre - 2 * half, tol)
        hi = _edge(S, meshes, kept.centre, kept.centre + 2 * half, tol)
        errors.append(max(abs(lo - kept.lower), abs(hi - kept.upper)) / half)
    big, small = errors
    assert small < 0.05, errors
    assert 0.35 <= small / big <= 0.65, errors


def test_the_split_pair_has_a_sum_band_where_the_phasing_keeps_it():
    """The whirls' sum resonance l Omega = w_- + w_+ (a combination band at speed; at rest
    part of the pair's own primary band): for the lowest pair (696.5 + 789.3 Hz) the
    phasing cuts it at l = 1 and 2, and the test's multipliers do not grow at those
    centres; it keeps it at l = 3 (Z_s l = 93, a multiple of 3), and they grow at its
    centre at the first-order rate s / (2 sqrt(w_1 w_2)) per unit time, within 10 %."""
    S, meshes = _set(0.05, harmonics=3)
    found = combination_instabilities(S, meshes, 3)
    lowest = [i for i in found if i.modes == (0,) and i.partner == (1,)]
    assert [(i.l, i.suppressed) for i in lowest] == [(1, True), (2, True), (3, False)]
    for ins in lowest[:2]:
        assert _growth(S, meshes, ins.centre) < 1e-7
    kept = lowest[2]
    rate = kept.s / (2 * math.sqrt(kept.omega * kept.omega_partner)) * 2 * math.pi / kept.centre
    assert math.log1p(_growth(S, meshes, kept.centre)) == pytest.approx(rate, rel=0.1)


def test_a_multiple_mode_at_speed_is_one_band_whatever_its_basis():
    """Five equally spaced planets: a planet mode stays double at speed, and the
    eigensolver's basis of it is not orthonormal in the slow equations' form (its
    off-diagonal entries reached 0.55: the band came out half as wide).  The first-order
    band of the lowest planet mode at l = 1 against the test's own multipliers at amplitude
    0.02: unstable at 0.8 of its half-width from the centre, stable at 1.25."""
    S, meshes = _set(0.02, planets=5)
    (ins,) = [
        i for i in primary_instabilities(S, meshes, 1) if len(i.modes) == 2 and not i.suppressed
    ][:1]
    half = 0.5 * (ins.upper - ins.lower)
    for side in (-1, 1):
        assert _growth(S, meshes, ins.centre + side * 0.8 * half) > 1e-7
        assert _growth(S, meshes, ins.centre + side * 1.25 * half) < 1e-7


def test_a_slow_carrier_has_the_fixed_carriers_bands():
    """At 0.001 rpm the complex modes' path (normalised with the frame's term) gives the
    fixed-carrier bands of the real modes' path: a translational pair is one group of two
    whose largest singular value does not depend on which basis of the pair the
    eigensolver returns, to 1e-6."""
    at_rest, meshes = _set(0.05, rpm=0.0)
    assert not at_rest.get("carrier_speed_rad_s")
    slow, _ = _set(0.05, rpm=1e-3)
    for kind in (primary_instabilities, combination_instabilities):
        a, b = kind(at_rest, meshes, 2), kind(slow, meshes, 2)
        assert [(i.l, i.modes, i.partner) for i in a] == [(i.l, i.modes, i.partner) for i in b]
        largest = max(i.s for i in a)
        for x, y in zip(a, b, strict=True):
            assert y.omega == pytest.approx(x.omega, rel=1e-8)
            assert abs(y.s - x.s) <= 1e-6 * largest, (x, y)


def test_the_command_gives_the_bands_at_speed(tmp_path):
    """gearsym modes --parametric on a turning set: the bands of its modes at speed, not
    a refusal; the JSON says the speed."""
    path = variant(
        tmp_path,
        "phased-turning",
        "lin-parker-1999-3-phased",
        "[planetary]\n",
        "[planetary]\ncarrier_speed_rpm = 3000\n",
    )
    done = run("modes", str(path), "--parametric")
    assert done.returncode == 0, done.stderr
    assert "696.5" in done.stdout and "789.3" in done.stdout
    assert "carrier at 3000 rpm" in done.stdout
    fast = variant(
        tmp_path,
        "phased-fast",
        "lin-parker-1999-3-phased",
        "[planetary]\n",
        "[planetary]\ncarrier_speed_rpm = 50000\n",
    )
    refused(run("modes", str(fast), "--parametric"), "indefinite")


def test_a_cut_band_inside_its_partners_band_is_said_to_be_there():
    """The shipped turning set (amplitude 0.2): at l = 1 the phasing cuts the primary band
    of the upper pair's slower whirl (6977.1 Hz), whose centre lies in the kept band of the
    faster one (6996.1 Hz, 19 Hz apart, the band 500 Hz wide).  The test's multipliers grow
    there, and ``holding`` names that band, where the command once said 'a higher-order
    band'."""
    import gearsym
    from gearsym.solver.analysis.parametric import holding

    st = gearsym.planetary.load("lin-parker-1999-3-turning-backlash")
    S = st.as_structure()
    meshes = Meshes(*planetary_meshes(st))
    found = primary_instabilities(S, meshes, 1) + combination_instabilities(S, meshes, 1)
    cut = next(i for i in found if i.l == 1 and not i.partner and i.suppressed and i.omega > 4e4)
    assert cut.omega / (2 * math.pi) == pytest.approx(6977.1, abs=0.1)
    assert _growth(S, meshes, cut.centre) > 1e-5
    (kept,) = [i for i in holding(found, cut.centre) if not i.partner]
    assert kept.modes == (cut.modes[0] + 1,) and kept.l == 1
    assert kept.omega / (2 * math.pi) == pytest.approx(6996.1, abs=0.1)


def test_the_tables_mode_numbers_are_those_gearsym_modes_prints(tmp_path):
    """Cooley and Parker's set has no rigid-body mode (every member held or on a bearing
    that holds it): the bands' mode numbers are the rows of ``gearsym modes`` (0 the
    lowest), not the flexible modes counted from 1, at rest and at speed."""
    import gearsym

    for rpm in ("", "carrier_speed_rpm = 3000\n"):
        path = variant(
            tmp_path,
            f"cp4-{len(rpm)}",
            "cooley-parker-2012-4",
            "[planetary]\n",
            f"[planetary]\nsun_teeth = 31\nring_teeth = 89\n{rpm}",
        )
        path.write_text(
            path.read_text(encoding="utf-8")
            + "\n[planetary.variation]\nsun_planet = { contact_ratio = 1.6, amplitude = 0.2 }\n"
            "ring_planet = { contact_ratio = 1.8, amplitude = 0.2 }\nharmonics = 1\n",
            encoding="utf-8",
        )
        listed = gearsym.planetary.modes(str(path)).modes
        assert listed[0].label != "rigid-body"
        table = gearsym.planetary.parametric_instabilities(str(path))
        for band in table["bands"] + table["combinations"]:
            hz = band["natural_hz"] if "partner" not in band else band["natural_hz"][0]
            assert listed[band["modes"][0]].frequency_hz == pytest.approx(hz, rel=1e-9)
        assert min(b["modes"][0] for b in table["bands"]) == 0
