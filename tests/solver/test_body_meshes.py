"""Models in body coordinates: a set at rest inside its backlash (a period-1 verdict that
says it is neutral), each mesh's loaded flank and its contact shares in sweep records.

The back-to-back rig at a twentieth of its locked-in load keeps every mesh inside its
backlash (the shafts' twist does not close the gaps): nothing couples the two halves of
the loop, and each turns freely inside its gap.  Every state is constant; the shooting
check converges to the rest state with one Floquet multiplier exactly 1 (the free
relative rotation: a family of equilibria) and the others inside the unit circle.  The
verdict was "undetermined" after 3,000 periods, with a 0-1 test and a section dimension
read off rounding noise of 1e-11, and spectral "peaks" of a coordinate at 1e-13.

References: the multiplier 1 of a family of orbits (a free motion) is exact, independent
of the integrator; the others follow from the run here.  The rest state's constancy is
the run's own output.
"""

from __future__ import annotations

import numpy as np
import pytest
from gearsym.derive.input.scene import resolve_target
from gearsym.resolve import planetary_system
from gearsym.solver.analysis.orbit_check import OrbitCheck
from gearsym.solver.analysis.point import analyse_point


def test_a_loop_at_rest_inside_its_backlash_is_period_1_neutral_with_no_peaks():
    rig = planetary_system(resolve_target("back-to-back-rig")).with_values(load_factor=0.05)
    res = analyse_point(rig)
    v = res.verdict
    assert v.motion == "period-1"
    assert v.periods_run == 400  # no windows: the check settles it at once
    assert "neutral" in v.evidence and "family" in v.evidence["neutral"]
    mu = np.array([complex(*m) for m in v.evidence["orbit"]["multipliers"]])
    assert np.min(np.abs(mu - 1.0)) < 1e-9  # the free rotation, exact
    assert np.sort(np.abs(mu))[-2] < 0.5  # everything else decays
    for name, sp in res.spectra.items():
        assert sp.peaks() == [], name  # constant to rounding, one coordinate near 0


def _check(mu) -> OrbitCheck:
    return OrbitCheck(1, True, np.zeros(2), 0.0, 1, 1, np.asarray(mu, complex), 0.0)


def test_neutral_needs_every_other_multiplier_inside():
    assert _check([1.0, 0.5]).neutral and not _check([1.0, 0.5]).attracting
    assert not _check([1.0, 1.2]).neutral  # another multiplier outside: unstable
    assert not _check([1.0 + 1e-4, 0.5]).neutral  # not +1 within the error: a fold's near
    # a saddle-node orbit of reference-light at its fold (omega 0.45838, the frequency
    # response's): its multiplier within the multipliers' error of 1, but not at 1 to
    # rounding -- a lone orbit, not a family (the review found it called neutral)
    assert not _check([-0.556 + 0.360j, -0.556 - 0.360j, 1.000000693, 0.4398]).neutral
    assert _check([1.0 - 1.6e-15, 0.2206, 0.0828]).neutral  # the rig's, at rest
    assert not _check([-1.0, 0.5]).neutral  # -1 is a flip, not a free motion
    assert not _check([0.5, 0.2]).neutral and _check([0.5, 0.2]).attracting


def test_each_meshs_loaded_flank_is_the_derivations():
    """The contact shares name each mesh's loaded flank by its side: the rig's test pair
    is loaded on u < -1, its slave pair on u > 1 (the derivation's ``loaded_flanks``,
    from the loop's static solution in body rotations, against the side read off the
    model's reduced static solution); at the rig's own load both run on it all the time.
    A planetary set's sun force loads every mesh on u > 1."""
    from gearsym.derive.equations.train import derive_train, loaded_flanks
    from gearsym.derive.input.train import load_train
    from gearsym.planetary_dynamics import contact
    from gearsym.solver.analysis.meshing import loaded_sides
    from gearsym.solver.integrate import simulate

    path = resolve_target("back-to-back-rig")
    rig = planetary_system(path)
    st = derive_train(load_train(path))
    want = dict(zip((m.id for m in st.train.meshes), loaded_flanks(st), strict=True))
    assert want == {"test": -1, "slave": 1}
    assert loaded_sides(rig) == want
    assert loaded_sides(rig.with_values(load_factor=1e-10)) == want  # relative, not absolute
    shares = contact(simulate(rig, rig.module.static_state(rig.p), transient=20, periods=20))
    for mesh in want:
        assert (shares[mesh]["loaded_flank"], shares[mesh]["back_flank"]) == (1.0, 0.0)
    lp = planetary_system(resolve_target("lin-parker-1999-3-backlash"))
    assert set(loaded_sides(lp).values()) == {1}


def test_a_body_models_sweep_record_carries_each_meshs_contact_shares():
    """A sweep point of the three-planet set with backlash (its records are what sweeps
    write) holds every mesh's shares, forward on its loaded flank, apart and backward,
    the same as ``contact`` reads off the same run (the rig's back-to-back loop: its test
    pair forward on u < -1); at 3,500 Hz a ring-planet mesh loses contact part of the
    time (a share between 0 and 1, the three shares summing to 1)."""
    from gearsym.planetary_dynamics import contact

    lp = planetary_system(resolve_target("lin-parker-1999-3-backlash"))
    for system in (
        lp.with_values(mesh_frequency_hz=3500.0),
        planetary_system(resolve_target("back-to-back-rig")),
    ):
        res = analyse_point(system, system.module.static_state(system.p))
        shares = res.record().meshing_states
        read = contact(res.trajectory)
        assert set(shares) == set(system.module.MESHES) == set(read)
        for mesh, s in shares.items():
            assert s["forward"] + s["separated"] + s["backward"] == pytest.approx(1.0)
            assert (s["forward"], s["separated"], s["backward"]) == (
                read[mesh]["loaded_flank"],
                read[mesh]["apart"],
                read[mesh]["back_flank"],
            )
        if system.name.startswith("lin-parker"):
            assert 0.0 < max(s["separated"] for s in shares.values()) < 1.0


def test_a_body_model_in_physical_units_states_its_mesh_frequency_and_micrometres():
    """``--units physical`` of a planetary set: its operating point as the mesh frequency
    its file states (it has no speed of a gear), each mesh's half backlash in µm beside
    its shares (the file's values, read here with tomllib)."""
    import tomllib

    from gearsym.planetary_dynamics import contact
    from gearsym.solver.integrate import simulate
    from gearsym.solver.units import Units

    path = resolve_target("lin-parker-1999-3-backlash")
    d = tomllib.loads(path.read_text(encoding="utf-8"))["planetary"]["dynamics"]
    lp = planetary_system(path)
    said = Units.of(lp).operating_point()
    assert said.startswith(f"mesh frequency {d['mesh_frequency_hz']:.6g} Hz (omega = ")
    rows = contact(simulate(lp, lp.module.static_state(lp.p), transient=2, periods=2))
    for mesh, row in rows.items():
        key = "sun_planet" if mesh.startswith("s") else "ring_planet"
        assert row["half_backlash_um"] == pytest.approx(d[f"{key}_half_backlash_um"])


def test_a_body_models_rows_in_physical_units_carry_their_mesh_frequency():
    """A sweep of the set over omega in physical units adds each row's mesh frequency,
    omega omega_n / 2 pi (the module's OMEGA_N), where a tree model adds its speed too."""
    from gearsym.solver.sweep import sweep
    from gearsym.solver.units_table import in_units

    lp = planetary_system(resolve_target("lin-parker-1999-3-backlash"))
    sw = sweep(lp, "omega", [0.09, 0.1], transient=5, periods=5, continuation=False)
    columns, rows = in_units(sw, lp).to_table()
    k = columns.index("mesh_frequency_hz")
    for row, w in zip(rows, (0.09, 0.1), strict=True):
        assert row[k] == pytest.approx(w * lp.module.OMEGA_N / (2 * np.pi), rel=1e-12)
    # the header does not state one frequency for rows that each have their own
    assert in_units(sw, lp).block()["operating_point"] == "omega varies by row (its column)"
