"""External torques out of balance are said, with the torque that balances them.

Reference: a tree of gears turns rigidly with speeds in the ratio of its tooth counts;
steady running needs the torques' power over that rotation to vanish.  For the DI-SO
(z_p = z_q = 50, z_g = 100, scenes/topologies/diso.toml) the balancing output torque is
T_g = -(T_p + T_q) z_g / z_p.
"""

from __future__ import annotations

import gearsym
import pytest
from gearsym.cli import main

Z_RATIO = 100 / 50


def test_the_study_s_torques_are_in_balance():
    system = gearsym.load("reference-light")
    assert system.torque_note is None
    q = system.module.PHYSICAL
    t_p, t_q, t_g = (q[f"torque_Nm_{g}"][0] for g in "pqg")
    assert t_g == pytest.approx(-(t_p + t_q) * Z_RATIO, rel=1e-12)


def test_an_input_torque_alone_is_said_with_the_output_torque_that_balances_it(capsys):
    system = gearsym.load("reference-light", torque_Nm_p=300.0)
    t_q = system.module.PHYSICAL["torque_Nm_q"][0]
    note = system.torque_note
    steady = -(300.0 + t_q) * Z_RATIO
    assert note is not None and "not in balance" in note
    said = float(note.split("torque_Nm_g = ")[1].split()[0])
    assert said == pytest.approx(steady, rel=1e-8)  # printed to 9 digits
    balanced = gearsym.load("reference-light", torque_Nm_p=300.0, torque_Nm_g=steady)
    assert balanced.torque_note is None
    # the value as printed balances too (the note does not come back after its own advice)
    printed = gearsym.load("reference-light", torque_Nm_p=300.0, torque_Nm_g=said)
    assert printed.torque_note is None

    argv = ["simulate", "reference-light", "--transient", "5", "--periods", "5"]
    assert main([*argv, "--set", "torque_Nm_p=300"]) == 0
    err = capsys.readouterr().err
    assert err.count("torques are not in balance") == 1 and "torque_Nm_g = " in err
    assert main([*argv, "--set", "torque_Nm_p=300", "--set", f"torque_Nm_g={steady!r}"]) == 0
    assert "not in balance" not in capsys.readouterr().err


def test_a_sweep_over_an_input_torque_says_so_once(tmp_path, capsys):
    argv = ["sweep", "reference-light", "--param", "torque_Nm_p", "--range", "300:400:2"]
    argv += ["--transient", "5", "--periods", "5", "--executor", "serial", "--quiet"]
    assert main([*argv, "--no-figure", "--out", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert err.count("torques are not in balance") == 1 and "at torque_Nm_p = 300," in err
