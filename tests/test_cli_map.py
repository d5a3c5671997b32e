"""`gearsym map` end to end: records, files, figures, resume, and one-line errors."""

import json

import pytest
from gearsym.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


SMALL = ("--transient", "60", "--periods", "24", "--lyapunov-periods", "40", "--quiet")


def test_map_prints_one_record_per_grid_point_and_attractor(capsys, tmp_path):
    argv = ["map", "reference-light", "--x=lambda=0:1:3", "--y=f1=0.1:0.3:2", *SMALL]
    code, out, err = run(capsys, *argv, "--json", "--executor=serial", f"--out={tmp_path}")
    assert code == 0, err
    records = [json.loads(line) for line in out.splitlines()]
    cells = {(r["lambda"], r["f1"]) for r in records}
    assert len(cells) == 3 * 2
    for r in records:
        assert 0 < r["share"] <= 1 and r["attractor"] < r["attractors"]
        assert set(r["motion"]) == {"u", "v"} and set(r["meshing"]) == {"u", "v"}
    for cell in cells:
        shares = [r["share"] for r in records if (r["lambda"], r["f1"]) == cell]
        assert sum(shares) == pytest.approx(1.0)
    names = {p.name for p in tmp_path.iterdir()}
    assert {"map.json", "map.csv", "map-motion.png", "map-lyapunov.png"} <= names
    assert {"map-attractors.png", "map-extremes.png", "map-meshing.png"} <= names
    # a second run resumes from the store and says so
    code, out, err = run(capsys, *argv, "--executor=serial", f"--out={tmp_path}")
    assert code == 0, err
    assert "resumed:" in out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ("--x=lamda=0:1:3", "--y=f1=0.1:0.3:2"),
            "--x lamda: not a parameter of reference_light (did you mean 'lambda'?)",
        ),
        (
            ("--x=lambda=0:1:3", "--y=f_1=0.1:0.3:2"),
            "--y f_1: not a parameter of reference_light (did you mean 'f1'?)",
        ),
        (("--x=lambda=0:1", "--y=f1=0.1:0.3:2"), "--x lambda=0:1: expected START:STOP:NUM"),
        (("--x=lambda=0:1:3", "--y=lambda=0:1:3"), "name the same parameter"),
        (("--x=lambda=0:1:3", "--y=f1=0.1:0.3:2", "--initial-states=0"), "--initial-states"),
        (("--x=lambda=0:1:3", "--y=f1=0.1:0.3:2", "--box=w=0:1"), "--box w: not a state"),
        (("--x=lambda=0:1:3", "--y=f1=0.1:0.3:2", "--box=u=1"), "expected STATE=LO:HI"),
        (
            ("--x=lambda=0:1:3", "--y=f1=0.1:0.3:2", "--lyapunov-periods=900"),
            "--lyapunov-periods 900 is more than the run",
        ),
    ],
)
def test_map_errors_are_one_line(capsys, tmp_path, args, message):
    code, out, err = run(capsys, "map", "reference-light", *args, f"--out={tmp_path}/m")
    assert code == 2
    assert message in err and err.count("\n") == 1


def test_map_refuses_an_unwritable_folder(capsys, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    argv = ["map", "reference-light", "--x=lambda=0:1:2", "--y=f1=0.1:0.3:2"]
    code, out, err = run(capsys, *argv, f"--out={blocker}/map")
    assert code == 2 and "cannot write there" in err


def test_a_sweep_over_an_open_value_points_to_the_map(capsys, tmp_path):
    # A model on bearings carries no inertia as a parameter: the flywheel is an open value.
    argv = ["sweep", "diso-bearings-light", "--param", "flywheel_inertia_kg_m2"]
    code, out, err = run(capsys, *argv, "--range", "2:20:3", f"--out={tmp_path}/s")
    assert code == 2 and "an open value" in err and "gearsym map" in err


def test_a_map_over_an_open_value_derives_one_model_per_value(capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    argv = ["map", "diso-bearings-light", "--x=lambda=0:1:2", "--y=flywheel_inertia_kg_m2=2:10:2"]
    code, out, err = run(capsys, *argv, *SMALL, "--json", "--executor=serial", f"--out={tmp_path}")
    assert code == 0, err
    records = [json.loads(line) for line in out.splitlines()]
    assert {r["flywheel_inertia_kg_m2"] for r in records} == {2.0, 10.0}
    models = tmp_path / "cache" / "models"
    assert len(list(models.glob("diso_bearings_light_open_*.py"))) == 1  # 10 is the scene's


def test_a_map_over_a_physical_quantity_derives_nothing(capsys, tmp_path, monkeypatch):
    """The transmission error is a parameter of the torsional model (derive/physical.py)."""
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    argv = ["map", "reference-light", "--x=lambda=0:1:2", "--y=te_amplitude_um=0:10:2"]
    code, out, err = run(capsys, *argv, *SMALL, "--json", "--executor=serial", f"--out={tmp_path}")
    assert code == 0, err
    records = [json.loads(line) for line in out.splitlines()]
    assert {r["te_amplitude_um"] for r in records} == {0.0, 10.0}
    assert not list((tmp_path / "cache" / "models").glob("reference_light_open_*.py"))
