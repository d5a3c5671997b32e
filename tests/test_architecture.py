"""The rooms of DESIGN.md hold: data moves down, nothing below reaches back up.

Read from the source with ``ast`` (nothing is imported): ``solver/`` never imports the
derivation or the application layer, ``derive/`` never imports the solver, no package
has an import circle (lazy imports inside functions count), and no module of ``solver/``
is longer than a reader takes in at one sitting (400 lines, issue 11).
"""

from __future__ import annotations

import ast
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


def test_solver_modules_are_short_enough_to_read_in_one_sitting():
    long = {
        str(p.relative_to(ROOT)): n
        for p in (ROOT / "solver").rglob("*.py")
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > 400
    }
    assert not long, long
