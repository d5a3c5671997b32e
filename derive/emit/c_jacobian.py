"""C text of a model's Jacobian, for the compiled monodromy.

The shooting check, shooting and continuation need the monodromy ``M = d phi_T / dx0``.
The compiled engine integrated it as ``n`` copies of the state, each carrying one tangent
(the variational library, ``C_SOURCE_VARIATIONAL``): every copy computed the state again
and ``F`` with ``J w`` once per stage, ``n (F + J w)`` in all.  With the Jacobian's
entries in C the matrix form ``(x, W)' = (F(tau, x), J(tau, x) W)`` runs one state: ``F``
and the nonzero entries of ``J`` once a stage, then ``J W`` over the nonzeros
(``solver/integrate/native/monodromy.c`` joins this text to ``C_SOURCE``).

``gs_jac(tau, x, p, J)`` writes the nonzero entries in the order of ``GS_JROW`` and
``GS_JCOL`` (row-major); it reads the time and the parameters itself (no ``gs_prep``
terms), so that it does not depend on how ``C_SOURCE`` reduces its harmonics.
"""

from __future__ import annotations

import sympy as sp

from ..escape import code_names
from .c import _Printer

__all__ = ["jacobian_source"]


def jacobian_source(model) -> str:
    """``GS_NJ``, ``GS_JROW``, ``GS_JCOL`` and ``gs_jac`` of ``model`` (anything with
    ``state_symbols``, ``parameter_symbols`` and a row-major ``jacobian``)."""
    states, params = list(model.state_symbols), list(model.parameter_symbols)
    printer = _Printer(code_names((*states, *params)))
    n = len(states)
    entries = [(k // n, k % n, e) for k, e in enumerate(model.jacobian) if e != 0]
    replacements, reduced = sp.cse(
        [e for _, _, e in entries], symbols=sp.numbered_symbols("j_"), order="canonical"
    )
    used = set().union(
        *(e.free_symbols for _, e in replacements), *(e.free_symbols for e in reduced)
    )
    rows = ", ".join(str(i) for i, _, _ in entries) or "0"
    cols = ", ".join(str(j) for _, j, _ in entries) or "0"
    lines = [
        "/* the Jacobian's nonzero entries, row-major, for the compiled monodromy */",
        f"#define GS_NJ {len(entries)}",
        f"static const int GS_JROW[{max(len(entries), 1)}] = {{{rows}}};",
        f"static const int GS_JCOL[{max(len(entries), 1)}] = {{{cols}}};",
        "",
        "static inline void gs_jac(double tau, const double *x, const double *p, double *J)",
        "{",
    ]
    lines += [
        f"    const double {printer.doprint(s)} = x[{k}];"
        for k, s in enumerate(states)
        if s in used
    ]
    lines += [
        f"    const double {printer.doprint(s)} = p[{k}];"
        for k, s in enumerate(params)
        if s in used
    ]
    lines += [f"    const double {s.name} = {printer.doprint(e)};" for s, e in replacements]
    lines += [f"    J[{k}] = {printer.doprint(e)};" for k, e in enumerate(reduced)]
    lines += ["    (void)tau; (void)x; (void)p; (void)J;", "}", ""]
    return "\n".join(lines)
