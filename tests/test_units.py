"""Results in physical units (solver/units.py, `simulate --units physical`).

References, each a closed form of gear kinematics or statics, not the model:
* mesh frequency = teeth x speed / 60 (Hz);
* static equilibrium of pinion p (and q) under a balanced set of torques: its mesh
  carries F = T_p / (r_b,p cos beta_b) along the line of action (r_b cos beta_b is the module's
  incidence entry), whatever the inertias;
* a deflection of x half backlashes is x b.
"""

from __future__ import annotations

import json
import math

import gearsym
import numpy as np
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


# -- --units physical on sweep, map, continue and shoot (issue 25, point 3) --------------
# Closed forms: reference-light's pinion p (the speed gear) has Z_P = 50 teeth and both
# meshes a half backlash of 50 µm (scenes/topologies/diso.toml); its audit page
# (docs/derivation/reference_light.md) gives omega = z n pi / 30 / omega_n, so the speed is
# n = 30 omega omega_n / (z pi) rpm and the mesh frequency z n / 60 Hz; a period T of the
# mesh is 60 / (z n) s; x half backlashes are x b; an exponent per unit tau is omega_n
# times that per second (tau = omega_n t).
Z_P, B_UM = 50, 50.0


def _rpm(omega: float, omega_n: float) -> float:
    return 30.0 * omega * omega_n / (Z_P * math.pi)


def test_a_table_in_physical_units_adds_columns_and_keeps_the_model_ones():
    from gearsym.solver.export import Document
    from gearsym.solver.units_table import InUnits

    system = gearsym.load("reference-light")
    omega_n = system.scales()["omega_n_rad_per_s"]  # inertias and stiffness: not swept here
    columns = ["omega", "half_backlash_um", "motion_u", "u", "max_v", "du", "lyapunov"]
    rows = [
        [0.4, 30.0, "period-1", 0.5, -1.2, 0.3, -0.01],
        [0.9, 60.0, "chaotic", 2.0, 1.0, 1.0, None],
    ]
    table = InUnits(
        Document({"parameter": "omega"}, columns, rows), system, ("omega", "half_backlash_um")
    )
    names, out = table.to_table()
    assert names[: len(columns)] == columns and [r[: len(columns)] for r in out] == rows
    added = dict(
        zip(names[len(columns) :], zip(*(r[len(columns) :] for r in out), strict=True), strict=True)
    )
    assert set(added) == {"u_um", "max_v_um", "lyapunov_per_s", "speed_rpm", "mesh_frequency_hz"}
    assert added["u_um"] == pytest.approx((0.5 * 30.0, 2.0 * 60.0), rel=1e-12)  # b is the row's
    assert added["max_v_um"] == pytest.approx((-1.2 * 30.0, 1.0 * 60.0), rel=1e-12)
    assert added["lyapunov_per_s"][0] == pytest.approx(-0.01 * omega_n, rel=1e-12)
    assert added["lyapunov_per_s"][1] is None  # missing stays missing
    rpm = [_rpm(0.4, omega_n), _rpm(0.9, omega_n)]
    assert added["speed_rpm"] == pytest.approx(rpm, rel=1e-12)
    assert added["mesh_frequency_hz"] == pytest.approx([Z_P * n / 60 for n in rpm], rel=1e-12)
    block = table.to_dict()["in_units"]
    assert block["table"]["u_um"] == list(added["u_um"]) and block["units"] == "physical"
    assert table.to_dict()["parameter"] == "omega"  # the model's keys stay
    model = InUnits(Document({}, columns, rows), system, ("omega",), "model")
    assert model.to_table() == (columns, rows) and "in_units" not in model.to_dict()


def test_the_parameter_axes_say_the_speed_and_the_mesh_frequency():
    from gearsym.solver.units import Units, parameter_axis

    system = gearsym.load("reference-light")
    omega_n = system.scales()["omega_n_rad_per_s"]
    label, (top, forward, inverse) = parameter_axis(Units.of(system), "omega")
    assert f"{omega_n / (2 * math.pi):.5g} Hz" in label and "rpm" in top
    assert forward(0.8) == pytest.approx(_rpm(0.8, omega_n), rel=1e-12)
    assert inverse(forward(0.8)) == pytest.approx(0.8, rel=1e-12)
    _, (top, forward, _) = parameter_axis(Units.of(system), "speed_rpm")
    assert top == "mesh frequency (Hz)" and forward(1200.0) == pytest.approx(Z_P * 1200.0 / 60)
    assert parameter_axis(Units.of(system, "model"), "omega") == ("omega", None)


def test_a_bifurcation_diagram_in_um(tmp_path):
    from gearsym.solver import plots

    system = gearsym.load("reference-light")
    sw = gearsym.sweep(
        system, "half_backlash_um", [40.0, 60.0], transient=50, periods=8, executor="serial"
    )
    fig = plots.bifurcation_diagram([sw], ["u", "du"], system=system, units="physical")
    u_ax, du_ax = fig.axes[:2]
    assert u_ax.get_ylabel().endswith("µm") and "per unit τ" in du_ax.get_ylabel()
    marks = [ln for ln in u_ax.get_lines() if ln.get_linestyle() == "None"]
    ys = np.concatenate([ln.get_ydata() for ln in marks if len(ln.get_xdata())])
    expected = np.concatenate(
        [np.asarray(p) * v for p, v in zip(sw.poincare("u"), sw.values, strict=True)]
    )
    # each value's distinct points (a period-1 orbit: one), times that value's b in µm
    assert np.all(np.min(np.abs(ys[:, None] - expected[None, :]), axis=1) < 1e-9 * np.abs(ys).max())
    assert du_ax.get_xlabel() == "half_backlash_um (µm)"
    # behind the points: each run's range (x b at its value) and the contact edges +-b
    edges = [ln for ln in u_ax.get_lines() if ln.get_linestyle() == "--"]
    assert len(edges) == 2 and np.allclose(sorted(e.get_ydata()[1] for e in edges), [-60, 60])
    bars = np.array(u_ax.collections[0].get_segments())  # one per run, at its value
    b = np.array(sw.values)
    np.testing.assert_allclose(bars[:, 0, 0], b)
    np.testing.assert_allclose(bars[:, 0, 1], sw.minima("u") * b, rtol=1e-12)
    np.testing.assert_allclose(bars[:, 1, 1], sw.maxima("u") * b, rtol=1e-12)
    assert not [c for c in fig.axes[1].collections]  # a velocity has no range bars


def _csv(path) -> dict:
    """The numeric columns of a result CSV (header lines start with #)."""
    import csv

    lines = [line for line in path.read_text().splitlines() if not line.startswith("#")]
    names, *rows = list(csv.reader(lines))
    out = {}
    for k, name in enumerate(names):
        try:
            out[name] = np.array([float(r[k]) if r[k] else np.nan for r in rows])
        except ValueError:
            continue  # text
    return out


def _run(argv, capsys):
    from gearsym.cli import main

    code = main(argv)
    return code, capsys.readouterr().out


def test_sweep_and_shoot_write_and_print_physical_units(tmp_path, capsys):
    from scipy.io import loadmat

    out = tmp_path / "sw"
    code, text = _run(
        ["sweep", "reference-light", "--param", "speed_rpm", "--range", "900:1500:3"]
        + ["--transient", "60", "--periods", "16", "--lyapunov-periods", "16"]
        + ["--executor", "serial", "--quiet", "--units", "physical", "--out", str(out)],
        capsys,
    )
    assert code == 0
    hz = ", ".join(f"{Z_P * n / 60:.4g}" for n in (900, 1500))
    assert f"mesh frequency {hz.replace(', ', ' to ')} Hz" in text
    table = _csv(out / "sweep.csv")
    assert table["max_u_um"] == pytest.approx(table["max_u"] * B_UM, rel=1e-12)
    assert table["mesh_frequency_hz"] == pytest.approx(table["speed_rpm"] * Z_P / 60)
    mat = loadmat(out / "sweep.mat", simplify_cells=True)
    assert mat["table"]["min_v_um"] == pytest.approx(table["min_v_um"], rel=1e-12)
    assert "max_u" in mat["table"] and "in_units" in mat["result"]
    data = json.loads((out / "sweep.json").read_text())
    assert data["in_units"]["table"]["max_u_um"] == pytest.approx(list(table["max_u_um"]))
    assert data["parameter"] == "speed_rpm" and len(data["points"]) == 3  # as before

    code, text = _run(
        ["shoot", "reference-light", "--set", "speed_rpm=1200", "--units", "physical", "--json"],
        capsys,
    )
    orbit = json.loads(text)
    assert orbit["in_units"]["period"] == pytest.approx(60.0 / (Z_P * 1200.0), rel=1e-9)
    assert orbit["in_units"]["x0"]["u"] == pytest.approx(orbit["x0"]["u"] * B_UM, rel=1e-12)
    assert "in_units" not in json.loads(
        _run(["shoot", "reference-light", "--set", "speed_rpm=1200", "--json"], capsys)[1]
    )


def test_map_and_continue_write_physical_columns(tmp_path, capsys):
    out = tmp_path / "map"
    code, text = _run(
        ["map", "reference-light", "--x", "speed_rpm=900:1500:3", "--y", "half_backlash_um=40:60:2"]
        + ["--initial-states", "1", "--transient", "60", "--periods", "16"]
        + ["--lyapunov-periods", "16", "--budget", "0", "--executor", "serial", "--quiet"]
        + ["--units", "physical", "--out", str(out)],
        capsys,
    )
    assert code == 0 and " µm" in text
    table = _csv(out / "map.csv")
    b = table["half_backlash_um"]  # the row's half backlash
    assert table["max_u_um"] == pytest.approx(table["max_u"] * b, rel=1e-12)
    assert table["min_v_um"] == pytest.approx(table["min_v"] * b, rel=1e-12)
    assert "max_du_um" not in table  # velocities stay non-dimensional
    from gearsym.solver.plots_maps import map_figures
    from gearsym.solver.sweep.maps_result import RegimeMap

    m = RegimeMap.load(out / "map.json")
    fig = map_figures(
        m, kinds=("extremes",), system=gearsym.load("reference-light"), units="physical"
    )["extremes"]
    cells = fig.axes[0].collections[0].get_array().reshape(len(m.y_values), len(m.x_values))
    b_um = np.asarray(m.y_values, float)[:, None]  # the y axis is the half backlash in µm
    assert np.asarray(cells) == pytest.approx(m.grid("max", "u") * b_um, rel=1e-12)
    assert "Max(u) in µm" in [ax.get_ylabel() for ax in fig.axes]  # its colour bar
    assert fig.axes[0].get_xlabel().startswith("speed_rpm: speed of gear 'p' (rpm)")

    out = tmp_path / "co"
    code, text = _run(
        ["continue", "reference-light", "--param", "omega", "--from", "0.5", "--to", "0.54"]
        + ["--step", "0.02", "--settle", "60", "--units", "physical", "--out", str(out)],
        capsys,
    )
    assert code == 0
    omega_n = gearsym.load("reference-light").scales()["omega_n_rad_per_s"]
    assert f"gear 'p' at {_rpm(0.5, omega_n):.4g} to" in text
    table = _csv(out / "branches.csv")
    assert table["u_um"] == pytest.approx(table["u"] * B_UM, rel=1e-12)
    rpm = [_rpm(w, omega_n) for w in table["omega"]]
    assert table["speed_rpm"] == pytest.approx(rpm, rel=1e-12)


def test_frequency_response_files_in_physical_units(tmp_path, capsys):
    """The issue's complaint: `frequency-response --physical` wrote non-dimensional CSV and
    MAT.  Now the model's columns stay and µm, rpm and Hz columns are added; references:
    x b with b = 50 µm (scenes/topologies/diso.toml), the mesh frequency teeth x speed / 60
    with 50 teeth on p, and the speed omega omega_n 30 / (z pi)."""
    from gearsym.cli import main
    from scipy.io import loadmat

    argv = ["frequency-response", "reference-light", "--param=omega=0.4:0.6:5", "--no-figure"]
    assert main([*argv, "--units", "physical", "--out", str(tmp_path)]) == 0
    said = capsys.readouterr().out
    assert "frequency_response.csv" in said and "frequency_response.mat" in said
    doc = json.loads((tmp_path / "frequency_response.json").read_text(encoding="utf-8"))
    lines = [ln for ln in (tmp_path / "frequency_response.csv").read_text().splitlines()]
    names, *rows = [ln.split(",") for ln in lines if not ln.startswith("#")]
    omega_n = doc["scales"]["omega_n_rad_per_s"]
    for row in rows:
        r = dict(zip(names, row, strict=True))
        omega, rpm = float(r["omega"]), float(r["speed_rpm"])
        assert rpm == pytest.approx(omega * omega_n * 30 / (50 * math.pi), rel=1e-12)
        assert float(r["mesh_frequency_hz"]) == pytest.approx(50 * rpm / 60, rel=1e-12)
        for c in ("u", "v"):
            for q in ("mean", "amplitude", "min", "max"):
                um = float(r[f"{c}_{q}_um"])
                assert um == pytest.approx(50.0 * float(r[f"{c}_{q}"]), rel=1e-12)
    mat = loadmat(tmp_path / "frequency_response.mat", simplify_cells=True)
    assert np.allclose(
        mat["table"]["u_amplitude_um"],
        [float(r[names.index("u_amplitude_um")]) for r in rows],
        rtol=1e-15,
    )
    assert doc["in_units"]["columns"]["speed_rpm"].startswith("speed of gear 'p'")
    # model units: the table as it always was
    assert main([*argv, "--out", str(tmp_path / "model")]) == 0
    head = (tmp_path / "model" / "frequency_response.csv").read_text().splitlines()
    assert not any("_um" in ln for ln in head if not ln.startswith("#"))


def test_simulate_writes_its_samples_and_draws_its_figure_in_physical_units(tmp_path, capsys):
    """`simulate --units physical`: the point files add µm and seconds beside the model's
    columns, and the figure's axes are in µm, ms, m/s and Hz.  References: x b with
    b = 50 µm (scenes/topologies/diso.toml), t = tau / omega_n, d/dt = omega_n d/dtau, and
    the mesh frequency omega omega_n / 2 pi."""
    from scipy.io import loadmat

    argv = ["simulate", "reference-light", "--transient", "20", "--periods", "10"]
    code, said = _run([*argv, "--units", "physical", "--out", str(tmp_path)], capsys)
    assert code == 0 and "µm" in said
    table = _csv(tmp_path / "point.csv")
    doc = json.loads((tmp_path / "point.json").read_text(encoding="utf-8"))
    omega_n = doc["scales"]["omega_n_rad_per_s"]
    assert np.allclose(table["u_um"], 50.0 * table["u"], rtol=1e-12, atol=0)
    assert np.allclose(table["t_s"], table["tau"] / omega_n, rtol=1e-12, atol=0)
    # the rates in m/s: d/dt = omega_n d/dtau, times b
    assert np.allclose(table["du_m_per_s"], 50e-6 * omega_n * table["du"], rtol=1e-12, atol=0)
    assert "speed_rpm" not in table  # one operating point, stated once in the block
    block = doc["in_units"]
    assert block["coordinates"]["v"]["range"] == pytest.approx(
        [50.0 * table["v"].min(), 50.0 * table["v"].max()], rel=1e-12
    )
    mat = loadmat(tmp_path / "point.mat", simplify_cells=True)
    assert np.allclose(mat["table"]["v_um"], table["v_um"], rtol=1e-15, atol=0)

    from gearsym.solver.plots import point_figure

    system = gearsym.load("reference-light")
    point = gearsym.analyse(system, transient=20, periods=10, lyapunov_periods=10)
    fig = point_figure(point, units="physical")
    series, portrait, spectrum = fig.axes[:3]
    assert series.get_ylabel() == "u (µm)" and series.get_xlabel() == "t (ms)"
    assert portrait.get_ylabel() == "du/dt (m/s)" and spectrum.get_xlabel() == "frequency (Hz)"
    tr = point.trajectory
    line = series.get_lines()[0]
    shown = tr.t[-line.get_xdata().size :]
    assert np.allclose(line.get_xdata(), shown / omega_n * 1e3, rtol=1e-12)
    assert np.allclose(line.get_ydata(), 50.0 * tr.coordinate("u")[-shown.size :], rtol=1e-12)
    du = portrait.get_lines()[0].get_ydata()
    assert np.allclose(du, 50e-6 * omega_n * tr.velocity("u")[-du.size :], rtol=1e-12)
    hz = omega_n / (2 * math.pi)
    assert spectrum.get_xlim()[1] == pytest.approx(6.5 * system.omega * hz, rel=1e-12)


def test_a_frequency_response_over_the_speed_is_drawn_in_um(tmp_path):
    """Over speed_rpm the response's amplitudes are µm (x b, b = 50 µm), its axis the speed
    with the mesh frequency (teeth x speed / 60, 50 teeth on p) on top."""
    from gearsym.solver.plots_response import frequency_response_figure

    system = gearsym.load("reference-light")
    resp = gearsym.frequency_response(system, "speed_rpm", 900.0, 1000.0, points=4, methods=("hb",))
    fig = frequency_response_figure(resp, physical=True)
    ax = fig.axes[0]
    assert ax.get_ylabel() == "half peak-to-peak of u (µm)"
    drawn = np.concatenate([ln.get_ydata() for ln in ax.get_lines()])
    expected = np.concatenate([50.0 * c.stats["u"]["amplitude"] for c in resp.curves])
    assert np.min(np.abs(drawn[:, None] - expected[None, :]), axis=1).max() < 1e-12
    assert expected.min() < 3.0 < expected.max() and drawn.size >= expected.size
    top = [a for a in ax.child_axes if a.get_xlabel() == "mesh frequency (Hz)"]
    assert top and fig.axes[-1].get_xlabel().startswith("speed_rpm")


def test_a_physical_parameter_s_axis_says_its_unit():
    """A map or sweep over a torque, an inertia or a backlash labels its axis with the unit
    the generated module states for it (PHYSICAL), in either kind of units; a plain factor
    or a non-dimensional parameter stays bare (a new user's map over torque_Nm_p)."""
    from gearsym.solver.units import parameter_axis

    system = gearsym.load("reference-light")
    for kind in ("physical", "model"):
        units = Units.of(system, kind)
        label = {n: parameter_axis(units, n)[0] for n in ("torque_Nm_p", "half_backlash_um")}
        assert label == {
            "torque_Nm_p": "torque_Nm_p (N m)",
            "half_backlash_um": "half_backlash_um (µm)",
        }
        assert parameter_axis(units, "flywheel_inertia_kg_m2")[0].endswith("(kg m²)")
        assert parameter_axis(units, "lambda")[0] == "lambda"
        assert parameter_axis(units, "stiffness_scale")[0] == "stiffness_scale"


def test_simulate_writes_each_mesh_force_in_newtons_at_every_sample(tmp_path, capsys):
    """`simulate --units physical` adds each mesh's dynamic force in N per sample
    (``<coordinate>_force_N``).  Reference, statics: on a periodic orbit the mean of each
    mesh's force over whole periods is its static load (the accelerations average to
    zero), and with balanced torques pinion p's mesh carries T_p / (r_b,p cos beta_b);
    the linear scene stays in contact, so its orbit is period-1 after the transient."""
    from gearsym.solver.units import Units
    from scipy.io import loadmat

    torques = {"torque_Nm_p": 500.0, "torque_Nm_q": 250.0, "torque_Nm_g": -1500.0}
    sets = [a for k, v in torques.items() for a in ("--set", f"{k}={v}")]
    argv = ["simulate", "reference-linear", *sets, "--transient", "400", "--periods", "20"]
    code, said = _run([*argv, "--units", "physical", "--out", str(tmp_path)], capsys)
    assert code == 0 and "period-1" in said
    table = _csv(tmp_path / "point.csv")
    system = gearsym.load("reference-linear", **torques)
    arm = system.module.STRUCTURE["incidence"][0][0]  # r_b,p cos(beta_b), m
    assert np.mean(table["u_force_N"]) == pytest.approx(500.0 / arm, rel=1e-6)
    assert np.mean(table["v_force_N"]) == pytest.approx(250.0 / arm, rel=1e-6)
    # the column is the model's mesh force at the sample times k_m b, and its extremes
    # are the range the block states
    units = Units.of(system)
    x = np.array([table[s] for s in system.states])
    model = system.module.mesh_force(table["tau"], x, system.p)
    assert np.allclose(table["u_force_N"], units.force("u", 1.0) * model[0], rtol=1e-9, atol=0)
    doc = json.loads((tmp_path / "point.json").read_text(encoding="utf-8"))
    stated = doc["in_units"]["coordinates"]["v"]["force_range"]
    assert stated == pytest.approx([table["v_force_N"].min(), table["v_force_N"].max()], rel=1e-9)
    assert "v_force_N" in doc["in_units"]["columns"]
    mat = loadmat(tmp_path / "point.mat", simplify_cells=True)
    assert np.allclose(mat["table"]["u_force_N"], table["u_force_N"], rtol=1e-15, atol=0)
