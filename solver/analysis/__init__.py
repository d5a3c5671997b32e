"""Analysis of responses: spectra, motion classification with its evidence, the largest
Lyapunov exponent, and everything about one operating point.

* ``spectra.py`` -- Hann-windowed spectra, extremes, meshing-state shares;
* ``classify.py`` -- the evidence of a Poincare point set (repetition, correlation
  dimension);
* ``lyapunov.py`` -- Benettin's estimate from the variational equations;
* ``zero_one.py``, ``torus.py`` -- the 0-1 test for chaos, a torus's rotation number;
* ``orbit_check.py`` -- the shooting check a period-n verdict rests on;
* ``verdict.py``, ``settle.py`` -- one verdict per attractor on that evidence, the run
  continued until it is settled;
* ``point.py`` -- :func:`analyse_point`, the convenience call on top of them.
"""

from .classify import Classification, classify_points, correlation_dimension, periodicity
from .lyapunov import LyapunovEstimate, largest_lyapunov
from .orbit_check import OrbitCheck, check_orbit
from .point import PointResult, analyse_point, analyse_trajectory, classification_tolerance
from .settle import BUDGET, settle
from .spectra import Spectrum, extremes, meshing_states, spectrum
from .torus import TorusEvidence, torus_evidence
from .verdict import Verdict
from .zero_one import ZeroOne, zero_one

__all__ = [
    "BUDGET",
    "Classification",
    "OrbitCheck",
    "TorusEvidence",
    "Verdict",
    "ZeroOne",
    "check_orbit",
    "settle",
    "torus_evidence",
    "zero_one",
    "LyapunovEstimate",
    "PointResult",
    "Spectrum",
    "analyse_point",
    "analyse_trajectory",
    "classification_tolerance",
    "classify_points",
    "correlation_dimension",
    "extremes",
    "largest_lyapunov",
    "meshing_states",
    "periodicity",
    "spectrum",
]
