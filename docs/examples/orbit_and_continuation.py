"""Load a scene, simulate, find the periodic orbit by shooting, judge its stability by its
Floquet multipliers, and follow it in the load ratio by pseudo-arclength continuation.

Run: ``python docs/examples/orbit_and_continuation.py [OUTDIR]`` (default: a temporary
folder); writes the branch as CSV and MATLAB ``.mat`` there.
"""

import sys
import tempfile
from pathlib import Path

import gearsym


def main(out: Path) -> None:
    system = gearsym.load("reference-light", **{"lambda": 0.8})  # lambda is a Python keyword
    run = gearsym.simulate(system, transient=100, periods=20)  # the fastest method by default
    u = run.coordinate("u")  # mesh deflection in half backlashes, over the sampled window
    print(f"simulated with {run.method}: {run.status}, u in [{u.min():.3f}, {u.max():.3f}]")

    # The period-1 orbit near the end state (t_final is a whole number of forcing
    # periods, so the orbit is taken at tau = 0 mod T, shoot's default t0).
    orbit = gearsym.shoot(system, run.x_final, 1)
    fl = orbit.floquet
    print(f"period-1 orbit: residual {orbit.residual:.1e} after {orbit.iterations} Newton steps")
    print("Floquet multipliers:", ", ".join(f"{m:.4f} (|{abs(m):.4f}|)" for m in fl.multipliers))
    print(f"stable: {fl.stable}; Liouville check |log det M - int tr J| = {fl.liouville_error:.1e}")

    branch = gearsym.continue_orbit(system, "lambda", 0.8, 1.0, orbit.x0, ds=0.05)
    for value, stable, mu in zip(branch.values, branch.stable, branch.multipliers, strict=True):
        verdict = "stable" if stable else "unstable"
        print(f"  lambda = {value:.4f}: {verdict}, largest |multiplier| {max(abs(mu)):.4f}")
    for b in branch.bifurcations:  # folds, period doublings, Neimark-Sacker points located
        print(f"  {b.kind} at lambda = {b.value:.6f}")
    print(f"{len(branch.values)} points; {branch.message}")
    for suffix in (".csv", ".mat"):
        print("wrote", branch.save(out / f"branch{suffix}"))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp()))
