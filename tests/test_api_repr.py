"""An API that fits a notebook (issue 25, point 6): every analysis the CLI runs is a name of
``gearsym`` (listed in ``__all__``, resolved lazily), and each result object a user meets
reads as one line (``repr``) and as a few lines (``summary()``), never as its arrays."""

import argparse
import re
import subprocess
import sys

import gearsym
import numpy as np
import pytest

# The CLI's commands and the API function behind each (``bench`` measures the package
# itself and ``stiffness`` reports on gear geometry from the derivation's internals: no
# result object of the API, so no name here).
COMMANDS = {
    "derive": "derive_model",
    "backlash": "fit_dead_zone",
    "simulate": "analyse",
    "sweep": "sweep",
    "map": "regime_map",
    "shoot": "shoot",
    "continue": "continue_orbit",
    "frequency-response": "frequency_response",
    "modes": "modes",
    "reproduce": "reproduce",
}
WITHOUT_API = {"bench", "stiffness"}


def test_every_name_of_all_resolves_and_every_export_is_listed():
    for name in gearsym.__all__:
        assert getattr(gearsym, name) is not None, name
    assert set(gearsym._EXPORTS) == set(gearsym.__all__)
    assert len(set(gearsym.__all__)) == len(gearsym.__all__)
    assert gearsym.plot.__name__ == "gearsym.plot"


def test_every_cli_command_has_its_api_function():
    from gearsym.cli import _parser

    (sub,) = [a for a in _parser()._actions if isinstance(a, argparse._SubParsersAction)]
    assert set(sub.choices) == set(COMMANDS) | WITHOUT_API
    for command, name in COMMANDS.items():
        assert name in gearsym.__all__ and callable(getattr(gearsym, name)), command


def test_import_gearsym_stays_light():
    """The names resolve on first use (PEP 562): importing the package loads none of the
    heavy libraries, so ``gearsym <command>`` pays only for what it uses."""
    code = (
        "import sys, gearsym; gearsym.__all__; "
        "print(sorted(m for m in ('matplotlib', 'sympy', 'scipy', 'casadi') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


@pytest.fixture(scope="module")
def results():
    """One of each result object, small and fast (reference-light, lambda = 0.8)."""
    system = gearsym.load("reference-light", **{"lambda": 0.8})
    point = gearsym.analyse(system, transient=60, periods=16, lyapunov_periods=20)
    sweep = gearsym.sweep(
        system, "lambda", [0.6, 0.7, 0.8], transient=40, periods=16, lyapunov_periods=0
    )
    regimes = gearsym.regime_map(
        system,
        ("lambda", [0.6, 0.8]),
        ("omega", [0.5, 0.55]),
        initial_states=1,
        transient=40,
        periods=16,
        lyapunov_periods=0,
        executor="serial",
    )
    orbit = gearsym.shoot(system, point.trajectory.x_final)
    branch = gearsym.continue_orbit(system, "lambda", 0.8, 0.9, orbit.x0)
    response = gearsym.frequency_response(system, "omega", 0.48, 0.52, points=4)
    return {
        "System": system,
        "PointResult": point,
        "Trajectory": point.trajectory,
        "SweepResult": sweep,
        "RegimeMap": regimes,
        "Orbit": orbit,
        "Branch": branch,
        "FrequencyResponse": response,
        "Modes": gearsym.modes(system),
    }


NAMES = [
    "System",
    "PointResult",
    "Trajectory",
    "SweepResult",
    "RegimeMap",
    "Orbit",
    "Branch",
    "FrequencyResponse",
    "Modes",
]


@pytest.mark.parametrize("name", NAMES)
def test_repr_is_one_short_line_and_summary_a_few(results, name):
    obj = results[name]
    assert type(obj).__name__ == name
    text = repr(obj)
    assert "\n" not in text and len(text) < 200, text
    assert text.startswith(f"{name}(") and text.endswith(")")
    # no array dumped: a handful of numbers, not the 200 Poincare values of old
    assert len(re.findall(r"\d+\.\d+", text)) <= 12, text
    assert "array(" not in text and "..." not in text
    summary = obj.summary()
    lines = summary.splitlines()
    assert 2 <= len(lines) <= 14, summary
    assert all(len(line) <= 200 for line in lines), summary
    assert "array(" not in summary


def test_summaries_say_the_evidence(results):
    """What a user reads first: the verdict with its evidence, the multipliers, the runs."""
    point = results["PointResult"].summary()
    assert "verdict: " in point and "periods run" in point
    assert re.search(r"\|Floquet multiplier\| 0\.\d+|Lyapunov exponent in \[", point)
    orbit = results["Orbit"]
    mu = np.max(np.abs(orbit.floquet.multipliers))
    assert f"max |μ| {mu:.4g}" in repr(orbit)
    assert "Liouville error" in orbit.summary()
    assert "period-1" in repr(results["SweepResult"]) and "3 points" in repr(results["SweepResult"])
    assert "lambda 0.6 to 0.8 (2) x omega 0.5 to 0.55 (2)" in repr(results["RegimeMap"])
    assert repr(results["System"]) == "System(reference_light: ω̄ = 0.5, lambda = 0.8)"


def test_plot_namespace_returns_figures_from_result_objects(results):
    """``gearsym.plot``: each function takes a result object and returns a Figure; a
    regime map gives one Figure per kind asked."""
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    r = results
    try:
        figures = [
            gearsym.plot.point(r["PointResult"]),
            gearsym.plot.point(r["Trajectory"]),
            gearsym.plot.bifurcation(r["SweepResult"]),
            gearsym.plot.branches(r["Branch"]),
            gearsym.plot.multipliers(r["Orbit"]),
            gearsym.plot.frequency_response(r["FrequencyResponse"]),
            gearsym.plot.campbell(r["Modes"]),
        ]
        maps = gearsym.plot.map(r["RegimeMap"], kinds=("motion", "lyapunov"))
        assert list(maps) == ["motion", "lyapunov"]
        for fig in [*figures, *maps.values()]:
            assert isinstance(fig, Figure) and fig.axes
        # the caption a map figure carried into its file is on the Figure itself
        assert "initial states per point" in maps["motion"].texts[-1].get_text()
        # the multipliers drawn are the orbit's
        crosses = [ln for ln in figures[4].axes[0].get_lines() if ln.get_label() == "multipliers"]
        np.testing.assert_array_equal(
            crosses[0].get_xdata(), np.asarray(r["Orbit"].floquet.multipliers).real
        )
    finally:
        plt.close("all")
