"""The derivation pipeline: targets -> models -> files, and the staleness check.

``build_files(paths)`` derives each target (a scene, or a topology with its default scene)
and returns the text of every file it owns, keyed by the path relative to the project
root: ``generated/<name>.py`` and ``docs/derivation/<name>.md``, plus
``docs/derivation.md`` when the shipped set is built.  ``check(root)`` rebuilds the
shipped set in memory and lists every file that differs from what is on disk.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

from .emit.audit import audit_page, index_page
from .emit.python import emit_module, write_atomic
from .emit.stiffness_report import stiffness_page
from .input.paths import display_path, project_root  # re-exported: callers import them here
from .input.reader import InputError
from .input.scene import builtin_root, load_target
from .input.topology import load_topology
from .model import Model, derive_model

__all__ = [
    "Built",
    "build_files",
    "check",
    "describe",
    "display_path",
    "project_root",
    "planetary_files",
    "shipped_planetary",
    "shipped_trains",
    "shipped_targets",
    "write_files",
    "write_stiffness_figure",
]


def shipped_targets() -> list[Path]:
    """Built-in scenes, then built-in topologies, in name order."""
    root = builtin_root()
    return sorted(root.glob("*.toml")) + sorted((root / "topologies").glob("*.toml"))


def shipped_planetary() -> list[Path]:
    """Built-in planetary sets (``scenes/planetary``): an audit page each, no module."""
    return sorted((builtin_root() / "planetary").glob("*.toml"))


def shipped_trains() -> list[Path]:
    """Built-in gear trains with closed loops (``scenes/trains``): an audit page each, their
    nonlinear model derived on first use into the cache."""
    return sorted((builtin_root() / "trains").glob("*.toml"))


def train_files(paths, derived: dict | None = None) -> dict[str, str]:
    """``docs/derivation/<name>.md`` of each gear train in ``paths``; ``derived``, if given,
    receives each path's linear model (the index reads them again)."""
    from .emit.audit_train import train_page
    from .equations.train import derive_train
    from .input.train import load_train

    files = {}
    for path in paths:
        st = derive_train(load_train(path))
        if derived is not None:
            derived[path] = st
        page = train_page(st, f"gearsym derive {display_path(path)}", display_path(path))
        files[f"docs/derivation/{st.train.name.replace('-', '_')}.md"] = page
    return files


def planetary_files(paths, derived: dict | None = None) -> dict[str, str]:
    """``docs/derivation/<name>.md`` of each planetary set in ``paths``; ``derived``, if
    given, receives each path's derived set (the index reads them again)."""
    from .emit.audit_planetary import planetary_name, planetary_page
    from .equations.planetary import derive_planetary
    from .input.planetary import load_planetary

    files = {}
    for path in paths:
        st = derive_planetary(load_planetary(path))
        if derived is not None:
            derived[path] = st
        command = f"gearsym derive {display_path(path)}"
        page = planetary_page(st, command, display_path(path))
        files[f"docs/derivation/{planetary_name(st.planetary.name)}.md"] = page
    return files


@dataclass(frozen=True)
class Built:
    models: tuple[Model, ...]
    files: dict[str, str]


def build_files(
    paths: list[Path], *, index: bool = False, overrides: dict[str, float] | None = None
) -> Built:
    """Derive every target in ``paths``; return the models and the files' text.
    ``overrides`` set scene parameters, or open values (``derive.open_values``), which
    give each target's variant."""
    from .input.open_values import is_open_value
    from .input.planetary import is_planetary
    from .input.train import is_train

    models, files = [], {}
    opened = {k: v for k, v in (overrides or {}).items() if is_open_value(k)}
    rest = {k: v for k, v in (overrides or {}).items() if k not in opened}
    planetary = [p for p in paths if is_planetary(p)]
    trains = [p for p in paths if is_train(p)]
    if (planetary or trains) and overrides:
        raise InputError(
            str((planetary + trains)[0]),
            "--set",
            "a planetary set or gear train takes no --set in derive; edit its file (or give "
            "--set to the command that runs it)",
        )
    derived: dict = {}
    jobs = [(p, rest, opened) for p in paths if p not in planetary and p not in trains]
    pool = _pool(len(jobs))
    pending = pool.map(_derive_one, jobs) if pool else None  # runs while the sets derive
    files.update(planetary_files(planetary + (shipped_planetary() if index else []), derived))
    files.update(train_files(trains + (shipped_trains() if index else []), derived))
    try:
        done = list(pending) if pool else [None] * len(jobs)
    finally:  # Ctrl-C: the workers (which ignore it) finish their target and stop
        if pool:
            pool.shutdown(wait=False, cancel_futures=True)
    for job, result in zip(jobs, done, strict=True):
        # a target a worker could not derive (or no workers) is derived here, where its
        # error is raised as the user should see it
        model, module, page = result or _derive_one(job, quiet=False)
        files[f"generated/{model.name}.py"] = module
        files[f"docs/derivation/{model.name}.md"] = page
        models.append(model)
    names = [m.name for m in models]
    if len(set(names)) != len(names):
        dup = sorted({n for n in names if names.count(n) > 1})
        raise InputError(
            "derive",
            "name",
            f"two targets derive to the same model name ({', '.join(dup)}); "
            "give each scene or topology its own name",
        )
    if index:
        from .emit.audit_planetary import planetary_index
        from .emit.audit_train import train_index

        sets = [derived[p] for p in shipped_planetary()]
        files["docs/derivation.md"] = (
            index_page(models, "gearsym derive")
            + planetary_index(sets)
            + train_index([derived[p] for p in shipped_trains()])
        )
        files[STIFFNESS_PAGE] = stiffness_page(
            load_topology(_reference_topology()), "gearsym derive", Path(STIFFNESS_FIGURE).name
        )
    return Built(tuple(models), files)


def _derive_one(job, quiet: bool = True):
    """``(model, module text, audit page)`` of one target; ``quiet``: None on any error (a
    worker's exception need not survive pickling; the caller derives it again)."""
    from .input.open_values import with_open_values

    path, rest, opened = job
    try:
        scene = with_open_values(load_target(path, rest or None), **opened)
        model = derive_model(scene)
        command = f"gearsym derive {display_path(path)}"
        return model, emit_module(model, command), audit_page(model, command)
    except Exception:
        if quiet:
            return None
        raise


def _pool(jobs: int):
    """Worker processes for ``jobs`` derivations (each a few seconds of SymPy, independent
    of the others), or None where one process is as quick: fewer than four targets (a
    user's own), one core, or ``GEARSYM_DERIVE_WORKERS=1``."""
    import os
    from concurrent.futures import ProcessPoolExecutor

    workers = int(os.environ.get("GEARSYM_DERIVE_WORKERS", os.cpu_count() or 1))
    if jobs < 4 or workers < 2:
        return None
    return ProcessPoolExecutor(max_workers=min(workers, jobs), initializer=_ignore_interrupt)


def _ignore_interrupt() -> None:
    """A worker leaves Ctrl-C to the command, which stops and says so in one line."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


STIFFNESS_PAGE = "docs/stiffness.md"
STIFFNESS_FIGURE = "docs/stiffness.png"


def _reference_topology() -> Path:
    return builtin_root() / "topologies" / "diso.toml"


def write_stiffness_figure(root: Path) -> Path:
    """Draw ``docs/stiffness.png`` (k(t) of the reference stage's first mesh)."""
    from .emit.stiffness_figures import mesh_pem, plot_mesh

    topology = load_topology(_reference_topology())
    mesh = topology.meshes[0]
    path = Path(root) / STIFFNESS_FIGURE
    path.parent.mkdir(parents=True, exist_ok=True)
    plot_mesh(
        mesh_pem(topology, mesh, 200, 3),
        path,
        f"{topology.name}: mesh {mesh.id} ({mesh.driver} drives {mesh.driven})",
    )
    return path


def write_files(files: dict[str, str], root: Path) -> list[Path]:
    written = []
    for rel, text in files.items():
        path = Path(root) / rel
        write_atomic(path, text)
        written.append(path)
    return written


def differs(old: str, new: str) -> str:
    """Why a file on disk (``old``) is stale against its regeneration (``new``): a
    generated module whose code changed under the same INPUTS_SHA256 means that models
    derived into users' caches before the change would be loaded stale."""

    def digest(text):
        found = re.search(r"^INPUTS_SHA256 = ['\"]([0-9a-f]{64})['\"]", text, re.M)
        return found and found.group(1)

    if digest(old) and digest(old) == digest(new):
        return (
            "differs under the same INPUTS_SHA256: edited by hand, or the emitted code "
            "changed; then bump EMITTED_FORMAT in derive/_version.py, so that models "
            "cached before are derived again"
        )
    return "differs"


def check(root: Path | None = None, built: Built | None = None) -> list[str]:
    """Files under ``root`` that differ from a fresh regeneration of the shipped set
    (``built``: that regeneration, when already made in this process)."""
    root = Path(root) if root is not None else project_root()
    built = built or build_files(shipped_targets(), index=True)
    stale = []
    for rel, text in built.files.items():
        path = root / rel
        if not path.exists():
            stale.append(f"{rel} (missing)")
        elif (old := path.read_text(encoding="utf-8")) != text:
            stale.append(f"{rel} ({differs(old, text)})")
    if not (root / STIFFNESS_FIGURE).exists():
        stale.append(f"{STIFFNESS_FIGURE} (missing)")
    owned = set(built.files)
    for folder, pattern in (("generated", "*.py"), ("docs/derivation", "*.md")):
        for path in sorted((root / folder).glob(pattern)):
            rel = path.relative_to(root).as_posix()
            if rel in owned or path.name == "__init__.py":
                continue
            head = path.read_text(encoding="utf-8", errors="replace")[:400]
            if "gearsym derive scenes/" in head:
                stale.append(f"{rel} (left over: its shipped source no longer exists)")
    return stale


def describe(model: Model) -> dict:
    """Every number of the non-dimensional equations, as plain JSON-ready data."""
    values = dict(zip(model.parameter_names, model.defaults, strict=True))
    coords = model.coordinates
    feats = model.features
    H = feats.stiffness_harmonics
    kappa = {}
    for ci in coords:
        for j, cj in enumerate(coords):
            mean = values.get(f"kappa_{ci}_{cj}")
            if mean is None:
                continue
            kappa[f"{ci}{cj}"] = {
                "mean": mean,
                "cos": [mean * values[f"kc_{cj}_{h}"] for h in range(1, H + 1)],
                "sin": [mean * values[f"ks_{cj}_{h}"] for h in range(1, H + 1)],
                "phase_rad": values.get(f"phi_{cj}", 0.0),
                "frequency_ratio": str(model.frequency_ratios[j]),
            }
    xi = {
        f"{ci}{cj}": values[f"xi_{ci}_{cj}"]
        for ci in coords
        for cj in coords
        if f"xi_{ci}_{cj}" in values
    }
    te = {}
    for c in coords:
        amps = [v for k, v in values.items() if k.startswith(f"E_{c}_")]
        if amps:
            te[c] = {
                "amplitude": amps,
                "phase_rad": [v for k, v in values.items() if k.startswith(f"psi_{c}_")],
            }
    b = feats.backlash
    backlash = {"kind": b.kind, "valid_range": b.valid_range}
    if b.kind == "polynomial":
        backlash.update(
            order=b.order,
            fit_samples=b.samples,
            coefficients={str(k): c for k, c in zip(b.powers, b.coefficients, strict=True)},
            max_error_vs_dead_zone=b.max_error(),
        )
    elif b.kind == "smooth":
        backlash.update(width=b.width, max_error_vs_dead_zone=b.max_error())
    return {
        "name": model.name,
        "scene": model.scene.name,
        "source": display_path(Path(model.scene.source)),
        "inputs_sha256": model.inputs_hash,
        "equation": "u_i'' + sum_j 2 xi_ij u_j' + sum_j kappa_ij(tau) g(u_j) = f_i + ebar_i''",
        "states": list(model.states),
        "parameters": values,
        "omega": values["omega"],
        "f": {c: values[f"f_{c}"] for c in coords},
        "xi": xi,
        "kappa": kappa,
        "kappa_form": "kappa_ij(tau) = mean + sum_h cos_h cos(h(r w tau - phase)) + "
        "sin_h sin(h(r w tau - phase)), r = frequency_ratio, w = omega",
        "transmission_error": te,
        "transmission_error_form": "ebar_j(tau) = sum_h amplitude_h cos(h(r w tau - phase_j)"
        " + phase_h)",
        "backlash": backlash,
        "features": feats.flags(),
        "scales": model.scales,
        "operations": model.operations,
    }


def describe_json(models) -> str:
    return json.dumps({m.name: describe(m) for m in models}, indent=2, sort_keys=False)
