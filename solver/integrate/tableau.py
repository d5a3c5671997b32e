"""Explicit Runge-Kutta methods as data: frozen Butcher tableaux that check themselves.

One generic step (:func:`rk_step`) does the work in NumPy; the compiled integrators
(``native/native_*.c``) read the same tableaux, printed as C arrays by
:func:`c_tables`.  The Dormand-Prince coefficients are SciPy's own
(``scipy.integrate._ivp``), so that the compiled step control is SciPy's (Hairer, Norsett
and Wanner 1993, "Solving Ordinary Differential Equations I", II.4-II.5).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

__all__ = ["DOP853", "DOPRI5", "RK4", "ButcherTableau", "c_tables", "rk_step"]  # noqa: F822


@dataclass(frozen=True)
class ButcherTableau:
    """Coefficients ``A`` (s, s), ``b`` (s,), ``c`` (s,) of an explicit method of ``order``;
    ``errors`` maps a name to an error-estimate weight vector (each sums to zero)."""

    name: str
    order: int
    A: np.ndarray
    b: np.ndarray
    c: np.ndarray
    errors: dict = field(default_factory=dict)

    def __post_init__(self):
        A, b, c = (np.asarray(v, dtype=float) for v in (self.A, self.b, self.c))
        s = b.size
        if A.shape != (s, s) or c.shape != (s,):
            raise ValueError(f"{self.name}: A must be ({s}, {s}) and c ({s},)")
        if np.any(np.triu(A) != 0):
            raise ValueError(f"{self.name}: A must be strictly lower triangular (explicit)")
        if not np.allclose(A.sum(axis=1), c, rtol=0, atol=1e-14):
            raise ValueError(f"{self.name}: the rows of A must sum to c")
        if abs(b.sum() - 1.0) > 1e-14:
            raise ValueError(f"{self.name}: the weights b must sum to 1")
        for key, e in self.errors.items():
            if abs(np.sum(e)) > 1e-14:
                raise ValueError(f"{self.name}: error weights {key} must sum to 0")
        for key, v in (("A", A), ("b", b), ("c", c)):
            v.setflags(write=False)
            object.__setattr__(self, key, v)

    @property
    def stages(self) -> int:
        return self.b.size


def rk_step(tab: ButcherTableau, f, t: float, y: np.ndarray, h: float) -> np.ndarray:
    """One step ``y(t) -> y(t + h)`` of ``y' = f(t, y)``; ``y`` may carry extra axes (a
    batch of columns)."""
    k = []
    for i in range(tab.stages):
        yi = y
        for j in range(i):
            if tab.A[i, j] != 0.0:
                yi = yi + h * tab.A[i, j] * k[j]
        k.append(f(t + tab.c[i] * h, yi))
    out = y
    for i in range(tab.stages):
        if tab.b[i] != 0.0:
            out = out + h * tab.b[i] * k[i]
    return out


RK4 = ButcherTableau(
    "RK4",
    4,
    A=[[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1, 0]],
    b=[1 / 6, 1 / 3, 1 / 3, 1 / 6],
    c=[0, 0.5, 0.5, 1],
)


@functools.cache
def _dormand_prince():
    from scipy.integrate._ivp import dop853_coefficients as d
    from scipy.integrate._ivp.rk import RK45

    s5 = RK45.n_stages
    dopri5 = ButcherTableau(
        "DOPRI5",
        5,
        A=np.pad(RK45.A, ((0, 0), (0, s5 - RK45.A.shape[1]))),
        b=RK45.B,
        c=RK45.C,
        errors={"E": RK45.E},
    )
    s8 = d.N_STAGES
    dop853 = ButcherTableau(
        "DOP853", 8, A=d.A[:s8, :s8], b=d.B, c=d.C[:s8], errors={"E3": d.E3, "E5": d.E5}
    )
    return dopri5, dop853


def __getattr__(name: str):
    # DOPRI5 and DOP853 are read from SciPy on first use (SciPy's import is slow and a
    # run on an already compiled library does not need them).
    if name in ("DOPRI5", "DOP853"):
        return _dormand_prince()[name == "DOP853"]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@functools.cache
def dop853_dense():
    """DOP853's dense output (Hairer, Norsett and Wanner, II.6; SciPy's coefficient
    arrays): three extra stages (rows ``A`` and nodes ``C`` over the 16 stages of the
    extended step) and the matrix ``D`` (4 x 16) of the seventh-order interpolant."""
    from scipy.integrate._ivp import dop853_coefficients as d

    s = d.N_STAGES + 1
    return {"A": d.A[s:], "C": d.C[s:], "D": d.D, "power": d.INTERPOLATOR_POWER}


def dop853_dense_tables(arr) -> list[str]:
    dense = dop853_dense()
    return [
        arr("GS_DOP853_AX", dense["A"]),
        arr("GS_DOP853_CX", dense["C"]),
        arr("GS_DOP853_D", dense["D"]),
    ]


def c_tables() -> str:
    """The tableaux of the compiled integrators as C arrays (no transcription by hand)."""

    DOPRI5, DOP853 = _dormand_prince()  # noqa: N806 (the module's names for them)

    def arr(name, values):
        flat = np.asarray(values, dtype=float).ravel()
        body = ", ".join(repr(float(v)) for v in flat)
        return f"static const double {name}[{flat.size}] = {{{body}}};"

    return "\n".join(
        [
            arr("GS_RK45_A", DOPRI5.A),
            arr("GS_RK45_B", DOPRI5.b),
            arr("GS_RK45_C", DOPRI5.c),
            arr("GS_RK45_E", DOPRI5.errors["E"]),
            arr("GS_DOP853_A", DOP853.A),
            arr("GS_DOP853_B", DOP853.b),
            arr("GS_DOP853_C", DOP853.c),
            arr("GS_DOP853_E3", DOP853.errors["E3"]),
            arr("GS_DOP853_E5", DOP853.errors["E5"]),
            *dop853_dense_tables(arr),
        ]
    )
