"""The audit page's section on the physical quantities a user sets (``derive/physical.py``).

It lists each quantity with its default, unit and meaning, says which symbols of the
closed forms above it replaces, and states what the scene holds when one changes.
"""

from __future__ import annotations

from ..escape import markdown

__all__ = ["physical_section"]


def physical_section(model) -> str:
    """Markdown: the physical quantities of ``model`` and how they enter its parameters."""
    layer = model.physical
    if layer is None:
        return ""
    out = [
        "### Physical quantities\n",
        "A user sets these by name (`--set`, `sweep --param`, `map --x`, the API's keyword "
        "values) with no new derivation: the generated `parameters()` evaluates the closed "
        "forms above with them -- $\\omega_n$, $K_{ij}$, $\\xi_{ij}$ and $f_i$ from the "
        "inertias $I_k$ (gear plus attached), torques $T_k$, half backlashes $b_i$ and mean "
        "stiffnesses $k_{m,i}$ (times the stiffness scale); "
        "$\\bar\\omega = z\\,n\\,\\pi/30/\\omega_n$ from the speed $n$; "
        "$E_{i1} = e_{i1}/b_i$; the layout phase $2\\pi\\,\\mathrm{frac}(z\\psi/360)$. "
        + (
            "The scene states $\\bar\\omega$, which is held when an inertia or a stiffness "
            "changes (the speed follows); setting `speed_rpm` states the speed instead. "
            if not layer.omega_from_speed
            else "The scene states the speed; $\\bar\\omega$ follows from it. "
        )
        + (
            "The scene's loads are non-dimensional and held; setting any `torque_Nm_<gear>` "
            "takes every load from the torques, whose defaults are the steady torques that "
            "give the scene's loads (no power into the rigid-body rotation). "
            if not layer.loads_from_torques
            else ""
        )
        + _operating(model)
        + "Setting a quantity and what it replaces (`omega` beside `speed_rpm`, say) is "
        "refused.\n",
        "| name | default | unit | meaning | replaces |",
        "|---|---|---|---|---|",
    ]
    for q in layer.quantities:
        replaced = ", ".join(f"`{r}`" for r in layer.replaces.get(q.name, ()))
        name, unit, meaning = markdown(q.name, code=True), markdown(q.unit), markdown(q.meaning)
        out.append(f"| `{name}` | {q.value:.10g} | {unit} | {meaning} | {replaced} |")
    if layer.aliases:
        out.append("")
        out.append(
            "Aliases: "
            + "; ".join(
                f"`{a}` sets " + ", ".join(f"`{n}`" for n in names)
                for a, names in layer.aliases.items()
            )
            + ".\n"
        )
    return "\n".join(out) + "\n"


def _operating(model) -> str:
    """A sentence when the scene's omega sets a speed other than the topology's own."""
    operating = model.scene.topology.operating
    if operating is None or model.physical.omega_from_speed:
        return ""
    rpm = operating.speed * 30.0 / 3.141592653589793
    speed = model.physical.quantities[0].value
    return (
        f"Here $\\bar\\omega$ = {model.scene_parameters['omega']:g} is {speed:.6g} rpm of gear "
        f"'{markdown(operating.gear)}'; the topology's `[operating]` speed, {rpm:g} rpm, "
        "applies only when the topology is derived on its own. "
    )
