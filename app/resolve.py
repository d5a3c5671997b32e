"""The scene resolver: from what a user names (a built-in scene or topology, with hyphens
or underscores, or a path to a TOML file) to a :class:`~gearsym.solver.System`.

A shipped target whose generated module is current is imported from ``generated/``; any
other target (a user's scene, or a shipped one edited since it was generated) is derived
once into the derivation cache, ``<cache root>/models`` (``gearsym.solver.cache``: the
same root as the compiled libraries), keyed by the hash of its inputs, and loaded from
there.  Nothing is ever written into the installed package.
"""

from __future__ import annotations

import hashlib
import importlib
import json
import os
import tomllib
from pathlib import Path
from types import ModuleType

from gearsym.solver.cache import cache_root
from gearsym.solver.contract import CONTRACT_FORMAT, load_generated
from gearsym.solver.system import System

__all__ = ["cached_module", "load", "model_cache", "module_for", "split_open_values"]


def model_cache() -> Path:
    """Where models derived from scene files are kept."""
    return cache_root() / "models"


def cached_module(name: str, digest: str) -> Path:
    """The derivation cache's file for model ``name`` with inputs hash ``digest`` (its
    audit page goes beside it with the suffix ``.md``)."""
    return model_cache() / f"{name.replace('-', '_')}_{digest[:12]}_c{CONTRACT_FORMAT}.py"


def module_for(target: str | Path, open_values: dict | None = None) -> ModuleType:
    """The generated module of a scene or topology (built-in name or path), derived into
    the cache first when ``generated/`` has no current one.  ``open_values`` (see
    ``gearsym.derive.open_values``) give a variant, derived once into the cache."""
    module = None if open_values else _known_current(target)
    if module is not None:
        return module
    from gearsym.derive import derive_model, load_target, resolve_target
    from gearsym.derive.emit import emit_module, write_atomic
    from gearsym.derive.model import inputs_hash
    from gearsym.derive.open_values import with_open_values

    path = resolve_target(str(target))
    scene = with_open_values(load_target(path), **(open_values or {}))
    name = scene.name.replace("-", "_")
    digest = inputs_hash(scene)
    if not open_values:
        _remember(path, digest)
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


# -- the fast path: a target whose files are unchanged since its digest was computed ----
# The derivation's inputs hash needs the scene parsed (SymPy, the stiffness model); a
# fingerprint of the bytes it depends on -- the target file, its topology file and the
# derive package's source -- maps to the digest computed last time, so that a command on
# an unchanged scene starts without loading the derivation at all.


def _fingerprint(target: str | Path) -> str | None:
    root = Path(__file__).resolve().parent.parent / "derive"
    builtin = (root.parent / "scenes") if (root.parent / "scenes").is_dir() else None
    path = Path(str(target))
    if not path.exists() and path.suffix != ".toml" and builtin is not None:
        for spelling in dict.fromkeys((str(target), str(target).replace("_", "-"))):
            for folder in (builtin, builtin / "topologies"):
                if (folder / f"{spelling}.toml").exists():
                    path = folder / f"{spelling}.toml"
                    break
            if path.exists():
                break
    try:
        data = path.read_bytes()
        parts = [str(path.resolve()).encode(), data]
        ref = tomllib.loads(data.decode("utf-8")).get("scene", {}).get("topology")
        if ref:
            topo = path.parent / ref
            if not topo.exists() and builtin is not None:
                topo = builtin / "topologies" / f"{ref}.toml"
            parts.append(topo.read_bytes())
        import gearsym.derive as derive_package

        source = Path(derive_package.__file__).parent
        parts += [f.read_bytes() for f in sorted(source.glob("*.py"))]
        parts += [f.read_bytes() for f in sorted((source / "data").glob("*")) if f.is_file()]
    except (OSError, ValueError, tomllib.TOMLDecodeError):
        return None
    return hashlib.sha256(b"\0".join(parts)).hexdigest()


def _digests() -> Path:
    return model_cache() / "digests.json"


def _known_current(target) -> ModuleType | None:
    """The shipped generated module of ``target`` when its fingerprint is known and its
    digest matches; else None (the slow path decides)."""
    key = _fingerprint(target)
    if key is None:
        return None
    try:
        known = json.loads(_digests().read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    entry = known.get(key)
    if not entry:
        return None
    try:
        module = importlib.import_module(f"gearsym.generated.{entry['name']}")
    except (ModuleNotFoundError, KeyError):
        return None
    return module if getattr(module, "INPUTS_SHA256", "") == entry.get("digest") else None


def _remember(path, digest: str) -> None:
    """Record the fingerprint of ``path``'s files and its digest (best effort: a cache
    folder that cannot be written only costs the fast path)."""
    key = _fingerprint(path)
    if key is None:
        return
    file = _digests()
    try:
        known = json.loads(file.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        known = {}
    name = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    name = (name.get("scene") or name.get("topology") or {}).get("name", "")
    known[key] = {"name": str(name).replace("-", "_"), "digest": digest}
    try:
        file.parent.mkdir(parents=True, exist_ok=True)
        tmp = file.with_name(f".{file.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(known), encoding="utf-8")
        os.replace(tmp, file)
    except OSError:
        pass


def load(target: str | Path | ModuleType, **values) -> System:
    """The System of a scene, topology or generated module, with ``values`` (scene or
    model parameters by name, or open values such as ``te_amplitude_um``, which derive a
    variant of the model once into the cache) set.

    ``target``: a built-in name (``"reference-light"`` or ``"reference_light"``), a path to
    a scene or topology TOML file, a generated ``.py`` file, or a module.
    """
    if isinstance(target, ModuleType):
        return System.load(target, **values)
    if Path(str(target)).suffix == ".py":
        return System.load(Path(target), **values)
    opened, rest = split_open_values(values)
    return System.load(module_for(target, opened), **rest)


def split_open_values(values: dict) -> tuple[dict, dict]:
    """(open values, the rest) of named values: the first need a derivation."""
    if not values:
        return {}, {}
    from gearsym.derive.open_values import is_open_value

    opened = {k: v for k, v in values.items() if is_open_value(k)}
    return opened, {k: v for k, v in values.items() if k not in opened}
