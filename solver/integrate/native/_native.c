/* gearsym compiled integrators: Dormand-Prince 5(4), DOP853 and classic RK4, many parameter
 * points per call, stroboscopic/uniform sampling after a transient.
 *
 * The step-size control follows SciPy's RK45 and DOP853 (Hairer, Norsett and Wanner,
 * "Solving Ordinary Differential Equations I", II.4 and II.10): RMS error norm with
 * scale atol + rtol max(|y|, |y_new|), safety 0.9, factor in [0.2, 10], no growth right after
 * a rejection, and the same initial-step selection.  Steps are clipped to land on every
 * sample time; after a clipped step the unclipped proposal is kept.
 *
 * The model (gs_prep, gs_rhs, GS_NX, GS_NP, GS_NQ) and the Butcher tables (the checked
 * tableaux of ../tableau.py, SciPy's coefficient arrays) are inserted above this text by
 * build.py.
 */

#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <string.h>

#define GS_OK 0
#define GS_DIVERGENT 1
#define GS_TOO_MANY_STEPS 2
#define GS_NOT_FINITE 3
#define GS_STEP_TOO_SMALL 4
#define GS_LEFT_RANGE 5 /* left the force law's valid range (maps; runs that stop there) */

typedef struct {
    int ns;           /* stages */
    const double *A;  /* ns x ns, row-major */
    const double *B;  /* ns */
    const double *C;  /* ns */
    const double *E;  /* ns + 1 (RK45) or NULL */
    const double *E3; /* ns + 1 (DOP853) or NULL */
    const double *E5; /* ns + 1 (DOP853) or NULL */
    int error_order;
} gs_tableau;

#define GS_MAXS 13

static const gs_tableau GS_RK45 = {6, GS_RK45_A, GS_RK45_B, GS_RK45_C, GS_RK45_E, 0, 0, 4};
static const gs_tableau GS_DOP853 = {12, GS_DOP853_A, GS_DOP853_B, GS_DOP853_C, 0,
                                     GS_DOP853_E3, GS_DOP853_E5, 7};

static double gs_rms(const double *v, const double *scale)
{
    double s = 0.0;
    for (int i = 0; i < GS_NX; ++i) {
        const double r = v[i] / scale[i];
        s += r * r;
    }
    return sqrt(s / GS_NX);
}

/* One explicit RK step: fills K[0..ns] (K[ns] = f(t + h, y_new)) and y_new. */
static void gs_step(const gs_tableau *T, double t, const double *y, const double *f, double h,
                    const double *p, const double *q, double K[GS_MAXS + 1][GS_NX],
                    double *ynew)
{
    double yt[GS_NX];
    memcpy(K[0], f, sizeof(double) * GS_NX);
    for (int s = 1; s < T->ns; ++s) {
        for (int i = 0; i < GS_NX; ++i) {
            double acc = 0.0;
            for (int j = 0; j < s; ++j) acc += T->A[s * T->ns + j] * K[j][i];
            yt[i] = y[i] + h * acc;
        }
        gs_rhs(t + T->C[s] * h, yt, p, q, K[s]);
    }
    for (int i = 0; i < GS_NX; ++i) {
        double acc = 0.0;
        for (int j = 0; j < T->ns; ++j) acc += T->B[j] * K[j][i];
        ynew[i] = y[i] + h * acc;
    }
    gs_rhs(t + h, ynew, p, q, K[T->ns]);
}

static double gs_error_norm(const gs_tableau *T, double K[GS_MAXS + 1][GS_NX], double h,
                            const double *scale)
{
    double e[GS_NX];
    if (T->E) {
        for (int i = 0; i < GS_NX; ++i) {
            double acc = 0.0;
            for (int j = 0; j <= T->ns; ++j) acc += T->E[j] * K[j][i];
            e[i] = acc * h;
        }
        return gs_rms(e, scale);
    }
    double e5 = 0.0, e3 = 0.0;
    for (int i = 0; i < GS_NX; ++i) {
        double a5 = 0.0, a3 = 0.0;
        for (int j = 0; j <= T->ns; ++j) {
            a5 += T->E5[j] * K[j][i];
            a3 += T->E3[j] * K[j][i];
        }
        a5 /= scale[i];
        a3 /= scale[i];
        e5 += a5 * a5;
        e3 += a3 * a3;
    }
    if (e5 == 0.0 && e3 == 0.0) return 0.0;
    return fabs(h) * e5 / sqrt((e5 + 0.01 * e3) * GS_NX);
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

static int gs_check(const double *y, double bound)
{
    for (int i = 0; i < GS_NX; ++i) {
        if (!isfinite(y[i])) return GS_NOT_FINITE;
        if (fabs(y[i]) > bound) return GS_DIVERGENT;
    }
    return GS_OK;
}

/* ---- The force law's valid range (|x_i| <= range_i), checked at every accepted step. ----
 * A step from (t, a0) to (t + h, a1) with slopes f0, f1 (NULL: a fixed step, straight
 * line) left the range of state i when the cubic Hermite interpolant of the step passes
 * |x| = r; the crossing is found by bisection on it.  A cheap bound skips almost every
 * step: |p| <= max(|a0|, |a1|) + (4/27) h (|f0| + |f1|) on the step (0.15 > 4/27 below). */
typedef struct {
    const double *range; /* GS_NX bounds (INFINITY: none), or NULL */
    int stop;            /* 1: the point stops at its first exit (status GS_LEFT_RANGE) */
    double *exit;        /* npts x 3: tau, state index, value of the first exit (tau NaN) */
} gs_range_t;

static double gs_hermite(double a0, double a1, double f0, double f1, double h, double x)
{
    const double x2 = x * x, x3 = x2 * x;
    return (2 * x3 - 3 * x2 + 1) * a0 + (x3 - 2 * x2 + x) * h * f0 + (-2 * x3 + 3 * x2) * a1 +
           (x3 - x2) * h * f1;
}

/* Fraction x in (0, 1] of the step where |x_i| first passes r, or -1. */
static double gs_crossing(double a0, double a1, const double *f0, const double *f1, double h,
                          double r)
{
    const double d0 = f0 ? f0[0] : 0.0, d1 = f1 ? f1[0] : 0.0;
    const double reach = fmax(fabs(a0), fabs(a1)) + (f0 ? 0.15 * fabs(h) * (fabs(d0) + fabs(d1)) : 0.0);
    if (!(reach > r) || fabs(a0) > r) return -1.0;
    double lo = 0.0, hi = -1.0;
    for (int k = 1; k <= 16; ++k) {
        const double x = k / 16.0;
        const double v = f0 ? gs_hermite(a0, a1, d0, d1, h, x) : a0 + x * (a1 - a0);
        if (fabs(v) > r) {
            hi = x;
            break;
        }
        lo = x;
    }
    if (hi < 0) return -1.0;
    for (int it = 0; it < 50; ++it) {
        const double x = 0.5 * (lo + hi);
        const double v = f0 ? gs_hermite(a0, a1, d0, d1, h, x) : a0 + x * (a1 - a0);
        if (fabs(v) > r) hi = x; else lo = x;
    }
    return hi;
}

/* Record point j's first exit in a step of length h from t (state i of y0 / y1 at
 * stride `st`, slopes likewise or NULL); returns 1 when the point must stop. */
static int gs_range_step(const gs_range_t *rg, int j, double t, double h, const double *y0,
                         const double *y1, const double *f0, const double *f1, long st)
{
    if (!rg || !rg->range || !isnan(rg->exit[3 * (long)j])) return 0;
    double best = 2.0, value = 0.0;
    int which = -1;
    for (int i = 0; i < GS_NX; ++i) {
        const double r = rg->range[i];
        if (!isfinite(r)) continue;
        const long e = (long)i * st;
        const double x = gs_crossing(y0[e], y1[e], f0 ? f0 + e : 0, f1 ? f1 + e : 0, h, r);
        if (x >= 0.0 && x < best) {
            best = x;
            which = i;
            value = f0 ? gs_hermite(y0[e], y1[e], f0[e], f1[e], h, x) : y0[e] + x * (y1[e] - y0[e]);
        }
    }
    if (which < 0) return 0;
    rg->exit[3 * (long)j] = t + best * h;
    rg->exit[3 * (long)j + 1] = which;
    rg->exit[3 * (long)j + 2] = value;
    return rg->stop;
}

/* Advance (t, y, f) to `target` with the adaptive method. */
static int gs_adaptive_to(const gs_tableau *T, double *t, double *y, double *f, double *h_abs,
                          double target, double rtol, double atol, const double *p,
                          const double *q, double bound, long long max_steps, long long *nfev,
                          long long *nsteps, const gs_range_t *rg, int j)
{
    double K[GS_MAXS + 1][GS_NX], ynew[GS_NX], scale[GS_NX];
    const double exponent = -1.0 / (T->error_order + 1);
    while (*t < target) {
        const double min_step = 10.0 * fabs(nextafter(*t, INFINITY) - *t);
        if (!isfinite(*h_abs)) return GS_NOT_FINITE;
        double h = *h_abs < min_step ? min_step : *h_abs;
        int rejected = 0;
        for (;;) {
            if (!(h >= min_step)) return GS_STEP_TOO_SMALL;
            double t_new = *t + h;
            int clipped = 0;
            if (t_new >= target) {
                t_new = target;
                clipped = 1;
            }
            const double hh = t_new - *t;
            gs_step(T, *t, y, f, hh, p, q, K, ynew);
            *nfev += T->ns;
            for (int i = 0; i < GS_NX; ++i) {
                const double a = fabs(y[i]), b = fabs(ynew[i]);
                scale[i] = atol + (a > b ? a : b) * rtol;
            }
            const double err = gs_error_norm(T, K, hh, scale);
            if (err < 1.0) {
                double factor = err == 0.0 ? 10.0 : 0.9 * pow(err, exponent);
                if (factor > 10.0) factor = 10.0;
                if (rejected && factor > 1.0) factor = 1.0;
                const double next = hh * factor;
                /* keep the unclipped proposal after a step shortened to hit a sample */
                *h_abs = clipped && !rejected && h > next ? h : next;
                const int leave = gs_range_step(rg, j, *t, hh, y, ynew, f, K[T->ns], 1);
                *t = t_new;
                memcpy(y, ynew, sizeof(double) * GS_NX);
                memcpy(f, K[T->ns], sizeof(double) * GS_NX);
                if (leave) {
                    *nsteps += 1;
                    return GS_LEFT_RANGE;
                }
                break;
            }
            double factor = 0.9 * pow(err, exponent);
            if (!(factor > 0.2)) factor = 0.2; /* also catches a NaN error norm */
            h = hh * factor;
            rejected = 1;
        }
        *nsteps += 1;
        const int c = gs_check(y, bound);
        if (c != GS_OK) return c;
        if (*nsteps >= max_steps) return GS_TOO_MANY_STEPS;
    }
    return GS_OK;
}

static void gs_rk4_step(double t, double *y, double h, const double *p, const double *q)
{
    double k1[GS_NX], k2[GS_NX], k3[GS_NX], k4[GS_NX], yt[GS_NX];
    gs_rhs(t, y, p, q, k1);
    for (int i = 0; i < GS_NX; ++i) yt[i] = y[i] + 0.5 * h * k1[i];
    gs_rhs(t + 0.5 * h, yt, p, q, k2);
    for (int i = 0; i < GS_NX; ++i) yt[i] = y[i] + 0.5 * h * k2[i];
    gs_rhs(t + 0.5 * h, yt, p, q, k3);
    for (int i = 0; i < GS_NX; ++i) yt[i] = y[i] + h * k3[i];
    gs_rhs(t + h, yt, p, q, k4);
    for (int i = 0; i < GS_NX; ++i) y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

/* method: 0 = Dormand-Prince 5(4), 1 = DOP853, 2 = RK4 with rk4_steps steps per period.
 * P: npts x GS_NP, X0: npts x GS_NX, OUT: npts x (n_sample*spp + 1) x GS_NX.
 * Sample k of point i is at t0 + (n_transient + k/spp) period. */
int gs_run(int method, int npts, const double *P, const double *X0, double t0, double period,
           int n_transient, int n_sample, int spp, double rtol, double atol, int rk4_steps,
           double bound, long long max_steps, double *OUT, long long *NFEV, long long *NSTEP,
           int *STATUS, double *TFAIL, const double *RANGE, int stop_exit, double *EXIT)
{
    const gs_range_t rg = {RANGE, stop_exit, EXIT};
    for (long k = 0; k < 3L * npts; ++k) EXIT[k] = NAN;
    const gs_tableau *T = method == 0 ? &GS_RK45 : &GS_DOP853;
    const int n_out = n_sample * spp + 1;
    for (int i = 0; i < npts; ++i) {
        const double *p = P + (long)i * GS_NP;
        double q[GS_NQ], y[GS_NX], f[GS_NX];
        double *out = OUT + (long)i * n_out * GS_NX;
        long long nfev = 0, nsteps = 0;
        int status = GS_OK;
        double t = t0;
        gs_prep(p, q);
        memcpy(y, X0 + (long)i * GS_NX, sizeof(double) * GS_NX);
        double h_abs = 0.0;
        const double t_end = t0 + (double)(n_transient + n_sample) * period;
        status = gs_check(y, bound);
        if (status == GS_OK && method != 2) {
            gs_rhs(t, y, p, q, f);
            nfev += 1;
            status = gs_check(f, INFINITY);
            h_abs = gs_initial_step(t, y, f, t_end - t0, T->error_order, rtol, atol, p, q,
                                    &nfev);
        }
        int k = 0;
        long long done = 0; /* RK4 steps taken */
        const int bad_start = status != GS_OK;
        for (; k < n_out && !bad_start; ++k) {
            const double target =
                t0 + ((double)n_transient * spp + k) * period / (double)spp;
            if (method == 2) {
                /* steps are laid on the global grid t0 + j period / rk4_steps */
                const long long upto =
                    ((long long)n_transient * spp + k) * (long long)rk4_steps / spp;
                const double h = period / rk4_steps;
                for (; done < upto; ++done) {
                    double y_old[GS_NX];
                    memcpy(y_old, y, sizeof(double) * GS_NX);
                    gs_rk4_step(t0 + done * h, y, h, p, q);
                    nfev += 4;
                    nsteps += 1;
                    status = gs_check(y, bound);
                    if (status == GS_OK && gs_range_step(&rg, i, t0 + done * h, h, y_old, y, 0, 0, 1))
                        status = GS_LEFT_RANGE;
                    if (status != GS_OK) {
                        t = t0 + (done + 1) * h;
                        break;
                    }
                }
                if (status == GS_OK) t = target;
            } else {
                status = gs_adaptive_to(T, &t, y, f, &h_abs, target, rtol, atol, p, q, bound,
                                        max_steps, &nfev, &nsteps, &rg, i);
            }
            if (status != GS_OK) break;
            memcpy(out + (long)k * GS_NX, y, sizeof(double) * GS_NX);
        }
        for (; k < n_out; ++k)
            for (int j = 0; j < GS_NX; ++j) out[(long)k * GS_NX + j] = NAN;
        NFEV[i] = nfev;
        NSTEP[i] = nsteps;
        STATUS[i] = status;
        TFAIL[i] = status == GS_OK ? NAN : status == GS_LEFT_RANGE ? EXIT[3 * (long)i] : t;
    }
    return 0;
}

/* Right-hand-side evaluations only (for the throughput benchmark): n calls at one point. */
double gs_rhs_loop(const double *p, const double *x0, long long n, double dt)
{
    double q[GS_NQ], x[GS_NX], dx[GS_NX], acc = 0.0;
    gs_prep(p, q);
    memcpy(x, x0, sizeof(double) * GS_NX);
    for (long long k = 0; k < n; ++k) {
        gs_rhs(k * dt, x, p, q, dx);
        x[0] += 1e-12 * dx[GS_NX - 1];
        acc += dx[GS_NX - 1];
    }
    return acc;
}

/* ---- Lockstep integration: a group of points shares time and step size. ----
 * The excitation terms are computed once per stage for the group (gs_rhs_batch) and the
 * per-point arithmetic vectorises.  The error norm of the group is the largest of its
 * points' norms, so every point meets the tolerance.  A point that diverges or turns
 * non-finite is marked, frozen and left out of the error norm.
 *
 * One engine serves plain sampled runs (gs_run_lockstep) and maps (gs_map_lockstep): the
 * group stops at t0 + (first + k) period / spp, k = 0 .. n_stops - 1, and `gs_extras`
 * says what a map keeps at each stop and after each accepted step. */
#include <stdlib.h>

typedef struct {
    int n_state;         /* components of the physical state (GS_NX / 2 with a tangent) */
    int tangent;         /* 1: components n_state .. 2 n_state - 1 are a tangent vector */
    int first_kept;      /* stop from which Poincare points and extremes are kept */
    int lyap_from;       /* log growth of the tangent is summed over stops after this one */
    const double *range; /* n_state bounds |x_i| <= range[i] (the force law's valid range) */
    double *poinc;       /* npts x (n_stops - first_kept) x n_state */
    double *xmin;        /* npts x n_state, over accepted steps and stops in the window */
    double *xmax;
    double *lyap;        /* npts x (n_stops - 1 - lyap_from): running exponent */
} gs_extras;

/* Status of point j (structure of arrays, n points) after a step: bound and valid range on
 * the physical state, finiteness on the rest. */
static int gs_check_soa(const double *Y, int n, int j, double bound, const gs_extras *m)
{
    const int ns = m ? m->n_state : GS_NX;
    for (int i = 0; i < GS_NX; ++i) {
        const double y = Y[(long)i * n + j];
        if (!isfinite(y)) return GS_NOT_FINITE;
        if (i < ns && fabs(y) > bound) return GS_DIVERGENT;
        if (i < ns && m && m->range && fabs(y) > m->range[i]) return GS_LEFT_RANGE;
    }
    return GS_OK;
}

static void gs_extremes(const double *Y, int n, int g0, const int *alive, const gs_extras *m)
{
    for (int j = 0; j < n; ++j) {
        if (!alive[j]) continue;
        double *lo = m->xmin + (long)(g0 + j) * m->n_state;
        double *hi = m->xmax + (long)(g0 + j) * m->n_state;
        for (int i = 0; i < m->n_state; ++i) {
            const double y = Y[(long)i * n + j];
            if (y < lo[i]) lo[i] = y;
            if (y > hi[i]) hi[i] = y;
        }
    }
}

/* The group's right-hand side.  iw < 0: in tau, the excitation computed once for the group
 * (gs_rhs_batch).  iw >= 0: in the excitation phase s = omega tau, each point with its own
 * omega = P[iw]: dX/ds = f(s / omega, X) / omega, so points of different forcing frequency
 * share the time grid (frequency sweeps in lockstep). */
static void gs_rhs_group(int iw, double t, int n, const double *Y, const double *Pg,
                         const double *Qg, double *K)
{
    if (iw < 0) {
        gs_rhs_batch(t, n, Y, Pg, Qg, K);
        return;
    }
    for (int j = 0; j < n; ++j) {
        double x[GS_NX], p[GS_NP], q[GS_NQ > 0 ? GS_NQ : 1], dx[GS_NX];
        for (int i = 0; i < GS_NX; ++i) x[i] = Y[(long)i * n + j];
        for (int k = 0; k < GS_NP; ++k) p[k] = Pg[(long)k * n + j];
        for (int k = 0; k < GS_NQ; ++k) q[k] = Qg[(long)k * n + j];
        const double w = p[iw];
        gs_rhs(t / w, x, p, q, dx);
        for (int i = 0; i < GS_NX; ++i) K[(long)i * n + j] = dx[i] / w;
    }
}

/* DOP853's dense output over the accepted step [t, t + hh] of a group (SciPy's
 * Dop853DenseOutput): the three extra stages into K rows 13..15, the seven interpolant
 * coefficients into F (7 x S), then y(t + x hh) = Y + a Horner-like sum in x and 1 - x. */
#define GS_KROWS 16
static void gs_dense_coefficients(int iw, double t, double hh, int n, const double *Y,
                                  const double *YN, double *K, double *YT, const double *Pg,
                                  const double *Qg, double *F)
{
    const long S = (long)GS_NX * n;
    for (int x = 0; x < 3; ++x) {
        const int row = 13 + x;
        for (long e = 0; e < S; ++e) {
            double acc = 0.0;
            for (int r = 0; r < row; ++r) acc += GS_DOP853_AX[x * GS_KROWS + r] * K[r * S + e];
            YT[e] = Y[e] + hh * acc;
        }
        gs_rhs_group(iw, t + GS_DOP853_CX[x] * hh, n, YT, Pg, Qg, K + row * S);
    }
    for (long e = 0; e < S; ++e) {
        const double dy = YN[e] - Y[e], f0 = K[e], f1 = K[12 * S + e];
        F[e] = dy;
        F[S + e] = hh * f0 - dy;
        F[2 * S + e] = 2.0 * dy - hh * (f1 + f0);
        for (int i = 0; i < 4; ++i) {
            double acc = 0.0;
            for (int r = 0; r < GS_KROWS; ++r) acc += GS_DOP853_D[i * GS_KROWS + r] * K[r * S + e];
            F[(3 + i) * S + e] = hh * acc;
        }
    }
}

static double gs_dense_value(const double *F, long S, long e, double x, double y0)
{
    double y = 0.0;
    for (int i = 0; i < 7; ++i) {
        y += F[(6 - i) * S + e];
        y *= (i % 2 == 0) ? x : 1.0 - x;
    }
    return y + y0;
}

/* Write sample k of the group's points (alive: from V, structure of arrays; else NaN). */
static void gs_write_sample(double *OUT, int n_out, int g0, int n, int k, const double *V,
                            const int *alive, int ok)
{
    for (int j = 0; j < n; ++j) {
        double *out = OUT + ((long)(g0 + j) * n_out + k) * GS_NX;
        for (int i = 0; i < GS_NX; ++i) out[i] = ok && alive[j] ? V[(long)i * n + j] : NAN;
    }
}

static int gs_lockstep(int method, int npts, int group, const double *P, const double *X0,
                       double t0, double period, int first, int n_stops, int spp, int dense,
                       int iw, double rtol, double atol, double bound, long long max_steps,
                       double *OUT, long long *NFEV, long long *NSTEP, int *STATUS,
                       double *TFAIL, const gs_extras *m, const gs_range_t *rg)
{
    /* dense: plain sampled DOP853 runs take their natural steps and interpolate the
     * samples (the 7th-order dense output) instead of shortening steps to land on them */
    const int use_dense = dense && !m && OUT && method != 0;
    const gs_tableau *T = method == 0 ? &GS_RK45 : &GS_DOP853;
    const int ns = T->ns;
    const double exponent = -1.0 / (T->error_order + 1);
    if (group < 1) group = 1;
    const int G = group;
    const int n_kept = m ? n_stops - m->first_kept : 0;
    const int n_lyap = m && m->tangent ? n_stops - 1 - m->lyap_from : 0;
    double *Pg = malloc(sizeof(double) * GS_NP * G), *Qg = malloc(sizeof(double) * GS_NQ * G);
    double *Y = malloc(sizeof(double) * GS_NX * G), *YT = malloc(sizeof(double) * GS_NX * G);
    double *YN = malloc(sizeof(double) * GS_NX * G);
    double *K = malloc(sizeof(double) * GS_KROWS * GS_NX * G);
    double *F = use_dense ? malloc(sizeof(double) * 7 * GS_NX * G) : 0;
    int *alive = malloc(sizeof(int) * G), *leave = malloc(sizeof(int) * G);
    if (rg && rg->exit)
        for (long k = 0; k < 3L * npts; ++k) rg->exit[k] = NAN;
    double *E5s = malloc(sizeof(double) * G), *E3s = malloc(sizeof(double) * G);
    double *growth = malloc(sizeof(double) * G);
    if (!Pg || !Qg || !Y || !YT || !YN || !K || !alive || !leave || !E5s || !E3s || !growth ||
        (use_dense && !F))
        return -1;
    for (int g0 = 0; g0 < npts; g0 += G) {
        const int n = npts - g0 < G ? npts - g0 : G;
        long long nfev = 0, nsteps = 0;
        double h_abs = INFINITY, t = t0;
        const double t_end = t0 + ((double)(first + n_stops - 1) / spp) * period;
        for (int j = 0; j < n; ++j) {
            const double *p = P + (long)(g0 + j) * GS_NP;
            const double *x0 = X0 + (long)(g0 + j) * GS_NX;
            double q[GS_NQ], f[GS_NX];
            gs_prep(p, q);
            for (int k = 0; k < GS_NP; ++k) Pg[k * n + j] = p[k];
            for (int k = 0; k < GS_NQ; ++k) Qg[k * n + j] = q[k];
            for (int i = 0; i < GS_NX; ++i) Y[i * n + j] = x0[i];
            gs_rhs(t0, x0, p, q, f);
            alive[j] = 1;
            leave[j] = 0;
            growth[j] = 0.0;
            STATUS[g0 + j] = GS_OK;
            TFAIL[g0 + j] = NAN;
            if (m) {
                for (int i = 0; i < m->n_state; ++i) {
                    m->xmin[(long)(g0 + j) * m->n_state + i] = INFINITY;
                    m->xmax[(long)(g0 + j) * m->n_state + i] = -INFINITY;
                }
            }
            int c = gs_check_soa(Y, n, j, bound, m);
            if (c == GS_OK) c = gs_check(f, INFINITY);
            if (c != GS_OK) {
                alive[j] = 0;
                STATUS[g0 + j] = c;
                TFAIL[g0 + j] = t0;
                for (int i = 0; i < GS_NX; ++i) Y[i * n + j] = 0.0;
                continue;
            }
            /* in the phase (iw >= 0) a small first step; the control adapts it at once */
            const double h0 = iw >= 0 ? 1e-3 * period
                                      : gs_initial_step(t0, x0, f, t_end - t0, T->error_order,
                                                        rtol, atol, p, q, &nfev);
            if (h0 < h_abs) h_abs = h0;
        }
        if (!isfinite(h_abs)) h_abs = 1e-6 * period;
        nfev = nfev / (n > 0 ? n : 1) + 1;
        gs_rhs_group(iw, t0, n, Y, Pg, Qg, K); /* K[0] = f(t0, y0) */
        int group_status = GS_OK;
        int next_out = 0; /* dense: the next sample to write */
        const double t_last = t0 + (double)(first + n_stops - 1) * period / (double)spp;
        if (use_dense) {
            while (next_out < n_stops &&
                   t0 + (double)(first + next_out) * period / (double)spp <= t)
                gs_write_sample(OUT, n_stops, g0, n, next_out++, Y, alive, 1);
        }
        for (int ko = 0; ko < (use_dense ? 1 : n_stops); ++ko) {
            const double target =
                use_dense ? t_last : t0 + (double)(first + ko) * period / (double)spp;
            const int in_window = m && ko > m->first_kept;
            while (t < target && group_status == GS_OK) {
                const double min_step = 10.0 * fabs(nextafter(t, INFINITY) - t);
                double h = h_abs < min_step ? min_step : h_abs;
                int rejected = 0;
                const int step_first = next_out; /* dense: samples written by this step */
                for (;;) {
                    if (h < min_step) {
                        group_status = GS_STEP_TOO_SMALL;
                        break;
                    }
                    double t_new = t + h;
                    int clipped = 0;
                    if (t_new >= target) {
                        t_new = target;
                        clipped = 1;
                    }
                    const double hh = t_new - t;
                    const long S = (long)GS_NX * n;
                    for (int s = 1; s < ns; ++s) {
                        for (long e = 0; e < S; ++e) {
                            double acc = 0.0;
                            for (int r = 0; r < s; ++r) acc += T->A[s * ns + r] * K[r * S + e];
                            YT[e] = Y[e] + hh * acc;
                        }
                        gs_rhs_group(iw, t + T->C[s] * hh, n, YT, Pg, Qg, K + s * S);
                    }
                    for (long e = 0; e < S; ++e) {
                        double acc = 0.0;
                        for (int r = 0; r < ns; ++r) acc += T->B[r] * K[r * S + e];
                        YN[e] = Y[e] + hh * acc;
                    }
                    gs_rhs_group(iw, t + hh, n, YN, Pg, Qg, K + ns * S);
                    nfev += ns;
                    /* per-point error norms, structure-of-arrays */
                    for (int j = 0; j < n; ++j) E5s[j] = E3s[j] = 0.0;
                    for (int i = 0; i < GS_NX; ++i) {
                        const double *y0 = Y + (long)i * n, *y1 = YN + (long)i * n;
                        for (int j = 0; j < n; ++j) {
                            double a5 = 0.0, a3 = 0.0;
                            const long e = (long)i * n + j;
                            if (T->E) {
                                for (int r = 0; r <= ns; ++r) a5 += T->E[r] * K[r * S + e];
                                a5 *= hh;
                            } else {
                                for (int r = 0; r <= ns; ++r) {
                                    a5 += T->E5[r] * K[r * S + e];
                                    a3 += T->E3[r] * K[r * S + e];
                                }
                            }
                            const double a = fabs(y0[j]), b = fabs(y1[j]);
                            const double sc = atol + (a > b ? a : b) * rtol;
                            a5 /= sc;
                            a3 /= sc;
                            E5s[j] += a5 * a5;
                            E3s[j] += a3 * a3;
                        }
                    }
                    double err = 0.0;
                    for (int j = 0; j < n; ++j) {
                        if (!alive[j]) continue;
                        double ej;
                        if (T->E) {
                            ej = sqrt(E5s[j] / GS_NX);
                        } else {
                            ej = (E5s[j] == 0.0 && E3s[j] == 0.0)
                                     ? 0.0
                                     : fabs(hh) * E5s[j] / sqrt((E5s[j] + 0.01 * E3s[j]) * GS_NX);
                        }
                        if (!isfinite(ej)) {
                            /* a non-finite point leaves the group instead of stalling it */
                            alive[j] = 0;
                            STATUS[g0 + j] = GS_NOT_FINITE;
                            TFAIL[g0 + j] = t;
                            for (int i = 0; i < GS_NX; ++i) Y[i * n + j] = 0.0;
                            continue;
                        }
                        if (ej > err) err = ej;
                    }
                    if (err < 1.0) {
                        double factor = err == 0.0 ? 10.0 : 0.9 * pow(err, exponent);
                        if (factor > 10.0) factor = 10.0;
                        if (rejected && factor > 1.0) factor = 1.0;
                        const double next = hh * factor;
                        h_abs = clipped && !rejected && h > next ? h : next;
                        if (use_dense) {
                            int have_f = 0;
                            for (;;) {
                                if (next_out >= n_stops) break;
                                const double ts =
                                    t0 + (double)(first + next_out) * period / (double)spp;
                                if (ts > t_new) break;
                                if (ts == t_new) {
                                    gs_write_sample(OUT, n_stops, g0, n, next_out++, YN, alive, 1);
                                    continue;
                                }
                                if (!have_f) {
                                    gs_dense_coefficients(iw, t, hh, n, Y, YN, K, YT, Pg, Qg,
                                                          F);
                                    nfev += 3;
                                    have_f = 1;
                                }
                                const double x = (ts - t) / hh;
                                for (int j = 0; j < n; ++j) {
                                    double *out = OUT + ((long)(g0 + j) * n_stops + next_out) * GS_NX;
                                    for (int i = 0; i < GS_NX; ++i) {
                                        const long e = (long)i * n + j;
                                        out[i] = alive[j] ? gs_dense_value(F, S, e, x, Y[e]) : NAN;
                                    }
                                }
                                next_out++;
                            }
                        }
                        if (rg && rg->range) {
                            /* the valid range on the step, from its ends and slopes (the
                             * excitation phase's time s = omega tau: Python converts) */
                            for (int j = 0; j < n; ++j)
                                if (alive[j])
                                    leave[j] = gs_range_step(rg, g0 + j, t, hh, Y + j, YN + j,
                                                             K + j, K + ns * S + j, n);
                        }
                        t = t_new;
                        memcpy(Y, YN, sizeof(double) * S);
                        memcpy(K, K + ns * S, sizeof(double) * S); /* FSAL */
                        break;
                    }
                    double factor = 0.9 * pow(err, exponent);
                    if (!(factor > 0.2)) factor = 0.2;
                    h = hh * factor;
                    rejected = 1;
                }
                nsteps += 1;
                if (nsteps >= max_steps && group_status == GS_OK) group_status = GS_TOO_MANY_STEPS;
                int dead = 0;
                for (int j = 0; j < n; ++j) {
                    if (!alive[j]) continue;
                    int c = gs_check_soa(Y, n, j, bound, m);
                    if (c == GS_OK && leave[j]) c = GS_LEFT_RANGE;
                    if (c != GS_OK) {
                        alive[j] = 0;
                        STATUS[g0 + j] = c;
                        TFAIL[g0 + j] = leave[j] ? rg->exit[3 * (long)(g0 + j)] : t;
                        for (int i = 0; i < GS_NX; ++i) Y[i * n + j] = 0.0;
                        dead = 1;
                        /* as without dense output: no samples from the failing step */
                        for (int k = step_first; use_dense && k < next_out; ++k)
                            for (int i = 0; i < GS_NX; ++i)
                                OUT[((long)(g0 + j) * n_stops + k) * GS_NX + i] = NAN;
                    }
                }
                if (dead) gs_rhs_group(iw, t, n, Y, Pg, Qg, K); /* refresh FSAL stage */
                if (in_window) gs_extremes(Y, n, g0, alive, m);
            }
            const int group_ok = group_status == GS_OK;
            if (use_dense) {
                /* a failed group leaves the samples it did not reach undefined */
                while (next_out < n_stops)
                    gs_write_sample(OUT, n_stops, g0, n, next_out++, Y, alive, 0);
                continue;
            }
            if (OUT) gs_write_sample(OUT, n_stops, g0, n, ko, Y, alive, group_ok);
            if (!m) continue;
            if (ko >= m->first_kept) {
                if (ko == m->first_kept) gs_extremes(Y, n, g0, alive, m);
                for (int j = 0; j < n; ++j) {
                    double *out = m->poinc + ((long)(g0 + j) * n_kept + ko - m->first_kept) *
                                                 m->n_state;
                    const int ok = alive[j] && group_ok;
                    for (int i = 0; i < m->n_state; ++i) out[i] = ok ? Y[i * n + j] : NAN;
                }
            }
            if (m->tangent && group_ok) {
                /* Benettin: renormalise the tangent vector every stop, sum log |w| after
                 * lyap_from; the FSAL stage changes with the rescaling. */
                for (int j = 0; j < n; ++j) {
                    if (!alive[j]) continue;
                    double g = 0.0;
                    for (int i = m->n_state; i < GS_NX; ++i) g += Y[(long)i * n + j] * Y[(long)i * n + j];
                    g = sqrt(g);
                    if (!(g > 0.0) || !isfinite(g)) {
                        alive[j] = 0;
                        STATUS[g0 + j] = GS_NOT_FINITE;
                        TFAIL[g0 + j] = t;
                        for (int i = 0; i < GS_NX; ++i) Y[i * n + j] = 0.0;
                        continue;
                    }
                    for (int i = m->n_state; i < GS_NX; ++i) Y[(long)i * n + j] /= g;
                    if (ko > m->lyap_from) {
                        growth[j] += log(g);
                        m->lyap[(long)(g0 + j) * n_lyap + ko - m->lyap_from - 1] =
                            growth[j] / ((double)(ko - m->lyap_from) * period / spp);
                    }
                }
                gs_rhs_group(iw, t, n, Y, Pg, Qg, K);
                nfev += 1;
            }
        }
        for (int j = 0; j < n; ++j) {
            NFEV[g0 + j] = nfev;
            NSTEP[g0 + j] = nsteps;
            if (STATUS[g0 + j] == GS_OK && group_status != GS_OK) {
                STATUS[g0 + j] = group_status;
                TFAIL[g0 + j] = t;
            }
            if (m && m->tangent && STATUS[g0 + j] != GS_OK)
                for (int k = 0; k < n_lyap; ++k) m->lyap[(long)(g0 + j) * n_lyap + k] = NAN;
        }
    }
    free(Pg); free(Qg); free(Y); free(YT); free(YN); free(K); free(alive); free(leave);
    free(E5s); free(E3s); free(growth); free(F);
    return 0;
}

/* Sampled runs: OUT npts x (n_sample spp + 1) x GS_NX at t0 + (n_transient + k / spp) T. */
int gs_run_lockstep(int method, int npts, int group, const double *P, const double *X0,
                    double t0, double period, int n_transient, int n_sample, int spp, int dense,
                    double rtol, double atol, double bound, long long max_steps, double *OUT,
                    long long *NFEV, long long *NSTEP, int *STATUS, double *TFAIL,
                    const double *RANGE, int stop_exit, double *EXIT)
{
    const gs_range_t rg = {RANGE, stop_exit, EXIT};
    return gs_lockstep(method, npts, group, P, X0, t0, period, n_transient * spp,
                       n_sample * spp + 1, spp, dense, -1, rtol, atol, bound, max_steps, OUT,
                       NFEV, NSTEP, STATUS, TFAIL, 0, &rg);
}

/* Sampled runs in the excitation phase s = omega tau (period 2 pi for every point): each
 * point its own forcing frequency P[iw], all in lockstep.  OUT as gs_run_lockstep's, at
 * s = s0 + 2 pi (n_transient + k / spp). */
int gs_run_phase(int method, int npts, int group, const double *P, const double *X0, double s0,
                 int iw, int n_transient, int n_sample, int spp, int dense, double rtol,
                 double atol, double bound, long long max_steps, double *OUT, long long *NFEV,
                 long long *NSTEP, int *STATUS, double *TFAIL, const double *RANGE,
                 int stop_exit, double *EXIT)
{
    if (iw < 0 || iw >= GS_NP) return -2;
    for (int j = 0; j < npts; ++j)
        if (!(P[(long)j * GS_NP + iw] > 0.0)) return -3;
    const gs_range_t rg = {RANGE, stop_exit, EXIT};
    return gs_lockstep(method, npts, group, P, X0, s0, 2.0 * M_PI, n_transient * spp,
                       n_sample * spp + 1, spp, dense, iw, rtol, atol, bound, max_steps, OUT,
                       NFEV, NSTEP, STATUS, TFAIL, 0, &rg);
}

/* Maps: stops at every period t0 + k T, k = 0 .. n_transient + n_sample.  Keeps the
 * Poincare points of the last n_sample + 1 stops (POINC), the extremes of the physical
 * state over the sampled window at every accepted step (XMIN, XMAX), the valid range
 * (RANGE, or NULL) as a status, and with tangent = 1 (the variational library: X0 holds
 * x and a tangent vector) the running largest Lyapunov exponent over the last n_lyap
 * periods (LYAP npts x n_lyap). */
int gs_map_lockstep(int method, int npts, int group, const double *P, const double *X0,
                    double t0, double period, int n_transient, int n_sample, int tangent,
                    int n_lyap, const double *RANGE, double rtol, double atol, double bound,
                    long long max_steps, double *POINC, double *XMIN, double *XMAX,
                    double *LYAP, long long *NFEV, long long *NSTEP, int *STATUS, double *TFAIL)
{
    const int n_stops = n_transient + n_sample + 1;
    if (tangent && (n_lyap < 1 || n_lyap > n_stops - 1)) return -2;
    gs_extras m = {tangent ? GS_NX / 2 : GS_NX, tangent, n_transient,
                   tangent ? n_stops - 1 - n_lyap : 0, RANGE, POINC, XMIN, XMAX, LYAP};
    return gs_lockstep(method, npts, group, P, X0, t0, period, 0, n_stops, 1, 0, -1, rtol, atol,
                       bound, max_steps, 0, NFEV, NSTEP, STATUS, TFAIL, &m, 0);
}

/* One right-hand-side evaluation (tests compare it with the NumPy code). */
void gs_eval(double tau, const double *x, const double *p, double *dx)
{
    double q[GS_NQ];
    gs_prep(p, q);
    gs_rhs(tau, x, p, q, dx);
}

/* The batched form on n points (structure of arrays; tests compare it too). */
void gs_eval_batch(double tau, int n, const double *X, const double *P, double *DX)
{
    double *Q = malloc(sizeof(double) * GS_NQ * (n > 0 ? n : 1));
    double p[GS_NP], q[GS_NQ];
    if (!Q) return;
    for (int j = 0; j < n; ++j) {
        for (int k = 0; k < GS_NP; ++k) p[k] = P[k * n + j];
        gs_prep(p, q);
        for (int k = 0; k < GS_NQ; ++k) Q[k * n + j] = q[k];
    }
    gs_rhs_batch(tau, n, X, P, Q, DX);
    free(Q);
}

#ifdef GS_VARIATIONAL
/* Benettin's largest Lyapunov exponent: the state x (first half) and a tangent vector w
 * (second half) integrated together period by period; w renormalised after each period and
 * log |w| accumulated.  running[k] = estimate after k + 1 periods.  Returns a GS_ status. */
int gs_benettin(const double *p, const double *z0, double t0, double period, int periods,
                double rtol, double atol, double bound, long long max_steps, double *running,
                long long *NFEV)
{
    const int n = GS_NX / 2;
    double q[GS_NQ], z[GS_NX], f[GS_NX];
    long long nfev = 0, nsteps = 0;
    gs_prep(p, q);
    memcpy(z, z0, sizeof(double) * GS_NX);
    double t = t0, total = 0.0;
    gs_rhs(t, z, p, q, f);
    nfev += 1;
    if (gs_check(z, bound) != GS_OK || gs_check(f, INFINITY) != GS_OK) {
        *NFEV = nfev;
        return GS_NOT_FINITE;
    }
    double h_abs = gs_initial_step(t, z, f, period, 7, rtol, atol, p, q, &nfev);
    for (int k = 0; k < periods; ++k) {
        const int status = gs_adaptive_to(&GS_DOP853, &t, z, f, &h_abs, t0 + (k + 1) * period,
                                          rtol, atol, p, q, bound, max_steps, &nfev, &nsteps,
                                          0, 0);
        if (status != GS_OK) {
            *NFEV = nfev;
            return status;
        }
        double g = 0.0;
        for (int i = n; i < GS_NX; ++i) g += z[i] * z[i];
        g = sqrt(g);
        if (!(g > 0.0) || !isfinite(g)) {
            *NFEV = nfev;
            return GS_NOT_FINITE;
        }
        total += log(g);
        for (int i = n; i < GS_NX; ++i) z[i] /= g;
        gs_rhs(t, z, p, q, f); /* the tangent part of f changed with the rescaling */
        nfev += 1;
        running[k] = total / ((k + 1) * period);
    }
    *NFEV = nfev;
    return GS_OK;
}
#endif
