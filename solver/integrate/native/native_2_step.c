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
 * along r for each element would gather K with stride S).  Zero weights are skipped: a
 * third of DOP853's (24 of 66 in A, 4 of 12 in b, 5 of 13 in each error row), each a
 * pass over S elements read from cache for nothing; for finite stages the sum is the
 * same to the bit (fma(0, k, s) = s, and fma(w, k, 0) rounds w k as w * k does).  A stage
 * that is not finite no longer reaches a sum that weights it zero: the error rows weight
 * the slope at the new state zero, so a point whose slope alone fails there now stops one
 * step later, at the next step's error norm, instead of at this one's. */
static inline __attribute__((always_inline)) void
gs_weighted_any(double *restrict out, const double *restrict K, const double *restrict w,
                int m, long S)
{
    int r0 = 0;
    while (r0 < m - 1 && w[r0] == 0.0) ++r0;
    const double w0 = w[r0];
    const double *restrict K0 = K + r0 * S;
    for (long e = 0; e < S; ++e) out[e] = w0 * K0[e];
    for (int r = r0 + 1; r < m; ++r) {
        const double wr = w[r];
        if (wr == 0.0) continue;
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
