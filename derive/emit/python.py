"""Emit a Model as Python source: NumPy right-hand side and Jacobian, and CasADi builders.

The module written to ``generated/<name>.py`` needs only NumPy (CasADi is imported by
:func:`casadi_functions` when called).  It announces the command that made it and the
sha256 of its inputs, documents the state and parameter order, states what a solver needs
to know as the literal ``CONTRACT`` (:attr:`Model.contract`), and is written to a
temporary name and renamed so that a reader never sees half a file.

Both back ends print the same common-subexpression-eliminated SymPy expressions through
one printer that differs only in its namespace (``np`` or ``ca``) and in how a
``Piecewise`` is written (``np.where`` or ``ca.if_else``).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import sympy as sp
from sympy.printing.str import StrPrinter

from ..equations.structure import physical_data
from ..escape import code_name, code_names, text
from ..input.scene import PARAMETER_LIMITS
from ..model import Model, operation_count  # operation_count re-exported
from .c import c_source

__all__ = ["CodePrinter", "emit_module", "operation_count", "write_atomic"]


class CodePrinter(StrPrinter):
    """Python source for an expression, with functions from namespace ``ns`` and each
    model symbol printed as its namespaced identifier (``names``: ``escape.code_names``)."""

    _FUNCTIONS = ("sin", "cos", "tan", "exp", "log", "sqrt")

    def __init__(self, ns: str, names: dict | None = None):
        super().__init__({"full_prec": True})
        self.ns = ns
        self.names = names or {}

    def _print_Symbol(self, expr):
        return self.names.get(expr, expr.name)

    def _print_Function(self, expr):
        name = expr.func.__name__
        if name not in self._FUNCTIONS:
            raise ValueError(f"no code printer for function {name}")
        return f"{self.ns}.{name}({', '.join(self._print(a) for a in expr.args)})"

    _print_sin = _print_cos = _print_tan = _print_exp = _print_log = _print_Function

    def _print_Abs(self, expr):
        fn = "abs" if self.ns == "np" else "fabs"
        return f"{self.ns}.{fn}({self._print(expr.args[0])})"

    def _print_Pow(self, expr, rational=False):
        base, exp = expr.args
        if exp == sp.S.Half:
            return f"{self.ns}.sqrt({self._print(base)})"
        if exp == -sp.S.Half:
            return f"1/{self.ns}.sqrt({self._print(base)})"
        return super()._print_Pow(expr, rational)

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Rational(self, expr):
        return f"({expr.p}/{expr.q})"

    def _print_Relational(self, expr):
        return f"({self._print(expr.lhs)} {expr.rel_op} {self._print(expr.rhs)})"

    def _print_Piecewise(self, expr):
        where = "np.where" if self.ns == "np" else "ca.if_else"
        *pairs, (last, cond) = expr.args
        if cond != sp.true:
            raise ValueError("a Piecewise needs a final 'otherwise' branch")
        out = self._print(last)
        for value, cond in reversed(pairs):
            out = f"{where}({self._print(cond)}, {self._print(value)}, {out})"
        return out


def _body(model: Model, outputs, printer: CodePrinter, indent: str = "    ") -> tuple[list, list]:
    """Lines unpacking states/parameters and computing CSE temporaries; printed outputs."""
    replacements, reduced = sp.cse(
        list(outputs), symbols=sp.numbered_symbols("_t"), order="canonical"
    )
    used = (
        set().union(*(e.free_symbols for _, e in replacements), *(e.free_symbols for e in reduced))
        if (replacements or reduced)
        else set()
    )
    lines = []
    for k, s in enumerate(model.state_symbols):
        if s in used:
            lines.append(f"{indent}{printer.doprint(s)} = x[{k}]")
    for k, s in enumerate(model.parameter_symbols):
        if s in used:
            lines.append(f"{indent}{printer.doprint(s)} = p[{k}]")
    for sym, expr in replacements:
        lines.append(f"{indent}{sym.name} = {printer.doprint(expr)}")
    return lines, [printer.doprint(e) for e in reduced]


def _stiffness_terms(names) -> dict:
    """``{coordinate: ((kc index, ks index, order), ...)}`` from the parameter names
    ``kc_<coordinate>_<order>`` and ``ks_<coordinate>_<order>``."""
    import re

    out: dict = {}
    for i, name in enumerate(names):
        m = re.fullmatch(r"kc_(.+)_(\d+)", name)
        if m and f"ks_{m[1]}_{m[2]}" in names:
            out.setdefault(m[1], []).append((i, names.index(f"ks_{m[1]}_{m[2]}"), int(m[2])))
    return {c: tuple(t) for c, t in out.items()}


def _stiffness_check_lines(terms) -> list[str]:
    """The generated check that each mesh's stiffness stays positive over its cycle
    (nothing when the model has no stiffness harmonics)."""
    if not terms:
        return [""]
    return [
        "",
        "_STIFFNESS_CHECKED = set()  # harmonics already found positive: sweeps repeat them",
        "",
        "",
        "def _check_stiffness(p):",
        '    """A mesh stiffness k_hat(tau) that is negative somewhere in its cycle is not',
        '    physical: refuse it with the value (721 phases per mesh period)."""',
        "    key = tuple(p[k] for t in STIFFNESS_TERMS.values() for i, j, _ in t for k in (i, j))",
        "    if key in _STIFFNESS_CHECKED:",
        "        return",
        "    theta = np.linspace(0.0, 2.0 * np.pi, 721)",
        "    for c, terms in STIFFNESS_TERMS.items():",
        "        k = 1.0 + sum(p[i] * np.cos(n * theta) + p[j] * np.sin(n * theta)",
        "                      for i, j, n in terms)",
        "        if np.min(k) <= 0.0:",
        "            m = int(np.argmin(k))",
        "            raise ValueError(",
        "                f'the stiffness of mesh {c} falls to {k[m]:.3g} times its mean at mesh '",
        "                f'phase {np.degrees(theta[m]):.0f} deg (harmonics '",
        "                + ', '.join(PARAMETERS[i][3:] for i, _, _ in terms)",
        "                + '): a negative stiffness is not physical; use smaller harmonics')",
        "    _STIFFNESS_CHECKED.add(key)",
        "",
        "",
    ]


def _docstring(model: Model, command: str) -> str:
    scene = model.scene
    feats = model.features
    lines = [
        f"{model.name}: non-dimensional equations of motion of scene '{scene.name}'.",
        "",
        f"Generated by `{command}`; do not edit.",
        "",
        "    u_i'' + sum_j 2 xi_ij u_j' + sum_j kappa_ij(tau) g(u_j) = f_i + ebar_i''(tau)",
        "",
        "written as the first-order system dX/dtau = rhs(tau, X, p).",
        "",
        "States (in order):",
    ]
    n_disp = len(model.displacements)
    for k, s in enumerate(model.states):
        if k < len(model.coordinates):
            mesh = scene.topology.meshes[k]
            what = (
                f"mesh {mesh.id} ({mesh.driver} -> {mesh.driven}) deflection along the "
                "line of action / half backlash"
            )
        elif k < n_disp:
            c = model.structure.coordinates[k]
            what = (
                f"shaft {c.owner}: twist / (b_1 / r_b)"
                if c.kind == "shaft"
                else f"gear {c.owner}: {c.kind} translation / b_1"
            )
        else:
            what = f"d({model.displacements[k - n_disp]})/dtau"
        lines.append(f"    {k:2d}  {s:<6} {what}")
    lines += ["", "Parameters (in order; default = the scene's value):"]
    for k, p in enumerate(model.parameters):
        lines.append(f"    {k:2d}  {p.name:<12} {p.value: .15g}  {p.meaning}")
    b = feats.backlash
    lines += [
        "",
        "Features: "
        f"stiffness harmonics {feats.stiffness_harmonics}; backlash {b.kind}"
        + (f" (valid for |u| <= {b.valid_range:g})" if b.valid_range is not None else "")
        + f"; transmission error {'on' if feats.transmission_error else 'off'}"
        f"; mesh phase {'on' if feats.mesh_phase else 'off'}"
        f"; damping coupling {'on' if feats.damping_coupling else 'off'}"
        + (
            ""
            if feats.degrees_of_freedom == "torsional"
            else f"; degrees of freedom {feats.degrees_of_freedom}"
        )
        + ".",
        f"Time: tau = omega_n t, omega_n = {model.scales['omega_n_rad_per_s']:.10g} rad/s.",
        "",
        "CONTRACT states as data what a solver needs: velocity indices, forcing frequency,",
        "loads, contact edges, piecewise or smooth, switching surfaces, valid range.",
        "",
        "Model symbols are namespaced in the code: state or parameter NAME is "
        f"{code_name('NAME')}.",
    ]
    # Names, paths and meanings are the user's text: escaped, so that none can end the
    # docstring or a line (derive/escape.py).
    return "\n".join(text(line) for line in lines)


def emit_module(model: Model, command: str) -> str:
    """Source text of ``generated/<name>.py`` for ``model``."""
    names = code_names((*model.state_symbols, *model.parameter_symbols))
    np_printer, ca_printer = CodePrinter("np", names), CodePrinter("ca", names)
    rhs = list(model.rhs)
    jac = list(model.jacobian)
    n, m_par = len(model.states), len(model.parameters)
    rhs_lines, rhs_out = _body(model, rhs, np_printer)
    jac_lines, jac_out = _body(model, jac, np_printer)
    ca_lines, ca_out = _body(model, rhs, ca_printer)
    force_lines, force_out = _body(model, list(model.mesh_forces), np_printer)
    m_mesh = len(model.displacements)
    static_lines, static_out = _body(
        model, list(model.static_kappa) + list(model.loads), np_printer
    )
    static_rows = ", ".join(
        "[" + ", ".join(static_out[i * m_mesh : (i + 1) * m_mesh]) + "]" for i in range(m_mesh)
    )
    static_loads = ", ".join(static_out[m_mesh * m_mesh :])
    damping_note = (
        "elastic k_hat(tau) g(u) plus viscous c u' (one damper per mesh)"
        if model.nondim.damping == "mesh"
        else "elastic k_hat(tau) g(u) only (modal damping couples the meshes)"
    )

    def fmt(v: float) -> str:
        # 15 significant digits: independent of the last-bit noise of LAPACK builds.
        return repr(float(f"{v:.15g}"))

    defaults = ",\n    ".join(fmt(p.value) for p in model.parameters)
    stiffness_terms = _stiffness_terms(model.parameter_names)
    scales = model.scales
    valid = model.valid_range
    jac_rows = ",\n        ".join(
        "(" + ", ".join(jac_out[i * n : (i + 1) * n]) + ",)" for i in range(n)
    )
    c_plain, c_variational = c_source(model), c_source(model, variational=True)
    for c_text in (c_plain, c_variational):  # it goes into r"""...""": nothing may end it
        if '"""' in c_text or c_text.rstrip("\n").endswith("\\"):
            raise ValueError("the C source cannot be held in a raw triple-quoted string")
    src = [
        f"# Generated by `{text(command)}`; do not edit.",
        f"# inputs-sha256: {model.inputs_hash}",
        '"""' + _docstring(model, command) + '\n"""',
        "",
        "import numpy as np",
        "",
        f"NAME = {model.name!r}",
        f"SCENE = {model.scene.name!r}",
        f"INPUTS_SHA256 = {model.inputs_hash!r}",
        f"STATES = {tuple(model.states)!r}",
        f"COORDINATES = {tuple(model.coordinates)!r}",
        f"PARAMETERS = {tuple(model.parameter_names)!r}",
        f"DEFAULTS = (\n    {defaults},\n)",
        f"VALID_RANGE = {valid!r}  # |coordinate| bound of the backlash model, None if global",
        f"OMEGA_N = {fmt(scales['omega_n_rad_per_s'])}  # rad/s; tau = OMEGA_N * t",
        "HALF_BACKLASH = {"
        + ", ".join(f"{k!r}: {fmt(v)}" for k, v in scales["half_backlash_m"].items())
        + "}  # m",
        f"FEATURES = {model.features.flags()!r}",
        "SCENE_PARAMETERS = {"
        + ", ".join(f"{k!r}: {fmt(v)}" for k, v in model.scene_parameters.items())
        + "}",
        "# (low, high, low excluded): derive/input/scene.py PARAMETER_LIMITS",
        "SCENE_PARAMETER_LIMITS = {"
        + ", ".join(
            f"{k!r}: {v!r}" for k, v in PARAMETER_LIMITS.items() if k in model.scene_parameters
        )  # fmt: skip
        + "}",
        "# mesh coordinate: ((cos index, sin index, harmonic), ...) of k_hat = 1 + sum ...",
        f"STIFFNESS_TERMS = {stiffness_terms!r}",
        f"OPERATIONS = {model.operations!r}",
        "",
        "# What a solver needs to know about this model, as plain data (Model.contract in",
        "# derive/model.py); solvers read this, never the source or the names.",
        "CONTRACT = {",
        *(f"    {k!r}: {v!r}," for k, v in model.contract.items()),
        "}",
        "",
        "# The linear, time-averaged model in physical coordinates, for the modal analysis",
        "# (derive/equations/structure.py physical_data; solver/analysis/modes.py).",
        "STRUCTURE = {",
        *(f"    {k!r}: {v!r}," for k, v in physical_data(model).items()),
        "}",
        "",
        "# The right-hand side in C for the compiled integrators (solver/integrate/native/).",
        'C_SOURCE = r"""',
        c_plain.rstrip("\n"),
        '"""',
        "",
        "# The same with the variational equations (x, w)' = (F, J w), for Lyapunov exponents.",
        'C_SOURCE_VARIATIONAL = r"""',
        c_variational.rstrip("\n"),
        '"""',
        "",
        "",
        "def rhs(tau, x, p):",
        '    """dX/dtau.  x: (n,) or (n, N); p: (P,) or (P, N); result (n,) or (n, N)."""',
        *rhs_lines,
        "    return np.array(np.broadcast_arrays(",
        *(f"        {o}," for o in rhs_out),
        "    ))",
        "",
        "",
        "def parameters(**values):",
        '    """Parameter vector p from named values; the rest keep the scene\'s values.',
        "",
        "    Names may be scene parameters (SCENE_PARAMETERS: what the scene's [parameters]",
        "    table sets, such as a load ratio) or model parameters (PARAMETERS); a model",
        "    parameter given by name overrides what the scene parameters imply.",
        '    """',
        "    unknown = sorted(set(values) - set(SCENE_PARAMETERS) - set(PARAMETERS))",
        "    if unknown:",
        "        raise KeyError(f'unknown parameter(s) {unknown}; scene parameters: '",
        "                       f'{sorted(SCENE_PARAMETERS)}; model parameters: '",
        "                       f'{list(PARAMETERS)}')",
        "    s = dict(SCENE_PARAMETERS)",
        "    s.update((k, float(v)) for k, v in values.items() if k in SCENE_PARAMETERS)",
        "    for k, v in s.items():",
        "        if not np.isfinite(v):",
        "            raise ValueError(f'{k} = {v} is not a finite number')",
        "        if k in SCENE_PARAMETER_LIMITS:",
        "            low, high, low_open = SCENE_PARAMETER_LIMITS[k]",
        "            if v < low or (low_open and v == low) or (high is not None and v > high):",
        "                rule = f'in [{low:g}, {high:g}]' if high is not None else (",
        "                    f'> {low:g}' if low_open else f'>= {low:g}')",
        "                raise ValueError(f'{k} must be {rule}, got {v:g}')",
        "    p = list(DEFAULTS)",
        *(
            f"    p[{model.parameter_names.index(k)}] = {src}  # {text(k)}"
            for k, src in model.parameter_sources.items()
        ),
        "    for k, v in values.items():",
        "        if k in PARAMETERS and k not in SCENE_PARAMETERS:",
        "            p[PARAMETERS.index(k)] = float(v)",
        *(["    _check_stiffness(p)"] if stiffness_terms else []),
        "    return np.array(p, dtype=float)",
        "",
        *_stiffness_check_lines(stiffness_terms),
        "def jacobian(tau, x, p):",
        '    """d rhs / d X, shape (n, n) or (n, n, N)."""',
        *jac_lines,
        "    return np.array(_broadcast(",
        f"        {jac_rows},",
        "    ))",
        "",
        "",
        "def mesh_force(tau, x, p):",
        f'    """Dynamic force of each mesh over its k_m b: {damping_note}; (m,) or (m, N)."""',
        *force_lines,
        "    return np.array(np.broadcast_arrays(",
        *(f"        {o}," for o in force_out),
        "    ), dtype=float)",
        "",
        "",
        "def static_mesh_force(p):",
        '    """Static force of each mesh over its k_m b: kappa F = f at the mean stiffness."""',
        *static_lines,
        f"    K = np.array([{static_rows}], dtype=float)",
        f"    f = np.array([{static_loads}], dtype=float)",
        "    return np.linalg.solve(K, f)"
        + ("" if m_mesh == len(model.coordinates) else f"[:{len(model.coordinates)}]"),
        "",
        "",
        "def _broadcast(*rows):",
        "    flat = np.broadcast_arrays(*(e for row in rows for e in row))",
        "    n = len(rows)",
        "    return [flat[i * n:(i + 1) * n] for i in range(n)]",
        "",
        "",
        "def casadi_functions():",
        '    """CasADi SX functions ``rhs(tau, x, p)`` and ``jacobian(tau, x, p)`` (AD)."""',
        "    import casadi as ca",
        "",
        "    tau = ca.SX.sym('tau')",
        f"    x = ca.SX.sym('x', {n})",
        f"    p = ca.SX.sym('p', {m_par})",
        *ca_lines,
        "    xdot = ca.vertcat(",
        *(f"        {o}," for o in ca_out),
        "    )",
        "    f = ca.Function('rhs', [tau, x, p], [xdot], ['tau', 'x', 'p'], ['xdot'])",
        "    j = ca.Function('jacobian', [tau, x, p], [ca.jacobian(xdot, x)],",
        "                    ['tau', 'x', 'p'], ['jac'])",
        "    return f, j",
        "",
    ]
    return "\n".join(src)


def write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file in the same folder and a rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(text)
        # mkstemp makes the file private (0600); give it the mode a plain write would.
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
