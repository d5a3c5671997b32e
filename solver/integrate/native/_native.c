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

#define GS_ABI_VERSION 1

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

#ifdef GS_VARIATIONAL
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

/* ---- The force law's valid range (|x_i| <= bounds_i), checked at every accepted step.
 * A step from (t, a0) to (t + h, a1) with slopes f0, f1 (NULL: a fixed step, straight
 * line) left the range of state i when the cubic Hermite interpolant of the step passes
 * |x| = r; the crossing is found by bisection on it.  A cheap bound skips almost every
 * step: |p| <= max(|a0|, |a1|) + (4/27) h (|f0| + |f1|) on the step (0.15 > 4/27). */
static double gs_hermite(double a0, double a1, double f0, double f1, double h, double x)
{
    const double x2 = x * x, x3 = x2 * x;
    return (2 * x3 - 3 * x2 + 1) * a0 + (x3 - 2 * x2 + x) * h * f0 + (-2 * x3 + 3 * x2) * a1 +
           (x3 - x2) * h * f1;
}

static double gs_on_step(double a0, double a1, const double *f0, const double *f1, double h,
                         double x)
{
    return f0 ? gs_hermite(a0, a1, f0[0], f1[0], h, x) : a0 + x * (a1 - a0);
}

/* Fraction x in (0, 1] of the step where |x_i| first passes r, or -1. */
static double gs_crossing(double a0, double a1, const double *f0, const double *f1, double h,
                          double r)
{
    const double slope = f0 ? 0.15 * fabs(h) * (fabs(f0[0]) + fabs(f1[0])) : 0.0;
    if (!(fmax(fabs(a0), fabs(a1)) + slope > r) || fabs(a0) > r) return -1.0;
    double lo = 0.0, hi = -1.0;
    for (int k = 1; k <= 16; ++k) {
        const double x = k / 16.0;
        if (fabs(gs_on_step(a0, a1, f0, f1, h, x)) > r) {
            hi = x;
            break;
        }
        lo = x;
    }
    if (hi < 0) return -1.0;
    for (int it = 0; it < 50; ++it) {
        const double x = 0.5 * (lo + hi);
        if (fabs(gs_on_step(a0, a1, f0, f1, h, x)) > r) hi = x;
        else lo = x;
    }
    return hi;
}

/* Record point `pt`'s first exit in a step of length h from t (component i of y0 / y1 at
 * [i st], slopes likewise or NULL); returns 1 when the point must stop there. */
static int gs_range_step(const gs_ctx *c, int64_t pt, double t, double h, const double *y0,
                         const double *y1, const double *f0, const double *f1, long st)
{
    double *exit = c->job->exits + 3 * pt;
    if (!c->range || !isnan(exit[0])) return 0;
    double best = 2.0, value = 0.0;
    int which = -1;
    for (int i = 0; i < GS_NSTATE; ++i) {
        const double r = c->job->bounds[i];
        if (!isfinite(r)) continue;
        const long e = (long)i * st;
        const double *g0 = f0 ? f0 + e : 0, *g1 = f1 ? f1 + e : 0;
        const double x = gs_crossing(y0[e], y1[e], g0, g1, h, r);
        if (x >= 0.0 && x < best) {
            best = x;
            which = i;
            value = gs_on_step(y0[e], y1[e], g0, g1, h, x);
        }
    }
    if (which < 0) return 0;
    exit[0] = t + best * h;
    exit[1] = which;
    exit[2] = value;
    return c->stop;
}

/* A start outside the valid range is an exit at t0; returns 1 when the point stops. */
static int gs_range_start(const gs_ctx *c, int64_t pt, const double *y)
{
    for (int i = 0; c->range && i < GS_NSTATE; ++i) {
        if (!(fabs(y[i]) > c->job->bounds[i])) continue;
        double *exit = c->job->exits + 3 * pt;
        exit[0] = c->job->t0;
        exit[1] = i;
        exit[2] = y[i];
        return c->stop;
    }
    return 0;
}

/* The group's right-hand side.  Phase mode: s = omega tau, each point with its own
 * omega = P[iw]: dX/ds = f(s / omega, X) / omega, so points of different forcing frequency
 * share the time grid.  Batched: the excitation once for the group (gs_rhs_batch).
 * Otherwise point by point. */
static void gs_rhs_group(const gs_ctx *c, double t, int n, const double *Y, double *K)
{
    if (c->batched && !c->phase) {
        gs_rhs_batch(t, n, Y, c->Pg, c->Qg, K);
        return;
    }
    if (n == 1 && !c->phase) { /* a point on its own: the group's arrays are its vectors */
        gs_rhs(t, Y, c->Pg, c->Qg, K);
        return;
    }
    for (int j = 0; j < n; ++j) {
        double x[GS_NX], p[GS_NP], q[GS_NQ > 0 ? GS_NQ : 1], dx[GS_NX];
        for (int i = 0; i < GS_NX; ++i) x[i] = Y[(long)i * n + j];
        for (int k = 0; k < GS_NP; ++k) p[k] = c->Pg[(long)k * n + j];
        for (int k = 0; k < GS_NQ; ++k) q[k] = c->Qg[(long)k * n + j];
        if (!c->phase) {
            gs_rhs(t, x, p, q, dx);
            for (int i = 0; i < GS_NX; ++i) K[(long)i * n + j] = dx[i];
            continue;
        }
        const double w = p[c->job->omega_index];
        gs_rhs(t / w, x, p, q, dx);
        for (int i = 0; i < GS_NX; ++i) K[(long)i * n + j] = dx[i] / w;
    }
}

/* out = w_0 K_0 + ... + w_{m-1} K_{m-1} on S elements (K_r at K + r S), each sum fused in
 * order of r.  The loops run along the contiguous elements, so they vectorise (a sum
 * along r for each element would gather K with stride S). */
static inline __attribute__((always_inline)) void
gs_weighted_any(double *restrict out, const double *restrict K, const double *restrict w,
                int m, long S)
{
    const double w0 = w[0];
    for (long e = 0; e < S; ++e) out[e] = w0 * K[e];
    for (int r = 1; r < m; ++r) {
        const double wr = w[r];
        const double *restrict Kr = K + r * S;
        for (long e = 0; e < S; ++e) out[e] = fma(wr, Kr[e], out[e]);
    }
}

/* A point on its own steps (S = GS_NX, known here) keeps out in registers. */
static void gs_weighted(double *restrict out, const double *restrict K,
                        const double *restrict w, int m, long S)
{
    if (S == GS_NX) gs_weighted_any(out, K, w, m, GS_NX);
    else gs_weighted_any(out, K, w, m, S);
}

/* out = y + hh (w_0 K_0 + ... + w_{m-1} K_{m-1}): a stage's state or the new state. */
static void gs_combine(double *restrict out, const double *restrict y,
                       const double *restrict K, const double *restrict w, int m, double hh,
                       long S)
{
    gs_weighted(out, K, w, m, S);
    for (long e = 0; e < S; ++e) out[e] = fma(hh, out[e], y[e]);
}

/* The explicit step of the tableau from (t, Y) with K[0] = f(t, Y): stages into K, the
 * new state into YN and its slope at t_new (first same as last) into K[ns]. */
static void gs_stages(gs_ctx *c, double t, double hh, double t_new, int n)
{
    const gs_tableau *T = c->T;
    const int ns = T->ns;
    const long S = (long)GS_NX * n;
    const double *K = c->K;
    for (int s = 1; s < ns; ++s) {
        gs_combine(c->YT, c->Y, K, T->A + s * ns, s, hh, S);
        gs_rhs_group(c, t + T->C[s] * hh, n, c->YT, c->K + s * S);
    }
    gs_combine(c->YN, c->Y, K, T->B, ns, hh, S);
    gs_rhs_group(c, t_new, n, c->YN, c->K + ns * S);
    c->nfev += ns;
}

/* Point j of the group stops with `status` at t (its state zeroed: it leaves the error
 * norm and the arithmetic stays finite). */
static void gs_stop_point(gs_ctx *c, int64_t g0, int n, int j, int status, double t)
{
    c->alive[j] = 0;
    c->job->status[g0 + j] = status;
    c->job->t_fail[g0 + j] = t;
    for (int i = 0; i < GS_NX; ++i) c->Y[(long)i * n + j] = 0.0;
}

/* The group's error norm of the step just taken: the largest of its points' norms
 * (each meets the tolerance); a point whose norm is not finite leaves the group. */
static double gs_error(gs_ctx *c, int64_t g0, int n, double t, double hh)
{
    const gs_tableau *T = c->T;
    const int ns = T->ns;
    const long S = (long)GS_NX * n;
    const double rtol = c->job->rtol, atol = c->job->atol;
    double *restrict E5s = c->E5s, *restrict E3s = c->E3s;
    /* the error estimates into the free work rows: YT (the stages are done) and W */
    double *restrict A5 = c->YT, *restrict A3 = c->W;
    gs_weighted(A5, c->K, T->E ? T->E : T->E5, ns + 1, S);
    if (T->E)
        for (long e = 0; e < S; ++e) A5[e] *= hh;
    else
        gs_weighted(A3, c->K, T->E3, ns + 1, S);
    for (int j = 0; j < n; ++j) E5s[j] = E3s[j] = 0.0;
    for (int i = 0; i < GS_NX; ++i) {
        const double *y0 = c->Y + (long)i * n, *y1 = c->YN + (long)i * n;
        for (int j = 0; j < n; ++j) {
            const long e = (long)i * n + j;
            const double a = fabs(y0[j]), b = fabs(y1[j]);
            const double sc = atol + (a > b ? a : b) * rtol;
            const double a5 = A5[e] / sc, a3 = T->E ? 0.0 : A3[e] / sc;
            E5s[j] += a5 * a5;
            E3s[j] += a3 * a3;
        }
    }
    double err = 0.0;
    for (int j = 0; j < n; ++j) {
        if (!c->alive[j]) continue;
        double ej;
        if (T->E)
            ej = sqrt(E5s[j] / GS_NX);
        else
            ej = (E5s[j] == 0.0 && E3s[j] == 0.0)
                     ? 0.0
                     : fabs(hh) * E5s[j] / sqrt((E5s[j] + 0.01 * E3s[j]) * GS_NX);
        if (!isfinite(ej)) {
            gs_stop_point(c, g0, n, j, GS_NOT_FINITE, t);
            continue;
        }
        if (ej > err) err = ej;
    }
    return err;
}

static double gs_sample_time(const gs_ctx *c, int64_t k)
{
    const gs_job *J = c->job;
    return J->t0 + (double)(J->transient * J->samples_per_period + k) * J->period /
                       (double)J->samples_per_period;
}

/* Write sample k of the group's points (alive and ok: from V; else NaN). */
static void gs_write_sample(gs_ctx *c, int64_t g0, int n, int64_t k, const double *V, int ok)
{
    const int64_t K = c->job->periods * c->job->samples_per_period + 1;
    for (int j = 0; j < n; ++j) {
        double *out = c->job->x + ((g0 + j) * K + k) * GS_NSTATE;
        for (int i = 0; i < GS_NSTATE; ++i)
            out[i] = ok && c->alive[j] ? V[(long)i * n + j] : NAN;
    }
}

/* DOP853's dense output over the accepted step [t, t + hh] (SciPy's Dop853DenseOutput):
 * the three extra stages into K rows 13..15, the seven interpolant coefficients into F
 * (7 x S); y(t + x hh) = Y + a Horner-like sum in x and 1 - x. */
static void gs_dense_coefficients(gs_ctx *c, double t, double hh, int n)
{
    const long S = (long)GS_NX * n;
    double *K = c->K, *F = c->F;
    for (int x = 0; x < 3; ++x) {
        const int row = 13 + x;
        gs_combine(c->YT, c->Y, K, GS_DOP853_AX + x * GS_KROWS, row, hh, S);
        gs_rhs_group(c, t + GS_DOP853_CX[x] * hh, n, c->YT, K + row * S);
    }
    for (long e = 0; e < S; ++e) {
        const double dy = c->YN[e] - c->Y[e], f0 = K[e], f1 = K[12 * S + e];
        F[e] = dy;
        F[S + e] = hh * f0 - dy;
        F[2 * S + e] = 2.0 * dy - hh * (f1 + f0);
    }
    for (int i = 0; i < 4; ++i) {
        double *Fi = F + (3 + i) * S;
        gs_weighted(Fi, K, GS_DOP853_D + i * GS_KROWS, GS_KROWS, S);
        for (long e = 0; e < S; ++e) Fi[e] *= hh;
    }
    c->nfev += 3;
}

/* The samples in (t, t + hh] of an accepted step, from its dense output. */
static void gs_dense_samples(gs_ctx *c, int64_t g0, int n, double t, double t_new,
                             int64_t *next)
{
    const int64_t n_samples = c->job->periods * c->job->samples_per_period + 1;
    const long S = (long)GS_NX * n;
    const double hh = t_new - t;
    int have_f = 0;
    for (; *next < n_samples; ++*next) {
        const double ts = gs_sample_time(c, *next);
        if (ts > t_new) break;
        if (ts == t_new) {
            gs_write_sample(c, g0, n, *next, c->YN, 1);
            continue;
        }
        if (!have_f) gs_dense_coefficients(c, t, hh, n);
        have_f = 1;
        const double x = (ts - t) / hh;
        for (int j = 0; j < n; ++j) {
            double *out = c->job->x + ((g0 + j) * n_samples + *next) * GS_NSTATE;
            for (int i = 0; i < GS_NSTATE; ++i) {
                const long e = (long)i * n + j;
                double y = 0.0;
                for (int r = 0; r < 7; ++r) {
                    y += c->F[(6 - r) * S + e];
                    y *= (r % 2 == 0) ? x : 1.0 - x;
                }
                out[i] = c->alive[j] ? y + c->Y[e] : NAN;
            }
        }
    }
}

static void gs_extremes(gs_ctx *c, int64_t g0, int n)
{
    for (int j = 0; j < n; ++j) {
        if (!c->alive[j]) continue;
        double *lo = c->job->xmin + (g0 + j) * GS_NSTATE, *hi = c->job->xmax + (g0 + j) * GS_NSTATE;
        for (int i = 0; i < GS_NSTATE; ++i) {
            const double y = c->Y[(long)i * n + j];
            if (y < lo[i]) lo[i] = y;
            if (y > hi[i]) hi[i] = y;
        }
    }
}

/* After an accepted step from t to t_new (YN, K[ns] its end): the valid range on the
 * step (slopes: Hermite; a fixed step: straight line), the step taken, every point checked
 * (finite, bound, range), the extremes in the window.  `sample_from`: the first sample
 * the step wrote by dense output (NaN again for a point that fails on it). */
static void gs_accept(gs_ctx *c, int64_t g0, int n, double t, double t_new, int slopes,
                      int in_window, int64_t sample_from, int64_t sample_to)
{
    const long S = (long)GS_NX * n;
    const int ns = c->T->ns;
    for (int j = 0; j < n; ++j)
        c->leave[j] = c->range && c->alive[j] && gs_range_step(c, g0 + j, t, t_new - t, c->Y + j, c->YN + j,
                                                   slopes ? c->K + j : 0,
                                                   slopes ? c->K + ns * S + j : 0, n);
    memcpy(c->Y, c->YN, sizeof(double) * S);
    memcpy(c->K, c->K + ns * S, sizeof(double) * S); /* first same as last */
    c->nsteps += 1;
    if (c->nsteps >= c->job->max_steps && c->group_status == GS_OK)
        c->group_status = GS_TOO_MANY_STEPS;
    int dead = 0;
    for (int j = 0; j < n; ++j) {
        if (!c->alive[j]) continue;
        double y[GS_NX];
        for (int i = 0; i < GS_NX; ++i) y[i] = c->Y[(long)i * n + j];
        int status = gs_check(y, GS_NSTATE, c->job->bound);
        if (status == GS_OK && c->leave[j]) status = GS_LEFT_RANGE;
        if (status == GS_OK) continue;
        gs_stop_point(c, g0, n, j, status, c->leave[j] ? c->job->exits[3 * (g0 + j)] : t_new);
        dead = 1;
        for (int64_t k = sample_from; k < sample_to; ++k) gs_write_sample(c, g0 + j, 1, k, y, 0);
    }
    if (dead) gs_rhs_group(c, t_new, n, c->Y, c->K); /* the first stage of the next step */
    if (in_window) gs_extremes(c, g0, n);
}

/* Advance the group to `target` by adaptive steps; dense output writes the samples the
 * steps pass. */
static void gs_adaptive_to(gs_ctx *c, int64_t g0, int n, double *t, double *h_abs,
                           double target, int in_window, int64_t *next_sample)
{
    const double exponent = -1.0 / (c->T->error_order + 1);
    while (*t < target && c->group_status == GS_OK) {
        const double min_step = 10.0 * fabs(nextafter(*t, INFINITY) - *t);
        double h = *h_abs < min_step ? min_step : *h_abs;
        int rejected = 0;
        for (;;) {
            if (!(h >= min_step)) {
                c->group_status = GS_STEP_TOO_SMALL;
                return;
            }
            double t_new = *t + h;
            int clipped = 0;
            if (t_new >= target) {
                t_new = target;
                clipped = 1;
            }
            const double hh = t_new - *t;
            gs_stages(c, *t, hh, *t + hh, n);
            const double err = gs_error(c, g0, n, *t, hh);
            if (err < 1.0) {
                double factor = err == 0.0 ? 10.0 : 0.9 * pow(err, exponent);
                if (factor > 10.0) factor = 10.0;
                if (rejected && factor > 1.0) factor = 1.0;
                const double next = hh * factor;
                /* keep the unclipped proposal after a step shortened to hit a stop */
                *h_abs = clipped && !rejected && h > next ? h : next;
                const int64_t from = *next_sample;
                if (c->dense) gs_dense_samples(c, g0, n, *t, t_new, next_sample);
                gs_accept(c, g0, n, *t, t_new, 1, in_window, from, *next_sample);
                *t = t_new;
                break;
            }
            double factor = 0.9 * pow(err, exponent);
            if (!(factor > 0.2)) factor = 0.2; /* also catches a NaN error norm */
            h = hh * factor;
            rejected = 1;
        }
    }
}

/* Advance the group by fixed steps on the grid t0 + j T / steps_per_period up to step
 * `upto`. */
static void gs_fixed_to(gs_ctx *c, int64_t g0, int n, double *t, int64_t upto, int in_window)
{
    const gs_job *J = c->job;
    const double h = J->period / (double)J->steps_per_period;
    for (; c->done < upto && c->group_status == GS_OK; ++c->done) {
        const double ta = J->t0 + (double)c->done * h, tb = J->t0 + (double)(c->done + 1) * h;
        gs_stages(c, ta, h, tb, n);
        gs_accept(c, g0, n, ta, tb, 0, in_window, 0, 0);
        *t = tb;
    }
}

/* Benettin's renormalisation of point j's tangent vector (components GS_NSTATE ..
 * GS_NX - 1): divided by its length g, returned (0: not a positive finite length).
 * Benettin, Galgani, Giorgilli and Strelcyn 1980, Meccanica 15. */
static double gs_benettin(double *Y, int n, int j)
{
    double g = 0.0;
    for (int i = GS_NSTATE; i < GS_NX; ++i) g += Y[(long)i * n + j] * Y[(long)i * n + j];
    g = sqrt(g);
    if (!(g > 0.0) || !isfinite(g)) return 0.0;
    for (int i = GS_NSTATE; i < GS_NX; ++i) Y[(long)i * n + j] /= g;
    return g;
}

/* At stop ko (index m on the grid of 1 / samples_per_period periods from t0): the sample,
 * the window's first extremes, and the exponent's renormalisation. */
static void gs_at_stop(gs_ctx *c, int64_t g0, int n, int64_t ko, double t)
{
    const gs_job *J = c->job;
    const int64_t spp = J->samples_per_period;
    const int ok = c->group_status == GS_OK;
    const int64_t k = ko - c->n_pre, m = k >= 0 ? J->transient * spp + k : ko * spp;
    if (k >= 0 && J->x) gs_write_sample(c, g0, n, k, c->Y, ok);
    if (k == 0 && c->extremes) gs_extremes(c, g0, n);
    if (!c->tangent || !ok) return;
    const int64_t n_lyap = J->lyapunov_periods, pk = m / spp;
    for (int j = 0; j < n; ++j) {
        if (!c->alive[j]) continue;
        const double g = gs_benettin(c->Y, n, j);
        if (g == 0.0) {
            gs_stop_point(c, g0, n, j, GS_NOT_FINITE, t);
            continue;
        }
        if (m <= c->lyap_from * spp) continue;
        c->growth[j] += log(g);
        if (m % spp == 0)
            J->exponent[(g0 + j) * n_lyap + pk - c->lyap_from - 1] =
                c->growth[j] / ((double)(pk - c->lyap_from) * J->period);
    }
    gs_rhs_group(c, t, n, c->Y, c->K); /* the first stage changed with the rescaling */
    c->nfev += 1;
}

/* The group's points at t0: state (and tangent), checks, first step size. */
static double gs_start(gs_ctx *c, int64_t g0, int n)
{
    const gs_job *J = c->job;
    double h_abs = INFINITY;
    const double t_end = gs_sample_time(c, J->periods * J->samples_per_period);
    for (int j = 0; j < n; ++j) {
        const double *p = J->P + (g0 + j) * GS_NP;
        double q[GS_NQ > 0 ? GS_NQ : 1], f[GS_NX], y[GS_NX];
        gs_prep(p, q);
        for (int k = 0; k < GS_NP; ++k) c->Pg[k * n + j] = p[k];
        for (int k = 0; k < GS_NQ; ++k) c->Qg[k * n + j] = q[k];
        for (int i = 0; i < GS_NSTATE; ++i) y[i] = J->X0[(g0 + j) * GS_NSTATE + i];
        for (int i = GS_NSTATE; i < GS_NX; ++i) y[i] = J->tangent0[i - GS_NSTATE];
        for (int i = 0; i < GS_NX; ++i) c->Y[i * n + j] = y[i];
        gs_rhs(J->t0, y, p, q, f);
        c->alive[j] = 1;
        c->growth[j] = 0.0;
        J->status[g0 + j] = GS_OK;
        J->t_fail[g0 + j] = NAN;
        if (c->extremes)
            for (int i = 0; i < GS_NSTATE; ++i) {
                J->xmin[(g0 + j) * GS_NSTATE + i] = INFINITY;
                J->xmax[(g0 + j) * GS_NSTATE + i] = -INFINITY;
            }
        int status = gs_check(y, GS_NSTATE, J->bound);
        if (status == GS_OK) status = gs_check(f, 0, INFINITY);
        if (status == GS_OK && gs_range_start(c, g0 + j, y)) status = GS_LEFT_RANGE;
        if (status != GS_OK) {
            gs_stop_point(c, g0, n, j, status, J->t0);
            continue;
        }
        if (!c->T->error_order) continue;
        /* in the phase a small first step; the control adapts it at once */
        const double h0 = c->phase ? 1e-3 * J->period
                                   : gs_initial_step(J->t0, y, f, t_end - J->t0,
                                                     c->T->error_order, J->rtol, J->atol, p, q,
                                                     &c->nfev);
        if (h0 < h_abs) h_abs = h0;
    }
    if (!isfinite(h_abs)) h_abs = 1e-6 * J->period;
    c->nfev = c->nfev / (n > 0 ? n : 1) + 1;
    gs_rhs_group(c, J->t0, n, c->Y, c->K); /* K[0] = f(t0, y0) */
    return h_abs;
}

/* One group of n points from g0: start, every stop, the statuses and counters. */
static void gs_group(gs_ctx *c, int64_t g0, int n)
{
    const gs_job *J = c->job;
    const int64_t spp = J->samples_per_period;
    c->nfev = c->nsteps = 0;
    c->done = 0;
    c->group_status = GS_OK;
    double h_abs = gs_start(c, g0, n), t = J->t0;
    int64_t next = 0; /* dense: the next sample to write */
    if (c->dense)
        while (next < J->periods * spp + 1 && gs_sample_time(c, next) <= t)
            gs_write_sample(c, g0, n, next++, c->Y, 1);
    int64_t reached = c->n_stops; /* stops done */
    for (int64_t ko = 0; ko < (c->dense ? 1 : c->n_stops); ++ko) {
        int any = 0;
        for (int j = 0; j < n; ++j) any |= c->alive[j];
        const int64_t k = c->dense ? J->periods * spp : ko - c->n_pre;
        const int64_t m = k >= 0 ? J->transient * spp + k : ko * spp;
        const int in_window = c->extremes && k > 0;
        if (!any) {
            reached = ko;
            break;
        }
        if (c->T->error_order)
            gs_adaptive_to(c, g0, n, &t, &h_abs, gs_sample_time(c, k), in_window, &next);
        else
            gs_fixed_to(c, g0, n, &t, m * (J->steps_per_period / spp), in_window);
        if (!c->dense) gs_at_stop(c, g0, n, ko, t);
    }
    /* samples not reached: a group whose points all stopped, dense output cut short */
    for (int64_t k = c->dense ? next : reached - c->n_pre; J->x && k < J->periods * spp + 1; ++k)
        if (k >= 0) gs_write_sample(c, g0, n, k, c->Y, 0);
    for (int j = 0; j < n; ++j) {
        const int64_t pt = g0 + j;
        J->nfev[pt] = c->nfev;
        J->nsteps[pt] = c->nsteps;
        if (J->status[pt] == GS_OK && c->group_status != GS_OK) {
            J->status[pt] = c->group_status;
            J->t_fail[pt] = t;
        }
        if (c->tangent && J->status[pt] != GS_OK)
            for (int64_t r = 0; r < J->lyapunov_periods; ++r)
                J->exponent[pt * J->lyapunov_periods + r] = NAN;
    }
}

static int gs_product(int64_t a, int64_t b, int64_t *out)
{
    return a < 0 || b < 0 || __builtin_mul_overflow(a, b, out);
}

/* An array of `len` elements where `want` (a product, checked) are needed; NULL allowed
 * when `optional`. */
static int gs_array_ok(const void *ptr, int64_t len, int64_t a, int64_t b, int optional)
{
    int64_t want;
    if (!ptr) return optional;
    return !gs_product(a, b, &want) && len == want;
}

/* Every size, option and array length of the job, before anything is written. */
static int gs_check_job(const gs_job *J)
{
    int64_t n_samples, total, steps;
    if (J->abi != GS_ABI_VERSION) return GS_E_ABI;
    if (J->n_points < 0 || J->n_states != GS_NSTATE || J->n_params != GS_NP) return GS_E_SIZE;
    if (J->group < 1 || J->group > GS_MOST_GROUP || J->transient < 0 || J->periods < 1 ||
        J->samples_per_period < 1 || J->steps_per_period < 1 || J->max_steps < 1 ||
        J->lyapunov_periods < 0)
        return GS_E_OPTION;
    if (gs_product(J->periods, J->samples_per_period, &n_samples) || n_samples >= GS_MOST_STOP ||
        J->transient > GS_MOST_STOP || gs_product(J->transient + J->periods,
                                                  J->samples_per_period, &total) ||
        total >= GS_MOST_STOP)
        return GS_E_SIZE;
    if (J->method < 0 || J->method > 2 || J->time_mode < 0 || J->time_mode > 1 ||
        J->valid_range < 0 || J->valid_range > 2 || (J->flags & ~7) ||
        J->lyapunov_periods > J->transient + J->periods)
        return GS_E_OPTION;
    if (J->method == 2 && (J->time_mode == 1 || J->steps_per_period % J->samples_per_period ||
                           gs_product(J->transient + J->periods, J->steps_per_period, &steps) ||
                           steps >= GS_MOST_STOP))
        return GS_E_OPTION;
    if (!(J->rtol > 0 && J->atol > 0 && J->bound > 0 && J->period > 0 && isfinite(J->t0) &&
          isfinite(J->period)))
        return GS_E_OPTION;
    const int64_t N = J->n_points, n = J->n_states, L = J->lyapunov_periods;
    int64_t Nn;
    if (gs_product(N, n, &Nn) || !gs_array_ok(J->P, J->P_len, N, GS_NP, 0) ||
        !gs_array_ok(J->X0, J->X0_len, N, n, 0) ||
        !gs_array_ok(J->x, J->x_len, Nn, n_samples + 1, 1) ||
        !gs_array_ok(J->xmin, J->xmin_len, N, n, 1) || !gs_array_ok(J->xmax, J->xmax_len, N, n, 1) ||
        !J->xmin != !J->xmax || !gs_array_ok(J->nfev, J->nfev_len, N, 1, 0) ||
        !gs_array_ok(J->nsteps, J->nsteps_len, N, 1, 0) ||
        !gs_array_ok(J->status, J->status_len, N, 1, 0) ||
        !gs_array_ok(J->t_fail, J->t_fail_len, N, 1, 0))
        return GS_E_SIZE;
    const int check = J->valid_range != 2;
    if (!gs_array_ok(J->bounds, J->bounds_len, n, 1, !check) ||
        !gs_array_ok(J->exits, J->exits_len, N, 3, !check) || (!check && (J->bounds || J->exits)))
        return GS_E_SIZE;
    /* the exponent: the variational library, a tangent start, period stops */
    if (!gs_array_ok(J->exponent, J->exponent_len, N, L, 1) || (!J->exponent) != (L == 0) ||
        (J->exponent && (GS_NSTATE == GS_NX || !(J->flags & GS_PERIOD_STOPS))) ||
        !gs_array_ok(J->tangent0, J->tangent0_len, GS_NX - GS_NSTATE, 1, GS_NSTATE == GS_NX))
        return GS_E_SIZE;
    if (J->time_mode == 1) {
        if (J->omega_index < 0 || J->omega_index >= GS_NP) return GS_E_OPTION;
        for (int64_t j = 0; j < N; ++j)
            if (!(J->P[j * GS_NP + J->omega_index] > 0.0)) return GS_E_OMEGA;
    }
    return 0;
}

/* Integrate the job (abi.py fills it, engine.py reads it back).  Returns 0, or a
 * GS_E_ code with nothing written. */
int gs_integrate(const gs_job *J)
{
    if (!J) return GS_E_SIZE;
    const int refused = gs_check_job(J);
    if (refused) return refused;
    const int64_t spp = J->samples_per_period;
    gs_ctx c = {.job = J, .T = &GS_TABLEAUX[J->method]};
    c.phase = J->time_mode == 1;
    c.batched = (J->flags & GS_BATCHED) != 0;
    c.tangent = J->exponent != 0;
    c.extremes = J->xmin != 0;
    c.dense = (J->flags & GS_DENSE) && J->method == 1 && J->x && !c.extremes && !c.tangent;
    c.range = J->valid_range != 2;
    c.stop = J->valid_range == 1;
    c.n_pre = (J->flags & GS_PERIOD_STOPS) ? J->transient : 0;
    c.n_stops = c.n_pre + J->periods * spp + 1;
    c.lyap_from = J->transient + J->periods - J->lyapunov_periods;
    const size_t G = (size_t)(J->group < J->n_points ? J->group : J->n_points > 0 ? J->n_points : 1);
    int code = GS_E_NOMEM;
    c.Pg = malloc(sizeof(double) * GS_NP * G);
    c.Qg = malloc(sizeof(double) * (GS_NQ > 0 ? GS_NQ : 1) * G);
    c.Y = malloc(sizeof(double) * GS_NX * G);
    c.YT = malloc(sizeof(double) * GS_NX * G);
    c.YN = malloc(sizeof(double) * GS_NX * G);
    c.W = malloc(sizeof(double) * GS_NX * G);
    c.K = malloc(sizeof(double) * GS_KROWS * GS_NX * G);
    c.F = c.dense ? malloc(sizeof(double) * 7 * GS_NX * G) : 0;
    c.E5s = malloc(sizeof(double) * G);
    c.E3s = malloc(sizeof(double) * G);
    c.growth = malloc(sizeof(double) * G);
    c.alive = malloc(sizeof(int) * G);
    c.leave = malloc(sizeof(int) * G);
    if (!c.Pg || !c.Qg || !c.Y || !c.YT || !c.YN || !c.W || !c.K || (c.dense && !c.F) || !c.E5s ||
        !c.E3s || !c.growth || !c.alive || !c.leave)
        goto cleanup;
    for (int64_t k = 0; c.range && k < 3 * J->n_points; ++k) J->exits[k] = NAN;
    for (int64_t g0 = 0; g0 < J->n_points; g0 += (int64_t)G) {
        const int64_t left = J->n_points - g0;
        gs_group(&c, g0, (int)(left < (int64_t)G ? left : (int64_t)G));
    }
    code = 0;
cleanup:
    free(c.Pg);
    free(c.Qg);
    free(c.Y);
    free(c.YT);
    free(c.YN);
    free(c.W);
    free(c.K);
    free(c.F);
    free(c.E5s);
    free(c.E3s);
    free(c.growth);
    free(c.alive);
    free(c.leave);
    return code;
}

/* Right-hand-side evaluations only (for the throughput benchmark): n calls at one point. */
double gs_rhs_loop(const double *p, const double *x0, long long n, double dt)
{
    double q[GS_NQ > 0 ? GS_NQ : 1], x[GS_NX], dx[GS_NX], acc = 0.0;
    gs_prep(p, q);
    memcpy(x, x0, sizeof(double) * GS_NX);
    for (long long k = 0; k < n; ++k) {
        gs_rhs(k * dt, x, p, q, dx);
        x[0] += 1e-12 * dx[GS_NX - 1];
        acc += dx[GS_NX - 1];
    }
    return acc;
}

/* One right-hand-side evaluation (tests compare it with the NumPy code). */
void gs_eval(double tau, const double *x, const double *p, double *dx)
{
    double q[GS_NQ > 0 ? GS_NQ : 1];
    gs_prep(p, q);
    gs_rhs(tau, x, p, q, dx);
}

/* The batched form on n points (structure of arrays; tests compare it too). */
void gs_eval_batch(double tau, int n, const double *X, const double *P, double *DX)
{
    double *Q = malloc(sizeof(double) * (GS_NQ > 0 ? GS_NQ : 1) * (n > 0 ? n : 1));
    double p[GS_NP], q[GS_NQ > 0 ? GS_NQ : 1];
    if (!Q) return;
    for (int j = 0; j < n; ++j) {
        for (int k = 0; k < GS_NP; ++k) p[k] = P[k * n + j];
        gs_prep(p, q);
        for (int k = 0; k < GS_NQ; ++k) Q[k * n + j] = q[k];
    }
    gs_rhs_batch(tau, n, X, P, Q, DX);
    free(Q);
}
