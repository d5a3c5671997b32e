"""Where a result came from: the header block every result file carries.

One function makes it for every result type and every command, so that a JSON, CSV or
MATLAB file says the same things in the same words: the gearsym version, the model's
name and hash, the scales back to SI (``System.scales()``), the user's values
(``System.values``), and, where the result has them, the initial state and the command.
"""

from __future__ import annotations

__all__ = ["KEYS", "header", "provenance"]

# The header keys, in the order files write them (CSV: leading "# key: value" lines).
KEYS = (
    "gearsym_version",
    "model",
    "model_hash",
    "scales",
    "overrides",
    "initial_state",
    "command",
)


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("gearsym")
    except PackageNotFoundError:  # a checkout run without installing
        return "unknown"


def header(model: str, model_hash: str, scales: dict, overrides: dict, **extra) -> dict:
    """The header block from its parts (for results that keep them without a System);
    ``extra`` may add ``initial_state`` and ``command`` (None values are left out)."""
    out = {
        "gearsym_version": _version(),
        "model": model,
        "model_hash": model_hash,
        "scales": dict(scales),
        "overrides": {k: float(v) for k, v in overrides.items()},
    }
    return out | {k: v for k, v in extra.items() if v is not None}


def provenance(system, **extra) -> dict:
    """The header block of a result of ``system`` (a :class:`~.system.System`)."""
    return header(system.name, system.model_hash, system.scales(), system.values, **extra)
