"""The exact dead zone is a scene's default backlash; the study's polynomial is stated.

References: the dead zone's contract is ``g = 0`` on ``[-1, 1]`` with kinks at ``+-1``
(``derive/mesh/backlash.py``, ``DeadZone``); the polynomial's zeros come from
``derive/mesh/force_sign.py``'s ``polynomial_sign`` on the scene's own coefficients (exact
root isolation in the derive layer), an independent route to the note's numbers, which
the solver reads from the generated module's contract.
"""

import re

import pytest
from gearsym.cli import _notes, main
from gearsym.cli._system import system_of
from gearsym.derive import load_target
from gearsym.derive.mesh.force_sign import polynomial_sign
from gearsym.resolve import module_for
from gearsym.solver.system import System

SCENE = """
[scene]
name = "my-pair"
topology = "siso"
description = "a user's own scene that does not name a backlash model"
{features}
[parameters]
omega = 0.5
damping_ratio = 0.05
"""


@pytest.mark.parametrize(
    "features",
    ["[features]\nstiffness_harmonics = 0\n", ""],
    ids=["features-without-backlash", "no-features-table"],
)
def test_a_users_scene_without_backlash_derives_the_dead_zone(tmp_path, features):
    path = tmp_path / "my-pair.toml"
    path.write_text(SCENE.format(features=features), encoding="utf-8")
    module = module_for(path)
    contract = module.CONTRACT
    assert module.FEATURES["backlash"] == "dead-zone"
    assert contract["piecewise"] is True
    assert contract["contact"] == {"u": (-1.0, 1.0)}
    assert contract["force_sign"]["u"]["zeros"] == (-1.0, 1.0)
    assert contract["force_sign"]["u"]["zero_between"] is True
    assert sorted(c for _, c in contract["switching_surfaces"]) == [-1.0, 1.0]
    assert System.load(module).backlash_note is None


@pytest.mark.parametrize("name", ["reference-light", "reference-heavy", "diso-bearings-light"])
def test_the_reference_scenes_still_state_the_polynomial(root, name):
    scene = load_target(root / "scenes" / f"{name}.toml")
    assert scene.features.backlash.kind == "polynomial"
    assert scene.features.backlash.order == 7  # the study's 7th-order fit
    assert System.load(name.replace("-", "_")).backlash == "polynomial"


def test_a_topology_on_its_own_keeps_the_polynomial_its_generated_model_carries(root):
    scene = load_target(root / "scenes" / "topologies" / "siso.toml")
    assert scene.kind == "topology"
    assert scene.features.backlash.kind == "polynomial"


def _note_zeros(note: str) -> list[float]:
    """The zeros a note names (``x = 0, ±0.770 half``), with ``±z`` as ``-z, z``."""
    text = re.search(r"zero at x = (.*?) half backlashes", note)[1]
    out = []
    for part in text.split(", "):
        z = float(part.lstrip("±"))
        out += [-z, z] if part.startswith("±") else [z]
    return sorted(out)


def test_the_notes_zeros_are_the_polynomials_zeros_from_the_derive_layer(root):
    fit = load_target(root / "scenes" / "reference-light.toml").features.backlash
    reference = polynomial_sign(fit.coefficients, fit.powers, fit.valid_range)
    system = System.load("reference_light")
    for sign in system.contract.force_sign.values():
        assert sign.zeros == pytest.approx(reference.zeros, abs=1e-12)
    assert _note_zeros(system.backlash_note) == [round(z, 3) for z in reference.zeros]
    assert _note_zeros(system.backlash_note) == [-0.77, 0.0, 0.77]  # force_sign.py's text
    assert "not at the backlash edge ±1" in system.backlash_note


NOTE = "gearsym: note: backlash model 'polynomial'"


def _simulate(capsys, scene: str, *more: str) -> tuple[int, str]:
    code = main(["simulate", scene, "--transient", "2", "--periods", "2", "--budget", "0", *more])
    return code, capsys.readouterr().err


def test_simulate_notes_the_polynomial_once_and_the_dead_zone_never(capsys):
    code, err = _simulate(capsys, "reference-light")
    assert code == 0 and err.count(NOTE) == 1 and "±0.770" in err, err
    code, err = _simulate(capsys, "reference-dead-zone")
    assert code == 0 and "backlash model" not in err, err
    assert _simulate(capsys, "reference-light")[1].count(NOTE) == 1  # each command says it


def test_a_model_loaded_twice_by_one_command_is_noted_once(capsys):
    _notes.forget()
    system_of("reference-light", {})
    system_of("reference-light", {"omega": 0.6})
    _notes.say()
    assert capsys.readouterr().err.count(NOTE) == 1


def test_a_refused_command_keeps_its_one_line_without_the_note(capsys):
    code, err = _simulate(capsys, "reference-light", "--x0", "1,2")  # 4 states: refused
    assert code == 2 and len(err.strip().splitlines()) == 1 and "x0" in err, err
