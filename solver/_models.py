"""Access to generated model modules."""

from __future__ import annotations

import importlib
import importlib.util
from pathlib import Path
from types import ModuleType

_REQUIRED = ("STATES", "PARAMETERS", "DEFAULTS", "rhs", "jacobian", "casadi_functions")


def load_generated(name_or_path: str | Path) -> ModuleType:
    """Import ``generated/<name>.py`` by model name, or a generated file by path."""
    path = Path(name_or_path)
    if path.suffix == ".py":
        if not path.exists():
            raise FileNotFoundError(f"{path}: no such generated model file")
        spec = importlib.util.spec_from_file_location(f"gearsym_generated_{path.stem}", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    else:
        try:
            module = importlib.import_module(f"gearsym.generated.{name_or_path}")
        except ModuleNotFoundError:
            raise FileNotFoundError(
                f"no generated model '{name_or_path}'; run `gearsym derive` on its scene"
            ) from None
    missing = [k for k in _REQUIRED if not hasattr(module, k)]
    if missing:
        raise ValueError(f"{module.__name__} is not a gearsym model (lacks {', '.join(missing)})")
    return module
