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
        /* one tangent start for every point, or one per point */
        const double *w0 = J->tangent0 + (J->tangent0_len > GS_NX - GS_NSTATE
                                              ? (g0 + j) * (GS_NX - GS_NSTATE)
                                              : 0);
        for (int i = GS_NSTATE; i < GS_NX; ++i) y[i] = w0[i - GS_NSTATE];
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
        /* the tangent's end (unit length after the last stop) and its log growth */
        if (J->tangent) {
            double *w = J->tangent + pt * (GS_NX - GS_NSTATE + 1);
            const int ok = J->status[pt] == GS_OK;
            for (int i = GS_NSTATE; i < GS_NX; ++i)
                w[i - GS_NSTATE] = ok ? c->Y[(long)i * n + j] : NAN;
            w[GS_NX - GS_NSTATE] = ok ? c->growth[j] : NAN;
        }
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
        (!gs_array_ok(J->tangent0, J->tangent0_len, GS_NX - GS_NSTATE, 1, GS_NSTATE == GS_NX) &&
         !gs_array_ok(J->tangent0, J->tangent0_len, N, GS_NX - GS_NSTATE, 0)))
        return GS_E_SIZE;
    /* the tangent's end: with the exponent, the tangent from the run's start */
    if (!gs_array_ok(J->tangent, J->tangent_len, N, GS_NX - GS_NSTATE + 1, 1) ||
        (J->tangent && (!J->exponent || J->lyapunov_periods != J->transient + J->periods)))
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
