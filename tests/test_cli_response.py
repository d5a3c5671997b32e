"""`gearsym frequency-response` end to end: records, files, the two methods, errors."""

import json

import numpy as np
import pytest
from gearsym.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_records_files_and_folds(capsys, tmp_path):
    argv = ["frequency-response", "reference-light", "--param=omega=0.3:0.9:60"]
    code, out, err = run(capsys, *argv, "--harmonics=12", "--json", f"--out={tmp_path}")
    assert code == 0, err
    records = [json.loads(line) for line in out.splitlines()]
    assert len(records) >= 60
    for r in records:
        assert r["method"] == "hb" and isinstance(r["stable"], bool)
        assert set(r) == {"method", "curve", "omega", "stable", "u", "v"}
        assert set(r["u"]) == {"mean", "amplitude", "rms", "min", "max", "dynamic_factor"}
        assert r["u"]["amplitude"] >= 0 and r["u"]["dynamic_factor"] >= 1 - 1e-9
    omegas = [r["omega"] for r in records]
    assert min(omegas) == pytest.approx(0.3) and omegas[-1] == pytest.approx(0.9)
    assert not all(r["stable"] for r in records)  # the branch between folds is unstable
    names = {p.name for p in tmp_path.iterdir()}
    assert {"frequency_response.json", "frequency_response.csv"} <= names
    assert {"frequency_response.mat", "frequency_response.png"} <= names
    data = json.loads((tmp_path / "frequency_response.json").read_text())
    folds = [e for e in data["curves"][0]["events"] if e["kind"] == "fold"]
    assert len(folds) % 2 == 0 and folds  # the branch enters and leaves each overhang
    # each fold cross-checked by a time integration's monodromy: a multiplier at +1.  At a
    # fold the critical multiplier moves with the square root of a perturbation of the
    # equations, here harmonic balance's truncation (its tail share)
    tail = data["curves"][0]["largest_tail_share"]
    for e in folds:
        assert abs(e["max_monodromy_multiplier"] - 1) < 10 * max(tail, 1e-12) ** 0.5
        assert e["hill_vs_monodromy"] < 10 * max(tail, 1e-12) ** 0.5


@pytest.mark.slow
def test_shooting_and_harmonic_balance_find_the_same_folds(capsys, tmp_path):
    # Reference: shooting continuation (monodromy, located by bisection on det(M - I)),
    # an independent method, over the first overhang of the light-load response.
    argv = ["frequency-response", "reference-light", "--param=omega=0.3:0.5:40"]
    code, out, err = run(capsys, *argv, "--method=all", "--no-figure", f"--out={tmp_path}")
    assert code == 0, err
    data = json.loads((tmp_path / "frequency_response.json").read_text())
    methods = [c["method"] for c in data["curves"]]
    assert methods == ["hb", "shooting", "integration", "integration"]
    hb, sh = data["curves"][:2]
    a = sorted(e["omega"] for e in hb["events"] if e["kind"] == "fold")
    b = sorted(e["omega"] for e in sh["events"] if e["kind"] == "fold")
    assert len(a) == len(b) == 2
    assert max(abs(x - y) for x, y in zip(a, b, strict=True)) < 1e-6


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--param=omega=0.3:0.9"], "expected NAME=START:STOP:NUM"),
        (["--param=omega=0.5:0.5:10"], "must be finite and differ"),
        (["--param=omega=0.3:0.9:1"], "NUM must be >= 2"),
        (["--param=nope=0.3:0.9:10"], "--param nope"),
        (["--param=omega=0.3:0.9:10", "--harmonics=0"], "--harmonics must be >= 1"),
        (["--param=omega=0.3:0.9:10", "--period=0"], "--period must be >= 1"),
        (["--param=lambda=0:1:10", "--method=integration"], "forcing frequency 'omega' only"),
        (["--param=omega=0.3:0.9:10", "--settle=0"], "--settle and --sampled must be >= 1"),
    ],
)
def test_errors_are_one_line(capsys, tmp_path, args, message):
    code, out, err = run(
        capsys, "frequency-response", "reference-light", *args, f"--out={tmp_path}"
    )
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1


def test_an_unwritable_folder_is_refused_before_computing(capsys, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    code, out, err = run(
        capsys,
        "frequency-response",
        "reference-light",
        "--param=omega=0.3:0.9:10",
        f"--out={blocker / 'sub'}",
    )
    assert code == 2 and "--out" in err and "cannot write there" in err


def test_a_second_curve_of_one_method_is_told_apart(capsys, tmp_path):
    """Harmonic balance from both ends of a range its branch turned out of: the CSV's
    'curve' column and the printed lines tell the two curves apart (the branch of
    reference-light over 900 to 1,000 rpm turns at its fold near 969 rpm, issue 25's
    new-user pass)."""
    argv = ["frequency-response", "reference-light", "--param=speed_rpm=900:1000:4"]
    code, out, err = run(capsys, *argv, "--no-figure", f"--out={tmp_path}")
    assert code == 0, err
    assert "hb (curve 0, column 'curve')" in out and "hb (curve 1, column 'curve')" in out
    assert "a second curve, from the other end (speed_rpm = 1000)" in out
    lines = [ln for ln in (tmp_path / "frequency_response.csv").read_text().splitlines()]
    names, *rows = [ln.split(",") for ln in lines if not ln.startswith("#")]
    curves = [int(r[names.index("curve")]) for r in rows]
    assert curves == sorted(curves) and set(curves) == {0, 1}
    first = [float(r[names.index("speed_rpm")]) for r in rows if r[1] == "1"][0]
    assert first == 1000.0


def test_a_response_over_the_speed_in_rpm_folds_where_the_one_over_omega_does():
    """The arclength counts a parameter whose range exceeds 1 in units of that range
    (engine.Settings.scale): over 600 to 1,900 rpm harmonic balance took steps of
    hundreds in the unknowns, crossed the branch at its first fold and came back as a
    spurious branch point.  Reference: the same continuation over omega (its range under
    1, so unscaled), the folds mapped to rpm by the model's own linear speed-omega rule."""
    import gearsym
    from gearsym.solver.sweep.frequency import frequency_response

    system = gearsym.load("reference-light")
    per_rpm = system.parameters_with(speed_rpm=1000.0)[0] / 1000.0
    rpm = frequency_response(system, "speed_rpm", 600.0, 1900.0, points=60)
    omega = frequency_response(system, "omega", 600.0 * per_rpm, 1900.0 * per_rpm, points=60)
    assert [c.method for c in rpm.curves] == ["hb"]  # one curve, through every fold
    names = {e.name for e in rpm.curves[0].events}
    assert names == {"fold"}
    folds = sorted(e.value for e in rpm.curves[0].events)
    expected = sorted(e.value / per_rpm for c in omega.curves for e in c.events)
    assert len(folds) == 4 and np.allclose(folds, expected, rtol=1e-6)
    assert 0 < int(rpm.curves[0].stable.sum()) < len(rpm.curves[0].values)


def test_stepped_integration_runs_over_the_speed_in_rpm_as_over_omega():
    """A speed in rpm sets only the forcing frequency, so the stepped-frequency
    integration takes it (it refused every parameter but omega).  References: the same
    sweeps over omega at the speeds' omegas (the model's linear speed-omega rule), and
    the up sweep's jump between the grid speeds that bracket harmonic balance's fold."""
    import gearsym
    from gearsym.solver.sweep.frequency import frequency_response

    system = gearsym.load("reference-light")
    per_rpm = system.parameters_with(speed_rpm=1000.0)[0] / 1000.0
    kw = dict(points=16, methods=("integration",), settle=60, sampled=8)
    rpm = frequency_response(system, "speed_rpm", 900.0, 1050.0, **kw)
    omega = frequency_response(system, "omega", 900.0 * per_rpm, 1050.0 * per_rpm, **kw)
    for a, b in zip(rpm.curves, omega.curves, strict=True):
        assert np.allclose(a.values * per_rpm, b.values, rtol=1e-12)
        for c in system.coordinates:
            assert np.allclose(a.stats[c]["amplitude"], b.stats[c]["amplitude"], rtol=1e-6)
    up = rpm.curves[0]
    v = up.stats["v"]["amplitude"]
    jump = int(np.argmax(np.abs(np.diff(v))))  # the last grid speed on the lower branch
    hb = frequency_response(system, "speed_rpm", 900.0, 1050.0, points=16, methods=("hb",))
    folds = [e.value for c in hb.curves for e in c.events if e.name == "fold"]
    assert any(up.values[jump] <= f <= up.values[jump + 1] for f in folds)


def test_stepped_integration_refuses_a_parameter_that_sets_more_than_the_frequency():
    import gearsym
    from gearsym.solver.sweep.frequency_ranges import others_moved

    system = gearsym.load("reference-light")
    assert others_moved(system, "speed_rpm", (900.0, 1200.0)) == []
    assert others_moved(system, "lambda", (0.1, 0.8)) == ["f_v"]  # lambda = |f2 / f1|


def test_a_curve_already_computed_stands_when_the_other_end_cannot_start(capsys, tmp_path):
    """The dead-zone scene's branch from omega = 0.3 turns back at a fold and leaves the
    range; the second curve would start at omega = 0.9, where the simulation settles on a
    chaotic motion (simulate says so) and harmonic balance has no period-1 orbit to start
    from.  The whole response failed and the first curve was lost; now it is written, and
    its note says why there is no second one."""
    code, out, err = run(
        capsys,
        "frequency-response",
        "reference-dead-zone",
        "--param=omega=0.3:0.9:40",
        f"--out={tmp_path}",
        "--json",
    )
    assert code == 0, err
    doc = json.loads((tmp_path / "frequency_response.json").read_text(encoding="utf-8"))
    (curve,) = doc["curves"]
    omegas = [r["omega"] for r in doc["records"]]
    assert curve["points"] == len(omegas) >= 5 and min(omegas) >= 0.3
    assert any("no second curve from the other end (omega = 0.9)" in n for n in curve["notes"])
