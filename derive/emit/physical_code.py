"""The physical layer of a generated module (``derive/physical.py``) as Python source.

Emits the tables ``PHYSICAL`` (name: default, unit, meaning), ``PHYSICAL_LIMITS``,
``PHYSICAL_ALIASES`` and ``PHYSICAL_REPLACES``, and the functions ``_physical(values)``
(the quantities in effect, or None when none is given) and ``_physical_parameters(p, q,
s, given)`` (the closed forms), and ``scales(**values)`` (omega_n, half backlash and mean
stiffness of each mesh, speed in effect: for results in physical units).  Every user
name enters as a string literal (``repr``) or a comment through ``escape.text``; every
quantity is ``q[k]`` in the code, so no name a user writes becomes code.
"""

from __future__ import annotations

import sympy as sp

from ..escape import text
from .printer import CodePrinter

__all__ = ["physical_lines", "physical_tables"]


def physical_tables(layer, fmt) -> list[str]:
    """Module-level tables of the physical layer (empty tables when there is none)."""
    if layer is None:
        return ["PHYSICAL = {}", "PHYSICAL_ALIASES = {}", "PHYSICAL_REPLACES = {}"]
    lines = [
        "# Physical quantities a user may set by name (default = the scene's value), and the",
        "# model parameters they give through the audit page's closed forms (derive/physical.py).",
        "PHYSICAL = {",
        *(
            f"    {q.name!r}: ({fmt(q.value)}, {q.unit!r}, {q.meaning!r}),"
            for q in layer.quantities
        ),
        "}",
        "PHYSICAL_LIMITS = {",
        *(f"    {q.name!r}: ({q.low!r}, {q.high!r}, {q.low_open!r})," for q in layer.quantities),
        "}",
        f"PHYSICAL_ALIASES = {layer.aliases!r}",
        "# Setting both a quantity and one of these is refused: they state the same thing.",
        f"PHYSICAL_REPLACES = {layer.replaces!r}",
        f"OMEGA_FROM_SPEED = {layer.omega_from_speed!r}  # the scene states a speed, not omega",
        f"LOADS_FROM_TORQUES = {layer.loads_from_torques!r}  # the scene states torques",
    ]
    return lines


def physical_lines(model) -> list[str]:
    """The functions ``_physical``, ``_physical_parameters`` and ``scales``."""
    layer = model.physical
    names = {s: f"q[{k}]" for k, s in enumerate(layer.symbols)} | {layer.zeta: "zeta"}
    printer = CodePrinter("np", names)
    index = {n: k for k, n in enumerate(model.parameter_names)}
    omega = index[model.forcing_frequency]

    def block(exprs: dict, indent: str) -> list[str]:
        if not exprs:
            return []
        keys = list(exprs)
        reps, reduced = sp.cse(
            [exprs[k] for k in keys], symbols=sp.numbered_symbols("_w"), order="canonical"
        )
        out = [f"{indent}{s.name} = {printer.doprint(e)}" for s, e in reps]
        for k, e in zip(keys, reduced, strict=True):
            out.append(f"{indent}p[{index[k]}] = {printer.doprint(e)}  # {text(k)}")
        return out

    phase_lines = []
    quantity = {q.name: k for k, q in enumerate(layer.quantities)}
    for name, (teeth, q) in layer.phases.items():
        phase_lines.append(
            f"    _z = {teeth!r} * q[{quantity[q]}] / 360.0  # teeth of the shared gear spanned"
        )
        phase_lines.append(
            f"    p[{index[name]}] = 2.0 * np.pi * (_z - np.floor(_z))  # {text(name)}"
        )
    scale_keys = list(layer.scales)
    reps, reduced = sp.cse(
        [layer.scales[k] for k in scale_keys], symbols=sp.numbered_symbols("_w"), order="canonical"
    )
    return [
        "",
        "def _physical(values):",
        '    """The physical quantities in effect (PHYSICAL order) and the names given, or',
        "    (None, set()) when none is given; aliases apply first, a name given beside its",
        '    alias wins; a quantity given beside what it replaces is refused."""',
        "    given = {}",
        "    for k, v in values.items():",
        "        for name in PHYSICAL_ALIASES.get(k, ()):",
        "            given.setdefault(name, (k, v))",
        "    for k, v in values.items():",
        "        if k in PHYSICAL:",
        "            given[k] = (k, v)",
        "    if not given:",
        "        return None, set()",
        "    for name, (key, _) in given.items():",
        "        for other in PHYSICAL_REPLACES.get(name, ()):",
        "            if other in values:",
        "                raise ValueError(f'{key} and {other} both set: they state the same '",
        "                                 f'quantity, one physically, one not; set one of them')",
        "    q = [v[0] for v in PHYSICAL.values()]",
        "    names = list(PHYSICAL)",
        "    for name, (key, v) in given.items():",
        "        v = float(v)",
        "        low, high, low_open = PHYSICAL_LIMITS[name]",
        "        if not np.isfinite(v) or v < low or (low_open and v == low) or (",
        "                high is not None and v > high):",
        "            rule = (f'in ({low:g}, {high:g}]' if low_open else f'in [{low:g}, {high:g}]')",
        "            raise ValueError(f'{key} must be {rule} {PHYSICAL[name][1]}, got {v:g}')",
        "        q[names.index(name)] = v",
        "    return q, set(given)",
        "",
        "",
        "def _physical_parameters(p, q, s, given):",
        '    """The model parameters from the physical quantities q (closed forms)."""',
        "    zeta = s['damping_ratio']",
        *block(layer.always, "    "),
        *phase_lines,
        "    if OMEGA_FROM_SPEED or 'speed_rpm' in given:",
        *block(layer.speed, "        "),
        *(
            [
                "    if LOADS_FROM_TORQUES or any(n.startswith('torque_Nm_') for n in given):",
                *block(layer.loads, "        "),
            ]
            if layer.loads
            else []
        ),
        "",
        "",
        "def scales(**values):",
        '    """Scales back to physical units with these values: omega_n (rad/s), each mesh',
        "    coordinate's half backlash (m) and mean stiffness (N/m), and the speed in effect",
        '    (rpm of the operating gear, from omega)."""',
        "    q, _ = _physical(values)",
        "    q = q if q is not None else [v[0] for v in PHYSICAL.values()]",
        *(f"    {s.name} = {printer.doprint(e)}" for s, e in reps),
        "    out = {",
        *(
            f"        {k!r}: float({printer.doprint(e)}),"
            for k, e in zip(scale_keys, reduced, strict=True)
        ),
        "    }",
        f"    omega = parameters(**values)[{omega}]",
        "    out['mesh_frequency_hz'] = float(omega * out['omega_n_rad_per_s'] / (2.0 * np.pi))",
        f"    out['speed_rpm'] = float(omega * out['omega_n_rad_per_s'] / "
        f"{float(layer.mesh_rad_per_rpm)!r})",
        f"    out['speed_gear'] = {layer.speed_gear!r}",
        "    return out",
        "",
    ]
