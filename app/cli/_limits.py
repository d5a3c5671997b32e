"""The limits of the periodic-orbit commands (``shoot``, ``continue``,
``frequency-response``): sizes past which a run would take hours, stated in ``--help`` and
refused in one line (issue 23, bounded work)."""

from __future__ import annotations

from ._common import Fail, at_most

__all__ = ["MAX_PERIOD", "MAX_SEGMENTS", "MAX_SETTLED", "MAX_TRIES", "MIN_STEP", "bounded_shoot"]

MAX_PERIOD = 64  # subharmonics beyond period 64 are not resolved by 15 harmonics anyway
MAX_SEGMENTS = 256
MAX_TRIES = 100
MAX_SETTLED = 200_000  # periods T settled for the guesses in all: settle x n x (tries + 1)
MIN_STEP = 1e-5  # continue_orbit's smallest step: a smaller first step ends the branch


def bounded_shoot(args) -> None:
    """Refuse a size that would make ``shoot`` run for hours (the limits above)."""
    at_most(
        ("--period", args.period, MAX_PERIOD),
        ("--segments", args.segments, MAX_SEGMENTS),
        ("--tries", args.tries, MAX_TRIES),
    )
    settle = 300 if args.settle is None else args.settle
    tries = args.tries if args.period > 1 else 0
    total = settle * args.period + tries * max(settle, 300) * args.period
    if total > MAX_SETTLED:
        raise Fail(
            f"--settle {settle} with --period {args.period} and --tries {tries} settles "
            f"up to {total:,} periods T, more than {MAX_SETTLED:,}; lower --settle or "
            "--tries"
        )
