"""A gear train with closed loops (a back-to-back rig), against references of its own:

* the locked-in torque of the loop: the closed form of going round it, the assembly twist
  shared among the shafts' twists and the meshes' deflections referred to the pinion
  shaft, the backlash taken up first (``derive/equations/train.py``'s docstring; written
  out here from the file's numbers);
* a perturbed, damped loop settles on that torque after 1,000 mesh periods, with no drift
  of the load it was assembled with;
* undamped, it conserves its energy (kinetic, elastic, and the work of the locked-in
  load) over 1,000 periods;
* linearised on its loaded equilibrium, its natural frequencies are those of M and K
  assembled by hand in the bodies' rotations (written for the test, no gearsym import);
* what cannot be a train is refused in one line: a locked loop, unbalanced torques,
  a mesh whose teeth and base radii disagree, bodies in two unjoined groups.
"""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys

import numpy as np
import pytest
from gearsym.derive.input.reader import InputError
from gearsym.derive.input.scene import resolve_target
from gearsym.resolve import planetary_system
from gearsym.solver.integrate import simulate

RIG = resolve_target("back-to-back-rig")
TEXT = RIG.read_text(encoding="utf-8")
# the rig's numbers, as its file states them; the base radii as the model takes them: the
# teeth times the base pitch the two gears share (their mean r / z)
PITCH = (33.8289e-3 / 16 + 50.7434e-3 / 24) / 2
R_P, R_W = 16 * PITCH, 24 * PITCH  # m
I_P, I_W = 5.0e-4, 2.5e-3  # kg m^2
K_MESH, B = 4.0e8, 50e-6  # N/m, m
K_WHEEL, K_PINION = 1.212e5, 1.256e4  # N m/rad
TWIST = math.radians(1.5)


def closed_form_torque(twist: float = TWIST) -> float:
    """The pinion shaft's locked-in torque:
    T (1/k_1 + i^2/k_2 + 2/(k_m r_p^2)) = twist - 2 b / r_p."""
    i = R_W / R_P
    compliance = 1 / K_PINION + i**2 / K_WHEEL + 2 / (K_MESH * R_P**2)
    return (twist - 2 * B / R_P) / compliance


def variant(tmp_path, name: str, text: str):
    path = tmp_path / f"{name}.toml"
    path.write_text(text.replace('"back-to-back-rig"', f'"{name}"'), encoding="utf-8")
    return path


def steady(tmp_path, name: str, zeta: str):
    """The rig without stiffness variation, at damping ratio ``zeta``."""
    text = re.sub(r"\nvariation = .*\n", "\n", TEXT)
    text = text.replace("damping_ratio = 0.03", f"damping_ratio = {zeta}")
    return planetary_system(variant(tmp_path, name, text))


def torques(system, x, f: float = 1.0) -> dict:
    m = len(system.module.COORDINATES)
    return {
        k: v["stiffness_Nm_per_rad"]
        * (
            np.tensordot(np.asarray(v["row"]), np.asarray(x)[:m], axes=1)
            - f * v["assembly_twist_rad"]
        )
        for k, v in system.module.SHAFTS.items()
    }


def test_the_loop_carries_the_closed_form_locked_in_torque():
    system = planetary_system(RIG)
    x = system.module.static_state(system.p)
    assert np.max(np.abs(system.module.rhs(0.0, x, system.p)[3:])) > 0  # the variation acts
    T = closed_form_torque()
    t = torques(system, x)
    assert abs(t["pinion_shaft"]) == pytest.approx(T, rel=1e-10)
    assert abs(t["wheel_shaft"]) == pytest.approx(T * R_W / R_P, rel=1e-10)
    # each mesh carries T / r_p along its line of action, beyond its backlash
    for u in system.module.mesh_deflections(x).values():
        assert abs(u) == pytest.approx(1 + T / (R_P * K_MESH * B), rel=1e-10)
    # a rig twisted less than its backlash takes up carries nothing: its shafts untwisted,
    # no mesh pressed beyond its edge (one of many such rests, or None: not unique)
    slack = planetary_system(RIG, load_factor=0.5 * (2 * B / R_P) / TWIST)
    rest = slack.module.static_state(slack.p)
    if rest is not None:
        assert (
            max(abs(v) for v in torques(slack, rest, 0.5 * (2 * B / R_P) / TWIST).values())
            < 1e-9 * T
        )
        assert all(abs(u) <= 1 + 1e-9 for u in slack.module.mesh_deflections(rest).values())


def test_a_perturbed_damped_loop_settles_on_the_locked_in_torque(tmp_path):
    system = steady(tmp_path, "rig-damped", "0.03")
    x0 = system.module.static_state(system.p).copy()
    m = len(system.module.COORDINATES)
    x0[:m] += 0.2 * np.array([1.0, -1.0, 0.5])[:m]  # every mesh stays in contact
    tr = simulate(system, x0, transient=0, periods=1000, samples_per_period=4, rtol=1e-11)
    assert tr.status == "ok"
    end = torques(system, tr.x[:, -1])
    T = closed_form_torque()
    assert abs(abs(end["pinion_shaft"]) - T) < 1e-8 * T
    assert abs(abs(end["wheel_shaft"]) - T * R_W / R_P) < 1e-8 * T


def test_undamped_the_loop_conserves_its_energy_over_1000_periods(tmp_path):
    system = steady(tmp_path, "rig-undamped", "0.0")
    from gearsym.derive.equations.train import derive_train, derive_train_dynamics
    from gearsym.derive.input.train import load_train

    dyn = derive_train_dynamics(derive_train(load_train(tmp_path / "rig-undamped.toml")))
    st = dyn.structure
    r = st.incidence[0]
    m_ref = 1.0 / np.sum(r**2 / np.asarray(st.mass))
    A = dyn.transform.T @ np.diag(st.mass) @ dyn.transform / m_ref
    x0 = system.module.static_state(system.p)
    m = len(system.module.COORDINATES)
    sides = {k: np.sign(u) for k, u in system.module.mesh_deflections(x0).items()}
    gaps = sum(
        sides[k] * v["weight"] * np.asarray(v["row"]) for k, v in system.module.MESHES.items()
    )
    load = system.p[1] * dyn.load_direction

    def energy(X):
        y, v = X[:m], X[m:]
        return (
            0.5 * np.einsum("i...,ij,j...->...", v, A, v)
            + 0.5 * np.einsum("i...,ij,j...->...", y, dyn.stiffness, y)
            - np.tensordot(load + gaps, y, axes=1)
        )

    E0 = energy(x0)
    x0 = x0.copy()
    x0[m:] = 0.01 * np.linspace(1.0, -1.0, m)  # small: every mesh stays in contact
    tr = simulate(
        system, x0, transient=0, periods=1000, samples_per_period=4, rtol=1e-11, atol=1e-13
    )
    assert tr.status == "ok"
    u = system.module.mesh_deflections(tr.x)
    assert all(np.all(np.abs(v) > 1) and np.all(np.sign(v) == sides[k]) for k, v in u.items())
    E = energy(tr.x) - E0
    assert np.max(np.abs(E - E[0])) < 1e-7 * E[0]


def by_hand() -> tuple[np.ndarray, np.ndarray]:
    """M and K in the rotations (test pinion, test wheel, slave wheel, slave pinion), every
    rotation counted in one sense: an external mesh strains r_a theta_a + r_b theta_b."""
    M = np.diag([I_P, I_W, I_W, I_P])
    K = np.zeros((4, 4))
    for i, j, ri, rj in ((0, 1, R_P, R_W), (3, 2, R_P, R_W)):  # the two meshes
        K[np.ix_([i, j], [i, j])] += K_MESH * np.outer([ri, rj], [ri, rj])
    for i, j, k in ((1, 2, K_WHEEL), (3, 0, K_PINION)):  # the two shafts
        K[np.ix_([i, j], [i, j])] += k * np.array([[1.0, -1.0], [-1.0, 1.0]])
    return M, K


def test_linearised_it_has_the_hand_assemblys_frequencies(tmp_path):
    from gearsym.solver.analysis.modes import modes

    system = steady(tmp_path, "rig-linear", "0.0")
    M, K = by_hand()
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    assert abs(w2[0]) < 1e-9 * w2[-1]  # one rigid-body rotation
    hand = hand_frequencies()
    x = system.module.static_state(system.p)
    lam = np.linalg.eigvals(system.module.jacobian(0.0, x, system.p))
    ours = np.sort(np.abs(lam.imag))[::2] * system.module.OMEGA_N / (2 * np.pi)
    assert np.max(np.abs(ours - hand) / hand) < 1e-9
    listed = [m.frequency_hz for m in modes(system).modes if m.label != "rigid-body"]
    assert np.max(np.abs(np.array(listed) - hand) / hand) < 1e-9


def hand_frequencies() -> np.ndarray:
    """The rig's elastic natural frequencies (Hz) from :func:`by_hand`."""
    M, K = by_hand()
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    return np.sqrt(w2[1:]) / (2 * np.pi)


def test_a_train_without_its_dynamics_table_has_its_modes(tmp_path):
    """``gearsym modes`` of the rig's file without ``[train.dynamics]`` (no operating
    point, so no nonlinear model): the natural frequencies of M and K assembled by hand,
    no ratio to a mesh frequency, and over ``--speeds`` the speeds where a harmonic h of
    the mesh frequency z n / 60 (z = 16, the test pinion's) meets a mode, written out here
    from those frequencies; ``--plot`` without ``--speeds`` is refused in one line."""
    import gearsym

    path = variant(tmp_path, "rig-modes", re.sub(r"\[train\.dynamics\][^\[]*$", "", TEXT))
    run = subprocess.run(
        [sys.executable, "-m", "gearsym", "modes", str(path), "--json", "--speeds", "0:30000"],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    data = json.loads(run.stdout)
    assert data["mesh_frequency_hz"] is None
    freq = {m["index"]: m["frequency_hz"] for m in data["modes"] if m["label"] != "rigid-body"}
    assert all(m["over_mesh_frequency"] is None for m in data["modes"])
    hand = hand_frequencies()
    assert np.max(np.abs(np.array(list(freq.values())) - hand) / hand) < 1e-9
    expected = {
        (i, h, round(60 * f / (16 * h), 6))
        for i, f in zip(freq, hand, strict=True)
        for h in (1, 2, 3)
        if 60 * f / (16 * h) <= 30000
    }
    got = {(r["mode"], r["harmonic"], round(r["speed_rpm"], 6)) for r in data["resonances"]}
    assert got == expected and len(got) > 3
    api = gearsym.planetary.modes(path)
    assert [m.frequency_hz for m in api.modes] == [m["frequency_hz"] for m in data["modes"]]
    run = subprocess.run(
        [sys.executable, "-m", "gearsym", "modes", str(path), "--plot", str(tmp_path / "c.png")],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 2 and "--speeds LO:HI" in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1


def test_a_trains_modes_are_the_same_with_and_without_its_nonlinear_model():
    """The rig's modes from its file alone (``gearsym.planetary.modes``: the linear model
    derived, no code generated) and from the generated nonlinear model's ``STRUCTURE``
    (``gearsym.modes``): the same frequencies and the same mesh frequency (400 Hz)."""
    import gearsym

    alone = gearsym.planetary.modes("back-to-back-rig")
    generated = gearsym.modes(planetary_system(RIG))
    assert alone.mesh_frequency_hz == pytest.approx(generated.mesh_frequency_hz, rel=1e-12)
    a = np.array([m.frequency_hz for m in alone.modes])
    g = np.array([m.frequency_hz for m in generated.modes])
    assert np.max(np.abs(a - g)) < 1e-9 * a.max()
    assert [m.label for m in alone.modes] == [m.label for m in generated.modes]


@pytest.mark.parametrize(
    "change, words",
    [
        # the slave pair 17/24 (radii to match): the loop's ratios do not close
        (
            lambda t: t.replace(
                "teeth = 16\nbase_radius_mm = 33.8289\ninertia_kg_m2 = 5.0e-4\n"
                '\n[[train.mesh]]\nid = "test"',
                "teeth = 17\nbase_radius_mm = 35.9432\ninertia_kg_m2 = 5.0e-4\n"
                '\n[[train.mesh]]\nid = "test"',
            ),
            "cannot turn",
        ),
        (lambda t: t.replace("teeth = 24", "teeth = 25", 1), "pass teeth at different rates"),
        (
            lambda t: t + '\n[[train.torque]]\nbody = "test_wheel"\ntorque_Nm = 10\n',
            "do not balance",
        ),
        (lambda t: re.sub(r"\[train\.dynamics\][^\[]*$", "", t), "[train.dynamics]"),
        # a fifth body no link joins to the others
        (
            lambda t: t.replace(
                "[[train.mesh]]",
                '[[train.body]]\nid = "spare"\nteeth = 20\nbase_radius_mm = 40\n'
                "inertia_kg_m2 = 1e-3\n\n[[train.mesh]]",
                1,
            ),
            "groups that no mesh or shaft joins (test_pinion",
        ),
        (lambda t: t.replace('id = "test"', 'id = "a b"', 1), "must start with a letter"),
    ],
)
def test_what_cannot_be_a_train_is_refused_in_one_line(tmp_path, change, words):
    path = variant(tmp_path, "rig-bad", change(TEXT))
    with pytest.raises(InputError, match=re.escape(words)):
        planetary_system(path)
    run = subprocess.run(
        [sys.executable, "-m", "gearsym", "simulate", str(path)],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 2 and words in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1


def test_simulate_prints_each_shafts_torque_and_each_meshs_contact():
    run = subprocess.run(
        [sys.executable, "-m", "gearsym", "simulate", "back-to-back-rig", "--json"],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    data = json.loads(run.stdout)
    assert set(data["shafts"]) == {"wheel_shaft", "pinion_shaft"}
    mean = abs(data["shafts"]["pinion_shaft"]["mean_Nm"])
    assert mean == pytest.approx(closed_form_torque(), rel=0.01)  # the variation moves it
    assert all(row["apart"] == 0.0 for row in data["meshes"].values())


def test_the_audit_page_states_the_loop_and_its_rigid_rotation():
    from gearsym.derive.build import build_files

    page = build_files([RIG]).files["docs/derivation/back_to_back_rig.md"]
    assert "1 independent closed loop" in page
    assert "Rigid-body modes (from the teeth, going round the graph): **1**" in page
    # the wheels turn at 16/24 of the pinions' speed, the other way (exact, from the teeth)
    assert page.count("| -2/3 |") == 2 and page.count("| +1 |") == 2
    assert "`u_2/r2 − u_3/r3`" in page  # the wheel shaft's twist


LOOP = """
[topology]
name = "three-mesh-loop"
description = "a ring pinion and a chain of three gears closed by two shafts"

[[train.body]]
id = "pinion"
teeth = 20
base_radius_mm = 18.8
inertia_kg_m2 = 1.0e-4

[[train.body]]
id = "ring"
teeth = 60
base_radius_mm = 56.4
inertia_kg_m2 = 8.0e-3

[[train.body]]
id = "wheel"
teeth = 30
base_radius_mm = 28.2
inertia_kg_m2 = 1.5e-3

[[train.body]]
id = "idler"
teeth = 10
base_radius_mm = 9.4
inertia_kg_m2 = 2.0e-5

[[train.body]]
id = "last"
teeth = 10
base_radius_mm = 9.4
inertia_kg_m2 = 3.0e-5

[[train.mesh]]
id = "wi"
gears = ["wheel", "idler"]
stiffness_N_per_m = 3.0e8
half_backlash_um = 40
variation = [[0.1, 0.05], [0.02, -0.03]]

[[train.mesh]]
id = "il"
gears = ["idler", "last"]
stiffness_N_per_m = 2.0e8
half_backlash_um = 30
variation = [[0.08, 0.0]]
phase = 0.3

[[train.mesh]]
id = "pr"
gears = ["pinion", "ring"]
internal = true
stiffness_N_per_m = 5.0e8
half_backlash_um = 60
variation = [[0.05, 0.02]]
phase = 0.25

[[train.shaft]]
id = "ring_wheel"
bodies = ["ring", "wheel"]
torsional_Nm_per_rad = 5.0e4

[[train.shaft]]
id = "last_pinion"
bodies = ["last", "pinion"]
torsional_Nm_per_rad = 2.0e3
assembly_twist_deg = 2.0

[[train.torque]]
body = "pinion"
torque_Nm = 30

[[train.torque]]
body = "wheel"
torque_Nm = -90

[train.dynamics]
mesh_frequency_hz = 500
damping_ratio = 0.05
"""


def test_a_loop_with_an_internal_mesh_torques_and_multiples_has_newtons_law(tmp_path):
    """The model's accelerations against Newton's law written here in the rotations theta
    (no gearsym import in it): an internal mesh at twice the first mesh's frequency (the
    pinion's 20 teeth at 3 times the wheel's speed against the wheel's 30), phases, balanced
    torques and an assembly twist, going round a loop of three meshes and two shafts."""
    path = tmp_path / "loop.toml"
    path.write_text(LOOP, encoding="utf-8")
    system = planetary_system(path)
    mod = system.module
    import tomllib

    d = tomllib.loads(LOOP)["train"]
    ids = [b["id"] for b in d["body"]]
    ix = {k: i for i, k in enumerate(ids)}
    n = len(ids)
    inertia = np.array([b["inertia_kg_m2"] for b in d["body"]])
    z = np.array([b["teeth"] for b in d["body"]], dtype=float)
    r0 = np.array([b["base_radius_mm"] * 1e-3 for b in d["body"]])
    # radii as the model takes them: teeth x the mean base pitch of the gears meshing together
    r = z.copy()
    for group in (["wheel", "idler", "last"], ["pinion", "ring"]):
        p = np.mean([r0[ix[g]] / z[ix[g]] for g in group])
        for g in group:
            r[ix[g]] = p * z[ix[g]]
    # speeds of the rigid rotation: wheel 1, idler -3, last 3, pinion = last, ring 20/60 of it
    speed = np.array([3.0, 1.0, 1.0, -3.0, 3.0])
    tau = np.zeros(n)
    for t in d["torque"]:
        tau[ix[t["body"]]] += t["torque_Nm"]
    assert abs(tau @ speed) < 1e-12  # the file's torques balance: 30 x 3 - 90 x 1
    first = d["mesh"][0]
    a0, b0 = ix[first["gears"][0]], ix[first["gears"][1]]
    m_ref = 1 / (r[a0] ** 2 / inertia[a0] + r[b0] ** 2 / inertia[b0])
    wn = math.sqrt(first["stiffness_N_per_m"] / m_ref)
    b_ref = first["half_backlash_um"] * 1e-6
    assert mod.OMEGA_N == pytest.approx(wn, rel=1e-12)
    # each mesh's frequency over the first's: its first gear's teeth x its speed
    h = [z[ix[m["gears"][0]]] * abs(speed[ix[m["gears"][0]]]) / 30.0 for m in d["mesh"]]
    assert h == [1.0, 1.0, 2.0]

    def accelerations(th, dth, t, f, zeta, w):
        F = f * tau.copy()
        for j, m in enumerate(d["mesh"]):
            a, b = ix[m["gears"][0]], ix[m["gears"][1]]
            s = -1.0 if m.get("internal") else 1.0
            k, gap = m["stiffness_N_per_m"], m["half_backlash_um"] * 1e-6
            delta = r[a] * th[a] + s * r[b] * th[b]
            rate = r[a] * dth[a] + s * r[b] * dth[b]
            x = h[j] * w * t - 2 * math.pi * m.get("phase", 0.0)
            v = sum(
                c * math.cos(l_ * x) + q * math.sin(l_ * x)
                for l_, (c, q) in enumerate(m.get("variation", []), start=1)
            )
            dead = delta - gap if delta > gap else (delta + gap if delta < -gap else 0.0)
            mass = 1 / (r[a] ** 2 / inertia[a] + r[b] ** 2 / inertia[b])
            P = k * (1 + v) * dead + 2 * zeta * math.sqrt(k * mass) * rate
            F[a] -= P * r[a]
            F[b] -= P * s * r[b]
        for sh in d["shaft"]:
            a, b = ix[sh["bodies"][0]], ix[sh["bodies"][1]]
            k = sh["torsional_Nm_per_rad"]
            twist = math.radians(sh.get("assembly_twist_deg", 0.0))
            mass = 1 / (1 / inertia[a] + 1 / inertia[b])
            T = k * (th[a] - th[b] - f * twist) + 2 * zeta * math.sqrt(k * mass) * (dth[a] - dth[b])
            F[a] -= T
            F[b] += T
        return F / inertia

    phys = [f"u_{i + 1}" for i in range(n)]
    pivot = phys.index(mod.PIVOT)
    rng = np.random.default_rng(7)
    m = len(mod.COORDINATES)

    def theta(ybar):  # the module's coordinates to rotations; the pivot from zero momentum
        u = np.zeros(n)
        for c, v in zip(mod.COORDINATES, ybar, strict=True):
            u[phys.index(c)] = v * b_ref
        th = u / r
        th[pivot] = -sum(inertia[i] * speed[i] * th[i] for i in range(n) if i != pivot) / (
            inertia[pivot] * speed[pivot]
        )
        return th

    worst = 0.0
    for _ in range(20):
        x = rng.normal(size=2 * m) * 2.0
        tau_ = rng.uniform(0.0, 50.0)
        p = system.p * np.array([rng.uniform(0.5, 2), rng.uniform(0.1, 2), rng.uniform(0.5, 2)])
        ours = accelerations(theta(x[:m]), theta(x[m:]) * wn, tau_ / wn, p[1], p[2], p[0] * wn)
        ours = ours * r / (b_ref * wn**2)
        theirs = mod.rhs(tau_, x, p)[m:]
        want = np.array([ours[phys.index(c)] for c in mod.COORDINATES])
        worst = max(worst, float(np.max(np.abs(theirs - want)) / np.max(np.abs(want))))
    assert worst < 1e-10


def test_a_cached_trains_model_loads_without_sympy():
    """Deriving needs SymPy; running a model already in the cache must not pay for it."""
    planetary_system(RIG)  # derived into the cache, if it was not
    code = (
        "import sys; from gearsym.resolve import load; load('back-to-back-rig'); "
        "print('sympy' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


@pytest.mark.slow
@pytest.mark.parametrize(
    "name, values",
    [("back-to-back-rig", {"mesh_frequency_hz": 5000.0}), ("lin-parker-1999-3-backlash", {})],
)
def test_the_compiled_flow_agrees_with_the_event_loops(name, values, monkeypatch):
    """Continuation and shooting take the compiled engine's flow and variational
    monodromy where the kinks are not located; against SciPy's DOP853 through the event
    loop (the route they took before, in Python) over two periods from the loaded
    equilibrium, at the flow map's tolerances."""
    from gearsym.resolve import load
    from gearsym.solver.periodic.flow import FlowMap

    system = load(name, **values)
    x0 = system.module.static_state(system.p)
    x0 = x0 + 0.05 * np.sin(np.arange(x0.size))  # off the equilibrium: a real transient
    T = 2 * system.period
    compiled = FlowMap(system).with_jacobian(x0, T, 0.0, method="variational")
    monkeypatch.setattr(FlowMap, "_compiled", lambda *args: None)
    python = FlowMap(system).with_jacobian(x0, T, 0.0, method="variational")
    scale = np.max(np.abs(python[1]))
    # measured: 1.1e-13 and 1.4e-13 in the states, 2.6e-13 and 2.2e-10 in the monodromy
    assert np.max(np.abs(compiled[0] - python[0])) < 1e-10 * max(1.0, np.max(np.abs(x0)))
    assert np.max(np.abs(compiled[1] - python[1])) < 1e-8 * scale
    assert compiled[2] == pytest.approx(python[2], rel=1e-9)  # int trace J: constant trace


def test_a_transmission_error_drives_the_linear_response_of_the_hand_assembly(tmp_path):
    """A transmission error on the test mesh, e = 2 um cos(w t + 30 deg), no stiffness
    variation, the teeth in contact throughout (the model then linear): the steady
    response of the test mesh's deflection against the complex amplitude solved from the
    hand assembly, (K - w^2 M + i w C) theta = -(k + i w c) e r, every spring's damper
    c = 2 zeta sqrt(k m) on the mass its deflection sees."""
    text = re.sub(r"\nvariation = .*\n", "\n", TEXT)
    text = text.replace(
        'half_backlash_um = 50\n\n[[train.mesh]]\nid = "slave"',
        "half_backlash_um = 50\ntransmission_error = { amplitude_um = [2.0], phase_deg = [30.0] }"
        '\n\n[[train.mesh]]\nid = "slave"',
    )
    assert "transmission_error" in text
    path = variant(tmp_path, "rig-te", text)
    system = planetary_system(path, mesh_frequency_hz=900.0)
    x0 = system.module.static_state(system.p)
    tr = simulate(system, x0, transient=300, periods=4, samples_per_period=64, rtol=1e-11)
    assert tr.status == "ok"
    u = system.module.mesh_deflections(tr.x)
    assert all(np.all(np.abs(v) > 1) for v in u.values())  # in contact: linear
    # the first harmonic of the test mesh's geometric deflection (m), over 4 periods
    delta = np.asarray(u["test"])[: 4 * 64] * B  # whole periods
    tau = np.asarray(tr.t)[: 4 * 64]
    w = system.p[0]  # per tau
    ours = 2 * np.mean(delta * np.exp(-1j * w * tau))
    # by hand, in the rotations (test pinion, test wheel, slave wheel, slave pinion)
    M, K = by_hand()
    rows = {
        "test": (np.array([R_P, R_W, 0, 0]), K_MESH),
        "slave": (np.array([0, 0, R_W, R_P]), K_MESH),
        "wheel": (np.array([0, 1.0, -1.0, 0]), K_WHEEL),
        "pinion": (np.array([-1.0, 0, 0, 1.0]), K_PINION),
    }
    zeta, Minv = 0.03, np.linalg.inv(M)
    C = sum(2 * zeta * np.sqrt(k / (r @ Minv @ r)) * np.outer(r, r) for r, k in rows.values())
    r, k = rows["test"]
    c = 2 * zeta * np.sqrt(k / (r @ Minv @ r))
    W = 2 * np.pi * 900.0  # rad/s
    # excess material presses the loaded flank: the test mesh's is delta < 0 in the rig
    flank = np.sign(system.module.mesh_deflections(x0)["test"])
    assert flank == -1
    E = flank * 2e-6 * np.exp(1j * math.radians(30.0))
    theta = np.linalg.solve(K - W**2 * M + 1j * W * C, -(k + 1j * W * c) * E * r)
    hand = r @ theta
    assert abs(ours - hand) < 1e-8 * abs(hand)  # measured 2.3e-11


def test_one_transmission_error_on_both_pairs_keeps_the_rigs_mirror_symmetry(tmp_path):
    """The slave pair is the test pair run half a mesh period later and loaded on the other
    flank (the loop's one sense of counting): with the same transmission error on both,
    excess material on each loaded flank, the slave mesh's deflection is the test mesh's
    half a period on, negated (the stiffness variation kept)."""
    te = "transmission_error = { amplitude_um = [5.0, 1.0], phase_deg = [0.0, 40.0] }\n"
    text = TEXT.replace("half_backlash_um = 50\n", "half_backlash_um = 50\n" + te)
    assert text.count("transmission_error") == 2
    system = planetary_system(variant(tmp_path, "rig-te-both", text), mesh_frequency_hz=900.0)
    x0 = system.module.static_state(system.p)
    tr = simulate(system, x0, transient=300, periods=2, samples_per_period=64, rtol=1e-11)
    assert tr.status == "ok"
    u = system.module.mesh_deflections(tr.x)
    test, slave = np.asarray(u["test"]), np.asarray(u["slave"])
    assert np.ptp(test) > 0.05  # the error moves it
    assert np.max(np.abs(test[:64] + slave[32:96])) < 1e-7


def test_a_value_stated_again_under_another_name_replaces_the_first():
    """with_values: the later value wins whatever its name (a continuation in omega of a
    system loaded at a mesh frequency), for a train and for a tree model alike; in one
    call both names are refused."""
    from gearsym.resolve import load

    rig = load("back-to-back-rig", mesh_frequency_hz=5000.0)
    assert rig.with_values(omega=0.5).p[0] == 0.5
    assert rig.parameters_with(omega=0.25)[0] == 0.25
    tree = load("reference-light", speed_rpm=3000.0)
    assert tree.with_values(omega=0.5).parameter("omega") == 0.5
    with pytest.raises(ValueError, match="one quantity"):
        load("back-to-back-rig", mesh_frequency_hz=5000.0, omega=0.5)


def test_a_response_over_the_mesh_frequency_in_hz_is_drawn_in_micrometres():
    """--units physical over a body model's mesh_frequency_hz (already Hz): the amplitudes
    in µm (times the half backlash), the axis as given."""
    import gearsym
    from gearsym.solver.plots_response import frequency_response_figure

    system = gearsym.planetary.dynamics("back-to-back-rig")
    resp = gearsym.frequency_response(
        system, "mesh_frequency_hz", 4000.0, 4400.0, points=3, methods=("shooting",)
    )
    fig = frequency_response_figure(resp, physical=True)
    ax = fig.axes[0]
    assert "(µm)" in ax.get_ylabel() and fig.axes[-1].get_xlabel() == "mesh frequency (Hz)"
    line = next(ln for ln in ax.get_lines() if len(ln.get_xdata()) > 1)
    curve = resp.curves[0]
    c = system.coordinates[0]
    assert np.allclose(line.get_xdata(), curve.values[: len(line.get_xdata())])
    assert np.allclose(
        line.get_ydata(), curve.stats[c]["amplitude"][: len(line.get_ydata())] * B * 1e6
    )
