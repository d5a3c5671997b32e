"""The figure of one operating point: time series, phase portrait with Poincaré points,
and spectrum of each mesh coordinate, in the model's units (half backlashes, τ) or
physical ones (µm, ms, m/s, Hz; ``solver/units.py``)."""

from __future__ import annotations

import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .analysis import spectrum  # noqa: E402
from .analysis.point import verdict_line  # noqa: E402
from .analysis.spectra import ROUNDING  # noqa: E402
from .integrate import Trajectory  # noqa: E402
from .plots_style import at_rest, operating_point  # noqa: E402
from .units import Units  # noqa: E402

__all__ = ["HARMONICS_SHOWN", "PORTRAIT_PERIODS", "point_figure"]

PORTRAIT_PERIODS = 500  # periods a phase portrait draws at most
HARMONICS_SHOWN = 6  # a spectrum runs to (HARMONICS_SHOWN + 1/2) omega: the 6th is whole


class _Scale:
    """What one coordinate's panels multiply by and the units they write: deflection,
    time, velocity and frequency (``units.Units``, None: the model's units; physical time
    in ms, velocity in m/s where the deflection is in µm)."""

    def __init__(self, units: Units | None, c: str):
        self.physical = units is not None
        self.x, self.x_unit, self.t, self.v, self.f = 1.0, "half backlashes", 1.0, 1.0, 1.0
        self.t_label, self.v_label = "τ (non-dimensional time)", f"d{c}/dτ"
        self.f_label = "frequency (rad per unit τ)"
        if units is None:
            return
        self.x, self.x_unit = units.deflection(c, 1.0), units.deflection_unit(c)
        per_s = 1.0 / units.time(1.0)  # omega_n: tau per second
        self.t, self.t_label = 1e3 / per_s, "t (ms)"
        if self.x_unit == "µm":  # d/dt = omega_n d/dtau; µm per s to m/s
            self.v, self.v_label = self.x * per_s * 1e-6, f"d{c}/dt (m/s)"
        self.f, self.f_label = units.frequency(1.0), "frequency (Hz)"


def _title(tr: Trajectory, point, title: str, units: Units | None) -> str:
    lines = [title] if title else []
    head = operating_point(tr.system)
    if units is not None:  # (omega is in the head already)
        head += "; " + units.operating_point().split(" (omega")[0]
    lines.append(head)
    if point is not None:
        lines.append(textwrap.fill(verdict_line(point), 150))
    return "\n".join(lines)


def point_figure(point, title: str = "", periods_shown: int = 20, units: str = "model"):
    """One operating point: time series, phase portrait with Poincaré points, and spectrum
    of each mesh coordinate (one row per coordinate).

    ``point`` is a :class:`~.analysis.PointResult` (any point, periodic or chaotic: its
    verdict per coordinate and largest Lyapunov exponent go into the title) or a bare
    :class:`~.integrate.Trajectory` (no verdict).  The title states ω̄, the loads and the
    backlash model (and, physical, the speed and mesh frequency).  Spectra: amplitude
    (Hann window, a cosine of amplitude a reads a) against frequency, up to 6.5 ω̄ so the
    sixth harmonic is whole; the top axis counts multiples of ω̄ (orders of the mesh
    frequency).  Nothing is floored: bins the FFT finds exactly zero are left out of the
    log axis.  ``units``: ``model`` (half backlashes, τ, rad per unit τ) or ``physical``
    (µm, ms, m/s, Hz).
    """
    tr = getattr(point, "trajectory", point)
    result = None if tr is point else point
    if units not in ("model", "physical"):
        raise ValueError(f"units '{units}': not one of model, physical")
    inu = Units.of(tr.system, units) if units == "physical" else None
    coords = tr.system.coordinates
    fig, axes = plt.subplots(len(coords), 3, figsize=(13, 3.3 * len(coords)), squeeze=False)
    spp = tr.samples_per_period
    shown = slice(max(0, tr.t.size - periods_shown * spp), None)
    for row, c in enumerate(coords):
        k = _Scale(inu, c)
        u, du = tr.coordinate(c) * k.x, tr.velocity(c) * k.v
        ax = axes[row, 0]
        ax.plot(tr.t[shown] * k.t, u[shown], lw=0.8, color="#1f1f1f", label="response")
        edges = tr.system.contract.contact.get(c, ())
        for n, edge in enumerate(edges):
            unit = " µm" if k.x_unit == "µm" else ""
            where = ", ".join(f"{e * k.x:g}" for e in edges) + unit
            ax.axhline(
                edge * k.x,
                color="grey",
                lw=0.8,
                ls="--",
                label=None if n else f"contact edges {c} = {where} (the model's contract)",
            )
        at_rest(ax, "y", u[shown])
        ax.set_xlabel(k.t_label)
        ax.set_ylabel(f"{c} ({k.x_unit})")
        ax.set_title(f"{c}: time series (last {periods_shown} periods)", fontsize=9)
        ax = axes[row, 1]
        # at most the last PORTRAIT_PERIODS periods (a path of every sample of a long run
        # takes matplotlib gigabytes); the Poincare points likewise
        tail = slice(max(0, tr.t.size - PORTRAIT_PERIODS * spp), None)
        ax.plot(u[tail], du[tail], lw=0.3, color="#1f1f1f", alpha=0.6)
        ax.plot(
            tr.poincare[tr.system.index(c)][-PORTRAIT_PERIODS:] * k.x,
            tr.poincare[tr.system.velocity_index(c)][-PORTRAIT_PERIODS:] * k.v,
            "o",
            ms=3,
            color="#ce1256",
            label="Poincaré points (τ = 0 mod T)",
        )
        at_rest(ax, "x", u[tail])
        at_rest(ax, "y", du[tail])
        ax.set_xlabel(f"{c} ({k.x_unit})")
        ax.set_ylabel(k.v_label)
        shown_periods = min(PORTRAIT_PERIODS, tr.poincare.shape[1])
        ax.set_title(f"{c}: phase portrait (last {shown_periods} periods)", fontsize=9)
        _spectrum_panel(axes[row, 2], tr, c, k)
    fig.suptitle(_title(tr, result, title, inu), fontsize=10)
    fig.tight_layout()
    handles = {}  # every panel's entries once (a band may be drawn in one row only)
    for c, ax in ((c, ax) for c, row in zip(coords, axes, strict=True) for ax in row):
        for h, label in zip(*ax.get_legend_handles_labels(), strict=True):
            handles.setdefault(label.replace(f" {c} = ", " = "), h)
    fig.legend(
        handles.values(),
        handles.keys(),
        loc="upper center",
        bbox_to_anchor=(0.5, 0.0),
        ncol=len(handles),
        fontsize=8,
        frameon=False,
    )
    return fig


def _spectrum_panel(ax, tr: Trajectory, c: str, k: _Scale) -> None:
    sp = spectrum(tr, c)
    top = (HARMONICS_SHOWN + 0.5) * sp.omega * k.f
    f, amplitude = sp.frequency * k.f, sp.amplitude * k.x
    keep = (f <= top) & (amplitude > 0)
    ax.semilogy(f[keep], amplitude[keep], lw=0.8, color="#1f1f1f")
    ax.set_xlim(0, top)
    # what the integration's relative tolerance cannot resolve, and what is rounding of
    # the signal (the spectrum's own floor: a coordinate at rest has nothing above it)
    level = tr.rtol * float(amplitude[keep].max()) if np.any(keep) else 0.0
    level = max(level, ROUNDING * sp.level * k.x)
    if level > (bottom := ax.get_ylim()[0]):
        ax.axhspan(
            bottom,
            level,
            color="0.9",
            zorder=0,
            label="below rtol × the largest peak, or rounding (1e-10 of the signal)",
        )
        ax.set_ylim(bottom=bottom)
    ax.set_xlabel(k.f_label)
    ax.set_ylabel(f"amplitude of {c} ({k.x_unit})")
    w = sp.omega * k.f
    harmonics = ax.secondary_xaxis("top", functions=(lambda f, w=w: f / w, lambda n, w=w: n * w))
    harmonics.set_xticks(range(HARMONICS_SHOWN + 1))
    harmonics.tick_params(labelsize=7)
    if k.physical:
        seconds = sp.duration * k.t * 1e-3
        about = f"{seconds:.3g} s, bin {sp.resolution * k.f:.2g} Hz"
        what = f"orders of the mesh frequency {w:.5g} Hz"
    else:
        about = f"{sp.duration:.0f} τ, bin {sp.resolution:.2g}"
        what = f"multiples of ω̄ = {sp.omega:g}"
    ax.set_title(f"{c}: spectrum, top axis in {what}; {about}", fontsize=8)
    ax.grid(alpha=0.3)
