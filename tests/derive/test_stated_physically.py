"""A scene states its operating point in the engineer's units (issue 25, point 1).

``speed_rpm`` and ``torque_Nm_<gear>`` in a scene's ``[parameters]`` take the place of
``omega`` and ``[loads]``; they were ignored without a word (the model ran at the omega of
a default speed, a stray key passed).  The reference: the same gears loaded as the
shipped dead-zone scene and given the same speed and torques at run time (``with_values``,
the generated ``parameters()``'s closed forms, the audit page's) -- the model derived from
the statement has the same parameter vector; and the mesh frequency is z n / 60.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from gearsym.derive.input.scene import builtin_root
from gearsym.resolve import load

SCENE = """[scene]
name = "light-physical"
topology = "{topology}"
description = "the dead-zone scene's gears at a stated speed and torques"

[features]
stiffness_harmonics = 3
backlash = "dead-zone"
transmission_error = true
mesh_phase = true
damping_coupling = true

[parameters]
speed_rpm = 3000
damping_ratio = 0.03
torque_Nm_p = 400
torque_Nm_q = -50
torque_Nm_g = -700
"""


def _write(tmp_path, text: str):
    path = tmp_path / "physical.toml"
    topology = builtin_root() / "topologies" / "diso.toml"
    path.write_text(text.format(topology=topology.as_posix()), encoding="utf-8")
    return path


def test_a_scene_stated_in_rpm_and_newton_metres_is_the_model_set_to_them(tmp_path):
    stated = load(str(_write(tmp_path, SCENE)))
    # the shipped scene of the same gears and features, its loads read the same way
    # (q braking: the topology's own reading of the torques' signs)
    ref = load("reference-dead-zone", load_reading="q-braking").with_values(
        speed_rpm=3000.0, torque_Nm_p=400.0, torque_Nm_q=-50.0, torque_Nm_g=-700.0
    )
    omega_n = stated.module.OMEGA_N
    assert omega_n == pytest.approx(ref.module.OMEGA_N, rel=1e-12)
    assert stated.parameter("omega") == pytest.approx(
        2 * np.pi * (50 * 3000 / 60) / omega_n, rel=1e-9
    )
    for name in ("omega", "f_u", "f_v", "kappa_u_v", "xi_u_v", "E_u_1", "phi_v"):
        assert stated.parameter(name) == pytest.approx(ref.parameter(name), rel=1e-9), name


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (
            ("speed_rpm = 3000", "speed_rpm = 3000\nomega = 0.5"),
            "stated beside omega, which states the speed too; keep one",
        ),
        (("torque_Nm_g = -700", "torque_Nm_g = -700\nbogus_key = 5"), "bogus_key: is not a"),
        (("torque_Nm_g = -700", "torque_Nm_x = -700"), "torque_Nm_x: names no gear"),
        (("speed_rpm = 3000", "speed_rpm = -1000"), "give a speed above 0 rpm"),
        (
            ("torque_Nm_g = -700", "torque_Nm_g = -700\n\n[loads]\nu = 0.1\nv = 0.01"),
            "and [loads] both state the loads",
        ),
    ],
)
def test_what_a_scene_cannot_state_is_refused_in_one_line(tmp_path, change, words):
    path = _write(tmp_path, SCENE.replace(*change))
    done = subprocess.run(
        [sys.executable, "-m", "gearsym", "derive", str(path), "--dry-run"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0], done.stderr


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (
            ["sweep", "reference-light", "--param", "speed_rpm", "--range", "1000:3000:3"]
            + ["--set", "omega=0.3"],
            "--set omega=0.3 and --param speed_rpm state one quantity",
        ),
        (
            ["sweep", "reference-light", "--param", "half_backlash_um_pg", "--range", "40:60:3"]
            + ["--set", "half_backlash_um=50"],
            "state one quantity (half_backlash_um and half_backlash_um_pg)",
        ),
    ],
)
def test_a_set_value_the_sweep_states_under_another_name_is_refused(tmp_path, argv, words):
    """The helper's find: a sweep over the speed with --set omega ran (the sweep's value
    won) and recorded the omega beside it; one quantity under two names is refused, as
    a map refuses it.  Another quantity beside the swept one is not (a torque of q while
    p's is swept)."""
    done = subprocess.run(
        [sys.executable, "-m", "gearsym", *argv, "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2 and words in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_a_continuation_over_the_speed_steps_by_its_range(tmp_path):
    """``continue --param speed_rpm`` with the default step: it stepped 0.02 rpm (omega's
    step) and stopped at its 400-point cap 32 rpm in (the second new-user pass); the step
    now follows the range (0.02 of it), so the branch reaches --to."""
    import json

    out = tmp_path / "c"
    done = subprocess.run(
        [sys.executable, "-m", "gearsym", "continue", "reference-light", "--param"]
        + ["speed_rpm", "--from", "1000", "--to", "1200", "--out", str(out)],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    branches = json.loads((out / "branches.json").read_text(encoding="utf-8"))["branches"]
    reached = max(max(b["values"]) for b in branches)
    assert reached == pytest.approx(1200.0, abs=1e-6)


def test_each_gears_torque_is_kept_when_another_is_set():
    """Setting p's torque dropped q's, set before it (both replace the non-dimensional
    loads, which made them one quantity to ``System._kept``): a sweep over p's torque with
    --set of q's ran at q's default torque.  The reference: the model given both at once."""
    light = load("reference-light")
    both = light.with_values(torque_Nm_q=-40.0, torque_Nm_p=300.0)
    one_by_one = light.with_values(torque_Nm_q=-40.0).with_values(torque_Nm_p=300.0)
    assert one_by_one.values == {"torque_Nm_q": -40.0, "torque_Nm_p": 300.0}
    np.testing.assert_array_equal(one_by_one.p, both.p)
    # one quantity under two names: the later wins, as before
    assert light.with_values(speed_rpm=2000.0).with_values(omega=0.4).values == {"omega": 0.4}
    assert light.with_values(f1=0.2).with_values(torque_Nm_p=300.0).values == {"torque_Nm_p": 300.0}
