"""The System a command runs: a scene's or topology's model with its ``--set`` values, or a
planetary set's nonlinear model (``gearsym.planetary.dynamics``)."""

from __future__ import annotations

from ._common import Fail

__all__ = ["system_of"]


def system_of(scene_arg: str, sets: dict[str, float]):
    """The System of a scene (name or path) with ``--set`` values (``gearsym.resolve``),
    a polynomial backlash noted once (``_notes``); a bad scene raises its own InputError."""
    from gearsym.cli._notes import note_backlash
    from gearsym.derive.input.reader import InputError
    from gearsym.resolve import module_for, planetary_path, planetary_system, split_open_values
    from gearsym.solver.system import System

    planetary = planetary_path(scene_arg)
    if planetary is not None:  # its nonlinear model (gearsym.planetary.dynamics)
        try:
            return planetary_system(planetary, **sets)
        except KeyError as err:
            raise Fail(f"--set: {err.args[0]}") from None
        except ValueError as err:
            if isinstance(err, InputError):
                raise
            given = " ".join(f"{k}={v}" for k, v in sets.items())
            raise Fail(f"--set {given}: {err}") from None
    module = module_for(scene_arg)
    opened, rest = split_open_values(sets, module)
    module = module_for(scene_arg, opened) if opened else module
    try:
        return note_backlash(System.load(module, **rest))
    except KeyError as err:
        from gearsym.derive.input.open_values import OPEN_VALUE_BASES
        from gearsym.derive.input.reader import nearest

        unknown = [k for k in rest if k not in module.PARAMETERS]
        hint = nearest(unknown[0], OPEN_VALUE_BASES) if unknown else ""
        more = f"{hint}; open values (derived anew): {', '.join(sorted(OPEN_VALUE_BASES))}"
        raise Fail(f"--set: {err.args[0]}{more}") from None
    except ValueError as err:
        given = " ".join(f"{k}={v}" for k, v in rest.items())
        raise Fail(f"--set {given}: {err}" if given else f"{scene_arg}: {err}") from None
