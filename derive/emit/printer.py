"""One printer of SymPy expressions as Python source, for NumPy and CasADi.

The two back ends of a generated module print the same common-subexpression-eliminated
expressions through :class:`CodePrinter`, which differs only in its namespace (``np`` or
``ca``) and in how a ``Piecewise`` is written (``np.where`` or ``ca.if_else``); every model
symbol is printed as its namespaced identifier (``derive/escape.py``).
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.str import StrPrinter

from ..model import Model

__all__ = ["CodePrinter", "function_body"]


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


def function_body(
    model: Model, outputs, printer: CodePrinter, indent: str = "    "
) -> tuple[list, list]:
    """Lines unpacking states/parameters and computing CSE temporaries; printed outputs.

    ``outputs`` are SymPy expressions in the model's state symbols (``x[k]``) and parameter
    symbols (``p[k]``); the lines bind only the symbols the outputs use."""
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
