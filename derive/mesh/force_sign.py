"""Where a backlash model's force g(x) vanishes, its sign elsewhere, and its static
equilibria.

"Contact" and "separation" are properties of the force, not of the coordinate: the
teeth are apart where ``g(x) = 0`` and pressed on one flank where ``g(x) != 0``.  For the
exact dead zone that is the backlash gap ``|x| <= 1``; for the study's 7th-order fit
``g(x) = 0.0017 x^7 - 0.0366 x^5 + 0.2833 x^3 - 0.1555 x`` the force vanishes only at
``x = 0`` and ``x = +-0.7701`` and is negative on ``(0, 0.7701)``: it never separates, it
carries load inside the gap, and at a light static load it holds a second, spurious
stable equilibrium on the unloaded side of the gap (a double well).

:class:`ForceSign` is the sign of ``g`` as data (zeros and the sign on each interval
between them), the table a model's contract carries (``derive/contract.py``).  The
polynomial's zeros and equilibria are real roots found exactly: SymPy isolates the real
roots of the polynomial with the coefficients as exact rationals (the floats the fit
gave) and refines them to 30 digits, so each printed zero is the correctly rounded root
of the emitted polynomial on every machine (``numpy.roots``, an eigenvalue solve, moves
in the last bits with the BLAS, and the generated files are compared byte for byte).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import sympy as sp

__all__ = [
    "Equilibrium",
    "ForceSign",
    "polynomial_sign",
    "spurious_load_limit",
    "static_equilibria",
]

_X = sp.Symbol("x", real=True)
_DIGITS = 30  # refinement of each isolated root before rounding to a float


@dataclass(frozen=True)
class ForceSign:
    """The sign of a backlash force ``g(x)`` on the real line, as data.

    Attributes
    ----------
    zeros : tuple of float
        Sorted ``x`` (half backlashes) where ``g(x) = 0`` and the sign may change; for a
        dead zone the ends of the interval where ``g`` vanishes.
    signs : tuple of int
        ``-1``, ``0`` or ``+1``: the sign of ``g`` on each open interval
        ``(-inf, zeros[0]), (zeros[0], zeros[1]), ..., (zeros[-1], inf)``
        (``len(zeros) + 1`` entries); ``g`` is 0 at each zero.
    """

    zeros: tuple[float, ...]
    signs: tuple[int, ...]

    def __post_init__(self):
        if not self.zeros or list(self.zeros) != sorted(set(self.zeros)):
            raise ValueError(f"force zeros must be distinct and sorted, got {self.zeros}")
        if len(self.signs) != len(self.zeros) + 1 or not set(self.signs) <= {-1, 0, 1}:
            raise ValueError(
                f"need one sign (-1, 0 or 1) per interval between {len(self.zeros)} zeros, "
                f"got {self.signs}"
            )

    @property
    def edges(self) -> tuple[float, float]:
        """``(lower, upper)``, the outer zeros: ``g`` keeps one sign beyond them."""
        return (self.zeros[0], self.zeros[-1])

    @property
    def zero_between(self) -> bool:
        """True when ``g`` vanishes on the whole of ``[lower, upper]`` (a dead zone)."""
        return len(self.zeros) > 1 and all(s == 0 for s in self.signs[1:-1])

    @property
    def loaded_in_gap(self) -> bool:
        """True when ``g`` is nonzero somewhere in the backlash gap ``-1 < x < 1``."""
        bounds = (float("-inf"), *self.zeros, float("inf"))
        return any(
            s != 0 and a < 1.0 and b > -1.0
            for s, a, b in zip(self.signs, bounds[:-1], bounds[1:], strict=True)
        )

    def to_contract(self) -> dict:
        """The contract's entry: plain literals (``derive/contract.py``)."""
        return {
            "edges": self.edges,
            "zero_between": self.zero_between,
            "zeros": self.zeros,
            "signs": self.signs,
        }

    def describe(self) -> str:
        """One sentence for the audit page: where ``g`` is zero and its sign elsewhere."""
        if self.zero_between:
            lo, hi = self.edges
            inner = f"zero on $[{_short(lo)}, {_short(hi)}]$, "
        else:
            inner = "zero at $x = " + ", ".join(_short(z) for z in self.zeros) + "$, "
        bounds = ("-\\infty", *(_short(z) for z in self.zeros), "\\infty")
        parts = [
            f"{'positive' if s > 0 else 'negative'} on $({a}, {b})$"
            for s, a, b in zip(self.signs, bounds[:-1], bounds[1:], strict=True)
            if s != 0
        ]
        gap = (
            "; it carries load inside the gap $|x| < 1$ and never separates"
            if self.loaded_in_gap and not self.zero_between
            else ""
        )
        return f"$g$ is {inner}{', '.join(parts)}{gap}"


def _short(z: float) -> str:
    """Four decimals without trailing zeros (``0.7701``, ``-1``, ``0``)."""
    text = f"{z:.4f}".rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def _polynomial(coefficients, powers, load: float = 0.0) -> sp.Poly:
    """``g(x) - load`` with the floats as exact rationals."""
    terms = [_rational(c) * _X**k for c, k in zip(coefficients, powers, strict=True)]
    return sp.Poly(sp.Add(*terms) - _rational(load), _X)


def _rational(value: float) -> sp.Rational:
    f = Fraction(value)
    return sp.Rational(f.numerator, f.denominator)


def _real_roots(poly: sp.Poly, bound: float | None) -> list[sp.Expr]:
    """Distinct real roots, sorted, within ``|x| <= bound`` (all when ``bound`` is None),
    each the midpoint of its isolating interval refined to a width of ``10**-_DIGITS``
    (exact rational arithmetic; ``real_roots``' algebraic numbers cost about 100 times
    more and give the same floats)."""
    width = sp.Rational(1, 10**_DIGITS)
    roots = [(a + b) / 2 for (a, b), _ in poly.intervals(eps=width)]
    if bound is not None:
        roots = [r for r in roots if abs(r) <= _rational(bound)]
    return roots


def _float(root: sp.Expr) -> float:
    return float(root.evalf(_DIGITS))


def polynomial_sign(coefficients, powers, valid_range: float | None) -> ForceSign:
    """The sign table of ``g(x) = sum_k a_k x^k`` within its valid range ``|x| <= A``.

    Parameters
    ----------
    coefficients, powers : sequence of float, sequence of int
        ``a_k`` and ``k`` (an odd polynomial has the root ``x = 0``).
    valid_range : float or None
        ``A``; zeros beyond it are not the model's (the fit is not valid there).

    Returns
    -------
    ForceSign
        The real zeros in ``[-A, A]`` and the sign of ``g`` between them, each sign read
        exactly (rational arithmetic) at a rational point inside its interval.
    """
    poly = _polynomial(coefficients, powers)
    roots = _real_roots(poly, valid_range)
    if not roots:
        raise ValueError(f"backlash polynomial {poly.as_expr()} has no real zero")
    # Each sign is read at the midpoint of 30-digit rational approximations of the zeros;
    # the outer intervals end at the valid range (or one beyond the outer zeros).
    inner = [sp.Rational(str(r.evalf(_DIGITS))) for r in roots]
    outer = max(abs(inner[0]), abs(inner[-1]))
    reach = _rational(valid_range) if valid_range and valid_range > outer else outer + 1
    bounds = [-reach, *inner, reach]
    signs = tuple(
        int(sp.sign(poly.eval((lo + hi) / 2))) for lo, hi in zip(bounds, bounds[1:], strict=False)
    )
    return ForceSign(tuple(_float(r) for r in roots), signs)


@dataclass(frozen=True)
class Equilibrium:
    """A static equilibrium ``g(x) = F`` of one mesh at its mean stiffness.

    Attributes
    ----------
    x : float
        Deflection in half backlashes.
    slope : float
        ``g'(x)``, the non-dimensional stiffness there.
    stable : bool
        ``g'(x) > 0`` (with positive damping the mesh returns to ``x``).
    spurious : bool
        Stable on the side opposite to the load (``x F < 0``): a well of the force law
        that the dead zone does not have.
    """

    x: float
    slope: float
    stable: bool
    spurious: bool

    @property
    def in_gap(self) -> bool:
        return abs(self.x) < 1.0


def static_equilibria(coefficients, powers, load: float, valid_range: float | None = None):
    """Every static equilibrium ``g(x) = F`` of a polynomial force law within ``|x| <= A``.

    Equation: ``x'' + 2 xi x' + k(tau) g(x) = f`` at rest with the mean stiffness
    ``k = 1`` gives ``g(x) = F`` (``F`` the mesh's static force over ``k_m b``, the
    generated module's ``static_mesh_force``; with a symmetric positive definite
    coupling ``kappa`` the coupled equilibrium is stable exactly when each mesh's is).

    Parameters
    ----------
    coefficients, powers : sequence of float, sequence of int
        ``a_k`` and ``k`` of ``g``.
    load : float
        ``F``, non-dimensional.
    valid_range : float or None
        ``A``: roots beyond it are left out.

    Returns
    -------
    tuple of Equilibrium
        Sorted by ``x``.  For the study's fit and ``0 < |F| < 0.0449``
        (:func:`spurious_load_limit`) one of them is stable and spurious.
    """
    poly = _polynomial(coefficients, powers, load)
    slope = poly.diff(_X)
    out = []
    for r in _real_roots(poly, valid_range):
        x = _float(r)
        d = float(slope.eval(r).evalf(_DIGITS))
        out.append(Equilibrium(x, d, d > 0, d > 0 and x * load < 0))
    return tuple(out)


def spurious_load_limit(coefficients, powers, valid_range: float | None = None) -> float:
    """``F*``: an odd force law holds a spurious stable equilibrium for ``0 < |F| < F*``.

    For ``F > 0`` the spurious equilibria are the stable roots of ``g(x) = F`` at ``x < 0``;
    they exist while ``F`` is below the highest value of ``g`` on ``[-A, 0]``, reached at a
    root of ``g'`` (a saddle-node at ``F = F*``).  0 when ``g <= 0`` on ``[-A, 0]``.
    """
    poly = _polynomial(coefficients, powers)
    critical = [r for r in _real_roots(poly.diff(_X), valid_range) if _float(r) < 0]
    return max([0.0, *(float(poly.eval(r).evalf(_DIGITS)) for r in critical)])
