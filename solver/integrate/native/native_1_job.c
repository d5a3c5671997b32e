/* gearsym compiled integrators: one entry, gs_integrate(const gs_job *), for every run.
 *
 * Methods are data: the Butcher tableaux of ../tableau.py (Dormand-Prince 5(4), DOP853 and
 * the classic RK4, printed as C arrays by build.py) drive one explicit step, gs_stages.
 * The adaptive step control follows SciPy's RK45 and DOP853 (Hairer, Norsett and Wanner,
 * "Solving Ordinary Differential Equations I", II.4 and II.10): RMS error norm with scale
 * atol + rtol max(|y|, |y_new|), safety 0.9, factor in [0.2, 10], no growth right after a
 * rejection, the same initial-step selection.  Steps are clipped to land on every stop;
 * after a clipped step the unclipped proposal is kept.  RK4 steps on the fixed grid
 * t0 + j T / steps_per_period.
 *
 * One step loop serves every run: points go in groups that share time and step size
 * (a group of one is a point on its own steps); the time mode, what is collected and the
 * valid-range mode are fields of the job, not copies of the loop.  Benettin's tangent
 * renormalisation (gs_benettin) is the one used by every exponent.
 *
 * The model (gs_prep, gs_rhs, gs_rhs_batch, GS_NX, GS_NP, GS_NQ; GS_VARIATIONAL when the
 * state carries a tangent vector) and the tables are inserted above this text by build.py.
 */

#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define GS_ABI_VERSION 2

/* a point's status */
#define GS_OK 0
#define GS_DIVERGENT 1
#define GS_TOO_MANY_STEPS 2
#define GS_NOT_FINITE 3
#define GS_STEP_TOO_SMALL 4
#define GS_LEFT_RANGE 5

/* gs_integrate's refusals (nothing is written): abi.py words them */
#define GS_E_ABI (-1)
#define GS_E_SIZE (-2)
#define GS_E_OPTION (-3)
#define GS_E_NOMEM (-4)
#define GS_E_OMEGA (-5)

#define GS_DENSE 1        /* DOP853 samples by its dense output (samples-only runs) */
#define GS_BATCHED 2      /* the group's excitation once per stage (gs_rhs_batch) */
#define GS_PERIOD_STOPS 4 /* stop at every period of the transient too (map iteration) */
#define GS_MOST_GROUP 4096
#define GS_MOST_STOP ((int64_t)1 << 53)

/* The job: X(type, name) in order; 'i' int64_t, 'd' double, 'p' a pointer, each array
 * followed by its length in elements.  gs_job_fields() and gs_job_layout() export it so
 * that abi.py's ctypes.Structure is checked against it when the library loads. */
#define GS_JOB(X)                                                                          \
    X(i, int64_t, abi) X(i, int64_t, n_points) X(i, int64_t, n_states)                    \
    X(i, int64_t, n_params) X(i, int64_t, group) X(i, int64_t, transient)                \
    X(i, int64_t, periods) X(i, int64_t, samples_per_period)                              \
    X(i, int64_t, steps_per_period) X(i, int64_t, lyapunov_periods)                       \
    X(i, int64_t, max_steps) X(i, int64_t, method) X(i, int64_t, time_mode)               \
    X(i, int64_t, omega_index) X(i, int64_t, valid_range) X(i, int64_t, flags)           \
    X(d, double, t0) X(d, double, period) X(d, double, rtol) X(d, double, atol)           \
    X(d, double, bound)                                                                    \
    X(p, const double *, P) X(i, int64_t, P_len)                                           \
    X(p, const double *, X0) X(i, int64_t, X0_len)                                         \
    X(p, const double *, bounds) X(i, int64_t, bounds_len)                                 \
    X(p, const double *, tangent0) X(i, int64_t, tangent0_len)                             \
    X(p, double *, x) X(i, int64_t, x_len)                                                 \
    X(p, double *, xmin) X(i, int64_t, xmin_len)                                           \
    X(p, double *, xmax) X(i, int64_t, xmax_len)                                           \
    X(p, double *, exponent) X(i, int64_t, exponent_len)                                   \
    X(p, double *, tangent) X(i, int64_t, tangent_len)                                     \
    X(p, int64_t *, nfev) X(i, int64_t, nfev_len)                                          \
    X(p, int64_t *, nsteps) X(i, int64_t, nsteps_len)                                      \
    X(p, int32_t *, status) X(i, int64_t, status_len)                                      \
    X(p, double *, t_fail) X(i, int64_t, t_fail_len)                                       \
    X(p, double *, exits) X(i, int64_t, exits_len)

#define GS_MEMBER(code, type, name) type name;
typedef struct {
    GS_JOB(GS_MEMBER)
} gs_job;

#define GS_NAME(code, type, name) #name ":" #code " "
const char *gs_job_fields(void) { return GS_JOB(GS_NAME); }

#define GS_OFFSET(code, type, name) (int64_t) offsetof(gs_job, name),
int64_t gs_job_layout(int64_t *out, int64_t size)
{
    static const int64_t table[] = {GS_ABI_VERSION, (int64_t)sizeof(gs_job), GS_JOB(GS_OFFSET)};
    const int64_t count = (int64_t)(sizeof table / sizeof table[0]);
    for (int64_t k = 0; k < count && k < size; ++k) out[k] = table[k];
    return count;
}

typedef struct {
    int ns;           /* stages */
    const double *A;  /* ns x ns, row-major */
    const double *B;  /* ns */
    const double *C;  /* ns */
    const double *E;  /* ns + 1 (RK45) or NULL */
    const double *E3; /* ns + 1 (DOP853) or NULL */
    const double *E5; /* ns + 1 (DOP853) or NULL */
    int error_order;  /* 0: a fixed-step method */
} gs_tableau;

static const gs_tableau GS_TABLEAUX[3] = {
    {6, GS_RK45_A, GS_RK45_B, GS_RK45_C, GS_RK45_E, 0, 0, 4},
    {12, GS_DOP853_A, GS_DOP853_B, GS_DOP853_C, 0, GS_DOP853_E3, GS_DOP853_E5, 7},
    {4, GS_RK4_A, GS_RK4_B, GS_RK4_C, 0, 0, 0, 0},
};
#define GS_KROWS 16 /* DOP853: 12 stages, the FSAL stage and 3 of the dense output */

#if defined(GS_MONODROMY_N) /* the state and the matrix W (monodromy.c) */
#define GS_NSTATE GS_MONODROMY_N
#elif defined(GS_VARIATIONAL)
#define GS_NSTATE (GS_NX / 2)
#else
#define GS_NSTATE GS_NX
#endif

/* One run: the job, what it derives, and the work arrays of one group (structure of
 * arrays: component i of point j at [i n + j]). */
typedef struct {
    const gs_job *job;
    const gs_tableau *T;
    int phase, batched, dense, tangent, extremes, range, stop;
    int64_t n_pre, n_stops, lyap_from, done; /* done: fixed steps taken by the group */
    double *Pg, *Qg, *Y, *YT, *YN, *W, *K, *F, *E5s, *E3s, *growth;
    int *alive, *leave;
    long long nfev, nsteps;
    int group_status;
} gs_ctx;

static double gs_rms(const double *v, const double *scale)
{
    double s = 0.0;
    for (int i = 0; i < GS_NX; ++i) {
        const double r = v[i] / scale[i];
        s += r * r;
    }
    return sqrt(s / GS_NX);
}

static int gs_check(const double *y, int n_bounded, double bound)
{
    for (int i = 0; i < GS_NX; ++i) {
        if (!isfinite(y[i])) return GS_NOT_FINITE;
        if (i < n_bounded && fabs(y[i]) > bound) return GS_DIVERGENT;
    }
    return GS_OK;
}

static double gs_initial_step(double t0, const double *y0, const double *f0, double length,
                              int order, double rtol, double atol, const double *p,
                              const double *q, long long *nfev)
{
    double scale[GS_NX], tmp[GS_NX], y1[GS_NX], f1[GS_NX];
    for (int i = 0; i < GS_NX; ++i) scale[i] = atol + fabs(y0[i]) * rtol;
    const double d0 = gs_rms(y0, scale), d1 = gs_rms(f0, scale);
    double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    if (h0 > length) h0 = length;
    for (int i = 0; i < GS_NX; ++i) y1[i] = y0[i] + h0 * f0[i];
    gs_rhs(t0 + h0, y1, p, q, f1);
    *nfev += 1;
    for (int i = 0; i < GS_NX; ++i) tmp[i] = f1[i] - f0[i];
    const double d2 = gs_rms(tmp, scale) / h0;
    const double dm = d1 > d2 ? d1 : d2;
    const double h1 = dm <= 1e-15 ? fmax(1e-6, h0 * 1e-3) : pow(0.01 / dm, 1.0 / (order + 1));
    double h = 100 * h0;
    if (h1 < h) h = h1;
    if (length < h) h = length;
    return h;
}

