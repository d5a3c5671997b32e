"""The shipped marine-stage-3: every number of its file computed again from the gear data
its comments state (the reference study's module, pressure angle, helix and face width;
ISO 6336-1 method B for the mesh stiffness through derive/mesh/iso6336.py; steel discs of
density 7850 kg/m^3 written out here for the masses and inertias), to the four figures the
file gives."""

from __future__ import annotations

import math

import pytest
from gearsym.derive.input.planetary import load_planetary
from gearsym.derive.input.scene import resolve_target
from gearsym.derive.mesh.geometry import gear_geometry, pair_geometry
from gearsym.derive.mesh.internal import internal_pair, ring_geometry
from gearsym.derive.mesh.iso6336 import iso_stiffness

RHO = 7850.0  # kg/m^3, steel
MN, ALPHA, BETA, B = 4e-3, math.radians(20.0), math.radians(10.0), 50e-3


def disc(outer: float, inner: float, width: float) -> tuple[float, float]:
    """Mass and polar moment of inertia of a steel annulus."""
    m = RHO * math.pi * (outer**2 - inner**2) * width
    return m, m * (outer**2 + inner**2) / 2


def test_every_number_follows_from_the_stated_geometry():
    ps = load_planetary(resolve_target("marine-stage-3"))
    sun = gear_geometry(50, MN, ALPHA, BETA)
    planet = gear_geometry(25, MN, ALPHA, -BETA)
    ring = ring_geometry(100, MN, ALPHA, -BETA)
    sp, rp = pair_geometry(sun, planet, B), internal_pair(planet, ring, B)
    assert sp.centre_distance == pytest.approx(rp.centre_distance, rel=1e-12)  # assembles
    assert (ps.sun_teeth, ps.ring_teeth, ps.planets) == (50, 100, 3)
    assert ps.k_sp == pytest.approx(iso_stiffness(sp).mesh_stiffness, rel=1e-3)
    assert ps.k_rp == pytest.approx(iso_stiffness(rp).mesh_stiffness, rel=1e-3)
    for angle in (ps.alpha_s_deg, ps.alpha_r_deg):
        assert angle == pytest.approx(math.degrees(sp.working_pressure_angle), abs=5e-3)
    r_c = sp.centre_distance
    expected = {
        "sun": (*disc(sun.pitch_radius, 0.0, B), sun.base_radius),
        "planet": (*disc(planet.pitch_radius, planet.pitch_radius / 2, B), planet.base_radius),
        "ring": (*disc(ring.pitch_radius + 5 * MN, ring.pitch_radius, B), ring.base_radius),
        "carrier": (*disc(r_c + planet.pitch_radius, 0.0, 2 * 20e-3), r_c),
    }
    for name, (m, inertia, r) in expected.items():
        member = ps.members[name]
        assert member.mass == pytest.approx(m, rel=1e-3), name
        assert member.inertia_over_r2 == pytest.approx(inertia / r**2, rel=1e-3), name
