"""The scene resolver: from what a user names (a built-in scene or topology, with hyphens
or underscores, or a path to a TOML file) to a :class:`~gearsym.solver.System`.

A shipped target whose generated module is current is imported from ``generated/``; any
other target (a user's scene, or a shipped one edited since it was generated) is derived
once into the derivation cache, ``<cache root>/models`` (``gearsym.solver.cache``: the
same root as the compiled libraries), keyed by the hash of its inputs, and loaded from
there.  Nothing is ever written into the installed package.
"""

from __future__ import annotations

import importlib
from pathlib import Path
from types import ModuleType

from gearsym.derive import derive_model, load_target, resolve_target
from gearsym.derive.emit import emit_module, write_atomic
from gearsym.derive.model import inputs_hash
from gearsym.solver.cache import cache_root
from gearsym.solver.contract import CONTRACT_FORMAT, load_generated
from gearsym.solver.system import System

__all__ = ["cached_module", "load", "model_cache", "module_for"]


def model_cache() -> Path:
    """Where models derived from scene files are kept."""
    return cache_root() / "models"


def cached_module(name: str, digest: str) -> Path:
    """The derivation cache's file for model ``name`` with inputs hash ``digest`` (its
    audit page goes beside it with the suffix ``.md``)."""
    return model_cache() / f"{name.replace('-', '_')}_{digest[:12]}_c{CONTRACT_FORMAT}.py"


def module_for(target: str | Path) -> ModuleType:
    """The generated module of a scene or topology (built-in name or path), derived into
    the cache first when ``generated/`` has no current one."""
    path = resolve_target(str(target))
    scene = load_target(path)
    name = scene.name.replace("-", "_")
    digest = inputs_hash(scene)
    try:
        module = importlib.import_module(f"gearsym.generated.{name}")
    except ModuleNotFoundError:
        module = None
    if module is not None and getattr(module, "INPUTS_SHA256", "") == digest:
        return module
    cached = cached_module(name, digest)
    if not cached.exists():
        model = derive_model(scene)
        write_atomic(cached, emit_module(model, f"gearsym derive {path}"))
    return load_generated(cached)


def load(target: str | Path | ModuleType, **values) -> System:
    """The System of a scene, topology or generated module, with ``values`` (scene or
    model parameters by name) set.

    ``target``: a built-in name (``"reference-light"`` or ``"reference_light"``), a path to
    a scene or topology TOML file, a generated ``.py`` file, or a module.
    """
    if isinstance(target, ModuleType):
        return System.load(target, **values)
    if Path(str(target)).suffix == ".py":
        return System.load(Path(target), **values)
    return System.load(module_for(target), **values)
