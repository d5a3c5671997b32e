"""The audit page of a gear train with closed loops (``docs/derivation/<name>.md``): the
kinematic graph with its loops and rigid-body modes, the bodies' coordinates and masses,
every link's deflection, the locked-in load, the nonlinear model's scales, and what is not
modelled."""

from __future__ import annotations

import math

import numpy as np

from ..equations.train import TrainStructure, loaded_flanks, mesh_multiples
from ..escape import markdown

__all__ = ["train_index", "train_page"]


def _name(name: str) -> str:
    return name.replace("-", "_")


def _deflection(st: TrainStructure, j: int) -> str:
    """A link's deflection over the coordinates, as text: ``u_1 + u_2``, ``u_2/r_2 - u_3/r_3``."""
    terms = []
    for i, v in enumerate(st.incidence[j]):
        if v == 0.0:
            continue
        sign = "−" if v < 0 else "+"
        term = st.physical[i] if st.kinds[j] == "mesh" else f"{st.physical[i]}/r{i + 1}"
        terms.append(f"{sign} {term}")
    text = " ".join(terms)
    return text[2:] if text.startswith("+ ") else "−" + text[2:]


def train_page(st: TrainStructure, command: str, source: str) -> str:
    """The page's Markdown (module docstring)."""
    tr = st.train
    n, links = len(tr.bodies), len(st.springs)
    loops = links - n + 1  # of a connected graph (the loader refuses unjoined groups)
    speeds = st.speeds
    lines = [
        f"# Derivation audit: `{markdown(_name(tr.name), code=True)}` (gear train with "
        "closed loops)\n",
        f"Derived by `{markdown(command, code=True)}` from `{markdown(source, code=True)}` "
        "(`derive/equations/train.py`, its nonlinear model `derive/equations/"
        "body_dynamics.py`).\n",
        f"{markdown(tr.description)}\n" if tr.description else "",
        "## Kinematic graph\n",
        f"{n} bodies joined by {len(tr.meshes)} meshes and {len(tr.shafts)} shafts: "
        f"{loops} independent closed loop{'s' if loops != 1 else ''}, so the train is "
        "not a tree and keeps each body's rotation `u_i = r_i θ_i` (`r_i` its base radius) "
        "as a coordinate. Every rotation is counted in one sense: an external mesh "
        "strains `u_a + u_b`, an internal one `u_a − u_b` (b the ring), a shaft "
        "`θ_a − θ_b`.\n",
        f"Rigid-body modes (from the teeth, going round the graph): "
        f"**{st.rigid_body_modes}**. "
        + (
            "The train turns as a whole with the speeds below (each over the first body's); "
            "the nonlinear model removes this rotation: "
            f"`{_pivot(st)}` follows from the others (the rotation that carries the "
            "train's momentum, `φ_0ᵀ M q = 0`).\n"
            if st.rigid_body_modes == 1
            else "Going round a loop the speed ratios do not come back to 1: the loop is "
            "locked and cannot turn; only its modes are derived.\n"
        ),
        "A gear's base radius as used is its teeth times the base pitch it shares with the "
        "gears it meshes with, so that the speed ratios are the teeth's exactly.\n",
        "| body | coordinate | teeth | base radius given (mm) | as used (mm) | inertia (kg m²) "
        "| mass I/r² (kg) | speed in the rigid rotation |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for i, b in enumerate(tr.bodies):
        speed = f"{'+' if speeds[i] > 0 else ''}{speeds[i]}" if speeds is not None else "—"
        lines.append(
            f"| `{markdown(b.id, code=True)}` | `{st.physical[i]}` | {b.teeth or '—'} | "
            f"{b.radius * 1e3:.6g} | {st.radius[i] * 1e3:.6g} | {b.inertia:.6g} | "
            f"{st.mass[i]:.6g} | {speed} |"
        )
    multiples = mesh_multiples(st) if st.speeds is not None else ("—",) * len(tr.meshes)
    flanks = loaded_flanks(st) if st.speeds is not None else (None,) * len(tr.meshes)
    lines += [
        "",
        "## Links\n",
        "Each link a spring along its deflection `δ = R q`, `K = Rᵀ diag(k) R`; a mesh's "
        "force is the dead zone of its half backlash at `δ + e(t)`, its stiffness "
        "`k (1 + v(t))`, `e` its transmission error (excess material on the flank the file's "
        "load presses, in the linear static solution: `Σ a_l cos(l ω_m t + φ_l)` at its "
        "mesh frequency and phase, signed by that flank).\n",
        "| link | kind | between | deflection | stiffness | half backlash / assembly twist "
        "| frequency over the first mesh's | phase (its mesh periods) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for j, link in enumerate((*tr.meshes, *tr.shafts)):
        a, b = (markdown(x, code=True) for x in link.bodies)
        if link.kind == "mesh":
            kind = "internal mesh" if link.internal else "external mesh"
            stiff = f"{link.stiffness:.6g} N/m"
            gap = f"{link.half_backlash * 1e6:.6g} µm"
            if flanks[j] is not None:
                gap += f", loaded on δ {'>' if flanks[j] > 0 else '<'} 0"
            if link.error is not None and link.error.amplitudes:
                gap += "; transmission error " + ", ".join(
                    f"{a * 1e6:.6g} µm at {math.degrees(p):.6g}° (harmonic {h})"
                    for h, (a, p) in enumerate(
                        zip(link.error.amplitudes, link.error.phases, strict=True), start=1
                    )
                )
            extra = f"{multiples[j]} | {link.phase:.6g}"
        else:
            kind, stiff = "shaft", f"{link.stiffness:.6g} N m/rad"
            gap = f"{math.degrees(link.twist):.6g}°" if link.twist else "—"
            extra = "— | —"
        lines.append(
            f"| `{markdown(link.id, code=True)}` | {kind} | `{a}`, `{b}` | "
            f"`{_deflection(st, j)}` | {stiff} | {gap} | {extra} |"
        )
    lines += ["", "## The load and the nonlinear model\n"]
    twisted = [s for s in tr.shafts if s.twist]
    lines.append(
        "Load per unit `f` (the `load_factor`, 1 as the file states): "
        + (
            ", ".join(
                f"shaft `{markdown(s.id, code=True)}` assembled with a twist of "
                f"{math.degrees(s.twist):.6g}° (its spring `k (δ − f Δ)`: a locked-in load "
                "the loop carries at rest)"
                for s in twisted
            )
            if twisted
            else "no assembly twist"
        )
        + (
            "; torques "
            + ", ".join(
                f"{markdown(k, code=True)} {v:.6g} N m" for k, v in sorted(tr.torques.items())
            )
            if tr.torques
            else "; no external torque (the losses a motor supplies are not modelled)"
        )
        + ".\n"
    )
    if tr.dynamics is not None and st.rigid is not None:
        first = tr.meshes[0]
        r = st.incidence[0]
        m_ref = 1.0 / float(np.sum(r**2 / np.asarray(st.mass)))
        omega_n = math.sqrt(first.stiffness / m_ref)
        lines.append(
            "Scales: lengths in the first mesh's half backlash b = "
            f"{first.half_backlash * 1e6:.6g} µm, time τ = ω_n t with ω_n = √(k/m) of that "
            f"mesh = {omega_n:.6g} rad/s "
            f"(m = {m_ref:.6g} kg, the mass its deflection sees); forcing frequency ω = 2π "
            f"f_mesh / ω_n = {2 * math.pi * tr.dynamics.mesh_frequency_hz / omega_n:.6g} at "
            f"{tr.dynamics.mesh_frequency_hz:g} Hz; damping ratio "
            f"{tr.dynamics.damping_ratio:g} on every spring's own mass.\n"
        )
    lines += [
        "## Not modelled\n",
        "Bearings and translations (the bodies only turn); the losses "
        "and the motor that supplies them; the shafts' own inertia (lump it with a body).\n",
    ]
    return "\n".join(line for line in lines if line is not None)


def train_index(structures: list) -> str:
    """The index page's section on the shipped gear trains with closed loops."""
    if not structures:
        return ""
    lines = [
        "\n## Gear trains with closed loops\n",
        "A train whose meshes and shafts close a loop (a back-to-back rig, a split-torque or "
        "idler train) is written as a `[train]` table and derived in its bodies' rotations "
        "(`derive/equations/train.py`); every command takes it.\n",
        "| train | bodies | meshes | shafts | rigid-body modes | page |",
        "|---|---|---|---|---|---|",
    ]
    for st in structures:
        tr = st.train
        name = _name(tr.name)
        lines.append(
            f"| `{markdown(name, code=True)}` | {len(tr.bodies)} | {len(tr.meshes)} | "
            f"{len(tr.shafts)} | {st.rigid_body_modes} | "
            f"[derivation/{name}.md](derivation/{name}.md) |"
        )
    return "\n".join(lines) + "\n"


def _pivot(st: TrainStructure) -> str:
    """The coordinate the nonlinear model fixes by the others (``body_dynamics.reduction``:
    the largest ``|M_ii phi_0,i|``)."""
    from ..equations.body_dynamics import reduction

    return reduction(st.physical, st.mass, st.incidence, st.rigid_body_modes)[1]
