"""Scenes: one analysis set-up -- a topology, the model features and the parameter values.

A scene names the features the model must carry (``derive/input/features.py``); the
derivation emits only their terms:

* ``stiffness_harmonics`` -- how many harmonics of each mesh stiffness to keep (0 gives
  constant stiffness and no time-varying stiffness code);
* ``backlash`` -- ``linear``, ``dead-zone`` (the default), ``smooth`` or ``polynomial``
  (the reference study's fit, with ``backlash_order``, ``backlash_range``,
  ``backlash_step``; or ``backlash_width``);
* ``transmission_error``, ``mesh_phase``, ``damping_coupling`` -- on or off.

``[parameters]`` holds named numbers: ``omega`` (the non-dimensional excitation
frequency of the reference mesh, required), ``damping_ratio`` (required) and any others
that ``[loads]`` uses.  ``[loads]`` gives the non-dimensional static load ``f_i`` of each
mesh coordinate as a number or an arithmetic expression of the parameters (``u = "f1"``,
``v = "-lambda*f1"``); with a ``load_reading`` (``[open]``, ``derive/input/readings.py``) it gives
the size of each load and the derivation gives its sign (the reference scenes:
``v = "lambda*f1"``).  Without ``[loads]`` the loads come from the topology's torques.

``[open]`` sets the values the reference study leaves open (``derive/input/open_values.py``):
numbers such as ``te_amplitude_um`` and the choices ``load_reading`` and
``damping_normalisation`` (``"mesh"`` or ``"modal"``, ``derive/equations/nondim.py``).

A topology file may be derived on its own: it then stands for a default scene with every
feature on, 3 harmonics, the reference study's backlash polynomial (stated here, not a
scene's default: the shipped topologies' generated models carry it), and ``omega`` and
the damping ratio from its ``[operating]`` table.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

from ..mesh.backlash import fit_dead_zone
from .features import BACKLASH_KEYS, Features, parse_features
from .reader import InputError, Table, load_toml, nearest, parse_expression
from .stated import SPEED, TORQUE, stated_physically
from .supports import load_topology_data
from .topology import Topology, load_topology, parse_topology

__all__ = [
    "Features",
    "Scene",
    "builtin_root",
    "load_scene",
    "load_target",
    "resolve_target",
    "variant",
]


def builtin_root() -> Path:
    """Folder of the built-in scenes and topologies (``scenes/`` of the package)."""
    from gearsym import scenes

    return Path(scenes.__file__).parent


@dataclass(frozen=True)
class Scene:
    """A resolved scene: everything the derivation needs, validated.

    ``loads`` maps each mesh coordinate to its non-dimensional static load, or is None
    when the loads come from the topology's torques.
    """

    name: str
    description: str
    topology: Topology
    features: Features
    parameters: dict[str, float]
    loads: dict[str, float] | None
    load_expressions: dict[str, str] | None
    source: str
    kind: str = "scene"  # "scene" or "topology" (a topology derived with default features)
    variations: dict = field(default_factory=dict)  # [features] changed by variant()
    # The study's open choices (derive/input/open_values.py, derive/input/readings.py): the
    # reading of the loads (None: [loads] carry their own signs) and the damping normalisation.
    load_reading: str | None = None
    damping_normalisation: str = "mesh"

    @property
    def omega(self) -> float | None:
        """omega, or None for a topology whose omega follows from its operating speed."""
        return self.parameters.get("omega")

    @property
    def damping_ratio(self) -> float:
        return self.parameters["damping_ratio"]


def variant(scene: Scene, name: str, **features) -> Scene:
    """``scene`` with some ``[features]`` keys changed, under another ``name``.

    The keys and values are those of a scene file's ``[features]`` table
    (``stiffness_harmonics=0``, ``backlash="dead-zone"``, ``backlash_order=5``,
    ``transmission_error=False``, ...), read and checked by the same code as the file;
    keys of another backlash kind are dropped when ``backlash`` changes.  The changes
    enter the derivation's inputs hash, so a variant never passes for its original.
    """
    data = load_toml(Path(scene.source)) if scene.kind == "scene" else {}
    table = dict(data.get("features", {}))
    if "backlash" in features:
        kind = features["backlash"]
        for other, keys in BACKLASH_KEYS.items():
            if other != kind:
                for key in keys:
                    if key not in features:
                        table.pop(key, None)
    table.update(features)
    where = f"{scene.source} (variant {name})"
    checked = Table({"name": name}, where).target_name("name")
    feats = parse_features(Table(table, where, "features"))
    return replace(scene, name=checked, features=feats, variations=scene.variations | features)


def resolve_target(name: str, *, kind: str | None = None) -> Path:
    """A path, or the name of a built-in scene or topology, to a file path."""
    path = Path(name)
    if path.suffix == ".toml" or path.exists():
        return path
    root = builtin_root()
    candidates = []
    # Built-in names may be written with underscores, as the generated modules are.
    for spelling in dict.fromkeys((name, name.replace("_", "-"))):
        if kind in (None, "scene"):
            candidates.append(root / f"{spelling}.toml")
        if kind in (None, "topology"):
            candidates.append(root / "topologies" / f"{spelling}.toml")
            candidates.append(root / "planetary" / f"{spelling}.toml")
            candidates.append(root / "trains" / f"{spelling}.toml")
    for c in candidates:
        if c.exists():
            return c
    known = sorted(p.stem for p in root.glob("*.toml")) + sorted(
        p.stem
        for folder in ("topologies", "planetary", "trains")
        for p in (root / folder).glob("*.toml")
    )
    raise InputError(
        name,
        "",
        "is neither a file nor a built-in scene or topology"
        + nearest(name, known)
        + f"; built-in: {', '.join(known)}",
    )


def load_scene(path: Path | str, overrides: dict[str, float] | None = None) -> Scene:
    """Read and validate a scene file (``overrides`` replace ``[parameters]`` values)."""
    path = Path(path)
    data = load_toml(path)
    source = str(path)
    top = Table(data, source)
    head = top.table("scene")
    name = head.target_name("name")
    description = head.string("description", "")
    topo_ref = head.string("topology")
    head.finish()
    topo_path = path.parent / topo_ref
    if not topo_path.exists():
        builtin = builtin_root() / "topologies" / f"{topo_ref}.toml"
        if not builtin.exists():
            known = sorted(p.stem for p in (builtin_root() / "topologies").glob("*.toml"))
            raise head.error(
                "topology",
                f"'{topo_ref}' is neither a file next to the scene "
                "nor a built-in topology"
                + nearest(topo_ref, known)
                + f"; built-in: {', '.join(known)}",
            )
        topo_path = builtin
    open_t = top.table("open", None)
    choices: dict[str, str] = {}
    if open_t is None:
        topology = load_topology(topo_path)
    else:
        # the study's open values, set in the scene (derive/input/open_values.py)
        from .open_values import CHOICES, apply_open_values

        for key in CHOICES:
            if open_t.has(key):
                choices[key] = open_t.string(key)
        values = {key: open_t.number(key) for key in open_t.data if key not in CHOICES}
        open_t.finish()
        data = apply_open_values(load_topology_data(topo_path), values, f"{source} [open]")
        topology = parse_topology(data, str(topo_path))
    reading = choices.get("load_reading")
    if reading is not None:
        from .readings import apply_reading

        topology = apply_reading(topology, reading, f"{source} [open]")
    damping = choices.get("damping_normalisation", "mesh")
    if damping != "mesh":
        from .open_values import check_damping

        check_damping(damping, f"{source} [open]")
    features = parse_features(top.table("features", None))

    pt = top.table("parameters")
    parameters: dict[str, float] = {}
    for key in pt.data:
        parameters[key] = pt.number(key)
    pt.finish()
    topology = stated_physically(pt, parameters, topology)
    for required in ("omega", "damping_ratio"):
        if required not in parameters and not (required == "omega" and SPEED in pt.data):
            raise pt.error(required, "is required but missing (or speed_rpm for omega)")
    for key, value in (overrides or {}).items():
        if key not in parameters:
            raise InputError(
                source,
                f"parameters.{key}",
                "cannot be set: not a parameter of this scene" + nearest(key, parameters),
            )
        parameters[key] = float(value)
    _check_parameters(pt, parameters)

    loads = expressions = None
    lt = top.table("loads", None)
    torques = [k for k in pt.data if k.startswith(TORQUE)]
    if lt is not None and torques:
        raise pt.error(
            torques[0],
            "and [loads] both state the loads; keep the torques (physical) or [loads] "
            "(non-dimensional)",
        )
    if lt is None:  # loads from the torques: every other key must be one the model uses
        for key in parameters:
            if key not in PARAMETER_LIMITS:
                raise pt.error(
                    key,
                    "is not a parameter of a scene whose loads come from its torques; "
                    "parameters: omega or speed_rpm, damping_ratio, torque_Nm_<gear>"
                    + nearest(key, ["omega", "damping_ratio", SPEED]),
                )
    if lt is not None:
        coords = [m.coordinate for m in topology.meshes]
        loads, expressions = {}, {}
        for key in lt.data:
            if key not in coords:
                raise lt.error(
                    key,
                    "is not a mesh coordinate of topology "
                    f"'{topology.name}'"
                    + nearest(key, coords)
                    + f"; coordinates: {', '.join(coords)}",
                )
        for c in coords:
            raw = lt.raw(c)
            loads[c] = parse_expression(raw, parameters, source=source, key=lt.key(c))
            expressions[c] = raw if isinstance(raw, str) else float(raw)
            if reading is not None and loads[c] < 0:
                raise lt.error(
                    c,
                    f"'{raw}' = {loads[c]:g} < 0: with a load_reading the load is a size and "
                    "its sign comes from the reading; drop the sign",
                )
        lt.finish()
        import re

        used = {
            w
            for e in expressions.values()
            if isinstance(e, str)
            for w in re.findall(r"[A-Za-z_]\w*", e)
        }
        for key in parameters:
            if key not in PARAMETER_LIMITS and key not in used:
                raise InputError(
                    source,
                    f"parameters.{key}",
                    "is not used by any load ([loads]: "
                    + ", ".join(f"{c} = {e}" for c, e in expressions.items())
                    + ")"
                    + nearest(key, sorted(used))
                    + "; use it in a load or remove it",
                )
    elif not topology.torques:
        raise InputError(
            source,
            "loads",
            "is missing and the topology has no [[torque]]; "
            "give the non-dimensional load of every coordinate",
        )
    elif reading is not None:
        raise InputError(source, "loads", "a load_reading needs [loads]: the size of each load")
    top.finish()
    return Scene(
        name,
        description,
        topology,
        features,
        parameters,
        loads,
        expressions,
        source,
        load_reading=reading,
        damping_normalisation=damping,
    )


# The one rule per scene parameter: (low, high, low excluded).  The scene file is checked
# here; the generated module carries the same table (SCENE_PARAMETER_LIMITS, emit.py) and
# checks every value that reaches parameters(): --set, sweep ranges, map axes, continuation.
# omega (the mesh frequency over omega_n) in [1e-3, 1e3]: below, the excitation is
# quasi-static and one period costs more than 1000 periods at omega = 1 (bounded work);
# above, it is a thousand times any mesh-to-natural frequency ratio a gear train runs at.
PARAMETER_LIMITS = {"omega": (1e-3, 1e3, False), "damping_ratio": (0.0, 1.0, False)}


def limit_text(key: str, value: float) -> str | None:
    """Why ``value`` is not allowed for scene parameter ``key``, or None."""
    if key not in PARAMETER_LIMITS:
        return None
    low, high, low_open = PARAMETER_LIMITS[key]
    if high is None:
        ok = value > low if low_open else value >= low
        rule = f"{'>' if low_open else '>='} {low:g}"
    else:
        ok, rule = low <= value <= high, f"in [{low:g}, {high:g}]"
    return None if ok else f"must be {rule}, got {value:g}"


def _check_parameters(t: Table, parameters: dict[str, float]) -> None:
    for key, value in parameters.items():
        if (why := limit_text(key, value)) is not None:
            raise t.error(key, why)


def load_target(path: Path | str, overrides: dict[str, float] | None = None) -> Scene:
    """A scene file, or a topology file wrapped in its default scene."""
    path = Path(path)
    data = load_toml(path)
    if "topology" in data and "scene" not in data:
        topology = parse_topology(load_topology_data(path), str(path))
        if topology.operating is None:
            raise InputError(
                str(path),
                "operating",
                "a topology derived on its own needs an "
                "[operating] table (gear, speed_rpm, damping_ratio) to set omega "
                "and the damping; or derive a scene that uses it",
            )
        if not topology.torques:
            raise InputError(
                str(path),
                "torque",
                "a topology derived on its own needs "
                "[[torque]] entries for its loads; or derive a scene that uses it",
            )
        # omega follows from the operating speed once the model knows omega_n (derive_model);
        # it may be overridden like the damping ratio.
        parameters = {"damping_ratio": topology.operating.damping_ratio}
        for key, value in (overrides or {}).items():
            if key not in ("omega", "damping_ratio"):
                raise InputError(
                    str(path), key, "cannot be set on a topology; parameters: omega, damping_ratio"
                )
            parameters[key] = float(value)
        _check_parameters(Table({}, str(path), "operating"), parameters)
        # Every feature on: a topology whose gears all sit on bearings moves them.
        supported = topology.bearings and set(topology.bearings) == {g.id for g in topology.gears}
        dofs = "lateral-torsional-axial" if supported else "torsional"
        return Scene(
            topology.name,
            topology.description,
            topology,
            Features(backlash=fit_dead_zone(), degrees_of_freedom=dofs),
            parameters,
            None,
            None,
            str(path),
            kind="topology",
        )
    if "scene" not in data:
        raise InputError(
            str(path),
            "",
            "is neither a scene (no [scene] table) nor a topology (no [topology] table)",
        )
    return load_scene(path, overrides)
