"""Figures a reader can trust (issue 27, point 7): one colour per meaning across figures,
markers of at least 3 px, both sweeps visible, legends outside the axes, the operating
point and the verdict in the title of a one-point figure, spectra unfloored and whole to
the sixth harmonic, runs that left the valid range shown in every map.

The figure functions return the Figure (nothing saved); the tests read its artists."""

from dataclasses import replace

import matplotlib.colors as mcolors
import matplotlib.pyplot as plt
import numpy as np
import pytest
from gearsym.solver import plots, plots_maps
from gearsym.solver.analysis import analyse_point
from gearsym.solver.periodic.records import Bifurcation, Branch, BranchPoint
from gearsym.solver.sweep import sweep
from gearsym.solver.sweep.atlas import regime_map

DPI = 120  # the figures' resolution: a marker of ms points is ms * DPI / 72 px


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def test_area_palettes_give_each_colour_one_meaning():
    pairs = list(plots_maps.MOTION_CLASSES) + [
        p for p in plots_maps.MESHING_CLASSES if p not in plots_maps.OUTCOMES
    ]
    colours = [mcolors.to_hex(c) for _, c in pairs]
    labels = [label for label, _ in pairs]
    assert len(set(labels)) == len(labels)
    shared = {c for c in colours if colours.count(c) > 1}
    assert not shared, [lab for lab, c in zip(labels, colours, strict=True) if c in shared]
    # an outcome means the same in both maps
    for label, colour in plots_maps.OUTCOMES:
        assert dict(plots_maps.MOTION_CLASSES)[label] == colour
        assert dict(plots_maps.MESHING_CLASSES)[label] == colour


def test_sweep_markers_are_visible_and_tell_the_directions_apart():
    fwd, bwd = plots_maps.SWEEPS["forward"], plots_maps.SWEEPS["backward"]
    assert min(fwd["ms"], bwd["ms"]) * DPI / 72 >= 3
    assert fwd["color"] != bwd["color"]
    assert bwd["ms"] > fwd["ms"] and bwd.get("mfc") == "none"  # a ring around the dot


def test_motion_class_reports_runs_that_left_the_valid_range():
    assert plots_maps.motion_class("period-1", "left the valid range") == "left the valid range"
    assert plots_maps.motion_class("undetermined", "invalid") == "left the valid range"
    assert plots_maps.motion_class("period-7") == "period-n (n > 3)"
    assert plots_maps.motion_class("something new") == "undetermined"


def _sweeps(duffing):
    s = duffing.with_values(k=0.1, B=0.3, a=1.0, c=0.1)
    settings = dict(transient=20, periods=8, lyapunov_periods=0, executor="serial")
    return s, [sweep(s, "omega", [1.1, 1.2, 1.3], backward=b, **settings) for b in (False, True)]


def test_bifurcation_diagram_shows_both_sweeps_and_the_operating_point(duffing, tmp_path):
    system, sweeps = _sweeps(duffing)
    fig = plots.bifurcation_diagram(sweeps, ["x"], title="a sweep", system=system)
    assert not list(tmp_path.iterdir())  # nothing saved: the caller's choice
    path = plots.save_figure(fig, tmp_path / "b.png")
    assert path.stat().st_size > 1000 and not plt.fignum_exists(fig.number)
    ax = fig.axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    fwd, bwd = lines["forward sweep"], lines["backward sweep"]
    # the backward sweep is drawn first, as rings, and the forward dots on top
    assert ax.get_lines().index(bwd) < ax.get_lines().index(fwd)
    assert bwd.get_markerfacecolor() == "none"
    assert min(fwd.get_markersize(), bwd.get_markersize()) * DPI / 72 >= 3
    assert ax.get_legend() is None and len(fig.legends) == 1  # one legend, outside
    # the title states the operating point: omega, swept here, at both ends (once)
    assert "a sweep\nω̄ = 1.1 to 1.3" in ax.get_title() and " over " not in ax.get_title()


def test_point_figure_titles_verdict_and_keeps_the_sixth_harmonic(duffing):
    s = duffing.with_values(k=0.1, B=0.3, a=1.0, c=0.1, omega=1.2)
    point = analyse_point(s, None, transient=30, periods=16, lyapunov_periods=0)
    fig = plots.point_figure(point, title="a point")
    title = fig._suptitle.get_text()
    assert "a point" in title and "ω̄ = 1.2" in title and "verdict: " in title
    spec = fig.axes[2]
    assert spec.get_xlim()[1] >= 6 * 1.2  # the sixth harmonic is inside the axis
    assert "half backlashes" in spec.get_ylabel()
    (curve,) = [ln for ln in spec.get_lines() if ln.get_xdata().size > 10]
    from gearsym.solver.analysis import spectrum

    sp = spectrum(point.trajectory, "x")
    keep = (sp.frequency <= 6.5 * 1.2) & (sp.amplitude > 0)
    assert np.array_equal(curve.get_ydata(), sp.amplitude[keep])  # nothing floored
    # a bare trajectory still draws, without a verdict
    bare = plots.point_figure(point.trajectory)
    assert "verdict" not in bare._suptitle.get_text()


def _branch(values, n=1, fold=None):
    pts = tuple(
        BranchPoint(v, np.array([v, -v, 0.0, 0.0]), np.array([0.5, 0.1]), True, "stable", 1)
        for v in values
    )
    bifs = ()
    if fold is not None:
        bifs = (Bifurcation("fold", fold, np.array([fold, -fold, 0.0, 0.0]), 1.0, "lambda"),)
    return Branch("lambda", n, pts, bifs, state_names=("u", "v", "du", "dv"))


def test_branch_figure_draws_each_coordinate_and_says_what_it_left_out():
    branches = [_branch([0.0, 0.2, 0.4], fold=0.2), _branch([0.0, 0.0])]
    fig = plots.branch_figure(branches, ("u", "v"), title="two panels")
    assert len(fig.axes) == 2 and len(fig.legends) == 1
    assert all(ax.get_legend() is None for ax in fig.axes)
    assert "1 branch(es) without extent in the parameter not drawn" in fig.axes[0].get_title()
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels.count("fold") == 1  # once for the figure, not once per panel
    for ax, k in zip(fig.axes, (0, 1), strict=True):  # the fold sits on each panel's curve
        (mark,) = [
            ln for ln in ax.get_lines() if ln.get_marker() == "s" and np.size(ln.get_xdata())
        ]
        assert mark.get_ydata()[0] == pytest.approx([0.2, -0.2][k])


def test_maps_show_runs_that_left_the_valid_range(duffing):
    s = duffing.with_values(a=1.0, c=0.1, k=0.1, B=0.3, omega=1.2)
    m = regime_map(
        s,
        ("omega", [1.1, 1.2]),
        ("B", [0.2, 0.3]),
        initial_states=1,
        lyapunov_periods=0,
        transient=20,
        periods=16,
        executor="serial",
    )
    cell = m.cells[0][0]
    left = replace(cell.dominant, run=replace(cell.dominant.run, status="left the valid range"))
    cells = ((replace(cell, attractors=(left,)), *m.cells[0][1:]), *m.cells[1:])
    m = replace(m, cells=cells)
    figures = plots_maps.map_figures(m, kinds=("motion", "lyapunov", "attractors"))
    motion, lyap, count = figures.values()
    # the caption line is the figure's last text
    cap_motion, cap_count = motion.texts[-1].get_text(), count.texts[-1].get_text()
    shown = [t.get_text() for t in motion.axes[0].get_legend().get_texts()]
    assert "left the valid range" in shown
    hatched = [p for p in lyap.axes[0].patches if p.get_hatch()]
    assert len(hatched) == 1
    assert "left the valid range" in lyap.axes[0].get_legend().get_texts()[0].get_text()
    assert "dominant attractor" in cap_motion and "dominant" not in cap_count


def test_a_fold_is_drawn_at_the_turn_not_a_grid_step_along_the_curve():
    """A branch resampled on a grid keeps its turning point (0.458 here) between grid
    points a step away in the parameter, far along the curve at a sharp fold: the marker
    goes to whichever of its two neighbours is nearer the fold's value (the turn), where
    the point before it alone put the marker off the curve (reproduce's light-load
    response, lambda 0.1)."""
    from types import SimpleNamespace

    from gearsym.solver.plots_response import event_point

    values = [0.4506, 0.4582, 0.4583, 0.4506]  # up to the turn (kept), then back down
    fold = SimpleNamespace(index=2, value=0.45831)
    assert event_point(values, fold) == 2
    fold = SimpleNamespace(index=3, value=0.45829)
    assert event_point(values, fold) == 2
    # no index: the nearest value over the curve
    assert event_point(values, SimpleNamespace(index=-1, value=0.4507)) in (0, 3)


def test_a_coordinate_at_rest_is_drawn_flat_not_stretched_over_rounding():
    """A value constant to 1e-14 (a body inside its backlash) gets an axis 2e-6 wide round
    it in plain numbers; a real motion of 1e-3 keeps matplotlib's own limits."""
    from gearsym.solver.plots_style import at_rest

    fig, ax = plt.subplots()
    rest = -0.4428 + 1e-14 * np.arange(50)
    ax.plot(rest)
    at_rest(ax, "y", rest)
    lo, hi = ax.get_ylim()
    assert hi - lo == pytest.approx(2e-6, rel=1e-9) and lo < rest.mean() < hi
    assert not ax.yaxis.get_major_formatter().get_useOffset()
    moving = 1e-3 * np.sin(np.arange(50))
    ax.cla()
    ax.plot(moving)
    before = ax.get_ylim()
    at_rest(ax, "y", moving)
    assert ax.get_ylim() == before
    plt.close(fig)
