"""Every kind of bad topology or scene input stops with one line naming file and key."""

import pytest
from gearsym.solver.cli import main


@pytest.fixture()
def files(tmp_path, root):
    topo = (root / "scenes" / "topologies" / "diso.toml").read_text()
    scene = (root / "scenes" / "reference-light.toml").read_text()
    return tmp_path, topo, scene


def derive(capsys, path):
    code = main(["derive", str(path), "--dry-run"])
    err = capsys.readouterr().err
    return code, err


def assert_one_line_error(code, err, path, expected):
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    assert str(path) in err and expected in err, err


TOPOLOGY_CASES = [
    # (what, old text, new text, expected fragment)
    (
        "mesh names unknown gear",
        'driver = "q"',
        'driver = "qq"',
        "mesh[1].driver: names unknown gear 'qq' (did you mean 'q'?)",
    ),
    ("negative teeth", "teeth = 100", "teeth = -100", "gear[2].teeth: must be >= 5, got -100"),
    (
        "unknown key",
        "teeth = 100",
        "teeth = 100\nteth = 3",
        "gear[2].teth: unknown key (did you mean 'teeth'?)",
    ),
    (
        "missing required key",
        "normal_module_mm = 4\n",
        "",
        "gear[0].normal_module_mm: is required but missing",
    ),
    ("duplicate gear", 'id = "q"', 'id = "p"', "gear[1].id: gear 'p' is defined twice"),
    (
        "self mesh",
        'driven = "g"\ncoordinate = "v"',
        'driven = "q"\ncoordinate = "v"',
        "mesh[1].driven: a gear cannot mesh with itself ('q')",
    ),
    (
        "reserved coordinate",
        'coordinate = "v"',
        'coordinate = "tau"',
        "mesh[1].coordinate: 'tau' is reserved",
    ),
    (
        "mismatched module",
        "normal_module_mm = 4\nnormal_pressure_angle_deg = 20\n"
        'helix_angle_deg = 10\nface_width_mm = 50\nmaterial = "steel"\nbore_radius_mm = 50',
        "normal_module_mm = 5\nnormal_pressure_angle_deg = 20\nhelix_angle_deg = 10\n"
        'face_width_mm = 50\nmaterial = "steel"\nbore_radius_mm = 50',
        "mesh[0].driven: 'p' and 'g' cannot mesh",
    ),
    (
        "bore larger than root",
        "bore_radius_mm = 30",
        "bore_radius_mm = 300",
        "gear[0].bore_radius_mm: 300 mm must be below the root radius",
    ),
    (
        "unknown material",
        'material = "steel"\nbore_radius_mm = 50',
        'material = "steal"\nbore_radius_mm = 50',
        "gear[2].material: 'steal' is not defined (did you mean 'steel'?)",
    ),
    (
        "unknown stiffness source",
        'source = "contact-line"',
        'source = "pem"',
        "mesh[0].stiffness.source: 'pem' is not one of 'harmonics', 'contact-line'",
    ),
    (
        "negative half backlash",
        "half_backlash_um = 50",
        "half_backlash_um = -5",
        "mesh[0].half_backlash_um: must be > 0, got -5",
    ),
    (
        "string where number",
        "helix_angle_deg = 10",
        'helix_angle_deg = "ten"',
        "gear[0].helix_angle_deg: must be a number, got 'ten'",
    ),
    (
        "TE lists of different length",
        "phase_deg = [0.0] }",
        "phase_deg = [0.0, 1.0] }",
        "mesh[0].transmission_error.phase_deg: must have 1 entries, got 2",
    ),
    (
        "unknown top-level table",
        "[operating]",
        "[operatin]",
        "operatin: unknown key (did you mean 'operating'?)",
    ),
    (
        "name that cannot name a module",
        'name = "diso"',
        'name = "2 stage"',
        "topology.name: '2 stage' must start with a letter",
    ),
    (
        "torque on unknown gear",
        'gear = "q"\ntorque_Nm',
        'gear = "z"\ntorque_Nm',
        "torque[1].gear: names unknown gear 'z'",
    ),
]


@pytest.mark.parametrize(
    "what,old,new,expected", TOPOLOGY_CASES, ids=[c[0] for c in TOPOLOGY_CASES]
)
def test_bad_topology(files, capsys, what, old, new, expected):
    tmp, topo, _ = files
    assert old in topo, f"test set-up: '{old}' not in the topology"
    path = tmp / "topo.toml"
    path.write_text(topo.replace(old, new, 1))
    assert_one_line_error(*derive(capsys, path), path, expected)


def test_disconnected_gear(files, capsys):
    tmp, topo, _ = files
    path = tmp / "topo.toml"
    path.write_text(
        topo + '\n[[gear]]\nid = "z"\nteeth = 30\nnormal_module_mm = 4\n'
        "face_width_mm = 40\nhelix_angle_deg = 10\n"
    )
    code, err = derive(capsys, path)
    assert code == 2 and "needs a [[gear]]" not in err
    assert "4 gears need exactly 3 meshes" in err


SCENE_CASES = [
    (
        "unknown feature key",
        "damping_coupling = true",
        "damping_coupling = true\nharmonics = 3",
        "features.harmonics: unknown key (did you mean 'stiffness_harmonics'?)",
    ),
    (
        "backlash typo",
        'backlash = "polynomial"',
        'backlash = "polynominal"',
        "features.backlash: 'polynominal' is not one of",
    ),
    (
        "even order",
        "backlash_order = 7",
        "backlash_order = 6",
        "features.backlash_order: must be odd",
    ),
    ("missing omega", "omega = 0.5 ", "", "parameters.omega: is required but missing"),
    ("negative omega", "omega = 0.5 ", "omega = -0.5 ", "parameters.omega: must be > 0"),
    (
        "load uses unknown parameter",
        'v = "-lambda*f1"',
        'v = "-lamda*f1"',
        "loads.v: 'lamda' in '-lamda*f1' is not a scene parameter (did you mean 'lambda'?)",
    ),
    (
        "load expression with a call",
        'v = "-lambda*f1"',
        'v = "__import__(1)"',
        "loads.v: '__import__(1)' may use only numbers",
    ),
    (
        "load for unknown coordinate",
        'v = "-lambda*f1"',
        'v = "-lambda*f1"\nw = 1',
        "loads.w: is not a mesh coordinate of topology 'diso'",
    ),
    (
        "missing topology file",
        'topology = "topologies/diso.toml"',
        'topology = "topologies/diso2.toml"',
        "scene.topology: 'topologies/diso2.toml' is "
        "neither a file next to the scene nor a built-in topology",
    ),
    (
        "harmonics out of range",
        "stiffness_harmonics = 3",
        "stiffness_harmonics = -1",
        "features.stiffness_harmonics: must be >= 0",
    ),
]


@pytest.mark.parametrize("what,old,new,expected", SCENE_CASES, ids=[c[0] for c in SCENE_CASES])
def test_bad_scene(files, capsys, root, what, old, new, expected):
    tmp, _, scene = files
    assert old in scene, f"test set-up: '{old}' not in the scene"
    (tmp / "topologies").mkdir(exist_ok=True)
    (tmp / "topologies" / "diso.toml").write_text(
        (root / "scenes" / "topologies" / "diso.toml").read_text()
    )
    path = tmp / "scene.toml"
    path.write_text(scene.replace(old, new, 1))
    assert_one_line_error(*derive(capsys, path), path, expected)


def test_bad_toml_syntax(tmp_path, capsys):
    path = tmp_path / "broken.toml"
    path.write_text("[scene\nname = 1\n")
    code, err = derive(capsys, path)
    assert code == 2 and "is not valid TOML" in err and str(path) in err


def test_missing_file_and_unknown_builtin(capsys):
    code, err = derive(capsys, "reference-lite")
    assert code == 2 and "did you mean 'reference-light'?" in err
    code, err = derive(capsys, "/nonexistent/scene.toml")
    assert code == 2 and "file not found" in err


def test_bad_set_values(capsys):
    for argv, fragment in (
        (["--set", "lambda"], "expected key=value"),
        (["--set", "lambda=abc"], "'abc' is not a number"),
        (["--set", "lamda=0.3"], "did you mean 'lambda'?"),
    ):
        code = main(["derive", "reference-light", "--dry-run", *argv])
        err = capsys.readouterr().err
        assert code == 2 and fragment in err and err.count("\n") == 1


def test_backlash_command_bad_order(capsys):
    assert main(["backlash", "--order", "4"]) == 2
    assert "odd" in capsys.readouterr().err
