"""The 400-point load-ratio sweep by the generated engine and by its peers, in one run.

Run: ``python -m gearsym.benchmarks.peers [--quick] [--json]`` (from a checkout also
``python benchmarks/peers.py``); prints a Markdown table.  JAX and diffrax are optional:
without them their row says why it is missing.  To measure it, use a separate environment
with the project installed too, e.g. ``python -m venv /tmp/jaxenv &&
/tmp/jaxenv/bin/pip install jax diffrax -e .``.

The sweep is the headline of ``performance.py``: ``reference_light``, 400 values of
``lambda`` on [0, 1] (only the loads ``f_u``, ``f_v`` differ between points), 300
transient + 100 sampled periods, rtol 1e-8, atol 1e-10, DOP853-class methods:

* (a) the generated engine, ``run_batch(..., method="dop853")``, one core, as
  ``solver/integrate/native/build.py`` builds it (since the library rule of
  ``engine.batch_shared``: the model's one library at -O3, no parameter compiled in);
  (a-) the same with no parameter declared shared (every point computes every term)
  and (a+) with ``-DGS_SHARED_k=1`` for the 30
  parameters but the loads, so that ``gs_rhs_batch`` computes the stiffness and
  transmission-error terms once per evaluation for the batch (:class:`WrappedBuild`);
* (b) the hand-written vectorised lockstep DOP853 of ``lockstep_reference.c``;
* (c) JAX + diffrax, ``Dopri8`` on the whole batch as one system of 4 x 400 states, the
  right-hand side written in ``jax.numpy`` (checked against the generated one), the same
  tolerances and the lockstep's error norm (Hairer's norm per point, the largest over the
  points decides), samples by diffrax's dense output; compiled (``jax.jit``) before timing;
  (c') the same at tolerances ten times tighter: Dopri8's error estimate lets through a
  larger error than DOP853's at equal tolerances, so this is the row of equal accuracy.

Accuracy, the same for every row: the largest difference of the Poincaré points (the state
at the start of each of the 100 sampled periods) from CVODES (BDF) at rtol 1e-13 on six
points spread over the sweep (two with ``--quick``), as in ``performance.py``.  Times:
the median of 5 repeats (3 with ``--quick``), the rows interleaved.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shlex
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

# absolute, so that ``python benchmarks/peers.py`` runs too
from gearsym.benchmarks import baseline, rhs_cost

TRANSIENT, PERIODS, RTOL, ATOL = 300, 100, 1e-8, 1e-10


def tight_reference(module, P, X0, subset) -> np.ndarray:
    """Poincaré points (len(subset), PERIODS, 4) by CVODES at rtol 1e-13, atol 1e-15."""
    return baseline.tight_reference(module, P, X0, subset, TRANSIENT, PERIODS)


class WrappedBuild:
    """The engine built by a wrapper of the C compiler, given as ``GEARSYM_CC`` while
    :meth:`active`, with a cache root of its own (the library's cache key does not see
    the flags): ``defines`` added, and with ``strip`` every ``-DGS_SHARED_k`` that
    ``build.py`` passes removed (no parameter declared shared: every point computes every
    term, as before issue 24).  ``calls()``: the compiler calls (the wrapper logs each)."""

    def __init__(self, folder: Path, defines=(), strip: bool = False):
        from gearsym.solver.integrate.native import build

        cc = build.compiler()
        if cc is None:
            raise RuntimeError("no C compiler: install gcc or clang, or set GEARSYM_CC")
        folder.mkdir(parents=True, exist_ok=True)
        self.log, wrapper = folder / "calls.log", folder / "cc"
        keep = '-DGS_SHARED_*) ;; *) set -- "$@" "$a" ;;' if strip else '*) set -- "$@" "$a" ;;'
        wrapper.write_text(
            f'#!/bin/sh\necho "$@" >> {shlex.quote(str(self.log))}\n'
            f'for a in "$@"; do shift; case "$a" in {keep} esac; done\n'
            f'exec {shlex.quote(cc)} {" ".join(defines)} "$@"\n',
            encoding="utf-8",
        )
        wrapper.chmod(0o755)
        self.env = {"GEARSYM_CC": str(wrapper), "GEARSYM_CACHE": str(folder / "cache")}

    @contextlib.contextmanager
    def active(self):
        saved = {k: os.environ.get(k) for k in self.env}
        os.environ.update(self.env)
        try:
            yield
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v

    def calls(self) -> int:
        return len(self.log.read_text().splitlines()) if self.log.exists() else 0


def _engine(module, P, X0, build: WrappedBuild | None = None):
    """A run of the generated engine: ``() -> (x, evaluations per point, facts)``."""
    from gearsym.solver.integrate.native import run_batch

    scope = build.active if build is not None else contextlib.nullcontext

    def go():
        with scope():
            res = run_batch(
                module,
                P,
                X0,
                method="dop853",
                transient=TRANSIENT,
                periods=PERIODS,
                rtol=RTOL,
                atol=ATOL,
            )
        facts = {"compiler_calls": build.calls()} if build is not None else {}
        return res.x, float(np.median(res.nfev)), facts

    with scope():
        run_batch(module, P[:2], X0[:2], transient=1, periods=1)  # compiled outside the timing
    return go


def _reference(module, P, X0):
    """A run of ``lockstep_reference.c``, or why there is none."""
    lib = baseline._reference_library()
    if lib is None:
        return "no C compiler"

    def go():
        x, nfev = baseline.reference_run(lib, module, P, X0, TRANSIENT, PERIODS, RTOL, ATOL)
        return x, float(nfev), {}

    return go


def jax_rhs(module, P):
    """The right-hand side of ``reference_light`` in ``jax.numpy`` for the batch ``P``
    (points x parameters; only ``f_u``, ``f_v`` may differ): ``f(t, y, args)`` with ``y``
    of shape (4, points), the equations of ``baseline.plain_rhs``."""
    import jax.numpy as jnp

    q = baseline._named(module, P[0])
    idx = module.PARAMETERS.index
    fu, fv = jnp.asarray(P[:, idx("f_u")]), jnp.asarray(P[:, idx("f_v")])
    w, phi = q["omega"], q["phi_v"]
    a_u = [q[f"kc_u_{h}"] for h in (1, 2, 3)]
    b_u = [q[f"ks_u_{h}"] for h in (1, 2, 3)]
    a_v = [q[f"kc_v_{h}"] for h in (1, 2, 3)]
    b_v = [q[f"ks_v_{h}"] for h in (1, 2, 3)]
    g1, g3, g5, g7 = q["g1"], q["g3"], q["g5"], q["g7"]

    def f(t, y, args):
        u, v, du, dv = y
        ku, kv = 1.0, 1.0
        for h in (1, 2, 3):
            ku = ku + a_u[h - 1] * jnp.cos(h * w * t) + b_u[h - 1] * jnp.sin(h * w * t)
            kv = (
                kv
                + a_v[h - 1] * jnp.cos(h * (w * t - phi))
                + b_v[h - 1] * jnp.sin(h * (w * t - phi))
            )
        eu = -q["E_u_1"] * w**2 * jnp.cos(w * t + q["psi_u_1"])
        ev = -q["E_v_1"] * w**2 * jnp.cos(w * t - phi + q["psi_v_1"])
        gu = ku * u * (g1 + u * u * (g3 + u * u * (g5 + u * u * g7)))
        gv = kv * v * (g1 + v * v * (g3 + v * v * (g5 + v * v * g7)))
        ddu = (
            fu
            + eu
            - 2 * (q["xi_u_u"] * du + q["xi_u_v"] * dv)
            - q["kappa_u_u"] * gu
            - q["kappa_u_v"] * gv
        )
        ddv = (
            fv
            + ev
            - 2 * (q["xi_v_u"] * du + q["xi_v_v"] * dv)
            - q["kappa_v_u"] * gu
            - q["kappa_v_v"] * gv
        )
        return jnp.stack([du, dv, ddu, ddv])

    return f


def _jax(module, P, X0, rtol: float = RTOL, atol: float = ATOL):
    """A run of JAX + diffrax (compiled here, outside the timing), or why there is none."""
    try:
        import diffrax
        import jax
        import jax.numpy as jnp
    except ImportError as err:
        return f"JAX + diffrax not importable here ({err}); pip install jax diffrax"
    jax.config.update("jax_enable_x64", True)
    f = jax_rhs(module, P)
    rng = np.random.default_rng(0)
    y, t = rng.uniform(-1, 1, (4, len(P))), 3.7
    want = module.rhs(t, y, P.T)
    got = np.asarray(f(t, jnp.asarray(y), None))
    if not np.allclose(got, want, rtol=1e-12, atol=1e-12):
        raise AssertionError("the jax.numpy right-hand side differs from the generated one")
    T = 2 * np.pi / P[0, module.PARAMETERS.index("omega")]
    ts = jnp.asarray((TRANSIENT + np.arange(PERIODS + 1)) * T)
    n = len(P)

    def point_norm(e):  # Hairer's norm per point, the largest over the points
        return jnp.max(jnp.sqrt(jnp.mean(jnp.reshape(e, (4, n)) ** 2, axis=0)))

    controller = diffrax.PIDController(rtol=rtol, atol=atol, norm=point_norm)

    @jax.jit
    def solve(y0):
        return diffrax.diffeqsolve(
            diffrax.ODETerm(f),
            diffrax.Dopri8(),
            t0=0.0,
            t1=ts[-1],
            dt0=None,
            y0=y0,
            saveat=diffrax.SaveAt(ts=ts),
            stepsize_controller=controller,
            max_steps=2**21,
        )

    y0 = jnp.asarray(X0.T)
    started = time.perf_counter()
    jax.block_until_ready(solve(y0))
    facts = {
        "compile_s": time.perf_counter() - started,
        "versions": f"jax {jax.__version__}, diffrax {diffrax.__version__}",
    }

    def go():
        sol = jax.block_until_ready(solve(y0))
        steps = int(sol.stats["num_steps"])
        x = np.transpose(np.asarray(sol.ys), (2, 0, 1))
        return x, float(13 * steps), {**facts, "steps": steps}  # Dopri8: 14 stages, FSAL

    return go


def run(quick: bool) -> dict:
    """Every row of the table, measured in this one process, the runs interleaved (each
    repeat runs every row once) so that the machine's load falls on all rows alike."""
    module, lam, P, X0 = baseline._reference()
    varying = ["f_u", "f_v"]
    shared = rhs_cost.shared_defines(module.PARAMETERS, varying)
    for k, name in enumerate(module.PARAMETERS):
        if name not in varying and not np.all(P[:, k] == P[0, k]):
            raise AssertionError(f"parameter {name} differs between the points of the sweep")
    subset = np.linspace(0, len(lam) - 1, 2 if quick else 6).round().astype(int)
    tight = tight_reference(module, P, X0, subset)
    with tempfile.TemporaryDirectory(prefix="gearsym-peers-") as tmp:
        runs = {
            "engine_unshared": _engine(module, P, X0, WrappedBuild(Path(tmp, "u"), strip=True)),
            "engine": _engine(module, P, X0),
            "engine_shared": _engine(module, P, X0, WrappedBuild(Path(tmp, "s"), shared)),
            "reference_c": _reference(module, P, X0),
            "jax_diffrax": _jax(module, P, X0),
            "jax_diffrax_tight": _jax(module, P, X0, RTOL / 10, ATOL / 10),
        }
        rows = {k: {"skipped": go} for k, go in runs.items() if isinstance(go, str)}
        times = {k: [] for k in runs if k not in rows}
        for _ in range(3 if quick else 5):
            for key in times:
                started = time.perf_counter()
                x, nfev, facts = runs[key]()
                times[key].append(time.perf_counter() - started)
                error = float(np.max(np.abs(x[subset, :-1] - tight)))
                rows[key] = {"nfev_per_point": nfev, "max_poincare_error": error, **facts}
    for key, t in times.items():
        rows[key].update(s=statistics.median(t), runs_s=t)
    cost = rhs_cost.module_cost(module, reps=2_000 if quick else 20_000)
    return {
        "points": len(lam),
        "subset": subset.tolist(),
        "rows": rows,
        "rhs": cost,
        "date": time.strftime("%Y-%m-%d"),
        "cpus": os.cpu_count(),
        "load_average": os.getloadavg()[0],
    }


LABELS = {
    "engine_unshared": "(a-) generated engine, batched DOP853, 1 core, no parameter declared "
    "shared (every point computes every term)",
    "engine": "(a) the same as `build.py` builds it (its own `-DGS_SHARED_k=1`, if any)",
    "engine_shared": "(a+) the same with `-DGS_SHARED_k=1` for at least the 30 parameters "
    "but the loads",
    "reference_c": "(b) hand-written vectorised lockstep DOP853 in C (`lockstep_reference.c`)",
    "jax_diffrax": "(c) JAX + diffrax `Dopri8`, the batch as one system, `jax.jit`",
    "jax_diffrax_tight": "(c') the same at rtol 1e-9, atol 1e-11 (its error near (a)'s)",
}


def lines(res: dict) -> list[str]:
    """The Markdown table of :func:`run`."""
    rows, cost = res["rows"], res["rhs"]
    out = [
        f"## Peers: the {res['points']}-point load-ratio sweep",
        "",
        f"`reference_light`, {TRANSIENT} transient + {PERIODS} sampled periods, rtol {RTOL:g}, "
        f"atol {ATOL:g}, measured in one run on {res['cpus']} cores ({res['date']}; load average "
        f"{res['load_average']:.1f}), each time the median of repeats interleaved. Error: the "
        "largest difference of the Poincaré points from CVODES (BDF) at rtol 1e-13 on "
        f"{len(res['subset'])} points spread over the sweep.",
        "",
        "| run | time for the sweep (s) | evaluations per point | max Poincaré error |",
        "|---|---|---|---|",
    ]
    for key, label in LABELS.items():
        r = rows[key]
        if "skipped" in r:
            out.append(f"| {label} | skipped: {r['skipped']} | | |")
            continue
        out.append(
            f"| {label} | {baseline._fmt(r['s'])} | {r['nfev_per_point']:.0f} | "
            f"{r['max_poincare_error']:.2g} |"
        )
    jx = rows["jax_diffrax"]
    calls = [f"{k}: {rows[k]['compiler_calls']}" for k in ("engine_unshared", "engine_shared")]
    out += ["", f"Compiler calls through the wrappers of (a-) and (a+): {', '.join(calls)}."]
    if "skipped" not in jx:
        out += [
            "",
            f"JAX: {jx['versions']}; compilation {jx['compile_s']:.1f} s (not in the "
            f"time); {jx['steps']} steps of 13 evaluations.",
        ]
    out += [
        "",
        f"Batched right-hand side of {cost['name']} alone: {cost['flops_varying']} flops per "
        f"point and evaluation with no parameter declared shared, {cost['flops_shared']} with "
        f"the {cost['shared']} shared ({cost['ns_per_point_varying']:.2f} and "
        f"{cost['ns_per_point_shared']:.2f} ns per point and evaluation); the hand-written "
        f"reference spends 38 flops. Largest difference of dx between the two builds, relative "
        f"to the largest |dx_i|: {cost['max_rel_diff']:.1e}.",
        "",
    ]
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer accuracy points, repeats")
    parser.add_argument("--json", action="store_true", help="also print the figures as JSON")
    args = parser.parse_args(argv)
    res = run(args.quick)
    print("\n".join(lines(res)))
    if args.json:
        print(json.dumps(res, indent=2, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
