"""Build and cache the native library of a generated model.

The generated module carries its right-hand side as C (``C_SOURCE``, printed by
``derive/emit/c.py`` from the same SymPy expressions as the NumPy and CasADi code, with
the excitation's harmonics reduced to one ``sincos`` per step stage).  It is compiled with
the system C compiler (``cc``, or ``$GEARSYM_CC``) together with the integrators of
``native_*.c`` and the checked tableaux of ``../tableau.py`` into a shared library, loaded
with ``ctypes`` and cached under ``<cache root>/native`` (``solver/cache.py``) keyed by
the sha256 of its full source, the compiler and the CPU, so that a second run pays no
compile time.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from ...cache import cache_root, locked
from ..tableau import RK4, c_tables
from . import abi
from .compiler import _compiler_id, _no_compiler, compiler, flags, level

__all__ = [
    "NativeUnavailable",
    "cache_dir",
    "compiler",
    "level",
    "library",
    "prebuild",
    "single_point",
    "source",
]

_loaded: dict[str, ctypes.CDLL] = {}
# (module file, inputs hash, variational, flags and defines, compiler, cache) -> library
_paths: dict[tuple, Path] = {}
_failed: dict[str, str] = {}  # cache key -> why it could not be built (once per session)
# (compiler, model file) -> the bug report of a compiler that failed on the model's C: its
# other libraries (with tangents, say), which hold the same C, are not tried again, so a
# run says the one line once
_broken: dict[tuple[str, str], str] = {}


class NativeUnavailable(RuntimeError):
    """No C compiler, or the compilation failed: the NumPy path is used instead.  A
    compiler that fails on a model's C text is a bug; its output is saved beside the
    library it should have built (``<name>-<key>.log`` in :func:`cache_dir`)."""


def cache_dir() -> Path:
    """Where compiled libraries are kept: ``native/`` under the cache root."""
    return cache_root() / "native"


def _rk4_tables() -> str:
    """The RK4 record of ``tableau.py`` as C arrays (the format of ``c_tables``)."""

    def arr(name, values):
        flat = np.asarray(values, dtype=float).ravel()
        return (
            f"static const double {name}[{flat.size}] = {{{', '.join(map(repr, flat.tolist()))}}};"
        )

    return "\n".join([arr("GS_RK4_A", RK4.A), arr("GS_RK4_B", RK4.b), arr("GS_RK4_C", RK4.c)])


def source(module, variational: bool | str = False) -> str:
    """Full C text of the library for a generated module (``variational``: the state
    extended by a tangent vector, for the Lyapunov exponent; ``"monodromy"``: by the
    matrix of all tangents, ``monodromy.c``)."""
    text = _model_text(module, variational)
    if variational == "monodromy":
        head = ["#include <math.h>"]
    else:
        head = [*(["#define GS_VARIATIONAL 1"] if variational else []), "#include <math.h>"]
    return "\n".join([*head, text, c_tables(), _rk4_tables(), engine_text()])


def monodromy_library(module) -> bool:
    """Whether ``module`` carries the C text of its Jacobian (``C_JACOBIAN``), which the
    monodromy library needs (modules generated before it run the tangents as copies)."""
    return hasattr(module, "C_JACOBIAN") and hasattr(module, "C_SOURCE")


def _model_text(module, variational) -> str:
    """The model's part of the library: its C source (``variational``: the one with the
    tangent; ``"monodromy"``: the plain one renamed, its Jacobian and monodromy.c)."""
    attrs = {False: "C_SOURCE", True: "C_SOURCE_VARIATIONAL", "monodromy": "C_JACOBIAN"}
    attr = attrs[variational]
    if not hasattr(module, attr):
        raise NativeUnavailable(
            f"generated module '{module.NAME}' has no {attr}; regenerate it with `gearsym derive`"
        )
    if variational != "monodromy":
        return getattr(module, attr)
    rename = ("gs_prep", "gs_rhs", "gs_rhs_batch")
    return "\n".join(
        [
            *(f"#define {f} gs_model_{f[3:]}" for f in rename),
            module.C_SOURCE,
            *(f"#undef {f}" for f in rename),
            module.C_JACOBIAN,
            f"#define GS_MONODROMY_N {len(module.CONTRACT['states'])}",
            (Path(__file__).parent / "monodromy.c").read_text(encoding="utf-8"),
        ]
    )


# The C engine, in the order its parts are joined: the job and the shared utilities, the
# step arithmetic (stages, error, samples, valid range), the step loop and the one entry.
ENGINE_PARTS = ("native_1_job.c", "native_2_step.c", "native_3_loop.c")


def engine_text() -> str:
    """The C engine's text: its parts joined in order (one translation unit)."""
    here = Path(__file__).parent
    return "".join((here / name).read_text(encoding="utf-8") for name in ENGINE_PARTS)


def _key_text(module, variational) -> str:
    """What the library's text depends on: the model's C, the engine and the tableaux'
    source (SciPy's version)."""
    from importlib.metadata import version

    text = _model_text(module, variational)  # raises NativeUnavailable with the reason
    engine = engine_text()
    tables = [f"scipy {version('scipy')}", _rk4_tables()]
    return "\n".join([f"variational={variational}", text, engine, *tables])


def _bug_report(module, cc: str, path: Path, c_file: Path, done, defines=()) -> str:
    """Save the compiler's full output (and the C text it was given) beside the library it
    should have made, and return the one line that says so: the C code of a model that
    derives is valid by construction, so a failing compile is a bug to report."""
    log, kept = path.with_suffix(".log"), path.with_suffix(".c")
    how = f"exit status {done.returncode}" if done.returncode else "no library written"
    lines = [
        f"$ {cc} {' '.join([*flags(cc), *defines])} -o lib.so {kept.name} -lm",
        f"({how})",
        "--- stdout ---",
        done.stdout or "",
        "--- stderr ---",
        done.stderr or "",
    ]
    try:
        shutil.copyfile(c_file, kept)
        log.write_text("\n".join(lines), encoding="utf-8")
        saved = f"the compiler's full output is in {log}"
    except OSError as err:
        saved = f"the compiler's output could not be saved: {err.strerror or err}"
    return (
        f"compiling the C code of {module.NAME} with {cc} failed ({how}); this is a bug, "
        f"please report it ({saved})"
    )


def _digest_file(path: Path) -> Path:
    return path.with_suffix(".sha256")


def _verified(path: Path) -> bool:
    """Whether the library's bytes hash to the digest written beside it when it was built
    (the cache is verified, never trusted: docs/user-guide.md)."""
    try:
        stated = _digest_file(path).read_text(encoding="utf-8").strip()
        return hashlib.sha256(path.read_bytes()).hexdigest() == stated
    except (OSError, UnicodeDecodeError):
        return False


def _shared_flags(module, shared) -> list[str]:
    """``-DGS_SHARED_<k>=1`` for each parameter index ``k`` equal across a batch."""
    n_p = len(module.CONTRACT["parameters"]) if hasattr(module, "CONTRACT") else None
    ks = sorted({int(k) for k in shared})
    if ks and (ks[0] < 0 or (n_p is not None and ks[-1] >= n_p)):
        raise ValueError(f"shared parameter indices {ks} must lie in [0, {n_p})")
    return [f"-DGS_SHARED_{k}=1" for k in ks]


def single_point(module) -> tuple[int, ...]:
    """``shared`` of a batch of one point (every parameter equal across it): the library
    a sweep's runs, a re-examined run and a shooting check use."""
    return tuple(range(len(module.CONTRACT["parameters"])))


def prebuild(items, *, executor: str = "serial", workers: int | None = None) -> None:
    """Compile the libraries ``items`` name side by side into the cache before a batch of
    runs needs them (one at a time in the main process, the compilations kept the workers
    idle).  Each item is ``(generated module file, variational, shared)`` as
    :func:`library` takes them.  Only with the ``processes`` executor (a cluster's workers
    build their own); a library that cannot be built is left to the caller's own
    :func:`library` call, which says why, once."""
    from ...executor import map_tasks

    todo = list(dict.fromkeys((str(f), bool(v), tuple(sh)) for f, v, sh in items))
    if executor == "processes" and len(todo) > 1 and compiler() is not None:
        map_tasks(_prebuild_one, todo, executor=executor, workers=workers)


def _prebuild_one(item: tuple) -> None:
    from ...contract import load_generated

    source, variational, shared = item
    try:
        library(load_generated(source), variational=variational, shared=shared)
    except NativeUnavailable:
        pass


def library(module, variational: bool | str = False, shared=()) -> tuple[ctypes.CDLL, dict]:
    """Compile (or load from the cache) the native library of ``module``
    (``variational``: with one tangent; ``"monodromy"``: with the matrix of tangents).

    ``shared``: indices of the parameters equal across the whole batch, compiled in as
    ``-DGS_SHARED_<k>=1`` so that the generated C may hoist what depends only on them (and
    tau) out of the point loop; the default (none) is the library for any batch.
    Returns the library and facts: ``path``, ``compiled`` (bool: built now), ``seconds``.
    Raises :class:`NativeUnavailable` without a working compiler, or when the library's
    job layout differs from ``abi.py``'s.
    """
    cc = compiler()
    if cc is None:
        raise NativeUnavailable(_no_compiler())
    # only a model whose C reads GS_SHARED_<k> gets them (else one library per level)
    text = getattr(module, "C_SOURCE_VARIATIONAL" if variational is True else "C_SOURCE", "")
    # (the monodromy library runs its points one at a time: nothing to hoist)
    monodromy = variational == "monodromy"
    defines = _shared_flags(module, shared) if "GS_SHARED_" in text and not monodromy else []
    defines = [*level(module, variational, shared), *defines]
    memo = (
        getattr(module, "__file__", module.NAME),
        getattr(module, "INPUTS_SHA256", ""),
        variational,
        tuple(defines),
        cc,
        str(cache_dir()),
    )
    facts = {"compiled": False, "seconds": 0.0, "compiler": cc}
    path = _paths.get(memo)
    if path is not None and str(path) in _loaded:
        facts["path"] = str(path)
        return _loaded[str(path)], facts
    # The key names everything the library is built from without building its text: the
    # tableaux are SciPy's coefficient arrays, so SciPy's version stands for them (and
    # SciPy itself is not imported for a library that is already compiled).
    key = hashlib.sha256(
        "\n".join(
            [_key_text(module, variational), _compiler_id(cc), " ".join([*flags(cc), *defines])]
        ).encode()
    ).hexdigest()[:20]
    if key in _failed:
        raise NativeUnavailable(_failed[key])
    if (cc, memo[0]) in _broken:
        raise NativeUnavailable(_broken[cc, memo[0]])
    # named by what it is built from, not by the model: models whose C is the same (the
    # light and heavy reference scenes, a variant and its scene) share the one library
    kind = "-mono" if monodromy else "-var" if variational else ""
    path = cache_dir() / f"rhs{kind}-{key}.so"
    facts["path"] = str(path)
    if str(path) in _loaded:
        _paths[memo] = path
        return _loaded[str(path)], facts
    # One build per library across processes: two workers that need the same library
    # at once (a reproduce's first tasks) compiled it twice; the second now waits for
    # the first and loads what it built.
    with locked(path):
        if path.exists() and not _verified(path):
            if _digest_file(path).exists():  # without one: built before digests, rebuilt quietly
                warnings.warn(
                    f"the compiled library {path} does not match the digest stored beside it "
                    "(cut short or changed); building it again",
                    stacklevel=2,
                )
            path.unlink(missing_ok=True)
        if not path.exists():
            started = time.perf_counter()
            path.parent.mkdir(parents=True, exist_ok=True)
            with tempfile.TemporaryDirectory(dir=path.parent) as tmp:
                c_file = Path(tmp) / "model.c"
                c_file.write_text(source(module, variational), encoding="utf-8")
                so = Path(tmp) / "lib.so"
                try:
                    done = subprocess.run(
                        [cc, *flags(cc), *defines, "-o", str(so), str(c_file), "-lm"],
                        capture_output=True,
                        text=True,
                        timeout=300,
                    )
                except (OSError, subprocess.SubprocessError) as err:
                    _failed[key] = f"the C compiler {cc} could not be run ({err})"
                    raise NativeUnavailable(_failed[key]) from None
                if done.returncode != 0 or not so.exists():
                    _failed[key] = _bug_report(module, cc, path, c_file, done, defines)
                    _broken[cc, memo[0]] = _failed[key]
                    raise NativeUnavailable(_failed[key])
                digest = hashlib.sha256(so.read_bytes()).hexdigest()
                stated = Path(tmp) / "lib.sha256"
                stated.write_text(digest + "\n", encoding="utf-8")
                os.replace(stated, _digest_file(path))  # the digest first, then the library:
                os.replace(so, path)  # atomic: parallel workers never see half a library
            facts.update(compiled=True, seconds=time.perf_counter() - started)
    _paths[memo] = path
    try:
        lib = ctypes.CDLL(str(path))
    except OSError as err:
        # a library that does not load (cut short on disk, another CPU's): build it anew
        # next time, and say why this run goes without it
        path.unlink(missing_ok=True)
        _failed[key] = f"the compiled library {path} could not be loaded ({err})"
        raise NativeUnavailable(_failed[key]) from None
    try:
        abi.bind(lib, str(path))
    except abi.LayoutMismatch as err:
        _failed[key] = str(err)
        raise NativeUnavailable(_failed[key]) from None
    _loaded[str(path)] = lib
    return lib, facts
