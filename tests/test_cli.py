"""End-to-end tests of the `gearsym` command line."""

import json
import subprocess
import sys

import pytest
from gearsym.cli import main
from gearsym.derive.build import (
    build_files,
    check,
    shipped_targets,
    write_files,
    write_stiffness_figure,
)


def run(capsys, *argv):
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_check_names_a_stale_file(tmp_path):
    # one regeneration of two targets for the three checks (each would make the same
    # again: the code and the inputs do not change in between); the whole shipped set's
    # `gearsym derive --check` is .ci/run's own step, after the tests
    two = [p for p in shipped_targets() if p.stem in ("siso", "tiso")]
    assert len(two) == 2
    built = build_files(two, index=True)
    write_files(built.files, tmp_path)
    assert check(tmp_path, built) == ["docs/stiffness.png (missing)"]
    write_stiffness_figure(tmp_path)
    assert check(tmp_path, built) == []
    target = tmp_path / "generated" / "siso.py"
    target.write_text(target.read_text() + "# edited by hand\n")
    (tmp_path / "docs" / "derivation" / "tiso.md").unlink()
    stale = check(tmp_path, built)  # a hand edit keeps the inputs hash: both causes said
    assert stale[1:] == ["docs/derivation/tiso.md (missing)"]
    assert stale[0].startswith("generated/siso.py (differs under the same INPUTS_SHA256: ")
    assert "edited by hand" in stale[0] and "bump EMITTED_FORMAT" in stale[0]


def test_derive_json_has_every_number(capsys):
    code, out, _ = run(capsys, "derive", "reference-light", "--json", "--dry-run")
    assert code == 0
    data = json.loads(out)["reference_light"]
    assert data["states"] == ["u", "v", "du", "dv"]
    assert set(data["kappa"]) == {"uu", "uv", "vu", "vv"}
    assert len(data["kappa"]["uv"]["cos"]) == 3 and len(data["kappa"]["uv"]["sin"]) == 3
    assert data["kappa"]["vv"]["phase_rad"] == pytest.approx(2.0943951023931957)
    assert set(data["xi"]) == {"uu", "uv", "vu", "vv"}
    assert data["f"] == {"u": 0.1, "v": pytest.approx(-0.01)}
    assert data["omega"] == 0.5
    assert data["backlash"]["valid_range"] == 3.0
    assert set(data["backlash"]["coefficients"]) == {"1", "3", "5", "7"}
    assert data["transmission_error"]["u"]["amplitude"] == [pytest.approx(0.1)]
    assert data["operations"]["rhs"] > 0
    assert data["scales"]["omega_n_rad_per_s"] > 0


def test_set_overrides_a_scene_parameter(capsys):
    code, out, _ = run(
        capsys, "derive", "reference-light", "--json", "--dry-run", "--set", "lambda=0.8"
    )
    assert code == 0
    assert json.loads(out)["reference_light"]["f"]["v"] == pytest.approx(-0.08)


def test_backlash_command_reproduces_the_study(capsys):
    code, out, _ = run(capsys, "backlash", "--order", "7", "--json")
    assert code == 0
    data = json.loads(out)
    coeff = {k: round(v, 4) for k, v in data["coefficients"].items()}
    # Reference: the study's printed polynomial.
    assert coeff == {"1": -0.1555, "3": 0.2833, "5": -0.0366, "7": 0.0017}
    assert data["valid_range"] == [-3.0, 3.0]
    assert 0 < data["max_error_vs_dead_zone"] < 0.2


def test_regenerating_a_topology_with_an_added_input_gear(tmp_path, root, capsys):
    text = (root / "scenes" / "topologies" / "diso.toml").read_text()
    text = text.replace('name = "diso"', 'name = "diso_plus"')
    extra = """
[[gear]]
id = "s"
teeth = 50
normal_module_mm = 4
normal_pressure_angle_deg = 20
helix_angle_deg = 10
face_width_mm = 50

[[mesh]]
id = "sg"
driver = "s"
driven = "g"
coordinate = "w"
half_backlash_um = 50
stiffness = { source = "contact-line", mean_N_per_m = 1.0e9 }
layout_angle_deg = 240
"""
    head, sep, tail = text.partition("# Used when the topology is derived on its own")
    path = tmp_path / "diso_plus.toml"
    path.write_text(head + extra + sep + tail)
    out_dir = tmp_path / "out"
    code, out, err = run(capsys, "derive", str(path), "--out", str(out_dir))
    assert code == 0, err
    sys.path.insert(0, str(out_dir / "generated"))
    try:
        import diso_plus
    finally:
        sys.path.pop(0)
    assert diso_plus.STATES == ("u", "v", "w", "du", "dv", "dw")
    page = (out_dir / "docs" / "derivation" / "diso_plus.md").read_text()
    assert "x_{sg}" in page and "K_{ww}" in page and "kappa_w_w" in page
    assert "| s | 50 |" in page


def test_console_script_runs_without_traceback_on_bad_input(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[scene]\nname = 'x'\n")
    proc = subprocess.run(
        [sys.executable, "-m", "gearsym.cli", "derive", str(bad)],
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert proc.stderr.count("\n") == 1
    assert "scene.topology: is required but missing" in proc.stderr


def test_stiffness_command_reports_pem_iso_and_phase(tmp_path, capsys):
    # Acceptance of the stiffness issue on the reference gears: contact ratios 1.76 / 0.69
    # / 2.45 (the study's Table 1), km within 25 % of ISO 6336-1's c_gamma_alpha b, the
    # layout phase 2 pi / 3 of diso.toml's 120 deg (100 teeth * 120/360 = 33 1/3).
    import json
    import math

    plot = tmp_path / "k.png"
    assert main(["stiffness", "diso", "--json", "--plot", str(plot)]) == 0
    out = json.loads(capsys.readouterr().out)
    pg, qg = out["meshes"]
    cr = pg["contact_ratio"]
    assert (round(cr["transverse"], 2), round(cr["axial"], 2), round(cr["total"], 2)) == (
        1.76,
        0.69,
        2.45,
    )
    assert 0.75 <= pg["pem_over_iso"] <= 1.25
    assert (
        pg["pem_over_iso"]
        == pg["pem"]["mean_N_per_m"] / pg["iso6336"]["k_from_c_gamma_alpha_N_per_m"]
    )
    assert len(pg["pem"]["harmonics"]) == 3
    assert [r["slices"] for r in pg["convergence"]] == [10, 50, 200, 1000]
    assert qg["phase"]["rad"] == pytest.approx(2 * math.pi / 3, rel=1e-12)
    assert qg["transmission_error"]["amplitude_um"] == [5.0]
    assert (tmp_path / "k_pg.png").stat().st_size > 0
    assert (tmp_path / "k_qg.png").stat().st_size > 0
    assert main(["stiffness", "reference-light", "--mesh", "pg", "--harmonics", "5"]) == 0
    text = capsys.readouterr().out
    assert "k_5:" in text and "PEM / ISO" in text


def test_built_in_names_take_underscores_and_user_scenes_derive_into_the_cache(
    tmp_path, root, capsys, monkeypatch
):
    # Issue 11: built-in names with hyphens or underscores; a user's scene is derived into
    # the user cache (never into the installed package) where the resolver finds it.
    monkeypatch.setenv("GEARSYM_CACHE", str(tmp_path / "cache"))
    code, out, err = run(capsys, "derive", "reference_light", "--dry-run")
    assert code == 0, err
    text = (root / "scenes" / "reference-light.toml").read_text()
    text = text.replace('name = "reference-light"', 'name = "my-light"')
    topo = (root / "scenes" / "topologies" / "diso.toml").as_posix()
    text = text.replace('topology = "topologies/diso.toml"', f'topology = "{topo}"')
    scene = tmp_path / "my-light.toml"
    scene.write_text(text)
    code, out, err = run(capsys, "derive", str(scene))
    assert code == 0, err
    written = sorted((tmp_path / "cache" / "models").iterdir())
    assert [p.suffix for p in written] == [".md", ".py", ".sha256"], written
    assert not (root / "generated" / "my_light.py").exists()
    import warnings

    from gearsym.resolve import module_for

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the module and its digest agree: no re-derivation
        assert module_for(scene).__file__ == str(written[1])
