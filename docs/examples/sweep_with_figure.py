"""A bifurcation sweep of the load ratio with continuation of the state, its diagram, and
the sweep as JSON and CSV.

Run: ``python docs/examples/sweep_with_figure.py [OUTDIR]`` (default: a temporary folder).
"""

import sys
import tempfile
from pathlib import Path

import gearsym
import numpy as np


def main(out: Path) -> None:
    system = gearsym.load("reference-light")
    values = np.linspace(0.0, 1.0, 6)
    result = gearsym.sweep(system, "lambda", values, transient=100, periods=16, lyapunov_periods=50)
    for point in result.points:
        print(
            f"lambda = {point.value:.2f}: u {point.motion('u')}, v {point.motion('v')}, "
            f"min(v) = {point.min('v'):.3f}"
        )
    figure = gearsym.plot.save(
        gearsym.plot.bifurcation(result, title="lambda sweep"), out / "bifurcation.png"
    )
    print("wrote", figure, result.save(out / "sweep.json"), result.save(out / "sweep.csv"))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp()))
