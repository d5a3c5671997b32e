"""The functions every generated module defines, written once for each kind of model: the
C source (plain, with the variational equations, the Jacobian), NumPy ``rhs`` and ``jacobian`` with
their ``_broadcast`` helper, and ``casadi_functions``.  A model here is anything with
``state_symbols``, ``parameter_symbols``, ``parameters``, ``rhs`` and a row-major
``jacobian`` (a tree's ``Model``, a planetary set's ``PlanetaryDynamics``)."""

from __future__ import annotations

from ..escape import code_names
from .c import c_source
from .c_jacobian import jacobian_source
from .printer import CodePrinter, function_body

__all__ = ["Emitted"]


class Emitted:
    """The printed bodies of one model's functions; each ``*_lines`` method gives the
    lines of one block of the module's text."""

    def __init__(self, model):
        names = code_names((*model.state_symbols, *model.parameter_symbols))
        self.np_printer = CodePrinter("np", names)
        ca_printer = CodePrinter("ca", names)
        self.model = model
        self.n, self.n_p = len(model.state_symbols), len(model.parameters)
        self.rhs = function_body(model, list(model.rhs), self.np_printer)
        self.jac = function_body(model, list(model.jacobian), self.np_printer)
        self.ca = function_body(model, list(model.rhs), ca_printer)

    def body(self, outputs) -> tuple[list, list]:
        """``function_body`` of other outputs with the module's NumPy printer."""
        return function_body(self.model, list(outputs), self.np_printer)

    def c_lines(self) -> list[str]:
        plain, variational = c_source(self.model), c_source(self.model, variational=True)
        jacobian = jacobian_source(self.model)
        for c_text in (plain, variational, jacobian):  # in r"""...""": nothing may end it
            if '"""' in c_text or c_text.rstrip("\n").endswith("\\"):
                raise ValueError("the C source cannot be held in a raw triple-quoted string")
        return [
            "# The right-hand side in C for the compiled integrators (solver/integrate/native/).",
            'C_SOURCE = r"""',
            plain.rstrip("\n"),
            '"""',
            "",
            "# The same with the variational equations (x, w)' = (F, J w), for Lyapunov exponents.",
            'C_SOURCE_VARIATIONAL = r"""',
            variational.rstrip("\n"),
            '"""',
            "",
            "# The Jacobian's nonzero entries in C: the monodromy's (x, W)' = (F, J W) in one",
            "# run (solver/integrate/native/monodromy.c).",
            'C_JACOBIAN = r"""',
            jacobian.rstrip("\n"),
            '"""',
            "",
            "",
        ]

    def rhs_lines(self) -> list[str]:
        lines, out = self.rhs
        return [
            "def rhs(tau, x, p):",
            '    """dX/dtau.  x: (n,) or (n, N); p: (P,) or (P, N); result (n,) or (n, N)."""',
            *lines,
            "    return np.array(np.broadcast_arrays(",
            *(f"        {o}," for o in out),
            "    ))",
            "",
            "",
        ]

    def jacobian_lines(self) -> list[str]:
        lines, out = self.jac
        n = self.n
        rows = ",\n        ".join(
            "(" + ", ".join(out[i * n : (i + 1) * n]) + ",)" for i in range(n)
        )
        return [
            "def jacobian(tau, x, p):",
            '    """d rhs / d X, shape (n, n) or (n, n, N)."""',
            *lines,
            "    return np.array(_broadcast(",
            f"        {rows},",
            "    ))",
            "",
            "",
        ]

    @staticmethod
    def broadcast_lines() -> list[str]:
        return [
            "def _broadcast(*rows):",
            "    flat = np.broadcast_arrays(*(e for row in rows for e in row))",
            "    n = len(rows)",
            "    return [flat[i * n:(i + 1) * n] for i in range(n)]",
            "",
            "",
        ]

    def casadi_lines(self) -> list[str]:
        lines, out = self.ca
        return [
            "def casadi_functions():",
            '    """CasADi SX functions ``rhs(tau, x, p)`` and ``jacobian(tau, x, p)`` (AD)."""',
            "    import casadi as ca",
            "",
            "    tau = ca.SX.sym('tau')",
            f"    x = ca.SX.sym('x', {self.n})",
            f"    p = ca.SX.sym('p', {self.n_p})",
            *lines,
            "    xdot = ca.vertcat(",
            *(f"        {o}," for o in out),
            "    )",
            "    f = ca.Function('rhs', [tau, x, p], [xdot], ['tau', 'x', 'p'], ['xdot'])",
            "    j = ca.Function('jacobian', [tau, x, p], [ca.jacobian(xdot, x)],",
            "                    ['tau', 'x', 'p'], ['jac'])",
            "    return f, j",
            "",
        ]
