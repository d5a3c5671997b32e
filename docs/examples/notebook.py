"""A notebook in a script: each ``# %%`` cell runs in Jupyter, VS Code or Spyder as it is.

It uses ``import gearsym`` alone: load a model, look at one operating point, sweep the
load ratio, map two parameters, find a periodic orbit with its Floquet multipliers and
continue it, compute a short frequency response and the modes, sweep the speed in rpm with
results in µm and Hz, and draw each result with ``gearsym.plot`` (each function returns a
matplotlib Figure; a notebook shows it).

Run: ``python docs/examples/notebook.py [OUTDIR]``: with OUTDIR the figures are saved
there as PNG; without, nothing is written.  About half a minute on one core.
"""

# %%
import sys
from pathlib import Path

import gearsym

figures = {}  # name -> Figure, in the order drawn

# %% [markdown]
# ## The model
# The reference study's light-load pair at the load ratio lambda = 0.8 (``lambda`` is a
# Python keyword, so it goes through a dict).  ``repr`` is one line, ``summary()`` a few.

# %%
system = gearsym.load("reference-light", **{"lambda": 0.8})
print(system)
print(system.summary())

# %% [markdown]
# ## One operating point: the response, its verdict and the evidence for it

# %%
point = gearsym.analyse(system, transient=100, periods=20, lyapunov_periods=50)
print(point.summary())
figures["point"] = gearsym.plot.point(point, title="lambda = 0.8")

# %% [markdown]
# ## A sweep of the load ratio, each point starting from the previous one's end state

# %%
values = [0.2 * k for k in range(6)]
sweep = gearsym.sweep(system, "lambda", values, transient=60, periods=16, lyapunov_periods=20)
print(sweep.summary())
figures["bifurcation"] = gearsym.plot.bifurcation(sweep, system=system)

# %% [markdown]
# ## A regime map over the load ratio and the forcing frequency (a small grid)

# %%
regimes = gearsym.regime_map(
    system,
    ("lambda", [0.2, 0.5, 0.8]),
    ("omega", [0.45, 0.5, 0.55]),
    initial_states=1,
    transient=50,
    periods=16,
    lyapunov_periods=0,
    executor="serial",
)
print(regimes.summary())
for kind, fig in gearsym.plot.map(regimes, kinds=("motion", "extremes")).items():
    figures[f"map-{kind}"] = fig

# %% [markdown]
# ## The periodic orbit by shooting, its Floquet multipliers, and its continuation

# %%
orbit = gearsym.shoot(system, point.trajectory.x_final)
print(orbit.summary())
figures["multipliers"] = gearsym.plot.multipliers(orbit, title="period-1 orbit, lambda = 0.8")
branch = gearsym.continue_orbit(system, "lambda", 0.8, 1.0, orbit.x0)
print(branch.summary())
figures["branch"] = gearsym.plot.branches(branch, ("u", "v"), sweeps=[sweep], system=system)

# %% [markdown]
# ## A short frequency response (harmonic balance) and the modes

# %%
response = gearsym.frequency_response(system, "omega", 0.45, 0.55, points=8)
print(response.summary())
figures["frequency-response"] = gearsym.plot.frequency_response(response)
modes = gearsym.modes(system)
print(modes.summary())
figures["campbell"] = gearsym.plot.campbell(modes)

# %% [markdown]
# ## In the engineer's units
# The same pair at 1,200 rpm of pinion p (a physical quantity of the generated model:
# no new derivation), swept over the speed; the figure in µm with the mesh frequency in
# Hz on its top axis, and the sweep's table with µm, rpm and Hz columns beside the
# model's own.

# %%
at_speed = gearsym.load("reference-light", speed_rpm=1200.0, **{"lambda": 0.8})
print(gearsym.Units.of(at_speed).operating_point())
speeds = [900.0, 1050.0, 1200.0]
by_speed = gearsym.sweep(
    at_speed, "speed_rpm", speeds, transient=60, periods=16, lyapunov_periods=20
)
columns, rows = gearsym.in_units(by_speed, at_speed).to_table()
print([c for c in columns if c.endswith(("_um", "_rpm", "_hz"))])
figures["bifurcation-physical"] = gearsym.plot.bifurcation(
    by_speed, system=at_speed, units="physical"
)

# %% [markdown]
# ## Saving is the caller's choice

# %%
if __name__ == "__main__" and len(sys.argv) > 1:
    out = Path(sys.argv[1])
    for name, fig in figures.items():
        print("wrote", gearsym.plot.save(fig, out / f"{name}.png"))
