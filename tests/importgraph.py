"""The import graph of a package folder, read from its source with ``ast``: what each
module imports (lazy imports inside functions included), and its circles."""

from __future__ import annotations

import ast
from pathlib import Path

__all__ = ["find_cycle", "import_graph"]


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


def import_graph(
    folder: Path | str, package: str, ignore: tuple[str, ...] = ()
) -> dict[str, set[str]]:
    """Module -> the modules of the same package that it imports, anywhere in its body.

    ``folder`` is the package's directory and ``package`` its dotted import name.  Relative
    imports are resolved against the importing module; absolute imports count when they
    name ``package`` or something inside it.  ``from . import x`` points at module ``x``
    when there is one, else at the package's ``__init__`` (which is then a real edge:
    ``__init__`` imports the submodules).  The implicit import of parent packages that
    every submodule import performs is not an edge, or every package would be a circle.
    Targets under a prefix in ``ignore`` are not edges (sub-packages installed from other
    folders, such as ``gearsym.solver`` seen from the ``gearsym`` package itself).
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
                if any(target == p or target.startswith(p + ".") for p in ignore):
                    continue
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
