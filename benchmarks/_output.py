"""Where the benchmarks write: an output folder or the checkout's ``docs/``.

A benchmark runs for minutes, so the folder is checked before it starts: created if
missing, then a probe file is written and removed. Failures are one line
(:class:`OutputError`); ``gearsym bench`` turns them into its own one-line error, and
:func:`run_script` prints them for ``python benchmarks/<name>.py``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

__all__ = ["OutputError", "checkout_docs", "output_folder", "run_script"]


class OutputError(Exception):
    """The output folder is missing, not a folder or not writable (one line)."""


def checkout_docs() -> Path:
    """The checkout's ``docs/`` folder; :class:`OutputError` outside a checkout.

    ``docs/`` is not installed with the package: it is there only when gearsym is
    installed editable from a clone (``pip install -e .``).
    """
    from gearsym.derive.build import project_root

    docs = project_root() / "docs"
    if not docs.is_dir():
        raise OutputError(
            f"no docs/ folder at {project_root()}: writing docs needs gearsym installed from "
            "a clone with `pip install -e .`"
        )
    return docs


def output_folder(folder: Path | str, names: tuple[str, ...] = ()) -> Path:
    """``folder``, created if missing, after checking that files can be written there.

    ``names`` are the files the benchmark will write; any that already exist must be
    writable too. Raises :class:`OutputError` naming the folder otherwise.
    """
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise OutputError(f"{folder} exists and is not a folder") from None
    except OSError as err:
        raise OutputError(f"cannot create the output folder {folder}: {err.strerror}") from None
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
        for name in names:
            if (folder / name).exists():
                with open(folder / name, "a", encoding="utf-8"):
                    pass
    except OSError as err:
        raise OutputError(f"cannot write to the output folder {folder}: {err.strerror}") from None
    return folder


def run_script(main) -> None:
    """Run ``main()`` as a script: an :class:`OutputError` prints one line and exits 2."""
    try:
        code = main()
    except OutputError as err:
        print(f"{Path(sys.argv[0]).name}: error: {err}", file=sys.stderr)
        sys.exit(2)
    sys.exit(code or 0)
