/* homog_eigen.c — extreme eigenvalue estimates of the free stiffness for
 * DR's parameters (4.47): Lanczos, Rayleigh quotients.  Contract: homog_eigen.h. */
#include "homog_eigen.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/dem/dem_kblocks.h"

/* number of eigenvalues of T below s (Sturm sequence) */
static int sturm_count(const double *a, const double *b, int m, double s)
{
    int cnt = 0;
    double q = a[0] - s;
    for (int k = 0;; k++) {
        if (q == 0)
            q = -1e-300;
        if (q < 0)
            cnt++;
        if (k + 1 >= m)
            break;
        q = a[k + 1] - s - b[k] * b[k] / q;
    }
    return cnt;
}

double pk_tridiag_min_eig(const double *a, const double *b, int m)
{
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < m; k++) { /* Gershgorin interval */
        double rad = (k > 0 ? fabs(b[k - 1]) : 0) + (k + 1 < m ? fabs(b[k]) : 0);
        lo = fmin(lo, a[k] - rad);
        hi = fmax(hi, a[k] + rad);
    }
    for (int it = 0; it < 200 && hi - lo > 1e-15 * fmax(fabs(lo), fabs(hi)); it++) {
        double mid = 0.5 * (lo + hi);
        if (sturm_count(a, b, m, mid) >= 1)
            hi = mid;
        else
            lo = mid;
    }
    return 0.5 * (lo + hi);
}

/* The masked dot product with dim a constant (2 or 3): the axis loop
 * unrolled, the same operations in the same order (it runs on every DR
 * iteration for the residual and in every Lanczos step). */
static inline double dot_mask_loop(const double *u, const double *v, const uint8_t *mask, size_t np,
                                   const int dim)
{
    double s = 0;
    for (size_t i = 0; i < np; i++)
        if (mask[i])
            for (int a = 0; a < dim; a++)
                s += u[3 * i + a] * v[3 * i + a];
    return s;
}

double pk_homog_dot_mask(const double *u, const double *v, const uint8_t *mask, size_t np, int dim)
{
    return dim == 2 ? dot_mask_loop(u, v, mask, np, 2) : dot_mask_loop(u, v, mask, np, dim);
}

/* dot_mask_loop's u·v (the same operations in the same order) and u·w in
 * the same pass. */
static inline double dot2_mask_loop(const double *u, const double *v, const double *w,
                                    const uint8_t *mask, size_t np, const int dim, double *uw)
{
    double s = 0, t = 0;
    for (size_t i = 0; i < np; i++)
        if (mask[i])
            for (int a = 0; a < dim; a++) {
                s += u[3 * i + a] * v[3 * i + a];
                t += u[3 * i + a] * w[3 * i + a];
            }
    *uw = t;
    return s;
}

double pk_homog_dot2_mask(const double *u, const double *v, const double *w, const uint8_t *mask,
                          size_t np, int dim, double *uw)
{
    return dim == 2 ? dot2_mask_loop(u, v, w, mask, np, 2, uw)
                    : dot2_mask_loop(u, v, w, mask, np, dim, uw);
}

double pk_homog_rayleigh(const pk_dem_pairs *c, int dim, size_t np, double E, const uint8_t *mask,
                         const double *v, double *work)
{
    double vv = pk_homog_dot_mask(v, v, mask, np, dim);
    if (!(vv > 0))
        return NAN;
    pk_dem_kv(c, dim, np, E, mask, v, work);
    return pk_homog_dot_mask(v, work, mask, np, dim) / vv;
}

double pk_homog_lanczos_min(const pk_dem_pairs *c, int dim, size_t np, double E,
                            const uint8_t *mask, int steps)
{
    size_t ndof = 0;
    for (size_t i = 0; i < np; i++)
        ndof += mask[i] ? (size_t)dim : 0;
    if (ndof == 0)
        return 0;
    if ((size_t)steps > ndof)
        steps = (int)ndof;
    double *q = calloc(3 * np, sizeof *q), *qp = calloc(3 * np, sizeof *qp);
    double *w = calloc(3 * np, sizeof *w);
    double *al = calloc((size_t)steps + 1, sizeof *al), *be = calloc((size_t)steps + 1, sizeof *be);
    size_t *dof = malloc(ndof * sizeof *dof); /* the masked entries, in order */
    pk_dem_kblocks kb = {0};                  /* K once for the `steps` products */
    if (!q || !qp || !w || !al || !be || !dof || pk_dem_kblocks_build(&kb, c, E, mask) != 0) {
        free(q), free(qp), free(w), free(al), free(be), free(dof);
        return NAN;
    }
    for (size_t i = 0, n = 0; i < np; i++)
        if (mask[i])
            for (int a = 0; a < dim; a++)
                dof[n++] = 3 * i + (size_t)a;
    /* deterministic, non-special start vector */
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (size_t i = 0; i < np; i++)
        if (mask[i])
            for (int a = 0; a < dim; a++) {
                h ^= h << 13, h ^= h >> 7, h ^= h << 17;
                q[3 * i + a] = (double)(h >> 11) / 9007199254740992.0 - 0.5;
            }
    double nq = sqrt(pk_homog_dot_mask(q, q, mask, np, dim));
    for (size_t k = 0; k < 3 * np; k++)
        q[k] /= nq;
    /* the vector passes run over the masked entries only (the others, and
     * z in 2D, stay 0: K·v reads v on the mask only); a cheaper q = w·(1/β)
     * moves λ_min's rounding and with it the bench's plastic paths
     * (docs/perf/homog.md) */
    int m = 0;
    double beta = 0;
    for (int it = 0; it < steps; it++) {
        pk_dem_kblocks_kv(&kb, dim, np, q, w);
        double alpha = pk_homog_dot_mask(q, w, mask, np, dim);
        for (size_t n = 0; n < ndof; n++) {
            const size_t k = dof[n];
            w[k] -= alpha * q[k] + beta * qp[k];
        }
        al[m++] = alpha;
        beta = sqrt(pk_homog_dot_mask(w, w, mask, np, dim));
        if (!(beta > 1e-14 * fabs(alpha)) || it + 1 == steps)
            break;
        be[m - 1] = beta;
        for (size_t n = 0; n < ndof; n++) {
            const size_t k = dof[n];
            qp[k] = q[k];
            q[k] = w[k] / beta;
        }
    }
    double lmin = pk_tridiag_min_eig(al, be, m);
    pk_dem_kblocks_free(&kb);
    free(q), free(qp), free(w), free(al), free(be), free(dof);
    return lmin;
}
