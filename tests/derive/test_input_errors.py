"""Every kind of bad topology or scene input stops with one line naming file and key."""

import pytest
from gearsym.cli import main


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
    ("a billion teeth", "teeth = 100", "teeth = 1000000000", "gear[2].teeth: must be <= 10000"),
    (
        "face width of a million km",
        "face_width_mm = 50",
        "face_width_mm = 1e12",
        "].face_width_mm: must be <= 10000",
    ),
    (
        "module of a metre",
        "normal_module_mm = 4\n",
        "normal_module_mm = 4e3\n",
        "gear[0].normal_module_mm: must be <= 1000",
    ),
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
        'source = "potential-energy"',
        'source = "pem"',
        "mesh[0].stiffness.source: 'pem' is not one of 'harmonics', 'contact-line', "
        "'potential-energy'",
    ),
    (
        "too few samples for the harmonics",
        "slices = 200, harmonics = 10 }",
        "slices = 200, harmonics = 40, samples = 64 }",
        "mesh[0].stiffness.samples: needs more than 80 samples per mesh period",
    ),
    (
        "zero slices",
        "slices = 200, harmonics = 10 }",
        "slices = 0, harmonics = 10 }",
        "mesh[0].stiffness.slices: must be >= 1, got 0",
    ),
    (
        "rack root radius too large",
        'id = "p"\n',
        'id = "p"\nrack_root_radius = 0.9\n',
        "gear[0].rack_root_radius: must be <= 0.6, got 0.9",
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
        "keyword coordinate",
        'coordinate = "v"',
        'coordinate = "if"',
        "mesh[1].coordinate: 'if' must be letters and digits starting with a letter, and not "
        "a Python keyword",
    ),
    (
        "coordinate clashing with a derivative",
        'coordinate = "v"',
        'coordinate = "du"',
        "mesh: coordinates 'u' and 'du' clash",
    ),
    (
        "coordinate named like a backlash coefficient",
        'coordinate = "v"',
        'coordinate = "g1"',
        "mesh[1].coordinate: 'g1' is reserved",
    ),
    (
        "phase on the first mesh",
        'coordinate = "u"',
        'coordinate = "u"\nstiffness_phase_deg = 90',
        "mesh[0].stiffness_phase_deg: the first mesh sets the time origin",
    ),
    (
        "misspelt layout key",
        "layout_angle_deg = 120",
        "layout_angle = 120",
        "mesh[1].layout_angle: unknown key (did you mean 'layout_angle_deg'?)",
    ),
    (
        "involute interference",
        "teeth = 50\nnormal_module_mm = 4\nnormal_pressure_angle_deg = 20\nhelix_angle_deg = 10"
        '\nface_width_mm = 50\nmaterial = "steel"\nbore_radius_mm = 30',
        "teeth = 8\nnormal_module_mm = 4\nnormal_pressure_angle_deg = 20\nhelix_angle_deg = 10"
        '\nface_width_mm = 50\nmaterial = "steel"\nbore_radius_mm = 5',
        "mesh[0].driven: involute interference: the tip of 'g' reaches below the base circle "
        "of 'p'",
    ),
    (
        "vanishing stiffness",
        '{ source = "potential-energy", slices = 200, harmonics = 10 }',
        '{ source = "harmonics", mean_N_per_m = 1e-320 }',
        "mean_N_per_m: must be >= 1000",
    ),
    (
        "misspelt array of tables",
        '[[torque]]\ngear = "q"',
        '[[torqe]]\ngear = "q"',
        "torqe: unknown key (did you mean 'torque'?)",
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
    (
        "reading names an unknown mesh",
        'reversed = ["qg"]',
        'reversed = ["qh"]',
        "reading[1].reversed: names no mesh 'qh' (did you mean 'qg'?)",
    ),
    (
        "gear both drives and brakes",
        'braking = ["q"]',
        'braking = ["q", "p"]',
        "reading[0].braking: gear 'p' cannot both drive and brake",
    ),
    (
        "tip radius where the diameter belongs",
        'id = "p"\nteeth = 50',
        'id = "p"\nteeth = 50\ntip_diameter_mm = 105.5',
        "gear[0].tip_diameter_mm: 105.5 mm must exceed both the root circle (193.085 mm) and "
        "the base circle (190.492 mm); give the tip diameter (not the radius) in mm",
    ),
    (
        "tip diameter above the standard tip",
        'id = "p"\nteeth = 50',
        'id = "p"\nteeth = 50\ntip_diameter_mm = 215',
        "gear[0].tip_diameter_mm: 215 mm is more than 0.8 mm (0.2 mn) above the standard tip "
        "diameter d + 2 (1 + x) mn = 211.085 mm",
    ),
    (
        "centre distance inside the base circles",
        'coordinate = "u"',
        'coordinate = "u"\ncentre_distance_mm = 280',
        "mesh[0].centre_distance_mm: 280 mm is not above the sum of the base radii (285.738 mm)",
    ),
    (
        "centre distance far beyond the reference",
        'coordinate = "u"',
        'coordinate = "u"\ncentre_distance_mm = 320',
        "mesh[0].centre_distance_mm: 320 mm is more than 2 mn beyond the reference centre "
        "distance 304.628 mm (at most 312.628 mm)",
    ),
    (
        "centre distance too close for the profile shifts",
        'coordinate = "u"',
        'coordinate = "u"\ncentre_distance_mm = 304.5',
        "mesh[0].centre_distance_mm: 304.5 mm fits profile shifts summing to -0.0319 without "
        "backlash, but x1 + x2 = 0: the teeth would jam; give at least 304.628 mm",
    ),
    (
        "orientation typo",
        'coordinate = "v"',
        'coordinate = "v"\norientation = "reverse"',
        "mesh[1].orientation: 'reverse' is not one of 'forward', 'reversed' (did you mean",
    ),
    # bearings, shafts, positions, masses (issue 15)
    (
        "bearing on an unknown gear",
        "[operating]",
        '[[bearing]]\ngear = "pp"\nradial_N_per_m = 1e9\naxial_N_per_m = 1e9\n[operating]',
        "bearing[0].gear: names unknown gear 'pp' (did you mean 'p'?)",
    ),
    (
        "two bearings on one gear",
        "[operating]",
        '[[bearing]]\ngear = "p"\nradial_N_per_m = 1e9\naxial_N_per_m = 1e9\n'
        '[[bearing]]\ngear = "p"\nradial_N_per_m = 1e9\naxial_N_per_m = 1e9\n[operating]',
        "bearing[1].gear: gear 'p' has a bearing already",
    ),
    (
        "negative bearing stiffness",
        "[operating]",
        '[[bearing]]\ngear = "p"\nradial_N_per_m = -1e9\naxial_N_per_m = 1e9\n[operating]',
        "bearing[0].radial_N_per_m: must be > 0",
    ),
    (
        "a shaft closes a loop",
        "[operating]",
        '[[shaft]]\nid = "w"\ngears = ["p", "q"]\ntorsional_Nm_per_rad = 1e5\n[operating]',
        "3 gears need exactly 2 meshes and shafts (a tree), got 3",
    ),
    (
        "a shaft with one gear",
        "[operating]",
        '[[shaft]]\nid = "w"\ngears = ["p"]\ntorsional_Nm_per_rad = 1e5\n[operating]',
        "shaft[0].gears: must be a list of two gear ids",
    ),
    (
        "driver position beyond a turn",
        "layout_angle_deg = 120",
        "layout_angle_deg = 120\ndriver_position_deg = 400",
        "mesh[1].driver_position_deg: must be <= 360",
    ),
    (
        "negative attached mass",
        "attached_inertia_kg_m2 = 10.0",
        "attached_inertia_kg_m2 = 10.0\nattached_mass_kg = -5",
        "gear[2].attached_mass_kg: must be >= 0",
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
    (
        "negative omega",
        "omega = 0.5 ",
        "omega = -0.5 ",
        "parameters.omega: must be in [0.001, 1000], got -0.5",
    ),
    (
        "load uses unknown parameter",
        'v = "lambda*f1"',
        'v = "-lamda*f1"',
        "loads.v: 'lamda' in '-lamda*f1' is not a scene parameter (did you mean 'lambda'?)",
    ),
    (
        "load expression with a call",
        'v = "lambda*f1"',
        'v = "__import__(1)"',
        "loads.v: '__import__(1)' may use only numbers",
    ),
    (
        "load for unknown coordinate",
        'v = "lambda*f1"',
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
        "key of another backlash model",
        'backlash = "polynomial"',
        'backlash = "smooth"',
        "features.backlash_order: applies to backlash = 'polynomial' only, not 'smooth'",
    ),
    (
        "backlash fit step too small",
        "backlash_step = 0.01",
        "backlash_step = 1e-7",
        "features.backlash_step: step 1e-07 gives 60000001 samples",
    ),
    (
        "load overflows",
        'v = "lambda*f1"',
        'v = "10**10**10"',
        "loads.v: '10**10**10' overflows",
    ),
    (
        "load is complex",
        'v = "lambda*f1"',
        'v = "(-1)**0.5"',
        "loads.v: '(-1)**0.5' is not a real number",
    ),
    (
        "load too long",
        'v = "lambda*f1"',
        'v = "' + "-" * 5000 + '1"',
        "is not a plain arithmetic expression of at most 200 characters",
    ),
    (
        "mangled keyword smuggled in",
        'v = "lambda*f1"',
        'v = "-lambda__kw*f1"',
        "is not a plain arithmetic expression",
    ),
    (
        "harmonics out of range",
        "stiffness_harmonics = 3",
        "stiffness_harmonics = -1",
        "features.stiffness_harmonics: must be >= 0",
    ),
    (
        "unknown load reading",
        'load_reading = "q-braking"',
        'load_reading = "q-brake"',
        "load_reading: 'q-brake' is not a reading of topology 'diso' (did you mean 'q-braking'?)",
    ),
    (
        "signed load under a reading",
        'v = "lambda*f1"',
        'v = "-lambda*f1"',
        "loads.v: '-lambda*f1' = -0.01 < 0: with a load_reading the load is a size",
    ),
    (
        "unknown damping normalisation",
        'damping_normalisation = "mesh"',
        'damping_normalisation = "modla"',
        "damping_normalisation: 'modla' is not one of mesh, modal (did you mean 'modal'?)",
    ),
    (
        "unknown open value",
        'load_reading = "q-braking"',
        'load_reading = "q-braking"\nflywheel_inertia = 3.0',
        "flywheel_inertia: is not an open value (did you mean 'flywheel_inertia_kg_m2'?)",
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


def test_topology_target_parameters_are_checked(root, capsys):
    topo = root / "scenes" / "topologies" / "diso.toml"
    for setting, fragment in (
        ("omega=-5", "operating.omega: must be in [0.001, 1000], got -5"),
        ("damping_ratio=5", "operating.damping_ratio: must be in [0, 1], got 5"),
    ):
        code = main(["derive", str(topo), "--dry-run", "--set", setting])
        err = capsys.readouterr().err
        assert code == 2 and fragment in err and err.count("\n") == 1


def test_layout_rule_refuses_an_idler(tmp_path, capsys):
    # p drives g, g drives h: g is driven in the first mesh and driver in the second, so
    # opposite flanks carry load and the plain layout rule does not apply.
    path = tmp_path / "idler.toml"
    gear = "teeth = {z}\nnormal_module_mm = 4\nface_width_mm = 40\n"
    path.write_text(
        '[topology]\nname = "idler"\n'
        + "".join(
            f'[[gear]]\nid = "{g}"\n' + gear.format(z=z)
            for g, z in (("p", 30), ("g", 40), ("h", 50))
        )
        + '[[mesh]]\nid = "pg"\ndriver = "p"\ndriven = "g"\ncoordinate = "u"\n'
        'half_backlash_um = 50\nstiffness = { source = "harmonics", mean_N_per_m = 1e9 }\n'
        '[[mesh]]\nid = "gh"\ndriver = "g"\ndriven = "h"\ncoordinate = "v"\n'
        'half_backlash_um = 50\nstiffness = { source = "harmonics", mean_N_per_m = 1e9 }\n'
        "layout_angle_deg = 100\n"
    )
    code, err = derive(capsys, path)
    assert_one_line_error(
        code,
        err,
        path,
        "mesh[1].layout_angle_deg: gear 'g' is the driven in mesh 'pg' but the driver here",
    )


def test_more_harmonics_than_the_mesh_gives(files, capsys, root):
    tmp, topo, scene = files
    topo = topo.replace(
        'stiffness = { source = "potential-energy", slices = 200, harmonics = 10 }',
        'stiffness = { source = "harmonics", mean_N_per_m = 1.0e9, cos_N_per_m = [1e7], '
        "sin_N_per_m = [0.0] }",
    )
    (tmp / "topologies").mkdir()
    (tmp / "topologies" / "diso.toml").write_text(topo)
    path = tmp / "scene.toml"
    path.write_text(scene)
    code, err = derive(capsys, path)
    assert_one_line_error(
        code, err, path, "features.stiffness_harmonics: asks for 3 harmonics but mesh 'pg'"
    )


def test_negative_profile_shifts_say_what_is_wrong(tmp_path, capsys):
    path = tmp_path / "shifted.toml"
    gear = "teeth = 10\nnormal_module_mm = 4\nface_width_mm = 40\nprofile_shift = -1.0\n"
    path.write_text(
        '[topology]\nname = "shifted"\n'
        + "".join(f'[[gear]]\nid = "{g}"\n' + gear for g in "pg")
        + '[[mesh]]\nid = "pg"\ndriver = "p"\ndriven = "g"\ncoordinate = "u"\n'
        'half_backlash_um = 50\nstiffness = { source = "harmonics", mean_N_per_m = 1e9 }\n'
    )
    code, err = derive(capsys, path)
    assert_one_line_error(
        code, err, path, "(x1 + x2 = -2) leave no positive working pressure angle"
    )


def test_undercut_gear_with_the_energy_method_is_refused(tmp_path, capsys):
    # 12 teeth of a 20 deg rack without profile shift are undercut (limit 17): the
    # potential-energy tooth assumes a full involute; the loader warns, the method refuses.
    path = tmp_path / "undercut.toml"
    path.write_text(
        '[topology]\nname = "undercut"\n'
        '[[gear]]\nid = "p"\nteeth = 12\nnormal_module_mm = 4\nface_width_mm = 40\n'
        "profile_shift = 0.0\n"
        '[[gear]]\nid = "g"\nteeth = 12\nnormal_module_mm = 4\nface_width_mm = 40\n'
        "profile_shift = 0.6\n"
        '[[mesh]]\nid = "pg"\ndriver = "p"\ndriven = "g"\ncoordinate = "u"\n'
        'half_backlash_um = 50\nstiffness = { source = "potential-energy" }\n'
    )
    with pytest.warns(UserWarning, match=r"gear\[0\].teeth: 12 teeth .* are undercut"):
        code, err = derive(capsys, path)
    assert_one_line_error(code, err, path, "mesh[0].stiffness.source: gear 'p' is undercut")


def test_mating_tip_in_the_fillet_is_refused(tmp_path, capsys):
    # A large rack tip rounding raises the form circle above the point where the mating
    # tip meets the flank: the contact would run into the fillet.
    path = tmp_path / "fillet.toml"
    gear = "normal_module_mm = 4\nface_width_mm = 40\nrack_dedendum = 1.1\nrack_root_radius = 0.6\n"
    path.write_text(
        '[topology]\nname = "fillet"\n'
        '[[gear]]\nid = "p"\nteeth = 30\n'
        + gear
        + '[[gear]]\nid = "g"\nteeth = 90\n'
        + gear
        + '[[mesh]]\nid = "pg"\ndriver = "p"\ndriven = "g"\ncoordinate = "u"\n'
        'half_backlash_um = 50\nstiffness = { source = "harmonics", mean_N_per_m = 1e9 }\n'
    )
    code, err = derive(capsys, path)
    assert_one_line_error(code, err, path, "tip interference: the tip of 'g' meets 'p'")


def _pair_file(tmp_path, pinion, gear):
    path = tmp_path / "pair.toml"
    common = "normal_module_mm = 4\nface_width_mm = 40\n"
    path.write_text(
        '[topology]\nname = "pair"\n'
        f'[[gear]]\nid = "p"\n{pinion}\n'
        + common
        + f'[[gear]]\nid = "g"\n{gear}\n'
        + common
        + '[[mesh]]\nid = "pg"\ndriver = "p"\ndriven = "g"\ncoordinate = "u"\n'
        'half_backlash_um = 50\nstiffness = { source = "harmonics", mean_N_per_m = 1e9 }\n'
    )
    return path


def test_pointed_teeth_are_refused(tmp_path, capsys):
    path = _pair_file(tmp_path, "teeth = 8\nprofile_shift = 1.5", "teeth = 60")
    code, err = derive(capsys, path)
    assert_one_line_error(
        code, err, path, "gear[0].profile_shift: 8 teeth with profile shift 1.5 are pointed"
    )


def test_negative_tip_clearance_is_refused(tmp_path, capsys):
    # Without tip shortening, large positive shifts on both gears push each tip into the
    # other's root circle.
    path = _pair_file(
        tmp_path, "teeth = 20\nprofile_shift = 0.6", "teeth = 25\nprofile_shift = 1.0"
    )
    code, err = derive(capsys, path)
    assert_one_line_error(code, err, path, "negative tip clearance")


def test_extends_names_a_missing_file(tmp_path, capsys):
    path = tmp_path / "topo.toml"
    path.write_text('[topology]\nextends = "nowhere.toml"\nname = "x"\n')
    assert_one_line_error(
        *derive(capsys, path), path, "topology.extends: 'nowhere.toml' is not a file next to"
    )


def test_lateral_freedom_without_bearings_is_refused(files, capsys):
    """reference-light on diso.toml (no bearings) asked for lateral freedom."""
    tmp, _, scene = files
    path = tmp / "scene.toml"
    text = scene.replace('topology = "topologies/diso.toml"', 'topology = "diso"')
    path.write_text(
        text.replace("[features]", '[features]\ndegrees_of_freedom = "lateral-torsional"')
    )
    code, err = derive(capsys, path)
    assert code == 2 and err.count("\n") == 1
    assert "features.degrees_of_freedom" in err and "have no [[bearing]]" in err, err


def test_pointed_teeth_at_the_given_tip_are_refused(tmp_path, capsys):
    # 8 teeth with x = 1.5 end in a point at d_a = 47.897 mm (see test_geometry): a drawn tip
    # of 50 mm, below the standard 52 mm, is still pointed.
    path = _pair_file(
        tmp_path, "teeth = 8\nprofile_shift = 1.5\ntip_diameter_mm = 50", "teeth = 60"
    )
    code, err = derive(capsys, path)
    assert_one_line_error(
        code,
        err,
        path,
        "gear[0].tip_diameter_mm: the teeth are pointed at 50 mm (tip thickness -2.759 mm); "
        "give a tip diameter below 47.897 mm",
    )


def test_a_shaft_may_not_take_a_reserved_name(tmp_path, root, capsys):
    text = (root / "scenes" / "topologies" / "two-stage.toml").read_text()
    path = tmp_path / "two.toml"
    path.write_text(text.replace('id = "w"', 'id = "tau"'))
    code, err = derive(capsys, path)
    assert code == 2 and err.count("\n") == 1
    assert "shaft id 'tau' is reserved" in err, err


def test_tilting_needs_the_tilting_stiffness_of_every_bearing(tmp_path, root, capsys):
    topo = tmp_path / "pair.toml"
    topo.write_text(
        f'[topology]\nextends = "{root / "scenes" / "topologies" / "siso.toml"}"\n'
        'name = "pair"\n'
        '[[bearing]]\ngear = "p"\nradial_N_per_m = 1e9\naxial_N_per_m = 1e9\n'
        "tilt_Nm_per_rad = 1e7\n"
        '[[bearing]]\ngear = "g"\nradial_N_per_m = 1e9\naxial_N_per_m = 1e9\n'
    )
    scene = tmp_path / "scene.toml"
    scene.write_text(
        f'[scene]\nname = "tilted"\ntopology = "{topo}"\n'
        '[features]\ndegrees_of_freedom = "lateral-torsional-axial-tilting"\n'
        "[parameters]\nomega = 0.5\ndamping_ratio = 0.03\n"
    )
    code, err = derive(capsys, scene)
    assert code == 2 and err.count("\n") == 1
    assert "gear(s) g" in err and "tilt_Nm_per_rad" in err, err
