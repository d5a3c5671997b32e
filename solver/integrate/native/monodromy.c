
/* The monodromy library's model: the state x (GS_MONODROMY_N) and the matrix W (row-major,
 * W[i][k] = d x_i / d x0_k), (x, W)' = (F(tau, x), J(tau, x) W).  Joined by build.py after
 * the model's C_SOURCE (its gs_prep, gs_rhs and gs_rhs_batch renamed gs_model_*) and its
 * C_JACOBIAN (gs_jac over the nonzero entries GS_JROW, GS_JCOL); F and J once a stage, then
 * J W over the nonzeros, where n copies of the state with one tangent each computed F and
 * J w n times (derive/emit/c_jacobian.py).  The engine sees one state of GS_NX components
 * whose tangent block is W: Benettin's renormalisation scales the whole matrix by one
 * number, which the log growth it returns undoes. */
#undef GS_NX /* GS_MONODROMY_N, the state's length, is defined by build.py */
#define GS_NX (GS_MONODROMY_N + GS_MONODROMY_N * GS_MONODROMY_N)

static void gs_prep(const double *p, double *q) { gs_model_prep(p, q); }

static inline void gs_rhs(double tau, const double *x, const double *p, const double *q,
                          double *dx)
{
    enum { N = GS_MONODROMY_N };
    double J[GS_NJ > 0 ? GS_NJ : 1];
    gs_model_rhs(tau, x, p, q, dx);
    gs_jac(tau, x, p, J);
    const double *W = x + N;
    double *dW = dx + N;
    for (int e = 0; e < N * N; ++e) dW[e] = 0.0;
    for (int e = 0; e < GS_NJ; ++e) {
        const double a = J[e];
        const double *restrict w = W + GS_JCOL[e] * N;
        double *restrict d = dW + GS_JROW[e] * N;
        for (int k = 0; k < N; ++k) d[k] += a * w[k];
    }
}

/* A group of points in structure-of-arrays layout (X[i*n + j]: component i of point j),
 * one point at a time: the monodromy's runs are single points or a few. */
static void gs_rhs_batch(double tau, int n, const double *restrict X, const double *restrict P,
                         const double *restrict Q, double *restrict DX)
{
    double x[GS_NX], dx[GS_NX], p[GS_NP], q[GS_NQ > 0 ? GS_NQ : 1];
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < GS_NX; ++i) x[i] = X[(long)i * n + j];
        for (int i = 0; i < GS_NP; ++i) p[i] = P[(long)i * n + j];
        for (int i = 0; i < GS_NQ; ++i) q[i] = Q[(long)i * n + j];
        gs_rhs(tau, x, p, q, dx);
        for (int i = 0; i < GS_NX; ++i) DX[(long)i * n + j] = dx[i];
    }
}
