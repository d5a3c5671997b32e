"""A forced Duffing oscillator with a known periodic orbit (test fixture).

    x'' + k x' + x^3 = F(tau),  F(tau) = -A cos(tau) - k A sin(tau) + A^3 cos(tau)^3

is built so that x = A cos(tau) solves it exactly (substitute and see).  Its variational
equation is Hill's equation y'' + k y' + 3 A^2 cos(tau)^2 y = 0, whose multipliers have
the product exp(-k T) (Liouville) and are computed independently in the test.
"""

import numpy as np

NAME = "designed_duffing"
SCENE = "designed"
INPUTS_SHA256 = "1" * 64
STATES = ("x", "dx")
COORDINATES = ("x",)
PARAMETERS = ("omega", "k", "A")
DEFAULTS = (1.0, 0.1, 1.5)
VALID_RANGE = None
OMEGA_N = 1.0
HALF_BACKLASH = {"x": 1.0}
FEATURES = {
    "backlash": "cubic",
    "stiffness_harmonics": 0,
    "transmission_error": False,
    "mesh_phase": False,
    "damping_coupling": False,
}
SCENE_PARAMETERS = {"omega": 1.0}
OPERATIONS = {"rhs": 20, "rhs_and_jacobian": 24}

# What the solver needs to know, as data (the generated modules' contract, format 1).
CONTRACT = {
    "format": 1,
    "states": STATES,
    "coordinates": COORDINATES,
    "velocities": {"x": 1},
    "parameters": PARAMETERS,
    "forcing_frequency": "omega",
    "loads": {},
    "contact": {},
    "piecewise": False,
    "switching_surfaces": (),
    "valid_range": None,
}


def parameters(**values):
    p = dict(zip(PARAMETERS, DEFAULTS, strict=True))
    unknown = set(values) - set(p)
    if unknown:
        raise KeyError(f"unknown parameter(s) {sorted(unknown)}")
    p.update(values)
    return np.array([p[k] for k in PARAMETERS], dtype=float)


def _forcing(tau, k, A, cos, sin):
    c = cos(tau)
    return -A * c - k * A * sin(tau) + A**3 * c**3


def rhs(tau, x, p):
    acc = -p[1] * x[1] - x[0] ** 3 + _forcing(p[0] * tau, p[1], p[2], np.cos, np.sin)
    return np.array(np.broadcast_arrays(x[1], acc))


def jacobian(tau, x, p):
    z = np.zeros_like(x[0])
    return np.array([[z, z + 1.0], [-3.0 * x[0] ** 2, z - p[1]]])


def casadi_functions():
    import casadi as ca

    tau, x, p = ca.SX.sym("tau"), ca.SX.sym("x", 2), ca.SX.sym("p", 3)
    acc = -p[1] * x[1] - x[0] ** 3 + _forcing(p[0] * tau, p[1], p[2], ca.cos, ca.sin)
    xdot = ca.vertcat(x[1], acc)
    f = ca.Function("rhs", [tau, x, p], [xdot])
    return f, ca.Function("jacobian", [tau, x, p], [ca.jacobian(xdot, x)])
