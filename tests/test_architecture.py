"""The rooms of DESIGN.md hold: data moves down, nothing below reaches back up.

Read from the source with ``ast`` (nothing is imported):

* ``solver/`` never imports the derivation or the application layer, ``derive/`` never
  imports the solver, no package has an import circle (lazy imports inside functions
  count);
* inside ``solver/`` the rooms import down one order (:data:`SOLVER_ORDER`): the ground
  (contract, cache, executor, export), ``system``, ``integrate``, ``periodic``,
  ``analysis``, ``sweep``, the plots;
* each engine exists once (issue 24): :data:`ENGINES` names the one module that defines
  it, and no other module of ``solver/`` defines a function or class of that name;
* the C interface is declared once: one ``ctypes.Structure`` and every ``argtypes`` in
  ``solver/integrate/native/abi.py``, and the C exports one integrator entry;
* no module of ``derive/``, ``solver/`` or ``app/`` is longer than a reader takes in at
  one sitting (400 lines), and the formatter is switched off at most 20 times in the tree.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest
from gearsym.derive.build import project_root

from .importgraph import find_cycle, import_graph

ROOT = project_root()
PACKAGES = {
    "derive": "gearsym.derive",
    "solver": "gearsym.solver",
    "app": "gearsym",
}
# What each room may import of gearsym (absolute imports; relative ones stay inside).
ALLOWED = {
    "derive": ("gearsym.derive", "gearsym.scenes"),
    "solver": ("gearsym.solver",),
    "app": ("gearsym",),
}


def _absolute_gearsym_imports(path: Path) -> set[str]:
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and not node.level:
            names = [f"{node.module}.{a.name}" for a in node.names]
        else:
            continue
        out |= {n for n in names if n == "gearsym" or n.startswith("gearsym.")}
    return out


@pytest.mark.parametrize("folder", sorted(PACKAGES))
def test_each_room_imports_only_what_lies_above_it(folder):
    allowed = ALLOWED[folder]
    bad = {}
    for path in sorted((ROOT / folder).rglob("*.py")):
        wrong = {
            n
            for n in _absolute_gearsym_imports(path)
            if not any(n == a or n.startswith(a + ".") for a in allowed)
        }
        if wrong:
            bad[str(path.relative_to(ROOT))] = sorted(wrong)
    assert not bad, f"{folder}/ reaches into another room: {bad}"


@pytest.mark.parametrize("folder", sorted(PACKAGES))
def test_no_import_circles(folder):
    others = tuple(p for p in PACKAGES.values() if p != PACKAGES[folder])
    # Sub-packages installed from other folders are other rooms, not modules of this one.
    elsewhere = tuple(
        o
        for o in (*others, "gearsym.generated", "gearsym.scenes", "gearsym.benchmarks")
        if o.startswith(PACKAGES[folder] + ".")
    )
    graph = import_graph(ROOT / folder, PACKAGES[folder], ignore=elsewhere)
    assert sum(map(len, graph.values())) > 10  # the graph was read, not empty
    cycle = find_cycle(graph)
    assert cycle is None, f"import circle in {folder}/: " + " -> ".join(cycle)


@pytest.mark.parametrize("folder", ["derive", "solver", "app"])
def test_modules_are_short_enough_to_read_in_one_sitting(folder):
    # Python modules, and the C engine's parts (solver/integrate/native/native_*.c)
    files = [*(ROOT / folder).rglob("*.py"), *(ROOT / folder).rglob("*.c")]
    long = {
        str(p.relative_to(ROOT)): n
        for p in files
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > 400
    }
    assert not long, long


def test_the_formatter_is_switched_off_at_most_twenty_times():
    where = {}
    for folder in ("derive", "solver", "app", "tests", "benchmarks", "scenes"):
        for p in (ROOT / folder).rglob("*.py"):
            n = p.read_text(encoding="utf-8").count("# fmt: " + "skip")
            n += p.read_text(encoding="utf-8").count("# fmt: " + "off")
            if n:
                where[str(p.relative_to(ROOT))] = n
    assert sum(where.values()) <= 20, where


# Inside solver/: a room may import its own modules and the rooms of its order or lower.
SOLVER_ORDER = {
    "__init__": 9,
    "_json": 0,
    "_matfile": 0,
    "_memory": 0,
    "_warnings": 0,
    "cache": 0,
    "contract": 0,
    "executor": 0,
    "export": 0,
    "provenance": 0,
    "system": 1,
    "units": 1,
    "units_table": 1,
    "integrate": 2,
    "periodic": 3,
    "analysis": 4,
    "sweep": 5,
    "plots": 6,
    "plots_maps": 6,
    "plots_style": 6,
    "plots_modes": 6,
    "plots_point": 6,
    "plots_response": 6,
}


def test_solver_rooms_import_down_one_order():
    graph = import_graph(ROOT / "solver", "gearsym.solver")
    room = {m: (m.split(".") + ["__init__"])[2] for m in graph}
    unknown = sorted({r for r in room.values()} - set(SOLVER_ORDER))
    assert not unknown, f"rooms of solver/ without a place in SOLVER_ORDER: {unknown}"
    up = sorted(
        f"{a} -> {b}"
        for a, targets in graph.items()
        for b in targets
        if room[a] != room[b] and SOLVER_ORDER[room[b]] > SOLVER_ORDER[room[a]]
    )
    assert not up, "imports that run up the order of solver/: " + "; ".join(up)


# Engine -> (the one module that defines it, the names only that module may define).
ENGINES = {
    "the run's options and result": ("integrate/spec.py", {"RunSpec", "RunResult"}),
    "the front door to the integrators": ("integrate/run.py", {"integrate", "Batch"}),
    "the compiled engine's call": ("integrate/native/engine.py", {"run_compiled"}),
    "the fallback without a compiler": (
        "integrate/native/fallback.py",
        {"run_fallback", "numpy_map", "_numpy_batch", "_scipy"},
    ),
    "Newton's method": ("periodic/newton.py", {"newton", "_at"}),
    "pseudo-arclength continuation": (
        "periodic/engine.py",
        {"tangent", "_tangent", "correct", "_correct", "_locate", "continue_branch"},
    ),
    "bifurcation records": ("periodic/records.py", {"Bifurcation", "Branch", "HBBranch"}),
    "bifurcation test functions": ("periodic/floquet.py", {"bifurcation_tests"}),
    "the record of a classified run": (
        "analysis/record.py",
        {"RunRecord", "RunOutcome", "SweepPointRecord"},
    ),
    "the store of sweeps and maps": ("sweep/store.py", {"RunStore", "MapStore", "SweepStore"}),
    "the process pool": ("executor.py", {"map_tasks"}),
    "the event loop at switching surfaces": (
        "integrate/events.py",
        {"integrate_located", "LocatedRun"},
    ),
    "the explicit Runge-Kutta step": ("integrate/tableau.py", {"rk_step", "ButcherTableau"}),
    "the verdict of a run": ("analysis/settle.py", {"settle", "Settled"}),
    "the labels and their evidence": ("analysis/verdict.py", {"Verdict", "judge"}),
    "the shooting check": ("analysis/orbit_check.py", {"check_orbit", "OrbitCheck"}),
}


def _definitions() -> dict[str, set[str]]:
    out: dict[str, set[str]] = {}
    for path in (ROOT / "solver").rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        rel = str(path.relative_to(ROOT / "solver"))
        out[rel] = {
            node.name
            for node in ast.walk(tree)
            if isinstance(node, ast.FunctionDef | ast.ClassDef | ast.AsyncFunctionDef)
        }
    return out


@pytest.mark.parametrize("engine", sorted(ENGINES))
def test_each_engine_exists_once(engine):
    home, names = ENGINES[engine]
    defs = _definitions()
    assert defs.get(home, set()) & names, f"{engine}: {home} defines none of {sorted(names)}"
    elsewhere = {m: sorted(d & names) for m, d in defs.items() if m != home and d & names}
    assert not elsewhere, f"{engine} lives in {home}, but is also defined in {elsewhere}"


def test_the_c_interface_is_declared_once():
    native = ROOT / "solver" / "integrate" / "native"
    structures, bindings = set(), set()
    for path in (ROOT / "solver").rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        rel = str(path.relative_to(ROOT))
        if "ctypes.Structure" in text:
            structures.add(rel)
        if ".argtypes" in text:
            bindings.add(rel)
    assert structures == bindings == {"solver/integrate/native/abi.py"}, (structures, bindings)
    c = "".join(p.read_text(encoding="utf-8") for p in sorted(native.glob("native_*.c")))
    exported = set(re.findall(r"^(?!static)[A-Za-z][\w \*]*?\b(gs_\w+)\s*\(", c, re.M))
    entries = {e for e in exported if e not in {"gs_job_fields", "gs_job_layout"}}
    integrators = entries - {"gs_eval", "gs_eval_batch", "gs_rhs_loop"}
    assert integrators == {"gs_integrate"}, f"the C exports more than one integrator: {entries}"
    benettin = re.findall(r"^static[^;{]*\bgs_benettin\w*\s*\(", c, re.M)
    assert len(benettin) == 1, f"Benettin's renormalisation is defined {len(benettin)} times"
