"""Parametric instability from mesh stiffness variation and mesh phasing (issue 26).

References: Mathieu's first instability tongue to second order (Nayfeh and Mook, 1979,
*Nonlinear Oscillations*, section 5.2: ``delta = 1/4 +- q/2 - q^2/8 + O(q^3)`` for
``x'' + (delta + q cos s) x = 0``); the selection rules of mesh phasing for equally spaced
planets (Lin and Parker, 2002, "Planetary gear parametric instability caused by mesh
stiffness variation"; Parker, 2000, "A physical explanation for the effectiveness of planet
phasing to suppress planetary gear vibration"); and the first-order band of
``primary_instabilities`` against the Floquet multipliers of the same equations, an
independent (numerical) method.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.optimize
from gearsym.derive.equations.planetary import (
    derive_planetary,
    planetary_meshes,
    rectangular_wave,
)
from gearsym.derive.input.planetary import load_planetary
from gearsym.derive.input.scene import resolve_target
from gearsym.solver.analysis.modes import planetary_modes
from gearsym.solver.analysis.parametric import (
    Meshes,
    combination_instabilities,
    floquet_band,
    modal_basis,
    monodromy,
    multipliers,
    primary_instabilities,
)

ONE_SPRING = {"mass": (1.0,), "incidence": ((1.0,),), "stiffness": (1.0,)}


def test_one_spring_is_mathieu():
    """x'' + (1 + eps cos Omega t) x = 0 is Mathieu's equation in s = Omega t with
    delta = 1 / Omega^2, q = eps / Omega^2: the band's edges by the multipliers agree with
    the second-order closed form to its third-order term (q^3 / 32 in delta, below 1e-6
    of Omega here), and the first-order band of ``primary_instabilities`` with it to
    O(q^2)."""
    eps = 0.1
    meshes = Meshes((0,), (0.0,), (((eps, 0.0),),))
    (ins,) = primary_instabilities(ONE_SPRING, meshes, 1)
    assert ins.s == pytest.approx(eps / 2, rel=1e-12)
    lo, hi = floquet_band(ONE_SPRING, meshes, ins)

    def edge(sign):
        def gap(Omega):
            delta, q = 1 / Omega**2, eps / Omega**2
            return delta - (0.25 + sign * q / 2 - q**2 / 8)

        return scipy.optimize.brentq(gap, 1.5, 2.5, xtol=1e-14)

    # the lower edge in Omega is the upper edge in delta = 1 / Omega^2
    assert abs(lo - edge(+1)) <= 2e-6 * lo
    assert abs(hi - edge(-1)) <= 2e-6 * hi
    assert abs(ins.lower - lo) <= 2 * (eps / 4) ** 2 * lo
    assert abs(ins.upper - hi) <= 2 * (eps / 4) ** 2 * hi


def _meshes(st, wave: tuple) -> Meshes:
    """Every mesh of ``st`` with the waveform ``wave``, delayed by its own phase (a ring
    mesh by its planet's ring phase: no ring-sun offset)."""
    rows = [i for i, kind in enumerate(st.kinds) if kind == "mesh"]
    phases = []
    for i in rows:
        name = st.springs[i]  # sp<n> or rp<n>
        phases.append(st.phases[int(name[2:]) - 1][0 if name[0] == "s" else 1])
    return Meshes(tuple(rows), tuple(phases), tuple(wave for _ in rows))


def _set(scene: str, sun_teeth: int, ring_teeth: int, eps: float, sin: float = 0.0):
    """The structure of a shipped set with the tooth counts given, its mesh springs varying
    by ``eps`` (and ``sin``) in each of four harmonics, each delayed by its mesh phase;
    the labels of its flexible modes."""
    ps = load_planetary(resolve_target(scene))
    ps = replace(ps, sun_teeth=sun_teeth, ring_teeth=ring_teeth)
    st = derive_planetary(ps)
    S = st.as_structure()
    meshes = _meshes(st, ((eps, sin),) * 4)
    labels = [m.label for m in planetary_modes(S, scene).modes if m.label != "rigid-body"]
    return S, meshes, labels, ps.planets


# a mode's planets move in the cyclic order k (rotational 0, translational +-1, a planet
# mode of four planets 2): harmonic l of the mesh stiffness drives its primary instability
# only where l Z_s is 0 or +-2k modulo N
ORDER = {"rotational": (0,), "translational": (1, -1), "planet": (2,)}


@pytest.mark.parametrize(
    "scene, sun, ring",
    [("lin-parker-1999-3", 31, 89), ("lin-parker-1999-4", 29, 91), ("lin-parker-1999-4", 30, 90)],
)
def test_phasing_suppresses_what_the_selection_rules_say(scene, sun, ring):
    """First order: the band of every primary instability (harmonics 1 to 4) is empty
    exactly where the selection rule says, and no wider than 1e-12 of the largest there."""
    S, meshes, labels, N = _set(scene, sun, ring, 0.05, 0.02)
    found = primary_instabilities(S, meshes, 4)
    largest = max(i.s for i in found)
    for ins in found:
        label = labels[ins.modes[0]]
        assert len(ins.modes) == (2 if label == "translational" else 1), ins
        driven = any((ins.l * sun - s * 2 * k) % N == 0 for k in ORDER[label] for s in (1, -1))
        driven = driven or (ins.l * sun) % N == 0
        assert (ins.s > 1e-12 * largest) == driven, (label, ins.l, ins.s)


def test_floquet_agrees_with_the_first_order_band():
    """Lin and Parker's three-planet set with Z_s = 31: the edges of two bands found by the
    Floquet multipliers (a translational pair at l = 1 and a rotational mode at l = 3)
    differ from the first-order closed form by O(eps^2): below a fifth of the half-width
    at eps = 0.05, and about half that at eps = 0.025.  A band the phasing suppresses
    (the same rotational mode at l = 1) is stable at its centre to the integration's
    error, where the band it keeps (l = 3) grows by more than 1 % a period."""
    ratios = {}
    for eps in (0.05, 0.025):
        S, meshes, labels, _ = _set("lin-parker-1999-3", 31, 89, eps)
        found = primary_instabilities(S, meshes, 3)
        upper = [i for i in found if i.modes[0] >= len(labels) - 6]  # the mesh modes
        pair = next(i for i in upper if i.l == 1 and labels[i.modes[0]] == "translational")
        rot = next(i for i in upper if i.l == 3 and labels[i.modes[0]] == "rotational")
        for ins in (pair, rot):
            half = 0.5 * (ins.upper - ins.lower)
            lo, hi = floquet_band(S, meshes, ins)
            err = max(abs(lo - ins.lower), abs(hi - ins.upper)) / half
            assert err <= 0.2, (eps, ins, lo, hi)
            ratios.setdefault(ins.modes, []).append(err)
    for modes, (big, small) in ratios.items():
        assert 0.35 <= small / big <= 0.65, (modes, big, small)
    S, meshes, labels, _ = _set("lin-parker-1999-3", 31, 89, 0.05)
    found = primary_instabilities(S, meshes, 3)
    kept = next(i for i in found if i.l == 3 and i.modes == rot.modes)
    cut = next(i for i in found if i.l == 1 and i.modes == rot.modes)
    assert cut.suppressed and not kept.suppressed
    assert np.abs(multipliers(S, meshes, cut.centre)).max() - 1 < 1e-9
    assert np.abs(multipliers(S, meshes, kept.centre)).max() - 1 > 1e-2
    # the growth at the centre is the first-order rate s / (2 omega) over a mesh period
    rate = kept.s / (2 * kept.omega) * 2 * math.pi / kept.centre
    grown = math.log(np.abs(multipliers(S, meshes, kept.centre)).max())
    assert grown == pytest.approx(rate, rel=0.1)


def test_unequal_spacing_suppresses_nothing():
    """The suppression rests on equal spacing: with Lin and Parker's second planet at
    117 deg instead of 120 (still assembled: 120 x 117 / 360 = 39 whole), the modes are
    coupled and no primary band of the six mesh modes is empty at l = 1; the multipliers
    at each band's centre grow, where with equal spacing the rotational ones stay on the
    unit circle."""
    ps = load_planetary(resolve_target("lin-parker-1999-3"))
    for angles, equal in (((0.0, 120.0, 240.0), True), ((0.0, 117.0, 240.0), False)):
        moved = replace(ps, sun_teeth=31, ring_teeth=89, angles_deg=angles, equally_spaced=equal)
        st = derive_planetary(moved)
        S = st.as_structure()
        meshes = _meshes(st, ((0.05, 0.0),))
        labels = [m.label for m in planetary_modes(S, "x").modes if m.label != "rigid-body"]
        for ins in primary_instabilities(S, meshes, 1):
            if ins.modes[0] < len(labels) - 6:
                continue
            grown = np.abs(multipliers(S, meshes, ins.centre)).max() - 1
            if equal and labels[ins.modes[0]] == "rotational":
                assert ins.suppressed and grown < 1e-9, ins
            else:
                assert labels[ins.modes[0]] == ("translational" if equal else "coupled")
                assert not ins.suppressed and grown > 1e-2, (ins, grown)


@pytest.mark.parametrize(
    "scene, sun, ring",
    [("lin-parker-1999-3", 31, 89), ("lin-parker-1999-4", 29, 91), ("lin-parker-1999-4", 30, 90)],
)
def test_combinations_follow_the_selection_rules(scene, sun, ring):
    """First order, sum type: modes of cyclic orders k1 and k2 are driven by harmonic l
    only where l Z_s + s1 k1 + s2 k2 is 0 modulo N for some signs s1, s2 (the product of
    their shapes round the carrier against the meshes' phases; with k1 = k2 the primary
    rule above): every band outside the rule is empty."""
    S, meshes, labels, N = _set(scene, sun, ring, 0.05, 0.02)
    found = combination_instabilities(S, meshes, 4)
    largest = max(i.s for i in found)
    assert all(i.omega_partner > i.omega for i in found)
    kept = 0
    for ins in found:
        k1, k2 = ORDER[labels[ins.modes[0]]], ORDER[labels[ins.partner[0]]]
        driven = any(
            (ins.l * sun + s1 * a + s2 * b) % N == 0
            for a in k1
            for b in k2
            for s1 in (1, -1)
            for s2 in (1, -1)
        )
        if not driven:
            assert ins.s <= 1e-12 * largest, (ins, labels[ins.modes[0]])
        kept += driven and ins.s > 1e-12 * largest
    # the rule is necessary, not sufficient: with one waveform on every mesh the
    # variation is proportional to the mean stiffness there, and two planet modes, or a
    # planet mode and another, can be orthogonal under it whatever the phases
    assert kept > 0  # and the test is not empty


def test_floquet_agrees_with_the_first_order_combination_band():
    """The sum-type band of the upper translational pair and rotational mode of Lin and
    Parker's three-planet set (l = 1, the widest of that pair): Floquet edges against
    |l Omega - omega_1 - omega_2| < s / sqrt(omega_1 omega_2), an error below a tenth of
    the half-width at eps = 0.05 that halves with eps."""
    errors = []
    for eps in (0.05, 0.025):
        S, meshes, labels, _ = _set("lin-parker-1999-3", 31, 89, eps)
        found = combination_instabilities(S, meshes, 1)
        ins = max(
            (
                i
                for i in found
                if labels[i.modes[0]] == "translational"
                and labels[i.partner[0]] == "rotational"
                and i.modes[0] >= len(labels) - 6
            ),
            key=lambda i: (i.upper - i.lower) / i.centre,
        )
        lo, hi = floquet_band(S, meshes, ins)
        half = 0.5 * (ins.upper - ins.lower)
        errors.append(max(abs(lo - ins.lower), abs(hi - ins.upper)) / half)
    assert errors[0] <= 0.1, errors
    assert 0.35 <= errors[1] / errors[0] <= 0.65, errors


# -- the command: gearsym modes SET --parametric -------------------------------------------

VARIATION = """
[planetary.variation]
sun_planet = { contact_ratio = 1.6, amplitude = 0.1 }
ring_planet = { contact_ratio = 1.8, amplitude = 0.1 }
ring_sun_phase = 0.25
harmonics = 3
"""


def _file(tmp_path, extra: str = VARIATION, teeth: str = "sun_teeth = 31\nring_teeth = 89\n"):
    text = Path(resolve_target("lin-parker-1999-3")).read_text(encoding="utf-8")
    text = text.replace("planets = 3\n", "planets = 3\n" + teeth, 1)
    path = tmp_path / "set.toml"
    path.write_text(text + extra, encoding="utf-8")
    return path


def run(*args):
    return subprocess.run(
        [sys.executable, "-m", "gearsym", *args], capture_output=True, text=True, timeout=300
    )


def test_rectangular_wave_is_its_fourier_series():
    """The waveform of a mesh with one more pair in contact during the first c - floor(c)
    of each mesh period: its harmonics against an FFT of the sampled wave (an independent
    method), to the FFT's sampling error."""
    for c, amp in ((1.6, 0.2), (1.25, 0.5), (2.4, 0.1)):
        wave = rectangular_wave(c, amp, 5)
        n = 1 << 16
        t = (np.arange(n) + 0.5) / n
        v = amp * ((t < c - math.floor(c)) - (c - math.floor(c)))
        F = np.fft.rfft(v) / n
        for h, (a, b) in enumerate(wave, start=1):
            assert a == pytest.approx(2 * F[h].real, abs=1e-4 * amp)
            assert b == pytest.approx(-2 * F[h].imag, abs=1e-4 * amp)


def test_cli_parametric(tmp_path):
    """`gearsym modes SET --parametric`: every primary band, the ones the phasing
    suppresses marked (rotational modes of Z_s = 31, N = 3: all but l = 3), the bands
    those of ``primary_instabilities`` on the file's waveform and phases, in Hz."""
    path = _file(tmp_path)
    done = run("modes", str(path), "--parametric", "--json")
    assert done.returncode == 0, done.stderr
    bands = json.loads(done.stdout)["parametric"]["bands"]
    assert {b["type"] for b in bands} == {"rotational", "translational"}
    for b in bands:
        if b["type"] == "rotational":
            assert b["suppressed"] == (b["harmonic"] != 3), b
        else:
            assert not b["suppressed"], b
    ps = load_planetary(path)
    st = derive_planetary(ps)
    rows, phases, waves = planetary_meshes(st)
    found = primary_instabilities(st.as_structure(), Meshes(rows, phases, waves), 3)
    assert len(found) == len(bands)
    for ins, b in zip(found, bands, strict=True):
        assert b["lower_hz"] == pytest.approx(ins.lower / (2 * math.pi), rel=1e-12)
        assert b["upper_hz"] == pytest.approx(ins.upper / (2 * math.pi), rel=1e-12)
    combos = json.loads(done.stdout)["parametric"]["combinations"]
    expected = combination_instabilities(st.as_structure(), Meshes(rows, phases, waves), 3)
    assert [(c["harmonic"], c["lower_hz"]) for c in combos] == [
        (i.l, pytest.approx(i.lower / (2 * math.pi), rel=1e-12)) for i in expected
    ]
    # the ring meshes lag their planet's sun mesh by the stated quarter period
    assert phases[1] == pytest.approx((st.phases[0][1] + 0.25) % 1.0)
    done = run("modes", str(path), "--parametric")
    assert done.returncode == 0, done.stderr
    assert "suppressed by the phasing" in done.stdout
    assert "first order" in done.stdout
    assert "combination instabilities" in done.stdout


@pytest.mark.parametrize(
    "extra, teeth, where",
    [
        (VARIATION, "", "sun_teeth"),
        (VARIATION.replace("1.6", "0.9"), None, "contact_ratio"),
        (
            VARIATION.replace("amplitude = 0.1 }\nring", "amplitude = 3.0 }\nring"),
            None,
            "amplitude",
        ),
        (VARIATION.replace("harmonics = 3", "harmonic = 3"), None, "harmonic"),
        ("", None, "[planetary.variation]"),
    ],
)
def test_cli_parametric_refusals(tmp_path, extra, teeth, where):
    """A variation without tooth counts, a contact ratio below 1, a stiffness that would
    fall to zero, an unknown key, and --parametric on a set without a variation: one line
    naming the input, exit 2."""
    path = _file(tmp_path, extra) if teeth is None else _file(tmp_path, extra, teeth)
    done = run("modes", str(path), "--parametric")
    assert done.returncode == 2, (done.stdout, done.stderr)
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert where in done.stderr
    assert "Traceback" not in done.stderr


def test_cli_parametric_refused_on_a_tree():
    done = run("modes", "reference-light", "--parametric")
    assert done.returncode == 2
    assert len(done.stderr.strip().splitlines()) == 1
    assert "planetary" in done.stderr


def test_the_api_gives_what_the_command_prints():
    """``gearsym.planetary.parametric_instabilities`` and ``gearsym.planetary.modes``
    (``planetary`` in ``gearsym.__all__``): the same bands as ``gearsym modes --parametric
    --json`` of the shipped lin-parker-1999-3-phased, and the modes with Lin and Parker's
    multiplicities."""
    import gearsym

    assert "planetary" in gearsym.__all__
    table = gearsym.planetary.parametric_instabilities("lin-parker-1999-3-phased")
    done = run("modes", "lin-parker-1999-3-phased", "--parametric", "--json")
    assert done.returncode == 0, done.stderr
    printed = json.loads(done.stdout)["parametric"]
    assert printed["bands"] == table["bands"]
    assert printed["combinations"] == table["combinations"]
    modal = gearsym.planetary.modes("lin-parker-1999-4")
    planet = [m for m in modal.modes if m.label == "planet"]
    assert planet and all(m.multiplicity == 1 for m in planet)  # N - 3 = 1
    with pytest.raises(ValueError, match="variation"):
        gearsym.planetary.parametric_instabilities("lin-parker-1999-3")
    with pytest.raises(ValueError, match="not a planetary set"):
        gearsym.planetary.modes("reference-light")


def test_energy_and_liouville():
    """The undamped linear model of Lin and Parker's three-planet set keeps its energy
    over 1,000 mesh periods (no variation: the monodromy to the 1,000th power leaves the
    energy form unchanged to 1e-8 at rtol 1e-13, an error that falls with rtol); with the
    variation at a band's centre, Liouville's formula (the system has no damping, so
    det = exp(integral of the trace) = 1) holds to 1e-9 and the multipliers come in pairs
    mu, 1 / mu (a Hamiltonian system)."""
    S, meshes, labels, _ = _set("lin-parker-1999-3", 31, 89, 0.0)
    omega, *_ = modal_basis(S)
    Omega = 1.3 * omega[0]
    n = omega.size
    E = np.diag(np.concatenate([omega**2 / Omega**2, np.ones(n)]))  # the energy form
    drift = {}
    for rtol in (1e-12, 1e-13):
        T1000 = np.linalg.matrix_power(monodromy(S, meshes, Omega, rtol=rtol), 1000)
        drift[rtol] = np.abs(T1000.T @ E @ T1000 - E).max() / np.abs(E).max()
    # what is left is the integration's error (about 1.4e-9 here), falling with its
    # tolerance: the model itself neither gains nor loses energy
    assert drift[1e-13] <= 1e-8, drift
    assert drift[1e-13] <= drift[1e-12] / 5, drift
    S, meshes, labels, _ = _set("lin-parker-1999-3", 31, 89, 0.05)
    ins = next(i for i in primary_instabilities(S, meshes, 1) if not i.suppressed)
    mu = np.linalg.eigvals(monodromy(S, meshes, ins.centre))
    assert abs(np.prod(mu) - 1.0) <= 1e-9
    assert np.abs(mu).max() > 1.0 + 1e-6  # unstable there, and yet
    for m in mu:
        assert np.abs(mu - 1.0 / m).min() <= 1e-7 * np.abs(mu).max()


def test_cli_parametric_diagram(tmp_path):
    """`--parametric --plot FILE` writes the diagram (also with --json); --plot alone on a
    planetary set, which has no resonance diagram, is refused in one line."""
    png = tmp_path / "parametric.png"
    done = run("modes", "lin-parker-1999-3-phased", "--parametric", "--json", "--plot", str(png))
    assert done.returncode == 0, done.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    done = run("modes", "lin-parker-1999-3-phased", "--plot", str(png))
    assert done.returncode == 2
    assert len(done.stderr.strip().splitlines()) == 1 and "--parametric" in done.stderr


def test_floquet_checks_a_suppressed_band_too(tmp_path):
    """With --floquet a band the phasing suppresses to first order is checked at its
    centre (its multipliers on the unit circle), and each kept band gets its Floquet
    edges: the torsional model of the phased set (small, so quick)."""
    text = resolve_target("lin-parker-1999-3-phased").read_text(encoding="utf-8")
    path = tmp_path / "torsional.toml"
    path.write_text(text.replace('"lateral-torsional"', '"torsional"', 1), encoding="utf-8")
    import gearsym

    table = gearsym.planetary.parametric_instabilities(path, floquet=True)
    cut = [b for b in table["bands"] if b["suppressed"]]
    kept = [b for b in table["bands"] if not b["suppressed"]]
    assert cut and kept
    assert all(b["floquet_stable_at_centre"] for b in cut)
    # (at this amplitude, 0.2, the first order is only a guide: the Floquet edges of the
    # planet modes' bands lie up to about one half-width from it; the convergence test
    # above takes amplitudes of 0.05 and less)
    assert all(b["floquet_hz"][0] < b["floquet_hz"][1] for b in kept)
