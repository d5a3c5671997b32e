"""Results in physical units (solver/units.py, `simulate --units physical`).

References, each a closed form of gear kinematics or statics, not the model:
* mesh frequency = teeth x speed / 60 (Hz);
* static equilibrium of pinion p (and q) under a balanced set of torques: its mesh
  carries F = T_p / (r_b,p cos beta_b) along the line of action (r_b cos beta_b is the module's
  incidence entry), whatever the inertias;
* a deflection of x half backlashes is x b.
"""

from __future__ import annotations

import gearsym
import pytest
from gearsym.solver.units import Units


def test_speed_and_mesh_frequency():
    system = gearsym.load("reference-light", speed_rpm=3000.0)
    units = Units.of(system)
    assert units.scales["mesh_frequency_hz"] == pytest.approx(50 * 3000.0 / 60.0, rel=1e-12)
    assert units.frequency(system.omega) == pytest.approx(2500.0, rel=1e-12)
    assert units.order(system.omega) == 1.0


def test_deflection_in_um_follows_the_backlash():
    units = Units.of(gearsym.load("reference-light", half_backlash_um=60.0))
    assert units.deflection("u", 1.5) == pytest.approx(90.0, rel=1e-12)
    assert units.deflection_unit("u") == "µm"
    model = Units.of(gearsym.load("reference-light"), "model")
    assert model.deflection("u", 1.5) == 1.5 and model.deflection_unit("u") == "half backlashes"


@pytest.mark.parametrize("flywheel", [10.0, 2.0])
def test_static_mesh_force_in_newtons(flywheel):
    torques = {"torque_Nm_p": 500.0, "torque_Nm_q": -50.0, "torque_Nm_g": -900.0}
    system = gearsym.load("reference-light", flywheel_inertia_kg_m2=flywheel, **torques)
    units = Units.of(system)
    static = system.module.static_mesh_force(system.p)
    arm = system.module.STRUCTURE["incidence"][0][0]  # r_b,p cos(beta_b), m
    assert units.force("u", float(static[0])) == pytest.approx(500.0 / arm, rel=1e-9)
    # q brakes (T_q < 0): its mesh is loaded on the back flank, a negative force
    assert units.force("v", float(static[1])) == pytest.approx(-50.0 / arm, rel=1e-9)


def test_a_point_in_physical_units():
    from gearsym.solver.units import point_in_units

    system = gearsym.load("reference-linear", speed_rpm=1200.0)
    point = gearsym.analyse(system, transient=50, periods=50, lyapunov_periods=50)
    row = point_in_units(point, Units.of(system))["coordinates"]["u"]
    b_um = system.scales()["half_backlash_m"]["u"] * 1e6
    u = point.trajectory.coordinate("u")
    assert row["range"] == pytest.approx([u.min() * b_um, u.max() * b_um], rel=1e-12)
    assert row["dynamic_factor"] is not None and row["dynamic_factor"] >= 1.0 - 1e-9
