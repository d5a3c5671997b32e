"""Imports inside derive/ flow one way: the intra-package import graph has no cycle.

The graph is read from the source with ``ast`` (nothing is imported), and it counts every
import statement, including the lazy ones inside functions: a lazy import hides a circle
from Python's import machinery, not from the design (DESIGN.md: data moves down, nothing
below reaches back up).  :func:`import_graph` takes any package folder, so the same check
can be pointed at another package, e.g. ``import_graph(root / "solver", "gearsym.solver")``.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from gearsym.derive.build import project_root


def _module_names(folder: Path, package: str) -> dict[Path, str]:
    """Every ``.py`` file under ``folder`` -> its dotted module name (``__init__`` -> the
    package itself)."""
    names = {}
    for path in sorted(folder.rglob("*.py")):
        parts = list(path.relative_to(folder).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        names[path] = ".".join([package, *parts])
    return names


def import_graph(folder: Path | str, package: str) -> dict[str, set[str]]:
    """Module -> the modules of the same package that it imports, anywhere in its body.

    ``folder`` is the package's directory and ``package`` its dotted import name.  Relative
    imports are resolved against the importing module; absolute imports count when they
    name ``package`` or something inside it.  ``from . import x`` points at module ``x``
    when there is one, else at the package's ``__init__`` (which is then a real edge:
    ``__init__`` imports the submodules).  The implicit import of parent packages that
    every submodule import performs is not an edge, or every package would be a circle.
    """
    folder = Path(folder)
    names = _module_names(folder, package)
    known = set(names.values())

    def resolve(target: str) -> str | None:
        # "pkg.mod.attr" -> "pkg.mod": strip attributes until a module is left.
        while target and target not in known:
            if "." not in target:
                return None
            target = target.rsplit(".", 1)[0]
        return target or None

    graph: dict[str, set[str]] = {}
    for path, name in names.items():
        is_package = path.name == "__init__.py"
        edges: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = name if is_package else name.rsplit(".", 1)[0]
                    for _ in range(node.level - 1):
                        base = base.rsplit(".", 1)[0]
                    base = f"{base}.{node.module}" if node.module else base
                else:
                    base = node.module or ""
                # "from base import x": module base.x if it exists, else base itself.
                targets = [
                    f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names
                ]
            else:
                continue
            for target in targets:
                if target == package or target.startswith(package + "."):
                    resolved = resolve(target)
                    if resolved is not None and resolved != name:
                        edges.add(resolved)
        graph[name] = edges
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import circle as ``[a, b, ..., a]``, or None when the graph is acyclic."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return path[path.index(nxt) :] + [nxt]
            if nxt not in state and (found := visit(nxt)) is not None:
                return found
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (found := visit(node)) is not None:
            return found
    return None


def test_derive_imports_flow_one_way():
    graph = import_graph(project_root() / "derive", "gearsym.derive")
    assert "gearsym.derive.model" in graph and "gearsym.derive.emit" in graph
    cycle = find_cycle(graph)
    assert cycle is None, "import circle in derive/: " + " -> ".join(cycle)


def test_moved_helpers_stay_importable_from_their_old_places():
    # Callers outside derive/ (tests, the CLI, studies) import these from build and emit.
    from gearsym.derive import __version__
    from gearsym.derive.build import display_path, project_root
    from gearsym.derive.emit import operation_count
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
