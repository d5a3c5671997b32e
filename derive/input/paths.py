"""Where the checkout is, and paths as the generated files and pages print them.

Shared by ``build`` (banners, ``describe``) and ``audit`` (page headers); it imports
nothing from the package, so both can use it without importing each other.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["display_path", "project_root"]


def project_root() -> Path:
    """The folder holding ``derive/``, ``generated/`` and ``docs/`` (the checkout)."""
    return Path(__file__).resolve().parents[2]


def display_path(path: Path | str) -> str:
    """``path`` relative to the project root when inside it, else as given."""
    p = Path(path).resolve()
    try:
        return p.relative_to(project_root()).as_posix()
    except ValueError:
        return str(path)
