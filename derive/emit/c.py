"""Emit a Model's right-hand side as C for the compiled integrators (``solver/integrate/native/``).

The same SymPy expressions as the NumPy and CasADi code, rewritten for speed:

* every ``cos``/``sin`` of ``n w tau + B`` (``n`` an integer, ``w`` and ``B`` free of ``tau``)
  becomes a polynomial in ``cos(w tau)``, ``sin(w tau)`` (one pair per distinct ``w``, the
  harmonics by the angle-addition recurrence) and ``cos B``, ``sin B``, which depend on the
  parameters only and are computed once per parameter set by ``gs_prep``;
* common subexpressions are eliminated and small integer powers are multiplications.

The C text defines ``GS_NX``, ``GS_NP``, ``GS_NQ``, ``gs_prep(p, q)`` and
``gs_rhs(tau, x, p, q, dx)``; it is stored in the generated module as ``C_SOURCE``.
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.c import C99CodePrinter

from ..escape import code_names, text
from ..model import Model

__all__ = ["c_source"]


class _Printer(C99CodePrinter):
    """C99 with each model symbol as its namespaced identifier (``escape.code_names``):
    a coordinate called ``int``, ``q`` or ``NAN`` cannot collide with C or with the host
    file's own names."""

    def __init__(self, names: dict | None = None):
        super().__init__()
        self.names = names or {}

    def _print_Symbol(self, expr):
        if expr in self.names:
            return self.names[expr]
        return super()._print_Symbol(expr)

    def _print_Pow(self, expr):
        base, exp = expr.args
        if exp.is_Integer and 2 <= int(exp) <= 8:
            b = self._print(base)
            return "(" + "*".join([f"({b})"] * int(exp)) + ")"
        if exp.is_Integer and -8 <= int(exp) <= -1:
            return f"(1.0/({self._print(sp.Pow(base, -exp))}))"
        return super()._print_Pow(expr)

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Piecewise(self, expr):
        *pairs, (last, cond) = expr.args
        if cond != sp.true:
            raise ValueError("a Piecewise needs a final 'otherwise' branch")
        out = f"({self._print(last)})"
        for value, c in reversed(pairs):
            out = f"(({self._print(c)}) ? ({self._print(value)}) : {out})"
        return out

    def _print_Rational(self, expr):
        return f"({float(expr.p)!r}/{float(expr.q)!r})"


def _reduce_trig(exprs, tau, params, omega):
    """Replace trig atoms by recurrence symbols; return (exprs, bases, q_defs).

    Only what is safe is rewritten: an argument ``n w tau + B`` whose frequency ``w``
    depends on ``omega`` alone (so that points sharing omega share the excitation) and whose
    phase ``B`` on parameters alone (hoisted into ``q``); anything else (a state inside a
    sine, a frequency set by another parameter) is printed as it is."""
    params = set(params)
    atoms = set().union(*(e.atoms(sp.sin, sp.cos) for e in exprs))
    bases: dict = {}  # w -> (index, max harmonic)
    q_defs: dict = {}  # parameter-only expression -> symbol
    replace = {}

    def q(expr):
        if expr not in q_defs:
            q_defs[expr] = sp.Symbol(f"q[{len(q_defs)}]")
        return q_defs[expr]

    def harmonic(w, k):
        idx, top = bases.get(w, (len(bases), 0))
        bases[w] = (idx, max(top, k))
        return sp.Symbol(f"C{idx}_{k}"), sp.Symbol(f"S{idx}_{k}")

    for atom in sorted(atoms, key=sp.default_sort_key):
        arg = sp.expand(atom.args[0])
        if not arg.free_symbols <= params | {tau}:
            continue  # depends on a state: computed where it stands
        if tau not in arg.free_symbols:
            replace[atom] = q(atom)
            continue
        a = sp.Add(*[t for t in sp.Add.make_args(arg) if tau in t.free_symbols])
        b = arg - a
        coeff = sp.simplify(a / tau)
        if tau in coeff.free_symbols:
            continue  # not linear in tau: printed as it is
        n, w = coeff.as_coeff_Mul()
        if not (n.is_Integer and n != 0):
            n, w = sp.Integer(1), coeff
        if not w.free_symbols <= {omega}:
            continue  # a frequency set by another parameter: not shared by a group
        k, sign = abs(int(n)), (1 if n > 0 else -1)
        c_a, s_a = harmonic(w, k)
        s_a = sign * s_a
        if b == 0:
            replace[atom] = c_a if isinstance(atom, sp.cos) else s_a
            continue
        c_b, s_b = q(sp.cos(b)), q(sp.sin(b))
        if isinstance(atom, sp.cos):
            replace[atom] = c_a * c_b - s_a * s_b
        else:
            replace[atom] = s_a * c_b + c_a * s_b
    return [e.xreplace(replace) for e in exprs], bases, q_defs


def _harmonic_lines(bases, printer, substitute=None) -> list[str]:
    """``cos``/``sin`` of ``k w tau`` for each base frequency ``w``: one pair by the library,
    the higher harmonics by the angle-addition recurrence."""
    lines = []
    for w, (idx, top) in sorted(bases.items(), key=lambda kv: kv[1][0]):
        freq = w.xreplace(substitute) if substitute else w
        lines.append(f"    const double th{idx} = ({printer.doprint(freq)})*tau;")
        lines.append(f"    const double C{idx}_1 = cos(th{idx}), S{idx}_1 = sin(th{idx});")
        for k in range(2, top + 1):
            lines.append(
                f"    const double C{idx}_{k} = C{idx}_{k - 1}*C{idx}_1 - S{idx}_{k - 1}*S{idx}_1;"
            )
            lines.append(
                f"    const double S{idx}_{k} = S{idx}_{k - 1}*C{idx}_1 + C{idx}_{k - 1}*S{idx}_1;"
            )
    return lines


def c_source(model: Model, variational: bool = False) -> str:
    """C text of ``gs_prep`` and ``gs_rhs`` for ``model``; with ``variational`` for the
    state extended by a tangent vector ``w``: ``(x, w)' = (F(tau, x), J(tau, x) w)``."""
    printer = _Printer(code_names((*model.state_symbols, *model.parameter_symbols)))
    tau = (
        next(s for e in model.rhs for s in e.free_symbols if s.name == "tau")
        if any(s.name == "tau" for e in model.rhs for s in e.free_symbols)
        else sp.Symbol("tau")
    )
    states = list(model.state_symbols)
    exprs = list(model.rhs)
    if variational:
        n0 = len(states)
        w = [sp.Symbol(f"w{i}") for i in range(n0)]
        jac = list(model.jacobian)
        exprs += [sp.Add(*[jac[i * n0 + j] * w[j] for j in range(n0)]) for i in range(n0)]
        states += w
    omega = next((s for s in model.parameter_symbols if s.name == "omega"), None)
    exprs, bases, q_defs = _reduce_trig(exprs, tau, model.parameter_symbols, omega)
    n, m = len(states), len(model.parameters)
    params = {s: k for k, s in enumerate(model.parameter_symbols)}

    def unpack(symbols, used, indent="    "):
        return [
            f"{indent}const double {printer.doprint(s)} = p[{params[s]}];"
            for s in symbols
            if s in used
        ]

    prep_used = set().union(*(e.free_symbols for e in q_defs)) if q_defs else set()
    what = " with the variational equations" if variational else ""
    lines = [
        f"/* {text(model.name)}: right-hand side{what} for the compiled integrators "
        "(gearsym derive). */",
        f"#define GS_NX {n}",
        f"#define GS_NP {m}",
        f"#define GS_NQ {max(len(q_defs), 1)}",
        "",
        "static void gs_prep(const double *p, double *q)",
        "{",
        *unpack(model.parameter_symbols, prep_used),
        *(f"    {sym.name} = {printer.doprint(e)};" for e, sym in q_defs.items()),
        "    (void)p; (void)q;",
        "}",
        "",
        "static inline void gs_rhs(double tau, const double *x, const double *p, "
        "const double *q, double *dx)",
        "{",
    ]
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("t_"), order="canonical")
    used = set().union(
        *(e.free_symbols for _, e in replacements), *(e.free_symbols for e in reduced)
    )
    for k, s in enumerate(states):
        if s in used:
            lines.append(f"    const double {printer.doprint(s)} = x[{k}];")
    base_used = set()
    for w in bases:
        base_used |= w.free_symbols
    lines += unpack(model.parameter_symbols, used | base_used)
    lines += _harmonic_lines(bases, printer)
    for sym, e in replacements:
        lines.append(f"    const double {sym.name} = {printer.doprint(e)};")
    for k, e in enumerate(reduced):
        lines.append(f"    dx[{k}] = {printer.doprint(e)};")
    lines += ["    (void)tau; (void)p; (void)q;", "}", ""]
    # Batched form for lockstep integration: n points in structure-of-arrays layout
    # (X[i*n + j] is state i of point j); the excitation terms are computed once for all
    # points (they share the time and, by contract, the frequencies), the rest vectorises.
    lines += [
        "static void gs_rhs_batch(double tau, int n, const double *restrict X, "
        "const double *restrict P, const double *restrict Q, double *restrict DX)",
        "{",
    ]
    first = {s: sp.Symbol(f"P[{params[s]}*n]") for s in model.parameter_symbols}
    lines += _harmonic_lines(bases, printer, first)
    lines += ["#pragma GCC ivdep", "    for (int j = 0; j < n; ++j) {"]
    if q_defs:
        lines.append("        double q[GS_NQ];")
        lines.append("        for (int k = 0; k < GS_NQ; ++k) q[k] = Q[k*n + j];")
    for k, s in enumerate(states):
        if s in used:
            lines.append(f"        const double {printer.doprint(s)} = X[{k}*n + j];")
    for s in model.parameter_symbols:
        if s in used:
            lines.append(f"        const double {printer.doprint(s)} = P[{params[s]}*n + j];")
    for sym, e in replacements:
        lines.append(f"        const double {sym.name} = {printer.doprint(e)};")
    for k, e in enumerate(reduced):
        lines.append(f"        DX[{k}*n + j] = {printer.doprint(e)};")
    lines += ["    }", "    (void)tau; (void)P; (void)Q;", "}", ""]
    return "\n".join(lines)
