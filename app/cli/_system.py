"""The System a command runs: a scene's or topology's model with its ``--set`` values, or a
planetary set's nonlinear model (``gearsym.planetary.dynamics``)."""

from __future__ import annotations

from ._common import Fail

__all__ = ["system_of", "unknown_names"]


def system_of(scene_arg: str, sets: dict[str, float]):
    """The System of a scene (name or path) with ``--set`` values (``gearsym.resolve``),
    a polynomial backlash noted once (``_notes``); a bad scene raises its own InputError."""
    from gearsym.cli._notes import note_backlash, note_frame, note_torques
    from gearsym.derive.input.reader import InputError
    from gearsym.resolve import module_for, planetary_path, planetary_system, split_open_values
    from gearsym.solver.system import System

    planetary = planetary_path(scene_arg)
    if planetary is not None:  # its nonlinear model (gearsym.planetary.dynamics)
        try:
            system = planetary_system(planetary, **sets)
        except KeyError as err:
            said = unknown_names(planetary_system(planetary).module, sets)
            raise Fail(said or f"--set: {err.args[0]}") from None
        except ValueError as err:
            if isinstance(err, InputError):
                raise
            given = " ".join(f"{k}={v}" for k, v in sets.items())
            raise Fail(f"--set {given}: {err}") from None
        return note_frame(system)
    module = module_for(scene_arg)
    opened, rest = split_open_values(sets, module)
    module = module_for(scene_arg, opened) if opened else module
    try:
        return note_torques(note_backlash(System.load(module, **rest)))
    except KeyError as err:
        raise Fail(unknown_names(module, rest) or f"--set: {err.args[0]}") from None
    except ValueError as err:
        given = " ".join(f"{k}={v}" for k, v in rest.items())
        raise Fail(f"--set {given}: {err}" if given else f"{scene_arg}: {err}") from None


def unknown_names(module, names, flag: str = "--set") -> str:
    """The line for ``flag`` naming a parameter the model does not take: the name, the
    nearest it does take, and what it takes in short (the per-mesh forms once, the
    model's own parameters by count); "" when every name is known."""
    from gearsym.derive.input.open_values import OPEN_VALUE_BASES
    from gearsym.derive.input.reader import nearest

    if not hasattr(module, "SCENE_PARAMETERS") or not hasattr(module, "PARAMETERS"):
        return ""
    aliases = getattr(module, "PHYSICAL_ALIASES", {})
    physical = getattr(module, "PHYSICAL", {})
    known = [*module.SCENE_PARAMETERS, *physical, *aliases, *module.PARAMETERS]
    unknown = [k for k in names if k not in known]
    if not unknown:
        return ""
    each = {m for members in aliases.values() for m in members}
    short = sorted(aliases) + sorted(k for k in physical if k not in each)
    suffixes = sorted({m.rsplit("_", 1)[1] for m in each})
    # open values are a tree model's (a model in body coordinates derives none)
    opened = [] if hasattr(module, "MESHES") else sorted(OPEN_VALUE_BASES)
    scene = ", ".join(sorted(module.SCENE_PARAMETERS))
    return (
        f"{flag} {unknown[0]}: not a parameter of {module.NAME}"
        f"{nearest(unknown[0], [*known, *opened])}; it takes "
        + (f"{scene}; " if scene else "")
        + f"in physical units {', '.join(short)}"
        + (f" (most also per mesh or gear: <name>_{'|'.join(suffixes)})" if suffixes else "")
        + f"; its {len(module.PARAMETERS)} model parameters (the audit page of `gearsym "
        "derive`)" + (f"; open values, derived anew: {', '.join(opened)}" if opened else "")
    )
