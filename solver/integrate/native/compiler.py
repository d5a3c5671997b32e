"""The C compiler the native libraries are built with, and its flags.

``compiler()`` finds it (``$GEARSYM_CC``, else cc, gcc or clang); ``_compiler_id`` names
it and the CPU for the libraries' cache keys; the flags are measured choices, each said
where it is set.
"""

from __future__ import annotations

import functools
import os
import platform
import shutil
import subprocess
from pathlib import Path

from ...contract import Contract

__all__ = ["compiler", "flags", "level"]

# Every library: -O2 and this CPU's instructions; a smooth model's and a large
# monodromy's at -O3 (below), which override the -O2
_FLAGS = (
    "-O2",
    "-march=native",
    "-fno-math-errno",
    "-fPIC",
    "-shared",
    "-Werror=implicit-function-declaration",
)
# The monodromy library at -O3: its J W and stage sums over n + n^2 components vectorise
# there (-O2's cost model leaves loops whose length is not a multiple of the vector
# width scalar): the three-planet set's one-period monodromy at rtol 1e-12 in 12.5 ms
# against 18.2 ms (and 33 ms as n copies of the state); one library per model.  A small
# model's loops are too short to gain from it (the DI-SO's 4 states) and -O3 compiles
# in 0.94 s against 0.53 s: only from 12 states on
_MONODROMY_FLAGS = ("-O3",)
# A smooth model's batch libraries at -O3 too: the lockstep loops over a group's points
# (gs_rhs_batch, the stage sums) vectorise there and stay scalar at -O2, whose cost model
# leaves them.  Measured on 2 cores, 40-point sweeps of 200 + 100 periods, medians of 3
# alternating runs: the DI-SO on bearings (22 states) 16.3 -> 4.5 ms a point, the
# two-stage train (30) 73 -> 20, for a compile of about 1.5 s against 0.7 s; the
# torsional DI-SO (4 states) with the model's one library (``engine.batch_shared``)
# 2.62 -> 1.05 ms, 4.03 -> 2.25 with the exponent's tangent.  (When every batch had a
# library of its own, -O3 for the small models' libraries cost a first reproduce more
# compiling than it saved: 218 and 213 s against 203 and 197 s.)  A small model's
# one-point library (a sweep's runs) gains nothing (6.8 against 7.1 ms for 300 periods):
# -O2, as is a piecewise model's (the dead zone runs its points one at a time).
_SMOOTH_FLAGS = ("-O3",)
_MONODROMY_O3_FROM = 12


def compiler() -> str | None:
    """The C compiler to use: ``$GEARSYM_CC`` if set (``none`` disables), else cc/gcc/clang.
    Looked up once per value of ``GEARSYM_CC`` in a process (every run asks: a PATH search
    per run was a second of a full reproduce)."""
    return _compiler(os.environ.get("GEARSYM_CC"))


@functools.lru_cache(maxsize=8)
def _compiler(env: str | None) -> str | None:
    if env is not None:
        if env.strip().lower() in ("", "none", "0"):
            return None
        return shutil.which(env) or (env if Path(env).exists() else None)
    for name in ("cc", "gcc", "clang"):
        found = shutil.which(name)
        if found:
            return found
    return None


def _no_compiler() -> str:
    """Why there is no compiler, naming GEARSYM_CC when it is set."""
    env = os.environ.get("GEARSYM_CC")
    if env is None:
        return "no C compiler found (install gcc or clang, or set GEARSYM_CC)"
    if env.strip().lower() in ("", "none", "0"):
        return f"GEARSYM_CC={env!r} turns the C compiler off"
    return (
        f"GEARSYM_CC={env!r} is not a program on PATH nor a file; set it to a C compiler "
        "(gcc, clang, or its path), or to none"
    )


@functools.lru_cache(maxsize=8)
def _compiler_id(cc: str) -> str:
    """The compiler's version line and this CPU's identity: the libraries are built with
    -march=native, so a cache shared between machines (a cluster's home) keeps one per CPU."""
    try:
        out = subprocess.run([cc, "--version"], capture_output=True, text=True, timeout=30)
        version = out.stdout.splitlines()[0] if out.stdout else cc
    except (OSError, subprocess.SubprocessError):
        version = cc
    cpu = platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as fh:
            for line in fh:
                if line.startswith(("flags", "Features", "model name")):
                    cpu += "|" + line.strip()
    except OSError:
        cpu += "|" + platform.processor()
    return version + "|" + cpu


def flags(cc: str) -> tuple[str, ...]:
    """The flags ``cc`` builds every library with (a library's own, such as -O3 for a
    smooth model, come after and override)."""
    return _FLAGS


def level(module, variational: bool | str = False, shared=()) -> tuple[str, ...]:
    """The optimisation flag of ``library(module, variational, shared)`` beyond
    ``flags``' -O2 (the comments above say what each choice measured): -O3 for a
    large model's monodromy library, and for a smooth model's libraries of batches
    (its one-point library only from 12 states on); none for a piecewise model."""
    n_states = len(module.CONTRACT["states"])
    if variational == "monodromy":
        return _MONODROMY_FLAGS if n_states >= _MONODROMY_O3_FROM else ()
    if Contract.of(module).piecewise:
        return ()
    one_point = len(set(shared)) == len(module.CONTRACT["parameters"])
    return _SMOOTH_FLAGS if n_states >= _MONODROMY_O3_FROM or not one_point else ()
