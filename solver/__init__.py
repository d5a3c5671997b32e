"""gearsym.solver -- non-dimensional analysis on the generated models.

Thin for now: :func:`load_generated` imports a generated model module by name.  The
simulation, sweep and periodic-orbit layers build on the interface that module exposes
(``STATES``, ``PARAMETERS``, ``DEFAULTS``, ``rhs``, ``jacobian``, ``casadi_functions``).
"""

from ._models import load_generated

__all__ = ["load_generated"]
