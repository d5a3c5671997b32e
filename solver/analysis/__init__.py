"""Analysis of responses: spectra, motion classification with its evidence, the largest
Lyapunov exponent, and everything about one operating point.

* ``spectra.py`` -- Hann-windowed spectra, extremes, meshing-state shares;
* ``classify.py`` -- period-n / quasi-periodic / chaotic / undetermined, with evidence;
* ``lyapunov.py`` -- Benettin's estimate from the variational equations;
* ``point.py`` -- :func:`analyse_point`, the convenience call on top of them.
"""

from .classify import Classification, classify_points, correlation_dimension, periodicity
from .lyapunov import LyapunovEstimate, largest_lyapunov
from .point import PointResult, analyse_point, analyse_trajectory, classification_tolerance
from .spectra import Spectrum, extremes, meshing_states, spectrum

__all__ = [
    "Classification",
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
