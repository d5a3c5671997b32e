"""The ``gearsym`` command line.

This is the one module of ``solver/`` that also drives ``derive/``: it is the front door
of the whole pipeline.  User errors (bad files, bad values) print one line and exit 2;
``--debug`` shows the traceback instead.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

__all__ = ["main"]


class _Fail(Exception):
    """A user-facing failure: one line, exit code 2."""


def _parse_set(items: list[str]) -> dict[str, float]:
    out = {}
    for item in items or []:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise _Fail(f"--set {item}: expected key=value, for example --set lambda=0.5")
        try:
            number = float(value)
        except ValueError:
            raise _Fail(f"--set {item}: '{value}' is not a number") from None
        if not math.isfinite(number):
            raise _Fail(f"--set {item}: value must be finite")
        out[key.strip()] = number
    return out


def _cmd_derive(args) -> int:
    from gearsym.derive.build import (
        build_files,
        check,
        describe_json,
        project_root,
        shipped_targets,
        write_files,
    )
    from gearsym.derive.scene import resolve_target

    if args.check:
        if args.targets or args.set or args.out:
            raise _Fail(
                "derive --check takes no targets, --set or --out: it checks the "
                "shipped scenes and topologies"
            )
        stale = check()
        for line in stale:
            print(f"stale: {line}", file=sys.stderr)
        if stale:
            print(
                f"{len(stale)} file(s) differ from a fresh regeneration; run "
                "`gearsym derive` and commit the result",
                file=sys.stderr,
            )
            return 1
        print(
            "generated/ and docs/ match a fresh regeneration of "
            f"{len(shipped_targets())} shipped targets"
        )
        return 0

    shipped = not args.targets
    paths = shipped_targets() if shipped else [resolve_target(t) for t in args.targets]
    built = build_files(paths, index=shipped, overrides=_parse_set(args.set))
    root = Path(args.out) if args.out else project_root()
    written = [] if args.dry_run else write_files(built.files, root)
    if args.json:
        print(describe_json(built.models))
        return 0
    for model in built.models:
        _summary(model)
    if written:
        print(f"wrote {len(written)} files under {root}")
    return 0


def _summary(model) -> None:
    from gearsym.derive.build import describe, display_path

    d = describe(model)
    print(f"{model.name}  ({display_path(model.scene.source)})")
    print(f"  states: {', '.join(d['states'])}   parameters: {len(d['parameters'])}")
    print(f"  omega_n = {d['scales']['omega_n_rad_per_s']:.6g} rad/s, omega = {d['omega']:.6g}")
    print("  f: " + ", ".join(f"{c} = {v:.6g}" for c, v in d["f"].items()))
    print("  kappa (means): " + ", ".join(f"{k} = {v['mean']:.6g}" for k, v in d["kappa"].items()))
    print("  xi: " + ", ".join(f"{k} = {v:.6g}" for k, v in d["xi"].items()))
    ops = d["operations"]
    print(f"  operations: rhs {ops['rhs']}, rhs + jacobian {ops['rhs_and_jacobian']}")


def _cmd_backlash(args) -> int:
    from gearsym.derive.backlash import fit_dead_zone

    try:
        fit = fit_dead_zone(args.order, args.range, None if args.continuous else args.step)
    except ValueError as err:
        raise _Fail(f"backlash: {err}") from None
    error = fit.max_error()
    if args.json:
        print(
            json.dumps(
                {
                    "order": fit.order,
                    "range": fit.fit_range,
                    "method": "continuous" if fit.samples is None else "samples",
                    "samples": fit.samples,
                    "coefficients": {
                        str(k): c for k, c in zip(fit.powers, fit.coefficients, strict=True)
                    },
                    "valid_range": [-fit.fit_range, fit.fit_range],
                    "max_error_vs_dead_zone": error,
                    "slope_at_zero": fit.coefficients[0],
                },
                indent=2,
            )
        )
        return 0
    how = (
        "continuous L2"
        if fit.samples is None
        else f"{fit.samples} uniform samples, step {args.step:g}"
    )
    print(
        f"odd polynomial of order {fit.order}, least squares on [-{fit.fit_range:g}, "
        f"{fit.fit_range:g}] ({how})"
    )
    for k, c in zip(fit.powers, fit.coefficients, strict=True):
        print(f"  x^{k:<2d} {c: .10f}")
    print(f"valid for |x| <= {fit.fit_range:g}; max |g - dead zone| = {error:.4g}")
    if fit.coefficients[0] < 0:
        print("note: negative slope at x = 0, so the origin of an unloaded mesh is unstable")
    return 0


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="gearsym", description="Gear-train nonlinear dynamics: derive, generate code, analyse."
    )
    parser.add_argument(
        "--debug", action="store_true", help="show full tracebacks instead of one-line errors"
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    d = sub.add_parser(
        "derive",
        help="derive models; write generated/ and docs/",
        description="Derive the non-dimensional model of scenes or "
        "topologies, write generated/<name>.py and docs/derivation/<name>.md. "
        "Without targets: every shipped scene and topology, and "
        "docs/derivation.md.",
    )
    d.add_argument(
        "targets",
        nargs="*",
        metavar="SCENE_OR_TOPOLOGY",
        help="a .toml path or the name of a built-in scene or topology",
    )
    d.add_argument(
        "--json",
        action="store_true",
        help="print every number of the non-dimensional equations as JSON",
    )
    d.add_argument(
        "--check",
        action="store_true",
        help="exit 1, naming the files, if generated/ or docs/ are stale",
    )
    d.add_argument("--out", metavar="DIR", help="write under DIR instead of the project")
    d.add_argument(
        "--set",
        action="append",
        metavar="KEY=VALUE",
        help="override a scene parameter (repeatable)",
    )
    d.add_argument("--dry-run", action="store_true", help="derive but write nothing")
    d.set_defaults(func=_cmd_derive)

    b = sub.add_parser(
        "backlash",
        help="odd-polynomial least-squares fit of the dead zone",
        description="Fit an odd polynomial to the unit dead zone by least "
        "squares; with the defaults it reproduces the reference study's "
        "7th-order coefficients.",
    )
    b.add_argument("--order", type=int, default=7, help="odd order (default 7)")
    b.add_argument(
        "--range", type=float, default=3.0, metavar="A", help="fit on [-A, A] (default 3)"
    )
    b.add_argument(
        "--step", type=float, default=0.01, help="spacing of the uniform samples (default 0.01)"
    )
    b.add_argument("--continuous", action="store_true", help="continuous L2 fit instead of samples")
    b.add_argument("--json", action="store_true", help="print JSON")
    b.set_defaults(func=_cmd_backlash)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if args.debug:
        return args.func(args)
    from gearsym.derive import InputError

    try:
        return args.func(args)
    except (InputError, _Fail) as err:
        print(f"gearsym: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("gearsym: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
