"""Backlash models: the restoring function g(x) of a mesh with unit half backlash.

All models are written for the non-dimensional mesh coordinate ``x = (deflection) / b``
with ``b`` the half backlash, so the dead zone is ``|x| <= 1``:

* :class:`LinearContact` -- ``g(x) = x`` (no backlash, teeth never separate);
* :class:`DeadZone` -- ``g(x) = x - clip(x, -1, 1)``, exact piecewise-linear backlash;
* :class:`SmoothDeadZone` -- ``g(x) = x - (sqrt((x+1)^2+e^2) - sqrt((x-1)^2+e^2)) / 2``,
  the dead zone with ``|y|`` replaced by ``sqrt(y^2 + e^2)`` (C-infinity, exact as e -> 0);
* :class:`PolynomialFit` -- an odd polynomial least-squares fit of the dead zone over
  ``[-A, A]``; valid only inside that range.

Each model is plain data plus the symbolic expression it contributes; the fit's
coefficients are computed here, never typed in.  :func:`fit_dead_zone` with its
defaults (order 7, range 3, uniform samples of step 0.01) reproduces the printed
coefficients of the reference study, ``0.0017 x^7 - 0.0366 x^5 + 0.2833 x^3 - 0.1555 x``.

Each model also lists the kinks of ``g`` (where its slope jumps) in ``kinks``: the dead
zone's edges ``+1, -1``; the smooth, linear and polynomial models have none.  The model's
contract (``derive/model.py``) turns them into switching surfaces for the solver.

Each model states where its force is zero and its sign elsewhere (:meth:`Backlash.force_sign`,
``force_sign.py``): the dead zone is zero on ``[-1, 1]``; the linear and smooth laws only
at ``x = 0``; the polynomial at its real zeros (``0`` and ``+-0.7701`` for the study's fit),
with load inside the gap.  The contract carries it, so that "contact" and "separation"
follow the model's own force.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from typing import ClassVar

import numpy as np
import sympy as sp

from .force_sign import ForceSign, polynomial_sign, spurious_load_limit, static_equilibria

__all__ = [
    "BACKLASH_MODELS",
    "DEAD_ZONE_EDGES",
    "Backlash",
    "DeadZone",
    "ForceSign",
    "LinearContact",
    "PolynomialFit",
    "SmoothDeadZone",
    "dead_zone",
    "fit_dead_zone",
]


# (lower, upper) edges of the dead zone in the unit half backlash: teeth in contact forward
# for x > upper, separated for lower <= x <= upper, in contact backward for x < lower.
DEAD_ZONE_EDGES = (-1.0, 1.0)


def dead_zone(x: np.ndarray) -> np.ndarray:
    """Exact dead zone with unit half backlash: ``x - clip(x, -1, 1)``."""
    x = np.asarray(x, dtype=float)
    return x - np.clip(x, -1.0, 1.0)


@dataclass(frozen=True)
class Backlash:
    """Base of the backlash models.

    Attributes
    ----------
    kind : str
        Registry name (``linear``, ``dead-zone``, ``smooth``, ``polynomial``).
    valid_range : float or None
        ``A`` such that the model is valid for ``|x| <= A``; None if valid everywhere.
    kinks : tuple of float
        The ``x`` where ``g`` has a kink (its slope jumps), upper before lower; ``()``
        for a smooth ``g``.  An integrator locates these as switching surfaces.
    """

    kind = "base"
    kinks: ClassVar[tuple[float, ...]] = ()
    valid_range: float | None = field(default=None, init=False)

    def parameters(self) -> tuple[tuple[str, float, str], ...]:
        """(name, value, meaning) of each number the expression uses, in order."""
        return ()

    def expression(self, x: sp.Expr) -> sp.Expr:
        """g(x) as a SymPy expression in ``x`` and the symbols of :meth:`parameters`."""
        raise NotImplementedError

    def force_sign(self) -> ForceSign:
        """Where g(x) is zero and its sign elsewhere (the contract's ``force_sign``)."""
        raise NotImplementedError

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        """g(x) numerically, with the model's own parameter values."""
        xs = sp.Symbol("x", real=True)
        subs = {sp.Symbol(n, real=True): v for n, v, _ in self.parameters()}
        f = sp.lambdify(xs, self.expression(xs).subs(subs), "numpy")
        return np.broadcast_to(f(np.asarray(x, dtype=float)), np.shape(x)).astype(float)

    def max_error(self, samples: int = 20001) -> float:
        """max |g(x) - dead zone(x)| over the valid range (or [-3, 3] if unbounded).

        The dead zone's corners at x = +-1, where the error of a smooth model peaks with a
        kink, are sampled exactly.
        """
        a = self.valid_range if self.valid_range is not None else 3.0
        x = np.union1d(np.linspace(-a, a, samples), [-1.0, 1.0])
        return float(np.max(np.abs(self.evaluate(x) - dead_zone(x))))

    def describe(self) -> dict:
        return {
            "kind": self.kind,
            "valid_range": self.valid_range,
            "parameters": {n: v for n, v, _ in self.parameters()},
        }


@dataclass(frozen=True)
class LinearContact(Backlash):
    """No backlash: ``g(x) = x``."""

    kind = "linear"

    def expression(self, x):
        return x

    def force_sign(self):
        return ForceSign((0.0,), (-1, 1))


@dataclass(frozen=True)
class DeadZone(Backlash):
    """Piecewise-linear dead zone ``g(x) = x - 1 (x > 1), 0 (|x| <= 1), x + 1 (x < -1)``."""

    kind = "dead-zone"
    kinks = (DEAD_ZONE_EDGES[1], DEAD_ZONE_EDGES[0])

    def expression(self, x):
        return sp.Piecewise((x - 1, x > 1), (x + 1, x < -1), (0, True))

    def force_sign(self):
        return ForceSign(DEAD_ZONE_EDGES, (-1, 0, 1))


@dataclass(frozen=True)
class SmoothDeadZone(Backlash):
    """Regularised dead zone ``x - (sqrt((x+1)^2 + e^2) - sqrt((x-1)^2 + e^2)) / 2``.

    Its largest deviation from the dead zone is ``e/2`` (at ``x = 0`` the error is 0; at
    ``x = +-1`` it is ``(e + 2 - sqrt(4 + e^2)) / 2 ~ e / 2``).
    """

    kind = "smooth"
    width: float = 0.05

    def __post_init__(self):
        if not (self.width > 0 and math.isfinite(self.width)):
            raise ValueError(f"smooth dead-zone width must be > 0, got {self.width}")

    def parameters(self):
        return (("eps_g", self.width, "regularisation width of the smooth dead zone"),)

    def expression(self, x):
        e = sp.Symbol("eps_g", real=True)
        return x - (sp.sqrt((x + 1) ** 2 + e**2) - sp.sqrt((x - 1) ** 2 + e**2)) / 2

    def force_sign(self):
        # g' = 1 - ((x+1)/r1 - (x-1)/r2)/2 with |(x -+ 1)/r| < 1, so g' > 0: g is strictly
        # increasing, zero only at x = 0, loaded in the gap by about e^2 x / (2 (1 - x^2)).
        return ForceSign((0.0,), (-1, 1))


@dataclass(frozen=True)
class PolynomialFit(Backlash):
    """Odd polynomial ``sum_k a_k x^k`` (k = 1, 3, ..., order) fitted to the dead zone.

    Attributes
    ----------
    order : int
        Odd polynomial order.
    fit_range : float
        Half-width ``A`` of the fitted interval ``[-A, A]``; the fit is valid there only.
    samples : int or None
        Number of uniformly spaced least-squares samples on ``[-A, A]``; None for the
        continuous L2 fit (exact integrals).
    coefficients : tuple of float
        ``a_1, a_3, ..., a_order``.
    """

    kind = "polynomial"
    order: int = 7
    fit_range: float = 3.0
    samples: int | None = None
    coefficients: tuple[float, ...] = ()

    def __post_init__(self):
        if self.order < 1 or self.order % 2 == 0:
            raise ValueError(f"polynomial order must be odd and >= 1, got {self.order}")
        if len(self.coefficients) != (self.order + 1) // 2:
            raise ValueError("need one coefficient per odd power")
        object.__setattr__(self, "valid_range", self.fit_range)

    @property
    def powers(self) -> tuple[int, ...]:
        return tuple(range(1, self.order + 1, 2))

    def parameters(self):
        return tuple(
            (f"g{k}", c, f"coefficient of x^{k} in the backlash polynomial")
            for k, c in zip(self.powers, self.coefficients, strict=True)
        )

    def expression(self, x):
        # Horner form in x^2: x (a1 + x^2 (a3 + x^2 (a5 + ...))) -- fewest operations.
        x2 = x**2
        acc = sp.Symbol(f"g{self.powers[-1]}", real=True)
        for k in reversed(self.powers[:-1]):
            acc = sp.Symbol(f"g{k}", real=True) + x2 * acc
        return x * acc

    def force_sign(self):
        """The real zeros of g in ``[-A, A]`` (exact root isolation) and its sign between."""
        return polynomial_sign(self.coefficients, self.powers, self.valid_range)

    def equilibria(self, load: float):
        """Static equilibria ``g(x) = F`` in ``[-A, A]`` (:func:`static_equilibria`)."""
        return static_equilibria(self.coefficients, self.powers, load, self.valid_range)

    def spurious_load_limit(self) -> float:
        """``F*``: a spurious stable equilibrium exists for ``0 < |F| < F*``."""
        return spurious_load_limit(self.coefficients, self.powers, self.valid_range)


BACKLASH_MODELS = {
    "linear": LinearContact,
    "dead-zone": DeadZone,
    "smooth": SmoothDeadZone,
    "polynomial": PolynomialFit,
}


_MAX_SAMPLES = 1_000_000


# The one rule for the fit's order and range (the scene's backlash_order and
# backlash_range, the backlash command's --order and --range).
MAX_ORDER = 31
MAX_RANGE = 100.0


def fit_dead_zone(
    order: int = 7, fit_range: float = 3.0, step: float | None = 0.01
) -> PolynomialFit:
    """Least-squares odd polynomial fit of the unit dead zone on ``[-A, A]``.

    Minimises ``sum_i (p(x_i) - dz(x_i))^2`` over ``x_i = -A, -A + h, ..., A`` (``step=h``),
    or, with ``step=None``, the continuous ``int_{-A}^{A} (p - dz)^2 dx``.  Both normal
    equations, in the scaled variable ``t = x / A``, are formed and solved exactly in rational
    arithmetic (the sample sums in closed form, Faulhaber's formula), so each coefficient is
    the correctly rounded least-squares solution at any order and the same on every
    machine.  A floating-point solve is not: LAPACK's answer moves in the last bits with the
    BLAS kernel, and the generated files, which carry these coefficients, are compared byte
    for byte.

    The defaults are the reference study's set-up: order 7, ``A = 3`` and ``h = 0.01``
    (601 samples) give ``0.0017 x^7 - 0.0366 x^5 + 0.2833 x^3 - 0.1555 x`` to its
    printed four decimals.
    """
    if not (isinstance(order, int) and 1 <= order <= MAX_ORDER and order % 2 == 1):
        raise ValueError(
            f"order must be an odd whole number from 1 to {MAX_ORDER}, got {order!r} (higher "
            "orders swing between the samples and lose every digit in floating point)"
        )
    if not (math.isfinite(fit_range) and 1.0 < fit_range <= MAX_RANGE):
        raise ValueError(
            f"range must be in (1, {MAX_RANGE:g}] (it must contain the backlash), got {fit_range}"
        )
    powers = range(1, order + 1, 2)
    a = Fraction(fit_range)  # exact: the float the caller gave
    if step is None:
        # Gram matrix of t^i t^j on [0, 1] (the problem is odd, so half the interval),
        # right side int_{1/A}^{1} t^i (A t - 1) dt.
        s = 1 / a
        gram = [[Fraction(1, p + q + 1) for q in powers] for p in powers]
        rhs = [a * (1 - s ** (p + 2)) / (p + 2) - (1 - s ** (p + 1)) / (p + 1) for p in powers]
        samples = None
    else:
        if not (math.isfinite(step) and step > 0):
            raise ValueError(f"step must be > 0, got {step}")
        samples = int(round(2.0 * fit_range / step)) + 1
        if samples > _MAX_SAMPLES:
            raise ValueError(
                f"step {step:g} gives {samples} samples (at most {_MAX_SAMPLES}); use a step "
                f">= {2.0 * fit_range / (_MAX_SAMPLES - 1):.3g}, or 0 for the continuous fit"
            )
        # The fit is odd: only the samples at t > 0 determine it, and the Gram matrix of
        # len(powers) odd powers needs as many distinct ones.
        positive = (samples - 1) - (samples - 1) // 2
        if positive < len(powers):
            raise ValueError(
                f"step {step:g} leaves {positive} sample(s) above zero for the {len(powers)} "
                f"odd coefficients; use a step of at most {fit_range / len(powers):.3g}"
            )
        # Samples t_i = j / M, j = 2i - M (i = 0..M, M = samples - 1).  Both sides are odd
        # in t, so the sums run over t > 0 (j > 0) and the factor 2 cancels; the dead zone
        # is A t - 1 where A t > 1, i.e. A j > M (a sample at A t = 1 adds 0).
        m = samples - 1
        moments = _odd_grid_sums(m, m // 2 + 1, 2 * order)
        outer = _odd_grid_sums(m, int((m + m / a) // 2) + 1, order + 1)
        gram = [[Fraction(moments[p + q], m ** (p + q)) for q in powers] for p in powers]
        rhs = [a * Fraction(outer[p + 1], m ** (p + 1)) - Fraction(outer[p], m**p) for p in powers]
    scaled = _solve_exact(gram, rhs)
    return PolynomialFit(
        order=order,
        fit_range=float(fit_range),
        samples=samples,
        coefficients=tuple(float(c / a**p) for c, p in zip(scaled, powers, strict=True)),
    )


def _bernoulli(n: int) -> list[Fraction]:
    """Bernoulli numbers B_0..B_n with B_1 = -1/2 (``sum_j C(m+1, j) B_j = 0``)."""
    b = [Fraction(1)]
    for m in range(1, n + 1):
        b.append(-sum(math.comb(m + 1, j) * b[j] for j in range(m)) / (m + 1))
    return b


def _power_sums(n: int, kmax: int, bernoulli: list[Fraction]) -> list[int]:
    """``sum_{i=0}^{n-1} i^k`` for k = 0..kmax, by Faulhaber's formula."""
    sums = []
    for k in range(kmax + 1):
        s = sum(math.comb(k + 1, j) * bernoulli[j] * n ** (k + 1 - j) for j in range(k + 1))
        sums.append(int(s / (k + 1)))  # an integer: the division is exact
    return sums


def _odd_grid_sums(m: int, start: int, kmax: int) -> list[int]:
    """``sum_{i=start}^{m} (2i - m)^k`` for k = 0..kmax, exactly, without a loop over i."""
    bernoulli = _bernoulli(kmax)
    d = [
        x - y
        for x, y in zip(
            _power_sums(m + 1, kmax, bernoulli), _power_sums(start, kmax, bernoulli), strict=True
        )
    ]
    return [
        sum(math.comb(k, j) * 2**j * (-m) ** (k - j) * d[j] for j in range(k + 1))
        for k in range(kmax + 1)
    ]


def _solve_exact(a: list[list[Fraction]], b: list[Fraction]) -> list[Fraction]:
    """Solve ``a x = b`` exactly (Gauss-Jordan in rationals; ``a`` is a Gram matrix, so
    nonsingular)."""
    n = len(b)
    rows = [[*row, rhs] for row, rhs in zip(a, b, strict=True)]
    for c in range(n):
        pivot = next(r for r in range(c, n) if rows[r][c] != 0)
        rows[c], rows[pivot] = rows[pivot], rows[c]
        for r in range(n):
            if r != c and rows[r][c] != 0:
                f = rows[r][c] / rows[c][c]
                rows[r] = [x - f * y for x, y in zip(rows[r], rows[c], strict=True)]
    return [rows[i][n] / rows[i][i] for i in range(n)]
