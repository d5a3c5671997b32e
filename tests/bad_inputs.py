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
    ),
    "dofs": ("mesh_phase = true", 'mesh_phase = true\ndegrees_of_freedom = "lateral"'),
    "tilting": (
        "mesh_phase = true",
        'mesh_phase = true\ndegrees_of_freedom = "lateral-torsional-axial-tilting"',
    ),
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
DEEP = 40  # levels of nesting, past derive._input.MAX_DEPTH
NESTED_ARRAY = "x = " + "[" * DEEP + "]" * DEEP
NESTED = "x = " + "{a = " * 999 + "1" + "}" * 999  # past tomllib's own recursion
SCENE_EDITS.update(
    {
        "topology_number": ('topology = "diso"', "topology = 5"),
        "topology_list": ('topology = "diso"', 'topology = ["diso"]'),
        "topology_table": ('topology = "diso"', 'topology = { file = "diso" }'),
        "name_number": ('name = "reference-light"', "name = 5"),
        "scene_array": ("[scene]", "[[scene]]"),
        "features_array": ("[features]", "[[features]]"),
        "parameters_array": ("[parameters]", "[[parameters]]"),
        "loads_array": ("[loads]", "[[loads]]"),
        "open_array": ("[open]", "[[open]]"),
        "harmonics_text": ("stiffness_harmonics = 3 ", 'stiffness_harmonics = "3" '),
        "mesh_phase_text": ("mesh_phase = true", 'mesh_phase = "yes"'),
        "omega_table": ("omega = 0.5 ", "omega = { value = 0.5 } "),
        "load_list": ('u = "f1"', 'u = ["f1"]'),
        "reading_number": ('load_reading = "q-braking"', "load_reading = 1"),
        "open_text": ("[open]", '[open]\nte_amplitude_um = "5"'),
        "deep_array": ("mesh_phase = true", "mesh_phase = true\n" + NESTED_ARRAY),
        "deep_table": ("mesh_phase = true", "mesh_phase = true\n" + NESTED),
    }
)
# One replaced line of scenes/topologies/diso.toml (every occurrence), used by a copy of
# the light-load scene: the placeholder {topo:KEY}.
TOPOLOGY_EDITS = {
    "topology_array": ("[topology]", "[[topology]]"),
    "extends_number": ('name = "diso"', 'name = "diso"\nextends = 5'),
    "materials_array": ("[materials.steel]", "[[materials.steel]]"),
    "gear_table": ("[[gear]]", "[[gear.entry]]"),
    "gear_id_number": ('id = "p"\n', "id = 1\n"),
    "teeth_text": ("teeth = 100", 'teeth = "100"'),
    "flywheel_text": ("attached_inertia_kg_m2 = 10.0", 'attached_inertia_kg_m2 = "10"'),
    "driver_list": ('driver = "p"', 'driver = ["p"]'),
    "stiffness_text": (
        'stiffness = { source = "potential-energy", slices = 200, harmonics = 10 }',
        'stiffness = "potential-energy"',
    ),
    "te_number": ("amplitude_um = [5.0]", "amplitude_um = 5.0"),
    "reading_text": ('driving = ["p"]\n', 'driving = "p"\n'),
    "torque_table": ("[[torque]]", "[[torque.entry]]"),
    "operating_array": ("[operating]", "[[operating]]"),
    "deep": ("[operating]", NESTED_ARRAY + "\n[operating]"),
}
CASES += [
    ("simulate {scene:topology_number}", "scene.topology: must be text"),
    ("simulate {scene:topology_list}", "scene.topology: must be text"),
    ("derive {scene:topology_table}", "scene.topology: must be text"),
    ("simulate {scene:name_number}", "scene.name: must be text"),
    ("simulate {scene:scene_array}", "write [scene] once"),
    ("derive {scene:scene_array}", "scene: must be a table"),
    ("stiffness {scene:scene_array}", "scene: must be a table"),
    ("simulate {scene:features_array}", "features: must be a table"),
    ("simulate {scene:parameters_array}", "parameters: must be a table"),
    ("simulate {scene:loads_array}", "loads: must be a table"),
    ("simulate {scene:open_array}", "open: must be a table"),
    ("simulate {scene:harmonics_text}", "features.stiffness_harmonics"),
    ("simulate {scene:mesh_phase_text}", "features.mesh_phase"),
    ("simulate {scene:omega_table}", "parameters.omega"),
    ("simulate {scene:load_list}", "loads.u"),
    ("simulate {scene:reading_number}", "open.load_reading: must be text"),
    ("simulate {scene:open_text}", "open.te_amplitude_um"),
    ("simulate {scene:deep_array}", "deeper than 32 levels"),
    ("derive {scene:deep_table}", "deeper than 32 levels"),
    ("simulate {topo:topology_array}", "write [topology] once"),
    ("simulate {topo:extends_number}", "topology.extends"),
    ("simulate {topo:materials_array}", "materials.steel: must be a table"),
    ("simulate {topo:gear_table}", "gear: must be an array of tables"),
    ("derive {topo:gear_table}", "gear: must be an array of tables"),
    ("simulate {topo:gear_id_number}", "gear[0].id: must be text"),
    ("simulate {topo:teeth_text}", "gear[2].teeth"),
    ("simulate {topo:flywheel_text}", "gear[2].attached_inertia_kg_m2"),
    ("simulate {topo:driver_list}", "mesh[0].driver: must be text"),
    ("simulate {topo:stiffness_text}", "mesh[0].stiffness: must be a table"),
    ("stiffness {topo:stiffness_text}", "mesh[0].stiffness: must be a table"),
    ("simulate {topo:te_number}", "mesh[0].transmission_error.amplitude_um"),
    ("simulate {topo:reading_text}", "reading[0].driving"),
    ("simulate {topo:torque_table}", "torque: must be an array of tables"),
    ("simulate {topo:operating_array}", "operating: must be a table"),
    ("simulate {topo:deep}", "deeper than 32 levels"),
]

# the derivation cache: a corrupted module or digest is derived again (tests/test_cache_trust.py)
CASES += []

# continuation parameters and their valid ranges
CASES += [
    (f"{FR} --param load_reading=0:1:3", "open value"),
    ("frequency-response diso-bearings-light --param flywheel_inertia_kg_m2=0:1:3", "open value"),
    ("continue diso-bearings-light --param flywheel_inertia_kg_m2 --from 2 --to 10", "open value"),
    (f"{FR} --param nosuch=0:1:3", "nosuch"),
    (f"{FR} --param damping_ratio=0.03:1.5:3", "damping_ratio"),
    (f"{FR} --param omega=0.5:-0.1:3", "omega"),
    ("continue reference-light --param damping_ratio --from 0.03 --to 2", "damping_ratio"),
    ("continue reference-light --param nosuch --from 0.1 --to 0.2", "nosuch"),
]

# bounded work: every size that sets the cost
CASES += [
    (f"{SH} --period 100000", "--period"),
    (f"{SH} --period 65", "--period"),
    (f"{SH} --segments 257", "--segments"),
    (f"{SH} --period 2 --tries 101", "--tries"),
    (f"{SH} --settle 300000", "--settle"),
    (f"{SH} --period 64 --tries 100", "--tries"),
    (f"{CO} --from 0.1 --to 0.5 --step 1e300", "--step"),
    (f"{CO} --from 0.1 --to 0.5 --step 0.5", "--step"),
    (f"{CO} --from 0.1 --to 0.5 --step 1e-7", "--step"),
    (f"{CO} --from 0.1 --to 0.5 --period 65", "--period"),
    (f"{CO} --from 0.1 --to 0.5 --settle 300000", "--settle"),
    (f"{FR} --param omega=0.4:0.5:20001", "NUM"),
    (f"{FR} --param omega=0.4:0.5:2001 --method shooting", "NUM"),
    (f"{FR} --param omega=0.4:0.5:3 --harmonics 300", "--harmonics"),
    (f"{FR} --param omega=0.4:0.5:3 --period 65", "--period"),
    (f"{FR} --param omega=0.4:0.5:3 --method integration --settle 10001", "--settle"),
    (f"{FR} --param omega=0.4:0.5:3 --method integration --sampled 10001", "--sampled"),
    (f"{FR} --param omega=0.4:0.5:2000 --method integration --settle 10000", "--settle"),
    (f"{S} --transient 1000001", "--transient"),
    (f"{S} --periods 1000001", "--periods"),
    (f"{S} --lyapunov-periods 100001", "--lyapunov-periods"),
    (f"{SW} --range 0:1:100001", "--range"),
    (f"{SW} --range 0:1:10000 --transient 200000", "--range"),
    (f"{MP} {MAPXY} --initial-states 65", "--initial-states"),
    (f"{MP} {MAPXY} --workers 1025", "--workers"),
    (f"{MP} {MAPXY} --transient 1000001", "--transient"),
    (f"{MP} --x lambda=0:1:100 --y f1=0.1:0.2:100 --transient 100000 --periods 1", "hours"),
]

# strict JSON and Unix manners (tests/test_unix_manners.py): values so far outside any
# gear train that the numbers would overflow are refused before they reach JSON
TOPOLOGY_EDITS.update(
    {
        "young_absurd": ("youngs_modulus_Pa = 2.06e11", "youngs_modulus_Pa = 1e200"),
        "density_absurd": ("density_kg_m3 = 7850", "density_kg_m3 = 1e-3"),
        "inertia_tiny": ('id = "p"\n', 'id = "p"\ninertia_kg_m2 = 1e-320\n'),
        "flywheel_huge": ("attached_inertia_kg_m2 = 10.0", "attached_inertia_kg_m2 = 1e300"),
        "stiffness_vanishing": (
            '{ source = "potential-energy", slices = 200, harmonics = 10 }',
            '{ source = "harmonics", mean_N_per_m = 1e-320 }',
        ),
        "speed_tiny": ("speed_rpm = 1500", "speed_rpm = 1.8e-252"),
        "speed_huge": ("speed_rpm = 1500", "speed_rpm = 1e9"),
    }
)
CASES += [
    ("stiffness {topo:young_absurd} --json", "youngs_modulus_Pa: must be <= 1e+13"),
    ("modes {topo:density_absurd} --json", "density_kg_m3: must be >= 10"),
    ("modes {topo:inertia_tiny} --json", "inertia_kg_m2: must be >= 1e-15"),
    ("modes {topo:flywheel_huge} --json", "attached_inertia_kg_m2: must be <= 1e+09"),
    ("simulate {topo:stiffness_vanishing}", "mean_N_per_m: must be >= 1000"),
    # a topology runs at its own speed: omega within [1e-3, 1e3] (bounded work)
    ("simulate {topofile:speed_tiny}", "operating.speed_rpm"),
    ("modes {topofile:speed_huge}", "operating.speed_rpm: must be <= 1e+06"),
    ("simulate reference-light --set omega=1e-4", "omega must be in [0.001, 1000]"),
    ("backlash --step 1.5", "use a step of at most 0.75"),
]


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
    topology = (Path(root) / "scenes" / "topologies" / "diso.toml").read_text(encoding="utf-8")
    for key, (old, new) in TOPOLOGY_EDITS.items():
        assert old in topology, old
        (folder / f"topo-{key}.toml").write_text(topology.replace(old, new), encoding="utf-8")
        path = folder / f"scene-topo-{key}.toml"
        path.write_text(scene.replace('"diso"', f'"topo-{key}.toml"'), encoding="utf-8")
        files[f"topo:{key}"] = str(path)
        files[f"topofile:{key}"] = str(folder / f"topo-{key}.toml")
    return files


def materialise(argv: str, files: dict) -> list[str]:
    """``argv`` with its placeholders replaced, split like a shell would."""
    import shlex

    for key, path in files.items():
        argv = argv.replace("{" + key + "}", path)
    return shlex.split(argv)
