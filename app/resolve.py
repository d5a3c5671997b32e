"""The scene resolver: from what a user names (a built-in scene or topology, with hyphens
or underscores, or a path to a TOML file) to a :class:`~gearsym.solver.System`.

A shipped target whose generated module is current is imported from ``generated/``; any
other target (a user's scene, or a shipped one edited since it was generated) is derived
once into the derivation cache, ``<cache root>/models`` (``gearsym.solver.cache``: the
same root as the compiled libraries), keyed by the hash of its inputs, and loaded from
there.  Nothing is ever written into the installed package.

The cache is verified, never trusted: a cached module is imported only when the sha256 of
its bytes equals the digest written beside it (``<module>.sha256``, written before the
module, each through a temporary file and a rename).  A module that is empty, cut short,
edited or not Python, a missing or wrong digest, and a ``digests.json`` of the wrong shape
are derived or written again, with one warning.  The check guards against corruption, not
against someone who can write the user's files (docs/user-guide.md, "Who can write the
cache").
"""

from __future__ import annotations

import hashlib
import importlib
import json
import os
import re
import warnings
from pathlib import Path
from types import ModuleType

from gearsym.solver.cache import cache_root
from gearsym.solver.contract import CONTRACT_FORMAT, load_generated
from gearsym.solver.system import System

__all__ = [
    "cached_module",
    "load",
    "load_cached",
    "model_cache",
    "module_for",
    "needs_derivation",
    "split_open_values",
    "store_cached",
]


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
    ``gearsym.derive.input.open_values``) give a variant, derived once into the cache."""
    module = None if open_values else _known_current(target)
    if module is not None:
        return module
    # a variant this process loaded already, while its files are unchanged (parsing the
    # scene for its inputs hash recomputes the mesh stiffness: 0.1 s a call, which a map
    # over open values pays per value and per task)
    seen = _fingerprint(target) if open_values else None
    if seen is not None:
        seen = (seen, str(model_cache()), json.dumps(open_values, sort_keys=True, default=str))
        module, stamp = _VARIANTS.get(seen, (None, None))
        if module is not None and _stamp(module) == stamp:
            return module
    module = _derived(target, open_values)
    if seen is not None:
        _VARIANTS[seen] = (module, _stamp(module))
    return module


# (fingerprint of the files, cache folder, open values) -> (module, the stamp of its file),
# in this process: a module file changed or removed since is looked up again
_VARIANTS: dict = {}


def _stamp(module: ModuleType) -> tuple | None:
    try:
        st = os.stat(module.__file__)
    except (OSError, TypeError):
        return None
    return st.st_mtime_ns, st.st_size


def _derived(target, open_values: dict | None) -> ModuleType:
    """:func:`module_for` without its fast paths: the scene parsed, its inputs hash, the
    shipped or cached module of that hash, else a derivation into the cache."""
    from gearsym.derive import derive_model, load_target, resolve_target
    from gearsym.derive.emit.python import emit_module
    from gearsym.derive.input.open_values import with_open_values
    from gearsym.derive.model import inputs_hash

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
    module = load_cached(cached)
    if module is None:
        model = derive_model(scene)
        store_cached(cached, emit_module(model, f"gearsym derive {path}"))
        module = load_generated(cached)
    return module


def _stated_digest(module: Path) -> Path:
    """The file beside a cached module that holds the sha256 of its bytes."""
    return module.with_suffix(".sha256")


def store_cached(module: Path, text: str) -> None:
    """Write ``text`` as the cached module ``module`` and the digest of its bytes beside
    it (the digest first: a module is never there without one)."""
    from gearsym.derive.emit.python import write_atomic

    data = text.encode("utf-8")  # what write_atomic writes: UTF-8, newlines kept
    write_atomic(_stated_digest(module), hashlib.sha256(data).hexdigest() + "\n")
    write_atomic(module, text)


def load_cached(module: Path) -> ModuleType | None:
    """The cached module at ``module`` when the sha256 of its bytes equals the digest
    beside it; None when there is none, or (with one warning) when it does not match."""
    try:
        data = module.read_bytes()
    except FileNotFoundError:
        return None
    except OSError as err:
        why = f"cannot be read ({err.strerror or err})"
    else:
        try:
            stated = _stated_digest(module).read_text(encoding="ascii").strip()
        except FileNotFoundError:
            stated, why = "", f"has no digest beside it ({_stated_digest(module).name})"
        except (OSError, ValueError):
            stated, why = "", "has an unreadable digest beside it"
        else:
            why = "differs from the digest beside it (empty, cut short or edited)"
        if stated and hashlib.sha256(data).hexdigest() == stated:
            return load_generated(module, source=data)  # the bytes verified, not a reread
    warnings.warn(f"the cached model {module} {why}; deriving it again", stacklevel=3)
    return None


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
    from gearsym.derive.input.reader import InputError, parse_toml

    try:
        data = path.read_bytes()
        parts = [str(path.resolve()).encode(), data]
        head = parse_toml(data.decode("utf-8"), str(path)).get("scene")
        ref = head.get("topology") if isinstance(head, dict) else None
        if isinstance(ref, str) and ref:
            topo = path.parent / ref
            if not topo.exists() and builtin is not None:
                topo = builtin / "topologies" / f"{ref}.toml"
            parts.append(topo.read_bytes())
        import gearsym.derive as derive_package

        source = Path(derive_package.__file__).parent
        parts += [f.read_bytes() for f in sorted(source.glob("*.py"))]
        parts += [f.read_bytes() for f in sorted((source / "data").glob("*")) if f.is_file()]
    except (OSError, ValueError, InputError):  # the slow path names what is wrong
        return None
    return hashlib.sha256(b"\0".join(parts)).hexdigest()


def _digests() -> Path:
    return model_cache() / "digests.json"


_SHA256 = re.compile(r"[0-9a-f]{64}")
_MODULE_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def _entry_ok(key, entry) -> bool:
    """Whether ``key: entry`` of digests.json is a fingerprint: {name, digest}."""
    return (
        isinstance(key, str)
        and _SHA256.fullmatch(key) is not None
        and isinstance(entry, dict)
        and set(entry) == {"name", "digest"}
        and isinstance(entry["name"], str)
        and _MODULE_NAME.fullmatch(entry["name"]) is not None
        and isinstance(entry["digest"], str)
        and _SHA256.fullmatch(entry["digest"]) is not None
    )


def _read_digests() -> tuple[dict, str | None]:
    """The well-formed entries of digests.json, and what else it held (None: nothing)."""
    from gearsym.derive.input.reader import shown

    try:
        known = json.loads(_digests().read_text(encoding="utf-8"))
    except FileNotFoundError:
        return {}, None
    except OSError as err:
        return {}, f"cannot be read ({err.strerror or err})"
    except (ValueError, RecursionError):  # not UTF-8, not JSON, nested without end
        return {}, "is not JSON (empty or cut short)"
    if not isinstance(known, dict):
        return {}, f"holds {shown(known)} instead of a table of fingerprints"
    good = {k: e for k, e in known.items() if _entry_ok(k, e)}
    if len(good) < len(known):
        return good, f"has {len(known) - len(good)} entries of the wrong shape"
    return good, None


def _known_current(target) -> ModuleType | None:
    """The shipped generated module of ``target`` when its fingerprint is known and its
    digest matches; else None (the slow path decides, and mends a bad digests.json)."""
    key = _fingerprint(target)
    if key is None:
        return None
    entry = _read_digests()[0].get(key)
    if entry is None:
        return None
    try:
        module = importlib.import_module(f"gearsym.generated.{entry['name']}")
    except ModuleNotFoundError:
        return None
    return module if getattr(module, "INPUTS_SHA256", "") == entry["digest"] else None


def _remember(path, digest: str) -> None:
    """Record the fingerprint of ``path``'s files and its digest (best effort: a cache
    folder that cannot be written only costs the fast path)."""
    from gearsym.derive.input.reader import InputError, load_toml

    key = _fingerprint(path)
    if key is None:
        return
    try:
        data = load_toml(Path(path))
    except InputError:
        return
    head = data.get("scene") or data.get("topology")
    name = str(head.get("name", "") if isinstance(head, dict) else "").replace("-", "_")
    if not (_MODULE_NAME.fullmatch(name) and _SHA256.fullmatch(digest)):
        return
    known, why = _read_digests()
    file = _digests()
    if why is not None:
        warnings.warn(f"the cache's fingerprint file {file} {why}; writing it anew", stacklevel=3)
    known[key] = {"name": name, "digest": digest}
    try:
        file.parent.mkdir(parents=True, exist_ok=True)
        tmp = file.with_name(f".{file.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(known), encoding="utf-8")
        os.replace(tmp, file)
    except OSError:
        pass


def load(target: str | Path | ModuleType, **values) -> System:
    """The System of a scene, topology or generated module, with ``values`` set: scene or
    model parameters by name, physical quantities (the module's ``PHYSICAL``: speed_rpm,
    torque_Nm_<gear>, half_backlash_um_<mesh>, ...; no new derivation), or other open
    values (``load_reading``, or any quantity a model does not carry as a parameter), which
    derive a variant of the model once into the cache.

    ``target``: a built-in name (``"reference-light"`` or ``"reference_light"``), a path to
    a scene or topology TOML file, a generated ``.py`` file, or a module.
    """
    if isinstance(target, ModuleType):
        return System.load(target, **values)
    if Path(str(target)).suffix == ".py":
        return System.load(Path(target), **values)
    path = planetary_path(target)
    if path is not None:
        return planetary_system(path, **values)
    module = module_for(target)
    opened, rest = split_open_values(values, module)
    return System.load(module_for(target, opened) if opened else module, **rest)


def split_open_values(values: dict, module: ModuleType | None = None) -> tuple[dict, dict]:
    """(open values, the rest) of named values: the first need a derivation.  A name the
    ``module`` carries as a physical quantity (``PHYSICAL`` or ``PHYSICAL_ALIASES``) is a
    parameter, not an open value."""
    if not values:
        return {}, {}
    opened = {k: v for k, v in values.items() if needs_derivation(k, module)}
    return opened, {k: v for k, v in values.items() if k not in opened}


def needs_derivation(name: str, module: ModuleType | None = None) -> bool:
    """Whether setting ``name`` derives a new model: an open value
    (``derive/input/open_values.py``) that ``module`` does not carry as a physical
    quantity of its generated ``parameters()``."""
    physical = set(getattr(module, "PHYSICAL", {})) | set(getattr(module, "PHYSICAL_ALIASES", {}))
    if name in physical:
        return False
    try:
        from gearsym.derive.input.open_values import is_open_value
    except ImportError:  # a derive layer without open values
        return False
    return is_open_value(name)


def planetary_path(target) -> Path | None:
    """The file of ``target`` (a built-in name or a path) when it is a model in body
    coordinates (a planetary set, ``[planetary]``, or a gear train with closed loops,
    ``[train]``), else None.  Looked up without the derivation (no SymPy): a command on a
    tree model must not pay for the question."""
    from gearsym import scenes
    from gearsym.derive.input.planetary import is_planetary
    from gearsym.derive.input.train import is_train

    path = Path(str(target))
    if path.suffix != ".toml" and not path.exists():
        root = Path(scenes.__file__).parent
        names = dict.fromkeys((str(target), str(target).replace("_", "-")))
        found = (root / folder / f"{n}.toml" for folder in ("planetary", "trains") for n in names)
        path = next((p for p in found if p.exists()), None)
        if path is None:
            return None
    return path if is_planetary(path) or is_train(path) else None


def planetary_system(path: Path, **values) -> System:
    """The nonlinear model of the planetary set or gear train at ``path``
    (``gearsym.planetary.dynamics``), derived once into the model cache under the hash of
    its file, this package's version and the module's format; a file without its dynamics
    table (``[planetary.dynamics]``, ``[train.dynamics]``) is refused in one line before any
    derivation."""
    from gearsym.derive.emit.planetary_module import inputs_hash, planetary_module
    from gearsym.derive.input.train import is_train

    # SymPy is imported only where the model is derived: a cached one is loaded without it
    if is_train(path):
        from gearsym.derive.input.train import load_train

        train = load_train(path)
        name = train.name

        def derive():
            from gearsym.derive.equations.train import derive_train, derive_train_dynamics

            return derive_train_dynamics(derive_train(train))

        if train.dynamics is None:  # its one line before any derivation
            derive()
    else:
        from gearsym.derive.input.planetary import load_planetary, needs_dynamics

        ps = load_planetary(path)
        needs_dynamics(ps)
        name = ps.name

        def derive():
            from gearsym.derive.equations.planetary import derive_planetary
            from gearsym.derive.equations.planetary_dynamics import derive_dynamics

            return derive_dynamics(derive_planetary(ps))

    command = f"gearsym.planetary.dynamics({name!r})"
    where = cached_module(f"{name}_dynamics", inputs_hash(path))
    module = load_cached(where)
    if module is None:
        store_cached(where, planetary_module(derive(), command))
        module = load_cached(where)
    return System.load(module, **values)
