/* Hand-written vectorised lockstep DOP853 for the reference DI-SO model: the speed target of
 * the compiled backend (benchmarks/performance.py measures both in one run).
 *
 *   u'' + 2 xi_uu u' + 2 xi_uv v' + K_uu k_u(t) g(u) + K_uv k_v(t) g(v) = f_u + e_u''(t)
 *   v'' + 2 xi_vu u' + 2 xi_vv v' + K_vu k_u(t) g(u) + K_vv k_v(t) g(v) = f_v + e_v''(t)
 *   k_u = 1 + sum_h a_h cos(h w t) + b_h sin(h w t),  k_v = k_u(t - phi/w) with its own a, b
 *   e_j'' = -E_j w^2 cos(w t - phi_j + psi_j),  g(x) = g1 x + g3 x^3 + g5 x^5 + g7 x^7
 *
 * All points share time and step (the largest error of the group decides); the excitation
 * is evaluated once per stage for the whole group; the loops over points vectorise.  Only
 * the static load f_u, f_v differs between points (a load-ratio sweep).  Step control as
 * SciPy's DOP853 (error norm of Hairer's dop853, safety 0.9, factor in [0.2, 10]).
 * Coefficients of the method are passed in (SciPy's arrays). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { NS = 12 };

typedef struct {
    double w, xi_uu, xi_uv, xi_vu, xi_vv, K_uu, K_uv, K_vu, K_vv;
    double a_u[3], b_u[3], a_v[3], b_v[3], phi, E_u, psi_u, E_v, psi_v, g1, g3, g5, g7;
} model;

static void rhs(const model *m, double t, int n, const double *restrict fu,
                const double *restrict fv, const double *restrict y, double *restrict dy)
{
    const double c1 = cos(m->w * t), s1 = sin(m->w * t);
    const double c2 = c1 * c1 - s1 * s1, s2 = 2.0 * s1 * c1;
    const double c3 = c2 * c1 - s2 * s1, s3 = s2 * c1 + c2 * s1;
    const double cp = cos(m->phi), sp = sin(m->phi);
    const double cp2 = cp * cp - sp * sp, sp2 = 2.0 * sp * cp;
    const double cp3 = cp2 * cp - sp2 * sp, sp3 = sp2 * cp + cp2 * sp;
    /* cos(h(wt - phi)) and sin(h(wt - phi)) */
    const double cv1 = c1 * cp + s1 * sp, sv1 = s1 * cp - c1 * sp;
    const double cv2 = c2 * cp2 + s2 * sp2, sv2 = s2 * cp2 - c2 * sp2;
    const double cv3 = c3 * cp3 + s3 * sp3, sv3 = s3 * cp3 - c3 * sp3;
    const double ku = 1.0 + m->a_u[0] * c1 + m->a_u[1] * c2 + m->a_u[2] * c3 + m->b_u[0] * s1 +
                      m->b_u[1] * s2 + m->b_u[2] * s3;
    const double kv = 1.0 + m->a_v[0] * cv1 + m->a_v[1] * cv2 + m->a_v[2] * cv3 +
                      m->b_v[0] * sv1 + m->b_v[1] * sv2 + m->b_v[2] * sv3;
    const double w2 = m->w * m->w;
    const double eu = -m->E_u * w2 * cos(m->w * t + m->psi_u);
    const double ev = -m->E_v * w2 * cos(m->w * t - m->phi + m->psi_v);
    const double *u = y, *v = y + n, *du = y + 2 * n, *dv = y + 3 * n;
    for (int j = 0; j < n; ++j) {
        const double u2 = u[j] * u[j], v2 = v[j] * v[j];
        const double gu = u[j] * (m->g1 + u2 * (m->g3 + u2 * (m->g5 + u2 * m->g7))) * ku;
        const double gv = v[j] * (m->g1 + v2 * (m->g3 + v2 * (m->g5 + v2 * m->g7))) * kv;
        dy[j] = du[j];
        dy[n + j] = dv[j];
        dy[2 * n + j] = fu[j] + eu - 2.0 * (m->xi_uu * du[j] + m->xi_uv * dv[j]) -
                        m->K_uu * gu - m->K_uv * gv;
        dy[3 * n + j] = fv[j] + ev - 2.0 * (m->xi_vu * du[j] + m->xi_vv * dv[j]) -
                        m->K_vu * gu - m->K_vv * gv;
    }
}

/* consts: w, xi_uu, xi_uv, xi_vu, xi_vv, K_uu, K_uv, K_vu, K_vv, a_u[3], b_u[3], a_v[3],
 * b_v[3], phi, E_u, psi_u, E_v, psi_v, g1, g3, g5, g7 (34 numbers).
 * tables: A (12 x 12), B (12), C (12), E3 (13), E5 (13).
 * OUT: n x (n_sample + 1) x 4, the state at the start of each sampled period and the end.
 * Returns the number of right-hand-side evaluations per point. */
long long ref_run(int n, const double *fu, const double *fv, const double *consts,
                  const double *A, const double *B, const double *C, const double *E3,
                  const double *E5, const double *y0, int n_transient, int n_sample,
                  double rtol, double atol, double *OUT)
{
    model m;
    memcpy(&m, consts, sizeof(model));
    const double T = 2.0 * M_PI / m.w;
    const long S = 4L * n;
    double *y = malloc(sizeof(double) * S), *yn = malloc(sizeof(double) * S);
    double *yt = malloc(sizeof(double) * S), *K = malloc(sizeof(double) * S * (NS + 1));
    double *e5 = malloc(sizeof(double) * n), *e3 = malloc(sizeof(double) * n);
    long long nfev = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < 4; ++i) y[i * n + j] = y0[4 * j + i];
    double t = 0.0, h = 1e-3 * T;
    rhs(&m, t, n, fu, fv, y, K);
    nfev = 1;
    for (int k = 0; k <= n_sample; ++k) {
        const double target = (n_transient + k) * T;
        while (t < target) {
            int rejected = 0;
            for (;;) {
                double hh = h, tn = t + h;
                int clipped = 0;
                if (tn >= target) {
                    tn = target;
                    hh = tn - t;
                    clipped = 1;
                }
                for (int s = 1; s < NS; ++s) {
                    for (long e = 0; e < S; ++e) {
                        double acc = 0.0;
                        for (int r = 0; r < s; ++r) acc += A[s * NS + r] * K[r * S + e];
                        yt[e] = y[e] + hh * acc;
                    }
                    rhs(&m, t + C[s] * hh, n, fu, fv, yt, K + s * S);
                }
                for (long e = 0; e < S; ++e) {
                    double acc = 0.0;
                    for (int r = 0; r < NS; ++r) acc += B[r] * K[r * S + e];
                    yn[e] = y[e] + hh * acc;
                }
                rhs(&m, tn, n, fu, fv, yn, K + NS * S);
                nfev += NS;
                for (int j = 0; j < n; ++j) e5[j] = e3[j] = 0.0;
                for (int i = 0; i < 4; ++i)
                    for (int j = 0; j < n; ++j) {
                        const long e = (long)i * n + j;
                        double a5 = 0.0, a3 = 0.0;
                        for (int r = 0; r <= NS; ++r) {
                            a5 += E5[r] * K[r * S + e];
                            a3 += E3[r] * K[r * S + e];
                        }
                        const double sc = atol + fmax(fabs(y[e]), fabs(yn[e])) * rtol;
                        e5[j] += (a5 / sc) * (a5 / sc);
                        e3[j] += (a3 / sc) * (a3 / sc);
                    }
                double err = 0.0;
                for (int j = 0; j < n; ++j) {
                    const double d = e5[j] + 0.01 * e3[j];
                    const double ej = d > 0.0 ? fabs(hh) * e5[j] / sqrt(d * 4.0) : 0.0;
                    if (ej > err) err = ej;
                }
                if (err < 1.0) {
                    double f = err == 0.0 ? 10.0 : 0.9 * pow(err, -1.0 / 8.0);
                    if (f > 10.0) f = 10.0;
                    if (rejected && f > 1.0) f = 1.0;
                    const double next = hh * f;
                    h = clipped && !rejected && h > next ? h : next;
                    t = tn;
                    memcpy(y, yn, sizeof(double) * S);
                    memcpy(K, K + NS * S, sizeof(double) * S);
                    break;
                }
                double f = 0.9 * pow(err, -1.0 / 8.0);
                if (f < 0.2) f = 0.2;
                h = hh * f;
                rejected = 1;
            }
        }
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < 4; ++i) OUT[((long)j * (n_sample + 1) + k) * 4 + i] = y[i * n + j];
    }
    free(y); free(yn); free(yt); free(K); free(e5); free(e3);
    return nfev;
}
