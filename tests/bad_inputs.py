"""The bad-input table: what a user can get wrong on every command, and the words the one
line of the refusal must contain.

Each case is ``(argv, fragment)``: ``argv`` is a command line after ``gearsym`` whose
placeholders name files the test makes (``{tmp}`` a writable folder, ``{file}`` a regular
file, ``{bad_utf8}`` a TOML file that is not UTF-8, ``{empty}`` an empty file,
``{brace}`` a JSON file holding ``{}``, ``{torn}`` a truncated JSON file, ``{scene:KEY}``
a copy of the light-load scene with one line replaced, see ``SCENE_EDITS``).  Every case
must end with exit code 2 and one line on stderr, before any computing.
``tests/test_bad_inputs.py`` runs them; ``benchmarks/robustness.py`` lists them in
``docs/robustness.md``.
"""

from __future__ import annotations

S = "simulate reference-light"
SW = "sweep reference-light --param lambda"
SH = "shoot reference-light"
CO = "continue reference-light --param lambda"
MP = "map reference-light"
FR = "frequency-response reference-light"
MAPXY = "--x lambda=0:1:3 --y f1=0.1:0.2:2"

# One replaced line of scenes/reference-light.toml: (old, new).
SCENE_EDITS = {
    "damping": ("damping_ratio = 0.03", "damping_ratio = -0.1"),
    "omega_text": ("omega = 0.5 ", 'omega = "fast" '),
    "backlash": ('backlash = "polynomial"', 'backlash = "polynominal"'),
    "unknown": ("mesh_phase = true", "mesh_phase = true\nmesh_phaze = true"),
    "syntax": ("f1 = 0.1 ", "f1 = = 0.1 "),
    "unused": ("lambda = 0.1 ", "lambda = 0.1\nlamda = 0.2 "),
    "reading": ('load_reading = "q-braking"', 'load_reading = "q-breaking"'),
    "flywheel": (
        'damping_normalisation = "mesh"',
        'damping_normalisation = "mesh"\nflywheel_inertia_kg_m2 = -1',
    ),  # fmt: skip
    "dofs": ("mesh_phase = true", 'mesh_phase = true\ndegrees_of_freedom = "lateral"'),
    "tilting": (
        "mesh_phase = true",
        'mesh_phase = true\ndegrees_of_freedom = "lateral-torsional-axial-tilting"',
    ),  # fmt: skip
}

OUT_COMMANDS = [
    "derive reference-light",
    f"{S} --periods 2 --transient 1",
    f"{SW} --range 0:1:3",
    SH,
    f"{CO} --from 0.1 --to 0.2",
    f"{MP} {MAPXY}",
    f"{FR} --param omega=0.4:0.5:3",
    "reproduce --quick",
    "bench --quick",
]
BAD_OUT = [
    ("/dev/null", "/dev/null"),
    ("{file}", "afile.txt"),
    ("/proc/gearsym-out", "/proc/gearsym-out"),
    ("{file}/sub", "sub"),
]

CASES: list[tuple[str, str]] = [
    (f"{cmd} --out {path}", fragment) for cmd in OUT_COMMANDS for path, fragment in BAD_OUT
]

CASES += [
    # stiffness --plot: format and path
    ("stiffness diso --plot {tmp}/k.xyz", "xyz"),
    ("stiffness diso --plot /proc/gearsym/k.png", "/proc/gearsym"),
    ("stiffness diso --plot {file}/k.png", "is a file"),
    ("stiffness diso --plot {tmp}", "--plot"),
    # scene files
    ("simulate {bad_utf8}", "UTF-8"),
    ("simulate {empty}", "empty"),
    ("simulate {tmp}", "is a folder"),
    ("simulate {tmp}/missing.toml", "missing.toml"),
    ("simulate reference-lite", "reference-light"),
    ("simulate {scene:damping}", "damping_ratio"),
    ("simulate {scene:omega_text}", "omega"),
    ("simulate {scene:backlash}", "polynominal"),
    ("simulate {scene:unknown}", "mesh_phaze"),
    ("simulate {scene:syntax}", "line"),
    ("simulate {scene:reading}", "q-breaking"),
    ("simulate {scene:unused}", "parameters.lamda: is not used by any load"),
    ("simulate {scene:flywheel}", "flywheel_inertia_kg_m2"),
    ("simulate {scene:dofs}", "degrees_of_freedom"),
    ("simulate {scene:tilting}", "have no [[bearing]]"),
    # modes (issue 15)
    ("modes reference-lite", "reference-light"),
    ("modes diso --speeds 3000", "--speeds"),
    ("modes diso --speeds 2000:1000", "--speeds"),
    ("modes diso --speeds=-5:100", "--speeds"),
    ("modes diso --plot {tmp}/c.xyz", "xyz"),
    ("derive {bad_utf8}", "UTF-8"),
    ("derive {scene:syntax}", "line"),
    ("stiffness {bad_utf8}", "UTF-8"),
    # --set: every parameter checked once, whichever way it arrives
    (f"{S} --set damping_ratio=-0.1", "damping_ratio"),
    (f"{S} --set damping_ratio=2", "damping_ratio"),
    (f"{S} --set omega=0", "omega"),
    (f"{S} --set omega=-1", "omega"),
    (f"{S} --set lambda=nan", "finite"),
    (f"{S} --set f1=inf", "finite"),
    (f"{S} --set lambda=abc", "not a number"),
    (f"{S} --set lambda", "key=value"),
    (f"{S} --set =1", "key=value"),
    (f"{S} --set lamda=0.2", "lambda"),
    (f"{S} --set lambda=0.1 --set lambda=0.2", "twice"),
    (f"{S} --set f1=1e6", "valid range"),
    (f"{S} --set load_reading=sideways", "load_reading"),
    (f"{S} --set damping_normalisation=foo", "damping_normalisation"),
    (f"{S} --set te_amplitude_um=-5", "te_amplitude_um"),
    (f"{S} --set flywheel_inertia_kg_m2=-1", "flywheel_inertia_kg_m2"),
    (f"{S} --set stiffness_harmonic_scale=50", "stiffness"),
    (f"{S} --set layout_angle_deg=nan", "layout_angle_deg"),
    (f"{S} --set te_phase_deg_xy=10", "te_phase_deg_xy"),
    # the analysis options
    (f"{S} --rtol 0", "--rtol"),
    (f"{S} --rtol -1e-8", "--rtol"),
    (f"{S} --rtol nan", "--rtol"),
    (f"{S} --rtol 0.5", "--rtol"),
    (f"{S} --atol 0", "--atol"),
    (f"{S} --atol inf", "--atol"),
    (f"{S} --transient -1", "--transient"),
    (f"{S} --periods 0", "--periods"),
    (f"{S} --periods 1e3", "--periods"),
    (f"{S} --periods 100000000", "memory"),
    (f"{S} --lyapunov-periods -1", "--lyapunov-periods"),
    (f"{S} --transient=-5", "--transient"),
    (f"{S} --method rk45", "--method"),
    (f"{S} --on-invalid ignore", "--on-invalid"),
    (f"{S} --x0 1,2", "--x0"),
    (f"{S} --x0 a,b,c,d,e,f", "--x0"),
    (f"{S} --x0 nan,0,0,0", "--x0"),
    (f"{S} --x0 9,0,0,0", "valid range"),
    (f"{S} --from-sweep {{tmp}}/none.json --at 0.5", "none.json"),
    (f"{S} --from-sweep {{brace}} --at 0.5", "brace.json"),
    (f"{S} --from-sweep {{torn}} --at 0.5", "torn.json"),
    (f"{S} --from-sweep {{bad_utf8}} --at 0.5", "bad.toml"),
    (f"{S} --at 0.5", "--at"),
    (f"{S} --x0 1,0,1,0,0,0 --from-sweep {{brace}}", "--from-sweep"),
    (f"{S} --unknown-option", "--unknown-option"),
    ("simulate", "SCENE"),
    ("simulat reference-light", "simulate"),
    (f"{S} --set lambda=1e6", "valid range"),
    # sweep
    (f"{SW} --range 0.5:0.5:3", "--range"),
    (f"{SW} --range 1:0:0", "--range"),
    (f"{SW} --range a:b:c", "--range"),
    (f"{SW} --range 0:1", "--range"),
    (f"{SW} --range 0:1:2.5", "--range"),
    (f"{SW} --range 0:1:100000000", "memory"),
    (f"{SW} --range 0:1:3 --set lambda=0.3", "lambda"),
    (f"{SW} --range 0:1:3 --backward --independent", "--independent"),
    (f"{SW} --range 0:1:3 --executor serial --scheduler tcp://x:1", "--scheduler"),
    (f"{SW} --range 0:1:3 --executor processes --scheduler tcp://x:1", "--scheduler"),
    ("sweep reference-light --param lamda --range 0:1:3", "lambda"),
    ("sweep reference-light --param damping_ratio --range=-0.1:0.1:3", "damping_ratio"),
    ("sweep reference-light --param omega --range=-1:1:3", "omega"),
    ("sweep reference-light --param omega --range -1:1:3", "--range=VALUE"),
    ("sweep reference-light --param f1 --range 0:1e9:3", "f1"),
    ("sweep reference-light --range 0:1:3", "--param"),
    (f"{SW}", "--range"),
    (f"{SW} --range 0:1:3 --periods 0", "--periods"),
    (f"{SW} --range 0:1:3 --lyapunov-periods -5", "--lyapunov-periods"),
    (f"{SW} --range 0:1:3 --rtol 2", "--rtol"),
    (f"{SW} --range 0:1:3 --set damping_ratio=5", "damping_ratio"),
    (f"{SW} --range 0:1:3 --executor threads", "--executor"),
    ("sweep reference-light --param load_reading --range 0:1:3", "load_reading"),
    # shoot
    (f"{SH} --period 0", "--period"),
    (f"{SH} --period -2", "--period"),
    (f"{SH} --tries -1", "--tries"),
    (f"{SH} --segments 0", "--segments"),
    (f"{SH} --segments 100000", "memory"),
    (f"{SH} --settle -1", "--settle"),
    (f"{SH} --monodromy exact", "--monodromy"),
    (f"{SH} --seed -1", "--seed"),
    (f"{SH} --x0 1,2,3", "--x0"),
    (f"{SH} --set damping_ratio=-1", "damping_ratio"),
    (f"{SH} --set omega=nan", "finite"),
    (f"{SH} --from-sweep {{torn}} --at 0.5", "torn.json"),
    (f"{SH} --at 0.3", "--at"),
    # continue
    (f"{CO} --from 0.5 --to 0.5", "--to"),
    (f"{CO} --from 0.1 --to 0.5 --step 0", "--step"),
    (f"{CO} --from 0.1 --to 0.5 --step -0.1", "--step"),
    (f"{CO} --from 0.1 --to 0.5 --period 0", "--period"),
    (f"{CO} --from nan --to 0.5", "--from"),
    (f"{CO} --from 0.1 --to inf", "--to"),
    ("continue reference-light --param lamda --from 0.1 --to 0.5", "lambda"),
    ("continue reference-light --param damping_ratio --from -0.1 --to 0.1", "damping_ratio"),
    (f"{CO} --from 0.1 --to 0.5 --set lambda=0.3", "lambda"),
    (f"{CO} --from 0.1 --to 0.5 --settle -3", "--settle"),
    (f"{CO} --from 0.1", "--to"),
    ("continue reference-light --param omega --from 0.5 --to -0.5", "omega"),
    # map
    (f"{MP} --x lambda=0:1:3 --y lambda=0:1:3", "--y"),
    (f"{MP} --x lambda:0:1:3 --y f1=0.1:0.2:2", "--x"),
    (f"{MP} --x lambda=0:1:1 --y f1=0.1:0.2:2", "--x"),
    (f"{MP} --x lambda=0.5:0.5:3 --y f1=0.1:0.2:2", "--x"),
    (f"{MP} --x lamda=0:1:3 --y f1=0.1:0.2:2", "lambda"),
    (f"{MP} --x lambda=0:1:3 --y=damping_ratio=-0.1:0.1:3", "damping_ratio"),
    (f"{MP} --x lambda=0:1:3 --y omega=0:1:3", "omega"),
    (f"{MP} {MAPXY} --initial-states 0", "--initial-states"),
    (f"{MP} {MAPXY} --box u=1:0", "--box"),
    (f"{MP} {MAPXY} --box w=0:1", "--box"),
    (f"{MP} {MAPXY} --workers 0", "--workers"),
    (f"{MP} {MAPXY} --method RK45", "--method"),
    (f"{MP} {MAPXY} --set lambda=0.2", "lambda"),
    (f"{MP} {MAPXY} --executor serial --scheduler tcp://x:1", "--scheduler"),
    (f"{MP} {MAPXY} --periods 0", "--periods"),
    (f"{MP} {MAPXY} --lyapunov-periods 500", "--lyapunov-periods"),
    (f"{MP} --x lambda=0:1:3000 --y f1=0.1:0.2:3000 --initial-states 100", "memory"),
    (f"{MP} --x load_reading=0:1:2 --y f1=0.1:0.2:2", "load_reading"),
    (f"{MP} --y f1=0.1:0.2:2", "--x"),
    # frequency-response
    (f"{FR} --param omega=0:1:3", "omega"),
    (f"{FR} --param omega=0.4:0.5:3 --harmonics 0", "--harmonics"),
    (f"{FR} --param omega=0.4:0.5:3 --harmonics -1", "--harmonics"),
    (f"{FR} --param omega=0.4:0.5:3 --harmonics 100000", "memory"),
    (f"{FR} --param omega=0.4:0.5:3 --tail 0", "--tail"),
    (f"{FR} --param omega=0.4:0.5:3 --tail 2", "--tail"),
    (f"{FR} --param omega=0.4:0.5:3 --tail nan", "--tail"),
    (f"{FR} --param omega=0.4:0.5:3 --period 0", "--period"),
    (f"{FR} --param omega=0.4:0.5:3 --settle -1", "--settle"),
    (f"{FR} --param omega=0.4:0.5:3 --sampled -1", "--sampled"),
    (f"{FR} --param lambda=0:1:3 --method integration", "integration"),
    (f"{FR} --param omega=0.4:0.5:3 --set omega=0.5", "omega"),
    (f"{FR} --param omga=0.4:0.5:3", "omega"),
    (f"{FR} --param omega=0.4:0.5", "--param"),
    (f"{FR} --param omega=0.4:0.5:3 --method fourier", "--method"),
    (f"{FR} --param damping_ratio=-1:0.1:3", "damping_ratio"),
    # backlash
    ("backlash --order 99", "--order"),
    ("backlash --order 2", "--order"),
    ("backlash --order -1", "--order"),
    ("backlash --range 0", "--range"),
    ("backlash --range -3", "--range"),
    ("backlash --range nan", "--range"),
    ("backlash --step 0", "--step"),
    ("backlash --step -0.01", "--step"),
    ("backlash --step 1e-9", "--step"),
    ("backlash --step 0.01 --continuous", "--continuous"),
    ("backlash --step 10", "--step"),
    # stiffness
    ("stiffness diso --slices 0", "--slices"),
    ("stiffness diso --slices 100000000", "--slices"),
    ("stiffness diso --harmonics -1", "--harmonics"),
    ("stiffness diso --harmonics 65", "--harmonics"),
    ("stiffness diso --mesh pq", "pq"),
    ("stiffness disso", "disso"),
    ("stiffness", "PAIR_OR_SCENE"),
    # derive
    ("derive reference-lite", "reference-light"),
    ("derive reference-light --set lambda=abc", "not a number"),
    ("derive reference-light --set te_amplitude_um=-1", "te_amplitude_um"),
    ("derive {tmp}/none.toml", "none.toml"),
    ("derive --check --dry-run", "--dry-run"),
    # reproduce and bench
    ("reproduce --quick --serial --unknown", "--unknown"),
    ("bench --docs --out {tmp}", "--docs"),
    ("bench --quik", "--quick"),
]

# -- issue 23: hostile and careless inputs (each block is one class of docs/robustness.md) --

# files of the wrong shape: wrong TOML types at any key, arrays for tables, deep nesting
CASES += []

# the derivation cache: a corrupted module or digest is derived again (tests/test_cache_trust.py)
CASES += []

# continuation parameters and their valid ranges
CASES += []

# bounded work: every size that sets the cost
CASES += []

# strict JSON and Unix manners (tests/test_unix_manners.py)
CASES += []


def make_files(folder, root) -> dict:
    """The files the placeholders name, made in ``folder``; returns placeholder -> path."""
    from pathlib import Path

    folder = Path(folder)
    (folder / "w").mkdir(exist_ok=True)
    (folder / "afile.txt").write_text("x", encoding="utf-8")
    (folder / "bad.toml").write_bytes(b'[scene]\nname = "\xff\xfe"\n')
    (folder / "empty.toml").write_text("", encoding="utf-8")
    (folder / "brace.json").write_text("{}", encoding="utf-8")
    (folder / "torn.json").write_text('{"model": "ref', encoding="utf-8")
    files = {
        "tmp": str(folder / "w"),
        "file": str(folder / "afile.txt"),
        "bad_utf8": str(folder / "bad.toml"),
        "empty": str(folder / "empty.toml"),
        "brace": str(folder / "brace.json"),
        "torn": str(folder / "torn.json"),
    }
    scene = (Path(root) / "scenes" / "reference-light.toml").read_text(encoding="utf-8")
    scene = scene.replace('topology = "topologies/diso.toml"', 'topology = "diso"')
    for key, (old, new) in SCENE_EDITS.items():
        assert old in scene, old
        path = folder / f"scene-{key}.toml"
        path.write_text(scene.replace(old, new), encoding="utf-8")
        files[f"scene:{key}"] = str(path)
    return files


def materialise(argv: str, files: dict) -> list[str]:
    """``argv`` with its placeholders replaced, split like a shell would."""
    import shlex

    for key, path in files.items():
        argv = argv.replace("{" + key + "}", path)
    return shlex.split(argv)
