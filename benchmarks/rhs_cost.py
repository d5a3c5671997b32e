"""Cost of the generated batched right-hand side: flops per point and time per evaluation.

Run: ``python -m gearsym.benchmarks.rhs_cost [NAME ...]`` (from a checkout also
``python benchmarks/rhs_cost.py``); prints a Markdown table, one row per generated module.

``gs_rhs_batch(tau, n, X, P, Q, DX)`` (``derive/emit/c.py``) computes the terms that
depend on the time and on parameters shared by the whole batch once per call, before its
loop over points, when each such parameter ``k`` is declared shared at compile time
(``-DGS_SHARED_k=1``); undeclared, every point computes them.  This module measures what
that saves, for a load sweep (every parameter shared but the loads ``f_*``):

* **flops per point and evaluation**: the loop body after the C preprocessor has applied
  the defines, counted by :func:`count_flops` (binary ``+ - * /`` and library calls such
  as ``cos``; a negation, an index, a copy and a constant ``(1.0/3.0)`` cost nothing);
* **time per point and evaluation**: ``gs_rhs_batch`` on ``N_POINTS`` random states,
  compiled here with the flags of ``solver/integrate/native/build.py``;
* **the largest difference** of ``dx`` between the two builds, relative to the largest
  ``|dx_i|`` of the batch: the same expressions in the same order, so it is zero but
  where the compiler fuses a multiply-add (``-ffp-contract``) on one side only.
"""

from __future__ import annotations

import ctypes
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

N_POINTS = 400
_HARNESS = r"""
#include <stdlib.h>
/* Q of every point by gs_prep, as the engine does once per run (native_*.c). */
double *rc_prep(int n, const double *P)
{
    double *Q = malloc(sizeof(double) * GS_NQ * (n > 0 ? n : 1)), p[GS_NP], q[GS_NQ];
    for (int j = 0; j < n; ++j) {
        for (int k = 0; k < GS_NP; ++k) p[k] = P[k * n + j];
        gs_prep(p, q);
        for (int k = 0; k < GS_NQ; ++k) Q[k * n + j] = q[k];
    }
    return Q;
}
void rc_free(double *Q) { free(Q); }
/* reps evaluations at times tau, tau + dt, ... (so that none is hoisted out). */
void rc_eval(double tau, double dt, long reps, int n, const double *X, const double *P,
             const double *Q, double *DX)
{
    for (long r = 0; r < reps; ++r) gs_rhs_batch(tau + r * dt, n, X, P, Q, DX);
}
"""
_TOKEN = re.compile(
    r"(?P<num>(?:\d+\.\d*|\.\d+|\d+)(?:[eE][+-]?\d+)?)|(?P<name>[A-Za-z_]\w*)"
    r"|(?P<op>\+\+|--|<=|>=|==|!=|&&|\|\||[-+*/()<>?:;,=!{}\[\]])|(?P<space>\s+)"
)
_KEYWORDS = {"for", "if", "while", "return", "double", "int", "long", "const", "sizeof"}


def shared_defines(names, varying) -> list[str]:
    """``-DGS_SHARED_k=1`` for each parameter ``k`` of ``names`` not in ``varying``."""
    return [f"-DGS_SHARED_{k}=1" for k, name in enumerate(names) if name not in varying]


def loop_body(c_text: str, defines=(), cc: str | None = None) -> str:
    """The loop over points of ``gs_rhs_batch`` in ``c_text`` as the compiler sees it with
    ``defines`` (``cc -E``), from ``for (int j`` to its closing brace."""
    cc = cc or _compiler()
    done = subprocess.run(
        [cc, "-E", "-P", *defines, "-x", "c", "-"],
        input=c_text,
        capture_output=True,
        text=True,
        check=True,
    )
    code = done.stdout[done.stdout.index("gs_rhs_batch(") :]
    start = code.index("for (int j")
    depth = 0
    for end in range(code.index("{", start), len(code)):
        depth += {"{": 1, "}": -1}.get(code[end], 0)
        if depth == 0:
            return code[start : end + 1]
    raise ValueError("gs_rhs_batch: the loop over points has no closing brace")


def count_flops(body: str) -> dict:
    """Floating-point operations of one pass through ``body`` (C text of one point):
    ``add`` (binary + and -), ``mul``, ``div``, ``call`` (cos, sin, pow, ...), ``cmp``
    (a comparison of a piecewise law) and their sum ``flops``.  Indices ``[...]``, the copy
    of ``Q`` into ``q``, negations and constant fractions ``(1.0/3.0)`` are not counted."""
    lines = [line for line in body.splitlines()[1:] if "for (int k" not in line]
    text = "\n".join(lines)
    while re.search(r"\[[^\[\]]*\]", text):
        text = re.sub(r"\[[^\[\]]*\]", "@", text)
    text = re.sub(r"\(\d+\.\d*/\d+\.\d*\)", "1.0", text)
    counts = dict.fromkeys(("add", "mul", "div", "call", "cmp"), 0)
    prev = None  # kind of the previous token: "value" (ends an operand) or "other"
    tokens = [m for m in _TOKEN.finditer(text.replace("@", "")) if not m.group("space")]
    for i, m in enumerate(tokens):
        kind, tok = m.lastgroup, m.group()
        if kind == "name" and tok not in _KEYWORDS:
            nxt = tokens[i + 1].group() if i + 1 < len(tokens) else ""
            counts["call"] += nxt == "("
            prev = "value" if nxt != "(" else "other"
            continue
        if tok in ("+", "-") and prev == "value":
            counts["add"] += 1
        elif tok == "*":
            counts["mul"] += 1
        elif tok == "/":
            counts["div"] += 1
        elif tok in ("<", ">", "<=", ">=") and prev == "value":
            counts["cmp"] += 1
        prev = "value" if kind == "num" or tok in (")",) else "other"
    counts["flops"] = sum(counts.values())
    return counts


def _compiler() -> str:
    from gearsym.solver.integrate.native import build

    cc = build.compiler()
    if cc is None:
        raise RuntimeError("no C compiler: install gcc or clang, or set GEARSYM_CC")
    return cc


def compile_rhs(c_text: str, defines=(), folder: Path | None = None) -> ctypes.CDLL:
    """A library of ``c_text`` (a model's ``C_SOURCE``) with ``rc_prep``/``rc_eval``,
    built with the flags of the engine (``build.flags``) and ``defines``."""
    from gearsym.solver.integrate.native import build

    folder = Path(folder or tempfile.mkdtemp(prefix="gearsym-rhs-"))
    c_file, so = folder / f"rhs{len(defines)}.c", folder / f"rhs{len(defines)}.so"
    c_file.write_text("#include <math.h>\n" + c_text + _HARNESS, encoding="utf-8")
    cc = _compiler()
    cmd = [cc, *build.flags(cc), *defines, "-o", str(so), str(c_file), "-lm"]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    lib = ctypes.CDLL(str(so))
    ptr = np.ctypeslib.ndpointer(np.float64, flags="C")
    d, i, ll = ctypes.c_double, ctypes.c_int, ctypes.c_long
    lib.rc_prep.restype = ctypes.c_void_p
    lib.rc_prep.argtypes = [i, ptr]
    lib.rc_free.argtypes = [ctypes.c_void_p]
    lib.rc_eval.argtypes = [d, d, ll, i, ptr, ptr, ctypes.c_void_p, ptr]
    return lib


def evaluate(lib, tau: float, X: np.ndarray, P: np.ndarray, reps: int = 1, dt: float = 0.0):
    """``dx`` of the batch ``X`` (states x points) with parameters ``P`` (parameters x
    points) at ``tau + (reps - 1) dt``, and the seconds the ``reps`` evaluations took."""
    X, P = np.ascontiguousarray(X, float), np.ascontiguousarray(P, float)
    out = np.empty_like(X)
    Q = lib.rc_prep(X.shape[1], P)
    try:
        started = time.perf_counter()
        lib.rc_eval(tau, dt, reps, X.shape[1], X, P, Q, out)
        took = time.perf_counter() - started
    finally:
        lib.rc_free(Q)
    return out, took


def module_cost(module, reps: int = 20_000, seed: int = 0) -> dict:
    """Flops, time per point and evaluation, and the largest relative difference of
    ``dx``, for ``module``'s batched right-hand side without and with the parameters of
    a load sweep (all but ``f_*``) declared shared."""
    names = module.PARAMETERS
    varying = [n for n in names if n.startswith("f_")]
    shared = shared_defines(names, varying)
    rng = np.random.default_rng(seed)
    n = N_POINTS
    X = rng.uniform(-1.0, 1.0, (len(module.STATES), n))
    P = np.repeat(np.asarray(module.DEFAULTS, float)[:, None], n, axis=1)
    P[[names.index(v) for v in varying]] *= rng.uniform(0.5, 1.5, (len(varying), n))
    row = {"name": module.NAME, "shared": f"{len(shared)}/{len(names)}"}
    taus = rng.uniform(0.0, 200.0, 20)
    with tempfile.TemporaryDirectory(prefix="gearsym-rhs-") as tmp:
        results = {}
        for label, defines in (("varying", ()), ("shared", shared)):
            row[f"flops_{label}"] = count_flops(loop_body(module.C_SOURCE, defines))["flops"]
            lib = compile_rhs(module.C_SOURCE, defines, Path(tmp))
            _, took = evaluate(lib, 0.3, X, P, reps, 1e-3)
            row[f"ns_per_point_{label}"] = 1e9 * took / (reps * n)
            results[label] = np.array([evaluate(lib, t, X, P)[0] for t in taus])
    scale = np.max(np.abs(results["varying"]), axis=(0, 2), keepdims=True)
    diff = np.abs(results["varying"] - results["shared"]) / np.where(scale > 0, scale, 1.0)
    row["max_rel_diff"] = float(diff.max())
    row["bit_identical"] = bool(np.array_equal(results["varying"], results["shared"]))
    return row


def table(rows: list[dict]) -> list[str]:
    """Markdown lines of :func:`module_cost` rows."""
    out = [
        f"Batched right-hand side `gs_rhs_batch`, {N_POINTS} points, flops per point and "
        "evaluation (loop body after the preprocessor) and time per point and evaluation; "
        "load sweep: every parameter but the loads `f_*` declared shared (`-DGS_SHARED_k=1`).",
        "",
        "| model | shared | flops, none shared | flops, shared | ns, none shared | "
        "ns, shared | largest difference of dx |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        same = "0 (bit-identical)" if r["bit_identical"] else f"{r['max_rel_diff']:.1e}"
        out.append(
            f"| {r['name']} | {r['shared']} | {r['flops_varying']} | {r['flops_shared']} | "
            f"{r['ns_per_point_varying']:.2f} | {r['ns_per_point_shared']:.2f} | {same} |"
        )
    return out


def main(argv: list[str] | None = None) -> int:
    from gearsym.derive.build import shipped_targets
    from gearsym.solver import load_generated

    argv = sys.argv[1:] if argv is None else argv
    names = argv or [t.stem.replace("-", "_") for t in shipped_targets()]
    rows = [module_cost(load_generated(name)) for name in sorted(names)]
    print("\n".join(table(rows)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
