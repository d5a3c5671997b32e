"""The forced Duffing oscillator in the generated-model interface (test fixture).

    x'' + k x' + a x + c x^3 = B cos(omega tau)

With the defaults (a = 0, c = 1, k = 0.05, B = 7.5, omega = 1) it is Ueda's oscillator,
chaotic (Ueda 1979, "Randomly transitional phenomena in the system governed by Duffing's
equation", J. Stat. Phys. 20); with a = -1 it is the twin-well oscillator of Guckenheimer
and Holmes (1983, "Nonlinear Oscillations, Dynamical Systems, and Bifurcations of Vector
Fields", section 2.2).  Written by hand: the solver must work on any module with this
interface, not only on what the derivation emits.
"""

import numpy as np

NAME = "ueda_duffing"
SCENE = "ueda"
INPUTS_SHA256 = "0" * 64
STATES = ("x", "dx")
COORDINATES = ("x",)
PARAMETERS = ("omega", "k", "B", "a", "c")
DEFAULTS = (1.0, 0.05, 7.5, 0.0, 1.0)
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
OPERATIONS = {"rhs": 8, "rhs_and_jacobian": 12}

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


def rhs(tau, x, p):
    acc = -p[1] * x[1] - p[3] * x[0] - p[4] * x[0] ** 3 + p[2] * np.cos(p[0] * tau)
    return np.array(np.broadcast_arrays(x[1], acc))


def jacobian(tau, x, p):
    z = np.zeros_like(x[0])
    return np.array([[z, z + 1.0], [-p[3] - 3.0 * p[4] * x[0] ** 2, z - p[1]]])


def casadi_functions():
    import casadi as ca

    tau, x, p = ca.SX.sym("tau"), ca.SX.sym("x", 2), ca.SX.sym("p", 5)
    acc = -p[1] * x[1] - p[3] * x[0] - p[4] * x[0] ** 3 + p[2] * ca.cos(p[0] * tau)
    xdot = ca.vertcat(x[1], acc)
    f = ca.Function("rhs", [tau, x, p], [xdot])
    return f, ca.Function("jacobian", [tau, x, p], [ca.jacobian(xdot, x)])


# The same right-hand side in C for the compiled integrators (written by hand, in the form
# the derivation emits: gs_prep, gs_rhs, gs_rhs_batch on structure-of-arrays groups).
_C_COMMON = r"""
#define GS_NP 5
#define GS_NQ 1
static void gs_prep(const double *p, double *q) { q[0] = 0.0; (void)p; }
"""
_C_FORCE = "p[2] * cos(p[0] * tau) - p[1] * x[1] - p[3] * x[0] - p[4] * x[0] * x[0] * x[0]"

C_SOURCE = (
    "#define GS_NX 2\n"
    + _C_COMMON
    + r"""
static inline void gs_rhs(double tau, const double *x, const double *p, const double *q,
                          double *dx)
{
    dx[0] = x[1];
    dx[1] = """
    + _C_FORCE
    + r""";
    (void)q;
}

static void gs_rhs_batch(double tau, int n, const double *X, const double *P,
                         const double *Q, double *DX)
{
    for (int j = 0; j < n; ++j) {
        double x[2] = {X[j], X[n + j]}, p[5], dx[2];
        for (int k = 0; k < 5; ++k) p[k] = P[k * n + j];
        gs_rhs(tau, x, p, Q, dx);
        DX[j] = dx[0];
        DX[n + j] = dx[1];
    }
}
"""
)

C_SOURCE_VARIATIONAL = (
    "#define GS_NX 4\n"
    + _C_COMMON
    + r"""
static inline void gs_rhs(double tau, const double *x, const double *p, const double *q,
                          double *dx)
{
    dx[0] = x[1];
    dx[1] = """
    + _C_FORCE
    + r""";
    dx[2] = x[3];
    dx[3] = -(p[3] + 3.0 * p[4] * x[0] * x[0]) * x[2] - p[1] * x[3];
    (void)q;
}

static void gs_rhs_batch(double tau, int n, const double *X, const double *P,
                         const double *Q, double *DX)
{
    for (int j = 0; j < n; ++j) {
        double x[4], p[5], dx[4];
        for (int i = 0; i < 4; ++i) x[i] = X[i * n + j];
        for (int k = 0; k < 5; ++k) p[k] = P[k * n + j];
        gs_rhs(tau, x, p, Q, dx);
        for (int i = 0; i < 4; ++i) DX[i * n + j] = dx[i];
    }
}
"""
)
