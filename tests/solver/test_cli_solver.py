"""End-to-end: gearsym simulate, sweep and reproduce."""

import json

import pytest
from gearsym.cli import main


def test_simulate_json_has_the_verdicts_and_their_evidence(capsys):
    code = main(
        [
            "simulate",
            "reference-light",
            "--set",
            "lambda=0.8",
            "--method",
            "cvodes",
            "--transient",
            "150",
            "--periods",
            "32",
            "--lyapunov-periods",
            "50",
            "--json",
        ]
    )
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert set(data["poincare"]) == {"u", "v", "du", "dv"} and len(data["poincare"]["u"]) == 32
    for c in ("u", "v"):
        verdict = data["classification"][c]
        assert verdict["motion"] == "period-1" and "spread" in verdict["evidence"]
        assert data["extremes"][c]["max"] > data["extremes"][c]["min"]
        shares = data["meshing_states"][c]
        split = ("forward", "separated", "backward")  # "loaded_in_gap" is not part of it
        assert sum(shares[k] for k in split) == pytest.approx(1.0)
        assert data["spectra"][c]["peaks"][0]["frequency"] == pytest.approx(0.5, abs=0.01)
    assert data["integration"]["method"] == "cvodes"
    assert data["system"]["values"] == {"lambda": 0.8}
    # one verdict for the attractor, on the shooting check's evidence
    orbit = data["verdict"]["evidence"]["orbit"]
    assert data["verdict"]["motion"] == "period-1" and orbit["attracting"]
    assert data["lyapunov"]["exponent"] < 0 and "multipliers" in data["lyapunov"]["method"]


def test_simulate_rejects_unknown_parameters_in_one_line(capsys):
    assert main(["simulate", "reference-light", "--set", "lamda=0.8"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--set lamda: not a parameter of reference_light" in err
    assert "(did you mean 'lambda'?)" in err and len(err) < 700


def test_sweep_writes_data_and_a_bifurcation_diagram(tmp_path, capsys):
    out = tmp_path / "sw"
    code = main(
        [
            "sweep",
            "reference-heavy",
            "--param",
            "lambda",
            "--range",
            "0:1:3",
            "--executor",
            "serial",
            "--transient",
            "60",
            "--periods",
            "16",
            "--lyapunov-periods",
            "20",
            "--out",
            str(out),
            "--quiet",
        ]
    )
    assert code == 0
    data = json.loads((out / "sweep.json").read_text())
    assert data["parameter"] == "lambda" and data["values"] == [0.0, 0.5, 1.0]
    assert data["model_hash"] and data["direction"] == "forward"
    assert len(data["points"]) == 3 and (out / "bifurcation.png").stat().st_size > 1000


def test_sweep_refuses_a_bad_range(capsys):
    assert main(["sweep", "reference-light", "--param", "lambda", "--range", "0:1"]) == 2
    assert "expected START:STOP:NUM" in capsys.readouterr().err


@pytest.mark.slow
def test_reproduce_quick_writes_the_report(tmp_path, capsys):
    # --fresh: every unit computed, none loaded from a result store an earlier run kept
    assert main(["reproduce", "--quick", "--fresh", "--out", str(tmp_path), "--quiet"]) == 0
    report = (tmp_path / "report.md").read_text()
    # stdout: the short summary, not the report (issue 25, point 7)
    said = capsys.readouterr().out
    assert said.startswith("findings of the study, polynomial: ") and "## " not in said
    assert f"report: {tmp_path / 'report.md'}" in said and len(said.splitlines()) == 5
    head = "| study | found with the polynomial | found with the dead zone | verdict | why |"
    assert head in report and "nan" not in report.lower().split()
    # the figure list names exactly the figures written
    listed = {w.strip("`") for w in report.split() if w.startswith("`") and w.endswith(".png`")}
    for name in listed:
        assert "*" in name or "<" in name or (tmp_path / name).exists(), name
    for name in (
        "bifurcation_light.png",
        "bifurcation_heavy.png",
        "map_f1_lambda.png",
        "point_heavy_lambda_0.8.png",
        "response_heavy.png",
        "sensitivity/heavy-both-driving-te_amplitude_um-motion.png",
    ):
        assert (tmp_path / name).stat().st_size > 1000
    # the sections of the sensitivity study and the frequency response (one reproduce
    # run serves both: it is the suite's longest command)
    assert "## Sensitivity to the values the study leaves open" in report
    assert "| light (f1 = 0.1) | q braking | `te_amplitude_um` (µm) |" in report
    assert "| heavy (f1 = 0.5) | both driving | `te_amplitude_um` (µm) |" in report
    assert "## Frequency response around the study's operating point" in report
    assert "### Physical scales" in report
    # the sweeps, maps and responses in every result format, as every command writes them
    tables = [p for p in (tmp_path / "data").glob("*.json") if p.stem.startswith(TABLES)]
    assert len(tables) > 10
    for path in tables:
        assert path.with_suffix(".csv").stat().st_size > 0, path.name
        assert path.with_suffix(".mat").stat().st_size > 0, path.name


TABLES = ("sweep_", "sensitivity_", "response_")


BAD_COMMANDS = [
    (["stiffness", "diso", "--slices", "0"], "--slices 0: give a number of slices"),
    (["stiffness", "diso", "--harmonics", "-1"], "--harmonics -1: give 0 to 64 harmonics"),
    (["stiffness", "diso", "--mesh", "pq"], "--mesh pq: no such mesh in diso (did you mean 'qg'?)"),
    (["stiffness", "disso"], "disso"),
    (
        [
            "continue",
            "reference-light",
            "--param",
            "lambda",
            "--from",
            "0.5",
            "--to",
            "0.6",
            "--step",
            "0",
        ],
        "--step must be a positive number",
    ),
    (
        [
            "continue",
            "reference-light",
            "--param",
            "lambda",
            "--from",
            "0.5",
            "--to",
            "0.6",
            "--period",
            "0",
        ],
        "--period must be >= 1",
    ),
    (["shoot", "reference-light", "--settle", "-1"], "--settle >= 0"),
    (
        ["continue", "reference-light", "--param", "lamda", "--from", "0.1", "--to", "0.2"],
        "--param lamda: not a parameter of reference_light (did you mean 'lambda'?)",
    ),
    (
        ["simulate", "lin-parker-1999-3-backlash", "--set", "omgea=1"],
        "--set omgea: not a parameter of lin-parker-1999-3-backlash (did you mean 'omega'?); "
        "it takes in physical units damping_ratio, mesh_frequency_hz, sun_force_N",
    ),
    (
        ["frequency-response", "reference-light", "--param=f_1=0.1:0.2:3"],
        "--param f_1: not a parameter of reference_light (did you mean 'f1'?)",
    ),
    (
        ["simulate", "reference-light", "--set", "omega=0"],
        "omega must be in [0.001, 1000]",
    ),
    (["sweep", "reference-light", "--param", "lambda", "--range", "nan:1:3"], "must be finite"),
    (
        ["sweep", "reference-light", "--param", "lambda", "--range", "0:1:2:7"],
        "expected START:STOP:NUM",
    ),
    (["sweep", "reference-light", "--param", "lambda", "--range", "0:1:1"], "NUM must be >= 2"),
    (
        ["sweep", "reference-light", "--param", "lamda", "--range", "0:1:3"],
        "--param lamda: not a parameter of reference_light (did you mean 'lambda'?)",
    ),
]


@pytest.mark.parametrize("argv,fragment", BAD_COMMANDS)
def test_solver_commands_fail_in_one_line(argv, fragment, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and fragment in err, err


def test_a_failing_point_is_recorded_and_the_sweep_goes_on(tmp_path, capsys):
    out = tmp_path / "sw"
    code = main(
        [
            "sweep",
            "reference-light",
            "--param",
            "xi_u_u",  # a model parameter: its negative value is allowed, and diverges
            "--range=-0.5:0.03:2",
            "--executor",
            "serial",
            "--transient",
            "20",
            "--periods",
            "8",
            "--lyapunov-periods",
            "0",
            "--out",
            str(out),
            "--quiet",
        ]
    )
    assert code == 3  # a point ended divergent or failed (docs/user-guide.md, exit codes)
    text = (out / "sweep.json").read_text()
    data = json.loads(text, parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    statuses = [p["status"] for p in data["points"]]
    assert statuses[-1] == "ok" and statuses[0] in ("failed", "divergent")
    assert "did not finish normally" in capsys.readouterr().out


def test_shoot_json_reports_the_orbit_and_its_multipliers(tmp_path, capsys):
    code = main(
        [
            "shoot",
            "reference-light",
            "--set",
            "lambda=0.8",
            "--settle",
            "100",
            "--compare-monodromy",
            "--json",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert data["residual"] < 1e-10 and data["iterations"] >= 1
    assert set(data["x0"]) == {"u", "v", "du", "dv"} and data["period"] > 0
    fl = data["floquet"]
    assert len(fl["multipliers"]) == 4 and fl["stable"] is True
    assert fl["liouville_error"] < 1e-8
    assert max(data["monodromy_agreement"].values()) < 1e-6
    assert (tmp_path / "multipliers.png").stat().st_size > 1000


@pytest.mark.slow
def test_continue_lists_the_folds_of_the_light_load_branch(tmp_path, capsys):
    code = main(
        [
            "continue",
            "reference-light",
            "--param",
            "lambda",
            "--from",
            "0",
            "--to",
            "1",
            "--step",
            "0.04",
            "--settle",
            "150",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert sum(line.lstrip().startswith("fold ") for line in out.splitlines()) == 2
    branches = json.loads((tmp_path / "branches.json").read_text())["branches"]
    folds = sorted(b["value"] for b in branches[0]["bifurcations"])
    # The hysteresis window of the brute-force sweeps, [0.3, 0.8], lies between them.
    assert 0.25 < folds[0] < 0.3 and 0.8 < folds[1] < 0.85


def test_continuing_to_a_refused_parameter_value_is_refused_before_computing(tmp_path, capsys):
    # omega must stay > 0: the end of the range is checked like any other value.
    code = main(
        [
            "continue",
            "reference-light",
            "--param",
            "omega",
            "--from",
            "0.3",
            "--to",
            "0.0",
            "--step",
            "0.1",
            "--settle",
            "50",
            "--out",
            str(tmp_path),
        ]
    )
    assert code == 2
    captured = capsys.readouterr()
    assert "--to 0: omega = 0: omega must be in [0.001, 1000]" in captured.err
    assert captured.out == ""


def test_long_periods_do_not_break_the_liouville_check(capsys):
    # omega = 0.002 (a period of 3142): det M is about exp(-377); the check compares
    # logarithms and reports null when round-off has taken det M (no division by zero).
    argv = ["shoot", "reference-light", "--set", "omega=0.002", "--settle", "2", "--json"]
    assert main(argv) == 0
    error = json.loads(capsys.readouterr().out)["floquet"]["liouville_error"]
    assert error is None or error >= 0


def test_shoot_says_where_a_stable_orbit_would_lose_stability(capsys):
    """A stable orbit whose largest multipliers are a complex pair is not a Neimark-Sacker
    point: the line says the pair would have to reach the unit circle.  Reference: the
    multipliers printed beside it (complex, modulus below 1)."""
    assert main(["shoot", "reference-light"]) == 0
    out = capsys.readouterr().out
    line = next(ln for ln in out.splitlines() if ln.strip().startswith("stable"))
    assert "one of a complex pair (were it to reach the unit circle" in line
    mus = next(ln for ln in out.splitlines() if "multipliers:" in ln)
    assert "i (|0.68" in mus and "(Neimark-Sacker)" not in out
