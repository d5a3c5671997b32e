"""Continuations stay inside their parameter's valid range, and every size that sets the
cost has a stated limit (issue 23, items 5 and 7).

A continuation that reaches the edge of the valid range the model states
(``SCENE_PARAMETER_LIMITS``; the forcing frequency > 0) is not a refusal: it ends with
exit code 0, says so in one line and keeps the branch computed so far.  The refusals
themselves are rows of ``tests/bad_inputs.py``."""

from __future__ import annotations

import json
import math

import pytest
from gearsym.cli import main


def run(capsys, *argv):
    try:
        code = main(list(argv))
    except SystemExit as stop:
        code = stop.code
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def light():
    from gearsym.solver.system import System

    return System.load("reference_light")


# -- the valid range, as the model states it ----------------------------------------------
def test_the_interval_is_what_the_generated_module_states(light):
    from gearsym.solver.periodic._bounds import Interval, interval_of

    omega, zeta = interval_of(light, "omega"), interval_of(light, "damping_ratio")
    # derive/input/scene.py PARAMETER_LIMITS: omega in [1e-3, 1e3], damping ratio in [0, 1]
    assert omega.rule() == "omega in [0.001, 1000]" and 1e-3 in omega and 9.99e-4 not in omega
    assert zeta.rule() == "damping_ratio in [0, 1]" and 0.0 in zeta and -1e-12 not in zeta
    assert interval_of(light, "lambda").rule() == "lambda: any finite value"
    # a closed end is reached; an excluded end is kept a thousandth of the range inside
    assert omega.ends(0.5, -1.0) == (1e-3, 0.5)
    assert zeta.ends(0.03, -0.2) == (0.0, 0.03)
    positive = Interval("omega", 0.0, math.inf, low_open=True)
    assert positive.rule() == "omega > 0" and 0.0 not in positive
    assert positive.ends(0.5, -1.0) == (pytest.approx(5e-4), 0.5)
    with pytest.raises(KeyError, match="nosuch"):
        interval_of(light, "nosuch")


def test_hb_continuation_past_a_boundary_stops_there_and_keeps_the_branch(light):
    from gearsym.solver.periodic.hb_continuation import continue_hb

    br = continue_hb(light, "omega", 0.3, -1.0, harmonics=3, check=False)
    assert br.status == "boundary" and "omega in [0.001, 1000]" in br.message, br.message
    assert len(br.points) > 3 and br.values[-1] == 1e-3 and br.values.min() == 1e-3
    br = continue_hb(light, "damping_ratio", 0.03, -0.2, harmonics=3, check=False)
    assert br.status == "boundary" and br.values[-1] == 0.0 and br.values.min() >= 0


def test_hb_continuation_in_a_scene_parameter_that_is_not_a_model_parameter(light):
    from gearsym.solver.periodic.hb_continuation import continue_hb

    assert "lambda" not in light.contract.parameters
    br = continue_hb(light, "lambda", 0.1, 0.3, harmonics=3, check=False)
    assert br.status == "complete" and br.values[-1] == pytest.approx(0.3)


# -- the CLI: a boundary is one line, exit 0, the branch kept ----------------------------
def test_frequency_response_down_to_zero_damping_stops_at_the_boundary(capsys, tmp_path):
    code, out, err = run(
        capsys,
        "frequency-response",
        "reference-light",
        "--param",
        "damping_ratio=0.05:0:3",
        "--harmonics",
        "3",
        "--no-figure",
        "--out",
        str(tmp_path),
    )
    assert code == 0, err
    assert "Traceback" not in err and "CasADi" not in err
    said = [ln for ln in out.splitlines() if "boundary" in ln]
    assert len(said) == 1 and "damping_ratio in [0, 1]" in said[0], out
    data = json.loads((tmp_path / "frequency_response.json").read_text())
    hb = data["curves"][0]
    assert hb["status"] == "boundary"
    # NUM = 3 points (the --param help): the grid 0.05, 0.025, 0, the last on the boundary
    values = [r["damping_ratio"] for r in data["records"] if r["method"] == "hb"]
    assert values == pytest.approx([0.05, 0.025, 0.0], abs=1e-15) and values[-1] == 0.0


def test_frequency_response_in_lambda_runs(capsys, tmp_path):
    code, out, err = run(
        capsys,
        "frequency-response",
        "reference-light",
        "--param",
        "lambda=0:1:5",
        "--harmonics",
        "3",
        "--no-figure",
        "--out",
        str(tmp_path),
    )
    assert code == 0 and err.startswith("gearsym: note: backlash") and err.count("\n") == 1, err
    assert out.startswith("hb: ")


@pytest.mark.slow
def test_a_wide_range_on_the_dead_zone_never_steps_below_zero_frequency(capsys, tmp_path):
    code, out, err = run(
        capsys,
        "frequency-response",
        "reference-dead-zone",
        "--param",
        "omega=0.05:3:50",
        "--harmonics",
        "5",
        "--no-figure",
        "--out",
        str(tmp_path),
    )
    assert code == 0 and "Traceback" not in err, err
    data = json.loads((tmp_path / "frequency_response.json").read_text())
    assert min(r["omega"] for r in data["records"]) >= 0.05 - 1e-12


def test_continue_to_zero_damping_says_the_boundary_and_keeps_the_branch(capsys, tmp_path):
    code, out, err = run(
        capsys,
        "continue",
        "reference-light",
        "--param",
        "damping_ratio",
        "--from",
        "0.03",
        "--to",
        "0",
        "--step",
        "0.02",
        "--out",
        str(tmp_path),
    )
    assert code == 0 and err.startswith("gearsym: note: backlash") and err.count("\n") == 1, err
    said = [ln for ln in out.splitlines() if "boundary" in ln]
    assert len(said) == 1 and said[0].startswith("period-1 branch:"), out
    (branch,) = json.loads((tmp_path / "branches.json").read_text())["branches"]
    assert branch["status"] == "boundary" and len(branch["values"]) >= 2
    assert branch["values"][-1] == 0.0 and min(branch["values"]) >= 0.0


# -- no third-party dumps -------------------------------------------------------------------
def test_a_failed_integration_is_one_line_without_casadi_dumps(capsys):
    code, out, err = run(capsys, "shoot", "reference-light", "--x0", "1e300,1e300,0,0")
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 3 and len(lines) == 1, err
    assert "CasADi" not in err and "Input 0" not in err
    assert "the integration failed" in lines[0]


# -- every limit stated in --help ------------------------------------------------------------
@pytest.mark.parametrize(
    "command,options",
    [
        ("shoot", ["--period", "--segments", "--tries", "--settle"]),
        ("continue", ["--period", "--step", "--settle"]),
        ("frequency-response", ["--param", "--harmonics", "--period", "--settle", "--sampled"]),
        ("simulate", ["--transient", "--periods", "--lyapunov-periods"]),
        ("sweep", ["--range", "--transient", "--periods", "--lyapunov-periods"]),
        ("map", ["--x", "--initial-states", "--transient", "--periods", "--workers"]),
    ],
)
def test_every_size_states_its_limit_in_help(command, options):
    from gearsym.cli import _parser

    parser = _parser()
    sub = next(a for a in parser._actions if isinstance(a.choices, dict)).choices[command]
    helps = {s: a.help or "" for a in sub._actions for s in a.option_strings}
    for option in options:
        text = helps[option]
        assert "at most" in text or " to " in text, (command, option, text)


def test_the_cli_states_the_solvers_harmonic_limits():
    from gearsym.cli import response
    from gearsym.solver.sweep import frequency

    assert (response.MAX_HARMONICS, response.MAX_UNKNOWNS) == (
        frequency.MAX_HARMONICS,
        frequency.MAX_UNKNOWNS,
    )
