"""Emit a Model's right-hand side as C for the compiled integrators (``solver/integrate/native/``).

The same SymPy expressions as the NumPy and CasADi code, rewritten for speed:

* every ``cos``/``sin`` of ``n w tau + B`` (``n`` an integer, ``w`` and ``B`` free of ``tau``)
  becomes a polynomial in ``cos(w tau)``, ``sin(w tau)`` (one pair per distinct ``w``, the
  harmonics by the angle-addition recurrence) and ``cos B``, ``sin B``, which depend on the
  parameters only and are computed once per parameter set by ``gs_prep``;
* common subexpressions are eliminated and small integer powers are multiplications;
* in the batched form, the terms free of the states are computed off the per-point path
  (:class:`_Hoist`): those of the parameters alone once per point by ``gs_prep``, those of
  the time once per call for the whole batch when the parameters they read are shared.

The C text defines ``GS_NX``, ``GS_NP``, ``GS_NQ``, ``gs_prep(p, q)``,
``gs_rhs(tau, x, p, q, dx)`` and ``gs_rhs_batch(tau, n, X, P, Q, DX)``; it is stored in the
generated module as ``C_SOURCE``.
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.c import C99CodePrinter

from ..escape import code_names
from ..model import Model

__all__ = ["c_source"]


class _Printer(C99CodePrinter):
    """C99 with each model symbol as its namespaced identifier (``escape.code_names``):
    a coordinate called ``int``, ``q`` or ``NAN`` cannot collide with C or with the host
    file's own names."""

    def __init__(self, names: dict | None = None):
        super().__init__()
        self.names = names or {}
        self.hoist: _Hoist | None = None  # set while printing gs_rhs_batch and gs_prep
        self.where = "loop"  # "loop" (per point), "pre" (before the loop) or "prep"
        self.mode = "off"  # which terms become hoisted symbols: "off", "q" or "all"
        self.seen: set = set()  # model symbols printed in the loop
        self._top = False  # the next node is a definition's own: printed, not replaced

    def text(self, expr, where: str, mode: str, top: bool = False) -> str:
        """``expr`` printed for ``where`` with the terms ``mode`` names replaced by their
        hoisted symbols (``top``: not ``expr`` itself, whose definition this is)."""
        self.where, self.mode, self._top = where, mode, top
        try:
            return self.doprint(expr)
        finally:
            self.mode, self._top = "off", False

    def _print(self, expr, **kwargs):
        if self.mode != "off" and not self._top:
            sym = self.hoist.unit(expr, tau=self.mode == "all")
            if sym is not None:
                return self._print_Symbol(sym)
        self._top = False
        return super()._print(expr, **kwargs)

    def _print_Symbol(self, expr):
        if self.hoist is not None:
            expr = self.hoist.alias.get(expr, expr)
            if self.where == "pre" and expr in self.hoist.pre_names:
                return self.hoist.pre_names[expr]
        if expr in self.names:
            if self.where == "loop":
                self.seen.add(expr)
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


def _trivial(expr) -> bool:
    """A symbol, a number or its negation: nothing to compute, nothing to hoist."""
    return expr.is_Atom or (
        expr.is_Mul and len(expr.args) == 2 and expr.args[0] == -1 and expr.args[1].is_Atom
    )


class _Hoist:
    """The terms of ``gs_rhs_batch`` that its loop over points need not compute.

    Each symbol is classified by what it depends on (``deps``: a state, the time, the set
    of parameter indices ``k``, as in ``P[k*n + j]``); a term free of the states is a
    *Q unit* ``q[i]`` when it reads parameters only (run once per point by ``gs_prep``
    into ``Q``), a *tau unit* ``h_i`` when it reads the time too (the stiffness and
    transmission-error harmonics at the step's time with their coefficients): computed
    once per call before the loop when every ``k`` it reads is declared shared
    (``-DGS_SHARED_k=1``), in the loop otherwise.  Units are found top-down while printing,
    each a whole operand where it stands: the arithmetic and its order stay the loop's.
    """

    def __init__(self, states, params: dict, tau, bases: dict, q_defs: dict):
        # symbol -> (state: bool, tau: bool, parameter indices); the harmonics C{i}_{k},
        # S{i}_{k} read the time and the parameters of their frequency
        self.deps = {s: (True, False, ()) for s in states}
        self.deps.update({s: (False, False, (k,)) for s, k in params.items()})
        self.deps[tau] = (False, True, ())
        for w, (i, top) in bases.items():
            on = (False, True, tuple(params[s] for s in w.free_symbols if s in params))
            self.deps.update(
                {sp.Symbol(f"{cs}{i}_{k}"): on for k in range(1, top + 1) for cs in "CS"}
            )
        self.n_q = len(q_defs)
        self.q_units: dict = {}  # parameter-only term -> q[i] (i after the trig q's)
        self.tau_units: dict = {}  # time-dependent term -> h_i
        self.fresh: list = []  # tau units not yet given their definitions
        self.alias: dict = {}  # CSE symbol whose whole value is a unit -> the unit
        self.pre_names = {s: f"P[{k}*n]" for s, k in params.items()}
        for e, sym in q_defs.items():
            self.deps[sym] = (False, False, self.of(e)[2])
            self.pre_names[sym] = f"Q[{sym.name[2:-1]}*n]"

    def of(self, expr) -> tuple[bool, bool, frozenset]:
        """What ``expr`` depends on; an unknown symbol counts as a state (never hoisted)."""
        state, tau, params = False, False, set()
        for s in expr.free_symbols:
            d_state, d_tau, d_params = self.deps.get(s, (True, False, ()))
            state, tau = state or d_state, tau or d_tau
            params.update(d_params)
        return state, tau, frozenset(params)

    def unit(self, expr, tau: bool):
        """The symbol standing for ``expr`` if it is a unit (``tau``: time-dependent ones
        too), else None."""
        if not isinstance(expr, sp.Expr) or _trivial(expr):
            return None
        state, on_tau, params = self.of(expr)
        if state or (on_tau and not tau):
            return None
        units = self.tau_units if on_tau else self.q_units
        if expr not in units:
            if on_tau:
                sym = sp.Symbol(f"h_{len(units)}")
                self.fresh.append(expr)
            else:
                sym = sp.Symbol(f"q[{self.n_q}]")
                self.pre_names[sym] = f"Q[{self.n_q}*n]"
                self.n_q += 1
            units[expr] = sym
            self.deps[sym] = (False, on_tau, params)
        return units[expr]


def _guarded(rows, indent: str, negate: bool) -> list[str]:
    """``(parameter indices, line)`` rows in ``#if`` blocks, one per run of equal indices:
    kept when every parameter read is shared (``negate``: when one is not); a row that
    reads none is kept unguarded (before the loop) or dropped (in it)."""
    lines, open_ = [], None
    for params, line in rows:
        if params != open_ and open_ is not None:
            lines.append("#endif")
            open_ = None
        if not params:
            if not negate:
                lines.append(indent + line)
            continue
        if open_ is None:
            cond = " && ".join(f"GS_SHARED_{k}" for k in sorted(params))
            lines.append(f"#if !({cond})" if negate else f"#if {cond}")
            open_ = params
        lines.append(indent + line)
    if open_ is not None:
        lines.append("#endif")
    return lines


def _batch(printer, hoist, replacements, reduced) -> tuple[list[str], list[str]]:
    """Lines of ``gs_rhs_batch`` before its loop over points and inside it.

    Each CSE replacement and output is printed with its units named (:class:`_Hoist`);
    a replacement that is a unit as a whole becomes an alias of it.  The definitions of
    the tau units met in a statement go before the loop, guarded by ``#if`` on the
    parameters they read, and again just before that statement in the loop, guarded by
    the negation: with no ``GS_SHARED_k`` defined the loop computes what it did before."""
    pre, body = [], []

    def settle(line: str | None = None):  # the fresh tau units' definitions, then line
        rows = []
        for expr in hoist.fresh:
            sym = hoist.tau_units[expr]
            for where, out in (("pre", pre), ("loop", rows)):
                code = printer.text(expr, where, "q", top=True)
                out.append((hoist.deps[sym][2], f"const double {sym.name} = {code};"))
        hoist.fresh.clear()
        body.extend([*_guarded(rows, "        ", negate=True), *([line] if line else [])])

    for sym, expr in replacements:
        hoist.deps[sym] = hoist.of(expr)
        unit = hoist.unit(expr, tau=True)
        if unit is not None:
            hoist.alias[sym] = unit
            settle()
        else:
            settle(f"        const double {sym.name} = {printer.text(expr, 'loop', 'all')};")
    for k, expr in enumerate(reduced):
        settle(f"        DX[{k}*n + j] = {printer.text(expr, 'loop', 'all')};")
    return _guarded(pre, "    ", negate=False), body


def c_source(model: Model, variational: bool = False) -> str:
    """C text of ``gs_prep``, ``gs_rhs`` and ``gs_rhs_batch`` for ``model``; with
    ``variational`` for the state extended by a tangent vector ``w``:
    ``(x, w)' = (F(tau, x), J(tau, x) w)``."""
    printer = _Printer(code_names((*model.state_symbols, *model.parameter_symbols)))
    found = (s for e in model.rhs for s in e.free_symbols if s.name == "tau")
    tau = next(found, sp.Symbol("tau"))
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

    def unpack(used):  # the parameters in ``used``, in their order
        return [
            f"    const double {printer.doprint(s)} = p[{k}];"
            for s, k in params.items()
            if s in used
        ]

    rhs = [
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
            rhs.append(f"    const double {printer.doprint(s)} = x[{k}];")
    base_used = set().union(*(w.free_symbols for w in bases))
    rhs += unpack(used | base_used)
    rhs += _harmonic_lines(bases, printer)
    for sym, e in replacements:
        rhs.append(f"    const double {sym.name} = {printer.doprint(e)};")
    for k, e in enumerate(reduced):
        rhs.append(f"    dx[{k}] = {printer.doprint(e)};")
    rhs += ["    (void)tau; (void)p; (void)q;", "}", ""]

    # Batched form for lockstep integration: n points in structure-of-arrays layout
    # (X[i*n + j] is state i of point j); the excitation's harmonics are computed once for
    # all points (they share the time and, by contract, the frequencies), and so is every
    # term of time and shared parameters alone (_Hoist); the rest vectorises.
    hoist = printer.hoist = _Hoist(states, params, tau, bases, q_defs)
    printer.seen = set()
    pre, body = _batch(printer, hoist, replacements, reduced)
    batch = [
        "/* -DGS_SHARED_k=1 declares parameter k equal for all points: the terms of the time",
        " * and of shared parameters alone are then computed once, before the loop. */",
        "static void gs_rhs_batch(double tau, int n, const double *restrict X, "
        "const double *restrict P, const double *restrict Q, double *restrict DX)",
        "{",
        *_harmonic_lines(bases, printer, {s: sp.Symbol(f"P[{k}*n]") for s, k in params.items()}),
        *pre,
        "#pragma GCC ivdep",
        "    for (int j = 0; j < n; ++j) {",
    ]
    if hoist.n_q:
        batch += [
            "        double q[GS_NQ];",
            "        for (int k = 0; k < GS_NQ; ++k) q[k] = Q[k*n + j];",
        ]
    for k, s in enumerate(states):
        if s in used:
            batch.append(f"        const double {printer.doprint(s)} = X[{k}*n + j];")
    for s in model.parameter_symbols:
        if s in printer.seen:
            batch.append(f"        const double {printer.doprint(s)} = P[{params[s]}*n + j];")
    batch += [*body, "    }", "    (void)tau; (void)P; (void)Q;", "}", ""]

    prep_used = set().union(*(e.free_symbols for e in (*q_defs, *hoist.q_units)))
    prep = [
        "static void gs_prep(const double *p, double *q)",
        "{",
        *unpack(prep_used),
        *(
            f"    {sym.name} = {printer.text(e, 'prep', 'off')};"
            for e, sym in (*q_defs.items(), *hoist.q_units.items())
        ),
        "    (void)p; (void)q;",
        "}",
        "",
    ]
    printer.hoist = None
    what = " with the variational equations" if variational else ""
    head = [
        # no name in the C text: two models with the same equations (the light and heavy
        # reference scenes, a variant and the scene it varies) share one compiled library
        f"/* right-hand side{what} for the compiled integrators (gearsym derive). */",
        f"#define GS_NX {n}",
        f"#define GS_NP {m}",
        f"#define GS_NQ {max(hoist.n_q, 1)}",
        "",
    ]
    return "\n".join([*head, *prep, *rhs, *batch])
