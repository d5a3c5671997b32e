"""``gearsym.plot`` -- every figure of the package, from the API's result objects.

Each function takes a result object of ``import gearsym`` and returns a matplotlib
``Figure``; nothing is saved or shown (a notebook shows the returned figure; a script
calls :func:`save` or ``fig.savefig``).  Units are non-dimensional (half backlashes, τ)
unless a function says otherwise::

    import gearsym

    system = gearsym.load("reference-light")
    fig = gearsym.plot.point(gearsym.analyse(system))
    gearsym.plot.save(fig, "point.png")   # 120 dpi, tight box; closes the figure

The functions draw with the palettes of ``gearsym.solver.plots_style`` (one meaning, one
colour in every figure) and are the same ones the CLI and ``gearsym reproduce`` save.
"""

from __future__ import annotations

__all__ = [
    "bifurcation",
    "branches",
    "campbell",
    "carrier",
    "frequency_response",
    "map",
    "mesh_response",
    "modes",
    "multipliers",
    "parametric",
    "point",
    "save",
]


def save(fig, path):
    """Write ``fig`` to ``path`` (PNG, SVG, PDF by the suffix; 120 dpi, the box tight
    around everything drawn; the folder made if missing), close it and return the path."""
    from gearsym.solver.plots_style import save_figure

    return save_figure(fig, path)


def point(result, title: str = "", periods_shown: int = 20, *, units: str = "model"):
    """One operating point: time series, phase portrait with its Poincaré points and
    spectrum of each mesh coordinate, one row per coordinate.

    ``result``: a ``PointResult`` (``gearsym.analyse``; its verdict and evidence go into
    the title) or a ``Trajectory`` (``gearsym.simulate``; no verdict).  ``units``:
    ``model`` (half backlashes, τ) or ``physical`` (µm, ms, m/s, Hz).  Returns a Figure.
    """
    from gearsym.solver.plots import point_figure

    return point_figure(result, title=title, periods_shown=periods_shown, units=units)


def bifurcation(sweeps, states=None, title: str = "", *, system=None, units: str = "model"):
    """Poincaré points against the swept parameter, one panel per state.

    ``sweeps``: a ``SweepResult`` (``gearsym.sweep``) or a list of them (a forward and a
    backward sweep: rings and dots, so hysteresis shows); ``states``: state names
    (default: the mesh coordinates); ``system``: the ``System`` swept, for ω̄ and the
    loads in the title; ``units="physical"`` (needs ``system``): deflections in µm at each
    point's own scales, the speed in rpm beside ω̄.  Returns a Figure.
    """
    from gearsym.solver.plots import bifurcation_diagram

    sweeps = [sweeps] if not isinstance(sweeps, list | tuple) else list(sweeps)
    if states is None:
        first = sweeps[0].points[0] if sweeps[0].points else None
        states = (
            list(system.coordinates)
            if system is not None
            else list(getattr(first, "classification", None) or ["u"])
        )
    return bifurcation_diagram(sweeps, list(states), title=title, system=system, units=units)


def map(result, *, kinds=None, ticks=None, title=None, system=None, units: str = "model"):
    """The figures of a regime map: ``{kind: Figure}`` for the kinds asked (default all:
    ``motion``, ``lyapunov``, ``attractors``, ``extremes``, ``meshing`` -- the last only
    for a model with contact edges), each with its caption line.

    ``result``: a ``RegimeMap`` (``gearsym.regime_map``); ``ticks``: ``{axis: [label per
    value]}`` for an axis whose values stand for text; ``title`` opens the caption;
    ``units="physical"`` with the mapped ``system``: extremes in µm, exponents per second,
    the speed or mesh frequency beside an omega or speed axis.
    """
    from gearsym.solver.plots_maps import FIGURES, map_figures

    kinds = FIGURES if kinds is None else kinds
    return map_figures(result, ticks=ticks, title=title, kinds=kinds, system=system, units=units)


def branches(result, state=None, sweeps=None, title: str = "", *, system=None, units="model"):
    """Continued periodic branches: stable solid, unstable dashed, bifurcations marked,
    over the Poincaré points of brute-force ``sweeps`` (``SweepResult`` list) if given.

    ``result``: a ``Branch`` (``gearsym.continue_orbit``) or a list of them; ``state``: a
    state name or a sequence of names (a panel each; default the first state); ``system``:
    for ω̄ and the loads in the title; ``units="physical"`` (needs ``system``): states in
    µm, the speed in rpm beside ω̄.  Returns a Figure.
    """
    from gearsym.solver.plots import branch_figure

    result = [result] if not isinstance(result, list | tuple) else list(result)
    return branch_figure(result, state, sweeps=sweeps, title=title, system=system, units=units)


def multipliers(orbit, title: str = ""):
    """Floquet multipliers in the complex plane with the unit circle.

    ``orbit``: an ``Orbit`` (``gearsym.shoot``; its ``floquet.multipliers``) or the
    multipliers themselves (complex array).  Returns a Figure.
    """
    from gearsym.solver.plots import multipliers_figure

    floquet = getattr(orbit, "floquet", None)
    return multipliers_figure(orbit if floquet is None else floquet.multipliers, title=title)


def frequency_response(result, physical: bool = False, title: str = ""):
    """Amplitude (half peak-to-peak) of each mesh coordinate against the parameter: one
    colour per method, stable solid, unstable dashed, folds marked.

    ``result``: a ``FrequencyResponse`` (``gearsym.frequency_response``); ``physical``:
    mesh frequency in Hz and amplitude in µm (over the forcing frequency only).
    Returns a Figure.
    """
    from gearsym.solver.plots_response import frequency_response_figure

    return frequency_response_figure(result, physical=physical, title=title)


def campbell(result, speeds_rpm=None, harmonics: int = 3):
    """The resonance (Campbell) diagram: natural frequencies and the mesh-frequency
    harmonics against the first mesh driver's speed (rpm; Hz on the y axis).

    ``result``: a ``Modes`` (``gearsym.modes``); ``speeds_rpm``: ``(low, high)``, default
    0 to twice the model's speed (marked).  Returns a Figure.
    """
    from gearsym.solver.plots_modes import campbell_figure

    scene_rpm = 60.0 * result.mesh_frequency_hz / result.reference_teeth
    speeds = (0.0, 2.0 * scene_rpm) if speeds_rpm is None else tuple(speeds_rpm)
    return campbell_figure(result, speeds, harmonics=harmonics, scene_rpm=scene_rpm)


modes = campbell  # the figure of gearsym.modes' result


def carrier(sweep):
    """A planetary set's natural frequencies against its carrier's speed (a Campbell
    diagram): each track coloured by its mode's type, the mesh harmonics and their
    meetings with the modes where known, the speeds without modes shaded.

    ``sweep``: the mapping of ``gearsym.planetary.carrier_sweep``.  Returns a Figure.
    """
    from gearsym.solver.plots_modes import carrier_figure

    return carrier_figure(sweep)


def parametric(table):
    """The parametric-instability diagram of a planetary set: the first-order wedges of
    its primary and combination instabilities over the mesh frequency (Hz) and the share
    of the stated stiffness variation, the bands its phasing suppresses marked.

    ``table``: the mapping of ``gearsym.planetary.parametric_instabilities``.  Returns a
    Figure.
    """
    from gearsym.solver.plots_modes import parametric_figure

    return parametric_figure(table)


def mesh_response(resp):
    """A planetary set's mesh frequency response: each kind of mesh's largest and smallest
    deflection against the mesh frequency, up and down, the band where teeth separate
    shaded and the resonances with the stiffness variation's harmonics dotted.

    ``resp``: the mapping of ``gearsym.planetary.mesh_response``.  Returns a Figure.
    """
    from gearsym.solver.plots_response import mesh_response_figure

    return mesh_response_figure(resp)
