"""Files of the wrong shape (issue 23): a wrong TOML type at any key of a scene or topology
file -- a number, text or an array where a table belongs, ``[[scene]]`` for ``[scene]``,
a table where an array of tables belongs, a number where text belongs -- and nesting
deeper than ``MAX_DEPTH`` are one :class:`InputError` line naming the file and the key,
never a traceback; the resolver's own reading of the files (``_fingerprint``,
``_remember``) passes over them."""

from __future__ import annotations

import copy
import json
import tomllib

import pytest
from gearsym import resolve
from gearsym.derive import InputError, load_target
from gearsym.derive.input.reader import MAX_DEPTH, parse_toml


def dump(value) -> str:
    """TOML of a value, inline (a table as ``{ ... }``)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float | str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(dump(v) for v in value) + "]"
    return "{" + ", ".join(f"{json.dumps(k)} = {dump(v)}" for k, v in value.items()) + "}"


def write(path, data: dict):
    path.write_text("".join(f"{json.dumps(k)} = {dump(v)}\n" for k, v in data.items()))
    return path


@pytest.fixture(scope="module")
def files(root):
    """The light-load scene and the DI-SO topology as data (the topology with a cheap
    stiffness, so that a case that passes the check does not cost a PEM run)."""
    scene = tomllib.loads((root / "scenes" / "reference-light.toml").read_text())
    scene["scene"]["topology"] = "topo.toml"
    topo = tomllib.loads((root / "scenes" / "topologies" / "diso.toml").read_text())
    for mesh in topo["mesh"]:
        mesh["stiffness"] = {"source": "contact-line", "mean_N_per_m": 4e8}
    return scene, topo


def edited(data: dict, path: tuple, value) -> dict:
    data = copy.deepcopy(data)
    inner = data
    for key in path[:-1]:
        inner = inner[key]
    inner[path[-1]] = value
    return data


# (file, where, the wrong value, the key the line must name)
CASES = [
    ("scene", ("scene",), 5, "scene: must be a table"),
    ("scene", ("scene",), [{"name": "x"}], "write [scene] once"),
    ("scene", ("scene", "topology"), 5, "scene.topology: must be text"),
    ("scene", ("scene", "topology"), ["diso"], "scene.topology: must be text"),
    ("scene", ("scene", "topology"), {"name": "diso"}, "scene.topology: must be text"),
    ("scene", ("scene", "name"), 5, "scene.name: must be text"),
    ("scene", ("scene", "description"), [1], "scene.description: must be text"),
    ("scene", ("features",), [{"backlash": "linear"}], "features: must be a table"),
    ("scene", ("features",), "all", "features: must be a table"),
    ("scene", ("features", "stiffness_harmonics"), "3", "features.stiffness_harmonics"),
    ("scene", ("features", "backlash"), 5, "features.backlash: must be text"),
    ("scene", ("features", "mesh_phase"), "yes", "features.mesh_phase"),
    ("scene", ("parameters",), [1, 2], "parameters: must be a table"),
    ("scene", ("parameters", "omega"), {"value": 1}, "parameters.omega"),
    ("scene", ("loads",), 5, "loads: must be a table"),
    ("scene", ("loads", "u"), [1], "loads.u"),
    ("scene", ("open",), [{"load_reading": "q-braking"}], "open: must be a table"),
    ("scene", ("open", "load_reading"), 5, "open.load_reading: must be text"),
    ("scene", ("open", "te_amplitude_um"), "5", "open.te_amplitude_um"),
    ("topo", ("topology",), 5, "topology: must be a table"),
    ("topo", ("topology",), [{"name": "diso"}], "write [topology] once"),
    ("topo", ("topology", "name"), 5, "topology.name: must be text"),
    ("topo", ("topology", "extends"), 5, "topology.extends"),
    ("topo", ("topology", "extends"), "none.toml", "topology.extends"),
    ("topo", ("materials",), [1], "materials: must be a table"),
    ("topo", ("materials", "steel"), 5, "materials.steel: must be a table"),
    ("topo", ("gear",), {"id": "p"}, "gear: must be an array of tables"),
    ("topo", ("gear",), "p", "gear: must be an array of tables"),
    ("topo", ("gear", 0), 5, "gear[0]: must be a table (one [[gear]] entry"),
    ("topo", ("gear", 0, "id"), 5, "gear[0].id: must be text"),
    ("topo", ("gear", 0, "teeth"), "50", "gear[0].teeth"),
    ("topo", ("gear", 2, "attached_inertia_kg_m2"), "10", "gear[2].attached_inertia_kg_m2"),
    ("topo", ("mesh",), "pg", "mesh: must be an array of tables"),
    ("topo", ("mesh", 0), [], "mesh[0]: must be a table"),
    ("topo", ("mesh", 0, "id"), ["pg"], "mesh[0].id: must be text"),
    ("topo", ("mesh", 0, "driver"), 5, "mesh[0].driver: must be text"),
    ("topo", ("mesh", 0, "stiffness"), "pem", "mesh[0].stiffness: must be a table"),
    ("topo", ("mesh", 0, "stiffness", "source"), 5, "mesh[0].stiffness.source"),
    ("topo", ("mesh", 0, "transmission_error"), [5.0], "mesh[0].transmission_error"),
    ("topo", ("mesh", 0, "transmission_error", "amplitude_um"), 5.0, "amplitude_um"),
    ("topo", ("mesh", 0, "transmission_error", "phase_deg"), "0", "phase_deg"),
    ("topo", ("mesh", 1, "layout_angle_deg"), "120", "mesh[1].layout_angle_deg"),
    ("topo", ("reading",), 5, "reading: must be an array of tables"),
    ("topo", ("reading", 0, "driving"), "p", "reading[0].driving"),
    ("topo", ("torque",), {"gear": "p"}, "torque: must be an array of tables"),
    ("topo", ("operating",), [1], "operating: must be a table"),
    ("topo", ("bearing",), 5, "bearing: must be an array of tables"),
    ("topo", ("shaft",), "x", "shaft: must be an array of tables"),
]


@pytest.mark.parametrize("which,where,value,fragment", CASES, ids=[str(c[:3]) for c in CASES])
def test_a_wrong_type_at_any_key_is_one_line_naming_file_and_key(
    files, tmp_path, monkeypatch, which, where, value, fragment
):
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    scene, topo = files
    if which == "scene":
        scene = edited(scene, where, value)
    else:
        topo = edited(topo, where, value)
    path = write(tmp_path / "scene.toml", scene)
    write(tmp_path / "topo.toml", topo)
    with pytest.raises(InputError) as err:
        load_target(path)
    line = str(err.value)
    assert "\n" not in line and len(line) < 400, line
    assert line.startswith(str(tmp_path / f"{which}.toml")), line
    assert fragment in line, line
    # The resolver reads the files itself before the derivation does: it passes over them.
    resolve._fingerprint(path)
    resolve._remember(path, "0" * 64)


def test_open_values_meet_a_topology_of_the_wrong_shape_as_one_line(files, tmp_path):
    # [open] values edit the topology's raw data before it is parsed.
    scene, topo = files
    scene = edited(scene, ("open", "flywheel_inertia_kg_m2"), 3.0)
    for where, value, fragment in [
        (("gear", 2, "attached_inertia_kg_m2"), "ten", "gear[2].attached_inertia_kg_m2"),
        (("mesh", 0, "transmission_error", "amplitude_um"), 5, "amplitude_um"),
        (("mesh",), [1, 2], "mesh[0]: must be a table"),
    ]:
        path = write(tmp_path / "scene.toml", scene)
        write(tmp_path / "topo.toml", edited(topo, where, value))
        with pytest.raises(InputError, match=fragment.replace("[", r"\[").replace("]", r"\]")):
            load_target(path)


def test_extends_names_the_file_whose_shape_is_wrong(files, tmp_path):
    scene, topo = files
    write(tmp_path / "base.toml", edited(topo, ("mesh",), {"id": "pg"}))
    own = {"topology": {"name": "own", "extends": "base.toml"}}
    path = write(tmp_path / "scene.toml", edited(scene, ("scene", "topology"), "own.toml"))
    write(tmp_path / "own.toml", own)
    with pytest.raises(InputError, match="base.toml: mesh: must be an array of tables"):
        load_target(path)


DEEP = {
    "arrays": "x = " + "[" * (MAX_DEPTH + 1) + "]" * (MAX_DEPTH + 1),
    "inline tables": "x = " + "{a = " * (MAX_DEPTH + 1) + "1" + "}" * (MAX_DEPTH + 1),
    "arrays past the parser's recursion": "x = " + "[" * 5000 + "]" * 5000,
    "inline tables past the parser's recursion": "x = " + "{a = " * 5000 + "1" + "}" * 5000,
    "dotted keys": "x" + ".a" * 5000 + " = 1",
    "table headers": "[x" + ".a" * 5000 + "]\nb = 1",
}


@pytest.mark.parametrize("how", DEEP)
def test_nesting_deeper_than_the_stated_limit_is_one_line(tmp_path, monkeypatch, how):
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    path = tmp_path / "deep.toml"
    path.write_text(DEEP[how] + "\n")
    with pytest.raises(InputError, match=f"deeper than {MAX_DEPTH} levels") as err:
        load_target(path)
    assert str(err.value).startswith(str(path)) and "\n" not in str(err.value)
    assert resolve._fingerprint(path) is None


def test_nesting_up_to_the_limit_is_read():
    limit = "x = " + "[" * (MAX_DEPTH - 1) + "]" * (MAX_DEPTH - 1)
    assert parse_toml(limit, "f.toml")["x"]
    with pytest.raises(InputError, match=f"f.toml: x: nests .* deeper than {MAX_DEPTH}"):
        parse_toml("x = " + "[" * MAX_DEPTH + "]" * MAX_DEPTH, "f.toml")
