"""Result files of every command: ``--format`` and one writer.

Every command that writes a result writes it under its ``--out`` folder with the name it
always had (``point``, ``sweep``, ``map``, ``orbit``, ``branches``, ``frequency_response``,
``modes``) in each format of ``--format`` (default all three: JSON, CSV and MATLAB
``.mat``), each with the header block of ``solver/provenance.py`` and the command line.
"""

from __future__ import annotations

import shlex
from pathlib import Path

from ._common import Fail

__all__ = [
    "FORMATS",
    "branches_document",
    "format_option",
    "result_formats",
    "units_option",
    "write_result",
]

FORMATS = ("json", "csv", "mat")


def format_option(parser, stem: str) -> None:
    parser.add_argument(
        "--format",
        default=",".join(FORMATS),
        metavar="LIST",
        help=f"result files written under --out: {stem}.json, {stem}.csv and/or {stem}.mat, "
        "comma-separated (default: %(default)s); each carries the gearsym version, model, "
        "model hash, scales, overrides and command (docs/user-guide.md, Result files)",
    )


def units_option(parser, physical: str) -> None:
    """``--units model|physical``; ``physical`` says what the command then gives in the
    engineer's units (``solver/units.py``)."""
    parser.add_argument(
        "--units",
        choices=("model", "physical"),
        default="model",
        help=f"physical: {physical}; model: the model's non-dimensional units "
        "(default: %(default)s)",
    )


def result_formats(args) -> tuple[str, ...]:
    """The formats of ``--format``, checked (one line naming the fix when not)."""
    text = getattr(args, "format", None) or ",".join(FORMATS)
    chosen = tuple(dict.fromkeys(f.strip().lower().lstrip(".") for f in text.split(",")))
    bad = [f for f in chosen if f not in FORMATS]
    if bad or not chosen:
        raise Fail(
            f"--format {text}: '{bad[0] if bad else ''}' is not a result format; give a "
            f"comma-separated list of {', '.join(FORMATS)}"
        )
    return chosen


def command_line(args) -> str | None:
    argv = getattr(args, "argv", None)
    return None if argv is None else shlex.join(["gearsym", *argv])


def _header_keys(args, extra: dict) -> dict:
    """The header keys a command adds to its result files: ``extra`` (those not None) and
    the command line."""
    extra = {"command": command_line(args), **extra}
    return {k: v for k, v in extra.items() if v is not None}


def write_result(out, stem: str, result, args, **extra) -> list[Path]:
    """Write ``result`` (a result type, or an ``export.Document``) as ``out/stem.<fmt>``
    for every format of ``--format``; ``extra`` adds header keys (``initial_state``)."""
    from gearsym.solver.export import save

    extra = _header_keys(args, extra)
    paths = []
    for fmt in result_formats(args):
        path = Path(out) / f"{stem}.{fmt}"
        if hasattr(result, "save"):
            paths.append(result.save(path, **extra))
        else:
            paths.append(save(result, path, **extra))
    return paths


def write_poincare(out, result, args, **extra) -> list[Path]:
    """A sweep's Poincare points as ``out/sweep_poincare.csv`` when ``--format`` has csv
    (``SweepResult.poincare_table``: one row per point and sampled period, in the model's
    units as the JSON holds them), with the header block of the sweep's files."""
    from gearsym.solver.export import save_csv
    from gearsym.solver.provenance import header

    if "csv" not in result_formats(args):
        return []
    extra = _header_keys(args, extra)
    data = header(result.model, result.model_hash, result.scales, result.base_values, **extra)
    return [save_csv(Path(out) / "sweep_poincare.csv", data, *result.poincare_table())]


def branches_document(system, branches):
    """The branches of ``continue`` as one result: the header block, the parameter, the
    state names and each branch's ``describe()`` under ``branches``; its table is the
    branches' tables one after another, with the branch's index first."""
    from gearsym.solver.export import Document
    from gearsym.solver.provenance import provenance

    columns, rows = ["branch"], []
    for k, b in enumerate(branches):
        cols, rs = b.to_table()
        columns = ["branch", *cols]
        rows += [[k, *r] for r in rs]
    data = provenance(system) | {
        "parameter": branches[0].parameter if branches else "",
        "state_names": list(system.states),
        "branches": [b.describe() for b in branches],
    }
    return Document(data, columns, rows)
