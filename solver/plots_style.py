"""The package's figure style: its palettes (one meaning, one colour, in every figure),
marker families, shared legend and caption helpers, and :func:`save_figure`, the one way
every caller writes a figure to a file.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import BoundaryNorm, ListedColormap  # noqa: E402
from matplotlib.layout_engine import PlaceHolderLayoutEngine  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

__all__ = [
    "BIFURCATIONS",
    "BRANCHES",
    "CONTACT",
    "DPI",
    "MESHING_CLASSES",
    "MOTION_CLASSES",
    "OUTCOMES",
    "REST",
    "SWEEPS",
    "at_rest",
    "categorical",
    "legend_below",
    "motion_class",
    "not_ok_marks",
    "put_caption",
    "operating_point",
    "period_colour",
    "save_figure",
    "sweep_marker",
]

DPI = 120  # every figure file of the package


# The package's palettes: one meaning, one colour, in every figure (these maps, the
# bifurcation and point figures of ``plots``, the responses, the studies' figures).  The
# area palettes (motion, meshing, outcomes) share no colour, so a cell's colour means one
# thing whichever map it is in; a test holds that.
OUTCOMES = (  # what a run that has no motion type became
    ("undetermined", "#c7c7c7"),
    ("divergent", "#000000"),
    ("left the valid range", "#9467bd"),
)
MOTION_CLASSES = (  # (label, colour) in legend order
    ("period-1", "#2ca02c"),
    ("period-2", "#bcbd22"),
    ("period-3", "#ff7f0e"),
    ("period-n (n > 3)", "#8c564b"),
    ("quasi-periodic", "#1f77b4"),
    ("chaotic", "#d62728"),
    *OUTCOMES,
)
MESHING_CLASSES = (
    ("no impact", "#9edae5"),
    ("single-sided impact", "#e377c2"),
    ("double-sided impact", "#7b0051"),
    ("no contact", "#ffed6f"),
    # a force law loaded inside the gap (the study's polynomial): it reverses, never lifts
    ("single-sided force reversal", "#fdb462"),
    ("double-sided force reversal", "#8c510a"),
    ("inside the outer zeros, loaded", "#b3de69"),
    *OUTCOMES,
)
# Marker families: a sweep's direction (filled dots over open rings: both stay visible
# where they agree), a mesh's contact state, a bifurcation's kind.
SWEEPS = {
    "forward": {"color": "#08519c", "marker": "o", "ms": 3.0, "mew": 0.0},
    "backward": {"color": "#e6550d", "marker": "o", "ms": 6.0, "mfc": "none", "mew": 1.0},
    "independent": {"color": "#08519c", "marker": "o", "ms": 3.0, "mew": 0.0},
}
CONTACT = {"forward": "#1b7837", "separated": "#878787", "backward": "#762a83"}
BIFURCATIONS = {
    "fold": ("s", "#e41a1c"),
    "branch point": ("^", "#ff7f00"),  # a multiplier through +1 where the branch does not turn
    # no multiplier at the critical value there: the orbit grazes a contact edge
    "non-smooth fold": ("s", "#a6761d"),
    "non-smooth branch point": ("^", "#a6761d"),
    "non-smooth period-doubling": ("D", "#a6761d"),
    "period-doubling": ("D", "#984ea3"),
    "neimark-sacker": ("o", "#4daf4a"),
}
# continued branches, by period multiple (1, 2, 3, more): dark lines over the sweeps' dots
BRANCHES = ("#252525", "#31a354", "#756bb1", "#8c6d31")
_OUTCOME_COLOUR = dict(OUTCOMES)


def period_colour(n: int) -> str:
    """The colour of a continued period-n branch (:data:`BRANCHES`)."""
    return BRANCHES[min(max(int(n), 1), len(BRANCHES)) - 1]


def motion_class(motion: str, status: str = "ok") -> str:
    """The legend class of a motion label (a run that did not end normally: its status)."""
    if status in ("left the valid range", "invalid"):
        return "left the valid range"
    if status == "divergent" or motion == "divergent":
        return "divergent"
    if motion in ("period-1", "period-2", "period-3"):
        return motion
    if motion.startswith("period-"):
        return "period-n (n > 3)"
    known = {label for label, _ in MOTION_CLASSES}
    return motion if motion in known else "undetermined"


def sweep_marker(direction: str) -> dict:
    """Keyword arguments of ``ax.plot`` for a sweep's points (:data:`SWEEPS`)."""
    return dict(SWEEPS.get(direction, SWEEPS["independent"]))


def operating_point(system, parameter: str | None = None, values=None) -> str:
    """The operating point in words: ω̄, each static load and the backlash model, e.g.
    ``ω̄ = 0.5; f_u = 0.1, f_v = -0 to -0.1 over lambda 0 to 1; polynomial backlash``.
    Over a sweep of ``parameter`` (``values``), what it changes is given at both ends."""
    c = system.contract
    ends = None
    if parameter is not None and values is not None and len(values):
        lo, hi = float(np.min(values)), float(np.max(values))
        ends = [system.with_values(**{parameter: v}) for v in (lo, hi)]

    def text(name: str, shown: str) -> str:
        a, b = (system, system) if ends is None else ends
        a, b = a.parameter(name) + 0.0, b.parameter(name) + 0.0  # no "-0"
        return f"{shown} = {a:.4g}" if a == b else f"{shown} = {a:.4g} to {b:.4g}"

    loads = ", ".join(text(name, name) for name in c.loads.values())
    out = text(c.forcing_frequency, "ω̄") + (f"; {loads}" if loads else "")
    if ends is not None and parameter != c.forcing_frequency:  # else the ω̄ range says it
        out += f" over {parameter} {lo:.4g} to {hi:.4g}"
    backlash = getattr(system.module, "FEATURES", {}).get("backlash")
    return out + (f"; {backlash} backlash" if backlash else "")


def categorical(ax, x_edges, y_edges, labels, classes) -> None:
    """Cells coloured by class (``classes``: (label, colour) pairs), with a legend of the
    classes present outside the axes, to the right."""
    names = [c for c, _ in classes]
    codes = np.vectorize(lambda s: names.index(s))(np.asarray(labels, dtype=object))
    cmap = ListedColormap([c for _, c in classes])
    norm = BoundaryNorm(np.arange(len(classes) + 1) - 0.5, cmap.N)
    ax.pcolormesh(x_edges, y_edges, codes.astype(float), cmap=cmap, norm=norm)
    present = [k for k in range(len(classes)) if np.any(codes == k)]
    ax.legend(
        handles=[Patch(color=classes[k][1], label=classes[k][0]) for k in present],
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=8,
        frameon=False,
    )


def legend_below(fig, axes, caption: str = "") -> None:
    """One legend for the whole figure, below it (each label once, whichever panels
    carry it), and ``caption`` under the legend."""
    seen: dict = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            seen.setdefault(label, handle)
    fig.tight_layout()
    bottom = 0.0
    if seen:
        legend = fig.legend(
            seen.values(),
            seen.keys(),
            loc="upper center",
            bbox_to_anchor=(0.5, 0.0),
            ncol=min(3, len(seen)),
            fontsize=8,
            frameon=False,
        )
        renderer = fig.canvas.get_renderer()
        box = legend.get_window_extent(renderer).transformed(fig.transFigure.inverted())
        bottom = box.y0
    if caption:
        put_caption(fig, bottom - 0.01, caption)


def put_caption(fig, top: float, caption: str, fontsize: float = 7) -> None:
    """``caption`` under the figure from ``top`` (figure coordinates) down, broken into
    lines of the figure's width.  The lines are broken by a count of characters at the
    font's mean advance (about 0.55 em, DejaVu Sans) rather than by matplotlib's
    ``wrap=True``, which measured every word of every caption at each draw and took a
    third of the time of a map's figures."""
    import textwrap

    width = 0.97 * fig.get_figwidth() * 72.0 / (0.55 * fontsize)
    lines = [
        textwrap.fill(part, max(int(width), 20)) if part else "" for part in caption.split("\n")
    ]
    fig.text(0.01, top, "\n".join(lines), fontsize=fontsize, ha="left", va="top")


def not_ok_marks(ax, values, statuses) -> None:
    """A cross on the panel's lower edge at each value whose run did not end normally
    (its outcome's colour): such runs have no Poincaré points to draw."""
    bad: dict = {}
    for value, status in zip(values, statuses, strict=True):
        if status != "ok":
            bad.setdefault(motion_class("", status), []).append(value)
    for label, xs in bad.items():
        ax.plot(
            xs,
            np.zeros(len(xs)),
            "x",
            ms=7,
            mew=1.5,
            color=_OUTCOME_COLOUR.get(label, "#c7c7c7"),
            transform=ax.get_xaxis_transform(),
            clip_on=False,
            label=f"run {label} (no Poincaré points)",
        )


def save_figure(fig, path, box=None) -> Path:
    """Write ``fig`` to ``path`` (its folder made if missing; the format from the suffix;
    :data:`DPI`, the bounding box tight around everything drawn) and close it; the path.
    ``box``: that bounding box (inches), already measured on the finished figure, padded
    as savefig pads its own."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tight = "tight" if box is None else box.padded(plt.rcParams["savefig.pad_inches"])
    # tight_layout() leaves a placeholder layout engine that lays out nothing, and any
    # engine makes savefig draw the figure once more before it draws it into the file
    # (a fifth of the cost of a map's figures); the same pixels without it
    if isinstance(fig.get_layout_engine(), PlaceHolderLayoutEngine):
        fig.set_layout_engine(None)
    fig.savefig(path, dpi=DPI, bbox_inches=tight)
    plt.close(fig)
    return path


# a coordinate whose span over a panel is below this share of max(1, its size) is at
# rest: its axis is drawn round it at that width, not stretched over rounding (a body
# inside its backlash drifts by 1e-14 half backlashes, which autoscaling drew as motion)
REST = 1e-9


def at_rest(ax, axis: str, values) -> None:
    """Draw the ``axis`` ("x" or "y") of ``ax`` round ``values`` at width :data:`REST`
    where they are constant to rounding, in plain numbers (no offset)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if not v.size:
        return
    mid, width = float(np.mean(v)), REST * max(1.0, float(np.max(np.abs(v))))
    if float(np.ptp(v)) <= width:
        (ax.set_ylim if axis == "y" else ax.set_xlim)(mid - 1e3 * width, mid + 1e3 * width)
        ax.ticklabel_format(axis=axis, useOffset=False, style="plain")
        ax.locator_params(axis=axis, nbins=3)  # long plain numbers: few of them
