"""A period-2 orbit of the reference DI-SO model by harmonic balance, checked by shooting.

At a transmission-error amplitude of 7.5 um (an open value of the study; the regime map of
``gearsym reproduce`` finds period-2 motion of both meshes there at f1 = 0.1, lambda = 0.4)
the response is period-2: harmonic balance with harmonics of omega/2 against shooting over
two forcing periods, whose minimal-period check confirms the period.
"""

import numpy as np
from gearsym.resolve import load
from gearsym.solver.integrate import default_initial_state, simulate
from gearsym.solver.periodic import shoot
from gearsym.solver.periodic.harmonic_balance import harmonic_balance


def test_a_period_two_orbit_of_the_reference_model():
    system = load("reference-light", te_amplitude_um=7.5).with_values(**{"lambda": 0.4})
    tr = simulate(system, default_initial_state(system), transient=400, periods=2)
    sol = harmonic_balance(system, tr, n=2, harmonics=24)
    assert sol.residual < 1e-10 and sol.tail_share() < 1e-6
    odd = sol.harmonic_amplitudes("u")[1::2]  # harmonics of omega/2 that omega lacks
    assert odd.max() > 1e-3, "a period-1 orbit in disguise: no subharmonic content"
    orbit = shoot(system, sol.state(0.0), 2, tol=1e-12)
    assert orbit.minimal_period == 2
    assert np.max(np.abs(sol.state(0.0) - orbit.x0)) < 1e-6
    np.testing.assert_allclose(
        np.sort_complex(sol.floquet.multipliers),
        np.sort_complex(orbit.floquet.multipliers),
        atol=1e-6,
    )
    assert sol.floquet.stable and orbit.floquet.stable
