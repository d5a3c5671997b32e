"""Imports inside derive/ flow one way: the intra-package import graph has no cycle.

The graph is read from the source with ``ast`` (nothing is imported), and it counts every
import statement, including the lazy ones inside functions: a lazy import hides a circle
from Python's import machinery, not from the design (DESIGN.md: data moves down, nothing
below reaches back up).  :func:`import_graph` takes any package folder, so the same check
can be pointed at another package, e.g. ``import_graph(root / "solver", "gearsym.solver")``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from gearsym.derive.build import project_root

from ..importgraph import find_cycle, import_graph


def test_derive_imports_flow_one_way():
    graph = import_graph(project_root() / "derive", "gearsym.derive")
    assert "gearsym.derive.model" in graph and "gearsym.derive.emit.python" in graph
    cycle = find_cycle(graph)
    assert cycle is None, "import circle in derive/: " + " -> ".join(cycle)


def test_moved_helpers_stay_importable_from_their_old_places():
    # Callers outside derive/ (tests, the CLI, studies) import these from build and emit.
    from gearsym.derive import __version__
    from gearsym.derive.build import display_path, project_root
    from gearsym.derive.emit.python import operation_count
    from gearsym.derive.model import operation_count as counted

    assert operation_count is counted
    assert display_path(project_root() / "scenes" / "x.toml") == "scenes/x.toml"
    assert __version__


def _package(tmp_path: Path, files: dict[str, str]) -> Path:
    for rel, text in files.items():
        path = tmp_path / "pkg" / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return tmp_path / "pkg"


def test_checker_sees_a_circle_closed_by_a_lazy_import(tmp_path):
    # Reference: a constructed package with exactly the circle derive/ had
    # (audit -> build at module level, build -> audit inside a function).
    folder = _package(
        tmp_path,
        {
            "__init__.py": "from .build import run\n",
            "build.py": "from .audit import page\n\ndef run():\n    return page()\n",
            "audit.py": "def page():\n    from .build import run\n    return run\n",
            "sub/__init__.py": "",
            "sub/leaf.py": "from ..audit import page\nfrom pkg.build import run\n",
        },
    )
    graph = import_graph(folder, "pkg")
    assert graph["pkg.sub.leaf"] == {"pkg.audit", "pkg.build"}
    assert find_cycle(graph) in (
        ["pkg.audit", "pkg.build", "pkg.audit"],
        ["pkg.build", "pkg.audit", "pkg.build"],
    )


@pytest.mark.parametrize(
    "text, edge",
    [
        ("from . import __version__\n", "pkg"),  # a name of the package: its __init__
        ("from . import leaf\n", "pkg.leaf"),  # a submodule
        ("import pkg.leaf as l\n", "pkg.leaf"),
        ("from pkg.leaf import thing\n", "pkg.leaf"),
    ],
)
def test_checker_resolves_each_import_form(tmp_path, text, edge):
    folder = _package(tmp_path, {"__init__.py": "", "leaf.py": "", "mod.py": text})
    assert import_graph(folder, "pkg")["pkg.mod"] == {edge}
